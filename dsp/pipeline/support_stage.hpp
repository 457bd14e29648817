#pragma once
// Stage 4 of the pipeline: the supports of the integration (ch. 5, 7.3) and their fusion.
//   ZUPT  at every standstill, found by the automatic detector (standstill_detector.hpp)
//   NBS   an axis whose set-point does not move during a move is held (Bild 7-8)
//   CUPT  every lit sample of a PSD strip is a position fix along its axis (psd_decoder.hpp)
// Live, the forward Kalman filter (fusion/forward_filter.hpp) corrects the estimate per
// sample; offline, finish() runs it again with hindsight (a standstill counts from its
// first quiet sample) and smooths backwards (Rauch–Tung–Striebel) over the same model.
// Everything here works in the sensors' time base — the PSD channels pass the same DAQ
// filter as the accelerometers, so they line up without the delay; the pipeline re-indexes
// the corrected trace onto the set-point's time afterwards.
#include "dsp/core/frame.hpp"
#include "dsp/core/run_meta.hpp"
#include "dsp/core/sample_rate.hpp"
#include "dsp/fusion/bias_steps.hpp"
#include "dsp/fusion/checkpointed_smoother.hpp"
#include "dsp/fusion/forward_filter.hpp"
#include "dsp/fusion/rts_smoother.hpp"
#include "dsp/supports/psd_decoder.hpp"
#include "dsp/supports/standstill_detector.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

namespace eical::dsp {

struct SupportConfig {
  bool zupt = true;
  bool nbs = false;
  bool cupt = true;                   // PSD strips as position fixes, when the run has any
  bool strips_set_the_frame = false;  // PipelineConfig::strips_set_the_frame
  bool smooth = true;                 // offline RTS pass (off: the forward filter's result, as live)
  // Record what the offline smoother reads (the schedule and its compact track); off for
  // the live pipeline, which only needs the forward filter's estimate.
  bool record = true;
  // Record ZUPT σ per sample as a bit (it is 0 or −1): the track of a streamed analysis,
  // a byte and a bit per sample in its first pass instead of five bytes.
  bool compact = false;
  fusion::ErrorModel model;
  supports::StandstillOptions standstill;
  ParallelFor parallel;  // the smoother's (fusion::SmootherSettings::parallel)
};

// A standstill found by the detector: where, and each sensor's mean acceleration there
// (machine axes, after the first rest window's bias: the bias drift between rests).
struct RestWindow {
  std::int64_t first_index = 0, last_index = 0;  // sample indices, sensor time base
  Eigen::Vector3d table_mps2 = Eigen::Vector3d::Zero(), head_mps2 = Eigen::Vector3d::Zero();
  std::size_t samples = 0;
  bool quiet = true;  // the acceleration confirmed it (false: found by the set-point, machine ringing)
  // Its late part (settled; quiet standstills only): mean relative reading head − table, length.
  Eigen::Vector3d late_rel_mps2 = Eigen::Vector3d::Zero();
  double late_s = 0.0;
};

// What the supports did in one measurement (published with the result).
struct SupportSummary {
  std::array<std::array<fusion::SupportTally, fusion::kSupportKinds>, 3> tally{};  // [axis][zupt|cupt|nbs]
  std::vector<RestWindow> rest_windows;
  std::size_t psd_fixes = 0, psd_fixes_dropped = 0;
  std::size_t resets = 0;      // covariance resets (a standstill the model could not explain)
  bool psd_disagrees = false;  // the PSD readings contradicted the integration: not used
  // Their slopes contradicted the standstills: one position per crossing was fused instead.
  bool psd_crossings_merged = false;
  std::size_t psd_rejected = 0;
  bool smoothed = false;
  bool diverged = false;  // the fusion met values it cannot take: trace left as integrated
  Eigen::Vector3d start_bias_sigma_um_s2 = Eigen::Vector3d::Zero();  // how well the first rest fixed the bias
  std::array<double, 3> start_frame_um{};   // the strips' frame against the start (fusion::ErrorModel)
  std::array<double, 3> scale_state_ppm{};  // the axes whose strips observe the scale (fusion::ErrorModel)
  // Their scale error as the strips showed it, ppm, and its σ (0, 0 on the other axes).
  std::array<double, 3> scale_ppm{}, scale_sigma_ppm{};
  std::array<double, 3> timing_state_us{};  // the axes whose strips observe the timing (fusion::ErrorModel)
  // Their timing error as the strips showed it, µs, and its σ (0, 0 on the other axes).
  std::array<double, 3> timing_us{}, timing_sigma_us{};
  // The bias jump at a move start as the standstills show it, and what the smoother assumed
  // (the measured one, or the model's when there was nothing to measure it on).
  fusion::BiasStepMeasurement bias_step;
  double bias_step_um_s2 = 0.0;
  bool bias_step_from_standstills = false;  // else the model's
};

// One sample of the motion as the supports see it (sensor time base).
struct SupportSample {
  std::size_t k = 0;             // trace index (the motion starts at 0)
  std::int64_t gap_samples = 1;  // samples since the previous one (lost frames)
  bool accel_valid = true;
  Eigen::Vector3d a_table_mps2 = Eigen::Vector3d::Zero(),
                  a_head_mps2 = Eigen::Vector3d::Zero();  // bias-free, machine axes
  Eigen::Vector3d pos_mm = Eigen::Vector3d::Zero(),
                  vel_mm_s = Eigen::Vector3d::Zero();  // the integrated relative motion
  bool cmd_valid = false, cmd_moved = false;
  Eigen::Vector3d cmd_mm = Eigen::Vector3d::Zero();
};

// The offline supports of a measurement without its trace: the smoother over the recorded
// track, from which each segment's corrections are recomputed on demand (TraceKeeping::track).
struct SmoothedCorrection {
  fusion::SupportSchedule schedule;  // as smoothed (CUPT off when the strips disagreed)
  fusion::SmootherTrack track;       // track.schedule points at `schedule`
  std::unique_ptr<fusion::CheckpointedSmoother> smoother;
  bool apply = false;  // false: the fusion diverged, the trace stays as integrated (σ NaN)
  // Trace position of a sample index (the trace's first sample at first_index).
  [[nodiscard]] std::size_t position_of(std::int64_t first_index, std::int64_t sample_index) const noexcept;
  // Sample index of trace position k (the inverse, from the recorded steps).
  [[nodiscard]] std::int64_t sample_index_of(std::int64_t first_index, std::size_t k) const noexcept;
  SmoothedCorrection() = default;
  SmoothedCorrection(const SmoothedCorrection&) = delete;
  SmoothedCorrection& operator=(const SmoothedCorrection&) = delete;
};

// The recorded integrated velocities (mm/s) of trace samples [first, last] that the
// smoother reads (fusion::reads_velocity), summed, and how many.
std::pair<Eigen::Vector3d, std::size_t> support_velocity_sum(const std::vector<std::uint8_t>& flags,
                                                             const std::vector<Eigen::Vector3d>& support_vel_mm_s,
                                                             std::size_t first, std::size_t last);

class SupportStage {
 public:
  SupportStage() = default;
  // Allocates everything the measurement can need (capacity_samples of trace).
  SupportStage(const SupportConfig& config, const Acquisition& acquisition, const std::vector<PsdSpec>& psd,
               double sensor_noise_var_m2ps4, std::size_t capacity_samples, std::size_t reserve_samples = SIZE_MAX);

