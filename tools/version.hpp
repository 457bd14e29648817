#pragma once
// The eical version (CMake's project version), for `eical version` and the reports' header.
namespace eical::tools {

#ifndef EICAL_VERSION
#define EICAL_VERSION "0.0.0-unknown"
#endif
inline constexpr const char* kVersion = EICAL_VERSION;

}  // namespace eical::tools
