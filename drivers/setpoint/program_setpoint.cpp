#include "drivers/setpoint/program_setpoint.hpp"

#include "dsp/align/accel_lag.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/frame.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

namespace eical::drivers {
namespace {

// Motion blocks: moves that follow each other without a rest are one block.
std::vector<std::pair<double, double>> motion_blocks(const sim::nc::Trajectory& tr) {
  std::vector<std::pair<double, double>> blocks;
  for (const auto& [a, b] : tr.move_spans_s()) {
    if (!blocks.empty() && a - blocks.back().second < 1e-6)
      blocks.back().second = b;
    else
      blocks.emplace_back(a, b);
  }
  return blocks;
}

struct Mark {
  double t_s;  // program time, or DAQ time of the recorded mark
  int code;
};

using MarkPairs = std::vector<std::pair<Mark, Mark>>;  // (program, recorded)

// The marks, in order; the first M101 of each is the anchor. The pairs that agree from it,
// and how many each side has (a flag when they differ).
MarkPairs match_marks(const sim::nc::Trajectory& tr, const dsp::Run& run, double fs, ProgramAlignment& out) {
  std::vector<Mark> prog, rec;
  for (const auto& t : tr.triggers())
    if (dsp::trigger::is_nc_trigger(t.code)) prog.push_back({t.t_s, t.code});
  for (const auto& f : run.frames)
    if (dsp::trigger::is_nc_trigger(f.trigger)) rec.push_back({static_cast<double>(f.sample_index) / fs, f.trigger});
  const auto p101 =
      std::find_if(prog.begin(), prog.end(), [](const Mark& m) { return m.code == dsp::trigger::program_start; });
  const auto r101 =
      std::find_if(rec.begin(), rec.end(), [](const Mark& m) { return m.code == dsp::trigger::program_start; });
  if (p101 == prog.end()) throw dsp::InputError("program set-point: the program has no M101");
  if (r101 == rec.end()) throw dsp::InputError("program set-point: the recording has no M101 mark");
  MarkPairs pairs;
  for (auto p = p101, r = r101; p != prog.end() && r != rec.end() && p->code == r->code; ++p, ++r)
    pairs.emplace_back(*p, *r);
  out.marks_program = static_cast<int>(prog.end() - p101);
  out.marks_recorded = static_cast<int>(rec.end() - r101);
  out.marks_matched = static_cast<int>(pairs.size());
  if (out.marks_matched != out.marks_program || out.marks_matched != out.marks_recorded)
    out.flags.push_back({dsp::FlagCode::setpoint,
                         {},
                         "the recording's marks (" + std::to_string(out.marks_recorded) +
                             " from M101) and the program's (" + std::to_string(out.marks_program) +
                             ") agree for the first " + std::to_string(out.marks_matched) +
                             " only; the rest is aligned by the motion alone"});
  return pairs;
}

// DAQ time − program time by the last matched mark at or before program_t (the first before any).
double marks_offset(const MarkPairs& pairs, double program_t) {
  double off = pairs.front().second.t_s - pairs.front().first.t_s;
  for (const auto& [p, r] : pairs)
    if (p.t_s <= program_t + 1e-9) off = r.t_s - p.t_s;
  return off;
}

// A motion block [s, e] (program time): the marks' offset, refined by cross-correlating
// the block's commanded acceleration with the measured one in a window about where the
// marks put it.
BlockAlignment align_block(double s, double e, const MarkPairs& pairs, const sim::nc::Trajectory& tr,
                           const dsp::Run& run, const std::vector<Eigen::Vector3d>& meas,
                           const ProgramSetPointOptions& o) {
  const double fs = run.meta.acquisition.fs_hz;
  const std::int64_t first_index = run.frames.front().sample_index;
  const std::size_t n = run.frames.size();
  BlockAlignment b;
  b.program_start_s = s, b.program_end_s = e;
  b.marks_offset_s = b.offset_s = marks_offset(pairs, s);
  // The window on the DAQ clock around where the marks put the block.
  const double t0 = s + b.offset_s - o.max_lag_s - 0.05, t1 = e + b.offset_s + o.max_lag_s + 0.05;
  const auto i0 = static_cast<std::size_t>(
      std::clamp<double>(std::floor(t0 * fs) - static_cast<double>(first_index), 0.0, static_cast<double>(n)));
  const auto i1 = static_cast<std::size_t>(
      std::clamp<double>(std::ceil(t1 * fs) - static_cast<double>(first_index), 0.0, static_cast<double>(n)));
  if (i1 <= i0 + 100) return b;
  std::vector<Eigen::Vector3d> cmd_acc(i1 - i0),
      meas_w(meas.begin() + static_cast<std::ptrdiff_t>(i0), meas.begin() + static_cast<std::ptrdiff_t>(i1));
  for (std::size_t i = i0; i < i1; ++i) {
    const double t = static_cast<double>(first_index + static_cast<std::int64_t>(i)) / fs - b.offset_s;
    // Only this block's motion: the neighbours' would correlate with their own lag.
    cmd_acc[i - i0] = t >= s && t <= e ? Eigen::Vector3d(tr.at(t).acc_mm_s2 * 1e-3) : Eigen::Vector3d::Zero();
  }
  dsp::align::LagOptions lo;
  lo.min_lag_s = -o.max_lag_s, lo.max_lag_s = o.max_lag_s;
  const auto lag = dsp::align::estimate_lag(cmd_acc, meas_w, fs, lo);
  b.correlation = lag.correlation;
  if (lag.valid && lag.correlation > 0.5) b.offset_s += lag.lag_s, b.correlated = true;
  return b;
}

// A flag for each pair of blocks that overlap on the DAQ clock after the alignment.
void flag_overlaps(ProgramAlignment& out) {
  for (std::size_t k = 1; k < out.blocks.size(); ++k) {
    const auto& a = out.blocks[k - 1];
    const auto& b = out.blocks[k];
    if (b.program_start_s + b.offset_s < a.program_end_s + a.offset_s - 1e-4)
      out.flags.push_back({dsp::FlagCode::setpoint,
                           {},
                           "motion blocks " + std::to_string(k) + " and " + std::to_string(k + 1) +
                               " overlap on the DAQ clock after the alignment (offsets " + std::to_string(a.offset_s) +
                               " s, " + std::to_string(b.offset_s) + " s)"});
  }
}

// The program time at DAQ time tau: inside a block by its offset, at rest in between.
double program_time(const std::vector<BlockAlignment>& blocks, const MarkPairs& pairs, double tau) {
  if (blocks.empty()) return tau - marks_offset(pairs, 0.0);
  const BlockAlignment* cur = nullptr;
  for (const auto& b : blocks)
    if (b.program_start_s + b.offset_s <= tau) cur = &b;
  if (!cur) return std::min(tau - blocks.front().offset_s, blocks.front().program_start_s);
  return std::min(tau - cur->offset_s, cur->program_end_s);  // after the block: resting at its end
}

// The set-point into every frame; returns it.
std::vector<Eigen::Vector3d> write_setpoint(dsp::Run& run, const sim::nc::Trajectory& tr,
                                            const std::vector<BlockAlignment>& blocks, const MarkPairs& pairs) {
  const double fs = run.meta.acquisition.fs_hz;
  const std::size_t n = run.frames.size();
  std::vector<Eigen::Vector3d> cmd_mm(n);
  for (std::size_t i = 0; i < n; ++i) {
    dsp::Frame& f = run.frames[i];
    const Eigen::Vector3d p = tr.at(program_time(blocks, pairs, static_cast<double>(f.sample_index) / fs)).pos_mm;
    for (int a = 0; a < 3; ++a) f.cmd_mm[a] = p[a];
    f.flags &= ~dsp::frame_flag::cmd_missing;
    cmd_mm[i] = p;
  }
  return cmd_mm;
}

// The residual of the whole set-point against the measured motion (a flag when poor).
void check_residual(const std::vector<Eigen::Vector3d>& cmd_mm, const std::vector<Eigen::Vector3d>& meas, double fs,
                    const ProgramSetPointOptions& o, ProgramAlignment& out) {
  const auto lag = dsp::align::estimate_lag(dsp::align::setpoint_accel_mps2(cmd_mm, fs), meas, fs);
  out.lag_s = lag.lag_s, out.correlation = lag.correlation, out.residual_ratio = lag.residual_ratio;
  if (!lag.valid || lag.residual_ratio > o.poor_residual_ratio)
    out.flags.push_back({dsp::FlagCode::setpoint,
                         {},
                         "the program's set-point does not match the measured motion (residual " +
                             std::to_string(static_cast<int>(std::lround(lag.residual_ratio * 100.0))) +
                             " % of the commanded acceleration, correlation " + std::to_string(lag.correlation) +
                             "): another program, a feed override or other machine limits?"});
}

}  // namespace

std::string with_mcode_stops(const std::string& gcode) {
  std::istringstream in(gcode);
  std::string out, line;
  while (std::getline(in, line)) {
    out += line;
    out += '\n';
    // The code part of the line: comments in parentheses and after ';' do not count.
    std::string code;
    int depth = 0;
    for (char c : line) {
      if (c == ';' && depth == 0) break;
      if (c == '(')
        ++depth;
      else if (c == ')' && depth > 0)
        --depth;
      else if (depth == 0 && c != ' ' && c != '\t')
        code += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    }
    for (std::size_t p = code.find('M'); p != std::string::npos; p = code.find('M', p + 1)) {
      std::size_t q = p + 1;
      while (q < code.size() && (std::isdigit(static_cast<unsigned char>(code[q])) || code[q] == '.')) ++q;
      if (q == p + 1) continue;
      const double m = std::atof(code.substr(p + 1, q - p - 1).c_str());
      if (m == std::floor(m) && m < 1e6 && dsp::trigger::is_nc_trigger(static_cast<std::int32_t>(m))) {
        out += "G4 P0\n";
        break;
      }
    }
  }
  return out;
}

ProgramAlignment apply_program_setpoint(dsp::Run& run, const dsp::Program& program,
                                        const ProgramSetPointOptions& options) {
  ProgramAlignment out;
  const double fs = run.meta.acquisition.fs_hz;
  const std::string gcode = options.mcode_stops ? with_mcode_stops(program.gcode) : program.gcode;
  const sim::nc::Trajectory tr = sim::nc::interpolate_gcode(gcode, "program", options.limits);
  if (run.frames.empty()) throw dsp::InputError("program set-point: the recording has no frames");
  // 1 Marks, in order; the first M101 of each is the anchor.
  const MarkPairs pairs = match_marks(tr, run, fs, out);
  // 2 Each motion block: the marks' offset, refined by cross-correlation.
  const std::vector<Eigen::Vector3d> meas = dsp::align::measured_accel_mps2(run);
  for (const auto& [s, e] : motion_blocks(tr)) out.blocks.push_back(align_block(s, e, pairs, tr, run, meas, options));
  if (out.blocks.empty())
    out.flags.push_back(
        {dsp::FlagCode::setpoint, {}, "the program does not move; its set-point is its start position"});
  // 3 The set-point on the DAQ clock: inside a block by its offset, at rest in between.
  flag_overlaps(out);
  const std::vector<Eigen::Vector3d> cmd_mm = write_setpoint(run, tr, out.blocks, pairs);
  // 4 The residual of the whole set-point against the measured motion.
  check_residual(cmd_mm, meas, fs, options, out);
  run.meta.program = program;
  return out;
}

}  // namespace eical::drivers
