// Haptic data of one sleeve-pulling trial, measured or simulated, in the rig's convention.
//
// The rig's convention (shared/data/README.md): F_motion along the gripper's direction of
// motion, negative when the gown resists (drag); F_vertical up positive; F_lateral sideways.
// Travel is the gripper's distance from its start, in metres. The paper's HMMs use only
// F_motion ("X") and F_vertical ("Y"), section V-B.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dressguard {

// One sample of the force-torque sensor at the gripper, 100 Hz in the study.
struct HapticSample {
  double t = 0.0;           // [s] since the start of the pull
  double travel = 0.0;      // [m] gripper travel along the motion direction
  double f_motion = 0.0;    // [N] along the motion, drag negative
  double f_lateral = 0.0;   // [N] sideways
  double f_vertical = 0.0;  // [N] up positive, static weight removed (sensor bias)
};

// The rig's motion (shared/data/README.md): from rest at kRigAcceleration up to the pull's speed,
// then at that speed. The simulator's TrialSpec::acceleration defaults to it.
inline constexpr double kRigAcceleration = 1.0;  // [m/s^2]

// A recording "starts late" when its first sample is more than kLateStart into the pull. 21 of
// the study's 22 recordings start within 1.1 mm; s0-middlemiss-10, the one trial at 0.15 m/s,
// starts 0.0958 m in. Whatever compares such a recording with one that starts with the pull must
// begin at the same point of the pull, read by the stamp as x / v: the objective pairs it with
// the simulated sample of that time (calib/objective.h, "Where the pairs begin"), the HMMs start
// their chain that many samples on (hmm/hmm.h, FeatureSequence::unobserved).
//
// What the recordings' position column is. The study stamped it from the commanded motion
// profile (data README), and in all 22 recordings it advances at the pull's speed from the first
// pair on (1.0 mm per 10 ms; 1.5 mm at 0.15 m/s): a parabola fitted to the first 30 samples has
// an acceleration within +-0.012 m/s^2, where a 1 m/s^2 ramp would advance 0.05 mm in the first
// 10 ms. So the stamp is a constant-speed profile without the ramp, and the small starting
// offsets (0.04-1.02 mm, up to about one sample's 1 mm) are where the first sample fell on it,
// not a ramp's first 0.05 s. If the rig did ramp at kRigAcceleration (data README), the stamp
// leads the real gripper by v^2 / 2a once the ramp is over: 5 mm at 0.1 m/s, 11 mm at 0.15 m/s.
// The simulator's travel is the ramped profile (sim/trial.h), so a simulated and a measured
// curve compared at equal travel are that far apart in the real gripper's position.
inline constexpr double kLateStart = 0.005;  // [m]

// [s] when a pull from rest reaches `travel` [m]: sqrt(2 x / a) on the ramp (x <= v^2 / 2a), and
// x / v + v / 2a after it (the ramp loses v / 2a against a pull at v from the start).
double pull_time_at(double travel, double speed, double acceleration = kRigAcceleration);

// The three outcomes of the task (paper section V-A).
enum class Outcome { Good = 0, Missed = 1, Caught = 2 };
inline constexpr int kOutcomeCount = 3;
// Paper V-A's label rule for a pull that stopped before the end of travel: good when no vertex of
// the sleeve opening's lower half ended farther than this from the elbow centre along the pull [m].
inline constexpr double kGoodLabelDistance = 0.07;

// The three controlled arm heights of the study; the real arm deviates from them.
enum class ArmHeight { High = 0, Middle = 1, Low = 2 };

std::string_view outcome_name(Outcome o);            // "good", "missed", "caught"
std::optional<Outcome> parse_outcome(std::string_view s);  // also accepts "miss"
std::string_view arm_height_name(ArmHeight h);       // "high", "middle", "low"
std::optional<ArmHeight> parse_arm_height(std::string_view s);

// One trial's samples and what is known about it.
struct HapticSequence {
  std::string id;                  // unique within a dataset, e.g. "s4-good-3"
  std::string participant;         // e.g. "4"; empty for simulated trials
  ArmHeight height = ArmHeight::High;
  double speed = 0.1;              // [m/s] commanded pull speed
  std::optional<Outcome> label;    // empty when unknown
  std::vector<HapticSample> samples;
};

// How many samples of `trial`'s pull went unrecorded before its first one: 0 unless it starts
// late (kLateStart); then the pull's time at the first sample, read from the constant-speed
// stamp as travel / speed (the trial's commanded speed), over the recording's mean sample period,
// rounded (0.01 s when it has fewer than two samples). s0-middlemiss-10: 0.0958 m at 0.15 m/s is
// 0.639 s, 64 samples of 10.0 ms. Until session 92 the travel was read as the ramped profile's
// (pull_time_at: 0.714 s, 71 samples), which put the HMMs' chain 7 samples (v / 2a) too far on.
std::size_t unrecorded_samples(const HapticSequence& trial);

// A recording's mean sample period [s]: (t_last - t_first) / (n - 1); 0 with fewer than 2 samples.
double mean_sample_period(const HapticSequence& trial);
// Two recordings' mean periods are the same rate within this (relative): a recording's clock
// jitters and drifts. The study's 22 trials' means span 9.99966-10.00041 ms (7.5e-5); a rate that
// changes a model's meaning (125 Hz for 100 Hz) differs by percent. Compared with
// model::same_period (models/dgm.h), which core/ does not include.
inline constexpr double kRecordingPeriodTolerance = 1e-3;
// The nominal period of recordings whose mean is `mean_s`: to the whole microsecond (the study's
// means all give 10 ms), so that a model trained on them matches a predictor configured at that
// rate within model::kPeriodTolerance; `mean_s` itself below 1 us.
double nominal_sample_period(double mean_s);

// Whether a recording holds its pull from `travel` [m] on: its first sample at most kLateStart
// past it (past 0 for a `travel` before the pull's start). A mean over a window of travel that
// begins before a late start would hold only its last samples and be set against another curve's
// whole window (prediction.h, residual_windows; discrepancy.h); such a window is not covered.
// The slack is kLateStart's, not less: the study's recordings that start with the pull do so up
// to 1.02 mm in. False for an empty recording.
bool records_from(const std::vector<HapticSample>& samples, double travel);

}  // namespace dressguard
