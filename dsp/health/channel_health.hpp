#pragma once
// Channel health, ahead of the pipeline: is each sampled channel a measurement at all?
// Frame by frame (no allocation, nothing thrown: it runs streamed beside the pipeline), per
// channel — the six accelerometer axes and the PSD electrodes the run has:
//   empty      not one sample in the run;
//   missing    empty fields for a span;
//   stuck      the same counts for longer than the sensor's noise makes plausible: with
//              the data sheet's noise (σ per sample n·√fs, run-format.md) two samples in a
//              row are equal with probability p = erf(0.5 / (2σ')) (σ' = σ/4 plus the
//              rounding, a margin for a channel quieter than its data sheet, in the
//              smallest step the channel was seen to take); a run of L equal samples is
//              taken as stuck when p^(L−1) < 1e-15 (not once in 10^9 samples, a day at
//              10 kHz);
//   dead       at rest (M101 to the first motion of the set-point) its σ is below a tenth
//              of the data sheet's (its variance below 1 %): a flat line that still toggles
//              an LSB or two;
//   clipped    at the ADC's limits (full scale);
// and for the recording as a whole (channel −1):
//   truncated  the program started (M101) and its end (M103) never came.
// Each finding names the channel and its span in seconds from the run's first sample.
// What a finding means for the figures is decided after the pipeline (dsp/analysis).
#include "dsp/core/frame.hpp"
#include "dsp/core/run.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace eical::dsp::health {

inline constexpr int kChannels = kAccelChannels + 2 * kMaxPsd;  // accel 0..5, then psd k: i1 6+2k, i2 7+2k

// Channel c as samples.csv names its column ("table_ay", "psd1_i2").
std::string channel_name(int c);
inline constexpr bool is_accel(int c) { return c >= 0 && c < kAccelChannels; }

enum class Fault { empty, missing, stuck, dead, clipped, truncated };
const char* fault_code(Fault f);  // "empty", "missing", ...

struct Finding {
  Fault fault = Fault::missing;
  int channel = -1;                 // −1: the recording as a whole
  double from_s = 0.0, to_s = 0.0;  // first and last affected sample, s from the run's first sample
  std::int64_t samples = 0;         // affected samples
  int spans = 1;                    // separate stretches they fall in
  // stuck: the counts of its longest stretch; dead: measured σ / data-sheet σ at rest.
  double value = 0.0;
  bool set_point_moving = false;  // truncated: the set-point still moved at the last sample
};

class ChannelHealth {
 public:
  // run: its metadata and channels (its frames are not read); a simulation whose truth.toml
  // gives its sensors no noise is checked for all but stuck and dead.
  explicit ChannelHealth(const Run& run);
  void frame(const Frame& f) noexcept;
  // What was found (allocates; once, after the last frame).
  [[nodiscard]] std::vector<Finding> finish();

  // The data sheet's σ of channel c in counts per sample with the rounding (PSD: the
  // rounding alone), and the shortest constant stretch taken as stuck when the channel
  // reads in single counts (in coarser steps, as an imported MEMS chip does: longer).
  [[nodiscard]] double noise_counts(int c) const { return noise_counts_[c]; }
  [[nodiscard]] std::int64_t stuck_samples(int c) const { return stuck_samples_[c]; }

 private:
  // Stretches of consecutive affected samples: their extent, count and number.
  struct Spans {
    std::int64_t first = -1, last = -1, samples = 0;
    int spans = 0;
    std::int64_t open_first = -1, open_last = -1, open_n = 0;  // the stretch in progress
    void add(std::int64_t index) noexcept;
    void close() noexcept;
  };
  struct Channel {
    bool active = false;
    Spans missing, clipped, stuck;
    bool has_last = false;
    std::int32_t last = 0;
    std::int64_t same_first = -1, same_last = -1, same_n = 0;  // the run of equal counts in progress
    std::int64_t longest_stuck = 0;
    std::int64_t min_step = 0;  // smallest change between samples seen (0: none yet)
    std::int32_t stuck_value = 0;
    std::int64_t rest_n = 0;  // Welford over the rest window
    double rest_mean = 0.0, rest_m2 = 0.0;
  };
  void end_same_run(Channel& ch) noexcept;
  void sample(int c, bool missing, std::int32_t counts, std::int64_t index, bool rest) noexcept;
  [[nodiscard]] double seconds(std::int64_t index) const { return static_cast<double>(index - first_index_) / fs_hz_; }

  double fs_hz_;
  bool noise_free_;
  double clip_high_, clip_low_;  // counts at the ADC's limits
  double noise_counts_[kChannels] = {};
  double sigma_counts_[kChannels] = {};  // the data sheet's σ without the rounding
  std::int64_t stuck_samples_[kChannels] = {};
  std::int64_t servo_hold_samples_ = 1;  // a set-point at servo rate holds this long between moves
  Channel ch_[kChannels];
  std::int64_t first_index_ = -1, last_index_ = -1, frames_ = 0;
  bool saw_start_ = false, saw_end_ = false, rest_ = true;
  std::int64_t rest_first_ = -1, rest_last_ = -1, last_move_ = -1;
  double prev_cmd_[3] = {};
  bool has_cmd_ = false;
};

// Every finding of the frames (in memory), as ChannelHealth gives them.
std::vector<Finding> check_channels(const Run& run);

}  // namespace eical::dsp::health
