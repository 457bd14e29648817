#include "drivers/run_io/file_spill.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace eical::drivers {
namespace {

constexpr std::size_t kBuffer = 1 << 20;
constexpr std::size_t kInFlight = 2;  // full buffers a spill may have queued before write() waits

class FileSpill;

// One thread writes the full buffers of every spill of a factory, in order: copying them
// into the page cache (about a quarter of a long analysis' time when the analysing thread
// did it) then runs beside the analysis.
class SpillIo {
 public:
  struct Job {
    FileSpill* spill;
    std::vector<unsigned char> data;
    std::size_t offset;
  };
  ~SpillIo() {
    {
      std::lock_guard lk(mu_);
      stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  void submit(Job job) {
    {
      std::lock_guard lk(mu_);
      if (!thread_.joinable()) thread_ = std::thread([this] { loop(); });
      queue_.push_back(std::move(job));
    }
    cv_.notify_all();
  }

 private:
  void loop();
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Job> queue_;
  bool stop_ = false;
  std::thread thread_;
};

class FileSpill final : public dsp::Spill {
 public:
  FileSpill(const std::filesystem::path& dir, std::shared_ptr<SpillIo> io) : dir_(dir), io_(std::move(io)) {
    fd_ = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    if (fd_ < 0) {  // a file system without O_TMPFILE: a named file, unlinked at once
      std::string name = (dir / "eical-spill-XXXXXX").string();
      fd_ = ::mkstemp(name.data());
      if (fd_ >= 0) ::unlink(name.c_str());
    }
    if (fd_ < 0)
      throw std::runtime_error("spill: cannot create a temporary file in " + dir.string() + ": " +
                               std::strerror(errno));
    buf_.reserve(kBuffer);
  }
  ~FileSpill() override {
    std::unique_lock lk(mu_);
    done_.wait(lk, [&] { return pending_ == 0; });  // the I/O thread writes into fd_
    lk.unlock();
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
      if (buf_.size() == kBuffer) hand_over();
    }
  }
  void read(std::size_t record_bytes, const std::function<void(const void*, std::size_t)>& block) override {
    flush();
    const std::size_t chunk = std::max<std::size_t>(1, kBuffer / std::max<std::size_t>(1, record_bytes)) *
                              std::max<std::size_t>(1, record_bytes);
    std::vector<unsigned char> in(std::min(chunk, std::max<std::size_t>(size_, 1)));
    for (std::size_t off = 0; off < size_;) {
      const std::size_t want = std::min(in.size(), size_ - off);
      pread_all(in.data(), want, off);
      block(in.data(), want);
      off += want;
    }
  }
  void read_at(std::size_t offset, void* out, std::size_t bytes) override {
    flush();
    if (offset + bytes > size_)
      throw std::runtime_error("spill in " + dir_.string() + ": read beyond what was written");
    pread_all(out, bytes, offset);
  }
  [[nodiscard]] std::size_t bytes() const override { return size_ + buf_.size(); }

  // I/O thread: writes one job's bytes at its offset.
  void write_job(SpillIo::Job& job) {
    std::string error;
    for (std::size_t done = 0; done < job.data.size();) {
      const ssize_t w =
          ::pwrite(fd_, job.data.data() + done, job.data.size() - done, static_cast<off_t>(job.offset + done));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) {
        error = std::string("write failed: ") + std::strerror(w < 0 ? errno : ENOSPC);
        break;
      }
      done += static_cast<std::size_t>(w);
    }
    job.data.clear();
    std::lock_guard lk(mu_);
    if (!error.empty() && error_.empty()) error_ = error;
    free_.push_back(std::move(job.data));  // its capacity serves the next buffer
    --pending_;
    done_.notify_all();
  }

 private:
  // The full (or last) buffer to the I/O thread; a buffer it has written back in its place.
  void hand_over() {
    if (buf_.empty()) return;
    std::vector<unsigned char> next;
    {
      std::unique_lock lk(mu_);
      done_.wait(lk, [&] { return pending_ < kInFlight; });
      throw_if_failed();
      if (!free_.empty()) next = std::move(free_.back()), free_.pop_back();
      ++pending_;
    }
    const std::size_t offset = size_;
    size_ += buf_.size();
    io_->submit({this, std::move(buf_), offset});
    buf_ = std::move(next);
    buf_.clear();
    buf_.reserve(kBuffer);
  }
  // Everything written is in the file.
  void flush() {
    hand_over();
    std::unique_lock lk(mu_);
    done_.wait(lk, [&] { return pending_ == 0; });
    throw_if_failed();
  }
  void throw_if_failed() const {
    if (!error_.empty()) throw std::runtime_error("spill in " + dir_.string() + ": " + error_);
  }
  void pread_all(void* out, std::size_t bytes, std::size_t offset) const {
    auto* p = static_cast<unsigned char*>(out);
    for (std::size_t got = 0; got < bytes;) {
      const ssize_t r = ::pread(fd_, p + got, bytes - got, static_cast<off_t>(offset + got));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0)
        throw std::runtime_error("spill in " + dir_.string() +
                                 ": read failed: " + (r < 0 ? std::strerror(errno) : "end of file"));
      got += static_cast<std::size_t>(r);
    }
  }

  std::filesystem::path dir_;
  std::shared_ptr<SpillIo> io_;
  int fd_ = -1;
  std::size_t size_ = 0;  // bytes handed to the file (written, or queued at their offset)
  std::vector<unsigned char> buf_;
  std::mutex mu_;
  std::condition_variable done_;
  std::size_t pending_ = 0;                       // buffers queued or being written
  std::vector<std::vector<unsigned char>> free_;  // written buffers, for reuse
  std::string error_;                             // the first write that failed
};

void SpillIo::loop() {
  for (;;) {
    Job job;
    {
      std::unique_lock lk(mu_);
      cv_.wait(lk, [&] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stop_, and every spill waited for its writes before it went
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    job.spill->write_job(job);
  }
}

}  // namespace

dsp::SpillFactory file_spills(std::filesystem::path dir) {
  auto io = std::make_shared<SpillIo>();
  return [dir = std::move(dir), io] { return std::make_unique<FileSpill>(dir, io); };
}

std::filesystem::path default_spill_dir() {
  const char* t = std::getenv("TMPDIR");
  return t && *t ? std::filesystem::path(t) : std::filesystem::path("/var/tmp");
}

}  // namespace eical::drivers
