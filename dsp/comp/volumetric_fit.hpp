#pragma once
// The 21-parameter model (volumetric.hpp, seed 004) identified from eical's runs, as far
// as they observe it:
// * a positioning run along axis a: at every target the standstill deviation of all three
//   channels (standstills.hpp), mean over runs of the two directions' means: the channel
//   of a is ata (positioning), the other channels atb (straightness of a in b);
// * squareness: a straightness channel's slope is the frame and the squareness. With the
//   usual frame (x's motion defines the x axis, with y's motion the xy plane: xty, xtz
//   and ytz have no slope), the squareness of a pair is the sum of the slopes its two
//   runs show in each other's channel (volumetric_fit.cpp, kPairs); and circles'
//   squareness (ballbar convention) where the result gives its uncertainty — estimates
//   combined by their inverse variance; rectangles give none (NBS holds the standing axis);
// * not observable: the nine rotations (xrx … zrz) — eical measures the relative
//   translation at one point, where a carriage's rotation is indistinguishable from a
//   translation; it needs a second measuring point at a known lever or an angle
//   reference — and everything of an axis no run moved.
// Every value is relative to the machine at the reference point of the measured range (the
// origin when the range holds it: a common offset is a zero point no relative measurement
// sees), with its expanded uncertainty (k = 2) from the runs' own Monte Carlo draws
// (dsp/analysis/figure_uncertainty: integration noise, bias walk, the sensor model of the
// data sheet or of the calibration, the strips): each run's share of the model is a pure
// function of its standstills (run_components), which the draws evaluate on every perturbed
// path, so U holds everything the analysis knows the run's error by — not only the scatter.
#include "dsp/comp/standstills.hpp"
#include "dsp/comp/volumetric.hpp"

#include <Eigen/Core>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace eical::dsp::comp {

// One positioning run's share of the model, per channel c: the bidirectional mean deviation
// at each target (the mean of the two directions' means), relative to the axis' reference
// point; a straightness channel (c ≠ axis) less its least-squares line, whose slope is the
// frame and the squareness (kept in slope_um_per_mm).
struct RunChannel {
  std::vector<double> pos_mm, value_um;
  double slope_um_per_mm = 0.0;
};
struct RunComponents {
  int axis = 0;
  std::array<RunChannel, 3> channel;
  std::array<double, 3> standing_mm{};  // where each axis stood, on average over the stops
};

// InputError when fewer than 2 targets were reached from both sides.
RunComponents run_components(int axis, const std::vector<Standstill>& stops);

// One positioning run: its components and their U (k = 2) from the run's draws.
struct AxisPass {
  int axis = 0;
  std::string source;
  RunComponents fit;
  std::array<std::vector<double>, 3> u_k2_um;    // per channel, per target
  std::array<double, 3> slope_u_k2_um_per_mm{};  // per channel (the run's own channel: 0)
};

// A squareness figure from elsewhere (a circle), pair 0 xy, 1 yz (ywz), 2 zx (xwz).
struct SquarenessFigure {
  int pair = 0;
  double urad = 0.0;
  std::optional<double> u_k2_urad;  // without it the figure is reported, not used
  std::string source;
};

struct ComponentFit {
  bool observed = false;
  std::string note;          // where it comes from, or why it is not observed
  std::vector<double> u_k2;  // per support point (observed components)
};

struct SquarenessFit {
  bool observed = false;
  double u_k2_urad = 0.0;
  std::string note;
};

struct VolumetricFit {
  VolumetricModel model;  // unobserved components are zero
  std::array<ComponentFit, 18> component;
  std::array<SquarenessFit, 3> squareness;  // xwy, ywz, xwz (the pairs' order)
};

// InputError when there is no pass, or the runs of one axis reached different targets.
VolumetricFit fit_volumetric(const std::vector<AxisPass>& passes, const std::vector<SquarenessFigure>& circles);

// Expanded uncertainty (k = 2) of the predicted e(x) − e(origin) of the observed model
// (the unobserved components contribute nothing they could be given a size for).
Eigen::Vector3d prediction_u_k2(const VolumetricFit& fit, const Eigen::Vector3d& x_mm);

}  // namespace eical::dsp::comp
