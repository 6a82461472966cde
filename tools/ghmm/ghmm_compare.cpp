// dg_ghmm_compare: our HMM against GHMM (the library the paper trained with) on the same
// sequences from the same equal-segment initial model:
//   1. forward log-likelihood of the initial model on every sequence: equal to 1e-9 relative;
//   2. one Baum-Welch step: the same log-likelihood, means and transitions to 1e-9 relative, and
//      the covariances equal to what GHMM's rule gives from our statistics (about the previous
//      mean, entries below 1e-4 in magnitude set to +-1e-4), to 1e-9 relative;
//   3. both trained to their own stop rules: log-likelihood on the training and on held-out data
//      (ours must be equal or better: >= GHMM's - 1e-9 relative on training, and on held-out
//      data at least as good as GHMM's minus the --heldout-slack in nats per sample);
//   4. training time of both in this run, as a ratio, and per Baum-Welch iteration.
// Exit 0 when every equality holds, 1 otherwise (the report names what failed).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "dataset.h"
#include "ghmm_bridge.h"
#include "hmm.h"

using namespace dressguard;

namespace {

double rel(double a, double b) { return std::fabs(a - b) / std::max(std::fabs(b), 1e-300); }
// Relative difference for parameters that may be ~0 (means, off-diagonals): scaled by max(|b|,1).
double relp(double a, double b) { return std::fabs(a - b) / std::max(std::fabs(b), 1.0); }

// The left-right truth the data are drawn from: n states whose means progress smoothly, dwell
// mean_len/n samples, a full covariance that rotates along the states.
model::ClassHmm truth(int n, double mean_len) {
  model::ClassHmm h = model::left_right_chain(n, 1.0 - n / mean_len);
  for (int j = 0; j < n; ++j) {
    model::GaussianEmission e;
    e.mean[0] = -3.0 + 6.0 * j / n + 0.5 * std::sin(1.3 * j);
    e.mean[1] = 1.5 * std::cos(0.7 * j);
    e.cov[0][0] = 0.2 + 0.05 * j;
    e.cov[1][1] = 0.3;
    e.cov[0][1] = e.cov[1][0] = 0.1 * std::sin(0.9 * j);
    h.emission.push_back(e);
  }
  return h;
}

// GHMM's covariance from our one-step statistics: about the previous mean mu_old, i.e.
// Sigma_new + (mu_new - mu_old)(mu_new - mu_old)^T, then |entry| < 1e-4 -> +-1e-4.
double ghmm_cov_rule(const model::ClassHmm& before, const model::ClassHmm& after, int j, int r, int c) {
  const double dr = after.emission[j].mean[r] - before.emission[j].mean[r];
  const double dc = after.emission[j].mean[c] - before.emission[j].mean[c];
  double v = after.emission[j].cov[r][c] + dr * dc;
  if (std::fabs(v) < 1e-4) v = v < 0 ? -1e-4 : 1e-4;
  return v;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int usage() {
  std::puts(
      "usage: dg_ghmm_compare [--states N] [--sequences N] [--heldout N] [--min-len T] [--max-len T]\n"
      "                       [--seed S] [--ghmm-eps E] [--heldout-slack NATS] [--timing-iterations K]\n"
      "                       [--study LABEL [--held-participant P]] [--tolerance NATS]\n"
      "  Draws sequences from a known left-right HMM, builds the equal-segment initial model, and\n"
      "  compares our HMM with GHMM on them (see the header of ghmm_compare.cpp). Defaults: 10 states,\n"
      "  40 training + 20 held-out sequences of 300-500 samples, seed 1, GHMM eps 1e-4, slack 1e-3.\n"
      "  --study LABEL: instead, the measured study's trials of that outcome (good or missed) in\n"
      "  scaled features, participant P (default 4) held out; exit 77 when the data are absent.\n"
      "  --tolerance: our stop rule, gain per sample in nats (default 1e-6, as dressguard train).");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  int states = 10, n_train = 40, n_held = 20, timing_iters = 0;
  std::string study_label, held_participant = "4";
  size_t min_len = 300, max_len = 500;
  uint64_t seed = 1;
  double ghmm_eps = 1e-4, slack = 1e-3, tolerance = 1e-6;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") return usage(), 0;
    if (i + 1 >= argc) return usage();
    const char* v = argv[++i];
    if (a == "--states") states = std::atoi(v);
    else if (a == "--sequences") n_train = std::atoi(v);
    else if (a == "--heldout") n_held = std::atoi(v);
    else if (a == "--min-len") min_len = std::strtoul(v, nullptr, 10);
    else if (a == "--max-len") max_len = std::strtoul(v, nullptr, 10);
    else if (a == "--seed") seed = std::strtoull(v, nullptr, 10);
    else if (a == "--ghmm-eps") ghmm_eps = std::atof(v);
    else if (a == "--heldout-slack") slack = std::atof(v);
    else if (a == "--timing-iterations") timing_iters = std::atoi(v);
    else if (a == "--study") study_label = v;
    else if (a == "--tolerance") tolerance = std::atof(v);
    else if (a == "--held-participant") held_participant = v;
    else return usage();
  }
  if (states < 1 || states > model::kMaxStates || n_train < 1 || n_held < 1 || min_len < static_cast<size_t>(states) ||
      max_len < min_len)
    return usage();

  std::vector<hmm::FeatureSequence> train, held;
  size_t n_samples = 0;
  if (!study_label.empty()) {
    // The measured study: one outcome's trials in the model's scaled features, one participant
    // held out. Exit 77 (ctest: skipped) when shared/data is absent.
    const auto dir = study_dir();
    if (dir.empty()) {
      std::puts("shared/data (the study) is not present: skipped");
      return 77;
    }
    const Dataset ds = import_study(dir);
    std::vector<const HapticSequence*> all;
    for (const auto& tr : ds.trials) all.push_back(&tr);
    const auto fc = hmm::fit_feature_scaling(all);
    for (const auto& tr : ds.trials) {
      if (!tr.label || outcome_name(*tr.label) != study_label) continue;
      auto f = hmm::features_of(tr, fc);
      // GHMM has no unobserved start (hmm.h, FeatureSequence::unobserved; one study trial begins
      // 64 samples into its pull): both libraries get each recording as it begins, so that the
      // comparison is of the two algorithms on the same sequences.
      f.unobserved = 0;
      if (tr.participant == held_participant) {
        held.push_back(std::move(f));
      } else {
        n_samples += f.size();
        train.push_back(std::move(f));
      }
    }
    n_train = static_cast<int>(train.size());
    n_held = static_cast<int>(held.size());
    if (train.empty() || held.empty()) {
      std::printf("study: no '%s' trials to train on or none of participant %s\n", study_label.c_str(), held_participant.c_str());
      return 2;
    }
    std::printf("measured study, label '%s', participant %s held out\n", study_label.c_str(), held_participant.c_str());
  } else {
    const model::ClassHmm t = truth(states, 0.5 * (min_len + max_len));
    std::mt19937_64 rng(seed);
    for (int i = 0; i < n_train + n_held; ++i) {
      const size_t T = min_len + rng() % (max_len - min_len + 1);
      (i < n_train ? train : held).push_back(hmm::sample(t, T, rng));
      if (i < n_train) n_samples += T;
    }
  }
  hmm::TrainOptions opt;
  opt.n_states = states;
  opt.cov_floor = 1e-6;  // far below the data's variances: the floor never acts, as GHMM's does not
  const model::ClassHmm init = hmm::initial_left_right(train, opt);
  bool ok = true;
  auto check = [&ok](bool cond, const char* what, double value, double limit) {
    std::printf("  %-58s %.3e (limit %.0e) %s\n", what, value, limit, cond ? "ok" : "FAIL");
    ok &= cond;
  };
  std::printf("GHMM comparison: %d states, %d training sequences (%zu samples), %d held-out, seed %llu\n", states,
              n_train, n_samples, n_held, static_cast<unsigned long long>(seed));

  // 1. Forward log-likelihood of the initial model.
  ghmm_bridge::Model g_init(init);
  double worst = 0.0;
  for (const auto& s : train) worst = std::max(worst, rel(g_init.log_likelihood(s), hmm::forward_log_likelihood(init, s)));
  check(worst <= 1e-9, "forward log-likelihood, max relative difference", worst, 1e-9);

  // 2. One Baum-Welch step.
  model::ClassHmm ours1;
  const double ll0 = hmm::baum_welch_step(init, train, 0.0, ours1);
  ghmm_bridge::Sequences g_train(train);
  const auto rep1 = ghmm_bridge::baum_welch(g_init, g_train, 1e-300, 1);
  const model::ClassHmm g1 = g_init.to_class_hmm();
  check(rep1.rc == 0 && rel(rep1.reported_log_likelihood, ll0) <= 1e-9, "one step: log-likelihood of the initial model",
        rel(rep1.reported_log_likelihood, ll0), 1e-9);
  double dm = 0, da = 0, dc = 0, dc_ours = 0;
  for (int j = 0; j < states; ++j) {
    for (int r = 0; r < 2; ++r) {
      dm = std::max(dm, relp(g1.emission[j].mean[r], ours1.emission[j].mean[r]));
      for (int c = 0; c < 2; ++c) {
        dc = std::max(dc, relp(g1.emission[j].cov[r][c], ghmm_cov_rule(init, ours1, j, r, c)));
        dc_ours = std::max(dc_ours, relp(g1.emission[j].cov[r][c], ours1.emission[j].cov[r][c]));
      }
    }
    for (int k = 0; k < states; ++k) da = std::max(da, relp(g1.transition[j * states + k], ours1.transition[j * states + k]));
    da = std::max(da, relp(g1.initial[j], ours1.initial[j]));
  }
  check(dm <= 1e-9, "one step: means, max relative difference", dm, 1e-9);
  check(da <= 1e-9, "one step: initial + transitions, max relative difference", da, 1e-9);
  check(dc <= 1e-9, "one step: covariances vs GHMM's rule from our statistics", dc, 1e-9);
  std::printf("  %-58s %.3e (GHMM's previous-mean bias)\n", "one step: covariances, ours vs GHMM's as is", dc_ours);

  // 3. Both trained to their own stop rules.
  opt.max_iterations = 500;
  opt.tolerance = tolerance;
  auto t0 = std::chrono::steady_clock::now();
  const hmm::TrainResult ours = hmm::train(init, train, opt);
  const double t_ours = seconds_since(t0);
  ghmm_bridge::Model g_model(init);
  t0 = std::chrono::steady_clock::now();
  const auto rep = ghmm_bridge::baum_welch(g_model, g_train, ghmm_eps, 500);
  const double t_ghmm = seconds_since(t0);
  double g_train_ll = 0, g_held_ll = 0, o_held_ll = 0;
  size_t held_samples = 0;
  for (const auto& s : train) g_train_ll += g_model.log_likelihood(s);
  for (const auto& s : held) {
    g_held_ll += g_model.log_likelihood(s);
    o_held_ll += hmm::forward_log_likelihood(ours.hmm, s);
    held_samples += s.size();
  }
  std::printf("  trained: ours %d iterations%s, GHMM eps %.0e (rc %d, reported %.6f, its final model %.6f)\n",
              ours.iterations, ours.converged ? "" : " (max)", ghmm_eps, rep.rc, rep.reported_log_likelihood, g_train_ll);
  std::printf("  training log-likelihood: ours %.6f, GHMM %.6f (%.5f vs %.5f per sample)\n", ours.log_likelihood,
              g_train_ll, ours.log_likelihood / n_samples, g_train_ll / n_samples);
  std::printf("  held-out log-likelihood: ours %.6f, GHMM %.6f (%.5f vs %.5f per sample)\n", o_held_ll, g_held_ll,
              o_held_ll / held_samples, g_held_ll / held_samples);
  check(ours.log_likelihood >= g_train_ll - 1e-9 * std::fabs(g_train_ll), "trained: ours >= GHMM on training data (deficit)",
        std::max(0.0, (g_train_ll - ours.log_likelihood) / std::fabs(g_train_ll)), 1e-9);
  const double held_deficit = (g_held_ll - o_held_ll) / held_samples;
  check(held_deficit <= slack, "trained: held-out deficit of ours, nats per sample", std::max(0.0, held_deficit), slack);

  // 4. Time, in this run.
  std::printf("  training time: ours %.4f s, GHMM %.4f s, ratio GHMM/ours %.2f\n", t_ours, t_ghmm, t_ghmm / t_ours);
  if (timing_iters > 0) {
    hmm::TrainOptions fixed = opt;
    fixed.max_iterations = timing_iters;
    fixed.tolerance = -std::numeric_limits<double>::infinity();  // run exactly timing_iters E-steps
    t0 = std::chrono::steady_clock::now();
    const auto o = hmm::train(init, train, fixed);
    const double to = seconds_since(t0) / o.iterations;
    ghmm_bridge::Model gm(init);
    t0 = std::chrono::steady_clock::now();
    ghmm_bridge::baum_welch(gm, g_train, 1e-300, timing_iters);
    const double tg = seconds_since(t0) / timing_iters;
    std::printf("  per Baum-Welch iteration: ours %.3f ms, GHMM %.3f ms, ratio %.2f\n", 1e3 * to, 1e3 * tg, tg / to);
  }
  std::printf("%s\n", ok ? "all comparisons hold" : "SOME COMPARISONS FAILED");
  return ok ? 0 : 1;
}
