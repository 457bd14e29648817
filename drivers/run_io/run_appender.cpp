#include "drivers/run_io/run_appender.hpp"

#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "drivers/run_io/sample_rows.hpp"
#include "dsp/core/error.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>
#include <stdexcept>

namespace eical::drivers {
namespace fs = std::filesystem;
namespace {

constexpr std::size_t kAppendChunkText = 1 << 20;  // bytes of text per chunk (a gzip member)

[[noreturn]] void fail_errno(const fs::path& p, const char* what, int err) {
  throw std::runtime_error(p.string() + ": " + what + ": " + std::strerror(err));
}

void pwrite_all(int fd, const fs::path& p, const unsigned char* data, std::size_t bytes, std::size_t offset) {
  for (std::size_t done = 0; done < bytes;) {
    const ssize_t w = ::pwrite(fd, data + done, bytes - done, static_cast<off_t>(offset + done));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) fail_errno(p, "write failed", w < 0 ? errno : ENOSPC);
    done += static_cast<std::size_t>(w);
  }
}

}  // namespace

RunAppender::RunAppender(fs::path parent, dsp::RunMeta meta, dsp::ChannelPresence channels, bool gzip)
    : parent_(std::move(parent)),
      meta_(std::move(meta)),
      channels_(channels),
      gzip_(gzip),
      samples_name_(gzip ? "samples.csv.gz" : "samples.csv"),
      text_(samples_header(channels)) {
  text_.reserve(kAppendChunkText + 4096);
  if (gzip_) {
    if (deflateInit2(&z_, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
      throw std::runtime_error("recording: cannot start gzip");
    z_ready_ = true;
  }
}

RunAppender::~RunAppender() {
  if (fd_ >= 0) ::close(fd_);
  std::error_code ec;
  if (committed_.empty() && !tmp_.empty()) fs::remove_all(tmp_, ec);
  if (z_ready_) deflateEnd(&z_);
}

fs::path RunAppender::samples_path() const { return (committed_.empty() ? tmp_ : committed_) / samples_name_; }

std::size_t RunAppender::held_bytes() const noexcept {
  std::size_t n = text_.size();
  for (const auto& c : held_) n += c.size();
  return n;
}

void RunAppender::append(const dsp::Frame& f) {
  append_sample_row(text_, f, meta_, channels_);
  ++frames_;
  synced_ = false;
  if (text_.size() < kAppendChunkText) return;
  seal();
  (void)write_held();  // a failure holds the chunk; the caller retries and reports
}

void RunAppender::seal() {
  if (text_.empty()) return;
  std::vector<unsigned char> chunk;
  if (!gzip_) {
    chunk.assign(text_.begin(), text_.end());
  } else {
    deflateReset(&z_);
    chunk.resize(deflateBound(&z_, static_cast<uLong>(text_.size())));
    z_.next_in = reinterpret_cast<Bytef*>(text_.data());
    z_.avail_in = static_cast<uInt>(text_.size());
    z_.next_out = chunk.data();
    z_.avail_out = static_cast<uInt>(chunk.size());
    if (deflate(&z_, Z_FINISH) != Z_STREAM_END) throw std::runtime_error("recording: gzip failed");
    chunk.resize(z_.total_out);
  }
  held_.push_back(std::move(chunk));
  text_.clear();
}

void RunAppender::ensure_file() {
  std::error_code ec;
  if (!committed_.empty()) return;  // the samples are in the run now (commit() makes it again if gone)
  if (fd_ >= 0) {
    if (!fs::exists(tmp_ / samples_name_, ec)) relocate();  // the directory was removed meanwhile
    return;
  }
  fs::create_directories(parent_, ec);  // like mkdir -p; errors surface below
  std::random_device rd;
  const fs::path tmp = parent_ / (".recording.tmp-" + std::to_string(rd()));
  if (::mkdir(tmp.c_str(), 0755) != 0) fail_errno(tmp, "cannot create", errno);
  const fs::path file = tmp / samples_name_;
  fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    const int err = errno;
    fs::remove_all(tmp, ec);
    fail_errno(file, "cannot create", err);
  }
  tmp_ = tmp;
}

void RunAppender::relocate() {
  std::error_code ec;
  fs::create_directories(parent_, ec);
  std::random_device rd;
  const fs::path tmp = parent_ / (".recording.tmp-" + std::to_string(rd()));
  if (::mkdir(tmp.c_str(), 0755) != 0) fail_errno(tmp, "cannot create", errno);
  const fs::path file = tmp / samples_name_;
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  try {
    if (fd < 0) fail_errno(file, "cannot create", errno);
    std::vector<unsigned char> buf(1 << 20);
    for (std::size_t off = 0; off < written_;) {  // the samples so far, from the file still open
      const ssize_t r = ::pread(fd_, buf.data(), std::min(buf.size(), written_ - off), static_cast<off_t>(off));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) fail_errno(samples_path(), "read back failed", r < 0 ? errno : EIO);
      pwrite_all(fd, file, buf.data(), static_cast<std::size_t>(r), off);
      off += static_cast<std::size_t>(r);
    }
  } catch (...) {
    if (fd >= 0) ::close(fd);
    fs::remove_all(tmp, ec);
    throw;
  }
  ::close(fd_);
  fd_ = fd;
  tmp_ = tmp;
  committed_.clear();
  synced_ = false;
}

