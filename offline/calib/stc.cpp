// The simulation-trained classifier, see stc.h.
#include "stc.h"

#include "hmm.h"

#include <cstdio>

namespace dressguard::calib {

model::OutcomeModel build_outcome_model(const std::vector<const HapticSequence*>& trials, const StcOptions& o) {
  hmm::ModelOptions mo;
  mo.hmm.n_states = o.states;
  mo.uniform_priors = o.uniform_priors;
  mo.features.axis[1] = o.use_vertical ? model::kAxisVertical : model::kAxisNone;
  mo.source_dataset = o.source;
  return hmm::train_outcome_model(trials, mo);
}

StcAxes choose_stc_axes(const std::vector<SequenceFit>& fits) {
  double error = 0, zero = 0;
  for (const auto& f : fits) {
    if (!f.vertical.measured()) return {true, "F_motion and F_vertical (the calibration has no axis fits)"};
    error += f.vertical.error;
    zero += f.vertical.zero;
  }
  if (fits.empty()) return {true, "F_motion and F_vertical (no calibration sequences)"};
  char buf[200];
  const bool use = error < zero;
  std::snprintf(buf, sizeof buf, "%s: the calibrated F_vertical is %.3f N m from the measured one, a zero force %.3f N m",
                use ? "F_motion and F_vertical" : "F_motion alone", error, zero);
  return {use, buf};
}

double accuracy(const model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials, double truncate_at,
                int* counted) {
  std::vector<const HapticSequence*> labelled;
  for (const auto* t : trials)
    if (t->label && !t->samples.empty()) labelled.push_back(t);
  const hmm::Evaluation e = hmm::evaluate(m, labelled, truncate_at);
  if (counted) *counted = static_cast<int>(labelled.size());
  return labelled.empty() ? 0.0 : static_cast<double>(e.correct) / labelled.size();
}

}  // namespace dressguard::calib
