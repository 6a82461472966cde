// dressguard predict: a calibrated simulator against the measured sequences of the other
// participants, beside the real-person yardstick (offline/calib/prediction.h).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "args.h"
#include "calibration.h"
#include "commands.h"
#include "dataset.h"
#include "discrepancy.h"
#include "files.h"
#include "json.h"
#include "prediction.h"
#ifdef DRESSGUARD_HAVE_SIM
#include "sim_bridge.h"
#endif

namespace dressguard::cli {

using namespace dressguard::calib;

namespace {

// A JSON number, or null for NaN (no yardstick, no sign to agree on).
std::string number(double v) { return std::isfinite(v) ? format_number(v) : "null"; }

}  // namespace

int run_predict(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json", "discrepancy"});
  if (args.has("help")) {
    std::puts(
        "usage: dressguard predict --calibration CAL.json --data DATASET [--out PREFIX] [options]\n"
        "  Simulates, with the calibrated parameters, every labelled non-caught trial of the\n"
        "  participants the calibration was not made on (their height, speed and end of travel) and\n"
        "  scores each with the calibration's objective (eq. 3-5). Beside it, the median of the same\n"
        "  objective from every real trial of a third participant at that height and speed: the\n"
        "  simulator predicts a trial no worse than another real person would when its L is at most\n"
        "  that (a trial no third person pulled at its speed has none, \"nan\").\n"
        "  Also the share of the travel where the simulated vertical force has the measured sign,\n"
        "  and what the simulation gets wrong: per height, travel window and force (F_motion,\n"
        "  F_vertical, F_lateral), the simulated mean force against the measured mean and the\n"
        "  people's spread (over people, each one's trials averaged first); the runs of windows where the\n"
        "  simulation is further from the people's mean than they are from each other are listed,\n"
        "  largest first (offline/calib/prediction.h, residual_windows). Then the heights' contrast:\n"
        "  where the people's high arm (good) differs from their middle or low arm (missed), whether\n"
        "  the simulator's differs the same way, not at all, or the other way round; what a\n"
        "  classifier trained on it learns from cut sequences (prediction.h, height_contrasts).\n"
        "  --out PREFIX   write PREFIX.csv (per trial), PREFIX.curves.csv, PREFIX.residual.csv and\n"
        "                 PREFIX.contrast.csv (for tools/plot/calib_overlay.py predict, residual and\n"
        "                 contrast; the gown and --discrepancy are recorded in them). Refused when one\n"
        "                 of them would replace the dataset's manifest or trials or the calibration\n"
        "  --discrepancy  add what the calibrated simulator gets wrong on its own person's\n"
        "                 sequences (in DATASET too) to every simulated curve before scoring\n"
        "                 (offline/calib/discrepancy.h): how much of the error is the simulator's\n"
        "                 and not the person's\n"
        "  --window M     [m] travel window of the residual (default 0.05)\n"
        "  --gown G       override the calibration's gown (full, reduced, coarse)\n"
        "  --threads N    threads per process (default: all cores); under mpirun every rank runs a share\n"
        "  --json         machine-readable summary");
    return 0;
  }
  args.allow_only({"help", "json", "calibration", "data", "out", "gown", "threads", "window", "discrepancy"});
  const std::string cal_path = args.require("calibration");
  const std::string data = args.require("data");
  const int threads = static_cast<int>(args.integer("threads", 0, 0, kMaxThreads));
  const double window = args.number("window", 0.05);
  if (!(window >= 0.005 && window <= 0.85)) throw UsageError("--window must be between 0.005 and 0.85 m");
  const Calibration cal = read_calibration(cal_path);
  const std::string gown = args.get("gown").value_or(cal.gown);
  if (gown != "full" && gown != "reduced" && gown != "coarse") throw UsageError("--gown must be full, reduced or coarse");
  const Dataset ds = load_dataset(data);
  const std::size_t targets = prediction_targets(ds, cal.participant).size();
  if (targets == 0)
    throw InputError(data + ": no labelled, non-caught trial of a participant other than '" + cal.participant + "'");
  // The outputs, refused before any simulation when one would replace an input (--out
  // DATASET/manifest wrote the prediction over the dataset's manifest).
  const auto prefix = args.get("out");
  std::vector<std::string> outputs;
  if (prefix)
    for (const char* suffix : {".csv", ".curves.csv", ".residual.csv", ".contrast.csv"})
      outputs.push_back(*prefix + suffix);
  std::vector<std::filesystem::path> inputs = ds.files;
  inputs.push_back(cal_path);
  for (const std::string& o : outputs)
    for (const auto& in : inputs)
      if (same_file(o, in))
        throw UsageError("--out " + *prefix + " would write " + o + " over the input " + in.string() +
                         ": choose a prefix outside the dataset's and the calibration's files");
#ifndef DRESSGUARD_HAVE_SIM
  (void)threads, (void)targets;
  throw UsageError("this dressguard was built without the cloth simulator (offline/sim); predict needs it");
#else
  const Comm& comm = Comm::world();
  const bool with_discrepancy = args.has("discrepancy");
  if (comm.is_root())
    std::fprintf(stderr,
                 "predict: the calibration of participant '%s' on %zu trials of other participants, gown %s%s\n",
                 cal.participant.c_str(), targets, gown.c_str(), with_discrepancy ? ", with its discrepancy" : "");
  const ClothSimulator sim = make_cloth_simulator(gown);
  Prediction p = predict_others(cal, ds, sim.trials, threads, comm, [](const PredictionProgress& pp) {
    std::fprintf(stderr, "predict: %d/%d trials on this rank, elapsed %.0f s, ETA %.0f s\n", pp.done, pp.total,
                 pp.elapsed_s, pp.eta_s);
  });
  if (!comm.is_root()) return 0;
  p.gown = gown;
  if (with_discrepancy) {
    // The calibrating person's own sequences are in the same dataset.
    const Discrepancy d =
        discrepancy_of(cal, calibration_inputs(cal, cal_path, ds, std::filesystem::path(data) / "manifest.csv"), sim.trials);
    add_discrepancy(p, d, ds, parse_objective(cal.objective_kind).value_or(ObjectiveKind::Area));
    std::fprintf(stderr, "predict: every simulated curve corrected by participant '%s''s discrepancy\n",
                 cal.participant.c_str());
  }
  if (prefix) {
    write_file_atomic(outputs[0], prediction_csv(p));
    write_file_atomic(outputs[1], prediction_curves_csv(p, ds));
  }
  const std::vector<ResidualWindow> windows = residual_windows(p, ds, window);
  const std::vector<ResidualFinding> findings = residual_findings(windows);
  const std::vector<HeightContrast> contrasts = height_contrasts(windows);
  const std::vector<ContrastFinding> contrast = contrast_findings(contrasts);
  const ContrastTally early = tally_contrasts(contrasts);  // up to issue 4's latest cut
  if (prefix) {
    write_file_atomic(outputs[2], residual_csv(windows));
    write_file_atomic(outputs[3], contrast_csv(contrasts));
  }
  const std::vector<PredictionSummary> sum = summarize(p);
  if (args.has("json")) {
    std::printf("{\"participant\": %s, \"trials\": %zu, \"gown\": %s, \"discrepancy\": %s, \"heights\": [",
                json_string(p.participant).c_str(), p.trials.size(), json_string(p.gown).c_str(),
                p.discrepancy ? "true" : "false");
    bool first = true;
    for (const auto& s : sum) {
      if (s.trials == 0) continue;
      std::printf("%s{\"height\": \"%s\", \"trials\": %d, \"objective_median\": %s, \"real_median\": %s, "
                  "\"no_worse\": %d, \"vertical_sign_median\": %s}",
                  first ? "" : ", ", std::string(arm_height_name(s.height)).c_str(), s.trials,
                  number(s.objective_median).c_str(), number(s.real_median).c_str(), s.no_worse,
                  number(s.vertical_sign_median).c_str());
      first = false;
    }
    std::printf("], \"residual_window_m\": %s, \"residual_findings\": [", number(window).c_str());
    first = true;
    for (const auto& f : findings) {
      std::printf("%s{\"height\": \"%s\", \"force\": \"%s\", \"from_m\": %s, \"to_m\": %s, \"residual_n\": %s, "
                  "\"measured_n\": %s, \"spread_n\": %s, \"trials\": %d, \"people\": %d}",
                  first ? "" : ", ", std::string(arm_height_name(f.height)).c_str(), force_column(f.axis),
                  number(f.from).c_str(), number(f.to).c_str(), number(f.residual).c_str(), number(f.measured).c_str(),
                  number(f.spread).c_str(), f.trials, f.people);
      first = false;
    }
    std::printf("], \"contrast_findings\": [");
    first = true;
    for (const auto& f : contrast) {
      std::printf("%s{\"force\": \"%s\", \"lower\": \"%s\", \"from_m\": %s, \"to_m\": %s, \"verdict\": \"%s\", "
                  "\"measured_n\": %s, \"simulated_n\": %s}",
                  first ? "" : ", ", force_column(f.axis), std::string(arm_height_name(f.lower)).c_str(),
                  number(f.from).c_str(), number(f.to).c_str(), std::string(contrast_verdict_name(f.verdict)).c_str(),
                  number(f.measured).c_str(), number(f.simulated).c_str());
      first = false;
    }
    std::printf("], \"contrast_up_to_m\": %s, \"contrast_agrees\": %d, \"contrast_misses\": %d, "
                "\"contrast_reverses\": %d}\n",
                number(kLatestCut).c_str(), early.agrees, early.misses, early.reverses);
    return 0;
  }
  std::printf("the simulator calibrated on participant '%s' (gown %s, %s), on %zu trials of other participants "
              "(L: %s objective)\n", p.participant.c_str(), p.gown.c_str(),
              p.discrepancy ? "corrected by its discrepancy term" : "without a discrepancy term", p.trials.size(),
              cal.objective_kind.c_str());
  std::printf("  %-18s %-6s %8s %12s %10s %9s %9s  %s\n", "trial", "height", "L sim", "L real (med)", "Fv sign",
              "sim end", "meas end", "sim label");
  for (const auto& t : p.trials)
    std::printf("  %-18s %-6s %8.3f %8.3f (%2d) %9.0f%% %8.3f m %8.3f m  %s\n", t.trial_id.c_str(),
                std::string(arm_height_name(t.height)).c_str(), t.objective, t.real_median, t.real_count,
                100 * t.vertical_sign, t.simulated_end, t.measured_end,
                t.simulated_outcome ? std::string(outcome_name(*t.simulated_outcome)).c_str() : "none");
  for (const auto& s : sum)
    if (s.trials > 0)
      std::printf("%-6s median L %.3f against %.3f between real people; no worse on %d of %d; Fv sign %.0f%%\n",
                  std::string(arm_height_name(s.height)).c_str(), s.objective_median, s.real_median, s.no_worse,
                  s.trials, 100 * s.vertical_sign_median);
  // The people's mean and spread are over people, each person's trials averaged first
  // (prediction.h, residual_windows).
  if (findings.empty())
    std::printf("what the simulation gets wrong: no %.2f m window where it is further from the people's mean than "
                "they are from each other (each person's trials averaged first)\n", window);
  else
    std::printf("what the simulation gets wrong (%.2f m windows where it is further from the people's mean than they are "
                "from each other, each person's trials averaged first; largest first):\n", window);
  // The largest few on the terminal; all of them in --json and, per window, in PREFIX.residual.csv.
  constexpr std::size_t kShown = 8;
  for (std::size_t i = 0; i < findings.size() && i < kShown; ++i) std::printf("  %s\n", findings[i].text.c_str());
  if (findings.size() > kShown)
    std::printf("  ... %zu smaller ones (--json lists all; --out writes every window)\n", findings.size() - kShown);
  // What an STC learns from the heights' difference, in travel order (the early windows are what
  // the cut sequences keep).
  if (contrast.empty())
    std::printf("the heights' contrast: wherever the people's high arm differs from a lower one, the simulator's "
                "differs the same way\n");
  else
    std::printf("the heights' contrast (what a classifier trained on the simulator learns; %.2f m windows where the "
                "people's heights differ by more than twice its standard error):\n", window);
  for (const auto& f : contrast) std::printf("  %s\n", f.text.c_str());
  std::printf("up to %.2f m of travel (issue 4's latest cut), where the people's heights differ: the simulator "
              "agrees in %d, misses %d and reverses %d of the window forces\n",
              kLatestCut, early.agrees, early.misses, early.reverses);
  if (prefix)
    std::printf("wrote %s.csv, %s.curves.csv, %s.residual.csv and %s.contrast.csv\n", prefix->c_str(), prefix->c_str(),
                prefix->c_str(), prefix->c_str());
  return 0;
#endif
}

}  // namespace dressguard::cli
