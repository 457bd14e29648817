#pragma once
// The software that wrote a result ("eical 0.1.0", the project's version), recorded in each
// result and in the calibration history, so that a change of figures can be told from a
// change of software.
namespace eical::drivers {

const char* software_version();

}  // namespace eical::drivers
