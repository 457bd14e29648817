#include "drivers/run_io/line_source.hpp"

#include "dsp/core/error.hpp"

#include <cerrno>
#include <cstring>

namespace eical::drivers {

LineSource::LineSource(const std::filesystem::path& file) : name_(file.string()), buf_(1 << 20) {
  gz_ = gzopen(name_.c_str(), "rb");
  if (!gz_) throw dsp::InputError(name_ + ": cannot open: " + std::strerror(errno));
  gzbuffer(gz_, 1 << 18);
}

LineSource::~LineSource() {
  if (gz_) gzclose(gz_);
}

bool LineSource::fill() {
  if (eof_) return false;
  const int n = gzread(gz_, buf_.data(), static_cast<unsigned>(buf_.size()));
  if (n < 0) {
    int code = 0;
    const char* msg = gzerror(gz_, &code);
    throw dsp::InputError(name_ + ": read error: " + (msg ? msg : "unknown"));
  }
  if (n == 0) {
    // gzread reports a truncated gzip stream as end of data with Z_BUF_ERROR.
    int code = 0;
    const char* msg = gzerror(gz_, &code);
    if (code != Z_OK && code != Z_STREAM_END)
      throw dsp::InputError(name_ + ": truncated or corrupt gzip stream (" + (msg ? msg : "unknown") + ")");
    eof_ = true;
    return false;
  }
  begin_ = 0;
  end_ = static_cast<std::size_t>(n);
  return true;
}

bool LineSource::next(std::string_view& line) {
  carry_.clear();
  for (;;) {
    if (begin_ == end_ && !fill()) {
      if (carry_.empty()) return false;
      ++line_no_;
      last_had_newline_ = false;
      line = carry_;
      return true;
    }
    const char* start = buf_.data() + begin_;
    const void* nl = std::memchr(start, '\n', end_ - begin_);
    if (nl) {
      const auto len = static_cast<std::size_t>(static_cast<const char*>(nl) - start);
      begin_ += len + 1;
      ++line_no_;
      last_had_newline_ = true;
      if (carry_.empty()) {
        line = std::string_view(start, len);
      } else {
        carry_.append(start, len);
        line = carry_;
      }
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      return true;
    }
    carry_.append(start, end_ - begin_);  // a line across the block boundary
    begin_ = end_;
  }
}

}  // namespace eical::drivers
