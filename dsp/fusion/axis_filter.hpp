#pragma once
// The Kalman filter of one axis' error state (error_model.hpp): predict per sample, one
// scalar update per support observation. Every update leaves a record — innovation,
// normalised innovation squared (NIS), accepted or rejected by the gate — the way PX4's
// aid sources do, so that a support that disagrees with the integration is visible and
// never silently absorbed. Per sample: no allocation, no branches on the data but the gate.
#include "dsp/fusion/error_model.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace eical::dsp::fusion {

enum class Support : std::uint8_t { zupt = 0, cupt = 1, nbs = 2 };
inline constexpr int kSupportKinds = 3;
const char* support_name(Support s) noexcept;

struct UpdateRecord {
  double innovation = 0.0;  // z − h·e (µm or µm/s)
  double nis = 0.0;         // innovation² / its variance
  bool accepted = false;
};

// Running tally per support kind: what a result reports about its supports.
struct SupportTally {
  std::size_t accepted = 0, rejected = 0;
  double nis_sum = 0.0;  // of the accepted ones (≈ accepted when the model fits)
  void add(const UpdateRecord& r) noexcept {
    if (r.accepted)
      ++accepted, nis_sum += r.nis;
    else
      ++rejected;
  }
};

struct AxisFilter {
  State e = State::Zero();
  StateCov P = StateCov::Zero();

  void predict(const Discrete& d) noexcept {
    e = d.F * e;
    P = d.F * P * d.F.transpose() + d.Q;
  }

  // z = h·e + noise of variance r; the symmetric form keeps P symmetric.
  UpdateRecord update_row(const StateRow& h, double z, double r, double gate_nis) noexcept {
    UpdateRecord rec;
    const State ph = P * h.transpose();
    const double s = h.dot(ph) + r;
    rec.innovation = z - h.dot(e);
    rec.nis = rec.innovation * rec.innovation / s;
    if (!(rec.nis <= gate_nis) || !(s > 0.0) || !std::isfinite(s)) return rec;  // also rejects NaN
    const State k = ph / s;
    e += k * rec.innovation;
    P -= k * ph.transpose();
    P = 0.5 * (P + P.transpose());
    rec.accepted = true;
    return rec;
  }
  // An observation of a single state (h = unit row).
  UpdateRecord update(int state, double z, double r, double gate_nis) noexcept {
    return update_row(StateRow::Unit(state), z, r, gate_nis);
  }
};

}  // namespace eical::dsp::fusion
