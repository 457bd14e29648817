#pragma once
// Bad input (malformed run, config, NaN, missing channel) is reported with this type:
// the message names the cause (file, line, field where known). Never thrown per sample.
#include <stdexcept>
#include <string>

namespace eical::dsp {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace eical::dsp
