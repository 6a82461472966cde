// Text and JSON renderings of outcome models and evaluations, shared by `dressguard train`,
// `classify` and `model show` (so every command prints a model or a confusion matrix alike).
#pragma once

#include <string>
#include <string_view>

#include "dgm.h"
#include "json.h"
#include "hmm.h"

namespace dressguard::hmm {

// core/json.h's, under the names this module's callers have always used.
using dressguard::json_number;
using dressguard::json_string;
// The whole model as one JSON object (metadata, features, stop policy, every class's parameters).
std::string model_json(const model::OutcomeModel& m);
// The confusion matrix as aligned text, rows = truth, columns = predicted.
std::string confusion_text(const Evaluation& ev);
// The accuracy as text, "0.6818", or "-" when no trial was scored: an evaluation of nothing has
// no accuracy, and 0 would read as every trial wrong (classify's text and its sweep).
std::string accuracy_text(const Evaluation& ev);
// {"classes": [...], "confusion": [[...]], "correct": n, "total": n, "skipped": n, "accuracy": x,
//  "accuracy_interval": [lower, upper]} (the 95 % Wilson interval, wilson_interval); when no
// trial was scored "accuracy" is null and the interval is left out, as in classify's sweep.
std::string evaluation_json(const Evaluation& ev);

}  // namespace dressguard::hmm
