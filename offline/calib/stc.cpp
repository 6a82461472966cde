// The simulation-trained classifier, see stc.h.
#include "stc.h"

#include "hmm.h"

#include <cstdio>

namespace dressguard::calib {

model::OutcomeModel build_outcome_model(const std::vector<const HapticSequence*>& trials, const StcOptions& o) {
  hmm::ModelOptions mo;
  mo.hmm = o.hmm;
  mo.uniform_priors = o.uniform_priors;
  mo.features.axis[1] = o.second_axis;
  mo.source_dataset = o.source;
  mo.trial_name = o.trial_name;
  return hmm::train_outcome_model(trials, mo);
}

const char* stc_forces_name(int second_axis) {
  switch (second_axis) {
    case model::kAxisVertical: return "motion,vertical";
    case model::kAxisLateral: return "motion,lateral";
    default: return "motion";
  }
}

namespace {

// Does the calibrated simulator predict this force better than a zero force on every sequence?
// `worst` receives the sequence where it is furthest behind zero (null when it passes).
struct AxisVerdict {
  bool measured = true;
  const SequenceFit* worst = nullptr;
  double error = 0, zero = 0;  // summed over the sequences
};
AxisVerdict judge_axis(const std::vector<SequenceFit>& fits, AxisFit SequenceFit::*axis) {
  AxisVerdict v;
  for (const auto& f : fits) {
    const AxisFit& a = f.*axis;
    if (!a.measured()) return {false, nullptr, 0, 0};
    v.error += a.error;
    v.zero += a.zero;
    if (!(a.error < a.zero) && (!v.worst || a.error - a.zero > (v.worst->*axis).error - (v.worst->*axis).zero))
      v.worst = &f;
  }
  return v;
}

}  // namespace

StcAxes choose_stc_axes(const std::vector<SequenceFit>& fits, bool lateral_fitted) {
  if (fits.empty()) return {model::kAxisVertical, "F_motion and F_vertical (no calibration sequences)"};
  char buf[400];
  std::string lateral_note;  // why F_lateral was not taken, when the calibration fitted it
  if (lateral_fitted) {
    const AxisVerdict l = judge_axis(fits, &SequenceFit::lateral);
    if (l.measured && !l.worst) {
      std::snprintf(buf, sizeof buf,
                    "F_motion and F_lateral: the calibration fitted the lateral force, and it is nearer the measured "
                    "one than a zero force on every sequence (%.3f against %.3f N m in all)",
                    l.error, l.zero);
      return {model::kAxisLateral, buf};
    }
    if (l.worst) {
      std::snprintf(buf, sizeof buf, " (F_lateral on %s: %.3f N m, a zero force %.3f N m)", l.worst->trial_id.c_str(),
                    l.worst->lateral.error, l.worst->lateral.zero);
      lateral_note = buf;
    }
  }
  const AxisVerdict v = judge_axis(fits, &SequenceFit::vertical);
  if (!v.measured) return {model::kAxisVertical, "F_motion and F_vertical (the calibration has no axis fits)"};
  if (v.worst)
    std::snprintf(buf, sizeof buf,
                  "F_motion alone: on %s the calibrated F_vertical is %.3f N m from the measured one, a zero force "
                  "%.3f N m%s",
                  v.worst->trial_id.c_str(), v.worst->vertical.error, v.worst->vertical.zero, lateral_note.c_str());
  else
    std::snprintf(buf, sizeof buf,
                  "F_motion and F_vertical: the calibrated F_vertical is nearer the measured one than a zero force on "
                  "every sequence (%.3f against %.3f N m in all)%s",
                  v.error, v.zero, lateral_note.c_str());
  return {v.worst ? model::kAxisNone : model::kAxisVertical, buf};
}

int count_correct(const model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials, double truncate_at,
                  int* counted, const std::vector<std::string>& among, std::vector<hmm::TrialResult>* per_trial) {
  // hmm::evaluate's rule, and its count: a trial with no sample before the cut (a recording that
  // starts late, cut early) is skipped, not counted wrong, so that bench, build-model and
  // classify score one model on one cut alike.
  std::vector<const HapticSequence*> labelled;
  for (const auto* t : trials)
    if (t->label && !t->samples.empty()) labelled.push_back(t);
  const hmm::Evaluation ev = hmm::evaluate(m, labelled, truncate_at, per_trial, among);
  if (counted) *counted = ev.total;
  return ev.correct;
}

double accuracy(const model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials, double truncate_at,
                int* counted) {
  int n = 0;
  const int right = count_correct(m, trials, truncate_at, &n);
  if (counted) *counted = n;
  return n ? static_cast<double>(right) / n : 0.0;
}

}  // namespace dressguard::calib
