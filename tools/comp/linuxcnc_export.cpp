#include "tools/comp/linuxcnc_export.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

namespace eical::tools::comp {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream is(text);
  for (std::string l; std::getline(is, l);) out.push_back(l);
  return out;
}

// "[JOINT_0]" → "JOINT_0"; "" when the line is not a section header.
std::string section_of(const std::string& line) {
  const std::string t = trim(line);
  if (t.size() < 3 || t.front() != '[' || t.back() != ']') return "";
  return upper(trim(t.substr(1, t.size() - 2)));
}

// "KEY = value" → KEY (upper case); "" for comments and other lines.
std::string key_of(const std::string& line) {
  const std::string t = trim(line);
  if (t.empty() || t[0] == '#' || t[0] == ';' || t[0] == '[') return "";
  const auto eq = t.find('=');
  return eq == std::string::npos ? "" : upper(trim(t.substr(0, eq)));
}

std::string value_of(const std::string& line) {
  const auto eq = line.find('=');
  return eq == std::string::npos ? "" : trim(line.substr(eq + 1));
}

std::string fmt_mm(double v) {
  char b[48];
  std::snprintf(b, sizeof b, "%.7f", v);
  return b;
}

std::vector<std::string> key_lines(const JointSettings& j, bool with_comments) {
  std::vector<std::string> out;
  if (with_comments)
    for (const auto& c : j.comments) out.push_back("# " + c);
  if (j.comp_file) {
    out.push_back("COMP_FILE = " + *j.comp_file);
    out.push_back("COMP_FILE_TYPE = 0");
  }
  if (j.backlash_mm) out.push_back("BACKLASH = " + fmt_mm(*j.backlash_mm));
  return out;
}

void check(const std::vector<JointSettings>& joints) {
  std::set<int> seen;
  for (const auto& j : joints) {
    if (!seen.insert(j.joint).second)
      throw dsp::InputError("comp: joint " + std::to_string(j.joint) + " has two proposals");
    if (j.backlash_mm && j.comp_file)
      throw dsp::InputError(
          "comp: joint " + std::to_string(j.joint) +
          " would get BACKLASH and COMP_FILE; LinuxCNC ignores BACKLASH with a COMP_FILE (fold it into the table)");
  }
}

}  // namespace

std::string linuxcnc_comp_file(const dsp::comp::AxisTable& t, const std::string& comment) {
  dsp::comp::validate(t);
  if (t.pos_mm.size() > kLinuxcncMaxCompPoints)
    throw dsp::InputError(std::string("comp: the ") + dsp::comp::axis_letter(t.axis) + " table has " +
                          std::to_string(t.pos_mm.size()) +
                          " points; LinuxCNC takes at most 256 per joint (give a larger --spacing-mm)");
  // usrmotLoadComp reads triplets until the first line that is not three numbers and stops
  // there: a comment above the data would leave the joint without compensation, so the
  // note goes after the last triplet, where LinuxCNC stops reading anyway.
  std::string text;
  for (std::size_t i = 0; i < t.pos_mm.size(); ++i) {
    char line[128];
    const double nominal = std::round(t.pos_mm[i] * 1e6) * 1e-6;  // as printed: the actuals refer to it
    std::snprintf(line, sizeof line, "%.6f %.7f %.7f\n", nominal, nominal + t.forward_um[i] * 1e-3,
                  nominal + t.reverse_um[i] * 1e-3);
    text += line;
  }
  text += "# " + comment +
          "\n# COMP_FILE_TYPE = 0: nominal, actual moving +, actual moving - (mm); actual = nominal + deviation\n";
  return text;
}

