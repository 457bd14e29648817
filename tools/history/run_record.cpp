#include "tools/history/run_record.hpp"

#include "drivers/config/sensor_calibration.hpp"
#include "drivers/results/result_json.hpp"
#include "drivers/results/software_version.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "history/record/result_record.hpp"
#include "history/record/utc_time.hpp"

#include <sys/stat.h>

#include <ctime>
#include <fstream>
#include <stdexcept>

namespace eical::tools {
namespace fs = std::filesystem;

namespace {

// run.toml without `created`: its modification time stands in.
std::string file_time_utc(const fs::path& p) {
  struct stat st {};
  return history::utc_text(::stat(p.c_str(), &st) == 0 ? st.st_mtime : std::time(nullptr));
}

}  // namespace

history::Record run_record(const fs::path& run_dir, const AddOptions& options) {
  const fs::path dir = fs::absolute(run_dir);
  const dsp::RunMeta meta = drivers::read_run_meta(dir / "run.toml");
  nlohmann::json doc;
  std::string calibration, software;
  const fs::path result = dir / "result.json";
  if (options.calibration.empty() && fs::exists(result)) {
    std::ifstream is(result);
    doc = nlohmann::json::parse(is, nullptr, false);
    if (doc.is_discarded()) throw std::runtime_error(result.string() + ": not JSON");
  } else {
    dsp::Run run = drivers::read_run(dir);
    dsp::AnalysisOptions opt;
    if (!options.calibration.empty()) {
      const auto cal = drivers::read_sensor_calibration(options.calibration, run.meta);
      drivers::apply_calibration(cal, run.meta, opt);
      calibration = cal.method + ": " + fs::absolute(options.calibration).string() + " (run " + cal.run_id + ")";
    }
    doc = drivers::result_json(run, dsp::analyze_run(run, opt));
    software = drivers::software_version();
  }
  history::Provenance p;
  p.machine = options.machine.empty() ? meta.machine.name : options.machine;
  p.measured_at = meta.created.empty() ? file_time_utc(dir / "run.toml") : meta.created;
  p.run_path = dir.string();
  if (!software.empty()) p.software_version = software;
  p.sensor_calibration = calibration;
  try {
    return history::record_from_result(doc, p);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(dir.string() + ": " + e.what());
  }
}

}  // namespace eical::tools
