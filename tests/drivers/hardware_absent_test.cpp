// The hardware paths on a machine without the hardware: each says what is missing at
// start (this sandbox has no USB devices, no PF_CAN and no gpiochip), and the CAN
// trigger protocol is checked on frames.
#include "drivers/can/can_trigger.hpp"
#include "drivers/gpio/gpio_trigger.hpp"
#include "drivers/usb_daq/usb_daq_source.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

namespace eical::drivers {
namespace {

TEST(HardwareAbsent, UsbDaqSaysWhichDeviceIsMissing) {
  UsbDaqSource src(dsp::RunMeta{}, parse_usb_id("1d50:6161"));
  try {
    src.open();
    GTEST_SKIP() << "a DAQ with id 1d50:6161 is attached";
  } catch (const SourceError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("usb_daq"), std::string::npos) << m;
    EXPECT_TRUE(m.find("no DAQ with USB id 1d50:6161") != std::string::npos ||
                m.find("libusb_init") != std::string::npos)
        << m;
  }
  EXPECT_THROW((void)parse_usb_id("1d50-6161"), SourceError);
}

TEST(HardwareAbsent, CanSaysWhatIsMissing) {
  try {
    CanTriggerInput in("can0", 0x1E0);
    GTEST_SKIP() << "can0 exists here";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("can: ", 0), 0u) << m;
    EXPECT_TRUE(m.find("SocketCAN is not available") != std::string::npos ||
                m.find("no CAN interface 'can0'") != std::string::npos)
        << m;
  }
}

TEST(HardwareAbsent, GpioSaysWhichChipIsMissing) {
  if (std::filesystem::exists("/dev/gpiochip0")) GTEST_SKIP() << "a gpiochip exists here";
  try {
    GpioTriggerInput in("gpiochip0", {17, 27, 22});
    FAIL() << "opened a missing gpiochip";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("gpio: cannot open gpiochip0"), std::string::npos) << e.what();
  }
}

TEST(CanTriggerFrames, RoundTripAndRejection) {
  const can_frame f = make_can_trigger(0x1E0, 102, 7, 2.5);
  const auto t = parse_can_trigger(f, 0x1E0);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->code, 102);
  EXPECT_EQ(t->sequence, 7);
  EXPECT_DOUBLE_EQ(t->p, 2.5);
  EXPECT_TRUE(std::isnan(parse_can_trigger(make_can_trigger(0x1E0, 101, 8), 0x1E0)->p));
  EXPECT_FALSE(parse_can_trigger(f, 0x1E1));  // another id
  can_frame bad = f;
  bad.data[0] = 9;  // not M101..M103
  EXPECT_FALSE(parse_can_trigger(bad, 0x1E0));
  bad = f;
  bad.len = 4;
  EXPECT_FALSE(parse_can_trigger(bad, 0x1E0));
}

}  // namespace
}  // namespace eical::drivers
