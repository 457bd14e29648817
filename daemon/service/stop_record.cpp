#include "daemon/service/stop_record.hpp"

#include "daemon/system/log.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "history/record/utc_time.hpp"

#include <unistd.h>

#include <ctime>
#include <fstream>

namespace eical::daemon {

namespace {

using history::utc_now;

}  // namespace

StopRecord::StopRecord(std::filesystem::path recording_dir)
    : file_(std::move(recording_dir) / kFileName), started_(utc_now()) {
  std::ifstream is(file_);
  if (!is) return;
  std::string who, why;
  std::getline(is, who);
  std::getline(is, why);
  previous_ = "the previous eicald (" + who + ") did not stop cleanly: " +
              (why.empty() ? std::string("no reason recorded (killed, crashed, or the power was lost)") : why);
}

void StopRecord::running(const std::string& why) {
  std::lock_guard lk(mu_);
  try {
    drivers::write_text_atomic(file_,
                               "pid " + std::to_string(::getpid()) + ", started " + started_ + "\n" + why + "\n");
  } catch (const std::exception& e) {
    log(LogLevel::warning, "state file: %s", e.what());
  }
}

void StopRecord::stopped_cleanly() {
  std::lock_guard lk(mu_);
  std::error_code ec;
  std::filesystem::remove(file_, ec);
}

}  // namespace eical::daemon
