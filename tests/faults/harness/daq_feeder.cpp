#include "tests/faults/harness/daq_feeder.hpp"

#include "drivers/usb_daq/frame_encoder.hpp"
#include "sim/scenario.hpp"
#include "sim/simulate.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <csignal>

namespace eical::faults {
namespace {

using Clock = std::chrono::steady_clock;

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

dsp::Frame as_daq(dsp::Frame f) {
  for (double& c : f.cmd_mm) c = 0.0;  // a DAQ knows no set-point
  for (double& r : f.ref_mm) r = std::nan("");
  return f;
}

const dsp::Run& circle_run() {
  static const dsp::Run run = sim::simulate(sim::circle_scenario(10.0, 2500.0, 2, "ccw", 3));
  return run;
}

}  // namespace

std::vector<dsp::Frame> daq_rest(double seconds) {
  dsp::Frame f = as_daq(circle_run().frames.front());
  f.trigger = 0;
  return std::vector<dsp::Frame>(static_cast<std::size_t>(seconds * circle_run().fs_hz()), f);
}

std::vector<dsp::Frame> daq_circle(double rest_s) {
  std::vector<dsp::Frame> out = daq_rest(rest_s);
  for (const auto& f : circle_run().frames) out.push_back(as_daq(f));
  return out;
}

DaqFeeder::DaqFeeder(std::filesystem::path fifo, std::vector<FeedPhase> phases, double fs_hz)
    : fifo_(std::move(fifo)), phases_(std::move(phases)), fs_hz_(fs_hz), started_ns_(phases_.size() + 1) {
  std::signal(SIGPIPE, SIG_IGN);  // eicald closes the pipe when it reopens: EPIPE, not death
  thread_ = std::thread([this] { run(); });
}

DaqFeeder::~DaqFeeder() {
  stop_ = true;
  thread_.join();
}

Clock::time_point DaqFeeder::phase_started(std::size_t k) const {
  return Clock::time_point(std::chrono::nanoseconds(started_ns_[std::min(k, phases_.size())].load()));
}

// Writes everything; on EPIPE (eicald reopened its end) opens the pipe again and resends
// this packet batch: a DAQ bridge reconnecting.
bool DaqFeeder::write_all(int& fd, const std::vector<std::uint8_t>& bytes) {
  std::size_t at = 0;
  while (at < bytes.size() && !stop_) {
    const ssize_t n = fd >= 0 ? ::write(fd, bytes.data() + at, bytes.size() - at) : -1;
    if (n > 0) {
      at += static_cast<std::size_t>(n);
      continue;
    }
    if (fd >= 0 && errno == EINTR) continue;
    if (fd >= 0) ::close(fd);
    fd = -1;
    at = 0;  // a fresh connection gets whole packets
    for (int i = 0; i < 3000 && fd < 0 && !stop_; ++i) {
      fd = ::open(fifo_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);  // fails (ENXIO) until eicald reads
      if (fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (fd < 0) return false;
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  }
  return at == bytes.size();
}

void DaqFeeder::run() {
  int fd = -1;
  drivers::usb_daq::FrameEncoder enc(0, 32);
  std::vector<std::uint8_t> bytes;
  std::int64_t index = 0;
  for (std::size_t p = 0; p < phases_.size() && !stop_; ++p) {
    phase_ = p;
    const std::int64_t t0 = now_ns();
    started_ns_[p] = t0;
    const FeedPhase& ph = phases_[p];
    if (ph.frames.empty()) {
      while (!stop_ && now_ns() - t0 < static_cast<std::int64_t>(ph.silence_s * 1e9))
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      continue;
    }
    std::vector<dsp::Frame> block;
    for (std::size_t i = 0; i < ph.frames.size() && !stop_; i += 32) {
      const std::size_t n = std::min<std::size_t>(32, ph.frames.size() - i);
      block.assign(ph.frames.begin() + static_cast<std::ptrdiff_t>(i),
                   ph.frames.begin() + static_cast<std::ptrdiff_t>(i + n));
      for (auto& f : block) f.sample_index = index++;
      // A packet leaves when its last sample is taken (at `pace` times the real rate).
      const auto due = t0 + static_cast<std::int64_t>(static_cast<double>(i + n) * 1e9 / (fs_hz_ * ph.pace));
      if (const auto wait = due - now_ns(); wait > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(wait));
      bytes.clear();
      enc.encode(block, bytes);
      if (!write_all(fd, bytes)) break;
    }
  }
  phase_ = phases_.size();
  started_ns_[phases_.size()] = now_ns();
  if (fd >= 0) ::close(fd);
}

}  // namespace eical::faults
