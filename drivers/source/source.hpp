#pragma once
// One interface for every origin of frames: hardware DAQ, simulator, recorded run.
// The acquisition thread calls read() in a loop and pushes into the SPSC ring.
#include "dsp/core/frame.hpp"
#include "dsp/core/run_meta.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace eical::drivers {

// A source that cannot start (absent device, unreadable file) says why with this type.
class SourceError : public std::runtime_error {
 public:
  explicit SourceError(const std::string& what) : std::runtime_error(what) {}
};

// How the pump treats a full ring. Live hardware must never block (the DAQ keeps
// sampling): the newest frame is dropped and counted. A source without a real-time
// clock (free-running replay or simulation) has nothing to lose by waiting.
enum class Backpressure { drop_newest, wait };

// What a source lost or repaired on its own threads. Sources keep these in atomics, so any
// thread (eicald's status thread) may read them; all zero for sources that count nothing.
struct SourceCounters {
  std::uint64_t decode_errors = 0;     // wire protocol: CRC errors and unknown packets
  std::uint64_t lost_samples = 0;      // samples the device or stream lost (sequence jumps, lost servo cycles)
  std::uint64_t dropped_frames = 0;    // frames the source had to drop itself (its own queue full)
  std::uint64_t setpoint_samples = 0;  // set-point samples received (servo stream)
  std::uint64_t setpoint_missing = 0;  // frames released without a set-point (none covered their time)
};

class Source {
 public:
  Source() = default;
  Source(const Source&) = delete;
  Source& operator=(const Source&) = delete;
  virtual ~Source() = default;

  // Starts acquisition; throws SourceError naming the cause when the device is absent.
  virtual void open() = 0;
  // Acquisition metadata (fs, ADC, sensors, site, PSD geometry) this source delivers.
  [[nodiscard]] virtual const dsp::RunMeta& meta() const = 0;
  // Fills `out` with the next frames; may block until they are due (paced sources).
  // Returns the number written; 0 together with at_end() means the source is finished.
  virtual std::size_t read(std::span<dsp::Frame> out) = 0;
  [[nodiscard]] virtual bool at_end() const = 0;
  [[nodiscard]] virtual std::string_view name() const = 0;
  [[nodiscard]] virtual Backpressure backpressure() const = 0;
  // CLOCK_MONOTONIC (ns) at which the sample was taken, when the source knows it better
  // than "when read() returned it" (a source that delivers with latency, e.g. linuxcnc);
  // 0 = unknown.
  [[nodiscard]] virtual std::int64_t sample_time_ns(std::int64_t /*sample_index*/) const { return 0; }
  [[nodiscard]] virtual SourceCounters counters() const { return {}; }
  // Diagnostic lines the source collected on its own threads (e.g. the M-code markers of
  // the LinuxCNC stream), handed over on a thread that may write streams (eicald's status
  // thread, about once a second); the acquisition path itself never writes a stream.
  virtual void drain_diagnostics(const std::function<void(const std::string&)>& /*sink*/) {}
};

}  // namespace eical::drivers