bool RunAppender::write_held() {
  if (held_.empty()) {
    error_.clear();
    return true;
  }
  try {
    ensure_file();
    while (!held_.empty()) {
      const auto& chunk = held_.front();
      pwrite_all(fd_, samples_path(), chunk.data(), chunk.size(), written_);
      written_ += chunk.size();
      held_.pop_front();
      synced_ = false;
    }
  } catch (const std::exception& e) {
    if (fd_ >= 0 && ::ftruncate(fd_, static_cast<off_t>(written_)) != 0) {
      // What part of the chunk went out stays beyond `written_`: written over when it goes again.
    }
    error_ = e.what();
    return false;
  }
  error_.clear();
  return true;
}

void RunAppender::finish_samples() {
  seal();
  if (!write_held()) throw std::runtime_error(error_);
  ensure_file();  // the temporary directory removed meanwhile: made again
  if (synced_) return;
  if (::fsync(fd_) != 0) fail_errno(samples_path(), "fsync failed", errno);
  sync_dir(samples_path().parent_path());
  synced_ = true;
}

dsp::Run RunAppender::load() const {
  dsp::Run run;
  run.meta = meta_;
  SampleReader reader(samples_path(), run.meta, run.channels);
  dsp::Frame f;
  run.frames.reserve(frames_);
  while (reader.next(f)) run.frames.push_back(f);
  for (int s = 0; s < 2; ++s) run.meta.sensor_present[s] = reader.sensor_seen(s);
  for (auto& fr : run.frames) absent_sensors_are_not_missing(run.meta.sensor_present, fr);
  return run;
}

void RunAppender::rewrite(const dsp::Run& run) {
  if (!committed_.empty()) throw std::logic_error("recording: samples rewritten after the commit");
  if (fd_ >= 0 && ::ftruncate(fd_, 0) != 0) fail_errno(samples_path(), "cannot truncate", errno);
  written_ = frames_ = 0;
  held_.clear();
  meta_ = run.meta;
  channels_ = run.channels;
  text_ = samples_header(channels_);
  for (const auto& f : run.frames) append(f);
  finish_samples();
}

void RunAppender::commit(const dsp::RunMeta& meta, const fs::path& dir) {
  std::error_code ec;
  if (!committed_.empty()) {
    if (fs::exists(committed_ / "run.toml", ec)) return;  // in place
    relocate();                                           // removed since: made again from the samples still open
  }
  finish_samples();
  if (!fs::exists(tmp_ / samples_name_, ec)) relocate(), finish_samples();
  write_synced(tmp_ / "run.toml", run_toml_text(meta));
  sync_dir(tmp_);
  if (fs::exists(dir, ec)) throw std::runtime_error(dir.string() + ": a run already exists here (not overwritten)");
  if (::rename(tmp_.c_str(), dir.c_str()) != 0) fail_errno(dir, "cannot rename the new run into place", errno);
  committed_ = dir;
  tmp_.clear();
  sync_dir(dir.parent_path().empty() ? fs::path(".") : dir.parent_path());
}

}  // namespace eical::drivers
