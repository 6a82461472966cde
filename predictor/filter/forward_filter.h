// The online forward filter the robot runs: one sample at a time, every class of one outcome model
// at once, posterior class probabilities after every sample (paper section V-B, classified online).
//
// For each class c with states j (Rabiner's scaled forward recursion, eq. 19-20 and 91-92):
//     pred_j   = sum_i alpha_{t-1}(i) A_ij            (alpha_0 = pi, so pred at t=1 is pi_j)
//     u_j      = pred_j * exp(log b_j(x_t) - m_t)     (m_t = max log b_j over states with pred_j > 0)
//     c_t      = sum_j u_j,   alpha_t(j) = u_j / c_t
//     log p(x_1..t | c) = sum_{s<=t} (log c_s + m_s)   (kept as sum m_s + log prod c_s, the product
//                                                     as mantissa and binary exponent: no log per sample)
// Shifting by m_t keeps c_t away from underflow however improbable the sample, so sequences of any
// length keep a finite log-likelihood. The posterior adds the model's log prior:
//     P(c | x_1..t) = exp(L_c + log_prior_c) / sum_k exp(L_k + log_prior_k).
// Left-right models have A_ij = 0 outside i <= j <= i+w: the filter finds the band width w at
// construction and sums only inside it, O(states * (w+1)) per class per sample (w <= 4); any other
// topology, or a wider band, takes the general O(states^2) sum. The emission update (Gaussian
// densities, exp, normalisation) runs four states at a time on CPUs with AVX2+FMA
// (emission_update.h), else portably.
//
// Real-time contract: the constructor allocates everything; reset() and step() allocate nothing,
// throw nothing, lock nothing and log nothing (tests/hmm/filter_alloc_test.cpp counts).
// Determinism: the same samples give the same bits on one machine. The AVX2 and the portable
// update differ in the last bits of exp (< 3e-16 relative), so two CPUs may differ in the last
// digits; both agree with hmm::forward_log_likelihood to 1e-9 relative (tests/hmm/filter_test.cpp).
#pragma once

#include <vector>

#include "dgm.h"
#include "emission_update.h"

namespace dressguard::filter {

class ForwardFilter {
 public:
  // Copies what it needs from `m` (which may then be destroyed). `m` must be valid (read_model
  // validates); throws model::ModelError otherwise.
  explicit ForwardFilter(const model::OutcomeModel& m);
  // Copyable and movable (a copy allocates; a copy carries the trial state along).

  // Start of a trial: alpha_0 = pi, log-likelihoods 0, posterior = prior.
  void reset() noexcept;
  // One raw sample in the rig's convention (drag negative, up positive), in newtons.
  void step(double f_motion, double f_lateral, double f_vertical) noexcept;
  // One sample already in feature units (FeatureConvention applied), for offline comparisons.
  void step_features(const double x[model::kFeatures]) noexcept;

  int classes() const noexcept { return n_classes_; }
  // P(class c | samples so far), including the model's log prior.
  double posterior(int c) const noexcept { return posterior_[c]; }
  // Running log p(x_1..t | class c) of the feature vectors; 0 before the first sample.
  // (Kept as sum of shifts + binary exponent + mantissa; this call takes the one log.)
  double log_likelihood(int c) const noexcept;
  // The normalised state probabilities alpha_t(j) of class c (n_states(c) entries).
  const double* state_probabilities(int c) const noexcept { return alpha_.data() + offset_[c]; }
  int n_states(int c) const noexcept { return n_states_[c]; }
  // Band width w of class c (A_ij = 0 unless i <= j <= i+w), or -1 when not left-right.
  int band(int c) const noexcept { return band_[c]; }
  // The class with the highest posterior (ties: the lower index).
  int best() const noexcept;
  // Samples taken (non-finite samples are skipped, not taken, and counted in rejected()).
  long samples() const noexcept { return samples_; }
  long rejected() const noexcept { return rejected_; }
  // True from the first sample after which no class has a finite log-likelihood, or whose
  // posteriors came out NaN, infinite or all zero, until reset():
  // the model cannot represent the trial (a sample some class rates at log density -inf, an
  // extreme model). The posteriors mean nothing then; the predictor stops on it (model_error)
  // rather than read them, since a NaN compares false against every threshold.
  bool failed() const noexcept { return failed_; }
  // True when the AVX2+FMA emission update runs (chosen once at construction from the CPU).
  bool vectorised() const noexcept;

 private:
  ClassBlock block(int c) const noexcept;
  // Constant after construction. Flat arrays: offset_[c] indexes class c's first state, each
  // class preceded by kBandPad zeros and padded to a multiple of 4 states (emission_update.h);
  // coef_ holds each class's band diagonals (or full matrix) from diag_offset_[c].
  model::FeatureConvention features_;
  int n_classes_ = 0;
  std::vector<int> n_states_, offset_, band_, diag_offset_;
  std::vector<double> log_prior_;
  std::vector<double> initial_;  // laid out like alpha_
  std::vector<double> coef_;
  // Emission j: mean, inverse covariance (p, q, r) = [[p q][q r]], constant -log(2 pi) - log|S|/2.
  std::vector<double> mean0_, mean1_, ip_, iq_, ir_, lconst_;
  ClassUpdateFn update_ = nullptr;
  Exp8Fn exp8_ = nullptr;
  // Mutable per-trial state.
  std::vector<double> alpha_, scratch_, logb_;
  // log p(x_1..t | c) = shift_sum_ + exp2_ ln 2 + log(mant_), mant_ in [0.5, 1): the product of
  // the normalisers c_t is kept as mantissa and exponent, so a sample costs no log.
  std::vector<double> shift_sum_, exp2_, mant_, score_, posterior_;
  long samples_ = 0, rejected_ = 0;
  bool failed_ = false;
};

}  // namespace dressguard::filter
