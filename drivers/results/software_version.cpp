#include "drivers/results/software_version.hpp"

namespace eical::drivers {

// EICAL_VERSION: the CMake project version, set on this file only (drivers/CMakeLists.txt).
const char* software_version() { return "eical " EICAL_VERSION; }

}  // namespace eical::drivers
