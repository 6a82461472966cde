// bench_sim_vertex_pass: would a vertex-centric solver move fewer vertices for the same work?
//
// bench_sim_kernels (offline/sim/MEASUREMENTS.md, session 76) put a floor under the tree's XPBD
// passes: moving each constraint's vertices into lanes and back, with no arithmetic, already
// costs 2.2-2.4x the reduced gown's budget for the 8x goal. A constraint-centric pass loads and
// stores a vertex once per constraint end (23 per vertex: 6 edges, 6 triangles, 11 hinge
// stencils). A vertex-centric pass writes each vertex once and reads its neighbours: Vertex Block
// Descent (Chen, Macklin, Li, Zhang, Kim, Grinspun 2024). Per colour group of vertices that share
// no element, each free vertex i takes one Newton step on the incremental potential with its
// neighbours held:
//   G(x) = sum_i m_i / (2 h^2) |x_i - y_i|^2 + sum_c E_c(x),
//   H_i dx_i = -g_i,   H_i = m_i / h^2 I + sum_{c at i} d2E_c / dx_i^2,
//                      g_i = m_i / h^2 (x_i - y_i) + sum_{c at i} dE_c / dx_i,
// with the XPBD constraints' own energies E_c = C^2 / (2 alpha) (constraints.h):
//   stretch edge  C = |x_i - x_j| - L:  dE = k C n,  d2E = k n n^T + k max(C, 0) / |d| (I - n n^T)
//                 (k = 1 / alpha, the compressive compliance below the rest length; the second
//                 term dropped in compression keeps H positive definite, as VBD does);
//   shear         C = f1 . f2 (f1 = a e1 + c e2, f2 = b e1 + d e2): grad_i C = p_i f2 + q_i f1 with
//                 (p, q) = (-(a + c), -(b + d)), (a, b), (c, d) for the triangle's vertex 0, 1, 2,
//                 d2C / dx_i^2 = 2 p_i q_i I: d2E = k g g^T + k max(C 2 p_i q_i, 0) I, k = A / alpha;
//   bending       E = k / 2 |sum_a k_a x_a|^2 (Bergou): dE = k k_i K x, d2E = k k_i^2 I.
//
// Measured on the same gowns, cloth (participant 4's paper-budget parameters) and start positions
// as bench_sim_kernels (sim_kernel_setup.h), one core, best of --reps:
// 1. Cost per pass: ns per free vertex, the vertex-centric pass (scalar, vertices colour by colour,
//    each vertex's terms stored in its order) against the tree's pass (the three AVX2 kernels, free
//    and careful blocks) and against the same pass through the scalar constraint functions, timed
//    in the same run, the three alternating.
// 2. Work per pass: from x = y = the jittered start, how much of G's excess over its minimum one
//    tree pass and 1, 2, 5 and 20 vertex passes remove (G* from 400 vertex passes; printed: how
//    much 400 more lower it). Each substep of the tree starts its multipliers at 0 ("small
//    steps"), so one pass of each is the like-for-like comparison. Twice: from the 1 mm start,
//    nearly linear, and from its displacements x 10 (1 cm on 1.4-2.8 cm edges), where the
//    energies curve and a Newton step per vertex might do more than a projection per constraint.
// 3. What the 8x and 1x goals would leave: vertex passes per 1/300 s output step if the whole
//    budget went to them (no integration, collision or output).
//
// Usage: bench_sim_vertex_pass [--reps N]   (default 5; about 10 s)
// The vertex pass is scalar here. Its AVX2 form (4 vertices of a colour at once, their terms
// padded to the block's largest count) is not written; the scalar and AVX2 tree passes printed
// side by side show what 4 lanes gave the tree's kernels.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "constraints.h"
#include "kernels.h"
#include "model.h"
#include "sim_kernel_setup.h"
#include "trial.h"

using namespace dressguard::sim;

