#pragma once
// The acquisition path shared by eicald and the offline tools: an acquisition thread
// reads blocks from a Source into the SPSC ring; the calling thread (the DSP thread)
// drains the ring and hands every frame to `consume`. Overruns are counted by the ring.
#include "drivers/ring/spsc_ring.hpp"
#include "drivers/source/source.hpp"

#include <array>
#include <atomic>
#include <cstdint>
#include <exception>
#include <span>
#include <string>
#include <thread>

namespace eical::drivers {

using FrameRing = SpscRing<dsp::Frame>;

struct PumpStats {
  std::uint64_t frames_read = 0;      // delivered by the source
  std::uint64_t frames_consumed = 0;  // handed to the consumer
  std::uint64_t overruns = 0;         // dropped because the ring was full
  bool stopped = false;               // ended by the stop flag, not by the source
  std::string source_error;           // non-empty when the source failed mid-run
};

// Runs until the source ends, fails, or `stop` becomes true. `consume(const Frame&)`
// runs on the calling thread and must not block for long (it is the DSP thread).
template <class Consume>
PumpStats pump(Source& source, FrameRing& ring, Consume&& consume, const std::atomic<bool>& stop) {
  PumpStats stats;
  const std::uint64_t overruns_before = ring.overruns();
  std::atomic<bool> producer_done{false};
  // Bumped once per block pushed; the consumer sleeps on it instead of polling.
  std::atomic<std::uint32_t> published{0};
  std::exception_ptr producer_error;
  std::uint64_t frames_read = 0;

  std::thread producer([&] {
    std::array<dsp::Frame, 64> block;
    const bool may_wait = source.backpressure() == Backpressure::wait;
    try {
      while (!stop.load(std::memory_order_relaxed)) {
        const std::size_t n = source.read(block);
        if (n == 0 && source.at_end()) break;
        for (std::size_t i = 0; i < n; ++i) {
          if (may_wait) {
            while (!ring.try_push(block[i])) {
              if (stop.load(std::memory_order_relaxed)) break;
              std::this_thread::yield();  // offline source: no sample clock to keep up with
            }
          } else {
            (void)ring.push_or_drop(block[i]);  // live: never block, the ring counts the drop
          }
        }
        frames_read += n;
        published.fetch_add(1, std::memory_order_release);
        published.notify_one();
      }
    } catch (...) {
      producer_error = std::current_exception();
    }
    producer_done.store(true, std::memory_order_release);
    published.fetch_add(1, std::memory_order_release);
    published.notify_one();
  });

  std::array<dsp::Frame, 256> batch;
  for (;;) {
    const std::uint32_t seen = published.load(std::memory_order_acquire);
    const bool done = producer_done.load(std::memory_order_acquire);
    std::size_t n;
    while ((n = ring.pop_many(std::span<dsp::Frame>(batch))) > 0) {
      for (std::size_t i = 0; i < n; ++i) consume(batch[i]);
      stats.frames_consumed += n;
    }
    if (done) break;  // producer finished before we drained: nothing more will come
    published.wait(seen, std::memory_order_acquire);
  }
  producer.join();

  stats.frames_read = frames_read;
  stats.overruns = ring.overruns() - overruns_before;
  stats.stopped = stop.load();
  if (producer_error) {
    try {
      std::rethrow_exception(producer_error);
    } catch (const std::exception& e) {
      stats.source_error = std::string(source.name()) + ": " + e.what();
    } catch (...) {
      stats.source_error = std::string(source.name()) + ": unknown failure";
    }
  }
  return stats;
}

}  // namespace eical::drivers
