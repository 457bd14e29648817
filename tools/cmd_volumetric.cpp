// eical volumetric: deviation vectors of a 3-axis machine from its 21-parameter model
// (seed 004). Model file eical-volumetric/1 (TOML), points CSV x,y,z,xp,yp,zp (mm),
// output CSV ex_um,ey_um,ez_um,status (ok | out_of_range:<axis>).
#include "drivers/config/strict_toml.hpp"
#include "dsp/comp/volumetric.hpp"
#include "dsp/core/error.hpp"
#include "tools/commands.hpp"
#include "tools/io/csv_table.hpp"
#include "tools/run_files.hpp"

#include <cstdio>
#include <memory>

namespace eical::tools {
namespace {

dsp::comp::VolumetricModel read_model(const std::string& file) {
  const toml::table root = drivers::StrictTable::parse_file(file);
  drivers::StrictTable t(root, file, "");
  const std::string format = t.string("format");
  if (format != "eical-volumetric/1") t.fail("format", "expected \"eical-volumetric/1\", got \"" + format + "\"");
  dsp::comp::VolumetricModel m;
  auto axes = t.table("axes");
  const char* keys[3] = {"x_range_mm", "y_range_mm", "z_range_mm"};
  for (int a = 0; a < 3; ++a) {
    const auto r = axes.numbers(keys[a], 2);
    m.range_mm[a] = {r[0], r[1]};
  }
  axes.finish();
  auto sq = t.table("squareness");
  m.xwy_urad = sq.number("xwy");
  m.xwz_urad = sq.number("xwz");
  m.ywz_urad = sq.number("ywz");
  sq.finish();
  std::array<bool, 18> seen{};
  for (auto& c : t.tables("component")) {
    const std::string name = c.string("name");
    int k = -1;
    for (int i = 0; i < 18; ++i)
      if (name == dsp::comp::kVolumetricComponents[i]) k = i;
    if (k < 0) c.fail("name", "'" + name + "' is not one of xtx, xty, ..., zrz");
    if (seen[k]) c.fail("name", "component '" + name + "' appears twice");
    seen[k] = true;
    m.component[k].pos_mm = c.numbers("positions_mm");
    m.component[k].values = c.numbers("values");
    c.finish();
  }
  t.finish();
  dsp::comp::validate(m);  // missing components, order, coverage
  return m;
}

}  // namespace

void register_volumetric(CLI::App& app) {
  struct Opt {
    std::string model, points, out;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand("volumetric", "Deviation vectors from the 21-parameter volumetric model (translations um, rotations urad)");
  cmd->add_option("--model", o->model, "model file (eical-volumetric/1 TOML)")->required();
  cmd->add_option("--points", o->points, "CSV x,y,z,xp,yp,zp in mm (position and tool offset)")->required();
  cmd->add_option("--out", o->out, "output CSV ex_um,ey_um,ez_um,status")->required();
  cmd->callback([o] {
    const auto m = read_model(o->model);
    const CsvTable p(o->points, {"x", "y", "z", "xp", "yp", "zp"});
    std::string text = "ex_um,ey_um,ez_um,status\n";
    int out_of_range = 0;
    for (std::size_t r = 0; r < p.rows(); ++r) {
      const Eigen::Vector3d x(p.number(r, "x"), p.number(r, "y"), p.number(r, "z"));
      const Eigen::Vector3d xp(p.number(r, "xp"), p.number(r, "yp"), p.number(r, "zp"));
      const auto d = dsp::comp::volumetric_deviation(m, x, xp);
      char line[160];
      if (d.ok()) std::snprintf(line, sizeof line, "%.6f,%.6f,%.6f,ok\n", d.e_um.x(), d.e_um.y(), d.e_um.z());
      else std::snprintf(line, sizeof line, ",,,out_of_range:%c\n", "xyz"[d.out_of_range_axis]), ++out_of_range;
      text += line;
    }
    write_file_atomic(o->out, text);  // only after every row was computed: no partial file
    std::printf("%zu points, %d out of range; written %s\n", p.rows(), out_of_range, o->out.c_str());
  });
}

}  // namespace eical::tools
