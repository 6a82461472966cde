// The simulation-trained classifier, see stc.h.
#include "stc.h"

#include "hmm.h"

namespace dressguard::calib {

model::OutcomeModel build_outcome_model(const std::vector<const HapticSequence*>& trials, const StcOptions& o) {
  hmm::ModelOptions mo;
  mo.hmm.n_states = o.states;
  mo.uniform_priors = o.uniform_priors;
  mo.source_dataset = o.source;
  return hmm::train_outcome_model(trials, mo);
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