namespace {

// One edge seen from one of its vertices: the other end, the rest length, 1 / alpha in tension
// and in compression.
struct EdgeTerm {
  int32_t j;
  double rest, k_t, k_c;
};
// One triangle seen from one of its vertices: its three vertices, Dm^-1, the vertex's gradient
// coefficients (grad_i C = p f2 + q f1) and k = A / alpha_shear.
struct TriTerm {
  int32_t v[3];
  double a, b, c, d, p, q, k;
};
// One hinge stencil seen from one of its vertices: its vertices and weights, the vertex's own
// weight and k = 1 / alpha_bend.
struct BendTerm {
  int32_t v[4];
  double w[4];
  double own, k;
};

// The vertex-centric form of a GownModel: free vertices in colour order, each with its terms.
struct VertexSolver {
  std::vector<int32_t> order;                     // free vertices, colour group after colour group
  int colours = 0;                                // vertex colours (groups of `order`, one after another)
  std::vector<int32_t> edge_off, tri_off, bend_off;  // per position in `order`: [off[k], off[k + 1])
  std::vector<EdgeTerm> edges;
  std::vector<TriTerm> tris;
  std::vector<BendTerm> bends;
  std::vector<double> m_h2;                       // m_i / h^2 per position in `order`
};

VertexSolver make_vertex_solver(const GownModel& m) {
  const SceneData& s = *m.scene;
  const int n = static_cast<int>(s.rest.size());
  // Vertices that share an element may not share a colour.
  std::vector<std::vector<int32_t>> nb(n);
  auto link = [&](const int32_t* v, int count) {
    for (int a = 0; a < count; ++a)
      for (int b = 0; b < count; ++b)
        if (a != b) nb[v[a]].push_back(v[b]);
  };
  for (const DistanceLink& l : s.stretch) link(&l.i, 2);
  for (const ShearTri& t : s.shear) link(t.v, 3);
  for (const BendStencil& b : s.bend) link(b.v, 4);
  std::vector<int> colour(n, -1);
  int colours = 0;
  for (int i = 0; i < n; ++i) {
    std::vector<char> used(colours + 1, 0);
    for (int32_t j : nb[i])
      if (colour[j] >= 0) used[colour[j]] = 1;
    int c = 0;
    while (used[c]) ++c;
    colour[i] = c;
    colours = std::max(colours, c + 1);
  }
  std::vector<std::vector<TriTerm>> tri_of(n);
  std::vector<std::vector<EdgeTerm>> edge_of(n);
  std::vector<std::vector<BendTerm>> bend_of(n);
  const double k_t = 1.0 / m.alpha_stretch, k_c = 1.0 / m.alpha_compress;
  for (const DistanceLink& l : s.stretch) {
    edge_of[l.i].push_back({l.j, l.rest, k_t, k_c});
    edge_of[l.j].push_back({l.i, l.rest, k_t, k_c});
  }
  for (const ShearTri& t : s.shear) {
    const double a = t.dm_inv[0], b = t.dm_inv[1], c = t.dm_inv[2], d = t.dm_inv[3];
    const double pq[3][2] = {{-(a + c), -(b + d)}, {a, b}, {c, d}};
    for (int r = 0; r < 3; ++r)
      tri_of[t.v[r]].push_back({{t.v[0], t.v[1], t.v[2]}, a, b, c, d, pq[r][0], pq[r][1], t.area / m.alpha_shear});
  }
  for (const BendStencil& st : s.bend)
    for (int r = 0; r < 4; ++r)
      bend_of[st.v[r]].push_back({{st.v[0], st.v[1], st.v[2], st.v[3]}, {st.k[0], st.k[1], st.k[2], st.k[3]}, st.k[r],
                                  1.0 / m.alpha_bend});
  VertexSolver v;
  const double inv_h2 = 1.0 / (m.h * m.h);
  for (int c = 0; c < colours; ++c) {
    for (int i = 0; i < n; ++i)
      if (colour[i] == c && m.w[i] > 0) {
        v.order.push_back(i);
        v.edge_off.push_back(static_cast<int32_t>(v.edges.size()));
        v.tri_off.push_back(static_cast<int32_t>(v.tris.size()));
        v.bend_off.push_back(static_cast<int32_t>(v.bends.size()));
        v.edges.insert(v.edges.end(), edge_of[i].begin(), edge_of[i].end());
        v.tris.insert(v.tris.end(), tri_of[i].begin(), tri_of[i].end());
        v.bends.insert(v.bends.end(), bend_of[i].begin(), bend_of[i].end());
        v.m_h2.push_back(m.mass[i] * inv_h2);
      }
  }
  v.colours = colours;
  v.edge_off.push_back(static_cast<int32_t>(v.edges.size()));
  v.tri_off.push_back(static_cast<int32_t>(v.tris.size()));
  v.bend_off.push_back(static_cast<int32_t>(v.bends.size()));
  return v;
}

// A symmetric 3x3 matrix, upper triangle: xx, xy, xz, yy, yz, zz.
struct Sym3 {
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
};
inline void add_outer(Sym3& h, double s, V3 g) {
  h.xx += s * g.x * g.x;
  h.xy += s * g.x * g.y;
  h.xz += s * g.x * g.z;
  h.yy += s * g.y * g.y;
  h.yz += s * g.y * g.z;
  h.zz += s * g.z * g.z;
}
inline void add_diag(Sym3& h, double s) {
  h.xx += s;
  h.yy += s;
  h.zz += s;
}

// One vertex's Newton step (the header's H_i dx_i = -g_i), solved by the adjugate.
inline void vertex_step(const VertexSolver& v, int k, V3* x, const V3* y) {
  const int32_t i = v.order[k];
  const V3 xi = x[i];
  Sym3 h;
  add_diag(h, v.m_h2[k]);
  V3 g = v.m_h2[k] * (xi - y[i]);
  for (int32_t e = v.edge_off[k]; e < v.edge_off[k + 1]; ++e) {
    const EdgeTerm& t = v.edges[e];
    const V3 d = xi - x[t.j];
    const double len = norm(d);
    if (len < 1e-12) continue;
    const V3 n = (1.0 / len) * d;
    const double C = len - t.rest;
    const double kk = C < 0 ? t.k_c : t.k_t;
    g += (kk * C) * n;
    if (C > 0) {
      const double s = kk * C / len;  // k C / |d| (I - n n^T)
      add_diag(h, s);
      add_outer(h, kk - s, n);
    } else {
      add_outer(h, kk, n);
    }
  }
  for (int32_t e = v.tri_off[k]; e < v.tri_off[k + 1]; ++e) {
    const TriTerm& t = v.tris[e];
    const V3 x0 = x[t.v[0]];
    const V3 e1 = x[t.v[1]] - x0, e2 = x[t.v[2]] - x0;
    const V3 f1 = t.a * e1 + t.c * e2, f2 = t.b * e1 + t.d * e2;
    const double C = dot(f1, f2);
    const V3 gr = t.p * f2 + t.q * f1;
    g += (t.k * C) * gr;
    add_outer(h, t.k, gr);
    add_diag(h, std::max(t.k * C * 2 * t.p * t.q, 0.0));
  }
  for (int32_t e = v.bend_off[k]; e < v.bend_off[k + 1]; ++e) {
    const BendTerm& t = v.bends[e];
    const V3 kx = t.w[0] * x[t.v[0]] + t.w[1] * x[t.v[1]] + t.w[2] * x[t.v[2]] + t.w[3] * x[t.v[3]];
    g += (t.k * t.own) * kx;
    add_diag(h, t.k * t.own * t.own);
  }
  // dx = -H^-1 g, H^-1 = adj(H) / det(H).
  const double c00 = h.yy * h.zz - h.yz * h.yz, c01 = h.xz * h.yz - h.xy * h.zz, c02 = h.xy * h.yz - h.xz * h.yy;
  const double det = h.xx * c00 + h.xy * c01 + h.xz * c02;
  if (!(det > 1e-300)) return;
  const double c11 = h.xx * h.zz - h.xz * h.xz, c12 = h.xy * h.xz - h.xx * h.yz, c22 = h.xx * h.yy - h.xy * h.xy;
  const double s = -1.0 / det;
  x[i] = xi + V3{s * (c00 * g.x + c01 * g.y + c02 * g.z), s * (c01 * g.x + c11 * g.y + c12 * g.z),
                 s * (c02 * g.x + c12 * g.y + c22 * g.z)};
}

void vertex_pass(const VertexSolver& v, V3* x, const V3* y) {
  const int count = static_cast<int>(v.order.size());
  for (int k = 0; k < count; ++k) vertex_step(v, k, x, y);
}

// The tree's constraint pass: the three AVX2 kernels over every colour group, free blocks then
// careful ones, as solve_kind() (solver.cpp) runs them.
template <class Block, class Free, class Careful>
void kind_pass(const std::vector<Block>& blocks, const std::vector<BlockSpan>& spans, V3* x, const uint8_t* grasped,
               double inv_h2, V3& force, Free free, Careful careful) {
  for (const BlockSpan& sp : spans) {
    free(blocks.data() + sp.begin, blocks.data() + sp.simd_end, x);
    careful(blocks.data() + sp.simd_end, blocks.data() + sp.end, x, grasped, inv_h2, force);
  }
}
void tree_pass(const GownModel& m, V3* x) {
  const uint8_t* grasped = m.scene->grasped.data();
  const double inv_h2 = 1.0 / (m.h * m.h);
  V3 force{0, 0, 0};
  kind_pass(m.stretch_blocks, m.stretch_spans, x, grasped, inv_h2, force, stretch_free_avx2, stretch_careful_avx2);
  kind_pass(m.shear_blocks, m.shear_spans, x, grasped, inv_h2, force, shear_free_avx2, shear_careful_avx2);
  kind_pass(m.bend_blocks, m.bend_spans, x, grasped, inv_h2, force, bend_free_avx2, bend_careful_avx2);
}

// The same pass through the scalar constraint functions (constraints.h), block by block, lane by
// lane, as solver.cpp's scalar path runs it without the gripper's force: the like-for-like
// baseline of the scalar vertex pass.
void tree_pass_scalar(const GownModel& m, V3* x) {
  for (const StretchBlock& b : m.stretch_blocks)
    for (int l = 0; l < 4 && b.i[l] >= 0; ++l) {
      V3 nrm;
      distance_constraint(x[b.i[l]], x[b.j[l]], b.wi[l], b.wj[l], b.rest[l], b.inv_t[l], b.inv_c[l], &nrm);
    }
  for (const ShearBlock& b : m.shear_blocks)
    for (int l = 0; l < 4 && b.v[0][l] >= 0; ++l) {
      const double dm[4] = {b.a[l], b.b[l], b.c[l], b.d[l]};
      V3 g[3];
      shear_constraint(x[b.v[0][l]], x[b.v[1][l]], x[b.v[2][l]], b.w0[l], b.w1[l], b.w2[l], dm, b.alpha_t[l], g);
    }
  for (const BendBlock& b : m.bend_blocks)
    for (int l = 0; l < 4 && b.v[0][l] >= 0; ++l) {
      const double k[4] = {b.k[0][l], b.k[1][l], b.k[2][l], b.k[3][l]};
      const double wk[4] = {b.wk[0][l], b.wk[1][l], b.wk[2][l], b.wk[3][l]};
      bending_constraint(x[b.v[0][l]], x[b.v[1][l]], x[b.v[2][l]], x[b.v[3][l]], k, wk, b.neg_inv_denom[l]);
    }
}

// G(x) of the header, over the whole mesh (grasped vertices do not move, so their inertia term is 0).
double potential(const GownModel& m, const std::vector<V3>& x, const std::vector<V3>& y) {
  const SceneData& s = *m.scene;
  const double inv_h2 = 1.0 / (m.h * m.h);
  double g = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const V3 d = x[i] - y[i];
    g += 0.5 * m.mass[i] * inv_h2 * dot(d, d);
  }
  for (const DistanceLink& l : s.stretch) {
    const double C = norm(x[l.i] - x[l.j]) - l.rest;
    g += 0.5 * C * C / (C < 0 ? m.alpha_compress : m.alpha_stretch);
  }
  for (const ShearTri& t : s.shear) {
    const V3 e1 = x[t.v[1]] - x[t.v[0]], e2 = x[t.v[2]] - x[t.v[0]];
    const V3 f1 = t.dm_inv[0] * e1 + t.dm_inv[2] * e2, f2 = t.dm_inv[1] * e1 + t.dm_inv[3] * e2;
    const double C = dot(f1, f2);
    g += 0.5 * C * C * t.area / m.alpha_shear;
  }
  for (const BendStencil& b : s.bend) {
    const V3 kx = b.k[0] * x[b.v[0]] + b.k[1] * x[b.v[1]] + b.k[2] * x[b.v[2]] + b.k[3] * x[b.v[3]];
    g += 0.5 * dot(kx, kx) / m.alpha_bend;
  }
  return g;
}

