// Outcome HMM training and inference (see hmm.h for the equations and the convergence rule).
#include "hmm.h"

#include "emission_update.h"  // predictor/filter: the vector exp

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace dressguard::hmm {

namespace {

constexpr double kLog2Pi = 1.8378770664093454835606594728112;
constexpr double kNegInf = -std::numeric_limits<double>::infinity();
// Normalised forward (and scaled backward) probabilities below this are set to 0, as the online
// filter does (predictor/filter/emission_update.h): states a left-right model has left behind
// would otherwise decay through the subnormal range, where arithmetic is ~100x slower.
constexpr double kFlushBelow = 1e-300;

// Per-state constants for the emission log density: mean, inverse covariance [[p q][q r]] and
// -log(2 pi) - log|S|/2.
struct EmissionCache {
  std::vector<double> m0, m1, p, q, r, c;
  explicit EmissionCache(const ClassHmm& h) {
    for (const auto& e : h.emission) {
      const model::EmissionTerms t = model::emission_terms(e);
      m0.push_back(t.mean0);
      m1.push_back(t.mean1);
      p.push_back(t.ip);
      q.push_back(t.iq);
      r.push_back(t.ir);
      c.push_back(t.lconst);
    }
  }
  double log_density(int j, const double* x) const {
    const double d0 = x[0] - m0[j], d1 = x[1] - m1[j];
    return c[j] - 0.5 * (p[j] * d0 * d0 + 2.0 * q[j] * d0 * d1 + r[j] * d1 * d1);
  }
};

// The band of a transition matrix: lo[j]..hi[j] are the predecessors i with A_ij possibly > 0.
struct Band {
  std::vector<int> lo, hi;   // predecessors of j
  std::vector<int> slo, shi; // successors of i
  explicit Band(const ClassHmm& h) {
    const int n = h.n_states;
    lo.assign(n, n);
    hi.assign(n, -1);
    slo.assign(n, n);
    shi.assign(n, -1);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        if (h.transition[i * n + j] > 0.0) {
          lo[j] = std::min(lo[j], i);
          hi[j] = std::max(hi[j], i);
          slo[i] = std::min(slo[i], j);
          shi[i] = std::max(shi[i], j);
        }
  }
};

// Raises every eigenvalue of the symmetric 2x2 [[a b][b d]] to at least `floor`.
void floor_covariance(double cov[2][2], double floor) {
  const double a = cov[0][0], b = 0.5 * (cov[0][1] + cov[1][0]), d = cov[1][1];
  const double h = 0.5 * (a + d), g = std::sqrt(0.25 * (a - d) * (a - d) + b * b);
  double l1 = h + g, l2 = h - g;  // l1 >= l2
  if (l2 >= floor) return;
  l1 = std::max(l1, floor);
  l2 = std::max(l2, floor);
  // Unit eigenvector of l1: (b, l1 - a) or, when b = 0, the axis of the larger diagonal entry.
  double v0, v1;
  if (std::fabs(b) > 1e-300) {
    v0 = b;
    v1 = (h + g) - a;
    const double nrm = std::hypot(v0, v1);
    v0 /= nrm;
    v1 /= nrm;
  } else if (a >= d) {
    v0 = 1.0, v1 = 0.0;
  } else {
    v0 = 0.0, v1 = 1.0;
  }
  // S = l1 v v^T + l2 w w^T with w = (-v1, v0).
  cov[0][0] = l1 * v0 * v0 + l2 * v1 * v1;
  cov[1][1] = l1 * v1 * v1 + l2 * v0 * v0;
  cov[0][1] = cov[1][0] = (l1 - l2) * v0 * v1;
}

// The chain's state distributions before a sequence's first sample when its first `steps` samples
// went unobserved (hmm.h, FeatureSequence::unobserved): rows f_0 = pi, f_{s+1} = f_s A, so row
// s is p(state at s) with nothing observed and f_steps is where the observed sequence begins.
// Each product keeps the sum 1 of a stochastic A; it is renormalised only against rounding.
// (steps + 1) x n, row-major, into `rows`.
void unobserved_rows(const ClassHmm& h, size_t steps, std::vector<double>& rows) {
  const int n = h.n_states;
  rows.assign((steps + 1) * n, 0.0);
  std::copy(h.initial.begin(), h.initial.end(), rows.begin());
  for (size_t k = 0; k < steps; ++k) {
    const double* p = &rows[k * n];
    double* q = &rows[(k + 1) * n];
    double z = 0.0;
    for (int j = 0; j < n; ++j) {
      double sum = 0.0;
      for (int i = 0; i < n; ++i) sum += p[i] * h.transition[i * n + j];
      q[j] = sum;
      z += sum;
    }
    for (int j = 0; j < n; ++j) q[j] /= z;
  }
}

// pi A^steps: unobserved_rows' last row.
std::vector<double> initial_after(const ClassHmm& h, size_t steps) {
  std::vector<double> rows;
  unobserved_rows(h, steps, rows);
  return std::vector<double>(rows.end() - h.n_states, rows.end());
}

// Scratch for one sequence's forward-backward pass, reused across sequences.
// One HMM laid out for the filter's update kernel: padded structure-of-arrays emissions and the
// band diagonals B_d[j] = A_{j-d,j} (band -1: the caller predicts with the full matrix).
struct KernelModel {
  int np = 0;
  std::vector<double> diag, m0, m1, ip, iq, ir, lc;
  filter::ClassBlock block;
  filter::ClassUpdateFn update = filter::class_update_best();  // hmm.h, Determinism: the bits per CPU
  explicit KernelModel(const ClassHmm& h, const Band& band) {
    const int n = h.n_states;
    np = (n + 3) & ~3;
    int w = 0;
    for (int j = 0; j < n; ++j) {
      if (band.lo[j] < j - filter::kMaxBand) w = -1;
      if (w >= 0) w = std::max(w, j - band.lo[j]);
      if (band.hi[j] > j) w = -1;  // a predecessor after j: not left-right
    }
    for (int j = 0; j < np; ++j) {
      model::GaussianEmission e;
      if (j < n) e = h.emission[j];
      const model::EmissionTerms t = model::emission_terms(e);
      m0.push_back(t.mean0), m1.push_back(t.mean1);
      ip.push_back(t.ip), iq.push_back(t.iq), ir.push_back(t.ir);
      lc.push_back(t.lconst);
    }
    if (w >= 0)
      for (int d = 0; d <= w; ++d)
        for (int j = 0; j < np; ++j) diag.push_back(j < n && j - d >= 0 ? h.transition[(j - d) * n + j] : 0.0);
    block.n_padded = np;
    block.band = w;
    for (int d = 0; d <= w; ++d) block.diag[d] = diag.data() + d * np;
    block.m0 = m0.data(), block.m1 = m1.data(), block.ip = ip.data(), block.iq = iq.data(), block.ir = ir.data();
    block.lc = lc.data();
  }
};

struct Workspace {
  std::vector<double> alpha, beta, bs, scale;  // T*n, 2*n (two rows), T*n (shifted emissions), T
  KernelModel km;
  std::vector<double> row, pred, logb, ex;     // one padded row for the kernel
  std::vector<double> v;                        // bs * beta / c of the row after
  std::vector<double> prefix, g, gn;            // an unobserved start: its rows, two backward rows
  Workspace(const ClassHmm& h, const Band& band)
      : km(h, band), row(filter::kBandPad + km.np, 0.0), pred(km.np, 0.0), logb(km.np, 0.0), ex(km.np, 0.0),
        v(h.n_states, 0.0), g(h.n_states, 0.0), gn(h.n_states, 0.0) {}
  void resize(size_t T, int n) {
    if (alpha.size() < T * n) {
      alpha.resize(T * n);
      bs.resize(T * n);
    }
    if (beta.size() < static_cast<size_t>(2 * n)) beta.resize(2 * n);
    if (scale.size() < T) scale.resize(T);
  }
};

// Sufficient statistics of one Baum-Welch iteration. Moments are about ref (the previous mean).
struct Accumulators {
  int n;
  std::vector<double> g0, g, s0, s1, s00, s01, s11, xi;
  explicit Accumulators(int n_) : n(n_), g0(n_), g(n_), s0(n_), s1(n_), s00(n_), s01(n_), s11(n_), xi(n_ * n_) {}
};

// The statistics of an unobserved start (hmm.h, FeatureSequence::unobserved), after the backward
// pass has reached the first observed sample with beta_0. The k unobserved steps s = 0..k-1 are
// steps with emission density 1, so with f_s = pi A^s (unobserved_rows) and
//   g_k = v,  v_j = bs_0(j) beta_0(j) / c_0     (the observed sequence given the state at k)
//   g_s = A g_{s+1}                               (the same, given the state at s)
// the posteriors are xi_s(i,j) = f_s(i) A_ij g_{s+1}(j) and gamma_0(i) = pi_i g_0(i); they need no
// normaliser, because sum_l f_k(l) v_l = sum_l alpha_0(l) beta_0(l) = 1. The transitions of the
// unobserved span go into xi and its first state into pi's statistic; the emissions get nothing.
void unobserved_statistics(const ClassHmm& h, const Band& band, Workspace& w, size_t k, const double* beta0,
                           Accumulators& acc) {
  const int n = h.n_states;
  const double* A = h.transition.data();
  const double ic = 1.0 / w.scale[0];
  double* g = w.g.data();
  double* gn = w.gn.data();
  for (int j = 0; j < n; ++j) g[j] = w.bs[j] * beta0[j] * ic;
  for (size_t st = k; st-- > 0;) {
    const double* f = &w.prefix[st * n];
    for (int i = 0; i < n; ++i) {
      double sum = 0.0;
      double* xi = acc.xi.data() + i * n;
      for (int j = band.slo[i]; j <= band.shi[i]; ++j) {
        const double pr = A[i * n + j] * g[j];
        sum += pr;
        xi[j] += f[i] * pr;
      }
      gn[i] = sum;
    }
    std::swap(g, gn);
  }
  for (int i = 0; i < n; ++i) acc.g0[i] += h.initial[i] * g[i];
}

// Scaled forward-backward on one sequence, band-restricted; adds its statistics to acc and returns
// log p(seq). bs(t,j) = b_j(x_t) exp(-m_t), zero for unreachable states (pred = 0): then every
// alpha, beta and product below stays finite (see hmm.h).
double forward_backward(const ClassHmm& h, const EmissionCache& em, const Band& band, const FeatureSequence& s,
                        Workspace& w, Accumulators& acc) {
  const int n = h.n_states;
  const size_t T = s.size();
  if (T == 0) return 0.0;
  w.resize(T, n);
  const double* A = h.transition.data();
  double ll = 0.0;
  // Forward with the filter's per-class update (predictor/filter/emission_update.h): band
  // prediction, log densities, exp and normalisation four states at a time. It works in place on
  // a padded row (kBandPad zeros, then the states); each alpha_t and its shifted emissions are
  // copied out to the T x n arrays the backward pass reads.
  const KernelModel& km = w.km;
  double* row = w.row.data() + filter::kBandPad;
  const size_t k = s.unobserved;
  if (k > 0) unobserved_rows(h, k, w.prefix);
  const double* start = k > 0 ? &w.prefix[k * n] : h.initial.data();  // pi A^k
  for (size_t t = 0; t < T; ++t) {
    double* al = &w.alpha[t * n];
    double* b = &w.bs[t * n];
    const double* x = s.at(t);
    bool given = false;
    if (t == 0) {
      for (int j = 0; j < km.np; ++j) w.pred[j] = j < n ? start[j] : 0.0;
      given = true;
    } else if (km.block.band < 0) {
      for (int j = 0; j < n; ++j) {
        double sum = 0.0;
        for (int i = band.lo[j]; i <= band.hi[j]; ++i) sum += row[i] * A[i * n + j];
        w.pred[j] = sum;
      }
      given = true;
    }
    double m = 0.0;
    const double c = km.update(km.block, given, x[0], x[1], row, w.pred.data(), w.logb.data(), &m, w.ex.data());
    for (int j = 0; j < n; ++j) {
      al[j] = row[j];
      b[j] = w.ex[j];
    }
    w.scale[t] = c;
    ll += std::log(c) + m;
  }
  // Backward pass fused with the statistics, t = T-1 down to 0, two beta rows only:
  //   v_j       = bs_{t+1}(j) beta_{t+1}(j) / c_{t+1}
  //   beta_t(i) = sum_j A_ij v_j                      (beta_T = 1)
  //   xi_t(i,j) = alpha_t(i) A_ij v_j                 (each product A_ij v_j serves both)
  //   gamma_t(j) = alpha_t(j) beta_t(j)               (sums to 1 per t with this scaling)
  double* nb = w.beta.data();      // beta_{t+1}
  double* cur = w.beta.data() + n;  // beta_t
  double* v = w.v.data();
  for (size_t tt = T; tt-- > 0;) {
    const double* al = &w.alpha[tt * n];
    if (tt == T - 1) {
      for (int j = 0; j < n; ++j) cur[j] = 1.0;
    } else {
      const double* b1 = &w.bs[(tt + 1) * n];
      const double ic = 1.0 / w.scale[tt + 1];
      for (int j = 0; j < n; ++j) v[j] = b1[j] * nb[j] * ic;
      for (int i = 0; i < n; ++i) {
        const double ai = al[i];
        double sum = 0.0;
        const double* Ai = A + i * n;
        double* xi = acc.xi.data() + i * n;
        for (int j = band.slo[i]; j <= band.shi[i]; ++j) {
          const double pr = Ai[j] * v[j];
          sum += pr;
          xi[j] += ai * pr;
        }
        cur[i] = sum < kFlushBelow ? 0.0 : sum;
      }
    }
    const double* x = s.at(tt);
    for (int j = 0; j < n; ++j) {
      const double gm = al[j] * cur[j];
      if (gm == 0.0) continue;
      const double d0 = x[0] - em.m0[j], d1 = x[1] - em.m1[j];
      acc.g[j] += gm;
      acc.s0[j] += gm * d0;
      acc.s1[j] += gm * d1;
      acc.s00[j] += gm * d0 * d0;
      acc.s01[j] += gm * d0 * d1;
      acc.s11[j] += gm * d1 * d1;
    }
    if (tt == 0 && k == 0)
      for (int j = 0; j < n; ++j) acc.g0[j] += al[j] * cur[j];
    if (tt == 0 && k > 0) unobserved_statistics(h, band, w, k, cur, acc);
    std::swap(nb, cur);
  }
  return ll;
}

// M-step (hmm.h): the re-estimated model from the statistics. A state no sequence visits keeps
// its previous emission; a row with no transitions out keeps its previous row.
void maximise(const ClassHmm& in, const Accumulators& acc, size_t n_seqs, double cov_floor, ClassHmm& out) {
  const int n = in.n_states;
  out = in;
  double g0sum = 0.0;
  for (int j = 0; j < n; ++j) g0sum += acc.g0[j];
  if (g0sum > 0.0)
    for (int j = 0; j < n; ++j) out.initial[j] = acc.g0[j] / g0sum;
  for (int i = 0; i < n; ++i) {
    double row = 0.0;
    for (int j = 0; j < n; ++j) row += acc.xi[i * n + j];
    if (!(row > 0.0)) continue;
    for (int j = 0; j < n; ++j) out.transition[i * n + j] = acc.xi[i * n + j] / row;
  }
  for (int j = 0; j < n; ++j) {
    const double G = acc.g[j];
    if (!(G > 1e-300)) continue;
    auto& e = out.emission[j];
    // Moments about the previous mean ref: mu = ref + S1/G, Sigma = S2/G - (S1/G)(S1/G)^T.
    const double dm0 = acc.s0[j] / G, dm1 = acc.s1[j] / G;
    e.mean[0] = in.emission[j].mean[0] + dm0;
    e.mean[1] = in.emission[j].mean[1] + dm1;
    e.cov[0][0] = acc.s00[j] / G - dm0 * dm0;
    e.cov[1][1] = acc.s11[j] / G - dm1 * dm1;
    e.cov[0][1] = e.cov[1][0] = acc.s01[j] / G - dm0 * dm1;
    if (cov_floor > 0.0) floor_covariance(e.cov, cov_floor);
  }
  (void)n_seqs;
}

void check_options(const TrainOptions& opt) {
  if (opt.n_states < 1 || opt.n_states > model::kMaxStates)
    throw std::invalid_argument("states must be 1.." + std::to_string(model::kMaxStates));
  if (opt.band < 0) throw std::invalid_argument("band must be >= 0");
  if (opt.max_iterations < 1) throw std::invalid_argument("max_iterations must be >= 1");
  if (!(opt.cov_floor >= kMinCovFloor))
    throw std::invalid_argument("cov_floor must be at least 1e-9 (hmm.h, kMinCovFloor)");
}

}  // namespace

ClassHmm initial_left_right(const std::vector<FeatureSequence>& seqs, const TrainOptions& opt) {
  check_options(opt);
  const int n = opt.n_states;
  ClassHmm h;
  h.n_states = n;
  h.initial.assign(n, 0.0);
  h.initial[0] = 1.0;
  h.transition.assign(n * n, 0.0);
  h.emission.assign(n, model::GaussianEmission{});
  // Equal segments of the pull: sample t of a length-T sequence that starts k samples late
  // (FeatureSequence::unobserved) belongs to state floor((k + t) n / (k + T)).
  std::vector<double> cnt(n), s0(n), s1(n), s00(n), s01(n), s11(n);
  double total_len = 0.0;
  size_t used = 0;
  for (const auto& s : seqs) {
    const size_t T = s.size();
    if (T < static_cast<size_t>(n)) continue;
    const size_t k = s.unobserved;
    total_len += static_cast<double>(k + T);
    ++used;
    for (size_t t = 0; t < T; ++t) {
      const int j = static_cast<int>((k + t) * static_cast<size_t>(n) / (k + T));
      const double* x = s.at(t);
      cnt[j] += 1;
      s0[j] += x[0];
      s1[j] += x[1];
      s00[j] += x[0] * x[0];
      s01[j] += x[0] * x[1];
      s11[j] += x[1] * x[1];
    }
  }
  if (used == 0)
    throw std::invalid_argument("no training sequence has at least as many samples as the " + std::to_string(n) +
                                " states (--states)");
  for (int j = 0; j < n; ++j)
    if (cnt[j] == 0)
      throw std::invalid_argument("no training sample falls in state " + std::to_string(j) +
                                  "'s segment (every sequence starts after it: too few states for how late they start)");
  for (int j = 0; j < n; ++j) {
    auto& e = h.emission[j];
    e.mean[0] = s0[j] / cnt[j];
    e.mean[1] = s1[j] / cnt[j];
    e.cov[0][0] = s00[j] / cnt[j] - e.mean[0] * e.mean[0];
    e.cov[1][1] = s11[j] / cnt[j] - e.mean[1] * e.mean[1];
    e.cov[0][1] = e.cov[1][0] = s01[j] / cnt[j] - e.mean[0] * e.mean[1];
    floor_covariance(e.cov, opt.cov_floor);
  }
  // Transitions: a segment lasts mean_len/n samples, so leaving has probability n/mean_len
  // (held to [1e-6, 0.5], hmm.h).
  const double mean_len = total_len / static_cast<double>(used);
  const double leave = std::clamp(static_cast<double>(n) / mean_len, 1e-6, 0.5);
  for (int i = 0; i < n; ++i) {
    const int reach = std::min(opt.band, n - 1 - i);
    if (reach == 0) {
      h.transition[i * n + i] = 1.0;
      continue;
    }
    double wsum = 0.0;
    for (int d = 1; d <= reach; ++d) wsum += std::ldexp(1.0, -(d - 1));
    h.transition[i * n + i] = 1.0 - leave;
    for (int d = 1; d <= reach; ++d) h.transition[i * n + i + d] = leave * std::ldexp(1.0, -(d - 1)) / wsum;
  }
  return h;
}

double baum_welch_step(const ClassHmm& in, const std::vector<FeatureSequence>& seqs, double cov_floor, ClassHmm& out) {
  const EmissionCache em(in);
  const Band band(in);
  Workspace w(in, band);
  Accumulators acc(in.n_states);
  double ll = 0.0;
  for (const auto& s : seqs) ll += forward_backward(in, em, band, s, w, acc);
  maximise(in, acc, seqs.size(), cov_floor, out);
  return ll;
}

TrainResult train(const ClassHmm& start, const std::vector<FeatureSequence>& seqs, const TrainOptions& opt) {
  check_options(opt);
  size_t n_samples = 0;
  for (const auto& s : seqs) n_samples += s.size();
  if (n_samples == 0) throw std::invalid_argument("no training samples");
  TrainResult r;
  ClassHmm cur = start, next;
  double prev = kNegInf;
  r.log_likelihood = kNegInf;
  for (int it = 0; it < opt.max_iterations; ++it) {
    const double ll = baum_welch_step(cur, seqs, opt.cov_floor, next);
    r.iterations = it + 1;
    r.history.push_back(ll);
    // -inf and NaN compare false with every likelihood: kept, -inf ended training "converged" and
    // an all-NaN run returned the 0-state model r.hmm starts as (hmm.h, train).
    if (!std::isfinite(ll)) {
      const char* what = std::isnan(ll) ? "NaN" : ll > 0 ? "+inf" : "-inf";
      throw std::invalid_argument(std::string("the log-likelihood is ") + what + " at iteration " +
                                  std::to_string(it + 1) + ": a sample is not finite, or so far from every state " +
                                  "that its squared distance overflows");
    }
    if (ll > r.log_likelihood) {
      r.log_likelihood = ll;
      r.hmm = cur;
    }
    // Gain per sample below tolerance (or a loss, possible only through the covariance floor).
    if (it > 0 && (ll - prev) / static_cast<double>(n_samples) < opt.tolerance) {
      r.converged = true;
      break;
    }
    prev = ll;
    cur = std::move(next);
  }
  return r;
}

TrainResult train(const std::vector<FeatureSequence>& seqs, const TrainOptions& opt) {
  return train(initial_left_right(seqs, opt), seqs, opt);
}

double emission_log_density(const model::GaussianEmission& e, const double x[kFeatures]) {
  // Cholesky S = L L^T, L = [[l00 0][l10 l11]]; log N = -log 2pi - log(l00 l11) - |L^-1 (x-mu)|^2/2.
  const double l00 = std::sqrt(e.cov[0][0]);
  const double l10 = e.cov[1][0] / l00;
  const double l11 = std::sqrt(e.cov[1][1] - l10 * l10);
  const double z0 = (x[0] - e.mean[0]) / l00;
  const double z1 = ((x[1] - e.mean[1]) - l10 * z0) / l11;
  return -kLog2Pi - std::log(l00 * l11) - 0.5 * (z0 * z0 + z1 * z1);
}

std::vector<double> forward_prefix_log_likelihoods(const ClassHmm& h, const FeatureSequence& s) {
  // General (full-matrix) scaled forward with Cholesky densities: an implementation independent
  // of the filter's band path, so the two can check each other.
  const int n = h.n_states;
  std::vector<double> alpha(h.initial), pred(n), lb(n), out;
  out.reserve(s.size());
  double ll = 0.0;
  for (size_t t = 0; t < s.size(); ++t) {
    if (t == 0) {
      pred = initial_after(h, s.unobserved);
    } else {
      for (int j = 0; j < n; ++j) {
        double sum = 0.0;
        for (int i = 0; i < n; ++i) sum += alpha[i] * h.transition[i * n + j];
        pred[j] = sum;
      }
    }
    double m = kNegInf;
    for (int j = 0; j < n; ++j) {
      if (pred[j] < kFlushBelow) pred[j] = 0.0;  // as the filter's kernel (emission_update.h)
      lb[j] = emission_log_density(h.emission[j], s.at(t));
      if (pred[j] > 0.0) m = std::max(m, lb[j]);
    }
    double c = 0.0;
    for (int j = 0; j < n; ++j) {
      alpha[j] = pred[j] > 0.0 ? pred[j] * std::exp(lb[j] - m) : 0.0;
      c += alpha[j];
    }
    for (int j = 0; j < n; ++j) alpha[j] = alpha[j] / c < kFlushBelow ? 0.0 : alpha[j] / c;
    ll += std::log(c) + m;
    out.push_back(ll);
  }
  return out;
}

double forward_log_likelihood(const ClassHmm& h, const FeatureSequence& s) {
  if (s.size() == 0) return 0.0;
  return forward_prefix_log_likelihoods(h, s).back();
}

ViterbiResult viterbi(const ClassHmm& h, const FeatureSequence& s) {
  ViterbiResult r;
  const int n = h.n_states;
  const size_t T = s.size();
  if (T == 0) return r;
  auto lg = [](double p) { return p > 0.0 ? std::log(p) : kNegInf; };
  std::vector<double> logA(n * n), delta(n), nd(n);
  for (int k = 0; k < n * n; ++k) logA[k] = lg(h.transition[k]);
  std::vector<int> back(T * n, -1);
  const std::vector<double> start = initial_after(h, s.unobserved);
  for (int j = 0; j < n; ++j) delta[j] = lg(start[j]) + emission_log_density(h.emission[j], s.at(0));
  for (size_t t = 1; t < T; ++t) {
    for (int j = 0; j < n; ++j) {
      double best = kNegInf;
      int arg = j;  // kept when no path reaches j (every v is -inf): a valid index, never -1
      for (int i = 0; i < n; ++i) {
        const double v = delta[i] + logA[i * n + j];
        if (v > best) best = v, arg = i;
      }
      nd[j] = best + emission_log_density(h.emission[j], s.at(t));
      back[t * n + j] = arg;
    }
    delta.swap(nd);
  }
  int last = static_cast<int>(std::max_element(delta.begin(), delta.end()) - delta.begin());
  r.log_probability = delta[last];
  r.path.assign(T, 0);
  for (size_t t = T; t-- > 0;) {
    r.path[t] = last;
    if (t > 0) last = back[t * n + last];
  }
  return r;
}

FeatureSequence sample(const ClassHmm& h, size_t T, std::mt19937_64& rng, std::vector<int>* states) {
  // Inverse-CDF draws from uniform doubles and Box-Muller normals: the same bits on every
  // platform for one rng state (std::normal_distribution is implementation-defined).
  auto uniform = [&rng]() { return (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53; };
  auto draw = [&](const double* p, int n) {
    double u = uniform(), acc = 0.0;
    for (int j = 0; j < n; ++j) {
      acc += p[j];
      if (u < acc) return j;
    }
    for (int j = n - 1; j >= 0; --j)
      if (p[j] > 0.0) return j;
    return n - 1;
  };
  const int n = h.n_states;
  FeatureSequence s;
  s.x.resize(T * kFeatures);
  if (states) states->resize(T);
  int st = draw(h.initial.data(), n);
  for (size_t t = 0; t < T; ++t) {
    if (t > 0) st = draw(&h.transition[st * n], n);
    if (states) (*states)[t] = st;
    const auto& e = h.emission[st];
    const double r = std::sqrt(-2.0 * std::log(uniform())), th = 2.0 * M_PI * uniform();
    const double z0 = r * std::cos(th), z1 = r * std::sin(th);
    const double l00 = std::sqrt(e.cov[0][0]), l10 = e.cov[1][0] / l00, l11 = std::sqrt(e.cov[1][1] - l10 * l10);
    s.x[t * kFeatures + 0] = e.mean[0] + l00 * z0;
    s.x[t * kFeatures + 1] = e.mean[1] + l10 * z0 + l11 * z1;
  }
  return s;
}

FeatureSequence features_of(const HapticSequence& trial, const model::FeatureConvention& fc, double truncate_at) {
  FeatureSequence s;
  s.unobserved = unrecorded_samples(trial);
  s.x.reserve(trial.samples.size() * kFeatures);
  for (const auto& smp : trial.samples) {
    if (smp.travel > truncate_at) break;
    double x[kFeatures];
    fc.apply(smp.f_motion, smp.f_lateral, smp.f_vertical, x);
    s.x.insert(s.x.end(), x, x + kFeatures);
  }
  return s;
}

model::FeatureConvention fit_feature_scaling(const std::vector<const HapticSequence*>& trials,
                                             const model::FeatureConvention& axes) {
  model::FeatureConvention fc;
  for (int k = 0; k < kFeatures; ++k) {
    fc.axis[k] = axes.axis[k];
    fc.sign[k] = axes.sign[k];
  }
  const auto each_sample = [&](const auto& f) {
    for (const auto* tr : trials)
      for (const auto& smp : tr->samples) {
        double x[kFeatures];
        fc.apply(smp.f_motion, smp.f_lateral, smp.f_vertical, x);
        f(x);
      }
  };
  // Two passes, the mean and then the spread about it. The one-pass E[x^2] - E[x]^2 cancels: a
  // feature constant at 0.3 N kept ~eps 0.3^2 = 7e-15 N^2 of rounding, was scaled by 8.6e-8, and
  // a trial 1 N off that constant then sat 1.2e7 feature units from every state, a penalty that
  // swamped the classes' differences (session 85's review, finding 1).
  double n = 0.0, sum[kFeatures] = {}, ss[kFeatures] = {}, lo[kFeatures], hi[kFeatures];
  std::fill(lo, lo + kFeatures, std::numeric_limits<double>::infinity());
  std::fill(hi, hi + kFeatures, kNegInf);
  each_sample([&](const double* x) {
    n += 1.0;
    for (int k = 0; k < kFeatures; ++k) sum[k] += x[k], lo[k] = std::min(lo[k], x[k]), hi[k] = std::max(hi[k], x[k]);
  });
  if (n < 2.0) return fc;
  double mean[kFeatures];
  for (int k = 0; k < kFeatures; ++k) mean[k] = sum[k] / n;
  each_sample([&](const double* x) {
    for (int k = 0; k < kFeatures; ++k) ss[k] += (x[k] - mean[k]) * (x[k] - mean[k]);
  });
  for (int k = 0; k < kFeatures; ++k) {
    // Constant: every sample the same (offset that value, so the feature is exactly 0), or a
    // spread below 1e-9 of the feature's size, which is rounding's (~eps |mean|), not the data's.
    const double sd = std::sqrt(ss[k] / n), tiny = 1e-9 * std::max(1.0, std::fabs(mean[k]));
    const bool constant = lo[k] == hi[k] || sd <= tiny;
    fc.offset[k] = lo[k] == hi[k] ? lo[k] : mean[k];
    fc.scale[k] = constant ? 1.0 : sd;
  }
  return fc;
}

void set_log_priors(model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials, bool uniform) {
  std::vector<double> count(m.classes.size(), 0.0);
  for (const auto* t : trials)
    if (t->label) {
      const int c = m.class_index(outcome_name(*t->label));
      if (c >= 0) count[c] += 1.0;
    }
  double total = 0.0;
  for (double n : count) total += n;
  for (size_t c = 0; c < m.classes.size(); ++c) {
    if (!uniform && !(count[c] > 0))
      throw std::invalid_argument("set_log_priors: no training trial of class '" + m.classes[c].name + "'");
    m.classes[c].log_prior = uniform ? -std::log(static_cast<double>(m.classes.size())) : std::log(count[c] / total);
  }
  // Renormalise the priors in log space so that their exponentials sum to 1 to rounding.
  double z = 0.0;
  for (const auto& h : m.classes) z += std::exp(h.log_prior);
  for (auto& h : m.classes) h.log_prior -= std::log(z);
}

void set_training_conditions(model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials,
                             const std::function<std::string(const HapticSequence&)>& trial_name) {
  const auto name = [&](const HapticSequence& t) { return trial_name ? trial_name(t) : "trial '" + t.id + "'"; };
  const HapticSequence* first = nullptr;  // the trial whose period the others must share
  double first_period = 0.0, sum = 0.0;
  size_t timed = 0;
  for (const auto* t : trials) {
    const double period = mean_sample_period(*t);
    if (!(period > 0.0)) continue;
    if (!first) first = t, first_period = period;
    if (!model::same_period(period, first_period, kRecordingPeriodTolerance)) {
      char at[64], first_at[64];
      std::snprintf(at, sizeof at, " is sampled every %.9g s, ", period);
      std::snprintf(first_at, sizeof first_at, " every %.9g s", first_period);
      throw std::invalid_argument(name(*t) + at + name(*first) + first_at +
                                  ": a model is trained at one sample period (they must agree within 1e-3 relative)");
    }
    sum += period;
    ++timed;
  }
  m.sample_period_s = timed ? nominal_sample_period(sum / static_cast<double>(timed)) : 0.0;
  m.speed_min_m_s = m.speed_max_m_s = 0.0;
  for (const auto* t : trials) {
    m.speed_min_m_s = m.speed_min_m_s == 0.0 ? t->speed : std::min(m.speed_min_m_s, t->speed);
    m.speed_max_m_s = std::max(m.speed_max_m_s, t->speed);
  }
}

model::OutcomeModel train_outcome_model(const std::vector<const HapticSequence*>& trials, const ModelOptions& opt,
                                        const std::function<void(const std::string&)>& progress) {
  std::vector<const HapticSequence*> labelled;
  for (const auto* t : trials)
    if (t->label) labelled.push_back(t);
  if (labelled.empty()) throw std::invalid_argument("no labelled trials to train on");
  model::OutcomeModel m;
  m.features = fit_feature_scaling(labelled, opt.features);
  m.source_dataset = opt.source_dataset;
  set_training_conditions(m, labelled, opt.trial_name);  // before Baum-Welch: a mixed rate fails at once
  std::string summary;
  for (int o = 0; o < kOutcomeCount; ++o) {
    std::vector<FeatureSequence> seqs;
    size_t samples = 0, longest = 0;
    for (const auto* t : labelled)
      if (static_cast<int>(*t->label) == o) {
        seqs.push_back(features_of(*t, m.features));
        samples += seqs.back().size();
        longest = std::max(longest, seqs.back().size());
      }
    if (seqs.empty()) continue;
    const std::string name(outcome_name(static_cast<Outcome>(o)));
    TrainResult r;
    try {
      r = train(seqs, opt.hmm);
    } catch (const std::invalid_argument& e) {
      // train() knows neither the class nor its trials. Without them, three 6-sample caught
      // trials read as if no trial had 10 samples, beside good and missed ones of 300.
      throw std::invalid_argument("class '" + name + "' (" + std::to_string(seqs.size()) + " trials, the longest " +
                                  std::to_string(longest) + " samples): " + e.what());
    }
    r.hmm.name = name;
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s: %zu sequences, %zu samples, %d states, %d iterations%s, log-likelihood %.6g (%.4f/sample)",
                  r.hmm.name.c_str(), seqs.size(), samples, opt.hmm.n_states, r.iterations, r.converged ? "" : " (not converged)",
                  r.log_likelihood, r.log_likelihood / static_cast<double>(samples));
    if (progress) progress(buf);
    summary += (summary.empty() ? "" : "; ") + std::string(buf);
    m.classes.push_back(std::move(r.hmm));
  }
  set_log_priors(m, labelled, opt.uniform_priors);
  m.training_summary = summary;
  return m;
}

Classification classify(const model::OutcomeModel& m, const FeatureSequence& seq, const ClassChoice& among) {
  Classification r;
  const auto chosen = [&](size_t c) {
    return among.empty() || std::find(among.begin(), among.end(), m.classes[c].name) != among.end();
  };
  double best = kNegInf;
  for (size_t c = 0; c < m.classes.size(); ++c) {
    const double ll = forward_log_likelihood(m.classes[c], seq);
    r.log_likelihood.push_back(ll);
    const double score = ll + m.classes[c].log_prior;
    if (chosen(c) && score > best) best = score, r.predicted = static_cast<int>(c);
  }
  if (r.predicted < 0)
    throw std::invalid_argument("classify: none of the classes to decide among is a class of the model");
  double z = 0.0;
  for (size_t c = 0; c < m.classes.size(); ++c) {
    r.posterior.push_back(chosen(c) ? std::exp(r.log_likelihood[c] + m.classes[c].log_prior - best) : 0.0);
    z += r.posterior.back();
  }
  for (double& p : r.posterior) p /= z;
  return r;
}

namespace {

// The confusion matrix's row of the label `name`: its class's, or a row appended (with a column
// that stays 0) when the classifier has no such class, so that a trial it can never get right
// shows as wrong in the matrix too, not only in the accuracy.
int truth_row(Evaluation& ev, const std::string& name) {
  const auto it = std::find(ev.classes.begin(), ev.classes.end(), name);
  if (it != ev.classes.end()) return static_cast<int>(it - ev.classes.begin());
  ev.classes.push_back(name);
  for (auto& row : ev.confusion) row.push_back(0);
  ev.confusion.emplace_back(ev.classes.size(), 0);
  return static_cast<int>(ev.classes.size()) - 1;
}

}  // namespace

Evaluation evaluate(const model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials, double truncate_at,
                    std::vector<TrialResult>* per_trial, const ClassChoice& among) {
  Evaluation ev;
  for (const auto& h : m.classes) ev.classes.push_back(h.name);
  const size_t k = m.classes.size();
  ev.confusion.assign(k, std::vector<int>(k, 0));
  for (const auto* t : trials) {
    TrialResult tr;
    tr.trial = t;
    if (t->label) tr.truth = m.class_index(outcome_name(*t->label));
    const FeatureSequence seq = features_of(*t, m.features, truncate_at);
    tr.samples = seq.size();
    if (!t->label || seq.size() == 0) {
      ++ev.skipped;
      tr.truth = -1;
    } else {
      // A label the model has no class for is scored too: wrong, whatever the model answers.
      tr.result = classify(m, seq, among);
      ev.confusion[truth_row(ev, std::string(outcome_name(*t->label)))][tr.result.predicted]++;
      ev.total++;
      if (tr.result.predicted == tr.truth) ev.correct++;
    }
    if (per_trial) per_trial->push_back(std::move(tr));
  }
  return ev;
}

namespace {

// The union of the models' class names, in the order they are first named.
std::vector<std::string> committee_classes(const std::vector<const model::OutcomeModel*>& models) {
  std::vector<std::string> names;
  for (const auto* m : models)
    for (const auto& h : m->classes)
      if (std::find(names.begin(), names.end(), h.name) == names.end()) names.push_back(h.name);
  return names;
}

int index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

}  // namespace

Vote vote(const std::vector<const model::OutcomeModel*>& models, const HapticSequence& trial, double truncate_at,
          const ClassChoice& among, const std::vector<double>& weights) {
  if (!weights.empty() && weights.size() != models.size())
    throw std::invalid_argument("vote: " + std::to_string(weights.size()) + " weights for " +
                                std::to_string(models.size()) + " models");
  Vote v;
  v.classes = committee_classes(models);
  v.votes.assign(v.classes.size(), 0);
  v.posterior_sum.assign(v.classes.size(), 0.0);
  for (const auto* m : models) {
    const FeatureSequence seq = features_of(trial, m->features, truncate_at);
    v.samples = seq.size();  // the cut is by travel, the same for every model
    if (seq.size() == 0) return v;
    const Classification c = classify(*m, seq, among);
    for (size_t k = 0; k < m->classes.size(); ++k) v.posterior_sum[index_of(v.classes, m->classes[k].name)] += c.posterior[k];
    v.answers.push_back(index_of(v.classes, m->classes[c.predicted].name));
    ++v.votes[v.answers.back()];
  }
  for (size_t k = 0; k < v.classes.size(); ++k) {
    const int b = v.predicted;
    if (b < 0 || v.votes[k] > v.votes[b] || (v.votes[k] == v.votes[b] && v.posterior_sum[k] > v.posterior_sum[b]))
      v.predicted = static_cast<int>(k);
  }
  if (!weights.empty()) v.predicted = weighted_choice(v, weights);
  return v;
}

int weighted_choice(const Vote& v, const std::vector<double>& weights) {
  if (weights.size() != v.answers.size() && !v.answers.empty())
    throw std::invalid_argument("weighted_choice: " + std::to_string(weights.size()) + " weights for " +
                                std::to_string(v.answers.size()) + " members");
  for (double w : weights)
    if (!std::isfinite(w) || w < 0) throw std::invalid_argument("weighted_choice: a weight is negative or not finite");
  if (v.answers.empty()) return -1;
  std::vector<double> sum(v.classes.size(), 0.0);
  for (size_t m = 0; m < v.answers.size(); ++m) sum[v.answers[m]] += weights[m];
  int best = -1;
  for (size_t k = 0; k < v.classes.size(); ++k)
    if (best < 0 || sum[k] > sum[best] || (sum[k] == sum[best] && v.posterior_sum[k] > v.posterior_sum[best]))
      best = static_cast<int>(k);
  return best;
}

double member_weight(int right, int n, int classes) {
  if (n <= 0 || right < 0 || right > n || classes < 2)
    throw std::invalid_argument("member_weight: needs 0 <= right <= n, n > 0 and at least two classes (right " +
                                std::to_string(right) + ", n " + std::to_string(n) + ", classes " +
                                std::to_string(classes) + ")");
  const double floor = 0.5 / n;
  const double a = std::clamp(static_cast<double>(right) / n, floor, 1.0 - floor);
  return std::max(0.0, std::log(a / (1.0 - a)) + std::log(static_cast<double>(classes - 1)));
}

LabelScore score_labels(const model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials,
                        double truncate_at, const ClassChoice& among) {
  // Every label a trial can carry and every answer the model can give, so that answer_counts()
  // counts each labelled trial (among: those labels only).
  std::vector<std::string> classes = among;
  if (classes.empty()) {
    for (Outcome o : {Outcome::Good, Outcome::Missed, Outcome::Caught}) classes.emplace_back(outcome_name(o));
    for (const auto& h : m.classes)
      if (index_of(classes, h.name) < 0) classes.push_back(h.name);
  }
  return label_score(answer_counts(m, trials, classes, truncate_at, among));
}

LabelScore label_score(const std::vector<std::vector<int>>& counts) {
  LabelScore s;
  for (size_t t = 0; t < counts.size(); ++t)
    for (size_t a = 0; a < counts[t].size(); ++a) s.scored += counts[t][a], s.right += t == a ? counts[t][a] : 0;
  return s;
}

std::vector<double> simulation_weights(const std::vector<const model::OutcomeModel*>& models,
                                       const std::vector<std::vector<const HapticSequence*>>& sets, double truncate_at,
                                       const ClassChoice& among) {
  if (sets.size() != models.size())
    throw std::invalid_argument("simulation_weights: " + std::to_string(sets.size()) + " sets for " +
                                std::to_string(models.size()) + " models");
  const int classes = static_cast<int>(among.empty() ? committee_classes(models).size() : among.size());
  std::vector<double> w;
  for (size_t i = 0; i < models.size(); ++i) {
    LabelScore sum;
    for (size_t j = 0; j < sets.size(); ++j) {
      if (j == i) continue;
      const LabelScore s = score_labels(*models[i], sets[j], truncate_at, among);
      sum.right += s.right, sum.scored += s.scored;
    }
    w.push_back(sum.scored > 0 ? member_weight(sum.right, sum.scored, classes) : 0.0);
  }
  return w;
}

AnswerModel answer_model(const std::vector<std::string>& classes, const std::vector<std::vector<int>>& counts) {
  const size_t k = classes.size();
  if (k < 2 || counts.size() != k)
    throw std::invalid_argument("answer_model: needs at least two classes and one row of counts per class (" +
                                std::to_string(k) + " classes, " + std::to_string(counts.size()) + " rows)");
  AnswerModel a;
  a.classes = classes;
  for (size_t t = 0; t < k; ++t) {
    if (counts[t].size() != k)
      throw std::invalid_argument("answer_model: row " + std::to_string(t) + " has " +
                                  std::to_string(counts[t].size()) + " counts for " + std::to_string(k) + " classes");
    double n = 0;
    for (int c : counts[t]) {
      if (c < 0) throw std::invalid_argument("answer_model: a count is negative");
      n += c;
    }
    std::vector<double> row;
    for (int c : counts[t]) row.push_back(std::log((c + 0.5) / (n + 0.5 * static_cast<double>(k))));
    a.log_p.push_back(std::move(row));
  }
  return a;
}

std::vector<std::vector<int>> answer_counts(const model::OutcomeModel& m,
                                            const std::vector<const HapticSequence*>& trials,
                                            const std::vector<std::string>& classes, double truncate_at,
                                            const ClassChoice& among) {
  std::vector<std::vector<int>> counts(classes.size(), std::vector<int>(classes.size(), 0));
  for (const auto* t : trials) {
    if (!t->label) continue;
    const std::string label(outcome_name(*t->label));
    const int truth = index_of(classes, label);
    if (truth < 0 || (!among.empty() && std::find(among.begin(), among.end(), label) == among.end())) continue;
    const FeatureSequence seq = features_of(*t, m.features, truncate_at);
    if (seq.size() == 0) continue;
    const std::string& said = m.classes[classify(m, seq, among).predicted].name;
    const int answer = index_of(classes, said);
    if (answer < 0)
      throw std::invalid_argument("answer_counts: the model answers '" + said + "', not one of the classes counted");
    ++counts[truth][answer];
  }
  return counts;
}

int answer_model_choice(const Vote& v, const std::vector<AnswerModel>& models, const ClassChoice& among) {
  if (v.answers.empty()) return -1;
  if (models.size() != v.answers.size())
    throw std::invalid_argument("answer_model_choice: " + std::to_string(models.size()) + " answer models for " +
                                std::to_string(v.answers.size()) + " members");
  int best = -1;
  double best_score = 0;
  for (size_t t = 0; t < v.classes.size(); ++t) {
    if (!among.empty() && std::find(among.begin(), among.end(), v.classes[t]) == among.end()) continue;
    double score = 0;  // sum_m ln P_m(a_m | t); a member whose model lacks t or its answer adds nothing
    for (size_t m = 0; m < models.size(); ++m) {
      const int row = index_of(models[m].classes, v.classes[t]);
      const int col = index_of(models[m].classes, v.classes[v.answers[m]]);
      if (row >= 0 && col >= 0) score += models[m].log_p[row][col];
    }
    if (best < 0 || score > best_score ||
        (score == best_score && v.posterior_sum[t] > v.posterior_sum[best]))
      best = static_cast<int>(t), best_score = score;
  }
  return best;
}

std::vector<AnswerModel> simulation_answer_models(const std::vector<const model::OutcomeModel*>& models,
                                                  const std::vector<std::vector<const HapticSequence*>>& sets,
                                                  double truncate_at, const ClassChoice& among) {
  if (sets.size() != models.size())
    throw std::invalid_argument("simulation_answer_models: " + std::to_string(sets.size()) + " sets for " +
                                std::to_string(models.size()) + " models");
  const std::vector<std::string> classes = among.empty() ? committee_classes(models) : among;
  std::vector<AnswerModel> out;
  for (size_t i = 0; i < models.size(); ++i) {
    std::vector<std::vector<int>> sum(classes.size(), std::vector<int>(classes.size(), 0));
    for (size_t j = 0; j < sets.size(); ++j) {
      if (j == i) continue;
      const auto c = answer_counts(*models[i], sets[j], classes, truncate_at, among);
      for (size_t t = 0; t < classes.size(); ++t)
        for (size_t a = 0; a < classes.size(); ++a) sum[t][a] += c[t][a];
    }
    out.push_back(answer_model(classes, sum));
  }
  return out;
}

Evaluation evaluate_vote(const std::vector<const model::OutcomeModel*>& models,
                         const std::vector<const HapticSequence*>& trials, double truncate_at,
                         std::vector<Vote>* per_trial, const ClassChoice& among, const std::vector<double>& weights) {
  Evaluation ev;
  ev.classes = committee_classes(models);
  ev.confusion.assign(ev.classes.size(), std::vector<int>(ev.classes.size(), 0));
  for (const auto* t : trials) {
    Vote v = t->label ? vote(models, *t, truncate_at, among, weights) : Vote{};
    if (!t->label || v.predicted < 0) {
      ++ev.skipped;
    } else {
      // A label no model has a class for is scored too: wrong, whatever the committee answers.
      const int truth = truth_row(ev, std::string(outcome_name(*t->label)));
      ev.confusion[truth][v.predicted]++;
      ev.total++;
      if (v.predicted == truth) ev.correct++;
    }
    if (per_trial) per_trial->push_back(std::move(v));
  }
  return ev;
}

int right_or_not(const TrialResult& r) {
  if (!r.trial || !r.trial->label || r.result.predicted < 0) return -1;
  return r.result.predicted == r.truth;
}

int right_or_not(const Vote& v, const HapticSequence& trial) {
  if (v.predicted < 0 || !trial.label) return -1;
  return v.classes[v.predicted] == outcome_name(*trial.label);
}

AccuracyInterval wilson_interval(int right, int n, double z) {
  if (n <= 0 || right < 0 || right > n) throw std::invalid_argument("wilson_interval: need 0 <= right <= n, n > 0");
  const double k = right, N = n, z2 = z * z;
  const double centre = (k + z2 / 2) / (N + z2);
  const double half = z * std::sqrt(k * (N - k) / N + z2 / 4) / (N + z2);
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

double mcnemar_exact_p(int only_first, int only_second) {
  if (only_first < 0 || only_second < 0) throw std::invalid_argument("mcnemar_exact_p: counts cannot be negative");
  const int n = only_first + only_second, m = std::min(only_first, only_second);
  if (n == 0) return 1.0;
  // sum_{i<=m} C(n, i) / 2^n in logs (lgamma), so that n in the thousands neither overflows nor
  // underflows term by term.
  double tail = 0;
  for (int i = 0; i <= m; ++i)
    tail += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) - n * std::log(2.0));
  return std::min(1.0, 2 * tail);
}

}  // namespace dressguard::hmm
