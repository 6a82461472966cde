// dressguard classify: an outcome model (or a committee of them) and a labelled dataset ->
// per-trial classes, accuracy and the confusion matrix; optionally cut at a travel distance
// (paper Fig. 6) or swept over many.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>

#include "args.h"
#include "commands.h"
#include "dataset.h"
#include "dgm.h"
#include "files.h"
#include "hmm.h"
#include "report.h"

namespace dressguard::cli {

namespace {

// "a:b:step" -> a, a+step, ..., up to b (inclusive within step/1000).
std::vector<double> parse_sweep(const std::string& s) {
  double v[3];
  std::stringstream in(s);
  std::string part;
  int k = 0;
  while (std::getline(in, part, ':')) {
    if (k >= 3) throw UsageError("--sweep must be START:END:STEP, got '" + s + "'");
    char* end = nullptr;
    v[k] = std::strtod(part.c_str(), &end);
    if (part.empty() || *end != '\0' || !std::isfinite(v[k])) throw UsageError("--sweep: not a number: '" + part + "'");
    ++k;
  }
  if (k != 3) throw UsageError("--sweep must be START:END:STEP, got '" + s + "'");
  if (!(v[2] > 0) || v[1] < v[0]) throw UsageError("--sweep needs STEP > 0 and END >= START");
  // As --truncate-at: a cut at or before 0 m leaves no trial a sample to score.
  if (!(v[0] > 0)) throw UsageError("--sweep needs START > 0, got '" + s + "'");
  std::vector<double> out;
  for (int i = 0;; ++i) {
    const double d = v[0] + i * v[2];
    if (d > v[1] + 1e-3 * v[2]) break;
    out.push_back(d);
    if (out.size() > 10000) throw UsageError("--sweep has more than 10000 points");
  }
  return out;
}

// The accuracy line (with its 95 % Wilson interval: on the study's 22 trials a few trials either
// way are noise, hmm.h) and the confusion matrix.
// One line per trial whose recording starts late, saying how the HMMs scored it (hmm.h,
// FeatureSequence::unobserved): a reader of the table should not take it for a pull from 0.
void print_late_starts(const std::vector<const HapticSequence*>& trials) {
  for (const auto* t : trials)
    if (const size_t k = unrecorded_samples(*t); k > 0)
      std::printf("%s starts %.4f m into its pull: scored from the state distribution %zu samples on\n",
                  t->id.c_str(), t->samples.front().travel, k);
}

void print_summary(const hmm::Evaluation& ev, size_t models) {
  std::string interval;
  if (ev.total > 0) {
    const hmm::AccuracyInterval iv = hmm::wilson_interval(ev.correct, ev.total);
    char buf[64];
    std::snprintf(buf, sizeof buf, "; 95 %% interval %.2f-%.2f", iv.lower, iv.upper);
    interval = buf;
  }
  std::printf("\naccuracy %s (%d/%d)%s%s%s\n", hmm::accuracy_text(ev).c_str(), ev.correct, ev.total,
              models > 1 ? (", a vote of " + std::to_string(models) + " models").c_str() : "",
              ev.skipped ? (", " + std::to_string(ev.skipped) + " trials skipped (unlabelled, or no sample before the cut)").c_str() : "",
              interval.c_str());
  std::printf("%s", hmm::confusion_text(ev).c_str());
}

// Per trial of `trials`: hmm::right_or_not of the model (one) or of the committee (several,
// voting) at the cut.
std::vector<int> right_per_trial(const std::vector<const model::OutcomeModel*>& models,
                                 const std::vector<const HapticSequence*>& trials, double cut,
                                 const hmm::ClassChoice& among, const std::vector<double>& weights = {}) {
  std::vector<int> right;
  if (models.size() == 1) {
    std::vector<hmm::TrialResult> per;
    hmm::evaluate(*models[0], trials, cut, &per, among);
    for (const auto& r : per) right.push_back(hmm::right_or_not(r));
  } else {
    std::vector<hmm::Vote> per;
    hmm::evaluate_vote(models, trials, cut, &per, among, weights);
    for (size_t i = 0; i < per.size(); ++i) right.push_back(hmm::right_or_not(per[i], *trials[i]));
  }
  return right;
}

// `--against`: this classifier and another on the same trials, paired (hmm.h, mcnemar_exact_p):
// only the trials both score count; b of them only this one gets right, c only the other.
struct Against {
  int both_scored = 0, other_right = 0, only_this = 0, only_other = 0;
  double p = 1;
};
Against pair_against(const std::vector<int>& mine, const std::vector<int>& other) {
  Against a;
  for (size_t i = 0; i < mine.size(); ++i) {
    if (mine[i] < 0 || other[i] < 0) continue;
    ++a.both_scored;
    a.other_right += other[i];
    a.only_this += mine[i] && !other[i];
    a.only_other += !mine[i] && other[i];
  }
  a.p = hmm::mcnemar_exact_p(a.only_this, a.only_other);
  return a;
}

// A model that knows its training sample period (models/FORMAT.md, version 3) classifies only
// trials recorded at it: its HMMs count time in samples. A trial at another rate (beyond a
// recording's jitter, kRecordingPeriodTolerance) is refused, naming its file and both periods.
void require_model_rate(const model::OutcomeModel& m, const std::string& model_path, const Dataset& ds,
                        const std::vector<const HapticSequence*>& trials) {
  if (!m.knows_period()) return;
  for (const auto* t : trials) {
    const double period = mean_sample_period(*t);
    if (!(period > 0.0) || model::same_period(period, m.sample_period_s, kRecordingPeriodTolerance)) continue;
    char at[64], trained[64];
    std::snprintf(at, sizeof at, " is sampled every %.9g s, ", period);
    std::snprintf(trained, sizeof trained, " was trained at %.9g s", m.sample_period_s);
    throw InputError(trial_file_name(ds, *t) + at + model_path + trained +
                     ": its HMMs count time in samples (a recording may differ by 1e-3 relative)");
  }
}

}  // namespace

int run_classify(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json", "no-plot"});
  if (args.has("help")) {
    std::puts(
        "usage: dressguard classify --model MODEL.dgm[,MODEL2.dgm,...] --data DATASET [options] [--json]\n"
        "  Classifies every labelled trial by the highest posterior (log-likelihood + log prior) and\n"
        "  prints per-trial results, the accuracy and the confusion matrix (rows truth, columns predicted).\n"
        "  A labelled trial whose label the model has no class for counts as wrong: its label gets a row\n"
        "  of the matrix (and a column of zeros); only unlabelled trials and cuts before a trial's first\n"
        "  sample are skipped.\n"
        "  With several models, they vote (a committee, e.g. the STCs of several people's simulators):\n"
        "  each model classifies the trial, the class most of them pick wins, a tie goes to the larger\n"
        "  sum of their posteriors; classes are matched by name. Each model file once (in --against\n"
        "  too): a file named twice would vote twice.\n"
        "  --truncate-at DIST      cut each trial after the last sample with travel <= DIST metres\n"
        "  --sweep A:B:STEP        accuracy at every truncation distance A, A+STEP, ..., B (metres)\n"
        "  --sweep-out PREFIX      with --sweep: write PREFIX.csv and PREFIX.png (tools/plot/hmm_sweep.py;\n"
        "                          if the script fails, the CSV is kept and classify exits 1)\n"
        "  --no-plot               with --sweep: write only the CSV\n"
        "  --participant P[,Q...]  only these participants' trials (leave-one-participant-out)\n"
        "  --among C[,C...]        decide among these classes only, e.g. good,missed: the question a\n"
        "                          classifier trained on the study's recordings (no caught trial) answers\n"
        "  --against B.dgm[,...]   also classify the same trials (same cut, same --among) by another model\n"
        "                          or committee, and pair the two: the trials only one of them gets right\n"
        "                          and McNemar's exact p (is the difference more than these trials' noise?)\n"
        "  --weigh-on SET[,SET...] with several models: one dataset per --model, in order, each the\n"
        "                          set that model was trained on; each member's vote then counts by\n"
        "                          its log-odds of being right on the other members' sets at the same\n"
        "                          cut and --among (hmm.h, simulation_weights: learnt from simulation\n"
        "                          alone; give one model per person, each set once). Printed, and in\n"
        "                          the JSON. For a model built with --discrepancy give its\n"
        "                          build-model --training-out set: the synthesized set on disk lacks\n"
        "                          the correction it learnt\n"
        "  --json                  print a machine-readable result");
    return 0;
  }
  args.allow_only({"help", "json", "no-plot", "model", "data", "truncate-at", "sweep", "sweep-out", "participant",
                    "among", "against", "weigh-on"});
  const std::string model_list = args.require("model"), data = args.require("data");
  const double truncate = args.number("truncate-at", std::numeric_limits<double>::infinity());
  if (!(truncate > 0)) throw UsageError("--truncate-at must be positive");
  std::vector<double> sweep;
  if (auto s = args.get("sweep")) {
    sweep = parse_sweep(*s);
    if (!args.get("sweep-out")) throw UsageError("--sweep needs --sweep-out PREFIX");
    if (args.get("truncate-at")) throw UsageError("--sweep and --truncate-at exclude each other");
  } else if (args.get("sweep-out")) {
    throw UsageError("--sweep-out needs --sweep");
  }
  const auto only = split_list(args.get("participant").value_or(""));

  const hmm::ClassChoice among = split_in_order(args.get("among").value_or(""));
  if (args.get("among") && among.empty()) throw UsageError("--among needs at least one class name");
  // A comma list of model files (--model, --against), each read and checked against --among.
  auto read_models = [&](const std::string& option, const std::vector<std::string>& paths) {
    std::vector<model::OutcomeModel> ms;
    for (const auto& path : paths) {
      try {
        ms.push_back(model::read_model(path));
      } catch (const model::ModelError& e) {
        throw InputError(e.what());
      }
      for (const auto& name : among)
        if (ms.back().class_index(name) < 0)
          throw UsageError("--among: '" + name + "' is not a class of " + path);
    }
    if (ms.empty()) throw UsageError("--" + option + " needs at least one model file");
    return ms;
  };
  // One model file twice in a committee (A.dgm,A.dgm or A.dgm,./A.dgm) would cast its vote twice
  // and outvote a member it disagrees with, without a word; as --weigh-on refuses a set twice.
  const std::string why_once = "its vote would count twice";
  const std::vector<std::string> model_paths = distinct_files("model", model_list, "model", why_once);
  const std::vector<model::OutcomeModel> models = read_models("model", model_paths);
  std::vector<const model::OutcomeModel*> committee;
  for (const auto& m : models) committee.push_back(&m);
  const std::vector<std::string> against_paths =
      distinct_files("against", args.get("against").value_or(""), "model", why_once);
  if (args.get("against") && !sweep.empty()) throw UsageError("--against pairs the models at one cut, not with --sweep");
  const std::vector<model::OutcomeModel> against_models =
      args.get("against") ? read_models("against", against_paths) : std::vector<model::OutcomeModel>{};
  std::vector<const model::OutcomeModel*> against_committee;
  for (const auto& m : against_models) against_committee.push_back(&m);
  // One model classifies as it always did (its log-likelihoods in the JSON); several vote.
  const model::OutcomeModel* single = models.size() == 1 ? &models[0] : nullptr;
  // --weigh-on: each member's training set, for the weights at each cut (rule S).
  if (args.get("weigh-on") && single) throw UsageError("--weigh-on weighs the members of a committee: give several --model");
  // One folder twice would weigh each of its two members on its own training set, which says how
  // well it learnt itself, not how it fares on a person it was not fitted to (hmm.h,
  // simulation_weights): a slip, as in train --data.
  std::vector<std::string> weigh_paths;
  if (const auto list = args.get("weigh-on"))
    for (const auto& path : dataset_list("weigh-on", *list,
                                         "each member must be weighed on the other members' training sets, "
                                         "not on its own"))
      weigh_paths.push_back(path.string());
  if (args.get("weigh-on") && weigh_paths.size() != models.size())
    throw UsageError("--weigh-on names " + std::to_string(weigh_paths.size()) + " sets for " +
                     std::to_string(models.size()) + " models: one set per model, in --model's order");
  std::vector<Dataset> weigh_sets;
  for (const auto& path : weigh_paths) {
    weigh_sets.push_back(load_dataset(path));
    if (weigh_sets.back().trials.empty()) throw InputError(path + ": no trials to weigh a member on");
  }
  std::vector<std::vector<const HapticSequence*>> weigh_on;
  for (const auto& set : weigh_sets) {
    weigh_on.emplace_back();
    for (const auto& t : set.trials) weigh_on.back().push_back(&t);
  }
  auto weights_at = [&](double d) {
    return weigh_on.empty() ? std::vector<double>{} : hmm::simulation_weights(committee, weigh_on, d, among);
  };
  const Dataset ds = load_dataset(data);
  require_known_participants("participant", only, ds, data);
  std::vector<const HapticSequence*> trials;
  for (const auto& t : ds.trials)
    if (only.empty() || only.count(t.participant)) trials.push_back(&t);
  if (trials.empty()) throw InputError(data + ": no trials" + (only.empty() ? "" : " of the given participants"));
  for (size_t i = 0; i < models.size(); ++i) require_model_rate(models[i], model_paths[i], ds, trials);
  for (size_t i = 0; i < against_models.size(); ++i)
    require_model_rate(against_models[i], against_paths[i], ds, trials);
  const bool json = args.has("json");
  // --against: the pairing, its JSON member and its text line (printed after the summary).
  std::string against_json, against_text;
  if (!against_committee.empty()) {
    const Against a = pair_against(right_per_trial(committee, trials, truncate, among, weights_at(truncate)),
                                   right_per_trial(against_committee, trials, truncate, among));
    std::string paths;
    for (const auto& path : against_paths) paths += (paths.empty() ? "" : ", ") + hmm::json_string(path);
    against_json = ", \"against\": {\"models\": [" + paths + "], \"trials\": " + std::to_string(a.both_scored) +
                   ", \"correct\": " + std::to_string(a.other_right) + ", \"only_this_right\": " +
                   std::to_string(a.only_this) + ", \"only_against_right\": " + std::to_string(a.only_other) +
                   ", \"mcnemar_exact_p\": " + hmm::json_number(a.p) + "}";
    char line[256];
    std::snprintf(line, sizeof line,
                  "against %s: %d/%d right; only this one right on %d, only the other on %d: McNemar's exact p %.3g\n",
                  args.get("against")->c_str(), a.other_right, a.both_scored, a.only_this, a.only_other, a.p);
    against_text = line;
  }
  auto evaluate_at = [&](double d) {
    return single ? hmm::evaluate(*single, trials, d, nullptr, among)
                  : hmm::evaluate_vote(committee, trials, d, nullptr, among, weights_at(d));
  };

  if (!sweep.empty()) {
    const std::string prefix = *args.get("sweep-out");
    std::string csv = "travel_m,accuracy,correct,total\n";
    std::string rows_json;
    for (double d : sweep) {
      const auto ev = evaluate_at(d);
      // A cut that leaves no trial scored has no accuracy (not 0): empty in the CSV, null in the
      // JSON, "-" in the text, and the plot leaves it out.
      char acc[32] = "", acc_json[32] = "null";
      if (ev.total > 0) {
        std::snprintf(acc, sizeof acc, "%.6f", ev.accuracy());
        std::snprintf(acc_json, sizeof acc_json, "%.6f", ev.accuracy());
      }
      char line[160];
      std::snprintf(line, sizeof line, "%.6g,%s,%d,%d\n", d, acc, ev.correct, ev.total);
      csv += line;
      std::snprintf(line, sizeof line, "%s{\"travel_m\": %.6g, \"accuracy\": %s, \"correct\": %d, \"total\": %d}",
                    rows_json.empty() ? "" : ", ", d, acc_json, ev.correct, ev.total);
      rows_json += line;
      if (!json)
        std::printf("travel %.3f m: accuracy %s (%d/%d)\n", d, hmm::accuracy_text(ev).c_str(), ev.correct, ev.total);
    }
    write_file_atomic(prefix + ".csv", csv);
    std::string png;
    bool plot_failed = false;
    // A picture of an earlier sweep under this prefix would pass for this one's: it goes first,
    // so that what is on disk is what the summary says.
    std::filesystem::remove(prefix + ".png");
    if (!args.has("no-plot")) {
      const auto script = plot_script("hmm_sweep.py");
      if (script.empty()) {
        std::fprintf(stderr, "classify: tools/plot/hmm_sweep.py not found; wrote only %s.csv\n", prefix.c_str());
      } else if (run_plot_script(script, {prefix + ".csv", prefix + ".png"}) == 0) {
        png = prefix + ".png";
      } else {
        // The picture was asked for and the script is there: its failure is an error (exit 1),
        // not a note a script calling classify would read past (session 85's tools review,
        // finding 3). The CSV and the summary still come out.
        std::fprintf(stderr, "classify: plotting failed (%s); wrote only %s.csv\n", script.c_str(), prefix.c_str());
        plot_failed = true;
      }
    }
    if (json) {
      std::printf("{\"sweep\": [%s], \"csv\": %s, \"png\": %s}\n", rows_json.c_str(), hmm::json_string(prefix + ".csv").c_str(),
                  png.empty() ? "null" : hmm::json_string(png).c_str());
    } else {
      std::printf("wrote %s.csv%s\n", prefix.c_str(), png.empty() ? "" : (" and " + png).c_str());
    }
    return plot_failed ? 1 : 0;
  }

  if (!single) {
    // The committee: per trial the votes and the models' posterior sums.
    std::vector<hmm::Vote> per;
    const std::vector<double> weights = weights_at(truncate);
    const auto ev = hmm::evaluate_vote(committee, trials, truncate, &per, among, weights);
    std::string weights_json;
    for (size_t k = 0; k < weights.size(); ++k)
      weights_json += (k ? ", " : "") + hmm::json_number(weights[k]);
    if (!weights.empty()) weights_json = ", \"weights\": [" + weights_json + "]";
    if (json) {
      std::string rows, paths;
      for (size_t i = 0; i < per.size(); ++i) {
        const auto& v = per[i];
        if (v.predicted < 0) continue;
        std::string votes, sums;
        for (size_t c = 0; c < v.classes.size(); ++c) {
          votes += (c ? ", " : "") + std::to_string(v.votes[c]);
          sums += (c ? ", " : "") + hmm::json_number(v.posterior_sum[c]);
        }
        rows += (rows.empty() ? "" : ", ") + std::string("{\"id\": ") + hmm::json_string(trials[i]->id) +
                ", \"participant\": " + hmm::json_string(trials[i]->participant) + ", \"samples\": " +
                std::to_string(v.samples) + ", \"unrecorded_samples\": " + std::to_string(unrecorded_samples(*trials[i])) +
                ", \"truth\": " + hmm::json_string(outcome_name(*trials[i]->label)) +
                ", \"predicted\": " + hmm::json_string(v.classes[v.predicted]) + ", \"votes\": [" + votes +
                "], \"posterior_sum\": [" + sums + "]}";
      }
      for (const auto& path : model_paths) paths += (paths.empty() ? "" : ", ") + hmm::json_string(path);
      std::printf("{\"models\": [%s]%s, \"data\": %s, \"truncate_at\": %s, \"trials\": [%s], \"evaluation\": %s%s}\n",
                  paths.c_str(), weights_json.c_str(), hmm::json_string(data).c_str(), hmm::json_number(truncate).c_str(),
                  rows.c_str(), hmm::evaluation_json(ev).c_str(), against_json.c_str());
      return 0;
    }
    if (!weights.empty()) {
      std::printf("weights (rule S: each member on the other members' training sets):");
      for (size_t k = 0; k < weights.size(); ++k) std::printf(" %s %.3f", model_paths[k].c_str(), weights[k]);
      std::printf("\n");
    }
    std::printf("%-24s %-6s %7s %-8s %-8s %6s\n", "trial", "part.", "samples", "truth", "predicted", "votes");
    for (size_t i = 0; i < per.size(); ++i) {
      const auto& v = per[i];
      if (v.predicted < 0) continue;
      const std::string truth(outcome_name(*trials[i]->label));
      // Weighted, the votes alone may look like the loser's: the winner's share of the weight too.
      std::string share;
      if (!weights.empty()) {
        double won = 0, all = 0;
        for (size_t k = 0; k < v.answers.size(); ++k) all += weights[k], won += v.answers[k] == v.predicted ? weights[k] : 0;
        char text[32];
        std::snprintf(text, sizeof text, " (weight %.2f)", all > 0 ? won / all : 0.0);
        share = text;
      }
      std::printf("%-24s %-6s %7zu %-8s %-8s %3d/%-2zu%s%s\n", trials[i]->id.c_str(), trials[i]->participant.c_str(),
                  v.samples, truth.c_str(), v.classes[v.predicted].c_str(), v.votes[v.predicted], committee.size(),
                  share.c_str(), truth == v.classes[v.predicted] ? "" : "   WRONG");
    }
    print_late_starts(trials);
    print_summary(ev, committee.size());
    std::printf("%s", against_text.c_str());
    return 0;
  }
  std::vector<hmm::TrialResult> per;
  const auto ev = hmm::evaluate(*single, trials, truncate, &per, among);
  if (json) {
    std::string rows;
    for (const auto& r : per) {
      if (r.result.predicted < 0) continue;  // skipped; a label the model lacks is scored (wrong)
      std::string ll, post;
      for (size_t c = 0; c < single->classes.size(); ++c) {
        ll += (c ? ", " : "") + hmm::json_number(r.result.log_likelihood[c]);
        post += (c ? ", " : "") + hmm::json_number(r.result.posterior[c]);
      }
      rows += (rows.empty() ? "" : ", ") + std::string("{\"id\": ") + hmm::json_string(r.trial->id) +
              ", \"participant\": " + hmm::json_string(r.trial->participant) + ", \"samples\": " + std::to_string(r.samples) +
              ", \"unrecorded_samples\": " + std::to_string(unrecorded_samples(*r.trial)) + ", \"truth\": " + hmm::json_string(outcome_name(*r.trial->label)) + ", \"predicted\": " +
              hmm::json_string(single->classes[r.result.predicted].name) + ", \"log_likelihood\": [" + ll + "], \"posterior\": [" +
              post + "]}";
    }
    std::printf("{\"model\": %s, \"data\": %s, \"truncate_at\": %s, \"trials\": [%s], \"evaluation\": %s%s}\n",
                hmm::json_string(model_list).c_str(), hmm::json_string(data).c_str(), hmm::json_number(truncate).c_str(),
                rows.c_str(), hmm::evaluation_json(ev).c_str(), against_json.c_str());
    return 0;
  }
  std::printf("%-24s %-6s %7s %-8s %-8s %9s\n", "trial", "part.", "samples", "truth", "predicted", "posterior");
  for (const auto& r : per) {
    if (r.result.predicted < 0) continue;
    std::printf("%-24s %-6s %7zu %-8s %-8s %9.4f%s\n", r.trial->id.c_str(), r.trial->participant.c_str(), r.samples,
                std::string(outcome_name(*r.trial->label)).c_str(), single->classes[r.result.predicted].name.c_str(),
                r.result.posterior[r.result.predicted], r.truth == r.result.predicted ? "" : "   WRONG");
  }
  print_late_starts(trials);
  print_summary(ev, 1);
  std::printf("%s", against_text.c_str());
  return 0;
}

}  // namespace dressguard::cli
