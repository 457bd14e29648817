// eical help [COMMAND [SUBCOMMAND...]]: the command list, or one command's options (as
// --help prints them); `eical help gen-nc identify` as `eical gen-nc identify --help`.
#include "tools/commands.hpp"

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace eical::tools {

void register_help(CLI::App& app) {
  auto topic = std::make_shared<std::vector<std::string>>();
  auto* cmd = app.add_subcommand("help", "Print the commands, or the options of one command");
  cmd->add_option("command", *topic, "a command (e.g. analyze, or gen-nc identify)");
  CLI::App* root = &app;
  cmd->callback([root, topic] {
    // Not root->help(): while `help` itself is the parsed subcommand, CLI11 delegates to it.
    if (topic->empty()) {
      std::fputs(root->get_formatter()->make_help(root, "eical", CLI::AppFormatMode::Normal).c_str(), stdout);
      return;
    }
    CLI::App* sub = root;
    std::string path = "eical";
    for (const std::string& word : *topic) {
      try {
        sub = sub->get_subcommand(word);
      } catch (const CLI::OptionNotFound&) {
        throw std::runtime_error("help: no command '" + word + "'" +
                                 (sub == root
                                      ? std::string(" (eical help lists them)")
                                      : " under '" + path + "' (eical help " + path.substr(6) + " lists them)"));
      }
      path += " " + word;
    }
    std::fputs(sub->help(path.substr(0, path.rfind(' '))).c_str(), stdout);
  });
}

}  // namespace eical::tools
