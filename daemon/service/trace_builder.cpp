#include "daemon/service/trace_builder.hpp"

#include <algorithm>

namespace eical::daemon {
namespace {

std::size_t stride_for(std::size_t n, std::size_t max_points) {
  if (max_points == 0 || n <= max_points) return 1;
  return (n + max_points - 1) / max_points;
}

int axis_index(const std::string& axis) { return axis == "y" ? 1 : axis == "z" ? 2 : 0; }

}  // namespace

std::optional<drivers::dds::TraceMsg> make_trace(const dsp::Run& run, const dsp::Analysis& analysis,
                                                 std::size_t max_points) {
  drivers::dds::TraceMsg t;
  t.program_id = run.meta.id;
  t.program = dsp::program_kind_name(run.meta.program.kind);
  if (analysis.circle) {
    const auto& c = analysis.circle->trace;
    const std::size_t n = std::min(c.angle_deg.size(), c.radius_deviation_um.size());
    if (n == 0) return std::nullopt;
    const std::size_t k = stride_for(n, max_points);
    t.x_name = "angle_deg";
    t.y_name = "radius_deviation_um";
    for (std::size_t i = 0; i < n; i += k) {
      t.x.push_back(c.angle_deg[i]);
      t.y.push_back(c.radius_deviation_um[i]);
      t.series.push_back(i < c.revolution.size() ? c.revolution[i] : 0);
      t.cw.push_back(i < c.direction.size() && c.direction[i] == "cw");
    }
    t.decimation = static_cast<std::uint32_t>(k);
    return t;
  }
  const auto& m = analysis.measurement;
  const std::size_t n = std::min({m.sample_index.size(), m.pos_mm.size(), m.cmd_mm.size()});
  if (n == 0 || !(m.fs_hz > 0.0)) return std::nullopt;
  const std::size_t k = stride_for(n, max_points);
  const int ax = axis_index(run.meta.program.axis);
  t.x_name = "time_s";
  t.y_name = "deviation_um";  // measured − set-point along the program axis
  for (std::size_t i = 0; i < n; i += k) {
    t.x.push_back(static_cast<double>(m.sample_index[i] - m.sample_index[0]) / m.fs_hz);
    t.y.push_back((m.pos_mm[i][ax] - m.cmd_mm[i][ax]) * 1000.0);
    t.series.push_back(0);
  }
  t.decimation = static_cast<std::uint32_t>(k);
  return t;
}

}  // namespace eical::daemon
