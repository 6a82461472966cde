// dressguard build-model: the simulation-trained classifier (STC) from a calibration (synthesize,
// then train three HMMs) or from an existing dataset (paper V-B).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include "args.h"
#include "calibration.h"
#include "commands.h"
#include "dataset.h"
#include "discrepancy.h"
#include "files.h"
#include "hmm_options.h"
#include "json.h"
#include "synthesis.h"
#ifdef DRESSGUARD_HAVE_SIM
#include "sim_bridge.h"
#endif
#ifdef DRESSGUARD_HAVE_HMM
#include "stc.h"
#endif

namespace dressguard::cli {

using namespace dressguard::calib;

SynthesisOptions synthesis_options_from(const Args& args);
SynthesisSummary run_synthesis(const Calibration& cal, const std::string& gown, const SynthesisOptions& o,
                               const std::string& out);

// The file --training-out leaves beside its manifest: this folder's dataset is build-model's.
constexpr const char* kTrainingOutMark = "training-set.txt";

int run_build_model(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json", "no-gown-noise", "no-arm-noise"});
  if (args.has("help")) {
    std::printf(
        "usage: dressguard build-model (--calibration CAL.json[,CAL...] | --data DATASET[,DATASET...])\n"
        "                              --out MODEL.dgm [options]\n"
        "  With --calibration: synthesizes the training data first (into --synth-dir, default\n"
        "  MODEL.dgm.synth/, resumable; the synthesize options apply), then trains one 10-state\n"
        "  left-right bivariate HMM per outcome (paper V-B) and writes the model file.\n"
        "  Several calibrations (several people's simulators, paper VII) each synthesize their\n"
        "  own set, into SYNTH-DIR/<calibration file's name>/, and the HMMs learn from all of them.\n"
        "  With --data: trains on the labelled trials of existing datasets (several are pooled,\n"
        "  each folder once).\n"
        "  --forces F   auto | both | lateral | motion: the second force beside F_motion\n"
        "               (F_vertical, F_lateral or none). Default auto: with --calibration,\n"
        "               F_lateral when the calibration fitted it (--lateral-weight), else\n"
        "               F_vertical, each only where the calibrated simulator predicts it better\n"
        "               than a zero force on every one of the calibration's sequences\n"
        "               (offline/calib/stc.h; pooled: on every sequence of every\n"
        "               calibration); with --data, both\n"
        "  --discrepancy DATASET   with --calibration: add what each calibrated simulator gets\n"
        "               wrong on its own sequences (found in DATASET, the measured data it was\n"
        "               calibrated on) to every trial it synthesized, before training\n"
        "               (offline/calib/discrepancy.h; Kennedy-O'Hagan's discrepancy term). Writes\n"
        "               MODEL.dgm.discrepancy.csv. --forces auto then takes the paper's F_vertical:\n"
        "               the correction removes the error that the rule above guards against\n"
        "  --per-height N --no-gown-noise --no-arm-noise --middle M --high-low H --seed S --threads N --gown G\n"
        "               (synthesis; see dressguard synthesize --help)\n"
        "  --label-margin M   leave out of training every synthesized trial whose label the rule's\n"
        "               7 cm decides by less than M metres (a stopped trial with max(d_behind,\n"
        "               d_ahead) within M of 7 cm, from each set's labels.csv): a label that the\n"
        "               noise models flip at random teaches a class the other's forces. Default 0\n"
        "  --training-out DIR   also write the trials the HMMs learnt, as a dataset: after\n"
        "               --label-margin and with --discrepancy's correction added, which the\n"
        "               synthesized set on disk does not hold. What `classify --weigh-on` weighs\n"
        "               this model's fellow members on. One training set only. It replaces\n"
        "               only a dataset it wrote itself (marked by training-set.txt)\n"
        "  --priors P   uniform (default: the paper's highest likelihood, and a caught arm's HMM\n"
        "               as likely as the others before any force is read) | training: each\n"
        "               class's share of the training trials (the Bayes decision for trials\n"
        "               drawn like the synthesized ones: the protocol's three heights alike)\n"
        "  --created T  creation time to record (default now, UTC); fixes the model's bytes\n"
        "  --json       machine-readable summary\n"
        " Baum-Welch (dressguard train's):\n%s",
        kHmmHelp);
    return 0;
  }
  std::set<std::string> known{"help", "json", "no-gown-noise", "no-arm-noise", "calibration", "data", "out",
                              "synth-dir", "per-height", "seed", "gown", "threads", "forces", "middle", "high-low",
                              "created", "discrepancy", "label-margin", "priors", "training-out"};
  known.insert(std::begin(kHmmOptionNames), std::end(kHmmOptionNames));
  args.allow_only(known);
  const std::string out = args.require_output_file("out");
  if (args.has("calibration") == args.has("data")) throw UsageError("give exactly one of --calibration and --data");
  const hmm::TrainOptions baum_welch = hmm_options(args);  // before the synthesis: a bad value fails at once
  const std::string priors = args.get("priors").value_or("uniform");
  if (priors != "uniform" && priors != "training") throw UsageError("--priors must be uniform or training");
  const std::string forces = args.get("forces").value_or("auto");
  if (forces != "auto" && forces != "both" && forces != "motion" && forces != "lateral")
    throw UsageError("--forces must be auto, both, lateral or motion");
  const double label_margin = args.number("label-margin", 0.0);
  if (!(label_margin >= 0.0 && label_margin < kGoodLabelDistance))
    throw UsageError("--label-margin must be in [0, 0.07) metres");
  if (args.has("training-out") && args.has("calibration") &&
      split_in_order(*args.get("calibration")).size() > 1)
    throw UsageError("--training-out writes one training set: give one --calibration (several pool their sets)");
  if (args.has("training-out") && args.has("data") && split_in_order(*args.get("data")).size() > 1)
    throw UsageError("--training-out writes one training set: give one --data (several pool their sets)");
  if (args.has("discrepancy") && !args.has("calibration"))
    throw UsageError("--discrepancy needs --calibration: it is a calibrated simulator's error on its own sequences");
  // The synthesis's options with --data would be ignored without a word.
  for (const char* o : {"per-height", "seed", "gown", "synth-dir", "middle", "high-low", "no-gown-noise",
                        "no-arm-noise", "threads"})
    if (args.has("data") && args.has(o))
      throw UsageError(std::string("--") + o + " needs --calibration: it sets the synthesis, and --data trains on "
                       "the datasets as they are");
  // --training-out replaces the dataset in its folder: only one it wrote itself (its mark beside
  // the manifest), never, say, the measured trials.
  const auto training_out = args.get("training-out");
  if (training_out && std::filesystem::exists(std::filesystem::path(*training_out) / "manifest.csv") &&
      !std::filesystem::exists(std::filesystem::path(*training_out) / kTrainingOutMark))
    throw UsageError("--training-out " + *training_out + " holds a dataset build-model did not write (no " +
                     kTrainingOutMark + " beside its manifest): choose another folder or remove it");
  // The training sets: one per calibration (synthesized here) or the datasets given.
  std::vector<std::filesystem::path> sets;
  std::vector<std::pair<std::string, Discrepancy>> discrepancies;  // per set (calibration file), with --discrepancy
  std::optional<std::vector<SequenceFit>> calibration_fits;
  bool lateral_fitted = false;
  if (args.has("calibration")) {
    const auto files = split_in_order(*args.get("calibration"));
    if (files.empty()) throw UsageError("--calibration names no file");
    std::vector<Calibration> cals;
    for (const auto& f : files) cals.push_back(read_calibration(f));  // every file checked before any synthesis
    const std::filesystem::path synth = args.get("synth-dir").value_or(out + ".synth");
    if (files.size() == 1) sets.push_back(synth);
    // Several: one folder per calibration, named after its file: resumable per simulator, and a
    // second file of the same name would write into the first one's trials.
    for (std::size_t i = 0; files.size() > 1 && i < files.size(); ++i) {
      const std::filesystem::path dir = synth / std::filesystem::path(files[i]).stem();
      if (std::find(sets.begin(), sets.end(), dir) != sets.end())
        throw UsageError("--calibration: two files are named " + std::filesystem::path(files[i]).stem().string() +
                         ": their synthesized sets would share " + dir.string());
      sets.push_back(dir);
    }
    calibration_fits.emplace();
    lateral_fitted = true;
    const SynthesisOptions so = synthesis_options_from(args);
    for (std::size_t i = 0; i < cals.size(); ++i) {
      calibration_fits->insert(calibration_fits->end(), cals[i].fits.begin(), cals[i].fits.end());
      lateral_fitted = lateral_fitted && cals[i].lateral_weight > 0;
      if (cals.size() > 1 && Comm::world().is_root())
        std::fprintf(stderr, "build-model: simulator %zu of %zu, %s -> %s\n", i + 1, cals.size(), files[i].c_str(),
                     sets[i].string().c_str());
      run_synthesis(cals[i], args.get("gown").value_or(cals[i].gown), so, sets[i]);
    }
    if (args.has("discrepancy") && Comm::world().is_root()) {  // training's input: one process's
#ifndef DRESSGUARD_HAVE_SIM
      throw UsageError("this dressguard was built without the cloth simulator (offline/sim); --discrepancy needs it");
#else
      const std::filesystem::path where = *args.get("discrepancy");
      const Dataset measured = load_dataset(where);
      for (std::size_t i = 0; i < cals.size(); ++i) {
        // The synthesis's gown: the correction belongs to the simulator that made the trials.
        const std::string gown = args.get("gown").value_or(cals[i].gown);
        discrepancies.emplace_back(
            files[i], discrepancy_of(cals[i], calibration_inputs(cals[i], files[i], measured, where / "manifest.csv"),
                                     make_cloth_simulator(gown).trials));
      }
#endif
    }
  } else {
    sets = dataset_list("data", *args.get("data"));
  }
  if (!Comm::world().is_root()) return 0;  // training is one process's job (seconds)
#ifndef DRESSGUARD_HAVE_HMM
  throw UsageError("this dressguard was built without the HMM module (offline/hmm); build-model needs it");
#else
  std::string data;  // the training sets' names, for the model's metadata and the summary
  for (const auto& d : sets) data += (data.empty() ? "" : ",") + d.string();
  const std::string set_names = data;  // `data` gains notes below; an error names the sets alone
  Dataset ds;
  int left_out = 0;
  for (std::size_t i = 0; i < sets.size(); ++i) {
    Dataset one = load_dataset(sets[i]);
    const std::vector<std::string> drop = label_margin > 0 ? ambiguous_labels(sets[i], label_margin)
                                                           : std::vector<std::string>{};
    for (std::size_t k = 0; k < one.trials.size(); ++k) {
      if (std::find(drop.begin(), drop.end(), one.trials[k].id) != drop.end()) {
        ++left_out;
        continue;
      }
      if (!discrepancies.empty()) apply_discrepancy(discrepancies[i].second, one.trials[k]);
      ds.trials.push_back(std::move(one.trials[k]));
      ds.trial_files.push_back(one.trial_files[k]);  // an error names the trial's file
    }
  }
  if (training_out) {
    save_dataset(ds, *training_out);
    write_file_atomic(std::filesystem::path(*training_out) / kTrainingOutMark,
                      "written by dressguard build-model --training-out for " + out + "\n");
  }
  if (!discrepancies.empty()) {
    write_file_atomic(out + ".discrepancy.csv", discrepancy_csv(discrepancies));
    data += " + discrepancy from " + *args.get("discrepancy");
  }
  if (label_margin > 0) {
    char note[160];
    std::snprintf(note, sizeof note, "; %d trials left out, their label within %.4g m of the rule's 7 cm", left_out,
                  label_margin);
    data += note;
  }
  std::vector<const HapticSequence*> trials;
  for (const auto& t : ds.trials) trials.push_back(&t);
  // The trials trained on, for the summary: the unlabelled ones teach no class.
  const auto labelled = static_cast<std::size_t>(
      std::count_if(trials.begin(), trials.end(), [](const HapticSequence* t) { return t->label.has_value(); }));
  StcAxes axes{model::kAxisVertical, "F_motion and F_vertical (training data given directly)"};
  if (forces == "both") axes = {model::kAxisVertical, "F_motion and F_vertical (--forces both)"};
  else if (forces == "lateral") axes = {model::kAxisLateral, "F_motion and F_lateral (--forces lateral)"};
  else if (forces == "motion") axes = {model::kAxisNone, "F_motion alone (--forces motion)"};
  else if (!discrepancies.empty())
    axes = {model::kAxisVertical, "F_motion and F_vertical (the paper's; --discrepancy corrects both on the "
                                  "calibration's own sequences)"};
  else if (calibration_fits) axes = choose_stc_axes(*calibration_fits, lateral_fitted);
  StcOptions so;
  so.hmm = baum_welch;
  so.source = data + "; forces: " + axes.reason + (priors == "training" ? "; priors: the training shares" : "");
  so.second_axis = axes.second_axis;
  so.uniform_priors = priors == "uniform";
  so.trial_name = [&ds](const HapticSequence& t) { return trial_file_name(ds, t); };
  // Training refuses what the trials cannot teach (a class whose trials are all shorter than
  // --states, no labelled trial): the input's fault, exit 2 as train's, not a runtime failure.
  model::OutcomeModel m;
  try {
    m = build_outcome_model(trials, so);
  } catch (const std::invalid_argument& e) {
    throw InputError(set_names + ": " + e.what());
  }
  m.tool_version = "dressguard 0.1.0 build-model";
  m.created = args.get("created").value_or(utc_now());
  model::write_model(out, m);
  const double acc = accuracy(m, trials, std::numeric_limits<double>::infinity());
  if (args.has("json")) {
    std::printf("{\"model\": %s, \"classes\": %zu, \"training_trials\": %zu, \"training_sets\": %zu, "
                "\"training_accuracy\": %.4f, \"forces\": \"%s\", \"priors\": \"%s\", \"label_margin\": %.6g, "
                "\"left_out\": %d}\n",
                json_string(out).c_str(), m.classes.size(), labelled, sets.size(), acc, stc_forces_name(axes.second_axis),
                priors.c_str(), label_margin, left_out);
  } else {
    std::printf("wrote %s: %zu classes (", out.c_str(), m.classes.size());
    for (std::size_t i = 0; i < m.classes.size(); ++i) std::printf("%s%s", i ? ", " : "", m.classes[i].name.c_str());
    std::printf(") from %zu trials of %s; accuracy on its own training data %.1f%%\nforces modelled: %s\n",
                labelled, data.c_str(), 100 * acc, axes.reason.c_str());
  }
  return 0;
#endif
}

}  // namespace dressguard::cli
