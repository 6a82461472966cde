// bench_hmm: speed of the outcome HMMs (issue 2), each figure against a baseline measured in the
// same run.
//   1. Online update of 3 classes x 10 states (ForwardFilter::step, band path), median / p99 /
//      p99.9 / max nanoseconds per sample over 1,000,000 samples, against a plain full-matrix
//      forward step (the O(n^2) textbook recursion). Goals: median < 250 ns, p99.9 < 2 us.
//   2. Training three 10-state HMMs on 300 sequences of 600-900 samples (one core). Goal < 2 s.
//   3. Per Baum-Welch iteration against GHMM on the same data and initial model (goal >= 2x),
//      both full trainings as a ratio, and one 770-sample log-likelihood.
// usage: bench_hmm [--samples N] [--quick]   (--quick: 100,000 samples, 60 sequences)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "forward_filter.h"
#include "hmm.h"
#ifdef DG_WITH_GHMM
#include "ghmm_bridge.h"
#endif

using namespace dressguard;
using Clock = std::chrono::steady_clock;

namespace {

// Class c's 10-state left-right HMM: means progress along the states, class-specific.
model::ClassHmm class_hmm(int c, int n, double mean_len) {
  model::ClassHmm h = model::left_right_chain(n, 1.0 - n / mean_len);  // dwell mean_len / n
  h.name = c == 0 ? "good" : c == 1 ? "missed" : "caught";
  for (int j = 0; j < n; ++j) {
    model::GaussianEmission e;
    e.mean[0] = -2.0 + (4.0 + c) * j / n;
    e.mean[1] = (1.0 - 0.6 * c) * std::sin(0.8 * j + c);
    e.cov[0][0] = 0.15 + 0.05 * c;
    e.cov[1][1] = 0.25;
    e.cov[0][1] = e.cov[1][0] = 0.05 * std::cos(j + c);
    h.emission.push_back(e);
  }
  h.log_prior = -std::log(3.0);
  return h;
}

// The textbook forward step over the full matrix, same scaling as the filter: the baseline.
struct PlainForward {
  int C, n;
  std::vector<double> A, m0, m1, ip, iq, ir, lc, alpha, tmp, ll;
  bool first = true;
  explicit PlainForward(const model::OutcomeModel& m) : C(static_cast<int>(m.classes.size())), n(m.classes[0].n_states) {
    for (const auto& h : m.classes) {
      A.insert(A.end(), h.transition.begin(), h.transition.end());
      alpha.insert(alpha.end(), h.initial.begin(), h.initial.end());
      for (const auto& e : h.emission) {
        const double det = e.cov[0][0] * e.cov[1][1] - e.cov[0][1] * e.cov[1][0];
        m0.push_back(e.mean[0]), m1.push_back(e.mean[1]);
        ip.push_back(e.cov[1][1] / det), iq.push_back(-e.cov[0][1] / det), ir.push_back(e.cov[0][0] / det);
        lc.push_back(-std::log(2 * M_PI) - 0.5 * std::log(det));
      }
    }
    tmp.resize(n);
    ll.assign(C, 0.0);
  }
  void step(double x0, double x1) {
    for (int c = 0; c < C; ++c) {
      double* a = &alpha[c * n];
      const double* Ac = &A[c * n * n];
      for (int j = 0; j < n; ++j) {
        double s = 0.0;
        if (first) {
          s = a[j];
        } else {
          for (int i = 0; i < n; ++i) s += a[i] * Ac[i * n + j];
        }
        const int k = c * n + j;
        const double d0 = x0 - m0[k], d1 = x1 - m1[k];
        tmp[j] = s * std::exp(lc[k] - 0.5 * (ip[k] * d0 * d0 + 2 * iq[k] * d0 * d1 + ir[k] * d1 * d1));
      }
      double z = 0.0;
      for (int j = 0; j < n; ++j) z += tmp[j];
      for (int j = 0; j < n; ++j) a[j] = tmp[j] / z;
      ll[c] += std::log(z);
    }
    first = false;
  }
};

struct Stats {
  double median, p99, p999, max, mean;
};
Stats stats(std::vector<int64_t>& ns) {
  std::sort(ns.begin(), ns.end());
  auto q = [&](double p) { return static_cast<double>(ns[std::min(ns.size() - 1, static_cast<size_t>(p * ns.size()))]); };
  double sum = 0;
  for (auto v : ns) sum += static_cast<double>(v);
  return {q(0.5), q(0.99), q(0.999), static_cast<double>(ns.back()), sum / ns.size()};
}

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

int main(int argc, char** argv) {
  long n_samples = 1000000;
  int per_class = 100;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) n_samples = 100000, per_class = 20;
    else if (!std::strcmp(argv[i], "--samples") && i + 1 < argc) n_samples = std::atol(argv[++i]);
    else {
      std::puts("usage: bench_hmm [--samples N] [--quick]");
      return 2;
    }
  }
  const int n = 10;
  model::OutcomeModel m;
  for (int c = 0; c < 3; ++c) m.classes.push_back(class_hmm(c, n, 750));
  double z = 0;  // exact prior normalisation
  for (auto& h : m.classes) z += std::exp(h.log_prior);
  for (auto& h : m.classes) h.log_prior -= std::log(z);

  // ---- 1. online update --------------------------------------------------------------------
  std::mt19937_64 rng(42);
  std::vector<double> xs;
  std::vector<char> starts;
  xs.reserve(2 * n_samples);
  while (static_cast<long>(xs.size()) < 2 * n_samples) {
    const size_t T = 600 + rng() % 301;
    const auto s = hmm::sample(m.classes[rng() % 3], T, rng);
    starts.push_back(1);
    starts.resize(xs.size() / 2 + T, 0);
    xs.insert(xs.end(), s.x.begin(), s.x.end());
  }
  xs.resize(2 * n_samples);
  starts.resize(n_samples);
  filter::ForwardFilter f(m);
  PlainForward plain(m);
  std::vector<int64_t> t_band(n_samples), t_plain(n_samples);
  double sink = 0;
  for (long i = 0; i < n_samples; ++i) {
    if (starts[i]) {
      f.reset();
      plain = PlainForward(m);
    }
    // The filter takes raw forces; with the identity convention raw = features.
    auto a = Clock::now();
    f.step(xs[2 * i], 0.0, xs[2 * i + 1]);
    auto b = Clock::now();
    plain.step(xs[2 * i], xs[2 * i + 1]);
    auto c = Clock::now();
    t_band[i] = std::chrono::duration_cast<std::chrono::nanoseconds>(b - a).count();
    t_plain[i] = std::chrono::duration_cast<std::chrono::nanoseconds>(c - b).count();
    sink += f.posterior(2) + plain.ll[0];
  }
  // Clock overhead: two back-to-back reads.
  std::vector<int64_t> t_clock(100000);
  for (auto& v : t_clock) {
    auto a = Clock::now();
    auto b = Clock::now();
    v = std::chrono::duration_cast<std::chrono::nanoseconds>(b - a).count();
  }
  const Stats sb = stats(t_band), sp = stats(t_plain), sc = stats(t_clock);
  std::printf("online update, 3 classes x 10 states, %ld samples (per-sample timing includes the clock read, median %.0f ns)\n",
              n_samples, sc.median);
  std::printf("  %-34s median %6.0f ns  p99 %6.0f ns  p99.9 %6.0f ns  max %8.0f ns  mean %6.1f ns\n",
              "ForwardFilter::step (band)", sb.median, sb.p99, sb.p999, sb.max, sb.mean);
  std::printf("  %-34s median %6.0f ns  p99 %6.0f ns  p99.9 %6.0f ns  max %8.0f ns  mean %6.1f ns\n",
              "plain full-matrix forward step", sp.median, sp.p99, sp.p999, sp.max, sp.mean);
  std::printf("  speed-up (median) %.2fx; goals: median < 250 ns %s, p99.9 < 2000 ns %s\n", sp.median / sb.median,
              sb.median < 250 ? "MET" : "MISSED", sb.p999 < 2000 ? "MET" : "MISSED");

  // ---- 2. training ----------------------------------------------------------------------------
  std::vector<std::vector<hmm::FeatureSequence>> data(3);
  size_t total = 0;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < per_class; ++k) {
      data[c].push_back(hmm::sample(m.classes[c], 600 + rng() % 301, rng));
      total += data[c].back().size();
    }
  hmm::TrainOptions opt;
  opt.n_states = n;
  opt.cov_floor = 1e-6;
  std::vector<model::ClassHmm> inits;
  auto t0 = Clock::now();
  int iters = 0;
  for (int c = 0; c < 3; ++c) {
    inits.push_back(hmm::initial_left_right(data[c], opt));
    const auto r = hmm::train(inits.back(), data[c], opt);
    iters += r.iterations;
    sink += r.log_likelihood;
  }
  const double t_train = since(t0);
  std::printf("training three 10-state HMMs on %d sequences of 600-900 samples (%zu samples), one core:\n", 3 * per_class, total);
  std::printf("  %.3f s, %d Baum-Welch iterations in all (%.1f ms each); goal < 2 s %s\n", t_train, iters,
              1e3 * t_train / iters, t_train < 2.0 ? "MET" : "MISSED");

