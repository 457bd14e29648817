#include "drivers/run_io/run_stream.hpp"

#include "drivers/config/strict_toml.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "dsp/core/error.hpp"

#include <zlib.h>

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

namespace eical::drivers {
namespace fs = std::filesystem;
namespace {

// About how many rows a samples file holds: its size over the length of its first rows
// (a plain file); compressed, gzip's record of the uncompressed size (below 4 GiB; of the
// last member only when the file holds several, as eicald writes them) or the ratio of the
// first megabyte, whichever is larger. A reserve, not a limit: 0 when it cannot tell.
std::size_t estimate_rows(const fs::path& file) {
  std::error_code ec;
  const auto bytes = static_cast<double>(fs::file_size(file, ec));
  if (ec || bytes <= 0) return 0;
  const bool gzip = file.extension() == ".gz";
  double plain = gzip ? 0.0 : bytes;
  if (gzip) {
    std::ifstream is(file, std::ios::binary);
    is.seekg(-4, std::ios::end);
    unsigned char b[4] = {};
    if (is.read(reinterpret_cast<char*>(b), 4)) {
      const std::uint32_t size_mod_4g =
          b[0] | (std::uint32_t{b[1]} << 8) | (std::uint32_t{b[2]} << 16) | (std::uint32_t{b[3]} << 24);
      const auto isize = static_cast<double>(size_mod_4g);
      if (bytes * 40.0 <= 4294967296.0 && isize >= bytes) plain = isize;  // else it may have wrapped
    }
  }
  gzFile gz = gzopen(file.c_str(), "rb");
  if (!gz) return 0;
  char line[4096];
  double len = 0;
  int rows = 0;
  for (int i = 0; i < 201 && gzgets(gz, line, sizeof line); ++i)
    if (i > 0) len += static_cast<double>(std::char_traits<char>::length(line)), ++rows;  // not the header
  if (gzip) {  // the compression ratio over the first megabyte
    std::vector<char> buf(1 << 16);
    double text = static_cast<double>(gztell(gz));
    for (int k = 0; k < 16; ++k) {
      const int n = gzread(gz, buf.data(), static_cast<unsigned>(buf.size()));
      if (n <= 0) break;
      text += n;
    }
    const auto packed = static_cast<double>(gzoffset(gz));
    if (packed > 0) plain = std::max(plain, bytes * text / packed);
  }
  gzclose(gz);
  if (rows == 0 || len <= 0 || plain <= 0) return 0;
  return static_cast<std::size_t>(plain / (len / rows) * 1.1) + 16;  // the time column grows a digit or two
}

}  // namespace

RunStream::RunStream(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw dsp::InputError(dir.string() + ": not a run directory");
  header_.meta = read_run_meta(dir / "run.toml");
  file_ = samples_file(dir);
  {  // the header line and the first row: channels, and the presence assumed until a replay
    SampleReader reader(file_, header_.meta, header_.channels);
    dsp::Frame f;
    reader.next(f);
    for (int s = 0; s < 2; ++s) header_.meta.sensor_present[s] = reader.sensor_seen(s);
    if (!header_.meta.sensor_present[0] && !header_.meta.sensor_present[1])
      header_.meta.sensor_present[0] = header_.meta.sensor_present[1] = true;
  }
  const fs::path truth = dir / "truth.toml";
  if (fs::exists(truth)) {
    (void)StrictTable::parse_file(truth.string());  // must at least be valid TOML
    std::ifstream is(truth, std::ios::binary);
    header_.truth_toml = std::string(std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>());
  }
  size_hint_ = estimate_rows(file_);
}

void RunStream::replay(const std::function<void(const dsp::Frame&)>& frame) {
  // The rows are parsed on a thread of their own and handed over in blocks: parsing is a
  // quarter of an analysis' work, and runs beside the pipeline when a core is free.
  constexpr std::size_t kBlockFrames = 8192, kBlocks = 4;
  std::mutex mu;
  std::condition_variable cv;
  std::deque<std::vector<dsp::Frame>> full, empty;
  for (std::size_t i = 0; i < kBlocks; ++i) empty.emplace_back().reserve(kBlockFrames);
  bool done = false, stop = false;
  std::exception_ptr error;
  bool seen[2] = {false, false};
  std::thread reader([&] {
    try {
      dsp::ChannelPresence channels;
      SampleReader rows(file_, header_.meta, channels);
      for (bool more = true; more;) {
        std::vector<dsp::Frame> block;
        {
          std::unique_lock lk(mu);
          cv.wait(lk, [&] { return stop || !empty.empty(); });
          if (stop) return;
          block = std::move(empty.front());
          empty.pop_front();
        }
        block.clear();
        dsp::Frame f;
        while (block.size() < kBlockFrames && (more = rows.next(f))) block.push_back(f);
        if (!more)
          for (int s = 0; s < 2; ++s) seen[s] = rows.sensor_seen(s);
        std::lock_guard lk(mu);
        full.push_back(std::move(block));
        cv.notify_all();
      }
    } catch (...) {
      std::lock_guard lk(mu);
      error = std::current_exception();
    }
    std::lock_guard lk(mu);
    done = true;
    cv.notify_all();
  });
  std::size_t n = 0;
  try {
    for (;;) {
      std::vector<dsp::Frame> block;
      {
        std::unique_lock lk(mu);
        cv.wait(lk, [&] { return !full.empty() || done; });
        if (full.empty()) break;  // done: every block handed over
        block = std::move(full.front());
        full.pop_front();
      }
      for (dsp::Frame& f : block) {
        absent_sensors_are_not_missing(header_.meta.sensor_present, f);
        frame(f);
      }
      n += block.size();
      std::lock_guard lk(mu);
      empty.push_back(std::move(block));
      cv.notify_all();
    }
  } catch (...) {
    {
      std::lock_guard lk(mu);
      stop = true;
      cv.notify_all();
    }
    reader.join();
    throw;
  }
  reader.join();
  if (error) std::rethrow_exception(error);  // the row that was wrong (file, line, column)
  for (int s = 0; s < 2; ++s) seen_[s] = seen[s];
  if (!seen_[0] && !seen_[1])
    throw dsp::InputError(file_.string() + ": no accelerometer data (every table_* and head_* field is empty)");
  header_.streamed_frames = n;
  replayed_ = true;
}

bool RunStream::presence_held() {
  if (!replayed_) return true;
  const bool held = seen_[0] == header_.meta.sensor_present[0] && seen_[1] == header_.meta.sensor_present[1];
  for (int s = 0; s < 2; ++s) header_.meta.sensor_present[s] = seen_[s];
  return held;
}

dsp::Analysis analyze_stream(RunStream& run, const dsp::AnalysisOptions& options, const dsp::StreamOptions& stream) {
  dsp::Analysis a = dsp::analyze_stream(run.header(), run, options, stream);
  if (run.presence_held()) return a;
  return dsp::analyze_stream(run.header(), run, options, stream);  // a sensor the first row did not show
}

}  // namespace eical::drivers
