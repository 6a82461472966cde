// The online forward filter (see forward_filter.h for the recursion and the real-time contract).
#include "forward_filter.h"

#include <cmath>
#include <limits>

namespace dressguard::filter {

namespace {
constexpr double kLog2Pi = 1.8378770664093454835606594728112;  // log(2 pi)
}

ForwardFilter::ForwardFilter(const model::OutcomeModel& m) : features_(m.features) {
  model::validate_model(m, "ForwardFilter model");
  n_classes_ = static_cast<int>(m.classes.size());
  int total = 0, ttotal = 0;
  for (const auto& h : m.classes) {
    n_states_.push_back(h.n_states);
    offset_.push_back(total);
    toffset_.push_back(ttotal);
    log_prior_.push_back(h.log_prior);
    total += h.n_states;
    ttotal += h.n_states * h.n_states;
    // Band width: the largest j - i with A_ij > 0; -1 when some A_ij > 0 has j < i.
    int w = 0;
    const int n = h.n_states;
    for (int i = 0; i < n && w >= 0; ++i)
      for (int j = 0; j < n; ++j) {
        if (h.transition[i * n + j] <= 0.0) continue;
        if (j < i) { w = -1; break; }
        if (j - i > w) w = j - i;
      }
    band_.push_back(w);
    initial_.insert(initial_.end(), h.initial.begin(), h.initial.end());
    transition_.insert(transition_.end(), h.transition.begin(), h.transition.end());
    for (const auto& e : h.emission) {
      // S^-1 of [[a b][b d]] is [[d -b][-b a]] / det; log N = -log(2 pi) - log(det)/2 - q/2.
      const double a = e.cov[0][0], b = 0.5 * (e.cov[0][1] + e.cov[1][0]), d = e.cov[1][1];
      const double det = a * d - b * b;
      mean0_.push_back(e.mean[0]);
      mean1_.push_back(e.mean[1]);
      ip_.push_back(d / det);
      iq_.push_back(-b / det);
      ir_.push_back(a / det);
      lconst_.push_back(-kLog2Pi - 0.5 * std::log(det));
    }
  }
  alpha_.assign(total, 0.0);
  scratch_.assign(total, 0.0);
  logb_.assign(total, 0.0);
  loglik_.assign(n_classes_, 0.0);
  posterior_.assign(n_classes_, 0.0);
  reset();
}

void ForwardFilter::reset() noexcept {
  for (int c = 0; c < n_classes_; ++c) {
    loglik_[c] = 0.0;
    posterior_[c] = std::exp(log_prior_[c]);
  }
  for (size_t k = 0; k < alpha_.size(); ++k) alpha_[k] = initial_[k];
  samples_ = 0;
  rejected_ = 0;
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
    const int n = n_states_[c], o = offset_[c], w = band_[c];
    const double* A = transition_.data() + toffset_[c];
    double* alpha = alpha_.data() + o;
    double* pred = scratch_.data() + o;
    double* logb = logb_.data() + o;
    // Predict: pred_j = sum_i alpha_i A_ij, inside the band i in [j-w, j] when left-right.
    if (first) {
      for (int j = 0; j < n; ++j) pred[j] = alpha[j];  // alpha_0 = pi
    } else if (w >= 0) {
      for (int j = 0; j < n; ++j) {
        double s = 0.0;
        const int i0 = j - w > 0 ? j - w : 0;
        for (int i = i0; i <= j; ++i) s += alpha[i] * A[i * n + j];
        pred[j] = s;
      }
    } else {
      for (int j = 0; j < n; ++j) {
        double s = 0.0;
        for (int i = 0; i < n; ++i) s += alpha[i] * A[i * n + j];
        pred[j] = s;
      }
    }
    // Emission log densities and their maximum m over reachable states.
    double m = -std::numeric_limits<double>::infinity();
    for (int j = 0; j < n; ++j) {
      const int k = o + j;
      const double d0 = x[0] - mean0_[k], d1 = x[1] - mean1_[k];
      const double q = ip_[k] * d0 * d0 + 2.0 * iq_[k] * d0 * d1 + ir_[k] * d1 * d1;
      logb[j] = lconst_[k] - 0.5 * q;
      if (pred[j] > 0.0 && logb[j] > m) m = logb[j];
    }
    // Update and normalise: alpha_j = pred_j exp(logb_j - m) / c.
    double csum = 0.0;
    for (int j = 0; j < n; ++j) {
      const double u = pred[j] > 0.0 ? pred[j] * std::exp(logb[j] - m) : 0.0;
      alpha[j] = u;
      csum += u;
    }
    const double inv = 1.0 / csum;
    for (int j = 0; j < n; ++j) alpha[j] *= inv;
    loglik_[c] += std::log(csum) + m;
    const double score = loglik_[c] + log_prior_[c];
    if (score > best_score) best_score = score;
  }
  // Posterior: softmax of L_c + log prior_c, shifted by the maximum.
  double z = 0.0;
  for (int c = 0; c < n_classes_; ++c) {
    posterior_[c] = std::exp(loglik_[c] + log_prior_[c] - best_score);
    z += posterior_[c];
  }
  const double iz = 1.0 / z;
  for (int c = 0; c < n_classes_; ++c) posterior_[c] *= iz;
  ++samples_;
}

int ForwardFilter::best() const noexcept {
  int b = 0;
  for (int c = 1; c < n_classes_; ++c)
    if (posterior_[c] > posterior_[b]) b = c;
  return b;
}

}  // namespace dressguard::filter
