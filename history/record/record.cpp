#include "history/record/record.hpp"

#include <algorithm>

namespace eical::history {

const Figure* Record::figure(const std::string& name) const {
  const auto it = std::lower_bound(figures.begin(), figures.end(), name,
                                   [](const Figure& f, const std::string& n) { return f.name < n; });
  return it != figures.end() && it->name == name ? &*it : nullptr;
}

}  // namespace eical::history