#ifdef DG_WITH_GHMM
  // ---- 3. against GHMM on the same data and initial models -------------------------------------
  const int K = 5;
  double ours_it = 0, ghmm_it = 0;
  hmm::TrainOptions fixed = opt;
  fixed.max_iterations = K;
  fixed.tolerance = -INFINITY;  // exactly K iterations
  for (int c = 0; c < 3; ++c) {
    t0 = Clock::now();
    const auto r = hmm::train(inits[c], data[c], fixed);
    ours_it += since(t0) / r.iterations;
    ghmm_bridge::Model g(inits[c]);
    ghmm_bridge::Sequences gs(data[c]);
    t0 = Clock::now();
    ghmm_bridge::baum_welch(g, gs, 1e-300, K);
    ghmm_it += since(t0) / K;
  }
  std::printf("per Baum-Welch iteration (sum over the 3 classes, %d iterations each):\n", K);
  std::printf("  ours %.2f ms, GHMM %.2f ms, ratio %.2fx; goal >= 2x %s\n", 1e3 * ours_it, 1e3 * ghmm_it, ghmm_it / ours_it,
              ghmm_it / ours_it >= 2.0 ? "MET" : "MISSED");
  t0 = Clock::now();
  for (int c = 0; c < 3; ++c) {
    ghmm_bridge::Model g(inits[c]);
    ghmm_bridge::Sequences gs(data[c]);
    sink += ghmm_bridge::baum_welch(g, gs, 1e-4, 500).reported_log_likelihood;
  }
  const double t_ghmm = since(t0);
  std::printf("full training of the three classes: ours %.3f s (tolerance 1e-6 nats/sample), GHMM %.3f s (eps 1e-4), ratio %.2fx\n",
              t_train, t_ghmm, t_ghmm / t_train);
  {
    const auto s = hmm::sample(m.classes[0], 770, rng);
    ghmm_bridge::Model g(m.classes[0]);
    const int R = 200;
    t0 = Clock::now();
    for (int r = 0; r < R; ++r) sink += hmm::forward_log_likelihood(m.classes[0], s);
    const double to = since(t0) / R;
    t0 = Clock::now();
    for (int r = 0; r < R; ++r) sink += g.log_likelihood(s);
    const double tg = since(t0) / R;
    filter::ForwardFilter ff(m);
    t0 = Clock::now();
    for (int r = 0; r < R; ++r) {
      ff.reset();
      for (size_t t = 0; t < s.size(); ++t) ff.step_features(s.at(t));
    }
    const double tf = since(t0) / R;
    std::printf("one 770-sample log-likelihood, 10 states: ours offline %.3f ms, GHMM %.3f ms (ratio %.2fx); "
                "ForwardFilter over all 3 classes %.3f ms\n", 1e3 * to, 1e3 * tg, tg / to, 1e3 * tf);
  }
#else
  std::printf("GHMM comparison not built (libghmm-dev absent)\n");
#endif
  std::printf("(checksum %g)\n", sink);
  return 0;
}
