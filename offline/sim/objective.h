// The paper's calibration objective (section IV-B.3, eq. 3-5), for reporting the simulator's
// fidelity against measured trials. The calibration module keeps its own, fuller version
// (offline/calib/objective.h, on the calib branch when this was written); this one is kept small
// and with the same reading of the paper, so the two give the same numbers:
//
//   e(S, R) = sum_{i=1}^{max(n,m)} d(s_i, r_i)                                           (eq. 3)
//   d = dx_i |s_i - r_i|    while both sequences run,
//       w dx_i |s_i - r_n|  where only the simulation runs on,
//       w dx_i |s_m - r_i|  where only the measurement runs on                           (eq. 4)
//   L = sum_k e(S_k^Y, R_k^Y) + e(S_k^X, R_k^X)                                          (eq. 5)
//
// w = 20; dx_i the travel between samples i-1 and i: the measured sequence's while both run,
// the longer sequence's beyond the shorter. X = f_motion, Y = f_vertical.
#pragma once

#include <vector>

#include "haptic.h"

namespace dressguard::sim {

enum class Axis { Motion, Vertical };

// eq. 3-4 for one axis. Needs at least one sample in each sequence (else returns 0).
double curve_error(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured, Axis axis,
                   double w = 20.0);

// One pair's share of eq. 5: e(S^Y, R^Y) + e(S^X, R^X).
double paper_objective(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured, double w = 20.0);

}  // namespace dressguard::sim
