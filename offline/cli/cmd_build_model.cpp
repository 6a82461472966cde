// dressguard build-model: the simulation-trained classifier (STC) from a calibration (synthesize,
// then train three HMMs) or from an existing dataset (paper V-B).
#include <cstdio>
#include <optional>
#include <vector>

#include "args.h"
#include "calibration.h"
#include "commands.h"
#include "dataset.h"
#include "files.h"
#include "synthesis.h"
#ifdef DRESSGUARD_HAVE_HMM
#include "stc.h"
#endif

namespace dressguard::cli {

using namespace dressguard::calib;

SynthesisOptions synthesis_options_from(const Args& args);
SynthesisSummary run_synthesis(const Calibration& cal, const std::string& gown, const SynthesisOptions& o,
                               const std::string& out);

int run_build_model(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json", "no-gown-noise", "no-arm-noise"});
  if (args.has("help")) {
    std::puts(
        "usage: dressguard build-model (--calibration CAL.json | --data DATASET) --out MODEL.dgm [options]\n"
        "  With --calibration: synthesizes the training data first (into --synth-dir, default\n"
        "  MODEL.dgm.synth/, resumable; the synthesize options apply), then trains one 10-state\n"
        "  left-right bivariate HMM per outcome (paper V-B) and writes the model file.\n"
        "  With --data: trains on the labelled trials of an existing dataset.\n"
        "  --states N   hidden states per HMM (default 10, paper VI)\n"
        "  --forces F   auto | both | lateral | motion: the second force beside F_motion\n"
        "               (F_vertical, F_lateral or none). Default auto: with --calibration,\n"
        "               F_lateral when the calibration fitted it (--lateral-weight), else\n"
        "               F_vertical, each only where the calibrated simulator predicts it better\n"
        "               than a zero force on every one of the calibration's sequences\n"
        "               (offline/calib/stc.h); with --data, both\n"
        "  --per-height N --no-gown-noise --no-arm-noise --middle M --seed S --threads N --gown G\n"
        "               (synthesis; see dressguard synthesize --help)\n"
        "  --created T  creation time to record (default now, UTC); fixes the model's bytes\n"
        "  --json       machine-readable summary");
    return 0;
  }
  args.allow_only({"help", "json", "no-gown-noise", "no-arm-noise", "calibration", "data", "out", "synth-dir",
                   "states", "per-height", "seed", "gown", "threads", "forces", "middle", "created"});
  const std::string out = args.require("out");
  if (args.has("calibration") == args.has("data")) throw UsageError("give exactly one of --calibration and --data");
  const int states = static_cast<int>(args.integer("states", 10));
  if (states < 1 || states > 32) throw UsageError("--states must be in 1..32");
  const std::string forces = args.get("forces").value_or("auto");
  if (forces != "auto" && forces != "both" && forces != "motion" && forces != "lateral")
    throw UsageError("--forces must be auto, both, lateral or motion");
  std::string data;
  std::optional<std::vector<SequenceFit>> calibration_fits;
  bool lateral_fitted = false;
  if (args.has("calibration")) {
    const Calibration cal = read_calibration(*args.get("calibration"));
    calibration_fits = cal.fits;
    lateral_fitted = cal.lateral_weight > 0;
    data = args.get("synth-dir").value_or(out + ".synth");
    run_synthesis(cal, args.get("gown").value_or(cal.gown), synthesis_options_from(args), data);
  } else {
    data = *args.get("data");
  }
  if (!Comm::world().is_root()) return 0;  // training is one process's job (seconds)
#ifndef DRESSGUARD_HAVE_HMM
  throw UsageError("this dressguard was built without the HMM module (offline/hmm); build-model needs it");
#else
  const Dataset ds = load_dataset(data);
  std::vector<const HapticSequence*> trials;
  for (const auto& t : ds.trials) trials.push_back(&t);
  StcAxes axes{model::kAxisVertical, "F_motion and F_vertical (training data given directly)"};
  if (forces == "both") axes = {model::kAxisVertical, "F_motion and F_vertical (--forces both)"};
  else if (forces == "lateral") axes = {model::kAxisLateral, "F_motion and F_lateral (--forces lateral)"};
  else if (forces == "motion") axes = {model::kAxisNone, "F_motion alone (--forces motion)"};
  else if (calibration_fits) axes = choose_stc_axes(*calibration_fits, lateral_fitted);
  StcOptions so;
  so.states = states;
  so.source = data + "; forces: " + axes.reason;
  so.second_axis = axes.second_axis;
  model::OutcomeModel m = build_outcome_model(trials, so);
  m.tool_version = "dressguard 0.1.0 build-model";
  m.created = args.get("created").value_or(utc_now());
  model::write_model(out, m);
  const double acc = accuracy(m, trials, std::numeric_limits<double>::infinity());
  if (args.has("json")) {
    std::printf("{\"model\": \"%s\", \"classes\": %zu, \"training_trials\": %zu, \"training_accuracy\": %.4f, "
                "\"forces\": \"%s\"}\n",
                out.c_str(), m.classes.size(), trials.size(), acc, stc_forces_name(axes.second_axis));
  } else {
    std::printf("wrote %s: %zu classes (", out.c_str(), m.classes.size());
    for (std::size_t i = 0; i < m.classes.size(); ++i) std::printf("%s%s", i ? ", " : "", m.classes[i].name.c_str());
    std::printf(") from %zu trials of %s; accuracy on its own training data %.1f%%\nforces modelled: %s\n",
                trials.size(), data.c_str(), 100 * acc, axes.reason.c_str());
  }
  return 0;
#endif
}

}  // namespace dressguard::cli
