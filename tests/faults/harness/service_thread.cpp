#include "tests/faults/harness/service_thread.hpp"

#include "drivers/dds/domain_claim.hpp"

namespace eical::faults {

daemon::DaemonConfig base_config(const std::filesystem::path& recording_dir) {
  daemon::DaemonConfig c;
  c.source.pacing = "free_running";
  c.source.sim_repeats = 2;
  c.source.sim_repeat_program = true;
  c.source.sim_idle_s = 0.2;
  c.source.retry_s = 0.2;
  c.triggers.inputs = {"frame"};
  c.dds.domain_id = drivers::dds::claim_free_domain();
  c.dds.config_uri = "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml";
  c.recording.dir = recording_dir;
  c.recording.gzip = false;
  c.realtime.sched_fifo_priority = 0;
  c.realtime.mlockall = false;
  c.limits.max_measurement_s = 30.0;
  c.dds.status_rate_hz = 20.0;  // the cases time recoveries on Status: 50 ms resolution
  return c;
}

ServiceThread::ServiceThread(daemon::DaemonConfig config)
    : thread_([this, c = std::move(config)] {
        try {
          daemon::Service(c).run(stop_, [this](const daemon::ServiceStatus& s) {
            std::lock_guard lk(mu_);
            last_ = s;
            if (watch_ && watch_(s)) watched_ = true;
          });
        } catch (const std::exception& e) {
          std::lock_guard lk(mu_);
          error_ = e.what();
        }
        finished_.store(true);
      }) {}

ServiceThread::~ServiceThread() { stop(); }

void ServiceThread::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

daemon::ServiceStatus ServiceThread::last() const {
  std::lock_guard lk(mu_);
  return last_;
}

std::optional<std::string> ServiceThread::error() const {
  std::lock_guard lk(mu_);
  return error_;
}

bool ServiceThread::wait_for(const std::function<bool(const daemon::ServiceStatus&)>& want,
                             std::chrono::milliseconds timeout) const {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (want(last())) return true;
    if (finished_.load()) return want(last());
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

void ServiceThread::watch(std::function<bool(const daemon::ServiceStatus&)> condition) {
  std::lock_guard lk(mu_);
  watch_ = std::move(condition);
  watched_ = false;
}

bool ServiceThread::seen() const {
  std::lock_guard lk(mu_);
  return watched_;
}

}  // namespace eical::faults
