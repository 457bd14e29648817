#include "dsp/fusion/axis_filter.hpp"

namespace eical::dsp::fusion {

const char* support_name(Support s) noexcept {
  switch (s) {
    case Support::zupt: return "zupt";
    case Support::cupt: return "cupt";
    case Support::nbs: return "nbs";
  }
  return "?";
}

}  // namespace eical::dsp::fusion
