// bench_sim_elements: would a smaller constraint set make the cloth simulator fast enough?
//
// offline/sim/README.md ("What the goals would take") names two ways to fewer vertex writes per
// substep that keep the 20 substeps and double precision. This measures both, on the
// reduced and the full gown, with participant 4's paper-budget cloth
// (models/participant4-paper-budget.json: stretch 0.193, shear 0.529, bend 0.733):
//
// 1. One element per triangle for stretch and shear (Mueller et al. 2014, strain based
//    dynamics): with the deformation gradient's columns f1, f2 in the rest frame (as
//    shear_constraint), S11 = |f1| - 1 and S22 = |f2| - 1 take the place of the edge distance
//    constraints, and S12 = f1 . f2 stays the shear. Timed in two forms against the baseline,
//    the tree's edges + shear, all scalar in mesh order from the same perturbed positions (each
//    vertex moved N(0, 1 mm) per coordinate), the variants alternating, best of --reps:
//      in turn:  each strain projected from the current positions (Bender's PBD library);
//      at once:  all three from one evaluation of f1, f2, their corrections summed (Jacobi
//                within the triangle): the cheapest form an element can take.
// 2. Bending as an explicit force instead of a projection. For stencil e the XPBD denominator
//    is alpha_t (1 + r_e) with r_e = h^2 sum_i w_i k_i^2 / alpha, which is also h^2 omega^2 of
//    its mode. The assembled operator is a sum of the stencils' positive semidefinite terms, so
//    its largest h^2 omega^2 is at least max r_e; symplectic Euler on a linear force is stable
//    only below 4. Printed: r's median, 90th percentile and maximum.
//
// Usage: bench_sim_elements [--reps N]   (default 5; about 10 s)
// Scalar on both sides: the AVX2 kernels (solver_avx2.cpp) run the baseline 2.1-2.6x faster than
// the scalar mesh order (bench_sim's window), and an element's AVX2 form would gain about as much.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "constraints.h"
#include "model.h"
#include "sim_kernel_setup.h"
#include "trial.h"

using namespace dressguard::sim;

