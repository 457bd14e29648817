#include "drivers/usb_daq/usb_daq_source.hpp"

#include <libusb.h>

#include <charconv>
#include <cstdio>

namespace eical::drivers {

UsbDaqOptions parse_usb_id(const std::string& id) {
  UsbDaqOptions o;
  const auto colon = id.find(':');
  unsigned v = 0, p = 0;
  const bool ok = colon == 4 && id.size() == 9 && std::from_chars(id.data(), id.data() + 4, v, 16).ec == std::errc() &&
                  std::from_chars(id.data() + 5, id.data() + 9, p, 16).ec == std::errc();
  if (!ok) throw SourceError("usb_daq: USB id '" + id + "' is not vendor:product in hex (e.g. 1d50:6161)");
  o.vendor_id = static_cast<std::uint16_t>(v);
  o.product_id = static_cast<std::uint16_t>(p);
  return o;
}

UsbDaqSource::UsbDaqSource(dsp::RunMeta meta, UsbDaqOptions options)
    : meta_(std::move(meta)), options_(options), frames_(static_cast<int>(meta_.psd.size())) {}

UsbDaqSource::~UsbDaqSource() { close(); }

void UsbDaqSource::close() noexcept {
  // Cancel what is in flight and let libusb deliver the cancellations before freeing.
  for (auto* t : transfers_) (void)libusb_cancel_transfer(t);
  for (int i = 0; i < 100 && in_flight_ > 0 && ctx_; ++i) {
    timeval tv{0, 10000};
    (void)libusb_handle_events_timeout_completed(ctx_, &tv, nullptr);
  }
  for (auto* t : transfers_) libusb_free_transfer(t);
  transfers_.clear();
  buffers_.clear();
  in_flight_ = 0;
  if (handle_) {
    libusb_release_interface(handle_, 0);
    libusb_close(handle_);
    handle_ = nullptr;
  }
  if (ctx_) libusb_exit(ctx_), ctx_ = nullptr;
}

void UsbDaqSource::open() {
  close();  // a reopen (after the DAQ failed) starts from scratch
  frames_.reset();
  error_ = 0;
  if (const int rc = libusb_init(&ctx_); rc != 0)
    throw SourceError(std::string("usb_daq: libusb_init failed: ") + libusb_error_name(rc));
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(ctx_, &list);
  if (n >= 0) libusb_free_device_list(list, 1);
  handle_ = libusb_open_device_with_vid_pid(ctx_, options_.vendor_id, options_.product_id);
  if (!handle_) {
    char id[16];
    std::snprintf(id, sizeof id, "%04x:%04x", options_.vendor_id, options_.product_id);
    throw SourceError(std::string("usb_daq: no DAQ with USB id ") + id + " found (" + std::to_string(n < 0 ? 0 : n) +
                      " USB devices visible)");
  }
  if (const int rc = libusb_claim_interface(handle_, 0); rc != 0)
    throw SourceError(std::string("usb_daq: cannot claim the DAQ's interface: ") + libusb_error_name(rc));
  for (int k = 0; k < options_.transfers; ++k) {
    buffers_.emplace_back(static_cast<std::size_t>(options_.transfer_bytes));
    libusb_transfer* t = libusb_alloc_transfer(0);
    if (!t) throw SourceError("usb_daq: cannot allocate a USB transfer");
    transfers_.push_back(t);
    // No timeout on the transfer itself: read() bounds its wait instead.
    libusb_fill_bulk_transfer(t, handle_, options_.endpoint, buffers_.back().data(), options_.transfer_bytes,
                              &UsbDaqSource::on_transfer, this, 0);
    if (const int rc = libusb_submit_transfer(t); rc != 0)
      throw SourceError(std::string("usb_daq: cannot start reading the DAQ: ") + libusb_error_name(rc));
    ++in_flight_;
  }
}

void UsbDaqSource::on_transfer(libusb_transfer* t) {
  auto* self = static_cast<UsbDaqSource*>(t->user_data);
  --self->in_flight_;
  if (t->status == LIBUSB_TRANSFER_COMPLETED) {
    self->frames_.feed(std::span<const std::uint8_t>(t->buffer, static_cast<std::size_t>(t->actual_length)));
    if (self->error_ == 0 && libusb_submit_transfer(t) == 0) ++self->in_flight_;
    return;
  }
  if (t->status != LIBUSB_TRANSFER_CANCELLED && self->error_ == 0) self->error_ = static_cast<int>(t->status);
}

std::size_t UsbDaqSource::read(std::span<dsp::Frame> out) {
  if (frames_.size() < out.size()) {
    timeval tv{options_.timeout_ms / 1000, (options_.timeout_ms % 1000) * 1000};
    const int rc = libusb_handle_events_timeout_completed(ctx_, &tv, nullptr);
    if (rc != 0 && rc != LIBUSB_ERROR_INTERRUPTED) throw SourceError(std::string("usb_daq: ") + libusb_error_name(rc));
    publish_counters();
    // libusb_error_name also names transfer states (LIBUSB_TRANSFER_NO_DEVICE, ...).
    if (error_ != 0 && frames_.size() == 0)
      throw SourceError(std::string("usb_daq: bulk transfer failed: ") + libusb_error_name(error_));
  }
  return frames_.pop(out);
}

void UsbDaqSource::publish_counters() noexcept {
  const auto& s = frames_.stats();
  decode_errors_.store(s.crc_errors + s.unknown_packets, std::memory_order_relaxed);
  lost_samples_.store(s.lost_samples, std::memory_order_relaxed);
  dropped_.store(frames_.dropped(), std::memory_order_relaxed);
}

SourceCounters UsbDaqSource::counters() const {
  SourceCounters c;
  c.decode_errors = decode_errors_.load(std::memory_order_relaxed);
  c.lost_samples = lost_samples_.load(std::memory_order_relaxed);
  c.dropped_frames = dropped_.load(std::memory_order_relaxed);
  return c;
}

}  // namespace eical::drivers
