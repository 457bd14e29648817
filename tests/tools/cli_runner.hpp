#pragma once
// Runs `eical ARGS...` in-process (the registered CLI11 app), for command-level tests.
#include "tools/commands.hpp"

#include <string>
#include <vector>

namespace eical::tools::testing {

inline void run_cli(std::vector<std::string> args) {
  CLI::App app;
  register_all(app);
  args.insert(args.begin(), "eical");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  app.parse(static_cast<int>(argv.size()), argv.data());
}

}  // namespace eical::tools::testing