namespace {

// S = |f| - 1 for the column f = p e1 + q e2 (e1 = x1 - x0, e2 = x2 - x0):
//   grad_1 S = p n, grad_2 S = q n, grad_0 S = -(p + q) n, n = f / |f|.
[[gnu::always_inline]] inline void strain_column(V3& x0, V3& x1, V3& x2, double w0, double w1, double w2, double p,
                                                 double q, double alpha_t) {
  const V3 f = p * (x1 - x0) + q * (x2 - x0);
  const double len = std::sqrt(dot(f, f));
  if (len < 1e-12) return;
  const V3 n = (1.0 / len) * f;
  const double g0 = -(p + q);
  const double dl = -(len - 1.0) / (w0 * g0 * g0 + w1 * p * p + w2 * q * q + alpha_t);
  x0 += (w0 * g0 * dl) * n;
  x1 += (w1 * p * dl) * n;
  x2 += (w2 * q * dl) * n;
}

// S11, S22 and S12 from one evaluation, the corrections summed.
[[gnu::always_inline]] inline void strain_triangle_at_once(V3& x0, V3& x1, V3& x2, double w0, double w1, double w2,
                                                           const double dm[4], double alpha_s, double alpha_sh) {
  const double a = dm[0], b = dm[1], c = dm[2], d = dm[3];
  const V3 e1 = x1 - x0, e2 = x2 - x0;
  const V3 f1 = a * e1 + c * e2, f2 = b * e1 + d * e2;
  const double l1 = std::sqrt(dot(f1, f1)), l2 = std::sqrt(dot(f2, f2));
  if (l1 < 1e-12 || l2 < 1e-12) return;
  const V3 n1 = (1.0 / l1) * f1, n2 = (1.0 / l2) * f2;
  const double d11 = -(l1 - 1.0) / (w0 * (a + c) * (a + c) + w1 * a * a + w2 * c * c + alpha_s);
  const double d22 = -(l2 - 1.0) / (w0 * (b + d) * (b + d) + w1 * b * b + w2 * d * d + alpha_s);
  const V3 g1 = a * f2 + b * f1, g2 = c * f2 + d * f1;
  const V3 g0 = (-1.0) * (g1 + g2);
  const double d12 = -dot(f1, f2) / (w0 * dot(g0, g0) + w1 * dot(g1, g1) + w2 * dot(g2, g2) + alpha_sh);
  const V3 s1 = d11 * n1, s2 = d22 * n2;
  x1 += w1 * (a * s1 + b * s2 + d12 * g1);
  x2 += w2 * (c * s1 + d * s2 + d12 * g2);
  x0 += w0 * ((-(a + c)) * s1 + (-(b + d)) * s2 + d12 * g0);
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

enum Variant { kEdges, kShear, kEdgesAndShear, kElementInTurn, kElementAtOnce, kVariants };

}  // namespace

int main(int argc, char** argv) {
  const int reps = dressguard::bench::parse_reps(argc, argv, "bench_sim_elements");
  if (reps == 0) return 2;
  constexpr int kSubsteps = 600;  // per timing: 0.1 s of simulated time
  for (const GownResolution res : {GownResolution::Reduced, GownResolution::Full}) {
    const dressguard::bench::KernelSetup k = dressguard::bench::kernel_setup(res);
    const SceneData& s = k.scene.data();
    const GownModel& m = k.model;
    const std::vector<V3>& start = k.start;
    const double h2 = m.h * m.h;

    std::vector<double> r;  // bending: h^2 sum w k^2 / alpha per stencil
    for (const BendStencil& b : s.bend) {
      double sw = 0;
      for (int a = 0; a < 4; ++a) sw += m.w[b.v[a]] * b.k[a] * b.k[a];
      if (sw > 0) r.push_back(sw * h2 / m.alpha_bend);
    }

    const double at = m.alpha_stretch / h2, ac = m.alpha_compress / h2;
    double best[kVariants];
    std::fill(best, best + kVariants, 1e30);
    std::vector<V3> x;
    for (int rep = 0; rep < reps; ++rep) {
      for (int v = 0; v < kVariants; ++v) {
        x = start;
        V3 n, g[3];
        const auto t0 = std::chrono::steady_clock::now();
        for (int k = 0; k < kSubsteps; ++k) {
          if (v == kEdges || v == kEdgesAndShear)
            for (const DistanceLink& e : s.stretch) {
              const double wi = m.w[e.i], wj = m.w[e.j];
              distance_constraint(x[e.i], x[e.j], wi, wj, e.rest, 1.0 / (wi + wj + at), 1.0 / (wi + wj + ac), &n);
            }
          if (v == kShear || v == kEdgesAndShear)
            for (const ShearTri& t : s.shear)
              shear_constraint(x[t.v[0]], x[t.v[1]], x[t.v[2]], m.w[t.v[0]], m.w[t.v[1]], m.w[t.v[2]], t.dm_inv,
                               m.alpha_shear / (t.area * h2), g);
          if (v == kElementInTurn)
            for (const ShearTri& t : s.shear) {
              const double w0 = m.w[t.v[0]], w1 = m.w[t.v[1]], w2 = m.w[t.v[2]];
              const double as = m.alpha_stretch / (t.area * h2);
              strain_column(x[t.v[0]], x[t.v[1]], x[t.v[2]], w0, w1, w2, t.dm_inv[0], t.dm_inv[2], as);
              strain_column(x[t.v[0]], x[t.v[1]], x[t.v[2]], w0, w1, w2, t.dm_inv[1], t.dm_inv[3], as);
              shear_constraint(x[t.v[0]], x[t.v[1]], x[t.v[2]], w0, w1, w2, t.dm_inv, m.alpha_shear / (t.area * h2), g);
            }
          if (v == kElementAtOnce)
            for (const ShearTri& t : s.shear)
              strain_triangle_at_once(x[t.v[0]], x[t.v[1]], x[t.v[2]], m.w[t.v[0]], m.w[t.v[1]], m.w[t.v[2]],
                                      t.dm_inv, m.alpha_stretch / (t.area * h2), m.alpha_shear / (t.area * h2));
        }
        const double us = 1e6 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / kSubsteps;
        best[v] = std::min(best[v], us);
        double sum = 0;  // keeps the loops' results alive
        for (const V3& q : x) sum += q.x + q.y + q.z;
        if (!std::isfinite(sum)) {
          std::fprintf(stderr, "bench_sim_elements: variant %d diverged\n", v);
          return 1;
        }
      }
    }
    const double base = best[kEdgesAndShear];
    std::printf("%s gown: %zu vertices, %zu edges, %zu triangles, %zu bending stencils\n",
                res == GownResolution::Full ? "full" : "reduced", s.rest.size(), s.stretch.size(), s.shear.size(),
                s.bend.size());
    std::printf("  per substep, scalar, mesh order, best of %d: edges + shear %.1f us (edges %.1f, shear %.1f)\n", reps,
                base, best[kEdges], best[kShear]);
    std::printf("  one element per triangle: in turn %.1f us (%.2fx the baseline), at once %.1f us (%.2fx)\n",
                best[kElementInTurn], best[kElementInTurn] / base, best[kElementAtOnce], best[kElementAtOnce] / base);
    std::printf("  per constraint: edge %.2f ns, shear %.2f ns, element in turn %.2f ns, at once %.2f ns\n",
                1e3 * best[kEdges] / s.stretch.size(), 1e3 * best[kShear] / s.shear.size(),
                1e3 * best[kElementInTurn] / s.shear.size(), 1e3 * best[kElementAtOnce] / s.shear.size());
    std::printf("  bending h^2 omega^2 per stencil: median %.3g, 90th percentile %.3g, max %.3g (explicit force "
                "stable only below 4)\n", quantile(r, 0.5), quantile(r, 0.9), quantile(r, 1.0));
  }
  return 0;
}
