// The online forward filter (see forward_filter.h for the recursion and the real-time contract).
#include "forward_filter.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace dressguard::filter {

namespace {
constexpr double kLn2 = 0.69314718055994530941723212145818;
int padded(int n) { return (n + 3) & ~3; }

// v = mant 2^k with mant in [0.5, 1): returns mant and adds k to `e` (v normal and > 0, which the
// product of normalisers c_t stays since it is renormalised every sample). frexp without a call.
double split_exponent(double v, double& e) noexcept {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  const int k = static_cast<int>((bits >> 52) & 0x7FF) - 1022;
  bits = (bits & ~(uint64_t{0x7FF} << 52)) | (uint64_t{1022} << 52);
  std::memcpy(&v, &bits, sizeof v);
  e += k;
  return v;
}
}  // namespace

ForwardFilter::ForwardFilter(const model::OutcomeModel& m) : features_(m.features) {
  model::validate_model(m, "ForwardFilter model");
  n_classes_ = static_cast<int>(m.classes.size());
  int total = 0;
  for (const auto& h : m.classes) {
    const int n = h.n_states, np = padded(n);
    total += kBandPad;  // zeros before the class's first state: alpha_{j-d} for j < d
    n_states_.push_back(n);
    offset_.push_back(total);
    log_prior_.push_back(h.log_prior);
    // Band width: the largest j - i with A_ij > 0; -1 when some A_ij > 0 has j < i.
    int w = 0;
    for (int i = 0; i < n && w >= 0; ++i)
      for (int j = 0; j < n; ++j) {
        if (h.transition[i * n + j] <= 0.0) continue;
        if (j < i) {
          w = -1;
          break;
        }
        if (j - i > w) w = j - i;
      }
    band_.push_back(w);
    // Band diagonals B_d[j] = A_{j-d,j} (the band path), or the full matrix (the general path).
    diag_offset_.push_back(static_cast<int>(coef_.size()));
    if (w >= 0 && w <= kMaxBand) {
      for (int d = 0; d <= w; ++d)
        for (int j = 0; j < np; ++j) coef_.push_back(j < n && j - d >= 0 ? h.transition[(j - d) * n + j] : 0.0);
    } else {
      coef_.insert(coef_.end(), h.transition.begin(), h.transition.end());
    }
    initial_.resize(total, 0.0);
    initial_.insert(initial_.end(), h.initial.begin(), h.initial.end());
    initial_.resize(total + np, 0.0);  // padding states: never reachable
    for (int j = 0; j < kBandPad; ++j) {
      mean0_.push_back(0.0), mean1_.push_back(0.0), ip_.push_back(1.0), iq_.push_back(0.0), ir_.push_back(1.0);
      lconst_.push_back(0.0);
    }
    for (int j = 0; j < np; ++j) {
      // S^-1 of [[a b][b d]] is [[d -b][-b a]] / det; log N = -log(2 pi) - log(det)/2 - q/2.
      // Padding states get the unit Gaussian: finite values that are multiplied by pred = 0.
      model::GaussianEmission e;
      if (j < n) e = h.emission[j];
      const model::EmissionTerms t = model::emission_terms(e);
      mean0_.push_back(t.mean0);
      mean1_.push_back(t.mean1);
      ip_.push_back(t.ip);
      iq_.push_back(t.iq);
      ir_.push_back(t.ir);
      lconst_.push_back(t.lconst);
    }
    total += np;
  }
  alpha_.assign(total, 0.0);
  scratch_.assign(total, 0.0);
  logb_.assign(total, 0.0);
  shift_sum_.assign(n_classes_, 0.0);
  exp2_.assign(n_classes_, 0.0);
  mant_.assign(n_classes_, 1.0);
  score_.assign(n_classes_, 0.0);
  posterior_.assign(n_classes_, 0.0);
  update_ = class_update_avx2();
  if (!update_) update_ = class_update_portable;
  exp8_ = exp8_avx2();
  if (!exp8_) exp8_ = exp8_portable;
  reset();
}