  void reset() noexcept;
  // Every frame (the PSD noise is learnt at rest too).
  void psd_frame(const Frame& f) noexcept;
  // A sample of the rest window before the motion: the relative acceleration's noise.
  void rest_sample(const Eigen::Vector3d& a_rel_mps2) noexcept;
  // The motion starts at trace index 0; `rest_bias` is what the pipeline subtracts.
  void start() noexcept;
  // One sample of the motion (the pipeline's stored sample at trace index s.k): the rest
  // decision, then the live filter's supports, in this order:
  //   find_rest → zupt_or_window_mean → schedule_flags → predict_and_support_velocity →
  //   position_fixes → record → track_rest_window
  void step(const SupportSample& s) noexcept;

  // The live filter's current error estimate (subtract from the integrated motion).
  [[nodiscard]] Eigen::Vector3d live_dx_mm() const noexcept;
  [[nodiscard]] Eigen::Vector3d live_dv_mm_s() const noexcept;

  // Offline: corrects pos/vel of the trace (sensor time base) in place; returns what was
  // done. sigma_x_um receives the posterior σ of the position per sample and axis.
  SupportSummary finish(const std::vector<std::int64_t>& sample_index, std::vector<Eigen::Vector3d>& pos_mm,
                        std::vector<Eigen::Vector3d>& vel_mm_s, std::vector<Eigen::Vector3d>& sigma_x_um);
  // Offline without the trace: the same schedule and smoother, the corrections left to be
  // applied segment by segment (`correction`, which takes the recorded schedule).
  // index_at(k): sample index of trace sample k; sink: the smoothed errors as they are made.
  SupportSummary finish_track(std::size_t samples, const std::function<std::int64_t(std::size_t)>& index_at,
                              std::unique_ptr<SmoothedCorrection>& correction, fusion::SegmentSink* sink = nullptr);
  // The integrated velocity (mm/s, as recorded) of trace samples [first, last], summed
  // over those the smoother reads; and how many (what ZUPT takes out at a standstill).
  [[nodiscard]] std::pair<Eigen::Vector3d, std::size_t> recorded_velocity_sum(std::size_t first,
                                                                              std::size_t last) const {
    return support_velocity_sum(schedule_.flags, support_vel_mm_s_, first, last);
  }
  // Sample index of trace sample k, the first at first_index (the recorded steps).
  [[nodiscard]] std::int64_t trace_index(std::int64_t first_index, std::size_t k) const noexcept;

  // The schedule the offline pass used (after finish()), for identification and tests.
  [[nodiscard]] const fusion::SupportSchedule& schedule() const noexcept { return schedule_; }

