// The calibration objective: how far a simulated force sequence is from a measured one.
//
// Paper section IV-B.3, eq. 3-5. For one force axis, with simulated samples s_0..s_m and measured
// samples r_0..r_n (both at the sensor's 100 Hz, paired by index):
//
//   e(S, R) = sum_{i=1}^{max(n,m)} d(s_i, r_i)                                         (eq. 3)
//   d(s_i, r_i) =   dx_i |s_i - r_i|        i <= m and i <= n   (both sequences still running)
//                 w dx_i |s_i - r_n|        i <= m and i > n    (simulation ran longer)   (eq. 4)
//                 w dx_i |s_m - r_i|        i > m and i <= n    (measurement ran longer)
//   L(R, theta) = sum_k e(S_k^Y, R_k^Y) + e(S_k^X, R_k^X)                               (eq. 5)
//
// with w = 20 and dx_i the end effector's travel between frames i-1 and i. The paper does not
// say whose travel; we take the measured sequence's while both run (the measurement is the
// reference the simulation is scored against) and the longer sequence's beyond the shorter one.
// Between two measured repeats the choice changes L by < 0.001 (tests/calib/objective_test.cpp).
// X is F_motion and Y is F_vertical (rig convention, haptic.h). e is an approximation of the
// unsigned area between the two curves over travel [N m], plus a w-weighted penalty for a
// different length (a trial that stops at 10 N too early or too late).
//
// Where the pairs begin. Pairing by index assumes both sequences start with the pull. 21 of the
// study's 22 recordings do, within 1.1 mm of stamped travel (within one 10 ms sample of the
// stamp's start: the stamp is a constant-speed profile, core/haptic.h, kLateStart);
// s0-middlemiss-10, the one trial at 0.15 m/s, starts 0.0958 m into its pull.
// Paired from the simulation's first sample, each of its samples met a simulated one 0.096 m
// behind it, and the 67 simulated samples left at the end were scored at w = 20 (session 45:
// 0.53 of participant 0's middle-arm L 1.10). So when the recording starts more than kLateStart
// (5 mm, core/haptic.h) further along than the simulation, i = 0 pairs its first sample with the
// simulated sample at the same time of the pull (paired_start), as eq. 3's index does for the
// pulls recorded from their start. That time is the stamp's: x_m / v, v the stamp's own speed
// (0.0958 m at 0.15 m/s is 0.639 s, the simulated sample at 0.64 s). Not the same travel: the
// simulation's travel is the ramped profile's and the stamp leads it by v^2 / 2a once the ramp is
// over (11 mm at 0.15 m/s), so pairing equal travels (sessions 45-91) paired the recording's
// first sample with the simulated one 0.075 s (v / 2a) later in the pull, at 0.714 s. A
// simulation that starts late (none does: the simulator records from the pull's start) pairs
// its first sample with the measured one stamped where the pull is at its time, v t. The 5 mm
// leave every recording that starts with the pull paired as the paper pairs it. The first
// argument is the simulation: its t is the pull's time, the recording's t its own clock.
//
// PositionWeighted: the variant in the paper's public code (gt-rad/learning-forces,
// physx_simulation CMAES HapticObjective, evalObj), described here in our own words as we read
// it: walk the *measured* samples; at each measured travel x_i the simulated force is linearly
// interpolated on the simulated travel; the absolute differences of both axes are summed and
// weighted by exp(x_i) [x in m, so the end of the pull weighs e^0.85 = 2.3 times the start] and by
// the measured travel step. Where the measurement runs beyond the simulation's final travel x_S,
// the difference to the simulation's last sample is weighted 1.5 exp(x_i + x_S); where the
// simulation runs beyond the measurement's final travel x_R, each further simulated sample's
// difference to the last measured one is weighted 1.5 exp(x_j - x_R) times its own travel step.
// Both axes are summed inside, so it is a whole-sequence error (no per-axis split).
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>
#include <vector>

#include "haptic.h"

