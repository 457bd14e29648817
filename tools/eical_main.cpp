// eical: the command line. Subcommands live in tools/cmd_<name>.cpp.
// Exit status (docs/command-line.md, tools/exit_codes.hpp): 0 done, 1 any error — a usage
// error of the command line as much as bad input —, and `eical analyze`'s verdict: 2
// degraded, 3 not measurable.
#include "tools/commands.hpp"
#include "tools/exit_codes.hpp"

#include <algorithm>
#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  CLI::App app{"eical - embedded inertial calibrator for machine tools"};
  app.require_subcommand(1);
  eical::tools::register_all(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --help-all, --version: printed, done
    return app.exit(e);
  } catch (const CLI::RuntimeError& e) {  // a command's own status (analyze's verdict)
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {  // the one place CLI11's errors become an exit status
    // CLI11 reports an unknown command as "A subcommand is required": name it instead.
    if (argc > 1 && argv[1][0] != '-') {
      const auto commands = app.get_subcommands({});
      const bool known =
          std::any_of(commands.begin(), commands.end(), [&](const CLI::App* c) { return c->check_name(argv[1]); });
      if (!known) {
        std::fprintf(stderr, "eical: no command '%s' (eical help lists them)\n", argv[1]);
        return eical::tools::kExitError;
      }
    }
    std::fprintf(stderr, "eical: %s (eical help [command] lists the options)\n", e.what());
    return eical::tools::kExitError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "eical: %s\n", e.what());
    return eical::tools::kExitError;
  }
  return eical::tools::kExitOk;
}
