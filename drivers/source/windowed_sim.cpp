#include "drivers/source/windowed_sim.hpp"

#include "drivers/source/source.hpp"
#include "sim/nc/sampled_set_point.hpp"
#include "sim/simulate.hpp"

#include <algorithm>
#include <cmath>

namespace eical::drivers {
namespace {

// What the windows cannot carry across a block boundary, by scenario effect name.
std::string stateful_effects(const sim::Scenario& sc, double history_s) {
  std::string out;
  auto add = [&](const std::string& what) { out += (out.empty() ? "" : ", ") + what; };
  for (int s = 0; s < 2; ++s) {
    const auto& t = sc.truth[s];
    const std::string who = s == 0 ? "table" : "head";
    if (t.bias_rw_ug_per_rts != 0.0) add(who + " bias random walk");
    if (t.bias_step_ug != 0.0) add(who + " bias steps");
    if (t.bias_drift_ug_per_s != 0.0) add(who + " bias drift");
    if (t.temperature.rise_c != 0.0) add(who + " case temperature rise");
  }
  if (sc.common_vibration.on()) add("common vibration");
  if (sc.differential_vibration.gain != Eigen::Vector3d::Zero()) add("differential vibration");
  for (int a = 0; a < 3; ++a) {
    const char axis = "xyz"[a];
    if (sc.machine.stick_slip[a].amp_um != 0.0) add(std::string("stick-slip on ") + axis);
    if (sc.machine.spike[a].amp_um != 0.0 && 12.0 * sc.machine.spike[a].tau_ms * 1e-3 > history_s)
      add(std::string("reversal spike on ") + axis + " (decays over 12 tau, longer than history)");
    const auto& sv = sc.machine.servo[a];
    // The loop forgets the window's start as exp(−Kv t): 8/Kv leaves 3e-4 of it.
    if (sv.kv_per_s > 0.0 && sv.kv_per_s * history_s < 8.0)
      add(std::string("servo on ") + axis + " slower than the history (needs history >= 8/Kv)");
  }
  return out;
}

}  // namespace

WindowedSim::WindowedSim(sim::Scenario scenario, WindowedSimOptions options)
    : scenario_(std::move(scenario)), options_(options) {
  const double fs = scenario_.meta.acquisition.fs_hz;
  const double r = fs / options_.servo_rate_hz;
  if (!(options_.servo_rate_hz > 0.0) || r < 1.0 || std::abs(r - std::round(r)) > 1e-9)
    throw SourceError("linuxcnc: fs_hz " + std::to_string(fs) + " is not a whole multiple of the servo rate " +
                      std::to_string(options_.servo_rate_hz) + " Hz");
  ratio_ = static_cast<int>(std::lround(r));
  if (options_.block_cycles < 10) throw SourceError("linuxcnc: block must be at least 10 servo cycles");
  if (options_.prefix_cycles < 12) throw SourceError("linuxcnc: the approach prefix needs at least 12 servo cycles");
  const std::string bad =
      stateful_effects(scenario_, static_cast<double>(options_.history_cycles) / options_.servo_rate_hz);
  if (!bad.empty())
    throw SourceError("linuxcnc: the block-wise simulation cannot continue these scenario effects across blocks: " +
                      bad);
  hist_.reserve(options_.history_cycles + 2 * (options_.block_cycles + options_.lookahead_cycles));
  filled_.reserve(hist_.capacity());
  cmd_.reserve(hist_.capacity());
  window_.reserve(options_.prefix_cycles + hist_.capacity());
}

void WindowedSim::push(const Eigen::Vector3d& drive_mm, const Eigen::Vector3d& cmd_mm, bool filled) {
  hist_.push_back(drive_mm);
  cmd_.push_back(cmd_mm);
  filled_.push_back(filled ? 1 : 0);
  ++pending_;
}

std::size_t WindowedSim::simulate_block(std::span<dsp::Frame> out, bool flush) {
  const std::size_t block = flush ? (pending_ > 0 ? pending_ : 0) : options_.block_cycles;
  if (block == 0 || (!flush && !block_ready()) || hist_.size() < 2) return 0;
  const std::size_t n_hist = hist_.size() - pending_;  // already emitted cycles kept as history
  const std::size_t lookahead = flush ? 0 : pending_ - block;

  // Prefix: hold short of the first position, then a smooth approach in the last direction.
  const Eigen::Vector3d p0 = hist_.front();
  Eigen::Vector3d approach;
  for (int a = 0; a < 3; ++a) approach[a] = dir_[a] * (scenario_.machine.backlash_um[a] * 1e-3 + 1e-3);
  window_.clear();
  const std::size_t np = options_.prefix_cycles, hold = np / 6, ramp = np / 3;
  for (std::size_t k = 0; k < np; ++k) {
    const double u = k < hold ? 0.0 : std::min(1.0, static_cast<double>(k - hold + 1) / static_cast<double>(ramp));
    const double s = u * u * (3.0 - 2.0 * u);
    window_.push_back(p0 - approach * (1.0 - s));
  }
  window_.insert(window_.end(), hist_.begin(), hist_.end());

  sim::Scenario sc = scenario_;
  sc.seed = scenario_.seed + blocks_;  // fresh noise in every window
  const sim::nc::SampledSetPoint sp(window_, options_.servo_rate_hz, {});
  const dsp::Run run = sim::simulate(sc, sp);

  // Frames after the last emitted cycle up to the block's last cycle. Cycle j of the
  // window sits on frame j·ratio.
  const std::size_t first_cycle = np + n_hist;  // first cycle of the block in window_
  const std::size_t last_cycle = first_cycle + block - 1;
  const std::size_t r = static_cast<std::size_t>(ratio_);
  std::size_t from = (first_cycle - 1) * r + 1, to = last_cycle * r;  // inclusive
  std::int64_t index = (emitted_cycles_ - 1) * ratio_ + 1;
  if (emitted_cycles_ == 0) from = first_cycle * r, index = 0;  // the stream's first frame is its first cycle
  std::size_t n = 0;
  for (std::size_t i = from; i <= to && i < run.frames.size() && n < out.size(); ++i, ++n) {
    dsp::Frame f = run.frames[i];
    f.sample_index = index + static_cast<std::int64_t>(n);
    const std::size_t cycle = (i + r - 1) / r - np;  // the cycle this frame leads up to
    if (cycle < filled_.size() && filled_[cycle]) f.flags |= dsp::frame_flag::cmd_missing;
    const std::size_t c0 = i / r - np, frac = i % r;
    Eigen::Vector3d cmd = cmd_[c0];
    if (frac != 0) cmd += (cmd_[c0 + 1] - cmd_[c0]) * (static_cast<double>(frac) / static_cast<double>(r));
    for (int a = 0; a < 3; ++a) f.cmd_mm[a] = cmd[a];
    out[n] = f;
  }
  emitted_cycles_ += static_cast<std::int64_t>(block);
  pending_ = lookahead;
  ++blocks_;

  // Keep `history_cycles` emitted cycles; note the direction of what leaves the window.
  const std::size_t keep = options_.history_cycles + pending_;
  if (hist_.size() > keep) {
    const std::size_t drop = hist_.size() - keep;
    for (std::size_t k = 0; k < drop; ++k)
      for (int a = 0; a < 3; ++a) {
        const double d = hist_[k + 1][a] - hist_[k][a];
        if (std::abs(d) > 1e-9) dir_[a] = d > 0 ? 1 : -1;
      }
    hist_.erase(hist_.begin(), hist_.begin() + static_cast<std::ptrdiff_t>(drop));
    filled_.erase(filled_.begin(), filled_.begin() + static_cast<std::ptrdiff_t>(drop));
    cmd_.erase(cmd_.begin(), cmd_.begin() + static_cast<std::ptrdiff_t>(drop));
  }
  return n;
}

}  // namespace eical::drivers