std::map<char, int> joint_map(const std::string& ini_text, const std::string& ini_name) {
  std::string section, kins, coords;
  for (const auto& l : lines_of(ini_text)) {
    if (const std::string s = section_of(l); !s.empty()) {
      section = s;
      continue;
    }
    const std::string k = key_of(l);
    if (section == "KINS" && k == "KINEMATICS") kins = value_of(l);
    if (section == "TRAJ" && k == "COORDINATES") coords = value_of(l);
  }
  if (kins.empty()) throw dsp::InputError(ini_name + ": no [KINS] KINEMATICS: which joint moves which axis is unknown");
  std::istringstream ks(kins);
  std::string module;
  ks >> module;
  if (module != "trivkins")
    throw dsp::InputError(ini_name + ": [KINS] KINEMATICS = " + kins +
                          ": eical merges trivkins configurations only (one joint per axis letter); write the snippet "
                          "with the joint numbers by hand");
  for (std::string p; ks >> p;)
    if (p.rfind("coordinates=", 0) == 0) coords = p.substr(12);
  std::string letters;
  for (char c : coords)
    if (std::isalpha(static_cast<unsigned char>(c)))
      letters += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (letters.empty()) letters = "xyz";
  std::map<char, int> m;
  for (std::size_t j = 0; j < letters.size(); ++j)
    if (!m.count(letters[j]))
      m[letters[j]] = static_cast<int>(j);  // trivkins: a repeated letter is a gantry; the first joint leads
  return m;
}

std::string linuxcnc_ini_snippet(const std::vector<JointSettings>& joints, const std::string& header) {
  check(joints);
  std::vector<JointSettings> sorted = joints;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.joint < b.joint; });
  std::string text = header;
  for (const auto& j : sorted) {
    text += "\n[JOINT_" + std::to_string(j.joint) + "]\n";
    for (const auto& l : key_lines(j, true)) text += l + "\n";
  }
  return text;
}

std::string merge_linuxcnc_ini(const std::string& ini_text, const std::string& ini_name,
                               const std::vector<JointSettings>& joints) {
  check(joints);
  const std::vector<std::string> in = lines_of(ini_text);
  std::map<std::string, const JointSettings*> by_section;
  for (const auto& j : joints) by_section["JOINT_" + std::to_string(j.joint)] = &j;
  std::map<std::string, int> seen;
  for (const auto& l : in)
    if (const std::string s = section_of(l); !s.empty() && ++seen[s] > 1 && by_section.count(s))
      throw dsp::InputError(ini_name + ": section [" + s +
                            "] appears twice: eical cannot tell which one LinuxCNC reads");

  static const std::set<std::string> kManaged = {"BACKLASH", "COMP_FILE", "COMP_FILE_TYPE"};
  std::vector<std::string> out;
  std::string section;
  std::size_t last_content = 0;  // index in `out` after the section's last non-blank line
  std::set<std::string> done;
  auto close_section = [&] {
    const auto it = by_section.find(section);
    if (it == by_section.end() || done.count(section)) return;
    std::vector<std::string> add = {"# eical comp (" + std::string(1, it->second->axis) + "):"};
    for (const auto& l : key_lines(*it->second, true)) add.push_back(l);
    out.insert(out.begin() + static_cast<std::ptrdiff_t>(last_content), add.begin(), add.end());
    done.insert(section);
  };
  for (const auto& l : in) {
    if (const std::string s = section_of(l); !s.empty()) {
      close_section();
      section = s;
      out.push_back(l);
      last_content = out.size();
      continue;
    }
    const std::string k = key_of(l);
    const auto it = by_section.find(section);
    if (it != by_section.end() && kManaged.count(k)) {
      out.push_back("# eical comp replaced: " + trim(l));
      if (k == "BACKLASH" && it->second->comp_file && !it->second->backlash_mm)
        out.push_back("BACKLASH = 0.0000000");  // folded into the COMP_FILE, which LinuxCNC uses instead
      last_content = out.size();
      continue;
    }
    out.push_back(l);
    if (!trim(l).empty()) last_content = out.size();
  }
  close_section();
  std::string text;
  for (const auto& l : out) text += l + "\n";
  for (const auto& [s, j] : by_section) {
    if (done.count(s)) continue;
    text += "\n[" + s + "]\n# eical comp (" + std::string(1, j->axis) + "): section added (the machine INI had none)\n";
    for (const auto& l : key_lines(*j, true)) text += l + "\n";
  }
  return text;
}

}  // namespace eical::tools::comp
