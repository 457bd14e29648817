#include "dsp/session/measurement_state.hpp"

#include <gtest/gtest.h>

namespace eical::dsp {

TEST(MeasurementState, NormalProgramRunsThroughAllStates) {
  MeasurementState m;
  EXPECT_EQ(m.handle(Event::arm).to, State::armed);
  auto t = m.handle(Event::program_start);
  EXPECT_EQ(t.to, State::measuring);
  EXPECT_EQ(t.action, Action::start_measurement);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(m.handle(Event::segment_mark).action, Action::mark_segment);
  EXPECT_EQ(m.segments(), 5u);
  t = m.handle(Event::program_end);
  EXPECT_EQ(t.to, State::evaluating);
  EXPECT_EQ(t.action, Action::stop_and_evaluate);
  t = m.handle(Event::evaluation_done);
  EXPECT_EQ(t.to, State::done);
  EXPECT_EQ(t.action, Action::publish_done);
}

TEST(MeasurementState, M101ArmsImplicitlyFromIdleAndDone) {
  MeasurementState m;
  EXPECT_EQ(m.handle(Event::program_start).to, State::measuring);
  m.handle(Event::program_end);
  m.handle(Event::evaluation_done);
  ASSERT_EQ(m.state(), State::done);
  auto t = m.handle(Event::program_start);
  EXPECT_TRUE(t.accepted);
  EXPECT_EQ(t.to, State::measuring);
  EXPECT_EQ(m.segments(), 0u) << "a new program starts counting segments afresh";
}

TEST(MeasurementState, OutOfOrderTriggersAreRefusedWithReason) {
  MeasurementState m;
  auto t = m.handle(Event::program_end);
  EXPECT_FALSE(t.accepted);
  EXPECT_EQ(m.state(), State::idle);
  EXPECT_NE(t.message.find("IDLE"), std::string::npos) << t.message;
  t = m.handle(Event::segment_mark);
  EXPECT_FALSE(t.accepted);
}

TEST(MeasurementState, FaultFromAnyStateKeepsReasonUntilReset) {
  for (Event before : {Event::arm, Event::program_start}) {
    MeasurementState m;
    m.handle(before);
    auto t = m.handle(Event::fault, "source stopped: usb_daq read timeout");
    EXPECT_EQ(t.to, State::fault);
    EXPECT_EQ(t.action, Action::enter_fault);
    EXPECT_EQ(m.fault_reason(), "source stopped: usb_daq read timeout");
    EXPECT_FALSE(m.handle(Event::program_start).accepted) << "no measuring while faulted";
    EXPECT_EQ(m.handle(Event::reset).to, State::idle);
    EXPECT_TRUE(m.fault_reason().empty());
  }
}

TEST(MeasurementState, AbortDiscardsMeasurement) {
  MeasurementState m;
  m.handle(Event::program_start);
  auto t = m.handle(Event::abort);
  EXPECT_EQ(t.to, State::idle);
  EXPECT_EQ(t.action, Action::discard);
}

TEST(MeasurementState, M101DuringAMeasurementIsRefusedAndItContinues) {
  MeasurementState m;
  m.handle(Event::program_start);
  m.handle(Event::segment_mark);
  auto t = m.handle(Event::program_start);
  EXPECT_FALSE(t.accepted);
  EXPECT_EQ(t.action, Action::none);
  EXPECT_EQ(m.state(), State::measuring);
  EXPECT_EQ(m.segments(), 1u) << "the running measurement keeps its segments";
  EXPECT_NE(t.message.find("continues untouched"), std::string::npos) << t.message;
  EXPECT_EQ(m.handle(Event::program_end).to, State::evaluating);
}

}  // namespace eical::dsp
