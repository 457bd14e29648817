// The daemon's per-frame path must not allocate: count the allocations of the DSP thread
// (this test's thread) through whole measurements — acquisition stamps, the guard, the
// DAQ clock, external triggers (DDS channel: an M101 accepted with its P word, an M101
// during the measurement refused), the session, the live pipeline, Live samples to the
// HMI publisher and the hand-over of the recording to the evaluation thread. Other
// threads (the HMI link's, the stand-in evaluator) may allocate: the count is per thread.
#include "daemon/service/frame_loop.hpp"
#include "daemon/service/hmi_link.hpp"
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
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
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
  dsp::MeasurementSession session(scfg);
  dsp::PipelineConfig live_cfg = dsp::pipeline_config(run->meta, session.recorder_capacity());
  live_cfg.trace = dsp::TraceKeeping::live;  // as the service runs it
  dsp::Pipeline live(live_cfg);
  FrameGuard guard(20.0f, 20.0f);
  RecordingHandoff handoff(session.recorder_capacity());
  ServiceCounters counters;
  FrameLoopOptions o;
  o.fs_hz = run->fs_hz();
  o.frame_triggers = true;  // the program's M101/M102/M103 on the frames
  o.live_every = 100;
  FrameLoop loop(o, source, session, live, guard, handoff, counters, &hmi);
  TriggerChannel nc("test-nc");
  loop.add_channel(nc);

  // The evaluation thread's part: take each recording and give its storage back.
  std::atomic<int> jobs{0}, returned{0};
  std::thread evaluator([&] {
    RecordingJob job;
    while (handoff.wait_job(job)) {
      ++jobs;
      handoff.give_back(std::move(job.frames));
      ++returned;
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
    // The evaluator returns the storage long before the next program ends in real time
    // (a swap of two vectors against seconds of 10 kHz frames); free-running, wait for it.
    for (int i = 0; i < 2000 && returned.load() < jobs.load(); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  t_counting = false;
  const std::size_t allocations = t_allocations;
  handoff.quit();
  evaluator.join();

  EXPECT_EQ(allocations, 0u) << "allocations on the DSP thread over " << frames << " frames";
  EXPECT_EQ(frames, run->frames.size());
  EXPECT_EQ(jobs.load(), 2) << "both measurements reached the evaluation thread";
  TriggerVerdict v;
  ASSERT_TRUE(nc.take_verdict(v));
  EXPECT_FALSE(v.accepted);
  EXPECT_EQ(v.refusal, Refusal::measurement_running);
  EXPECT_EQ(counters.measurements.load(), 2u);
  EXPECT_EQ(counters.frames.load(), run->frames.size());
}

}  // namespace
}  // namespace eical::daemon
