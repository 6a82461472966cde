// The per-class step of the forward filter, the one place the filter spends its time:
//     pred_j  = sum_{d=0..w} B_d[j] alpha_{j-d}        (B_d[j] = A_{j-d,j}: the left-right band)
//     logb_j  = lc_j - q_j / 2,   q_j = (x - mu_j)^T S_j^-1 (x - mu_j)     (Gaussian log density)
//     pred_j  = 0 where pred_j < kFlushBelow          (written back into pred)
//     m       = max { logb_j : pred_j > 0 }
//     alpha_j = pred_j exp(logb_j - m) / c,   c = sum_j pred_j exp(logb_j - m)   (0 below kFlushBelow)
// returning c and m: the sample's log-likelihood increment is log c + m (see forward_filter.h).
//
// Two implementations with one contract: a portable one with std::exp, and one for x86-64 CPUs
// with AVX2 and FMA that does four states at a time with an inline exp (~1 ulp). ForwardFilter
// picks one at construction (a CPU check once, never per sample).
// Layout: each class's arrays hold a multiple of 4 states; padding states have B_d = 0 and pred
// = 0 and contribute nothing. alpha has kBandPad zeros before each class's first state, so
// alpha_{j-d} reads 0 for j < d without a branch.
#pragma once

namespace dressguard::filter {

// Normalised state probabilities below this are set to 0. Without it the states a left-right
// model has left behind decay through the subnormal range, where every multiplication costs ~100
// cycles. hmm::forward_log_likelihood flushes alike, so the two agree; a state this improbable
// (< 1e-300) never matters to a classification.
// Predictions below it are flushed too, and that bounds the normaliser: the state that attains m
// has pred >= kFlushBelow and exp(0) = 1, so c >= 1e-300, and 1/c and the filter's running
// product of the c stay normal numbers. Without it a tiny transition (a trained band can hold
// 1e-258) times a small alpha gives a subnormal prediction; when that state alone explains the
// sample, c is subnormal, 1/c overflows and the posteriors turn NaN.
inline constexpr double kFlushBelow = 1e-300;
// Widest band the band path takes (w <= kMaxBand); wider or non-left-right models take the
// general O(n^2) prediction, done by the caller.
inline constexpr int kMaxBand = 4, kBandPad = 4;

// Constant per-class parameters, structure-of-arrays, n_padded entries each.
struct ClassBlock {
  int n_padded = 0;
  int band = 0;                          // w, or -1: pred is computed by the caller
  const double* diag[kMaxBand + 1] = {}; // B_d[j] = A_{j-d,j}, d = 0..w
  const double* m0 = nullptr;            // mean, feature 0
  const double* m1 = nullptr;            // mean, feature 1
  const double* ip = nullptr;            // inverse covariance [[ip iq][iq ir]]
  const double* iq = nullptr;
  const double* ir = nullptr;
  const double* lc = nullptr;            // -log(2 pi) - log|S| / 2
};

// `pred_given`: pred already holds the prediction (first sample, or a general topology);
// otherwise it is computed from alpha by the band. Returns c (> 0) and writes m to *m_out.
// e_out (may be null; offline training uses it): exp(logb_j - m) for reachable states, else 0.
using ClassUpdateFn = double (*)(const ClassBlock& b, bool pred_given, double x0, double x1, double* alpha, double* pred,
                                 double* logb, double* m_out, double* e_out) noexcept;

double class_update_portable(const ClassBlock& b, bool pred_given, double x0, double x1, double* alpha, double* pred,
                             double* logb, double* m_out, double* e_out) noexcept;
// The best update this CPU has (AVX2 when available, else portable).
ClassUpdateFn class_update_best();
// nullptr when the CPU (or the compiler) lacks AVX2 + FMA.
ClassUpdateFn class_update_avx2();

// out[k] = exp(x[k]) for k < 8, every x[k] <= 0 (values below -708 give 0): the posterior's
// softmax over up to kMaxClasses = 8 classes in one call.
using Exp8Fn = void (*)(const double* x, double* out) noexcept;
void exp8_portable(const double* x, double* out) noexcept;
Exp8Fn exp8_avx2();  // nullptr without AVX2 + FMA

// out[k] = exp(x[k]) for k < n, n a multiple of 4, every x[k] <= 0 (below -708: 0), with the
// best implementation this CPU has (chosen once). For offline loops (hmm training); the filter
// itself binds its functions at construction.
void exp_nonpositive_batch(const double* x, double* out, int n) noexcept;

}  // namespace dressguard::filter
