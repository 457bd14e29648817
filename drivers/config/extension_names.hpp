#pragma once
// The extension namespace shared by every TOML key and CSV column eical reads
// (docs/run-files.md): names that begin with ext_ belong to other tools and are skipped; every
// other name a reader does not know is an error naming the file, the line and the name.
#include <string_view>

namespace eical::drivers {

inline constexpr std::string_view kExtensionPrefix = "ext_";
[[nodiscard]] inline bool is_extension_name(std::string_view name) { return name.starts_with(kExtensionPrefix); }

}  // namespace eical::drivers
