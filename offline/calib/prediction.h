// How well a calibrated simulator predicts the measured sequences of people it was not
// calibrated on (issue 4's yardstick: "no worse than another real person would").
//
// A calibration fits one participant's 2-3 sequences; synthesis then pretends its simulator is a
// population of people. Whether that holds is measured here: the calibrated simulator, with the
// participant's cloth parameters, arm offsets and arm compliance, pulls the sleeve as in each
// labelled, non-caught measured trial of every *other* participant (the trial's height, speed and
// end of travel, calibration.h: request_for), and its curve is scored against that trial with
// the calibration's objective (eq. 3-5, w = 20). Beside it, the same objective from every real
// trial of the same height of a third participant (neither the target's nor the calibrated
// one's) to the target: the real-person yardstick. The simulator predicts a trial "no worse than
// another real person would" when its L is at most the median of those.
//
// Heights that the calibration did not fit (a participant whose inputs hold no middle trial) are
// simulated at the nominal height, offset 0, as synthesis does.
#pragma once

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
  Outcome simulated_outcome = Outcome::Missed;  // the simulator's own label (paper V-A)
  std::vector<HapticSample> simulated;          // the simulated curve, for the overlay plots
};

struct Prediction {
  std::string participant;  // the calibrated one
  std::vector<PredictedTrial> trials;  // in the dataset's order
};

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
// `calibrated`. Empty when there is none.
std::vector<const HapticSequence*> prediction_targets(const Dataset& ds, const std::string& calibrated);

// Simulates every target with `cal`'s parameters and scores it. The targets are dealt round-robin
// into one group per thread and rank (run_batch spreads the groups), and each group goes to the
// batch simulator at once, so that the cloth simulator settles the gown once per group instead of
// once per target (sim::simulate_trials, the same bits as one at a time): the results do not
// depend on the thread or rank count. Throws InputError when the dataset holds no trial of
// another participant to predict.
Prediction predict_others(const Calibration& cal, const Dataset& ds, const TrialBatchSimulator& sim, int threads,
                          const Comm& comm);
// The same with a one-trial simulator (one_by_one).
Prediction predict_others(const Calibration& cal, const Dataset& ds, const TrialSimulator& sim, int threads,
                          const Comm& comm);

// The real-person yardstick of one target: L(other, target) for every labelled, non-caught trial
// of the same height whose participant is neither the target's nor `calibrated`, with the
// objective `kind`; their median (NaN when none) and count.
std::pair<double, int> real_person_median(const Dataset& ds, const HapticSequence& target, const std::string& calibrated,
                                          ObjectiveKind kind);

// The three heights' summaries, high, middle, low; a height without trials has trials = 0.
std::vector<PredictionSummary> summarize(const Prediction& p);

// Per-trial table (CSV: trial_id,participant,height,speed,objective,real_median,real_count,
// vertical_sign,simulated_end,measured_end,simulated_outcome) and the curves for the overlay
// plot (CSV: trial_id,source,travel,f_motion,f_vertical; source "measured" or "simulated").
std::string prediction_csv(const Prediction& p);
std::string prediction_curves_csv(const Prediction& p, const Dataset& ds);

}  // namespace dressguard::calib
