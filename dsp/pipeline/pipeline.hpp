#pragma once
// The DSP pipeline: frames → relative position head − table in machine axes.
// Causal per-sample step() (live, in eicald's DSP thread) and an offline finish() that
// adds what needs the whole measurement (ZUPT at the rest after the motion). The same
// code runs live and offline, in double or in Q-format integers (Arithmetic).
//
//   1 static compensation per sensor (StaticComp / FixedStaticComp): (6-16) with the
//     frames' case temperature, (6-17) and cross terms, (6-18) into machine axes
//   2 bias from the rest window M101 → first set-point motion (per sensor: it removes
//     gravity, the data-sheet bias error and the machine's tilt in one go)
//   3 Coriolis (3-6) with each sensor's velocity fed back from its first integrator
//   4 trapezoid integration of each sensor from the start of the motion with the dynamic
//     compensation of the PT2 at the chosen level (SensorIntegrator / FixedIntegrator);
//     relative = head − table (3-1), starting at the set-point there
//   5 supports and fusion (SupportStage): ZUPT at every standstill the automatic detector
//     finds, NBS for held axes, CUPT from the PSD strips; the forward Kalman filter live,
//     the same filter again plus the RTS smoother in finish()
//   6 finish(): the DAQ delay removed by re-indexing the trace (exact for any signal; the
//     live estimate is predicted over it instead)
#include "dsp/core/flag.hpp"
#include "dsp/core/frame.hpp"
#include "dsp/core/run_meta.hpp"
#include "dsp/pipeline/coriolis.hpp"
#include "dsp/pipeline/dynamic_comp.hpp"
#include "dsp/pipeline/fixed_integrator.hpp"
#include "dsp/pipeline/fixed_static_comp.hpp"
#include "dsp/pipeline/rest_noise.hpp"
#include "dsp/pipeline/sensor_integrator.hpp"
#include "dsp/pipeline/static_comp.hpp"
#include "dsp/pipeline/support_stage.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace eical::dsp {

// How much of each measurement the pipeline keeps.
enum class TraceKeeping {
  whole,   // the trace in memory (Measurement), up to capacity_samples; finish() smooths it
  track,   // only what the smoother reads (a few bytes per sample); finish_track() smooths
           // it, and the streamed analysis (dsp/stream) replays the frames for the trace
  replay,  // no supports: each stored sample goes to PipelineConfig::sink (that replay)
  live,    // the live estimate only (eicald's DSP thread): nothing per sample is kept
};

// A trace sample as integrated: before the supports' corrections and the delay alignment.
struct TraceSample {
  std::int64_t sample_index = 0;
  std::int32_t trigger = 0;        // the frame's NC trigger code (0: none)
  float temp_c[2] = {0.0F, 0.0F};  // the frame's case temperatures (table, head)
  std::uint32_t frame_flags = 0;   // the frame's frame_flag bits
  Eigen::Vector3d pos_mm = Eigen::Vector3d::Zero(), vel_mm_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d cmd_mm = Eigen::Vector3d::Zero(), ref_mm = Eigen::Vector3d::Zero();
};

// Receives every stored trace sample (TraceKeeping::track and replay), in order.
class TraceSink {
 public:
  virtual ~TraceSink() = default;
  virtual void sample(const TraceSample& s) = 0;
};

// double: the reference path. fixed_q: static compensation, bias and integrators in
// Q-format integers (fixed_point.hpp); supports DynamicComp none and position_level
// (two_stage) and no Coriolis term (the constructor says so otherwise).
enum class Arithmetic { double_precision, fixed_q };

