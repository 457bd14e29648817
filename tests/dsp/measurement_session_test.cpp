#include "dsp/session/measurement_session.hpp"

#include <gtest/gtest.h>

namespace eical::dsp {
namespace {

constexpr double kFs = 1000.0;

SessionConfig config(double max_s = 10.0) {
  SessionConfig c;
  c.fs_hz = kFs;
  c.max_measurement_s = max_s;
  c.pretrigger_s = 0.2;
  c.posttrigger_s = 0.1;
  return c;
}

Frame frame(std::int64_t i, int trigger = 0) {
  Frame f;
  f.sample_index = i;
  f.trigger = trigger;
  f.cmd_mm[0] = static_cast<double>(i);  // lets the test see which frames were kept
  return f;
}

std::vector<Frame> spare_for(const MeasurementSession& s) {
  std::vector<Frame> v;
  v.reserve(s.recorder_capacity());
  return v;
}

TEST(MeasurementSession, RecordsFromPretriggerToPosttrigger) {
  MeasurementSession s(config());
  for (std::int64_t i = 0; i < 3000; ++i) s.on_frame(frame(i, i == 1000 ? 101 : i == 1500 ? 102 : i == 2000 ? 103 : 0));
  ASSERT_TRUE(s.measurement_ready());
  EXPECT_EQ(s.state().state(), State::evaluating);
  auto rec = spare_for(s);
  ASSERT_TRUE(s.take(rec));
  ASSERT_EQ(rec.size(), 200u + 1000u + 1u + 100u);  // pre-trigger, M101..M103, post-trigger
  EXPECT_EQ(rec.front().sample_index, 800);
  EXPECT_EQ(rec.back().sample_index, 2100);
  EXPECT_EQ(rec[200].trigger, 101);
  for (std::size_t k = 1; k < rec.size(); ++k) ASSERT_EQ(rec[k].sample_index, rec[k - 1].sample_index + 1);
  s.evaluation_done();
  EXPECT_EQ(s.state().state(), State::done);
  EXPECT_EQ(s.counters().measurements_completed, 1u);
}

TEST(MeasurementSession, TakeRefusesASpareThatWouldMakeItAllocate) {
  MeasurementSession s(config());
  for (std::int64_t i = 0; i < 600; ++i) s.on_frame(frame(i, i == 300 ? 101 : i == 400 ? 103 : 0));
  std::vector<Frame> small;
  EXPECT_FALSE(s.take(small));
  auto rec = spare_for(s);
  EXPECT_TRUE(s.take(rec));
}

TEST(MeasurementSession, ExternalTriggersLandOnTheirSampleAndLateOnesAreCounted) {
  MeasurementSession s(config());
  ASSERT_TRUE(s.queue_trigger(500, 101));
  for (std::int64_t i = 0; i < 700; ++i) s.on_frame(frame(i));
  ASSERT_TRUE(s.queue_trigger(650, 103));  // already in the past
  for (std::int64_t i = 700; i < 1000; ++i) s.on_frame(frame(i));
  EXPECT_EQ(s.counters().triggers_late, 1u);
  auto rec = spare_for(s);
  ASSERT_TRUE(s.take(rec));
  EXPECT_EQ(rec.front().sample_index, 300);
  EXPECT_EQ(rec[200].sample_index, 500);
  EXPECT_EQ(rec[200].trigger, 101);
  EXPECT_EQ(rec[400].sample_index, 700);  // the late M103 is recorded on the frame that applied it
  EXPECT_EQ(rec[400].trigger, 103);
}

TEST(MeasurementSession, AbortDiscardsAndRefusedTriggersAreCounted) {
  MeasurementSession s(config());
  s.on_frame(frame(0, 103));  // M103 without M101
  EXPECT_EQ(s.counters().triggers_refused, 1u);
  for (std::int64_t i = 1; i < 300; ++i) s.on_frame(frame(i, i == 250 ? 101 : 0));
  EXPECT_EQ(s.state().state(), State::measuring);
  EXPECT_TRUE(s.command(Event::abort).accepted);
  for (std::int64_t i = 300; i < 400; ++i) s.on_frame(frame(i));
  EXPECT_FALSE(s.measurement_ready());
  EXPECT_EQ(s.state().state(), State::idle);
}

TEST(MeasurementSession, OverlongMeasurementKeepsTheStartAndCountsTheOverflow) {
  MeasurementSession s(config(1.0));  // room for 1 s + pre-trigger
  for (std::int64_t i = 0; i < 3000; ++i) s.on_frame(frame(i, i == 300 ? 101 : i == 2800 ? 103 : 0));
  EXPECT_GT(s.recorder_overflow(), 0u);
  auto rec = spare_for(s);
  ASSERT_TRUE(s.take(rec));
  EXPECT_EQ(rec.size(), s.recorder_capacity());
  EXPECT_EQ(rec.front().sample_index, 100);
}

// A sink that keeps what a streamed recording sends it (room for `room` frames).
class KeptFrames final : public RecordingSink {
 public:
  explicit KeptFrames(std::size_t room = SIZE_MAX) : room_(room) {}
  void begin() noexcept override { ++begun, frames.clear(); }
  bool frame(const Frame& f) noexcept override {
    if (frames.size() >= room_) return false;
    frames.push_back(f);
    return true;
  }
  void discard() noexcept override { ++discarded, frames.clear(); }
  int begun = 0, discarded = 0;
  std::vector<Frame> frames;

