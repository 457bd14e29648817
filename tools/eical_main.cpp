// eical: the command-line tool. Subcommands live in tools/cmd_<name>.cpp.
#include "tools/commands.hpp"

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  CLI::App app{"eical - embedded inertial calibrator for machine tools"};
  app.require_subcommand(1);
  eical::tools::register_all(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "eical: %s\n", e.what());
    return 1;
  }
  return 0;
}
