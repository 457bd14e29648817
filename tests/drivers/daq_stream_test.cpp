// The DAQ's wire protocol from a byte stream: simulated frames encoded as the firmware
// sends them (FrameEncoder) come out of DaqStreamSource — the USB path's decoder — equal,
// through a named pipe and a Unix socket, without an allocation in read(); an absent
// writer is a clear error naming the path.
#include "drivers/usb_daq/daq_stream_source.hpp"
#include "drivers/usb_daq/frame_encoder.hpp"
#include "sim/simulate.hpp"
#include "tests/support/allocation_counter.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <random>
#include <thread>

namespace eical::drivers {
namespace {

namespace fs = std::filesystem;

fs::path scratch() {
  const fs::path d = fs::temp_directory_path() / ("eical-daqstream-" + std::to_string(std::random_device{}()));
  fs::create_directories(d);
  return d;
}

dsp::Run short_run() {
  dsp::Run run = sim::simulate(sim::circle_scenario(10.0, 2500.0, 1));
  run.frames.resize(20000);  // 2 s: rest, M101 and the start of the motion
  return run;
}

std::vector<std::uint8_t> encoded(const dsp::Run& run) {
  std::vector<std::uint8_t> bytes;
  usb_daq::FrameEncoder enc(static_cast<int>(run.meta.psd.size()));
  enc.encode(run.frames, bytes);
  return bytes;
}

void write_all(int fd, const std::vector<std::uint8_t>& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, std::min<std::size_t>(4096, bytes.size() - done));
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

// Reads until `want` frames or 10 s; counts this thread's allocations inside read().
std::vector<dsp::Frame> read_frames(DaqStreamSource& src, std::size_t want, std::size_t& allocations) {
  std::vector<dsp::Frame> out;
  out.reserve(want);
  std::array<dsp::Frame, 64> block;
  allocations = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (out.size() < want && std::chrono::steady_clock::now() < end) {
    test::start_counting_allocations();
    const std::size_t n = src.read(block);
    allocations += test::stop_counting_allocations();
    out.insert(out.end(), block.begin(), block.begin() + static_cast<std::ptrdiff_t>(n));
  }
  return out;
}

void expect_same_frames(const dsp::Run& run, const std::vector<dsp::Frame>& got) {
  ASSERT_EQ(got.size(), run.frames.size());
  std::size_t triggers = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    const dsp::Frame& a = run.frames[i];
    const dsp::Frame& b = got[i];
    ASSERT_EQ(b.sample_index, a.sample_index);
    for (int c = 0; c < 6; ++c) ASSERT_EQ(b.accel_counts[c], a.accel_counts[c]) << "sample " << i << " channel " << c;
    for (std::size_t c = 0; c < 2 * run.meta.psd.size(); ++c)
      ASSERT_EQ(b.psd_counts[c], a.psd_counts[c]) << "sample " << i;
    ASSERT_EQ(b.trigger, a.trigger) << "sample " << i;
    triggers += a.trigger != 0;
    ASSERT_NEAR(b.temp_c[0], a.temp_c[0], 0.006f);  // 1/100 °C on the wire
    ASSERT_NE(b.flags & dsp::frame_flag::cmd_missing, 0u) << "a DAQ has no set-point";
  }
  EXPECT_GE(triggers, 1u) << "the run's M101 travelled on the trigger channel";
}

TEST(DaqStream, SimulatedFramesThroughAPipeDecodeEqualWithoutAllocating) {
  const fs::path dir = scratch();
  const dsp::Run run = short_run();
  const auto bytes = encoded(run);
  DaqStreamOptions o;
  o.path = dir / "daq.fifo";
  o.connect_timeout_s = 5.0;
  DaqStreamSource src(run.meta, o);
  std::thread writer([&] {
    // The pipe exists once open() created it; then the device side writes its packets.
    for (int i = 0; i < 500 && !fs::is_fifo(o.path); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    const int fd = ::open(o.path.c_str(), O_WRONLY);
    if (fd < 0) return;
    write_all(fd, bytes);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the reader drains before EOF
    ::close(fd);
  });
  src.open();
  std::size_t allocations = 0;
  const auto got = read_frames(src, run.frames.size(), allocations);
  writer.join();
  expect_same_frames(run, got);
  if (test::allocations_counted()) {
    EXPECT_EQ(allocations, 0u) << "read() allocated";
  }
  EXPECT_EQ(src.counters().decode_errors, 0u);
  // The writer closed the pipe: the source fails naming it (eicald reopens it).
  try {
    std::array<dsp::Frame, 64> block;
    for (int i = 0; i < 50; ++i) (void)src.read(block);
    FAIL() << "no error after the writer closed";
  } catch (const SourceError& e) {
    EXPECT_NE(std::string(e.what()).find(o.path.string()), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(DaqStream, ConnectsToAListeningUnixSocket) {
  const fs::path dir = scratch();
  const dsp::Run run = short_run();
  const auto bytes = encoded(run);
  const fs::path sock = dir / "daq.sock";
  const int listener = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(listener, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, sock.c_str(), sizeof addr.sun_path - 1);
  ASSERT_EQ(::bind(listener, reinterpret_cast<const sockaddr*>(&addr), sizeof addr), 0);
  ASSERT_EQ(::listen(listener, 1), 0);
  std::thread bridge([&] {
    const int fd = ::accept(listener, nullptr, nullptr);
    if (fd < 0) return;
    write_all(fd, bytes);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ::close(fd);
  });
  DaqStreamOptions o;
  o.path = sock;
  DaqStreamSource src(run.meta, o);
  src.open();
  std::size_t allocations = 0;
  const auto got = read_frames(src, run.frames.size(), allocations);
  bridge.join();
  ::close(listener);
  expect_same_frames(run, got);
  fs::remove_all(dir);
}

TEST(DaqStream, WithoutAWriterOpenFailsNamingThePath) {
  const fs::path dir = scratch();
  DaqStreamOptions o;
  o.path = dir / "daq.fifo";
  o.connect_timeout_s = 0.3;
  DaqStreamSource src(dsp::RunMeta{}, o);
  const auto t0 = std::chrono::steady_clock::now();
  try {
    src.open();
    FAIL() << "opened without a DAQ";
  } catch (const SourceError& e) {
    EXPECT_NE(std::string(e.what()).find("no DAQ packets on " + o.path.string()), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2)) << "must not hang";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical::drivers
