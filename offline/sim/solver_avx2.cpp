// The AVX2 kernels (kernels.h). Stretch and shear solve the 4 constraints of a block at once, one
// lane each (vertices transposed into x, y, z lanes); bending, linear in x, solves them one after
// another with one register per vertex (x, y, z, pad), as does the integration. They mirror the
// scalar functions of constraints.h and solver.cpp operation for operation (same order, no FMA),
// so each result has the same bits as the scalar function's. The 4 constraints of a block share
// no vertex (one colour group, checked by make_model), so solving them together equals solving
// them one after another.
//
// Compiled for every x86-64 (function-level target attributes, no -mavx2 for the file): the
// inline helpers of the headers used here are inlined into the AVX2 functions, and nothing with
// AVX2 instructions can leak into the scalar code. The caller checks cpu_has_avx2() first.
#include "kernels.h"

#if defined(__x86_64__)
#include "lanes_avx2.h"

namespace dressguard::sim {
namespace {

using namespace lanes;

// A careful block's lanes: their number, and the indices with each empty lane (-1) set to lane
// 0's, so that it loads real vertices (its weights are 0; its result is not stored).
inline int lanes_of(const int32_t in[4], int32_t out[4]) {
  int count = 0;
  for (int l = 0; l < 4; ++l) {
    count += in[l] >= 0;
    out[l] = in[l] >= 0 ? in[l] : in[0];
  }
  return count;
}

// Lanes of a register, for the per-lane force sums.
struct Spill {
  alignas(32) double v[4];
};
DG_AVX2 inline Spill spill(__m256d a) {
  Spill s;
  _mm256_store_pd(s.v, a);
  return s;
}
DG_AVX2 inline V3 lane(const Spill& x, const Spill& y, const Spill& z, int l) { return {x.v[l], y.v[l], z.v[l]}; }

// distance_constraint() over 4 lanes. A degenerate lane (|d| < 1e-12) gets n = 0 and dl = 0,
// so its vertices are stored unchanged.
template <bool careful>
DG_AVX2 void stretch_kernel(const StretchBlock* b, const StretchBlock* e, V3* x, const uint8_t* grasped, double inv_h2,
                            V3* force) {
  const __m256d tiny = _mm256_set1_pd(1e-12), one = _mm256_set1_pd(1.0);
  for (const StretchBlock* p = b; p < e; ++p) {
    int32_t ci[4], cj[4];
    const int32_t *pi = p->i, *pj = p->j;
    int count = 4;
    if constexpr (careful) {
      count = lanes_of(p->i, ci);
      lanes_of(p->j, cj);
      pi = ci;
      pj = cj;
    }
    Lanes3 xi = load4(x, pi), xj = load4(x, pj);
    const Lanes3 d = sub3(xi, xj);
    const __m256d len = _mm256_sqrt_pd(dot3(d, d));
    const __m256d ok = _mm256_cmp_pd(len, tiny, _CMP_NLT_UQ);
    const __m256d rest = _mm256_load_pd(p->rest);
    const Lanes3 n = and3(scale(_mm256_div_pd(one, len), d), ok);
    const __m256d inv = _mm256_blendv_pd(_mm256_load_pd(p->inv_t), _mm256_load_pd(p->inv_c),
                                         _mm256_cmp_pd(len, rest, _CMP_LT_OQ));
    const __m256d dl = _mm256_and_pd(mul(sub(rest, len), inv), ok);
    xi = add3(xi, scale(mul(_mm256_load_pd(p->wi), dl), n));
    xj = sub3(xj, scale(mul(_mm256_load_pd(p->wj), dl), n));
    store4(x, pi, xi, count);
    store4(x, pj, xj, count);
    if constexpr (careful) {
      const Spill sd = spill(dl), nx = spill(n.x), ny = spill(n.y), nz = spill(n.z);
      for (int l = 0; l < count; ++l) stretch_force(pi[l], pj[l], sd.v[l], lane(nx, ny, nz, l), grasped, inv_h2, *force);
    }
  }
}

// shear_constraint() over 4 lanes. A lane with denom <= 1e-300 gets dl = 0.
template <bool careful>
DG_AVX2 void shear_kernel(const ShearBlock* b, const ShearBlock* e, V3* x, const uint8_t* grasped, double inv_h2,
                          V3* force) {
  const __m256d tiny = _mm256_set1_pd(1e-300), minus_one = _mm256_set1_pd(-1.0);
  const __m256d sign = _mm256_set1_pd(-0.0);
  for (const ShearBlock* p = b; p < e; ++p) {
    int32_t cv[3][4];
    const int32_t *p0 = p->v[0], *p1 = p->v[1], *p2 = p->v[2];
    int count = 4;
    if constexpr (careful) {
      count = lanes_of(p->v[0], cv[0]);
      lanes_of(p->v[1], cv[1]);
      lanes_of(p->v[2], cv[2]);
      p0 = cv[0];
      p1 = cv[1];
      p2 = cv[2];
    }
    Lanes3 x0 = load4(x, p0), x1 = load4(x, p1), x2 = load4(x, p2);
    const __m256d a = _mm256_load_pd(p->a), bb = _mm256_load_pd(p->b);
    const __m256d c = _mm256_load_pd(p->c), d = _mm256_load_pd(p->d);
    const Lanes3 e1 = sub3(x1, x0), e2 = sub3(x2, x0);
    const Lanes3 f1 = add3(scale(a, e1), scale(c, e2)), f2 = add3(scale(bb, e1), scale(d, e2));
    const __m256d C = dot3(f1, f2);
    const Lanes3 g1 = add3(scale(a, f2), scale(bb, f1)), g2 = add3(scale(c, f2), scale(d, f1));
    const Lanes3 g0 = scale(minus_one, add3(g1, g2));
    const __m256d w0 = _mm256_load_pd(p->w0), w1 = _mm256_load_pd(p->w1), w2 = _mm256_load_pd(p->w2);
    const __m256d denom =
        add(add(add(mul(w0, dot3(g0, g0)), mul(w1, dot3(g1, g1))), mul(w2, dot3(g2, g2))), _mm256_load_pd(p->alpha_t));
    const __m256d ok = _mm256_cmp_pd(denom, tiny, _CMP_NLE_UQ);
    const __m256d dl = _mm256_and_pd(_mm256_div_pd(_mm256_xor_pd(C, sign), denom), ok);
    x0 = add3(x0, scale(mul(w0, dl), g0));
    x1 = add3(x1, scale(mul(w1, dl), g1));
    x2 = add3(x2, scale(mul(w2, dl), g2));
    store4(x, p0, x0, count);
    store4(x, p1, x1, count);
    store4(x, p2, x2, count);
    if constexpr (careful) {
      const Spill sd = spill(dl);
      const Spill s0x = spill(g0.x), s0y = spill(g0.y), s0z = spill(g0.z);
      const Spill s1x = spill(g1.x), s1y = spill(g1.y), s1z = spill(g1.z);
      const Spill s2x = spill(g2.x), s2y = spill(g2.y), s2z = spill(g2.z);
      for (int l = 0; l < count; ++l) {
        const int v[3] = {p0[l], p1[l], p2[l]};
        const V3 g[3] = {lane(s0x, s0y, s0z, l), lane(s1x, s1y, s1z, l), lane(s2x, s2y, s2z, l)};
        shear_force(v, sd.v[l], g, grasped, inv_h2, *force);
      }
    }
  }
}

// bending_constraint() for one lane of a block, each vertex one register (x, y, z, pad): the
// constraint is linear in x, so it needs no lane transposes (measured as fast as the transposed
// 4-lane form, and simpler). The pad lane stays 0 (0 + (-0) = +0). Returns dlambda (x, y, z, 0).
DG_AVX2 inline __m256d bend_lane(const BendBlock* p, int l, const int32_t* v0, const int32_t* v1, const int32_t* v2,
                                 const int32_t* v3, V3* x) {
  V3 &a = x[v0[l]], &b = x[v1[l]], &c = x[v2[l]], &d = x[v3[l]];
  const __m256d x0 = _mm256_load_pd(&a.x), x1 = _mm256_load_pd(&b.x);
  const __m256d x2 = _mm256_load_pd(&c.x), x3 = _mm256_load_pd(&d.x);
  const __m256d kx = add(add(add(mul(_mm256_broadcast_sd(&p->k[0][l]), x0), mul(_mm256_broadcast_sd(&p->k[1][l]), x1)),
                             mul(_mm256_broadcast_sd(&p->k[2][l]), x2)),
                         mul(_mm256_broadcast_sd(&p->k[3][l]), x3));
  const __m256d dl = mul(_mm256_broadcast_sd(&p->neg_inv_denom[l]), kx);
  _mm256_store_pd(&a.x, add(x0, mul(_mm256_broadcast_sd(&p->wk[0][l]), dl)));
  _mm256_store_pd(&b.x, add(x1, mul(_mm256_broadcast_sd(&p->wk[1][l]), dl)));
  _mm256_store_pd(&c.x, add(x2, mul(_mm256_broadcast_sd(&p->wk[2][l]), dl)));
  _mm256_store_pd(&d.x, add(x3, mul(_mm256_broadcast_sd(&p->wk[3][l]), dl)));
  return dl;
}

}  // namespace

DG_AVX2 void stretch_free_avx2(const StretchBlock* b, const StretchBlock* e, V3* x) {
  stretch_kernel<false>(b, e, x, nullptr, 0, nullptr);
}
DG_AVX2 void shear_free_avx2(const ShearBlock* b, const ShearBlock* e, V3* x) {
  shear_kernel<false>(b, e, x, nullptr, 0, nullptr);
}
DG_AVX2 void bend_free_avx2(const BendBlock* b, const BendBlock* e, V3* x) {
  for (const BendBlock* p = b; p < e; ++p)
    for (int l = 0; l < 4; ++l) bend_lane(p, l, p->v[0], p->v[1], p->v[2], p->v[3], x);
}
DG_AVX2 void stretch_careful_avx2(const StretchBlock* b, const StretchBlock* e, V3* x, const uint8_t* grasped, double inv_h2,
                          V3& force) {
  stretch_kernel<true>(b, e, x, grasped, inv_h2, &force);
}
DG_AVX2 void shear_careful_avx2(const ShearBlock* b, const ShearBlock* e, V3* x, const uint8_t* grasped, double inv_h2,
                        V3& force) {
  shear_kernel<true>(b, e, x, grasped, inv_h2, &force);
}
DG_AVX2 void bend_careful_avx2(const BendBlock* b, const BendBlock* e, V3* x, const uint8_t* grasped, double inv_h2, V3& force) {
  for (const BendBlock* p = b; p < e; ++p)
    for (int l = 0; l < 4 && p->v[0][l] >= 0; ++l) {
      const Spill dl = spill(bend_lane(p, l, p->v[0], p->v[1], p->v[2], p->v[3], x));
      const int v[4] = {p->v[0][l], p->v[1][l], p->v[2][l], p->v[3][l]};
      const double k[4] = {p->k[0][l], p->k[1][l], p->k[2][l], p->k[3][l]};
      bend_force(v, k, V3{dl.v[0], dl.v[1], dl.v[2]}, grasped, inv_h2, force);
    }
}

DG_AVX2 void integrate_avx2(int n, bool velocities, double h, double inv_h, double decay, V3 g, const double* w,
                            const V3* f, V3* x, V3* p, V3* v) {
  const __m256d vh = _mm256_set1_pd(h), vinv_h = _mm256_set1_pd(inv_h), vdecay = _mm256_set1_pd(decay);
  const __m256d vg = _mm256_loadu_pd(&g.x);  // (a by-value argument: no alignment assumed)
  for (int i = 0; i < n; ++i) {
    const __m256d xi = _mm256_load_pd(&x[i].x);
    __m256d vi = velocities ? mul(vinv_h, sub(xi, _mm256_load_pd(&p[i].x))) : _mm256_load_pd(&v[i].x);
    _mm256_store_pd(&p[i].x, xi);
    const __m256d acc = f ? add(vg, mul(_mm256_broadcast_sd(&w[i]), _mm256_load_pd(&f[i].x))) : vg;
    vi = add(mul(vdecay, vi), mul(vh, acc));
    _mm256_store_pd(&v[i].x, vi);
    _mm256_store_pd(&x[i].x, add(xi, mul(vh, vi)));
  }
}

}  // namespace dressguard::sim

#else  // not x86-64: cpu_has_avx2() is false and these are never called.

namespace dressguard::sim {
void stretch_free_avx2(const StretchBlock*, const StretchBlock*, V3*) {}
void shear_free_avx2(const ShearBlock*, const ShearBlock*, V3*) {}
void bend_free_avx2(const BendBlock*, const BendBlock*, V3*) {}
void stretch_careful_avx2(const StretchBlock*, const StretchBlock*, V3*, const uint8_t*, double, V3&) {}
void shear_careful_avx2(const ShearBlock*, const ShearBlock*, V3*, const uint8_t*, double, V3&) {}
void bend_careful_avx2(const BendBlock*, const BendBlock*, V3*, const uint8_t*, double, V3&) {}
void integrate_avx2(int, bool, double, double, double, V3, const double*, const V3*, V3*, V3*, V3*) {}
}  // namespace dressguard::sim

#endif
