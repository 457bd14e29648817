#pragma once
// A command-line option that names a program kind: the run file's names
// (dsp::kProgramKindNames) map to the kind, limited to the kinds the command runs.
#include "dsp/core/program_kind.hpp"

#include <CLI/CLI.hpp>

#include <initializer_list>
#include <map>
#include <string>

namespace eical::tools {

inline CLI::Option* add_program_kind_option(CLI::App& cmd, const std::string& flag, dsp::ProgramKind& kind,
                                            std::initializer_list<dsp::ProgramKind> allowed, std::string help) {
  std::map<std::string, dsp::ProgramKind> names;
  for (const dsp::ProgramKind k : allowed) names.emplace(dsp::program_kind_name(k), k);
  return cmd.add_option(flag, kind, std::move(help))
      ->transform(CLI::CheckedTransformer(names))
      ->default_str(dsp::program_kind_name(kind));
}

}  // namespace eical::tools
