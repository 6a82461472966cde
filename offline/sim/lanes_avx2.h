// The AVX2 kernels' lane helpers (solver_avx2.cpp): four 32-byte vertices (model.h, V3) moved
// into x, y, z lanes and back, and the per-lane arithmetic in the order of model.h's operators.
// Internal to dg_sim and its benchmarks (tools/bench/bench_sim_kernels.cpp times load4 and store4
// alone). x86-64 only; every function carries the avx2 target attribute, so a caller must check
// cpu_has_avx2() (model.h) before calling into code that uses them.
#pragma once

#if defined(__x86_64__)
#include <immintrin.h>

#include <cstdint>

#include "model.h"

#define DG_AVX2 __attribute__((target("avx2")))

namespace dressguard::sim::lanes {

// Four vertices as x, y, z lanes.
struct Lanes3 {
  __m256d x, y, z;
};

// Loads vertices idx[0..3] and transposes them into lanes. Each vertex is read as two 16-byte
// halves, (x, y) and (z, pad), the upper register half by a memory-source insert: that takes 3
// shuffles (the one port that shuffles is what limits these kernels) instead of the 7 of a
// full 4 x 4 transpose of 32-byte loads. The stores below write the same halves, so a vertex
// stored by one colour group is forwarded to the next group's loads.
DG_AVX2 inline Lanes3 load4(const V3* x, const int32_t* idx) {
  const V3 &a = x[idx[0]], &b = x[idx[1]], &c = x[idx[2]], &d = x[idx[3]];
  const __m256d ac_xy = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_load_pd(&a.x)), _mm_load_pd(&c.x), 1);
  const __m256d bd_xy = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_load_pd(&b.x)), _mm_load_pd(&d.x), 1);
  const __m256d ac_zp = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_load_pd(&a.z)), _mm_load_pd(&c.z), 1);
  const __m256d bd_zp = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_load_pd(&b.z)), _mm_load_pd(&d.z), 1);
  return {_mm256_unpacklo_pd(ac_xy, bd_xy), _mm256_unpackhi_pd(ac_xy, bd_xy), _mm256_unpacklo_pd(ac_zp, bd_zp)};
}

// The inverse of load4(); the pad of each vertex is written as 0. Only the first `count` lanes
// are stored (a careful block's empty lanes compute on a copy of lane 0 and are dropped).
DG_AVX2 inline void store4(V3* x, const int32_t idx[4], Lanes3 v, int count) {
  const __m256d zero = _mm256_setzero_pd();
  const __m256d ac_xy = _mm256_unpacklo_pd(v.x, v.y);   // ax ay cx cy
  const __m256d bd_xy = _mm256_unpackhi_pd(v.x, v.y);   // bx by dx dy
  const __m256d ac_zp = _mm256_unpacklo_pd(v.z, zero);  // az 0  cz 0
  const __m256d bd_zp = _mm256_unpackhi_pd(v.z, zero);  // bz 0  dz 0
  V3 &a = x[idx[0]], &b = x[idx[1]], &c = x[idx[2]], &d = x[idx[3]];
  _mm_store_pd(&a.x, _mm256_castpd256_pd128(ac_xy));
  _mm_store_pd(&a.z, _mm256_castpd256_pd128(ac_zp));
  if (count > 1) {
    _mm_store_pd(&b.x, _mm256_castpd256_pd128(bd_xy));
    _mm_store_pd(&b.z, _mm256_castpd256_pd128(bd_zp));
  }
  if (count > 2) {
    _mm_store_pd(&c.x, _mm256_extractf128_pd(ac_xy, 1));
    _mm_store_pd(&c.z, _mm256_extractf128_pd(ac_zp, 1));
  }
  if (count > 3) {
    _mm_store_pd(&d.x, _mm256_extractf128_pd(bd_xy, 1));
    _mm_store_pd(&d.z, _mm256_extractf128_pd(bd_zp, 1));
  }
}

DG_AVX2 inline __m256d add(__m256d a, __m256d b) { return _mm256_add_pd(a, b); }
DG_AVX2 inline __m256d sub(__m256d a, __m256d b) { return _mm256_sub_pd(a, b); }
DG_AVX2 inline __m256d mul(__m256d a, __m256d b) { return _mm256_mul_pd(a, b); }
// (a.x b.x + a.y b.y) + a.z b.z, the order of dot() in model.h.
DG_AVX2 inline __m256d dot3(const Lanes3& a, const Lanes3& b) {
  return add(add(mul(a.x, b.x), mul(a.y, b.y)), mul(a.z, b.z));
}
// s a, per lane (operator*(double, V3)).
DG_AVX2 inline Lanes3 scale(__m256d s, const Lanes3& a) { return {mul(s, a.x), mul(s, a.y), mul(s, a.z)}; }
DG_AVX2 inline Lanes3 add3(const Lanes3& a, const Lanes3& b) { return {add(a.x, b.x), add(a.y, b.y), add(a.z, b.z)}; }
DG_AVX2 inline Lanes3 sub3(const Lanes3& a, const Lanes3& b) { return {sub(a.x, b.x), sub(a.y, b.y), sub(a.z, b.z)}; }
DG_AVX2 inline Lanes3 and3(const Lanes3& a, __m256d m) {
  return {_mm256_and_pd(a.x, m), _mm256_and_pd(a.y, m), _mm256_and_pd(a.z, m)};
}

}  // namespace dressguard::sim::lanes

#endif  // __x86_64__