namespace dressguard::calib {

enum class ObjectiveKind { Area = 0, PositionWeighted = 1 };
std::string_view objective_name(ObjectiveKind k);           // "area", "position-weighted"
std::optional<ObjectiveKind> parse_objective(std::string_view s);

enum class ForceAxis { Motion, Vertical, Lateral };

inline constexpr double kLengthPenaltyWeight = 20.0;  // w of eq. 4

// The first index of each sequence that eq. 3 pairs (i = 0): both 0 unless one starts more than
// kLateStart further along; then the other's sample at the same time of the pull ("Where the
// pairs begin"; its last sample if it never gets there); and how many pairs follow from there. A recording whose stamp does not
// advance (no speed to read its time by) is paired from the same travel.
struct PairedStart {
  std::size_t sim = 0;
  std::size_t measured = 0;
  std::size_t count = 0;  // the pairs: from these indices to the shorter sequence's end (>= 1)
};
PairedStart paired_start(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured);

// The measured samples of eq. 3's pairs (from paired_start to the shorter sequence's end), each
// with its simulated partner's travel: the recording on the simulator's travel. What compares a
// recording with a simulation over travel (a window's mean, prediction.h residual_windows) reads
// it there. By its own stamp, a constant-speed profile that leads the simulator's ramped travel
// by v^2 / 2a once the ramp is over (core/haptic.h), each measured force would stand beside the
// simulated one of 5 mm (0.1 m/s) or 11 mm (0.15 m/s) earlier in the pull. Empty when either is.
std::vector<HapticSample> measured_on_simulated_travel(const std::vector<HapticSample>& sim,
                                                       const std::vector<HapticSample>& measured);

// eq. 3-4 for one axis, paired from paired_start(). `sim` and `measured` need at least one sample each.
double area_error(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured, ForceAxis axis,
                  double w = kLengthPenaltyWeight);

// Both axes of eq. 5 for one sequence pair: e(S^Y, R^Y) + e(S^X, R^X).
double area_objective(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured,
                      double w = kLengthPenaltyWeight);

// A lower bound of area_objective() for a simulation still under way (calibrate --prune): its
// terms that no later sample can change. Every term of eq. 3-4 is >= 0; the pairs up to the
// simulation's last sample and the w-weighted ones where it already runs longer than the
// measurement stay as they are, and the measurement-longer terms, which pair the measurement
// with the simulation's final sample, are left out (they may vanish as it goes on). So it
// never decreases as samples come, and area_objective() of the whole simulation is at least it.
// While the simulation has not reached the travel where a late-starting measurement begins
// (paired_start) it is 0. An empty simulation scores 0.
double area_objective_so_far(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured,
                             double w = kLengthPenaltyWeight);

// The public code's position-weighted error (see above), both axes.
double position_weighted_objective(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured);

// The vertical force's sign (issue 5: the paper's simulator "often has the opposite sign"): the
// share of the measured travel, over eq. 3's pairs, where the measured |F_vertical| exceeds
// `threshold` and its simulated partner's F_vertical (the same moment of the pull) has the same
// sign. Each measured sample after the first pair counts with its travel step (a sample at
// 0.1 m/s and one at 0.15 m/s weigh by the distance they stand for). Until session 94 the
// simulated force was interpolated at the recording's stamped travel, which leads the simulated
// pull by v^2 / 2a (measured_on_simulated_travel). NaN when no such travel exists. The
// 0.2 N default is ten times the sensor's high-frequency noise (shared/data: 0.017 N), so a sign
// is only asked of where the measurement has one.
double vertical_sign_agreement(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured,
                               double threshold = 0.2);

// ---- the heights' contrast (an extension of the paper's objective; calibrate --contrast-weight) ---
//
// A classifier trained on the simulator tells good from missed by how the force differs between
// the arm height that gives good (high) and the one that gives missed (middle, low), and cut
// early (issue 4: up to 0.30 m) that difference is all it has. Eq. 3-5 scores each sequence on
// its own, by area, and the forces at 0.2-0.3 m (a few tenths of a newton) weigh little against
// the newtons of the late pull: calibrations that fit participant 4 and 5 at L <= 0.3 per
// sequence order the heights the wrong way round there (prediction.h, height_contrasts). This
// term scores that difference directly, for one high sequence H and one lower sequence W, each
// simulated (S) and measured (R):
//
//   c(S, R) = sum_axes sum_j dx |(S_H(x_j) - S_W(x_j)) - (R_H(x_j) - R_W(x_j))|,   x_j = (j + 1/2) dx
//
// over x_j < min(up_to, the end of all four curves), each curve linearly interpolated on its
// travel, dx = kContrastStep. A force both heights share (an offset of every curve alike) does
// not count: only the difference does. [N m], like eq. 3.
inline constexpr double kLatestCut = 0.30;     // [m] issue 4's latest cut of the measured sequences
inline constexpr double kContrastStep = 0.005;  // [m]: 5 samples at 0.1 m/s, 100 Hz

double contrast_error(const std::vector<HapticSample>& sim_high, const std::vector<HapticSample>& sim_lower,
                      const std::vector<HapticSample>& measured_high, const std::vector<HapticSample>& measured_lower,
                      double up_to);

// The chosen objective for one pair.
double sequence_objective(ObjectiveKind kind, const std::vector<HapticSample>& sim,
                          const std::vector<HapticSample>& measured);

}  // namespace dressguard::calib
