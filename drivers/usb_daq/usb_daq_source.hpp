#pragma once
// The 24-bit multichannel DAQ on USB (libusb-1.0, bulk IN), decoded by usb_daq::Decoder.
// open() finds the device by vendor:product; an absent device is a SourceError that says
// so (with the number of USB devices visible), never a crash. Asynchronous transfers,
// allocated and submitted in open() and resubmitted from their completion callback (which
// libusb runs inside read() on the acquisition thread): libusb's synchronous
// libusb_bulk_transfer allocates a transfer on every call, this path allocates nothing
// after open().
#include "drivers/source/source.hpp"
#include "drivers/usb_daq/decoded_frames.hpp"

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

struct libusb_context;
struct libusb_device_handle;
struct libusb_transfer;

namespace eical::drivers {

struct UsbDaqOptions {
  std::uint16_t vendor_id = 0x1d50, product_id = 0x6161;
  unsigned char endpoint = 0x81;
  int timeout_ms = 200;  // read() waits at most this long for a transfer to complete
  int transfers = 4;     // kept in flight: the DAQ never waits for the host
  int transfer_bytes = 16384;
};

// "1d50:6161" → ids; throws SourceError on a malformed id.
UsbDaqOptions parse_usb_id(const std::string& id);

class UsbDaqSource final : public Source {
 public:
  UsbDaqSource(dsp::RunMeta meta, UsbDaqOptions options);
  ~UsbDaqSource() override;

  void open() override;
  [[nodiscard]] const dsp::RunMeta& meta() const override { return meta_; }
  std::size_t read(std::span<dsp::Frame> out) override;
  [[nodiscard]] bool at_end() const override { return false; }  // a DAQ streams until stopped
  [[nodiscard]] std::string_view name() const override { return "usb_daq"; }
  [[nodiscard]] Backpressure backpressure() const override { return Backpressure::drop_newest; }
  [[nodiscard]] SourceCounters counters() const override;

 private:
  static void on_transfer(libusb_transfer* t);  // libusb callback, acquisition thread
  void close() noexcept;
  void publish_counters() noexcept;

  dsp::RunMeta meta_;
  UsbDaqOptions options_;
  usb_daq::DecodedFrames frames_;  // decoder + fixed queue: read() never allocates
  libusb_context* ctx_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  std::vector<libusb_transfer*> transfers_;
  std::vector<std::vector<unsigned char>> buffers_;
  int in_flight_ = 0;
  int error_ = 0;  // the first failed transfer's libusb status (acquisition thread)
  std::atomic<std::uint64_t> decode_errors_{0}, lost_samples_{0}, dropped_{0};
};

}  // namespace eical::drivers
