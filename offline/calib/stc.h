// The simulation-trained classifier (STC, paper section V-B and VI): one left-right HMM per
// outcome, trained on a synthesized dataset with the HMM module (dg_hmm), written as a .dgm model.
// Built only when dg_hmm is (DRESSGUARD_HAVE_HMM).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "calibration.h"
#include "dataset.h"
#include "dgm.h"
#include "hmm.h"

namespace dressguard::calib {

struct StcOptions {
  hmm::TrainOptions hmm;       // Baum-Welch's; its defaults are paper VI's 10 hidden states
  bool uniform_priors = true;  // paper V-B: the class whose HMM has the highest likelihood
  // The second feature beside F_motion: model::kAxisVertical (the paper's), kAxisLateral, or
  // kAxisNone (F_motion alone).
  int second_axis = model::kAxisVertical;
  std::string source;          // written into the model's metadata
  // Names a training trial in an error (its file, where the caller knows it); empty: its id.
  std::function<std::string(const HapticSequence&)> trial_name;
};

// Which forces an STC should model, from its calibration. The paper's HMMs are bivariate
// (F_motion, F_vertical), but a force the simulator gets wrong (our sleeve-pulling gown hangs on
// the arm and lifts the gripper where the measured vertical force stays near 0;
// offline/calib/MEASUREMENTS.md, session 5) teaches the classifier a difference between
// simulation and reality instead of one between outcomes. So a second force is modelled only where
// the calibrated simulator predicts it better than a zero force does on every one of the
// calibration's own sequences (AxisFit::error < AxisFit::zero, calibration.h). Every sequence, not
// their sum: each outcome's HMM learns mostly from one arm height, so a force wrong at one height
// is wrong in that class (participant 4's paper-budget calibration: right at the low arm, wrong at
// the high one, better in sum; its bivariate STC scored 15-20 % at 0.20-0.25 m of travel, F_motion
// alone 45 %; offline/calib/MEASUREMENTS.md, session 15).
// In order:
//  1. F_lateral when the calibration fitted it (`lateral_fitted`: calibrate --lateral-weight) and
//     it passes: the people's good and missed trials differ in it from 0.1 m of travel on, where
//     they barely differ in the other two (offline/sim/MEASUREMENTS.md, "The lateral force");
//  2. F_vertical when it passes (the paper's pair);
//  3. F_motion alone.
// Both forces when the fits were not measured (a calibration file written before 2026-11-23).
struct StcAxes {
  int second_axis = model::kAxisVertical;
  std::string reason;  // one line for the terminal and the model's metadata
};
StcAxes choose_stc_axes(const std::vector<SequenceFit>& fits, bool lateral_fitted = false);
// "motion,vertical", "motion,lateral" or "motion".
const char* stc_forces_name(int second_axis);

// Trains the HMMs of every outcome present among the labelled trials.
model::OutcomeModel build_outcome_model(const std::vector<const HapticSequence*>& trials, const StcOptions& o);

// How many of the labelled `trials` the model gets right, with every trial cut after
// `truncate_at` metres of travel (infinity: whole), deciding `among` the named classes only
// (empty: all; hmm::classify). A trial whose label is not a class of the model counts as wrong
// (a model trained on simulated data without any "good" trial cannot be right about a good
// trial). The trials counted are hmm::evaluate's: the labelled ones with a sample before the cut;
// one without (a recording that starts late, cut before its start) is skipped, not counted wrong,
// so that this and `classify` score one model on one cut alike. `counted` receives their number,
// `per_trial` (may be null) each labelled trial's result, skipped ones included (hmm::evaluate).
int count_correct(const model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials,
                  double truncate_at, int* counted = nullptr, const std::vector<std::string>& among = {},
                  std::vector<hmm::TrialResult>* per_trial = nullptr);

// The same as a fraction of the trials counted (0 when none was: check `counted`).
double accuracy(const model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials,
                double truncate_at, int* counted = nullptr);

}  // namespace dressguard::calib
