#include "sim/gcode/canonical.hpp"

#include "sim/gcode/format.hpp"
#include "sim/gcode/parser.hpp"

#include <cmath>

namespace eical::sim::gcode {
namespace {

// Coordinates at kWrittenResolutionMm (9 decimals), which the reader's checks allow for.
static_assert(kWrittenResolutionMm == 1e-9, "append_xyz and the arc offsets write 9 decimals");

// " X.. Y.. Z..", appended (GCC 12 warns falsely on `"literal" + std::string&&`).
void append_xyz(std::string& out, const Eigen::Vector3d& p_mm) {
  for (int a = 0; a < 3; ++a) {
    out += ' ';
    out += static_cast<char>('X' + a);
    out += format_number("%.9f", p_mm[a]);
  }
}

void append_word(std::string& out, char letter, const char* printf_format, double v) {
  out += ' ';
  out += letter;
  out += format_number(printf_format, v);
}

struct Render {
  std::string out;
  Plane plane = Plane::xy;
  void set_plane(Plane p) {
    if (p == plane) return;
    plane = p;
    out += p == Plane::xy ? "G17\n" : p == Plane::zx ? "G18\n" : "G19\n";
  }
  void operator()(const Linear& l) {
    out += l.rapid ? "G0" : "G1";
    append_xyz(out, l.to_mm);
    if (!l.rapid) append_word(out, 'F', "%.9f", l.feed_mm_min);
    out += '\n';
  }
  void operator()(const Arc& a) {
    set_plane(a.plane);
    const Eigen::Vector3d off = a.center_mm - a.from_mm;
    const int u = a.plane == Plane::xy ? 0 : a.plane == Plane::zx ? 2 : 1;
    const int v = a.plane == Plane::xy ? 1 : a.plane == Plane::zx ? 0 : 2;
    out += a.clockwise ? "G2" : "G3";
    append_xyz(out, a.to_mm);
    for (int k : {u, v}) append_word(out, static_cast<char>('I' + k), "%.9f", off[k]);
    append_word(out, 'F', "%.9f", a.feed_mm_min);
    out += '\n';
  }
  void operator()(const Dwell& d) {
    out += "G4";
    append_word(out, 'P', "%.9f", d.duration_s);
    out += '\n';
  }
  void operator()(const Trigger& t) {
    out += 'M';
    out += std::to_string(t.code);
    if (!std::isnan(t.p)) append_word(out, 'P', "%.9f", t.p);
    if (!std::isnan(t.q)) append_word(out, 'Q', "%.9f", t.q);
    out += '\n';
  }
};

}  // namespace

std::string linuxcnc_text(const Program& program) {
  Render r;
  r.out = program.exact_stop ? "G90 G21 G17 G94 G91.1 G61\n" : "G90 G21 G17 G94 G91.1 G64\n";
  for (const auto& b : program.blocks) std::visit(r, b);
  return r.out;
}

std::string canonical_gcode(std::string_view text, std::string_view name, Dialect d) {
  ParseOptions o;
  o.dialect = d;
  const Program first = parse(text, name, o);
  require_motion(first, name);
  if (d == Dialect::linuxcnc) return std::string(text);
  // Where the simulator puts the machine (nc::interpolate_gcode): at the first rapid
  // move's end when the program begins with one; the text is written from there.
  for (const auto& b : first.blocks) {
    if (const auto* l = std::get_if<Linear>(&b)) {
      if (l->rapid) o.start_mm = l->to_mm;
      break;
    }
    if (std::holds_alternative<Arc>(b)) break;
  }
  return linuxcnc_text(parse(text, name, o));
}

}  // namespace eical::sim::gcode