// The constant arrays of class c as the update reads them. Built per step from offsets (a few
// additions) rather than stored as pointers, so that copies and moves of a filter stay valid.
ClassBlock ForwardFilter::block(int c) const noexcept {
  ClassBlock b;
  const int o = offset_[c], np = padded(n_states_[c]);
  b.n_padded = np;
  b.band = band_[c] <= kMaxBand ? band_[c] : -1;
  if (b.band >= 0)
    for (int d = 0; d <= b.band; ++d) b.diag[d] = coef_.data() + diag_offset_[c] + d * np;
  b.m0 = mean0_.data() + o;
  b.m1 = mean1_.data() + o;
  b.ip = ip_.data() + o;
  b.iq = iq_.data() + o;
  b.ir = ir_.data() + o;
  b.lc = lconst_.data() + o;
  return b;
}

bool ForwardFilter::vectorised() const noexcept { return update_ != class_update_portable; }

void ForwardFilter::reset() noexcept {
  for (int c = 0; c < n_classes_; ++c) {
    shift_sum_[c] = 0.0;
    exp2_[c] = 0.0;
    mant_[c] = 1.0;
    posterior_[c] = std::exp(log_prior_[c]);
  }
  for (size_t k = 0; k < alpha_.size(); ++k) alpha_[k] = initial_[k];
  samples_ = 0;
  rejected_ = 0;
  failed_ = false;
}

void ForwardFilter::step(double f_motion, double f_lateral, double f_vertical) noexcept {
  double x[model::kFeatures];
  features_.apply(f_motion, f_lateral, f_vertical, x);
  step_features(x);
}

void ForwardFilter::step_features(const double x[model::kFeatures]) noexcept {
  // A non-finite sample (a sensor glitch) would poison every class at once: skip it, count it.
  if (!std::isfinite(x[0]) || !std::isfinite(x[1])) {
    ++rejected_;
    return;
  }
  const bool first = samples_ == 0;
  double best_score = -std::numeric_limits<double>::infinity();
  for (int c = 0; c < n_classes_; ++c) {
    const ClassBlock b = block(c);
    const int n = n_states_[c], o = offset_[c];
    double* alpha = alpha_.data() + o;
    double* pred = scratch_.data() + o;
    // The first sample predicts pi (alpha holds pi after reset); a general topology predicts
    // with the full matrix here, O(n^2); a left-right band is predicted inside the update.
    bool given = first;
    if (first) {
      for (int j = 0; j < n; ++j) pred[j] = alpha[j];
    } else if (b.band < 0) {
      const double* A = coef_.data() + diag_offset_[c];
      for (int j = 0; j < n; ++j) {
        double s = 0.0;
        for (int i = 0; i < n; ++i) s += alpha[i] * A[i * n + j];
        pred[j] = s;
      }
      given = true;
    }
    double m = 0.0;
    const double cs = update_(b, given, x[0], x[1], alpha, pred, logb_.data() + o, &m, nullptr);
    // L_c = M_c + E_c ln 2 + log(mant_c): sum the shifts m, multiply the normalisers into the
    // mantissa and move its binary exponent into E_c (bit operations, no log per sample).
    shift_sum_[c] += m;
    mant_[c] = split_exponent(mant_[c] * cs, exp2_[c]);
    const double score = shift_sum_[c] + exp2_[c] * kLn2 + log_prior_[c];
    score_[c] = score;
    if (score > best_score) best_score = score;
  }
  // Posterior: P_c proportional to exp(L_c + log prior_c - best) = exp(score_c - best) mant_c,
  // with mant_c in [0.5, 1): no overflow, and the best class contributes at least 0.5.
  double arg[model::kMaxClasses], e[model::kMaxClasses];
  for (int c = 0; c < model::kMaxClasses; ++c) arg[c] = c < n_classes_ ? score_[c] - best_score : -1000.0;
  exp8_(arg, e);
  double z = 0.0;
  for (int c = 0; c < n_classes_; ++c) {
    posterior_[c] = e[c] * mant_[c];
    z += posterior_[c];
  }
  // NaN fails both comparisons; a best score of -inf means no class can explain the samples.
  if (!(z > 0.0 && z <= std::numeric_limits<double>::max()) || !std::isfinite(best_score)) failed_ = true;
  const double iz = 1.0 / z;
  for (int c = 0; c < n_classes_; ++c) posterior_[c] *= iz;
  ++samples_;
}

double ForwardFilter::log_likelihood(int c) const noexcept {
  return shift_sum_[c] + exp2_[c] * kLn2 + std::log(mant_[c]);
}

int ForwardFilter::best() const noexcept {
  int b = 0;
  for (int c = 1; c < n_classes_; ++c)
    if (posterior_[c] > posterior_[b]) b = c;
  return b;
}

}  // namespace dressguard::filter