struct PipelineConfig {
  Acquisition acquisition;
  Site site;
  SensorSpec sensors[2];
  bool sensor_present[2] = {true, true};  // an absent sensor reads zero (single-sensor runs)
  StaticCalibration calibration[2];       // cross terms and mounting (6-4, 6-18); default: data sheet
  std::vector<PsdSpec> psd;               // the run's PSD strips (CUPT)
  std::size_t capacity_samples = 0;       // longest measurement the trace can hold
  // Of the supports' per-sample records, how much to reserve up front (SIZE_MAX: the capacity).
  std::size_t reserve_samples = SIZE_MAX;
  DynamicComp dynamic = DynamicComp::two_stage;
  StaticCompOptions static_comp;  // temperature (6-16) and nonlinearity (6-17) on/off
  // (3-6) Earth-rate Coriolis from [site]. Off by default: the simulator's built-in runs
  // leave it out (sc.coriolis), and correcting a term that is absent adds it. Real runs: on.
  bool coriolis = false;
  Arithmetic arithmetic = Arithmetic::double_precision;
  bool zupt = true;
  // NBS (Bild 7-8): an axis whose set-point does not move during a move is held still —
  // its integrated drift there is removed (and so is any real motion of it: straightness of
  // the moving axis is no longer seen). For rectangles and other axis-parallel programs.
  bool nbs = false;
  bool cupt = true;  // PSD strips as position fixes (when the run has [[psd]])
  // The strips set the frame: the start is anchored to the set-point only within the
  // scale's share of the way to the nearest strip (fusion::ErrorModel::start_frame_um). For
  // tests whose figures are differences (ISO 230-2): there the set-point at the start is
  // no reference, and the first run must meet the strip like the others. pipeline_config()
  // sets it from the program.
  bool strips_set_the_frame = false;
  bool smooth = true;          // RTS pass in finish() (off: the forward filter's causal result)
  fusion::ErrorModel fusion;   // pipeline_config() sets the noise from the sensors' data sheet
  bool keep_raw = false;       // Measurement::raw (identification, explain; offline only)
  bool keep_schedule = false;  // Measurement::raw.schedule alone (the uncertainty of the figures)
  TraceKeeping trace = TraceKeeping::whole;
  TraceSink* sink = nullptr;  // track and replay: where the stored samples go (may be none)
  supports::StandstillOptions standstill;
  // Offline work side by side: the smoother's backward pass (fusion::SmootherSettings).
  // Empty: in order, on the caller's thread (the live pipeline).
  ParallelFor parallel;
};

PipelineConfig pipeline_config(const RunMeta& meta, std::size_t capacity_samples);

// Why a result is degraded (bit set) — in Measurement::flags as the FlagCode of the same
// number (dsp/core/flag.hpp).
namespace quality_flag {
inline constexpr std::uint32_t accel_missing = 1u << 0;
inline constexpr std::uint32_t accel_saturated = 1u << 1;
inline constexpr std::uint32_t frames_lost = 1u << 2;
inline constexpr std::uint32_t not_finite = 1u << 3;
inline constexpr std::uint32_t no_start_trigger = 1u << 4;
inline constexpr std::uint32_t no_motion = 1u << 5;
inline constexpr std::uint32_t short_rest_window = 1u << 6;
inline constexpr std::uint32_t no_zupt_window = 1u << 7;
inline constexpr std::uint32_t capacity_exceeded = 1u << 8;
inline constexpr std::uint32_t no_end_trigger = 1u << 9;
inline constexpr std::uint32_t fixed_saturated = 1u << 10;
inline constexpr std::uint32_t supports_diverged = 1u << 11;
inline constexpr std::uint32_t psd_disagrees = 1u << 12;
}  // namespace quality_flag

std::vector<Flag> quality_flags(std::uint32_t bits);

struct LiveEstimate {
  std::int64_t sample_index = -1;
  bool integrating = false;
  Eigen::Vector3d pos_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d vel_mm_s = Eigen::Vector3d::Zero();
};

struct TriggerMark {
  std::int64_t sample_index;
  int code;
};

