#include "daemon/service/history_hook.hpp"

#include "daemon/system/log.hpp"
#include "drivers/results/result_json.hpp"
#include "drivers/results/software_version.hpp"
#include "history/record/result_record.hpp"

namespace eical::daemon {

HistoryHook::HistoryHook(const HistoryConfig& config, std::string sensor_calibration)
    : sensor_calibration_(std::move(sensor_calibration)),
      sink_({config.db, config.spool_dir, config.retry_s, /*create=*/true},
            [](history::Sink::Level level, const std::string& m) {
              log(level == history::Sink::Level::error ? LogLevel::error : LogLevel::notice, "%s", m.c_str());
            }) {}

void HistoryHook::append(const dsp::Run& run, const dsp::Analysis& analysis, const std::filesystem::path& run_dir) {
  try {
    std::error_code ec;
    const auto path = std::filesystem::absolute(run_dir, ec);
    sink_.submit(history::record_from_result(drivers::result_json(run, analysis),
                                             {run.meta.machine.name, run.meta.created, (ec ? run_dir : path).string(),
                                              std::string(drivers::software_version()), sensor_calibration_}));
  } catch (const std::exception& e) {
    log(LogLevel::error, "history: result %s not recorded in the history: %s (its run directory keeps it)",
        run.meta.id.c_str(), e.what());
  }
}

}  // namespace eical::daemon
