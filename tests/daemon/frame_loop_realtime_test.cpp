// The daemon's per-frame path must not allocate: count the allocations of the DSP thread
// (this test's thread) through whole measurements — acquisition stamps, the guard, the
// DAQ clock, external triggers (DDS channel: an M101 accepted with its P word, an M101
// during the measurement refused), the session, the live pipeline, Live samples to the
// HMI publisher, every recorded frame into the recording ring and the hand-over of the
// recording to the evaluation thread. Other threads (the HMI link's, the stand-in
// recording and evaluation thread) may allocate: the count is per thread.
#include "daemon/service/frame_loop.hpp"
#include "daemon/service/hmi_link.hpp"
#include "daemon/service/recording_stream.hpp"
#include "drivers/dds/domain_claim.hpp"
#include "drivers/source/replay_source.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <new>
#include <thread>

namespace {
thread_local bool t_counting = false;
thread_local std::size_t t_allocations = 0;
}  // namespace

// Sanitizers replace operator new themselves; the count runs in the plain build only.
#if defined(EICAL_SANITIZED)
#define EICAL_COUNT_ALLOCATIONS 0
#else
#define EICAL_COUNT_ALLOCATIONS 1
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  if (t_counting) ++t_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop
#endif

namespace eical::daemon {
namespace {

TEST(FrameLoopRealTime, WholeMeasurementsAllocateNothingOnTheDspThread) {
  if (!EICAL_COUNT_ALLOCATIONS) GTEST_SKIP() << "sanitizer build: allocations are counted in the plain build";
  auto run = std::make_shared<dsp::Run>(sim::simulate(sim::circle_scenario(10.0, 2500.0, 1)));
  // Twice the program: a second measurement needs the storage the evaluator gave back.
  const std::size_t n_prog = run->frames.size();
  for (std::size_t i = 0; i < n_prog; ++i) {
    dsp::Frame f = run->frames[i];
    f.sample_index += static_cast<std::int64_t>(n_prog);
    run->frames.push_back(f);
  }
  drivers::StampedSource source(std::make_unique<drivers::ReplaySource>(run, drivers::Pacing::free_running));
  source.open();

  DdsConfig dds;
  dds.domain_id = drivers::dds::claim_free_domain();
  dds.config_uri = "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml";
  HmiLink hmi(dds, "frame-loop-test");

  dsp::SessionConfig scfg;
  scfg.fs_hz = run->fs_hz();
  scfg.max_measurement_s = 30.0;
  RecordingStream recording(1 << 16);
  dsp::MeasurementSession session(scfg, &recording);
  dsp::PipelineConfig live_cfg = dsp::pipeline_config(run->meta, session.recorder_capacity());
  live_cfg.trace = dsp::TraceKeeping::live;  // as the service runs it
  dsp::Pipeline live(live_cfg);
  FrameGuard guard(20.0f, 20.0f);
  RecordingHandoff handoff(recording);
  ServiceCounters counters;
  FrameLoopOptions o;
  o.fs_hz = run->fs_hz();
  o.frame_triggers = true;  // the program's M101/M102/M103 on the frames
  o.live_every = 100;
  FrameLoop loop(o, source, session, live, guard, handoff, counters, &hmi);
  TriggerChannel nc("test-nc");
  loop.add_channel(nc);

  // The recording and evaluation threads' part: drain the ring, count each recording's
  // frames, and say each one is evaluated.
  std::atomic<int> jobs{0}, returned{0};
  std::atomic<bool> stop{false};
  std::vector<std::size_t> recorded;  // frames of each recording, in order
  std::thread evaluator([&] {
    std::vector<dsp::Frame> block(4096);
    std::size_t frames_now = 0;
    for (;;) {
      const bool last = stop.load();
      for (;;) {
        RecordEvent e;
        bool has_event = false;
        const std::size_t n = recording.drain(block, e, has_event);
        frames_now += n;
        if (has_event && e.kind == RecordEvent::Kind::begin) frames_now = 0;
        if (has_event && e.kind == RecordEvent::Kind::end) {
          recorded.push_back(frames_now);
          ++jobs;
          handoff.done();
          ++returned;
        }
        if (n == 0 && !has_event) break;
      }
      if (last) return;
      recording.wait(std::chrono::milliseconds(5));
    }
  });

  // The counter counts (or a broken replacement would pass everything).
  t_allocations = 0;
  t_counting = true;
  auto probe = std::make_unique<int>(1);
  t_counting = false;
  ASSERT_EQ(t_allocations, 1u);

  std::array<dsp::Frame, 64> block;
  std::size_t frames = 0;
  bool sent_during = false;
  t_allocations = 0;
  t_counting = true;
  for (std::size_t n; (n = source.read(block)) > 0;) {
    for (std::size_t k = 0; k < n; ++k) {
      loop.on_frame(block[k]);
      ++frames;
      // Mid-measurement, an M101 from another input: refused, the measurement continues.
      if (!sent_during && session.state().state() == dsp::State::measuring && frames % 5000 == 0) {
        TriggerRequest r;
        r.id = 1, r.code = 101, r.p = 7.0;
        ASSERT_TRUE(nc.send(r));
        sent_during = true;
      }
    }
    // Free-running, faster than a DAQ: the recording thread keeps the ring from filling
    // and says each recording is evaluated long before the next ends in real time; wait for it.
    for (int i = 0; i < 2000 && (recording.queued() > recording.capacity() / 2 || returned.load() < jobs.load()); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  t_counting = false;
  const std::size_t allocations = t_allocations;
  stop.store(true);
  recording.wake();
  evaluator.join();

  EXPECT_EQ(allocations, 0u) << "allocations on the DSP thread over " << frames << " frames";
  EXPECT_EQ(frames, run->frames.size());
  EXPECT_EQ(jobs.load(), 2) << "both measurements reached the evaluation thread";
  ASSERT_EQ(recorded.size(), 2u);
  for (const std::size_t n : recorded) EXPECT_GT(n, n_prog / 2) << "a recording's frames went through the ring";
  EXPECT_EQ(recording.lost_frames(), 0u);
  TriggerVerdict v;
  ASSERT_TRUE(nc.take_verdict(v));
  EXPECT_FALSE(v.accepted);
  EXPECT_EQ(v.refusal, Refusal::measurement_running);
  EXPECT_EQ(counters.measurements.load(), 2u);
  EXPECT_EQ(counters.frames.load(), run->frames.size());
}

}  // namespace
}  // namespace eical::daemon