// Part 2 of the header from x = y: prints the share of G(y) - G* that one tree pass and 1, 2, 5
// and 20 vertex passes remove. False if the vertex passes did not lower G at every count.
bool work_per_pass(const GownModel& m, const VertexSolver& v, const std::vector<V3>& y, const char* label) {
  std::vector<V3> x = y;
  for (int k = 0; k < 400; ++k) vertex_pass(v, x.data(), y.data());
  const double g_min = potential(m, x, y);
  for (int k = 0; k < 400; ++k) vertex_pass(v, x.data(), y.data());
  const double g_min2 = potential(m, x, y);
  const double g0 = potential(m, y, y);
  auto removed = [&](const std::vector<V3>& xs) { return (g0 - potential(m, xs, y)) / (g0 - g_min); };
  x = y;
  tree_pass(m, x.data());
  std::printf("  %s start: G(y) - G* = %.4g J (G* after 400 vertex passes; 400 more lower it by %.2g of that); "
              "removed by one tree pass %.3f",
              label, g0 - g_min, (g_min - g_min2) / (g0 - g_min), removed(x));
  x = y;
  int done = 0;
  // Each vertex step is a full Newton step with a positive definite H: downhill, but it could
  // overshoot where the energy curves away from its quadratic model; that would show here.
  bool descends = true;
  double last = 0;
  for (const int k : {1, 2, 5, 20}) {
    for (; done < k; ++done) vertex_pass(v, x.data(), y.data());
    const double r = removed(x);
    descends = descends && r > last;
    last = r;
    std::printf(", %d vertex pass%s %.3f", k, k == 1 ? "" : "es", r);
  }
  std::printf("\n");
  return descends;
}

