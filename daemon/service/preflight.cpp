#include "daemon/service/preflight.hpp"

#include "drivers/setpoint/program_catalog.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace eical::daemon {
namespace fs = std::filesystem;

std::optional<std::string> recording_dir_problem(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return "recording: cannot create " + dir.string() + ": " + ec.message() + " ([recording] dir)";
  if (!fs::is_directory(dir, ec)) return "recording: " + dir.string() + " is not a directory ([recording] dir)";
  const fs::path probe = dir / (".eicald-check-" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) return "recording: " + dir.string() + " is not writable: " + std::strerror(errno) + " ([recording] dir)";
  ::close(fd);
  fs::remove(probe, ec);
  return std::nullopt;
}

std::optional<std::string> dds_config_problem(const DdsConfig& dds) {
  const char* env = std::getenv("CYCLONEDDS_URI");
  const std::string uri = !dds.config_uri.empty() ? dds.config_uri : env ? std::string(env) : std::string();
  const std::string origin = !dds.config_uri.empty() ? "[dds] config_uri" : "CYCLONEDDS_URI";
  if (uri.empty()) return std::nullopt;  // Cyclone's built-in defaults
  std::size_t first = uri.find_first_not_of(" \t\n");
  if (first == std::string::npos || uri[first] == '<') return std::nullopt;  // inline XML
  for (std::size_t pos = first; pos < uri.size();) {
    std::size_t comma = uri.find(',', pos);
    if (comma == std::string::npos) comma = uri.size();
    std::string entry = uri.substr(pos, comma - pos);
    pos = comma + 1;
    const auto a = entry.find_first_not_of(" \t\n"), b = entry.find_last_not_of(" \t\n");
    if (a == std::string::npos) continue;
    entry = entry.substr(a, b - a + 1);
    const std::string path = entry.rfind("file://", 0) == 0 ? entry.substr(7) : entry;
    if (!fs::is_regular_file(path))
      return "dds: the Cyclone DDS configuration " + path + " (" + origin + ") does not exist";
    if (::access(path.c_str(), R_OK) != 0)
      return "dds: cannot read the Cyclone DDS configuration " + path + " (" + origin + "): " + std::strerror(errno);
  }
  return std::nullopt;
}

std::optional<std::string> setpoint_problem(const SetPointConfig& setpoint) {
  if (setpoint.source == "none") return std::nullopt;
  // The program set-point needs its programs; beside the servo stream they only name
  // what to evaluate, so a missing directory matters only when a default is set.
  if (!fs::is_directory(setpoint.program_dir) && (setpoint.source == "program" || setpoint.default_program >= 0))
    return "setpoint: the program directory " + setpoint.program_dir.string() +
           " does not exist ([setpoint.program] directory)";
  if (setpoint.default_program >= 0) {
    try {
      (void)drivers::ProgramCatalog(setpoint.program_dir).program(setpoint.default_program);
    } catch (const std::exception& e) {
      return std::string("setpoint: default program: ") + e.what();
    }
  }
  return std::nullopt;
}

}  // namespace eical::daemon