 private:
  // What the standstill detector decided for this sample, and how a ringing standstill is
  // used (by the mean velocity over each vibration window, not sample by sample).
  struct RestDecision {
    supports::StandstillDetector::Decision det;
    bool rest = false;
    double zupt_sigma_um_s = 0.0;  // 0: the sample's own ZUPT; < 0: none (ringing)
    bool mean_update = false;
    fusion::VelocityMean mean;
  };
  RestDecision find_rest(const SupportSample& s) noexcept;
  void zupt_or_window_mean(const SupportSample& s, RestDecision& r) noexcept;
  std::uint8_t schedule_flags(const SupportSample& s, const RestDecision& r) noexcept;
  void predict_and_support_velocity(const SupportSample& s, const RestDecision& r, std::uint8_t flags) noexcept;
  void position_fixes(const SupportSample& s, const Eigen::Vector3d& vel_corr_mm_s) noexcept;
  void record(const SupportSample& s, std::uint8_t flags, const RestDecision& r) noexcept;
  void track_rest_window(const SupportSample& s, const RestDecision& r) noexcept;
  void close_rest_window() noexcept;
  void late_part_sample(const Eigen::Vector3d& a_rel_mps2) noexcept;
  void measure_bias_step(SupportSummary& sum) const;
  void anchor_start(const Eigen::Vector3d& pos_mm) noexcept;
  // The schedule with hindsight and the rest windows in sample indices (finish's first half).
  SupportSummary refine(std::size_t n, const std::function<std::int64_t(std::size_t)>& index_at);
  // The smoother over the recorded track (its second half); CUPT is dropped when the strips
  // disagree. hand_over: the recorded schedule and track move into the result.
  std::unique_ptr<SmoothedCorrection> smooth_track(std::size_t n, SupportSummary& sum, bool hand_over,
                                                   fusion::SegmentSink* sink = nullptr);
  // The smoother over the PSD fixes, over one per crossing when they disagree, or without
  // them when those disagree too (sum says which).
  void fuse_psd(SmoothedCorrection& c, SupportSummary& sum, bool hand_over, const fusion::SmootherSettings& st,
                fusion::SegmentSink* sink);

  SupportConfig cfg_;
  double fs_hz_ = kDefaultFs_hz;
  fusion::Discrete step_;
  supports::StandstillDetector detector_;
  std::vector<supports::PsdDecoder> psd_;
  std::array<supports::PsdReading, kMaxPsd> psd_now_{};
  fusion::ForwardFilter live_;
  fusion::SupportSchedule schedule_;
  // What the smoother reads besides the schedule, recorded as the samples pass: the steps
  // that are not one sample, the integrated velocity where a velocity support reads it,
  // the integrated position at each PSD fix.
  std::vector<std::pair<std::size_t, std::int64_t>> gaps_;
  std::vector<Eigen::Vector3d> support_vel_mm_s_;
  std::vector<double> fix_pos_mm_;
  std::vector<bool> zupt_unused_;  // SupportConfig::compact: ZUPT σ −1 (true) or 0 per sample
  bool record_way_ = false;        // the schedule's way per sample (a scale state on some axis)
  std::size_t capacity_ = 0;
  // Rest window before the motion: Σa, Σa² of the relative acceleration.
  Eigen::Vector3d rest_sum_ = Eigen::Vector3d::Zero(), rest_sq_ = Eigen::Vector3d::Zero();
  std::size_t rest_n_ = 0;
  // Batch means of the rest window (blocks of 20 ms): how well its mean fixed the bias when
  // the samples are not independent (a tone over an incomplete number of periods, ch. 8.3.1).
  std::vector<Eigen::Vector3d> block_means_;
  Eigen::Vector3d block_sum_ = Eigen::Vector3d::Zero();
  std::size_t block_n_ = 0, block_len_ = 200;
  Eigen::Vector3d start_bias_sigma_ = Eigen::Vector3d::Zero();
  // Detected rests.
  bool at_rest_ = false, started_ = false;
  Eigen::Vector3d start_pos_mm_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d frame_ref_mm_ = Eigen::Vector3d::Constant(
      std::numeric_limits<double>::quiet_NaN());  // per axis: where the strips' frame is referred (anchor_start)
  Eigen::Vector3d cmd_at_rest_ = Eigen::Vector3d::Zero();
  RestWindow open_{};
  std::vector<RestWindow> rests_;
  // The open standstill's late part in batches (fusion/bias_steps.hpp): the running batch,
  // the sum and square sum of its batch means; their scatter pooled over the closed ones.
  Eigen::Vector3d late_batch_sum_ = Eigen::Vector3d::Zero(), late_sum_ = Eigen::Vector3d::Zero(),
                  late_sq_ = Eigen::Vector3d::Zero(), batch_ss_ = Eigen::Vector3d::Zero();
  std::size_t late_batch_n_ = 0, late_batches_ = 0, batch_dof_ = 0;
  bool late_quiet_ = true;                                 // the acceleration confirmed every sample of the late part
  std::size_t late_settle_ = 2000, late_batch_len_ = 500;  // samples (set from fs)
  std::size_t rests_dropped_ = 0, fixes_dropped_ = 0, ringing_count_ = 0;
};

}  // namespace eical::dsp
