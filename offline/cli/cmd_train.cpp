// dressguard train: a labelled dataset -> an outcome model file (one left-right HMM per outcome).
#include <cstdio>
#include <ctime>
#include <iterator>
#include <set>
#include <sstream>

#include "args.h"
#include "commands.h"
#include "dataset.h"
#include "files.h"
#include "dgm.h"
#include "hmm.h"
#include "hmm_options.h"
#include "report.h"

namespace dressguard::cli {

int run_train(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json", "uniform-priors"});
  if (args.has("help")) {
    std::printf(
        "usage: dressguard train --data DATASET[,DATASET...] --out MODEL.dgm [options] [--json]\n"
        "  Trains one left-right HMM per labelled outcome (good, missed, caught) on F_motion and\n"
        "  F_vertical (paper V-B): equal-segment initialisation, Baum-Welch to convergence.\n"
        "  Several datasets (comma-separated, each folder once) are pooled, their trials in the\n"
        "  order given.\n"
        "%s"
        "  --uniform-priors        equal class priors instead of the training counts\n"
        "  --exclude-participant P[,Q...]  leave these participants out (leave-one-participant-out)\n"
        "  --stop-threshold X      predictor default: stop when P(caught) > X ... (default 0.9)\n"
        "  --stop-consecutive K    ... for K consecutive samples (default 5)\n"
        "  --created TIME          creation time to record (default now, UTC); fixes the bytes\n"
        "  --json                  print a machine-readable summary\n",
        kHmmHelp);
    return 0;
  }
  std::set<std::string> known{"help", "json", "uniform-priors", "data", "out", "exclude-participant",
                              "stop-threshold", "stop-consecutive", "created"};
  known.insert(std::begin(kHmmOptionNames), std::end(kHmmOptionNames));
  args.allow_only(known);
  const std::string data = args.require("data"), out = args.require_output_file("out");
  hmm::ModelOptions opt;
  opt.hmm = hmm_options(args);
  opt.uniform_priors = args.has("uniform-priors");
  opt.source_dataset = data;
  const double stop_threshold = args.number("stop-threshold", 0.9);
  const long stop_consecutive = args.integer("stop-consecutive", 5);
  if (!(stop_threshold > 0 && stop_threshold < 1)) throw UsageError("--stop-threshold must be in (0, 1)");
  if (stop_consecutive < 1 || stop_consecutive > 100000) throw UsageError("--stop-consecutive must be 1..100000");
  const auto excluded = split_list(args.get("exclude-participant").value_or(""));
  const Dataset ds = load_datasets(dataset_list("data", data));
  opt.trial_name = [&ds](const HapticSequence& t) { return trial_file_name(ds, t); };
  require_known_participants("exclude-participant", excluded, ds, data);
  std::vector<const HapticSequence*> trials;
  for (const auto& t : ds.trials)
    if (!excluded.count(t.participant)) trials.push_back(&t);
  // The trials trained on, for the summary: the unlabelled ones teach no class.
  size_t labelled = 0;
  for (const auto* t : trials) labelled += t->label.has_value();
  if (labelled == 0) throw InputError(data + ": no labelled trials to train on" + (excluded.empty() ? "" : " (after exclusions)"));

  const bool json = args.has("json");
  model::OutcomeModel m;
  try {
    m = hmm::train_outcome_model(trials, opt, [&](const std::string& line) { std::fprintf(stderr, "train: %s\n", line.c_str()); });
  } catch (const std::invalid_argument& e) {
    throw InputError(data + ": " + e.what());
  }
  m.tool_version = "dressguard 0.1.0 train";
  m.created = args.get("created").value_or(utc_now());
  m.stop_threshold = stop_threshold;
  m.stop_consecutive = static_cast<int>(stop_consecutive);
  if (!excluded.empty()) {
    std::string ex;
    for (const auto& p : excluded) ex += (ex.empty() ? "" : ",") + p;
    m.source_dataset += " (excluding participants " + ex + ")";
  }
  model::write_model(out, m);
  const auto bytes = model::encode_model(m);
  if (json) {
    std::printf("{\"out\": %s, \"bytes\": %zu, \"trials\": %zu, \"model\": %s}\n", hmm::json_string(out).c_str(),
                bytes.size(), labelled, hmm::model_json(m).c_str());
  } else {
    std::printf("trained %zu classes (%d states) on %zu trials; wrote %s (%zu bytes)\n", m.classes.size(),
                opt.hmm.n_states, labelled, out.c_str(), bytes.size());
    std::printf("%s\n", m.training_summary.c_str());
  }
  return 0;
}

}  // namespace dressguard::cli