 private:
  std::size_t room_;
};

TEST(MeasurementSession, StreamedRecordingSendsTheSameFramesAndHoldsNone) {
  KeptFrames sink;
  MeasurementSession streamed(config(), &sink);
  MeasurementSession held(config());
  for (std::int64_t i = 0; i < 3000; ++i) {
    const Frame f = frame(i, i == 1000 ? 101 : i == 1500 ? 102 : i == 2000 ? 103 : 0);
    streamed.on_frame(f), held.on_frame(f);
  }
  ASSERT_TRUE(streamed.measurement_ready());
  auto rec = spare_for(held);
  ASSERT_TRUE(held.take(rec));
  std::vector<Frame> none;
  EXPECT_FALSE(streamed.take(none)) << "a streamed recording is not handed over by buffer";
  ASSERT_TRUE(streamed.take_streamed());
  EXPECT_FALSE(streamed.take_streamed());
  EXPECT_EQ(sink.begun, 1);
  ASSERT_EQ(sink.frames.size(), rec.size());
  for (std::size_t k = 0; k < rec.size(); ++k) {
    ASSERT_EQ(sink.frames[k].sample_index, rec[k].sample_index);
    ASSERT_EQ(sink.frames[k].trigger, rec[k].trigger);
  }
  streamed.evaluation_done();
  EXPECT_EQ(streamed.state().state(), State::done);
}

TEST(MeasurementSession, StreamedAbortDiscardsAndAFullSinkCountsTheLostFrames) {
  KeptFrames sink(500);
  MeasurementSession s(config(), &sink);
  for (std::int64_t i = 0; i < 300; ++i) s.on_frame(frame(i, i == 250 ? 101 : 0));
  EXPECT_TRUE(s.command(Event::abort).accepted);
  EXPECT_EQ(sink.discarded, 1);
  for (std::int64_t i = 300; i < 2000; ++i) s.on_frame(frame(i, i == 400 ? 101 : i == 1500 ? 103 : 0));
  ASSERT_TRUE(s.take_streamed());
  EXPECT_EQ(sink.begun, 2);
  EXPECT_EQ(sink.frames.size(), 500u);
  // Pre-trigger (100 frames since the abort), M101..M103, post-trigger: 500 taken, the rest lost.
  EXPECT_EQ(s.recorder_overflow(), 100u + 1101u + 100u - 500u);
}

TEST(MeasurementSession, LostFramesAreCounted) {
  MeasurementSession s(config());
  Frame f = frame(10);
  f.flags = frame_flag::gap_before;
  s.on_frame(frame(0));
  s.on_frame(f);
  EXPECT_EQ(s.counters().frames_lost, 1u);
  EXPECT_EQ(s.counters().frames_flagged, 1u);
}

}  // namespace
}  // namespace eical::dsp
