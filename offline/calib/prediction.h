// How well a calibrated simulator predicts the measured sequences of people it was not
// calibrated on (issue 4's yardstick: "no worse than another real person would").
//
// A calibration fits one participant's 2-3 sequences; synthesis then pretends its simulator is a
// population of people. Whether that holds is measured here: the calibrated simulator, with the
// participant's cloth parameters, arm offsets and arm compliance, pulls the sleeve as in each
// labelled, non-caught measured trial of every *other* participant (the trial's height, speed and
// end of travel, calibration.h: request_for), and its curve is scored against that trial with
// the calibration's objective (eq. 3-5, w = 20). Beside it, the same objective from every real
// trial of the same height and speed of a third participant (neither the target's nor the
// calibrated one's) to the target: the real-person yardstick. The simulator predicts a trial "no worse than
// another real person would" when its L is at most the median of those.
//
// Heights that the calibration did not fit (a participant whose inputs hold no middle trial) are
// simulated at the nominal height, offset 0, as synthesis does.
#pragma once

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calibration.h"

namespace dressguard::calib {

// One predicted trial of another participant.
struct PredictedTrial {
  std::string trial_id;
  std::string participant;
  ArmHeight height = ArmHeight::High;
  double speed = 0.1;
  double objective = 0;       // L(simulated, measured), the calibration's objective kind
  double real_median = 0;     // median L(another real person's trial, measured); NaN: no such trial
  int real_count = 0;         // how many real trials that median is over
  double vertical_sign = 0;   // vertical_sign_agreement(simulated, measured); NaN: none to agree on
  double simulated_end = 0;   // [m] travel where the simulated pull stopped
  double measured_end = 0;    // [m] and the measured one
  // The simulator's own label (paper V-A); none when its simulation did not stay finite.
  std::optional<Outcome> simulated_outcome;
  std::vector<HapticSample> simulated;          // the simulated curve, for the overlay plots
};

struct Prediction {
  std::string participant;  // the calibrated one
  std::vector<PredictedTrial> trials;  // in the dataset's order
  // What simulated the curves, carried into every output so that a corrected prediction's files
  // are not taken for the plain simulator's: the gown (predict_others: the calibration's; a
  // caller that simulates on another sets it) and whether add_discrepancy corrected them.
  std::string gown;
  bool discrepancy = false;
};

// "simulated", or "simulated+discrepancy" after add_discrepancy: the curves' source in
// prediction_curves_csv.
std::string simulated_source(const Prediction& p);

// Per height: the medians over the predicted trials of that height (NaN where there are none).
struct PredictionSummary {
  ArmHeight height = ArmHeight::High;
  int trials = 0;
  double objective_median = 0;    // median L of the simulator
  double real_median = 0;         // median of the trials' real-person medians
  int no_worse = 0;               // trials where the simulator's L <= their real-person median
  double vertical_sign_median = 0;
};

// The trials predicted: every labelled, non-caught trial of `ds` whose participant is not
// `calibrated`. Empty when there is none; InputError for one not recorded at the simulator's
// rate (calibration.h, require_simulated_rate).
std::vector<const HapticSequence*> prediction_targets(const Dataset& ds, const std::string& calibrated);

// Progress of predict_others on this rank: targets done of this rank's, elapsed and estimated
// remaining seconds.
struct PredictionProgress {
  int done = 0, total = 0;
  double elapsed_s = 0, eta_s = 0;
};

// At most this many targets (of one height) share one settling, so that progress comes every
// few trials; the settling is then done once per 4 targets instead of once per target.
inline constexpr int kPredictionGroup = 4;

// Simulates every target with `cal`'s parameters and scores it. The targets go in groups of one
// height (one arm placement), at most kPredictionGroup a group and at least one group per thread
// and rank where there are enough (run_batch spreads the groups), and each group to the batch
// simulator at once, so that the cloth simulator settles the gown once per group instead of once
// per target (sim::simulate_trials: an arm placed alike settles alike, the same bits as one at a
// time): the results do not depend on the thread or rank count. `progress` (rank 0, may be empty) hears after every group. Throws
// InputError when the dataset holds no trial of another participant to predict.
Prediction predict_others(const Calibration& cal, const Dataset& ds, const TrialBatchSimulator& sim, int threads,
                          const Comm& comm, const std::function<void(const PredictionProgress&)>& progress = {});
// The same with a one-trial simulator (one_by_one).
Prediction predict_others(const Calibration& cal, const Dataset& ds, const TrialSimulator& sim, int threads,
                          const Comm& comm, const std::function<void(const PredictionProgress&)>& progress = {});

// The prediction of a simulator extended by a discrepancy term (discrepancy.h: what the
// calibrated simulator gets wrong on its own person's sequences): `d` is added to every
// simulated curve of `p`, and each trial's objective (the calibration's `kind`) and vertical
// sign are scored again against its measured trial in `ds`. Whether that lowers L on *other*
// people says how much of the error belongs to the simulator rather than to the person
// (`dressguard predict --discrepancy`). Outcomes and ends stay the simulator's; `p` is marked
// corrected (Prediction::discrepancy).
struct Discrepancy;
void add_discrepancy(Prediction& p, const Discrepancy& d, const Dataset& ds, ObjectiveKind kind);

// The real-person yardstick of one target: L(other, target) for every labelled, non-caught trial
// of the same height and pull speed whose participant is neither the target's nor `calibrated`,
// with the objective `kind`; their median (NaN when none) and count.
//
// The same speed, because eq. 3-5 pairs the two curves sample by sample: at 0.15 against 0.1 m/s
// sample i of the faster pull runs 5 cm further ahead each second, and it ends its travel seconds
// earlier, so w = 20 weighs the slower one's whole tail. Such an L measures the rig's speed,
// not how another person differs: the study's one 0.15 m/s trial (s0-middlemiss-10) put the
// middle arm's yardstick at 0.71-0.97 where the same-speed trials give 0.25-0.32 (session 90's
// review). A target with no other trial at its speed has no yardstick (NaN, count 0), and
// `summarize` makes no claim for it.
inline constexpr double kSamePullSpeed = 0.005;  // [m/s] 5 % of the study's 0.1 m/s: about 3.5 cm
                                                 // of travel apart after a 7 s pull
inline bool same_pull_speed(double a, double b) { return std::abs(a - b) <= kSamePullSpeed; }
std::pair<double, int> real_person_median(const Dataset& ds, const HapticSequence& target, const std::string& calibrated,
                                          ObjectiveKind kind);

// The three heights' summaries, high, middle, low; a height without trials has trials = 0.
std::vector<PredictionSummary> summarize(const Prediction& p);

// Per-trial table (CSV: trial_id,participant,height,speed,objective,real_median,real_count,
// vertical_sign,simulated_end,measured_end,simulated_outcome,gown,discrepancy; simulated_outcome
// empty for a simulation that did not stay finite; the last two the same on every row,
// discrepancy 0 or 1, for the plots' titles) and the curves for the overlay
// plot (CSV: trial_id,source,travel,f_motion,f_vertical; source "measured" or
// simulated_source(p)).
std::string prediction_csv(const Prediction& p);
std::string prediction_curves_csv(const Prediction& p, const Dataset& ds);

// ---- what the simulation gets wrong: the residual over travel ------------------------------------
//
// L says how far a prediction is off; the residual says where and which way. Per height and
// travel window [from, to), over the predicted trials whose measured and simulated curves both
// cover it (the measured one recorded from `from` on, records_from, and both reaching `to`): each
// trial's mean force over the window (samples with from <= travel < to; the recording's samples
// at their simulated partners' travel, as eq. 3 pairs them: objective.h,
// measured_on_simulated_travel; by its stamp until session 94), then each person's
// mean over their trials there, then over those people the measured mean, the people's spread
// (the sample standard deviation of the people's means: how much the real people differ from
// each other there) and the simulated mean (of the people's simulated means). Per person first,
// because a person's repeats are not other people: counted per trial, the study's four people
// with two trials of one height each counted twice in the mean, and their repeats, closer to
// each other than to anyone else, shrank the spread and, as two in n, the contrast's standard
// error (3 of 84 windows of participant 4's prediction were outside the trials' spread and
// inside the people's). residual = simulated - measured; F_motion is negative for drag, so a
// positive F_motion residual is too little drag, and a positive F_vertical one too much upward
// force on the gripper (or too little downward).
//
// A window is *outside* the people when at least kResidualMinPeople people cover it and
// |residual| exceeds both the people's spread and kResidualFloor: there the simulated mean is
// further from the measured mean than a typical person is. (The floor keeps windows where every
// person measures nearly the same, 0.02-0.05 N apart at the start of a pull, from flagging
// differences of the size of the sensor's drift; it is six times the sensor's noise, 0.017 N.)
inline constexpr int kResidualMinPeople = 3;
inline constexpr double kResidualFloor = 0.1;  // [N]

// The forces the residual and the contrast look at, by index: [0] F_motion, [1] F_vertical (the
// paper's two) and [2] F_lateral (positive toward the person: sim/trial.h). F_lateral since
// 2026-11-25: the people's good and missed trials differ in it from 0.15 m of travel on
// (offline/sim/MEASUREMENTS.md, "The lateral force").
inline constexpr int kForces = 3;
const char* force_name(int axis);    // "F_motion", "F_vertical", "F_lateral"
const char* force_column(int axis);  // "motion", "vertical", "lateral" (the CSV columns' suffixes)

struct ResidualWindow {
  ArmHeight height = ArmHeight::High;
  double from = 0, to = 0;  // [m] travel
  int trials = 0;           // the trials that cover the window
  int people = 0;           // and their participants: the n of the mean and the spread
  // by force (kForces); NaN when no trial covers the window
  double measured[kForces] = {}, spread[kForces] = {}, simulated[kForces] = {};
  double residual(int axis) const { return simulated[axis] - measured[axis]; }
  bool outside(int axis) const;
};

// The windows of every height that has predicted trials, `window` metres wide from travel 0 to
// the longest measured travel (windows no trial covers have trials = 0). Throws
// std::invalid_argument for a window that is not positive.
std::vector<ResidualWindow> residual_windows(const Prediction& p, const Dataset& ds, double window = 0.05);

// Runs of consecutive outside windows of one height and axis whose residuals share a sign, as
// findings: the run's travel, its mean residual, measured mean and spread (means over the run's
// windows), the fewest trials and people of its windows, and one line of text. Sorted by |residual| times
// the run's length (its share of eq. 3's area), largest first.
struct ResidualFinding {
  ArmHeight height = ArmHeight::High;
  int axis = 0;  // force_name(axis)
  double from = 0, to = 0, residual = 0, measured = 0, spread = 0;
  int trials = 0, people = 0;
  std::string text;
};
std::vector<ResidualFinding> residual_findings(const std::vector<ResidualWindow>& windows);

// CSV: height,from,to,trials,people, then measured/spread/simulated/residual/outside for F_motion, for
// F_vertical and for F_lateral (tools/plot/calib_overlay.py residual).
std::string residual_csv(const std::vector<ResidualWindow>& windows);

// ---- what a simulation-trained classifier learns wrong: the contrast between the heights ----------
//
// The STC tells the classes apart by how the forces differ between the arm heights that produce
// them: good at the high arm, missed at the middle and low ones (the classes the measured files
// hold). Cut early (issue 4: 0.15-0.30 m of travel) little else is left to tell them by, and a
// simulator whose residual is moderate at every height can still order the heights the wrong
// way round there, so that a classifier trained on it learns the opposite of what people show.
//
// Per travel window, force and lower height (middle, low), from the residual windows:
//   contrast = mean(high) - mean(lower height),
// for the people (measured) and for the simulator (its predictions of the same trials). The
// people show a contrast where both heights hold kResidualMinPeople people and
//   |contrast| > max(kResidualFloor, 2 SE),  SE = sqrt(s_high^2 / n_high + s_low^2 / n_low)
// (s the people's spread of each height's window and n its people, each person's trials
// averaged first: the difference of two means is then more than twice its standard error, and
// above the sensor's drift). The simulator then
//   agrees     same sign and |simulated contrast| > kResidualFloor,
//   misses it  |simulated contrast| <= kResidualFloor (no cue: the classifier learns nothing here),
//   reverses   opposite sign and |simulated contrast| > kResidualFloor (a wrong cue).
enum class ContrastVerdict { NoContrast, Agrees, Misses, Reverses };
std::string_view contrast_verdict_name(ContrastVerdict v);  // "none", "agrees", "misses", "reverses"

struct HeightContrast {
  ArmHeight lower = ArmHeight::Low;  // the height compared with the high arm
  double from = 0, to = 0;           // [m] travel
  int trials_high = 0, trials_lower = 0;
  int people_high = 0, people_lower = 0;  // the SE's n
  // by force (kForces): high minus lower [N]; NaN where either height has no trial
  double measured[kForces] = {}, standard_error[kForces] = {}, simulated[kForces] = {};
  ContrastVerdict verdict[kForces] = {ContrastVerdict::NoContrast, ContrastVerdict::NoContrast,
                                      ContrastVerdict::NoContrast};
};

// One entry per window and lower height that both heights have windows for (in the windows'
// order: middle first, then low).
std::vector<HeightContrast> height_contrasts(const std::vector<ResidualWindow>& windows);

// Runs of consecutive windows of one lower height and force where the people show a contrast
// of one sign and the simulator misses or reverses it (one verdict per run), as one line each,
// e.g. "F_vertical, high against low, 0.20-0.30 m: the people's high arm reads +0.17 N against
// their low arm; the simulator's -0.31 N (reverses: a classifier trained on it learns the
// opposite here)". Sorted by the run's start, then by force.
struct ContrastFinding {
  ArmHeight lower = ArmHeight::Low;
  int axis = 0;  // force_name(axis)
  ContrastVerdict verdict = ContrastVerdict::Reverses;
  double from = 0, to = 0, measured = 0, simulated = 0;  // means over the run's windows
  std::string text;
};
std::vector<ContrastFinding> contrast_findings(const std::vector<HeightContrast>& contrasts);

// The verdicts counted over the windows that end at or before `up_to` metres (every force, both
// lower heights): what a sequence cut there holds (kLatestCut: objective.h). Since 2026-11-25 with
// F_lateral's windows.
struct ContrastTally {
  int agrees = 0, misses = 0, reverses = 0;  // NoContrast windows are not counted
};
ContrastTally tally_contrasts(const std::vector<HeightContrast>& contrasts, double up_to = kLatestCut);

// CSV: lower,from,to,trials_high,trials_lower,people_high,people_lower, then
// measured/standard_error/simulated/verdict for
// F_motion, for F_vertical and for F_lateral (tools/plot/calib_overlay.py contrast).
std::string contrast_csv(const std::vector<HeightContrast>& contrasts);

}  // namespace dressguard::calib
