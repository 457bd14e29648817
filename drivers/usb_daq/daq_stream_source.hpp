#pragma once
// The DAQ's wire protocol (PROTOCOL.md) from a byte stream instead of the USB endpoint: a
// named pipe (created when absent) or a listening Unix stream socket to connect to. The
// same decoder as the USB path, so a bridge (a DAQ on a serial line or the network, or
// the device simulator of the hardware-in-the-loop tests) exercises the real decode path.
// The acquisition thread reads with poll() bounded to 100 ms (the pump sees its stop
// flag); nothing allocates after open().
#include "drivers/source/source.hpp"
#include "drivers/usb_daq/decoded_frames.hpp"

#include <atomic>
#include <filesystem>
#include <memory>

namespace eical::drivers {

struct DaqStreamOptions {
  std::filesystem::path path = "/run/eical/daq.stream";
  double connect_timeout_s = 5.0;  // open(): the first packet within this time, else "no DAQ"
  double stall_timeout_s = 1.0;    // no bytes for this long while streaming: the source fails
};

class DaqStreamSource final : public Source {
 public:
  DaqStreamSource(dsp::RunMeta meta, DaqStreamOptions options);
  ~DaqStreamSource() override;

  // Opens the stream and waits for the first decoded sample; SourceError naming the path
  // and the cause otherwise.
  void open() override;
  [[nodiscard]] const dsp::RunMeta& meta() const override { return meta_; }
  std::size_t read(std::span<dsp::Frame> out) override;
  [[nodiscard]] bool at_end() const override { return false; }  // a DAQ streams until stopped
  [[nodiscard]] std::string_view name() const override { return "daq_stream"; }
  [[nodiscard]] Backpressure backpressure() const override { return Backpressure::drop_newest; }
  [[nodiscard]] SourceCounters counters() const override;

 private:
  // Reads what is there within `timeout_ms` into the decoder; false on timeout.
  bool pull(int timeout_ms);
  void close() noexcept;
  void publish_counters() noexcept;

  dsp::RunMeta meta_;
  DaqStreamOptions options_;
  usb_daq::DecodedFrames frames_;
  int fd_ = -1;
  std::int64_t last_data_ns_ = 0;
  std::atomic<std::uint64_t> decode_errors_{0}, lost_samples_{0}, dropped_{0};
};

}  // namespace eical::drivers
