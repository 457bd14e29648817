#pragma once
// What must hold on this machine before eicald can measure, each problem one line naming
// the cause: the recording path is writable, the Cyclone DDS configuration the service
// will use exists, the program directory of the program set-point is there. `eicald
// --check` reports all of them (and opens the source and the trigger inputs); start-up
// refuses a missing DDS configuration or program directory and reports an unwritable
// recording path in Status (measuring goes on; every write is retried).
#include "daemon/config/daemon_config.hpp"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace eical::daemon {

// Creates the directory when missing, then a file in it (removed again).
std::optional<std::string> recording_dir_problem(const std::filesystem::path& dir);
// The configuration in use: [dds] config_uri, else $CYCLONEDDS_URI; each file:// (or
// plain path) entry must be a readable file; inline XML is not checked here.
std::optional<std::string> dds_config_problem(const DdsConfig& dds);
// [setpoint]: the program directory exists (always for source = "program"; beside the
// servo stream when a default program is set) and the default program reads.
std::optional<std::string> setpoint_problem(const SetPointConfig& setpoint);

}  // namespace eical::daemon