// The trace in the sensors' time base before supports and delay alignment, with what went
// into it (PipelineConfig::keep_raw): what identification and explain fit their models to.
struct RawTrace {
  std::vector<Eigen::Vector3d> pos_mm, vel_mm_s;       // integrated relative motion (dynamic comp applied)
  std::vector<Eigen::Vector3d> table_mps2, head_mps2;  // each sensor, bias-free, machine axes
  std::vector<Eigen::Vector3d> rest_rel_mps2;          // head − table in the rest before the motion (incl. bias)
  fusion::SupportSchedule schedule;                    // standstills, held axes, PSD fixes (µm)
  Eigen::Vector3d rest_bias_mps2[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};  // table, head; incl. gravity
  [[nodiscard]] bool empty() const noexcept { return pos_mm.empty(); }
};

struct Measurement {
  double fs_hz = 0.0;
  std::vector<std::int64_t> sample_index;  // from the start of the motion to the end
  std::vector<Eigen::Vector3d> pos_mm, vel_mm_s, cmd_mm, ref_mm;
  std::vector<TriggerMark> triggers;   // all triggers seen, on the DAQ clock
  std::int64_t start_index = -1;       // first sample of the motion (integration start)
  std::int64_t motion_end_index = -1;  // last sample where the set-point moved
  bool degraded = false;
  std::vector<Flag> flags;
  Eigen::Vector3d rest_bias_rel_mps2 = Eigen::Vector3d::Zero();        // head − table, incl. gravity
  Eigen::Vector3d zupt_velocity_error_mm_s = Eigen::Vector3d::Zero();  // integrated velocity at the last standstill
  std::size_t rest_window_samples = 0, zupt_window_samples = 0;
  std::vector<Eigen::Vector3d> sigma_um;  // posterior σ of pos_mm per axis (after finish())
  // Long runs analysed as they stream (dsp/stream) keep every decimation-th sample of the
  // trace in the arrays above (and its last); the figures are computed from every sample.
  std::size_t decimation = 1;
  std::size_t trace_samples = 0;  // samples of the whole trace
  // Over the whole trace: the largest posterior σ per axis among samples whose σ is finite,
  // and the largest of any axis (NaN ignored) — what the result and the integration check quote.
  Eigen::Vector3d sigma_max_um = Eigen::Vector3d::Zero();
  double sigma_peak_um = 0.0;
  // Streamed runs (no frames kept): each sample's case temperatures, table and head (the
  // last finite ones), what the uncertainty reads from the frames otherwise.
  std::vector<Eigen::Vector2d> temp_c;
  SupportSummary supports;
  // The relative acceleration's white noise measured where the machine stood still (the
  // rest before the motion and every settled stop of the set-point): rest_noise.hpp.
  RestNoise rest_noise;
  RawTrace raw;  // only with PipelineConfig::keep_raw
};

// Folds σ of trace samples into Measurement::sigma_max_um and sigma_peak_um.
void note_sigma(Measurement& m, const std::vector<Eigen::Vector3d>& sigma_um);

class Pipeline {
 public:
  explicit Pipeline(const PipelineConfig& config);

  void step(const Frame& frame) noexcept;
  [[nodiscard]] const LiveEstimate& live() const noexcept { return live_; }
  [[nodiscard]] std::uint32_t quality_bits() const noexcept { return quality_; }
  // Offline completion (allocates; not for the DSP thread's per-sample path). Call once.
  Measurement finish();
  // TraceKeeping::track: the measurement without its per-sample arrays, and the smoothed
  // corrections to apply to the replayed trace (none when nothing moved).
  struct Tracked {
    Measurement measurement;       // every field but the per-sample arrays
    std::size_t samples = 0;       // trace samples (those a replay stores)
    std::int64_t first_index = 0;  // sample index of the trace's first sample
    std::unique_ptr<SmoothedCorrection> correction;
    double delay_samples = 0.0;  // to re-index by (0: none, DynamicComp::none)
  };
  // sink: receives the smoothed errors as they are made (to keep them, not recompute them).
  Tracked finish_track(fusion::SegmentSink* sink = nullptr);
  // Back to waiting for M101, keeping the reserved trace storage (for the live path,
  // which discards its causal estimate at the end of each measurement).
  void reset() noexcept;

