#include "drivers/run_io/file_spill.hpp"

#include "dsp/core/error.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace eical::drivers {
namespace {

class FileSpill final : public dsp::Spill {
 public:
  explicit FileSpill(const std::filesystem::path& dir) : dir_(dir) {
    fd_ = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    if (fd_ < 0) {  // a file system without O_TMPFILE: a named file, unlinked at once
      std::string name = (dir / "eical-spill-XXXXXX").string();
      fd_ = ::mkstemp(name.data());
      if (fd_ >= 0) ::unlink(name.c_str());
    }
    if (fd_ < 0)
      throw dsp::InputError("spill: cannot create a temporary file in " + dir.string() + ": " + std::strerror(errno));
    buf_.reserve(kBuffer);
  }
  ~FileSpill() override {
    if (fd_ >= 0) ::close(fd_);
  }
  FileSpill(const FileSpill&) = delete;
  FileSpill& operator=(const FileSpill&) = delete;

  void write(const void* data, std::size_t bytes) override {
    const auto* p = static_cast<const unsigned char*>(data);
    while (bytes > 0) {
      const std::size_t take = std::min(bytes, kBuffer - buf_.size());
      buf_.insert(buf_.end(), p, p + take);
      p += take, bytes -= take;
      if (buf_.size() == kBuffer) flush();
    }
  }
  void read(std::size_t record_bytes, const std::function<void(const void*, std::size_t)>& block) override {
    flush();
    const std::size_t chunk = std::max<std::size_t>(1, kBuffer / std::max<std::size_t>(1, record_bytes)) *
                              std::max<std::size_t>(1, record_bytes);
    std::vector<unsigned char> in(chunk);
    for (std::size_t off = 0; off < size_;) {
      const std::size_t want = std::min(chunk, size_ - off);
      std::size_t got = 0;
      while (got < want) {
        const ssize_t r = ::pread(fd_, in.data() + got, want - got, static_cast<off_t>(off + got));
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0)
          throw dsp::InputError("spill in " + dir_.string() +
                                ": read failed: " + (r < 0 ? std::strerror(errno) : "end of file"));
        got += static_cast<std::size_t>(r);
      }
      block(in.data(), want);
      off += want;
    }
  }
  void read_at(std::size_t offset, void* out, std::size_t bytes) override {
    flush();
    if (offset + bytes > size_) throw dsp::InputError("spill in " + dir_.string() + ": read beyond what was written");
    auto* p = static_cast<unsigned char*>(out);
    for (std::size_t got = 0; got < bytes;) {
      const ssize_t r = ::pread(fd_, p + got, bytes - got, static_cast<off_t>(offset + got));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0)
        throw dsp::InputError("spill in " + dir_.string() +
                              ": read failed: " + (r < 0 ? std::strerror(errno) : "end of file"));
      got += static_cast<std::size_t>(r);
    }
  }
  [[nodiscard]] std::size_t bytes() const override { return size_ + buf_.size(); }

 private:
  void flush() {
    std::size_t done = 0;
    while (done < buf_.size()) {
      const ssize_t w = ::pwrite(fd_, buf_.data() + done, buf_.size() - done, static_cast<off_t>(size_ + done));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) throw dsp::InputError("spill in " + dir_.string() + ": write failed: " + std::strerror(errno));
      done += static_cast<std::size_t>(w);
    }
    size_ += buf_.size();
    buf_.clear();
  }
  static constexpr std::size_t kBuffer = 1 << 20;
  std::filesystem::path dir_;
  int fd_ = -1;
  std::size_t size_ = 0;  // bytes in the file
  std::vector<unsigned char> buf_;
};

}  // namespace

dsp::SpillFactory file_spills(std::filesystem::path dir) {
  return [dir = std::move(dir)] { return std::make_unique<FileSpill>(dir); };
}

std::filesystem::path default_spill_dir() {
  const char* t = std::getenv("TMPDIR");
  return t && *t ? std::filesystem::path(t) : std::filesystem::path("/var/tmp");
}

}  // namespace eical::drivers
