#include "drivers/setpoint/program_catalog.hpp"

#include "drivers/config/meta_sections.hpp"
#include "drivers/config/strict_toml.hpp"
#include "dsp/core/error.hpp"
#include "sim/gcode/parser.hpp"

namespace eical::drivers {

dsp::Program read_program_file(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw dsp::InputError(path.string() + ": no such program file");
  const toml::table root = StrictTable::parse_file(path.string());
  StrictTable file(root, path.string(), "");
  auto program = file.optional_table("program");
  if (!program) throw dsp::InputError(path.string() + ": no [program] table (write it with eical gen-nc --meta)");
  dsp::Program p = read_program(*program);
  if (p.gcode.empty()) throw dsp::InputError(path.string() + ": [program] has no gcode");
  // Read here, where the file is known, so that its errors name it (the set-point and the
  // simulator read it again later, by then as eical's own text).
  (void)sim::gcode::parse(p.gcode, path.string() + " [program] gcode");
  file.finish();
  return p;
}

dsp::Program ProgramCatalog::program(int number) const {
  if (number < 0)
    throw dsp::InputError("program number " + std::to_string(number) + " is not valid (M101 P must be 0 or more)");
  return read_program_file(file_of(number));
}

}  // namespace eical::drivers
