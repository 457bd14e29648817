#include "tools/run_files.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace eical::tools {

void write_file_atomic(const std::filesystem::path& file, const std::string& text) {
  const std::filesystem::path tmp = file.string() + ".tmp";
  {
    std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
    if (!os) throw std::runtime_error(tmp.string() + ": cannot create: " + std::strerror(errno));
    os << text;
    if (!os.flush()) throw std::runtime_error(tmp.string() + ": write failed: " + std::strerror(errno));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) throw std::runtime_error(file.string() + ": " + ec.message());
}

std::string summary_text(const dsp::Run& run, const dsp::Analysis& a) {
  std::string o;
  char b[256];
  std::snprintf(b, sizeof b, "run %s (%s, %zu samples at %.0f Hz)\n", run.meta.id.c_str(), run.meta.program.kind.c_str(),
                run.frame_count(), run.meta.acquisition.fs_hz);
  o += b;
  if (a.circle) {
    std::snprintf(b, sizeof b, "  mean radius deviation   %8.2f um\n  circular deviation G    %8.2f um  (%d revolutions, %s)\n",
                  a.circle->radius_mean_deviation_um, a.circle->circular_deviation_G_um, a.circle->revolutions, a.circle->direction.c_str());
    o += b;
  }
  if (a.circle_accuracy_rms_um) {
    std::snprintf(b, sizeof b, "  accuracy vs reference   %8.2f um RMS of (measured - true) radius deviation\n", *a.circle_accuracy_rms_um);
    o += b;
  }
  if (a.step) {
    std::snprintf(b, sizeof b, "  end-position error      %8.2f um\n  scatter                 %8.2f um\n  overshoot               %8.2f um\n",
                  a.step->end_position_error_um, a.step->scatter_um, a.step->overshoot_um);
    o += b;
  }
  o += a.degraded ? "  result DEGRADED:\n" : "  quality: ok\n";
  for (const auto& f : a.flags) o += "    - " + f + "\n";
  return o;
}

}  // namespace eical::tools
