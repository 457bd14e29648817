#pragma once
// What the evaluation of a program derives from its set-point alone, kept for the next
// evaluation of a path on the same set-point. The uncertainty's draws evaluate some 200
// paths on one set-point (figure_uncertainty.cpp); with this they find the circle's
// revolutions and make the diagnostics' design (eval::CircleDesign) once, not each time.
//
// Evaluations fill it until it is frozen and only read it after: fill it with one
// evaluation, freeze it, then evaluate in parallel. Every evaluation given it must be of
// the same set-point (the measurement's cmd, sample indices and triggers, the program).
#include "dsp/eval/circle_diagnostics.hpp"

#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

namespace eical::dsp {

struct SetPointCache {
  struct Circle {
    std::vector<std::pair<std::int64_t, std::int64_t>> ccw, cw;  // the evaluated revolutions
    std::shared_ptr<const eval::CircleDesign> design;            // null: no full revolutions to diagnose
  };
  std::optional<Circle> circle;  // filled once the revolutions are found
  bool frozen = false;
};

}  // namespace eical::dsp
