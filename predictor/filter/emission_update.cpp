#include "emission_update.h"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define DG_HAVE_AVX2_PATH 1
#endif

namespace dressguard::filter {

double class_update_portable(const ClassBlock& b, bool pred_given, double x0, double x1, double* alpha, double* pred,
                             double* logb, double* m_out, double* e_out) noexcept {
  const int n = b.n_padded;
  if (!pred_given) {
    for (int j = 0; j < n; ++j) {
      double s = 0.0;
      for (int d = 0; d <= b.band; ++d) s += b.diag[d][j] * alpha[j - d];
      pred[j] = s;
    }
  }
  double m = -std::numeric_limits<double>::infinity();
  for (int j = 0; j < n; ++j) {
    if (pred[j] < kFlushBelow) pred[j] = 0.0;  // see emission_update.h: c >= kFlushBelow
    const double d0 = x0 - b.m0[j], d1 = x1 - b.m1[j];
    logb[j] = b.lc[j] - 0.5 * (b.ip[j] * d0 * d0 + 2.0 * b.iq[j] * d0 * d1 + b.ir[j] * d1 * d1);
    if (pred[j] > 0.0 && logb[j] > m) m = logb[j];
  }
  double c = 0.0;
  for (int j = 0; j < n; ++j) {
    // Unreachable states (pred 0) may have logb_j > m: clamp so exp stays finite, product 0.
    const double a = std::min(logb[j] - m, 0.0);
    const double e = pred[j] > 0.0 && a >= -708.0 ? std::exp(a) : 0.0;
    const double u = pred[j] * e;
    if (e_out) e_out[j] = e;
    alpha[j] = u;
    c += u;
  }
  const double inv = 1.0 / c;
  for (int j = 0; j < n; ++j) {
    const double a = alpha[j] * inv;
    alpha[j] = a < kFlushBelow ? 0.0 : a;
  }
  *m_out = m;
  return c;
}

#ifdef DG_HAVE_AVX2_PATH
namespace {

// exp(x) for four x <= 0 (x > 0 is clamped to 0; x < -708, where exp would be subnormal, gives 0):
// x = k ln2 + r with ln2 split in a high part (exact k ln2_hi) and a low part (Cody-Waite),
// |r| <= ln2/2; e^r by its Taylor series to degree 13 (remainder < 0.347^14/14! = 4e-18 relative)
// in Estrin's scheme (a chain 5 FMAs deep instead of Horner's 13); times 2^k built in the exponent
// bits. Measured against std::exp over [-708, 0]: within 2.3e-16 relative.
__attribute__((target("avx2,fma"))) inline __m256d exp4_nonpositive(__m256d x) {
  const __m256d lo = _mm256_set1_pd(-708.0);
  const __m256d underflow = _mm256_cmp_pd(x, lo, _CMP_LT_OQ);
  x = _mm256_max_pd(_mm256_min_pd(x, _mm256_setzero_pd()), lo);
  const __m256d shift = _mm256_set1_pd(0x1.8p52);  // adding it rounds to an integer in the low bits
  const __m256d kd_shifted = _mm256_fmadd_pd(x, _mm256_set1_pd(1.4426950408889634074), shift);
  const __m256d kd = _mm256_sub_pd(kd_shifted, shift);
  __m256d r = _mm256_fnmadd_pd(kd, _mm256_set1_pd(6.93147180369123816490e-01), x);  // ln2 high part
  r = _mm256_fnmadd_pd(kd, _mm256_set1_pd(1.90821492927058770002e-10), r);           // ln2 low part
#define C(v) _mm256_set1_pd(v)
  const __m256d r2 = _mm256_mul_pd(r, r), r4 = _mm256_mul_pd(r2, r2), r8 = _mm256_mul_pd(r4, r4);
  const __m256d q0 = _mm256_fmadd_pd(r, C(1.0), C(1.0));
  const __m256d q1 = _mm256_fmadd_pd(r, C(1.0 / 6), C(0.5));
  const __m256d q2 = _mm256_fmadd_pd(r, C(1.0 / 120), C(1.0 / 24));
  const __m256d q3 = _mm256_fmadd_pd(r, C(1.0 / 5040), C(1.0 / 720));
  const __m256d q4 = _mm256_fmadd_pd(r, C(1.0 / 362880), C(1.0 / 40320));
  const __m256d q5 = _mm256_fmadd_pd(r, C(1.0 / 39916800), C(1.0 / 3628800));
  const __m256d q6 = _mm256_fmadd_pd(r, C(1.0 / 6227020800), C(1.0 / 479001600));
#undef C
  const __m256d s0 = _mm256_fmadd_pd(q1, r2, q0), s1 = _mm256_fmadd_pd(q3, r2, q2), s2 = _mm256_fmadd_pd(q5, r2, q4);
  const __m256d t0 = _mm256_fmadd_pd(s1, r4, s0), t1 = _mm256_fmadd_pd(q6, r4, s2);
  const __m256d p = _mm256_fmadd_pd(t1, r8, t0);
  // kd_shifted's bits are 0x4338...0 + k (two's complement in the mantissa); (bits + 1023) << 52
  // leaves exactly (k + 1023) << 52, the double 2^k.
  const __m256i bits = _mm256_castpd_si256(kd_shifted);
  const __m256i scale = _mm256_slli_epi64(_mm256_add_epi64(bits, _mm256_set1_epi64x(1023)), 52);
  return _mm256_andnot_pd(underflow, _mm256_mul_pd(p, _mm256_castsi256_pd(scale)));
}

// alpha_{j+k-d} for lanes k = 0..3, from the aligned blocks prev = alpha[j-4..j-1] and cur =
// alpha[j..j+3]: permutes and a blend instead of an unaligned load, which would straddle two
// recent vector stores and stall on store-to-load forwarding (measured 3x slower in training).
__attribute__((target("avx2,fma"))) inline __m256d shifted(__m256d prev, __m256d cur, int d) {
  switch (d) {
    case 1:
      return _mm256_blend_pd(_mm256_permute4x64_pd(cur, 0x90), _mm256_permute4x64_pd(prev, 0xFF), 0x1);  // [p3 c0 c1 c2]
    case 2:
      return _mm256_blend_pd(_mm256_permute4x64_pd(cur, 0x40), _mm256_permute4x64_pd(prev, 0x0E), 0x3);  // [p2 p3 c0 c1]
    case 3:
      return _mm256_blend_pd(_mm256_permute4x64_pd(cur, 0x00), _mm256_permute4x64_pd(prev, 0x39), 0x7);  // [p1 p2 p3 c0]
    default:
      return prev;  // d = 4
  }
}

__attribute__((target("avx2,fma"))) double class_update_avx2_impl(const ClassBlock& b, bool pred_given, double x0,
                                                                  double x1, double* alpha, double* pred,
                                                                  double* logb, double* m_out, double* e_out) noexcept {
  const int n = b.n_padded;
  const __m256d vx0 = _mm256_set1_pd(x0), vx1 = _mm256_set1_pd(x1), half = _mm256_set1_pd(0.5),
                two = _mm256_set1_pd(2.0), zero = _mm256_setzero_pd(),
                ninf = _mm256_set1_pd(-std::numeric_limits<double>::infinity()),
                flush = _mm256_set1_pd(kFlushBelow);
  __m256d vmax = ninf;
  // Pass 1: prediction along the band (reads of alpha_{j-d} below 0 hit the zero pad), log
  // densities, and their maximum over reachable states. pred is written to its own buffer
  // first because pass 2 overwrites alpha.
  for (int j = 0; j < n; j += 4) {
    __m256d pr;
    if (pred_given) {
      pr = _mm256_loadu_pd(pred + j);
    } else {
      const __m256d cur = _mm256_loadu_pd(alpha + j), prev = _mm256_loadu_pd(alpha + j - 4);
      pr = _mm256_mul_pd(_mm256_loadu_pd(b.diag[0] + j), cur);
      for (int d = 1; d <= b.band; ++d) pr = _mm256_fmadd_pd(_mm256_loadu_pd(b.diag[d] + j), shifted(prev, cur, d), pr);
    }
    pr = _mm256_and_pd(pr, _mm256_cmp_pd(pr, flush, _CMP_GE_OQ));  // see emission_update.h
    _mm256_storeu_pd(pred + j, pr);
    const __m256d d0 = _mm256_sub_pd(vx0, _mm256_loadu_pd(b.m0 + j));
    const __m256d d1 = _mm256_sub_pd(vx1, _mm256_loadu_pd(b.m1 + j));
    __m256d q = _mm256_mul_pd(_mm256_mul_pd(_mm256_loadu_pd(b.ip + j), d0), d0);
    q = _mm256_fmadd_pd(_mm256_mul_pd(two, _mm256_loadu_pd(b.iq + j)), _mm256_mul_pd(d0, d1), q);
    q = _mm256_fmadd_pd(_mm256_mul_pd(_mm256_loadu_pd(b.ir + j), d1), d1, q);
    const __m256d lb = _mm256_fnmadd_pd(half, q, _mm256_loadu_pd(b.lc + j));
    _mm256_storeu_pd(logb + j, lb);
    vmax = _mm256_max_pd(vmax, _mm256_blendv_pd(ninf, lb, _mm256_cmp_pd(pr, zero, _CMP_GT_OQ)));
  }
  alignas(32) double mx[4];
  _mm256_store_pd(mx, vmax);
  const double m = std::max(std::max(mx[0], mx[1]), std::max(mx[2], mx[3]));
  const __m256d vm = _mm256_set1_pd(m);
  // Pass 2: u_j = pred_j exp(logb_j - m), their sum c.
  __m256d vc = zero;
  for (int j = 0; j < n; j += 4) {
    const __m256d pr = _mm256_loadu_pd(pred + j);
    const __m256d e = exp4_nonpositive(_mm256_sub_pd(_mm256_loadu_pd(logb + j), vm));
    const __m256d u = _mm256_mul_pd(pr, e);
    if (e_out) _mm256_storeu_pd(e_out + j, _mm256_and_pd(e, _mm256_cmp_pd(pr, zero, _CMP_GT_OQ)));
    _mm256_storeu_pd(alpha + j, u);
    vc = _mm256_add_pd(vc, u);
  }
  alignas(32) double cs[4];
  _mm256_store_pd(cs, vc);
  const double c = (cs[0] + cs[1]) + (cs[2] + cs[3]);
  // Pass 3: normalise, flushing probabilities below kFlushBelow to 0.
  const __m256d inv = _mm256_set1_pd(1.0 / c);
  for (int j = 0; j < n; j += 4) {
    const __m256d a = _mm256_mul_pd(_mm256_loadu_pd(alpha + j), inv);
    _mm256_storeu_pd(alpha + j, _mm256_and_pd(a, _mm256_cmp_pd(a, flush, _CMP_GE_OQ)));
  }
  *m_out = m;
  return c;
}

__attribute__((target("avx2,fma"))) void exp8_avx2_impl(const double* x, double* out) noexcept {
  _mm256_storeu_pd(out, exp4_nonpositive(_mm256_loadu_pd(x)));
  _mm256_storeu_pd(out + 4, exp4_nonpositive(_mm256_loadu_pd(x + 4)));
}

__attribute__((target("avx2,fma"))) void exp_batch_avx2(const double* x, double* out, int n) noexcept {
  for (int k = 0; k < n; k += 4) _mm256_storeu_pd(out + k, exp4_nonpositive(_mm256_loadu_pd(x + k)));
}

}  // namespace
#endif

namespace {
void exp_batch_portable(const double* x, double* out, int n) noexcept {
  for (int k = 0; k < n; ++k) out[k] = x[k] < -708.0 ? 0.0 : std::exp(std::min(x[k], 0.0));
}
using ExpBatchFn = void (*)(const double*, double*, int) noexcept;
ExpBatchFn choose_exp_batch() {
#ifdef DG_HAVE_AVX2_PATH
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return exp_batch_avx2;
#endif
  return exp_batch_portable;
}
// Chosen during static initialisation, before main: no guard on the call path.
const ExpBatchFn g_exp_batch = choose_exp_batch();
}  // namespace

void exp_nonpositive_batch(const double* x, double* out, int n) noexcept { g_exp_batch(x, out, n); }

void exp8_portable(const double* x, double* out) noexcept {
  for (int k = 0; k < 8; ++k) out[k] = x[k] < -708.0 ? 0.0 : std::exp(std::min(x[k], 0.0));
}

Exp8Fn exp8_avx2() {
#ifdef DG_HAVE_AVX2_PATH
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return exp8_avx2_impl;
#endif
  return nullptr;
}

ClassUpdateFn class_update_best() {
  const ClassUpdateFn f = class_update_avx2();
  return f ? f : class_update_portable;
}

ClassUpdateFn class_update_avx2() {
#ifdef DG_HAVE_AVX2_PATH
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return class_update_avx2_impl;
#endif
  return nullptr;
}

}  // namespace dressguard::filter