template <class Pass>
double seconds_per_pass(const std::vector<V3>& start, int passes, Pass pass) {
  std::vector<V3> x = start;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < passes; ++k) pass(x.data());
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / passes;
}

}  // namespace

int main(int argc, char** argv) {
  const int reps = dressguard::bench::parse_reps(argc, argv, "bench_sim_vertex_pass");
  if (reps == 0) return 2;
  if (!cpu_has_avx2()) {
    std::fprintf(stderr, "bench_sim_vertex_pass: this CPU has no AVX2; the tree's kernels it compares with do not "
                         "run\n");
    return 1;
  }
  constexpr double kPassesPerSimSecond = 300.0 * 20.0;
  for (const GownResolution res : {GownResolution::Reduced, GownResolution::Full}) {
    const bool reduced = res == GownResolution::Reduced;
    const dressguard::bench::KernelSetup ks = dressguard::bench::kernel_setup(res);
    const GownModel& m = ks.model;
    const std::vector<V3>& y = ks.start;  // the inertial target: x = y at the pass's start
    const VertexSolver v = make_vertex_solver(m);
    const double free_vertices = static_cast<double>(v.order.size());
    double edge_sum = 0;
    for (const DistanceLink& l : m.scene->stretch) edge_sum += l.rest;
    std::printf("%s gown: %zu vertices (%zu free), %d vertex colours, mean edge %.1f mm; terms per free vertex: "
                "%.2f edges, %.2f triangles, %.2f hinge stencils (%.2f MB of terms a pass)\n",
                reduced ? "reduced" : "full", y.size(), v.order.size(), v.colours,
                1e3 * edge_sum / static_cast<double>(m.scene->stretch.size()), v.edges.size() / free_vertices,
                v.tris.size() / free_vertices, v.bends.size() / free_vertices,
                (v.edges.size() * sizeof(EdgeTerm) + v.tris.size() * sizeof(TriTerm) +
                 v.bends.size() * sizeof(BendTerm)) / 1048576.0);

    // 1. Cost per pass, the three alternating (tree with AVX2 kernels, tree scalar, vertex pass),
    // best of `reps`.
    const int passes = reduced ? 600 : 150;
    double t_tree = 1e30, t_scalar = 1e30, t_vertex = 1e30;
    for (int r = 0; r < reps; ++r) {
      t_tree = std::min(t_tree, seconds_per_pass(y, passes, [&](V3* x) { tree_pass(m, x); }));
      t_scalar = std::min(t_scalar, seconds_per_pass(y, passes, [&](V3* x) { tree_pass_scalar(m, x); }));
      t_vertex = std::min(t_vertex, seconds_per_pass(y, passes, [&](V3* x) { vertex_pass(v, x, y.data()); }));
    }
    const double budget = reduced ? 0.125 : 1.0;  // s per simulated s: 8x and 1x real time
    std::printf("  cost per pass, ns per free vertex: tree, AVX2 kernels %.2f (%.1f us); tree, scalar "
                "constraint functions %.2f; vertex pass, scalar %.2f (%.2fx the scalar tree's, %.2fx the AVX2 "
                "tree's)\n",
                t_tree * 1e9 / free_vertices, t_tree * 1e6, t_scalar * 1e9 / free_vertices,
                t_vertex * 1e9 / free_vertices, t_vertex / t_scalar, t_vertex / t_tree);
    std::printf("  20 passes per output step: tree %.3f s per simulated s, vertex %.3f; the %s goal's %.3f s "
                "would hold %.1f vertex passes per output step (the tree's kernels alone: %.1f)\n",
                t_tree * kPassesPerSimSecond, t_vertex * kPassesPerSimSecond, reduced ? "8x" : "1x", budget,
                budget / 300.0 / t_vertex, budget / 300.0 / t_tree);

    // 2. Work per pass, from the 1 mm start and from the same displacements x 10 (1 cm).
    std::vector<V3> wide(y.size());
    for (std::size_t i = 0; i < y.size(); ++i) wide[i] = m.scene->rest[i] + 10.0 * (y[i] - m.scene->rest[i]);
    // Both starts run and print before either is judged, so a failure names its start.
    const bool descends_1mm = work_per_pass(m, v, y, "1 mm");
    const bool descends_1cm = work_per_pass(m, v, wide, "1 cm");
    if (!descends_1mm || !descends_1cm) {
      const char* which = !descends_1mm && !descends_1cm ? "1 mm and 1 cm" : descends_1mm ? "1 cm" : "1 mm";
      std::fprintf(stderr,
                   "bench_sim_vertex_pass: %s gown, %s start: the vertex passes did not lower G at every count\n",
                   reduced ? "reduced" : "full", which);
      return 1;
    }
  }
  return 0;
}