 private:
  enum class Phase { wait_start, rest, moving };
  void apply_supports(Measurement& m);
  // Rest-window bookkeeping after the supports: ZUPT window, the velocity ZUPT takes out,
  // whether a rest follows the motion.
  void rest_windows_done(Measurement& m, const Eigen::Vector3d& last_rest_velocity_mm_s);
  [[nodiscard]] bool runs_supports() const noexcept { return config_.trace != TraceKeeping::replay; }
  void align_delay(Measurement& m) const;
  void store(const Frame& f, const Eigen::Vector3d& pos_mm, const Eigen::Vector3d& vel_mm_s) noexcept;
  void compensate(const Frame& f) noexcept;
  void start_motion() noexcept;
  [[nodiscard]] Eigen::Vector3d bias_free(int sensor) const noexcept;
  void integrate(std::int64_t k_samples, double dt_s, Eigen::Vector3d& pos_m, Eigen::Vector3d& vel_mps) noexcept;
  // One frame's step: its time step, validity and set-point, with the triggers noted.
  struct FrameStep {
    std::int64_t k_samples = 1;  // samples since the previous frame (lost frames: more)
    double dt_s = 0.0;
    bool accel_valid = false;
    Eigen::Vector3d cmd_mm = Eigen::Vector3d::Zero();
    bool cmd_valid = false, cmd_moved = false;
  };
  void note_quality(const Frame& f) noexcept;
  FrameStep advance(const Frame& f) noexcept;
  void rest_sample() noexcept;
  void begin_motion(const Frame& f, const FrameStep& fs) noexcept;
  void moving_sample(const Frame& f, const FrameStep& fs) noexcept;
  // The quiet samples for the noise measurement (a settled stop of the set-point).
  void note_stillness(const Frame& f, const FrameStep& fs) noexcept;
  [[nodiscard]] Eigen::Vector3d relative_acceleration() const noexcept;

  PipelineConfig config_;
  bool fixed_ = false;
  StaticComp comp_[2];
  FixedStaticComp fcomp_[2];
  SensorIntegrator integ_[2];
  FixedIntegrator finteg_[2];
  CoriolisComp coriolis_;
  SupportStage supports_;
  fx::Saturation saturation_;
  double dt_s_;
  double delay_samples_ = 0.0;      // DAQ group delay, removed by re-indexing in finish()
  float temp_c_[2] = {0.0F, 0.0F};  // last valid case temperature
  // This frame's compensated acceleration (double path, m/s²; fixed path, Q40 m/s²).
  Eigen::Vector3d a_[2];
  std::int64_t aq_[2][3] = {};
  std::int64_t last_valid_aq_[2][3] = {};
  fx::Int128 fbias_sum_[2][3] = {};
  std::int64_t fbias_[2][3] = {};
  Eigen::Vector3d rest_hist_[2][3];  // the last three rest samples (derivative history)
  Phase phase_ = Phase::wait_start;
  std::uint32_t quality_ = 0;
  bool saw_start_ = false, saw_end_ = false;
  std::int64_t prev_index_ = -1;
  Eigen::Vector3d prev_cmd_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d last_valid_a_[2];
  // Rest window sums.
  Eigen::Vector3d bias_sum_[2];
  std::size_t bias_n_ = 0;
  Eigen::Vector3d bias_[2];
  Eigen::Vector3d start_pos_mm_ = Eigen::Vector3d::Zero();
  RestNoiseMeter rest_noise_;
  std::int64_t still_since_ = -1;  // sample index of the set-point's last move
  std::int64_t start_index_ = -1, motion_end_index_ = -1;
  LiveEstimate live_;
  Measurement m_;                   // trace storage, reserved in the constructor
  std::size_t stored_ = 0;          // trace samples stored (or sent) in this measurement
  std::int64_t first_stored_ = -1;  // sample index of the first
  std::size_t trigger_capacity_ = 4096;
};

}  // namespace eical::dsp
