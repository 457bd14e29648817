// eical help [COMMAND]: the command list, or one command's options (as --help prints them).
#include "tools/commands.hpp"

#include <cstdio>
#include <memory>

namespace eical::tools {

void register_help(CLI::App& app) {
  auto topic = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("help", "Print the commands, or the options of one command");
  cmd->add_option("command", *topic, "a command (e.g. analyze)");
  CLI::App* root = &app;
  cmd->callback([root, topic] {
    // Not root->help(): while `help` itself is the parsed subcommand, CLI11 delegates to it.
    if (topic->empty()) {
      std::fputs(root->get_formatter()->make_help(root, "eical", CLI::AppFormatMode::Normal).c_str(), stdout);
      return;
    }
    CLI::App* sub = nullptr;
    try {
      sub = root->get_subcommand(*topic);
    } catch (const CLI::OptionNotFound&) {
      throw std::runtime_error("help: no command '" + *topic + "' (eical help lists them)");
    }
    std::fputs(sub->help("eical").c_str(), stdout);
  });
}

}  // namespace eical::tools
