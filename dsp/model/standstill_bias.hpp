#pragma once
// The sensors' bias at the standstills between moves (ch. 8.3.2: each partial move has its
// own bias). The nominal model holds the bias measured in the rest window before M101
// for the whole run; at every later standstill each sensor should read that bias again.
//
// Per standstill: the mean of the bias-free relative reading head − table over the window's
// late part (from 0.2 s after it opens: the position loop's creep has decayed by
// e^(−kv·0.2 s)) and a mode between head and table has stopped ringing, Hann-weighted
// against tones), its standard error by batch means, and the data-sheet bias walk as
// tolerated variance. The relative reading is what the measurement integrates, and the
// machine's common vibration cancels in it; each sensor's own mean says which one changed.
// Tests: χ² of all standstill means against "no change" (z = 5), then which pattern
// explains them — a linear drift in time, steps that alternate from move to move, or the
// case temperature (a bias coefficient within what a sensor can have). The temperature
// wins only with a plausible coefficient and a fit at least as good as the drift's.
#include "dsp/model/run_residuals.hpp"

#include <string>
#include <vector>

namespace eical::dsp::model {

struct StandstillBias {
  struct Window {
    double t_s = 0.0;                       // mid of the late part, from the start of the motion
    double settle_s = 0.0, length_s = 0.0;  // the late part: from this long after the rest opened, this long
    double temp_c[2] = {0.0, 0.0};          // case temperature change since the start, table/head
    double bias_ug[3] = {};                 // change of the mean relative reading per machine axis
    double sigma_ug[3] = {};                // its standard error (noise and tolerated walk)
    double sensor_ug[2][3] = {};            // each sensor's own change (attribution only)
  };
  std::vector<Window> windows;
  double chi2 = 0.0;
  int dof = 0;
  bool changed = false;  // χ² beyond z = 5 and a change above 1 µg
  double largest_change_ug = 0.0;
  std::string pattern = "none";                                           // "drift" | "steps" | "temperature" | "walk"
  double drift_ug_per_s = 0.0, step_ug = 0.0, temp_coeff_ug_per_c = 0.0;  // of the axis with the largest change
  int temp_coeff_sensor = -1;  // whose bias coefficient temp_coeff_ug_per_c is (0 table, 1 head)
  int sensor = -1, axis = -1;  // where the largest change is (sensor: the one whose own mean moved more)
  double temperature_change_c = 0.0;
  std::string evidence;
};

StandstillBias standstill_bias(const RunResiduals& run);

}  // namespace eical::dsp::model
