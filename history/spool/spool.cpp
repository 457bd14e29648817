#include "history/spool/spool.hpp"

#include "history/record/record_json.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace eical::history {
namespace fs = std::filesystem;

namespace {

constexpr const char* kFormat = "eical-history-spool/1";

[[noreturn]] void sys_fail(const fs::path& p, const char* what, int err) {
  throw std::runtime_error(p.string() + ": " + what + ": " + std::strerror(err));
}

void fsync_dir(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) sys_fail(dir, "cannot open", errno);
  const int rc = ::fsync(fd), err = errno;
  ::close(fd);
  if (rc != 0) sys_fail(dir, "fsync", err);
}

void write_durable(const fs::path& file, const std::string& text) {
  const fs::path tmp = file.parent_path() / ("." + file.filename().string() + ".tmp");
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0640);
  if (fd < 0) sys_fail(tmp, "cannot create", errno);
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      sys_fail(tmp, "write failed", err);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    sys_fail(tmp, "fsync", err);
  }
  ::close(fd);
  if (::rename(tmp.c_str(), file.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    sys_fail(file, "rename", err);
  }
  fsync_dir(file.parent_path());
}

}  // namespace

fs::path Spool::put(const Record& r) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (!fs::is_directory(dir_))
    throw std::runtime_error(dir_.string() + ": cannot create the spool directory" + (ec ? ": " + ec.message() : ""));
  static std::atomic<unsigned> seq{0};
  const auto ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  char name[80];
  std::snprintf(name, sizeof name, "%020lld-%d-%u.json", static_cast<long long>(ns), static_cast<int>(::getpid()),
                seq++);
  const fs::path file = dir_ / name;
  write_durable(file, nlohmann::json{{"format", kFormat}, {"record", record_json(r)}}.dump() + "\n");
  return file;
}

std::vector<fs::path> Spool::waiting() const {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir_, ec)) {
    const std::string n = e.path().filename().string();
    if (e.is_regular_file() && n[0] != '.' && e.path().extension() == ".json") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

Record Spool::read(const fs::path& file) {
  std::ifstream is(file);
  if (!is) throw std::runtime_error(file.string() + ": cannot read");
  const auto j = nlohmann::json::parse(is, nullptr, false);
  if (j.is_discarded()) throw std::runtime_error(file.string() + ": not JSON");
  if (!j.is_object() || j.value("format", "") != kFormat || !j.contains("record"))
    throw std::runtime_error(file.string() + ": not an " + std::string(kFormat) + " file");
  try {
    return record_from_json(j["record"]);
  } catch (const std::exception& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  }
}

void Spool::remove(const fs::path& file) const {
  std::error_code ec;
  fs::remove(file, ec);
}

fs::path Spool::set_aside(const fs::path& file) const {
  const fs::path bad = dir_ / "bad";
  std::error_code ec;
  fs::create_directories(bad, ec);
  const fs::path to = bad / file.filename();
  fs::rename(file, to, ec);
  return ec ? file : to;
}

}  // namespace eical::history
