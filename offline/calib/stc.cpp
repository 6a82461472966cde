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
  if (fits.empty()) return {true, "F_motion and F_vertical (no calibration sequences)"};
  double error = 0, zero = 0;
  const SequenceFit* worst = nullptr;  // the sequence where the simulation is furthest behind zero
  for (const auto& f : fits) {
    if (!f.vertical.measured()) return {true, "F_motion and F_vertical (the calibration has no axis fits)"};
    error += f.vertical.error;
    zero += f.vertical.zero;
    if (!(f.vertical.error < f.vertical.zero) &&
        (!worst || f.vertical.error - f.vertical.zero > worst->vertical.error - worst->vertical.zero))
      worst = &f;
  }
  char buf[240];
  if (worst)
    std::snprintf(buf, sizeof buf,
                  "F_motion alone: on %s the calibrated F_vertical is %.3f N m from the measured one, a zero force "
                  "%.3f N m",
                  worst->trial_id.c_str(), worst->vertical.error, worst->vertical.zero);
  else
    std::snprintf(buf, sizeof buf,
                  "F_motion and F_vertical: the calibrated F_vertical is nearer the measured one than a zero force on "
                  "every sequence (%.3f against %.3f N m in all)",
                  error, zero);
  return {worst == nullptr, buf};
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
