// The XPBD "small steps" solver (Macklin et al. 2019): one output step = collision detection
// once, then `substeps` x (integrate, solve each constraint once in a fixed Gauss-Seidel order,
// resolve contacts with friction, update velocities). Allocation-free: every buffer lives in
// GownState. Deterministic: fixed orders everywhere (constraint lists, hash buckets, pairs).
// Speed: the constraints are solved colour group by colour group in blocks of 4 (model.h), by
// the AVX2 kernels (solver_avx2.cpp) when the CPU has AVX2, else by the scalar ones here; both
// give the same bits (kernels.h).
#include <algorithm>
#include <cmath>

#include "constraints.h"
#include "kernels.h"
#include "model.h"

namespace dressguard::sim {
namespace {

// The arm candidates of a vertex at `x` moving at `v`: up to two round cones whose surface is
// within the margin (contact offset + 1 cm + twice this step's travel); the exact distance is
// re-evaluated every substep against these (two are enough at the elbow where the forearm and
// upper arm meet). `extra` widens the margin (watch_arms()).
ArmCandidates arm_candidates(const GownModel& m, V3 x, V3 v, double extra) {
  ArmCandidates c;
  const double margin = m.scene->opt.contact_offset + 0.01 + 2.0 * norm(v) * m.dt + extra;
  double best[2] = {1e300, 1e300};
  for (int k = 0; k < static_cast<int>(m.arm.size()); ++k) {
    // A bounding sphere first: every point of a round cone lies within len / 2 + max(ra, rb)
    // of its axis' midpoint, so phi >= |x - mid| - that. A vertex beyond it by the margin
    // (and 1e-9 m against rounding) skips the exact distance, which would reject it too.
    const RoundCone& cone = m.arm[k];
    const V3 d = x - 0.5 * (cone.a + cone.b);
    const double reach = 0.5 * cone.len + std::max(cone.ra, cone.rb) + margin + 1e-9;
    if (dot(d, d) > reach * reach) continue;
    V3 nrm;
    const double phi = round_cone_distance(cone, x, &nrm);
    if (phi >= margin) continue;
    if (phi < best[0]) {
      best[1] = best[0];
      c.c[1] = c.c[0];
      best[0] = phi;
      c.c[0] = static_cast<int8_t>(k);
    } else if (phi < best[1]) {
      best[1] = phi;
      c.c[1] = static_cast<int8_t>(k);
    }
  }
  return c;
}

// Arm candidates of every free vertex, found once per output step. The vertices with candidates
// (all free ones when there are planes) are listed for solve_contacts().
void detect_arm(const GownModel& m, GownState& s) {
  const SceneData& sc = *m.scene;
  const int n = static_cast<int>(s.x.size());
  const bool planes = !sc.planes.empty();
  s.contact_count = 0;
  // A moving arm: its cones where the step starts, the margin wider by the step's arm travel.
  const V3 shift = s.arm_shift_from;
  const double arm_travel = norm(s.arm_shift_to - s.arm_shift_from);
  for (int i = 0; i < n; ++i) {
    const ArmCandidates c =
        sc.grasped[i] || m.arm.empty() ? ArmCandidates{} : arm_candidates(m, s.x[i] - shift, s.v[i], arm_travel);
    s.cand[i] = c;
    if (c.c[0] < 0) s.anchored[i] = 0;
    // The support where the step starts; the margin wider by the step's rise.
    bool near_support = false;
    if (m.has_support && !sc.grasped[i]) {
      const double margin = sc.opt.contact_offset + 0.01 + 2.0 * norm(s.v[i]) * m.dt +
                            std::abs(s.support_lift_from - s.support_lift_to);
      V3 nrm;
      near_support = round_cone_distance(m.support, s.x[i] + V3{0, 0, s.support_lift_from}, &nrm) < margin;
    }
    s.support_cand[i] = near_support;
    if (!sc.grasped[i] && (c.c[0] >= 0 || planes || near_support)) s.contact_list[s.contact_count++] = i;
  }
}

// floor(v) as an integer without a library call (std::floor is one without SSE4.1); exact for
// |v| < 2^63, far beyond any cell coordinate here.
inline int64_t floor_i64(double v) {
  const int64_t t = static_cast<int64_t>(v);
  return t - (static_cast<double>(t) > v);
}

// The hash slot of a row of cells, (iy, iz), with cell ix of the row at slot (row + ix) & mask:
// the cells of a row are consecutive slots, so up to 3 neighbouring cells of a row are one range
// of the counting sort (a window). The row's slot is 4 G with G's low 4 bits (iy mod 4, iz mod 4):
// two rows of one 3 x 3 neighbourhood (|dy|, |dz| <= 2) differ there, so their G differ modulo
// the table / 4 (at least 16 slots), their slots by a nonzero multiple of 4 modulo the table, and
// the windows of different rows never overlap: every vertex is a candidate once.
inline uint64_t row_slot(int64_t iy, int64_t iz) {
  const uint64_t p = static_cast<uint64_t>(iy) * 19349663ULL ^ static_cast<uint64_t>(iz) * 83492791ULL;
  return ((p << 4) | ((static_cast<uint64_t>(iy) & 3) << 2) | (static_cast<uint64_t>(iz) & 3)) << 2;
}

// Self-collision candidates (paper IV-A.3): a spatial hash of the vertices, built once per output
// step by a counting sort; pairs closer than the search radius, excluding pairs whose rest
// distance is within the search radius (mesh neighbours) and pairs of two grasped vertices.
// The pairs are listed in (i, j) order, i < j: the order of the Gauss-Seidel pass of solve_self()
// depends on the pair set only, not on the hash.
void detect_self(const GownModel& m, GownState& s) {
  const SceneData& sc = *m.scene;
  s.pair_count = 0;
  const int n = static_cast<int>(s.x.size());
  const double ds = sc.opt.self_distance;
  // Search radius: 1.5 collision distances, so pairs closing by up to half a collision distance
  // per output step (1.8 m/s relative at 12 mm, 300 Hz) are caught. It must stay below the mesh
  // edge: vertices nearer than that at rest are mesh neighbours, never self-collision pairs.
  const double r = 1.5 * ds;
  // Cells as wide as the search radius (1e-9 wider, so that two points nearer than r never have
  // cell coordinates 2 apart after the rounding of x / cell): the neighbours within r of a point
  // lie in the 3 x 3 x 3 cells around its own. Each pair is looked for once, from the vertex
  // whose cell comes first in (z, y, x) order: a vertex visits its own cell (the later vertices
  // there) and the 13 cells after it, as 5 windows of consecutive slots (row_slot()): the rows
  // (y, z + 1), (y +- 1, z + 1), (y + 1, z) and cells x, x + 1 of its own row. Against cells of
  // 2 r and their 2 x 2 x 2 block, from both sides: about a quarter of the candidates.
  const double inv = 1.0 / (r * (1 + 1e-9));
  const uint32_t table = static_cast<uint32_t>(s.cell_start.size() - 1);
  const uint32_t mask = table - 1;
  std::fill(s.cell_start.begin(), s.cell_start.end(), 0);
  for (int i = 0; i < n; ++i) {
    const V3 q = s.x[i];
    const uint32_t h = static_cast<uint32_t>(row_slot(floor_i64(q.y * inv), floor_i64(q.z * inv)) +
                                             static_cast<uint64_t>(floor_i64(q.x * inv))) & mask;
    s.cell_of[i] = h;
    s.cell_start[h + 1]++;
  }
  for (uint32_t k = 0; k < table; ++k) s.cell_start[k + 1] += s.cell_start[k];
  // Scatter in vertex order using cell_start as cursors, then restore the starts. The positions
  // are copied in cell order too, so that the candidate loop below reads them in sequence.
  for (int i = 0; i < n; ++i) {
    const int32_t a = s.cell_start[s.cell_of[i]]++;
    s.cell_sorted[a] = i;
    s.cell_x[a] = s.x[i];
  }
  for (uint32_t k = table; k > 0; --k) s.cell_start[k] = s.cell_start[k - 1];
  s.cell_start[0] = 0;
  const double r2 = r * r, excl2 = r2;
  const size_t cap = s.pairs.size();
  const int32_t* start = s.cell_start.data();
  const int32_t* sorted = s.cell_sorted.data();
  const V3* cx_sorted = s.cell_x.data();
  int32_t* slots = s.self_scratch.data();
  for (int i = 0; i < n; ++i) {
    const V3 q = s.x[i];
    const int64_t cx = floor_i64(q.x * inv), cy = floor_i64(q.y * inv), cz = floor_i64(q.z * inv);
    // The candidates' slots (positions in cell order), window after window, the own cell's slot
    // first. Short windows are listed with a fixed count of 8 writes and the list advanced by
    // their size: a loop whose length varied with each window would mispredict its exit at every
    // window, which cost more than the candidates themselves. The windows are disjoint
    // (row_slot()), so at most n slots plus 8 written beyond (self_scratch holds n + 8).
    int nslots = 0;
    auto list = [&](int32_t a0, int32_t a1) {
      const int32_t count = a1 - a0;
      if (count <= 8) {
        for (int t = 0; t < 8; ++t) slots[nslots + t] = a0 + t;
        nslots += count;
      } else {
        for (int t = 0; t < count; ++t) slots[nslots++] = a0 + t;
      }
    };
    // Cells [x0, x0 + len) of row (y, z); a window may wrap around the table's end.
    auto window = [&](int64_t y, int64_t z, int64_t x0, uint32_t len) {
      const uint32_t w = static_cast<uint32_t>(row_slot(y, z) + static_cast<uint64_t>(x0)) & mask;
      if (w + len <= table) {
        list(start[w], start[w + len]);
      } else {
        list(start[w], start[table]);
        list(start[0], start[w + len - table]);
      }
    };
    window(cy, cz, cx, 1);
    // The own cell's slot may hold other cells too (hash collisions), but none within r of q:
    // those are in other windows' slots. Only its later vertices pair with i from here.
    const int own = nslots;
    window(cy, cz, cx + 1, 1);
    window(cy + 1, cz, cx - 1, 3);
    for (int dy = -1; dy <= 1; ++dy) window(cy + dy, cz + 1, cx - 1, 3);
    // The close vertices, compacted in place without a branch per candidate (the tests would
    // go either way at random): each is written, and kept by advancing the count.
    int nclose = 0;
    for (int c = 0; c < nslots; ++c) {
      const int32_t a = slots[c];
      const V3 d = cx_sorted[a] - q;
      const int j = sorted[a];
      slots[nclose] = j;
      nclose += (dot(d, d) < r2) & ((j > i) | (c >= own));
    }
    for (int c = 0; c < nclose; ++c) {
      const int j = slots[c];
      if (sc.grasped[i] && sc.grasped[j]) continue;
      const V3 dr = sc.rest[j] - sc.rest[i];
      if (dot(dr, dr) < excl2) continue;
      if (s.pair_count < cap) {
        s.pairs[s.pair_count++] = {std::min(i, j), std::max(i, j)};
      } else {
        s.pairs_dropped++;
      }
    }
  }
  // (i, j) order (a few hundred pairs: well below a percent of the detection). Should the list
  // ever be full, which pairs were dropped would depend on the hash (pairs_dropped counts them).
  std::sort(s.pairs.begin(), s.pairs.begin() + static_cast<long>(s.pair_count), [](SelfPair a, SelfPair b) {
    return a.i != b.i ? a.i < b.i : a.j < b.j;
  });
}

// Integration: the grasped vertices follow the gripper, the others move under gravity, the
// perturbation and velocity damping (symplectic Euler prediction of XPBD). With `velocities`,
// first v = (x - p) / h, the velocity update that ends the previous substep (update_velocities()):
// one pass over the vertices instead of two. The pass treats every vertex as free (no branch per
// vertex), then the grasped ones are placed; their velocity is not read until the step's final
// update_velocities() sets it from their motion.
template <bool velocities>
void integrate(const GownModel& m, GownState& s, V3 grip) {
  const SceneData& sc = *m.scene;
  const int n = static_cast<int>(s.x.size());
  const double h = m.h, inv_h = 1.0 / m.h, decay = m.damping_factor;
  const double* w = m.w.data();
  const V3 g = m.gravity;
  V3 *x = s.x.data(), *p = s.p.data(), *vel = s.v.data();
  // Without a perturbation the force array is not read (g + w 0 = g exactly: the same bits).
  const V3* f = s.ext_force_on ? s.ext_force.data() : nullptr;
  if (m.path == KernelPath::Avx2) {
    integrate_avx2(n, velocities, h, inv_h, decay, g, w, f, x, p, vel);
  } else {
    for (int i = 0; i < n; ++i) {
      if constexpr (velocities) vel[i] = inv_h * (x[i] - p[i]);
      p[i] = x[i];
      V3 v = decay * vel[i];
      v += h * (f ? g + w[i] * f[i] : g);
      vel[i] = v;
      x[i] += h * v;
    }
  }
  for (int i : sc.grasp_list) x[i] = sc.rest[i] + s.jaw_closed * (sc.grasp_target[i] - sc.rest[i]) + grip;
}

// The scalar kernels: a block lane by lane through the constraint functions of constraints.h
// (the AVX2 kernels of solver_avx2.cpp mirror them). The force that constraints touching grasped
// vertices exert on them is added to `force` (XPBD: f = grad C lambda / h^2). Only for those:
// the other constraints' terms are +-0, and adding them would not change a sum that starts at +0
// (x + (+-0) = x for x != 0 and for x = +0), so both paths give the same bits.

void stretch_scalar(const StretchBlock& b, V3* x, const uint8_t* grasped, double inv_h2, V3& force) {
  for (int l = 0; l < 4; ++l) {
    const int i = b.i[l], j = b.j[l];
    if (i < 0) break;
    V3 nrm;
    const double dl = distance_constraint(x[i], x[j], b.wi[l], b.wj[l], b.rest[l], b.inv_t[l], b.inv_c[l], &nrm);
    if (grasped[i] | grasped[j]) stretch_force(i, j, dl, nrm, grasped, inv_h2, force);
  }
}

void shear_scalar(const ShearBlock& b, V3* x, const uint8_t* grasped, double inv_h2, V3& force) {
  for (int l = 0; l < 4; ++l) {
    const int v[3] = {b.v[0][l], b.v[1][l], b.v[2][l]};
    if (v[0] < 0) break;
    const double dm[4] = {b.a[l], b.b[l], b.c[l], b.d[l]};
    V3 g[3];
    const double dl = shear_constraint(x[v[0]], x[v[1]], x[v[2]], b.w0[l], b.w1[l], b.w2[l], dm, b.alpha_t[l], g);
    if (grasped[v[0]] | grasped[v[1]] | grasped[v[2]]) shear_force(v, dl, g, grasped, inv_h2, force);
  }
}

void bend_scalar(const BendBlock& b, V3* x, const uint8_t* grasped, double inv_h2, V3& force) {
  for (int l = 0; l < 4; ++l) {
    const int v[4] = {b.v[0][l], b.v[1][l], b.v[2][l], b.v[3][l]};
    if (v[0] < 0) break;
    const double k[4] = {b.k[0][l], b.k[1][l], b.k[2][l], b.k[3][l]};
    const double wk[4] = {b.wk[0][l], b.wk[1][l], b.wk[2][l], b.wk[3][l]};
    const V3 dl = bending_constraint(x[v[0]], x[v[1]], x[v[2]], x[v[3]], k, wk, b.neg_inv_denom[l]);
    if (grasped[v[0]] | grasped[v[1]] | grasped[v[2]] | grasped[v[3]]) bend_force(v, k, dl, grasped, inv_h2, force);
  }
}

// One constraint kind, colour group by colour group: the free blocks, then the careful ones.
template <class Block, class Scalar, class Free, class Careful>
void solve_kind(const GownModel& m, GownState& s, const std::vector<Block>& blocks, const std::vector<BlockSpan>& spans,
                Scalar scalar, Free free, Careful careful, double inv_h2, V3& force) {
  const uint8_t* grasped = m.scene->grasped.data();
  V3* x = s.x.data();
  const Block* bl = blocks.data();
  if (m.path == KernelPath::Avx2) {
    for (const BlockSpan& sp : spans) {
      free(bl + sp.begin, bl + sp.simd_end, x);
      careful(bl + sp.simd_end, bl + sp.end, x, grasped, inv_h2, force);
    }
  } else {
    for (const BlockSpan& sp : spans)
      for (int32_t k = sp.begin; k < sp.end; ++k) scalar(bl[k], x, grasped, inv_h2, force);
  }
}

// One contact against a collider with the chosen friction scheme; `move` is the collider
// surface's displacement over this substep (the arm's, zero for a fixed arm and the planes):
// friction acts on the slip relative to it, so the vertex's start point is taken as p + move.
inline void collide_static(const GownModel& m, GownState& s, int i, double phi, V3 nrm, V3 move) {
  const double dn = contact_constraint(s.x[i], phi, nrm, m.scene->opt.contact_offset);
  if (dn <= 0) return;
  s.contact_n[i] = nrm;
  s.contact_dn[i] += dn;
  if (m.scheme == FrictionScheme::Improved) {
    friction_position(s.x[i], s.p[i] + move, nrm, dn, m.friction);
  } else if (m.scheme == FrictionScheme::Constraint) {
    if (!s.anchored[i]) {
      s.anchor[i] = s.p[i];
      s.anchored[i] = 1;
    }
    // The stick point rides on the (moving) surface. A vertex touching two cones in one substep
    // gets the move twice (friction_anchor resets the anchor to x after the first): an error of
    // one substep's arm move, about 1e-6 m, accepted to keep the contact pass per collider.
    s.anchor[i] += move;
    friction_anchor(s.x[i], s.anchor[i], nrm, dn, m.friction, m.friction * m.scene->opt.kinetic_ratio);
  }
}

// Contacts with the arm's candidate round cones and the test planes, for the vertices listed by
// detect_arm(); the collision force on each vertex (paper eq. 2: f = m dx_col / h^2) is
// accumulated for the per-vertex contact map.
void solve_contacts(const GownModel& m, GownState& s, double inv_h2, double lift, V3 support_move) {
  const SceneData& sc = *m.scene;
  const double off = sc.opt.contact_offset;
  for (size_t q = 0; q < s.contact_count; ++q) {
    const int i = s.contact_list[q];
    const V3 before = s.x[i];
    const double dn_before = s.contact_dn[i];
    for (int k = 0; k < 2; ++k) {
      const int c = s.cand[i].c[k];
      if (c < 0) break;
      V3 nrm;
      const double phi = round_cone_distance(m.arm[c], s.x[i] - s.arm_shift, &nrm);
      const V3 pre = s.x[i];
      collide_static(m, s, i, phi, nrm, s.arm_move);
      s.part_acc[static_cast<size_t>(c)] += (m.mass[i] * inv_h2) * (s.x[i] - pre);
    }
    for (const HalfSpace& pl : sc.planes) {
      const double phi = dot(pl.n, s.x[i]) - pl.d;
      if (phi - off > 1e-3) s.anchored[i] = 0;
      collide_static(m, s, i, phi, pl.n, V3{0, 0, 0});
    }
    if (s.contact_dn[i] > dn_before) {
      s.contact_acc[i] += (m.mass[i] * inv_h2) * (s.x[i] - before);
      s.arm_corrected = true;
    }
    // The support: not the arm, so neither in the contact map nor in what the arm touched.
    if (s.support_cand[i]) {
      V3 nrm;
      const V3 pre = s.x[i];
      const double dn_arm = s.contact_dn[i];
      collide_static(m, s, i, round_cone_distance(m.support, s.x[i] + V3{0, 0, lift}, &nrm), nrm, support_move);
      if (s.contact_dn[i] > dn_arm) s.support_acc += (m.mass[i] * inv_h2) * (s.x[i] - pre);
    }
  }
}

// Self-collision with self-friction (paper IV-A.3): vertex pairs kept `ds` apart, and their
// relative tangential slip of this substep removed up to mu_self times the normal correction
// (the same rule as against the arm; none in the Stock scheme, as in stock PhysX).
void solve_self(const GownModel& m, GownState& s, double inv_h2, V3& force) {
  const double ds = m.scene->opt.self_distance, mus = m.self_friction;
  const bool position_friction = m.scheme != FrictionScheme::Stock && mus > 0;
  for (size_t k = 0; k < s.pair_count; ++k) {
    const int i = s.pairs[k].i, j = s.pairs[k].j;
    const double wi = m.w[i], wj = m.w[j], wsum = wi + wj;
    const V3 d = s.x[i] - s.x[j];
    const double len2 = dot(d, d);
    if (len2 >= ds * ds || wsum <= 0 || len2 < 1e-24) continue;
    const double len = std::sqrt(len2);
    const V3 nrm = (1.0 / len) * d;
    const double dl = (ds - len) / wsum;
    const V3 xi0 = s.x[i], xj0 = s.x[j];
    s.x[i] += (wi * dl) * nrm;
    s.x[j] -= (wj * dl) * nrm;
    if (position_friction) {
      const V3 u = (s.x[i] - s.p[i]) - (s.x[j] - s.p[j]);
      const V3 ut = u - dot(u, nrm) * nrm;
      const double lt = norm(ut);
      if (lt > 1e-15) {
        const double f = std::min(1.0, mus * (ds - len) / lt) / wsum;
        s.x[i] -= (wi * f) * ut;
        s.x[j] += (wj * f) * ut;
      }
    }
    // A grasped (kinematic) vertex pushing a free one: the reaction, -m dx / h^2 of the free
    // vertex's correction (eq. 2), loads the gripper.
    if (wi == 0) force -= (m.mass[j] * inv_h2) * (s.x[j] - xj0);
    if (wj == 0) force -= (m.mass[i] * inv_h2) * (s.x[i] - xi0);
  }
}

// v = (x - p) / h, after the last substep (integrate<true> does it for the others).
void update_velocities(const GownModel& m, GownState& s) {
  const int n = static_cast<int>(s.x.size());
  const double inv_h = 1.0 / m.h;
  for (int i = 0; i < n; ++i) s.v[i] = inv_h * (s.x[i] - s.p[i]);
}

// Stock PBD friction, once per output step: the tangential velocity loses at most mu times the
// step's normal velocity change (sum of the substeps' normal corrections / h).
void stock_friction(const GownModel& m, GownState& s) {
  const int n = static_cast<int>(s.x.size());
  for (int i = 0; i < n; ++i)
    if (s.contact_dn[i] > 0) friction_velocity(s.v[i], s.contact_n[i], s.contact_dn[i], m.friction, m.h);
}

// Where solve_contacts() would have moved a listed vertex, had a watched arm been placed there
// (watch_arms()): within the contact offset of any of its cones (1 um wider, as the listing).
void check_watched_arms(const GownModel& m, GownState& s) {
  const double reach = m.scene->opt.contact_offset + 1e-6;
  for (const ArmWatch& w : s.watch)
    for (const RoundCone& cone : m.arm) {
      V3 nrm;
      if (round_cone_distance(cone, s.x[w.vertex] - s.arm_shift - V3{0, 0, w.dz}, &nrm) < reach) {
        s.watch_touched = true;
        return;
      }
    }
}

// One substep; `first`: the step's first substep (the velocities are current), else the
// previous substep's velocity update is fused into the integration.
void substep(const GownModel& m, GownState& s, V3 grip, V3 grip_accel, bool first, double lift, V3 support_move) {
  const SceneData& sc = *m.scene;
  const double inv_h2 = 1.0 / (m.h * m.h);
  if (first) {
    integrate<false>(m, s, grip);
  } else {
    integrate<true>(m, s, grip);
  }
  V3 force{0, 0, 0};  // of the gown on the gripper, this substep
  solve_kind(m, s, m.stretch_blocks, m.stretch_spans, stretch_scalar, stretch_free_avx2, stretch_careful_avx2, inv_h2,
             force);
  solve_kind(m, s, m.shear_blocks, m.shear_spans, shear_scalar, shear_free_avx2, shear_careful_avx2, inv_h2, force);
  solve_kind(m, s, m.bend_blocks, m.bend_spans, bend_scalar, bend_free_avx2, bend_careful_avx2, inv_h2, force);
  solve_contacts(m, s, inv_h2, lift, support_move);
  if (!s.watch.empty() && !s.watch_touched) check_watched_arms(m, s);
  if (m.self_collision) solve_self(m, s, inv_h2, force);
  // The grasped vertices' own weight and inertia also load the gripper.
  for (int g : sc.grasp_list) force += m.mass[g] * (m.gravity - grip_accel);
  s.force_acc += force;
  s.force_count++;
}

}  // namespace

bool watch_arms(const GownModel& m, GownState& s, const std::vector<double>& dz) {
  const SceneData& sc = *m.scene;
  s.watch.clear();
  if (m.arm.empty()) return false;
  // The arm moved by dz is the vertex moved by -dz; 1 um more margin covers the rounding of
  // that move, so that a vertex not listed here is never a candidate of an arm placed there.
  for (double d : dz)
    for (size_t i = 0; i < s.x.size(); ++i)
      if (!sc.grasped[i] && arm_candidates(m, s.x[i] - s.arm_shift_from - V3{0, 0, d}, s.v[i], 1e-6).c[0] >= 0)
        s.watch.push_back({static_cast<int32_t>(i), d});
  return !s.watch.empty();
}

void place_arm(GownModel& m, double arm_dz) {
  m.arm = (m.fist_shift == 0 && m.fist_lateral == 0) || m.scene->arm.empty()
              ? m.scene->arm
              : arm_colliders(m.scene->opt, m.fist_shift, m.fist_lateral);
  const V3 d{0, m.arm_lateral, arm_dz};
  for (auto& c : m.arm) {
    c.a = c.a + d;
    c.b = c.b + d;
  }
  m.elbow = m.scene->elbow + d;
}

void step(const GownModel& m, GownState& s, V3 grip_from, V3 grip_to, V3 grip_accel) {
  s.ext_force_on = false;
  for (const V3& f : s.ext_force) s.ext_force_on |= (f.x != 0) | (f.y != 0) | (f.z != 0);
  detect_arm(m, s);
  if (m.self_collision) detect_self(m, s);
  std::fill(s.contact_dn.begin(), s.contact_dn.end(), 0.0);
  s.arm_corrected = false;
  double lift = s.support_lift_from;
  for (int k = 0; k < m.substeps; ++k) {
    const double f = static_cast<double>(k + 1) / m.substeps;
    const V3 grip = grip_from + f * (grip_to - grip_from);
    s.grip_offset = grip;
    const V3 arm = s.arm_shift_from + f * (s.arm_shift_to - s.arm_shift_from);
    s.arm_move = arm - s.arm_shift;
    s.arm_shift = arm;
    const double lift_next = s.support_lift_from + f * (s.support_lift_to - s.support_lift_from);
    substep(m, s, grip, grip_accel, k == 0, lift_next, V3{0, 0, lift - lift_next});
    lift = lift_next;
  }
  update_velocities(m, s);
  if (m.scheme == FrictionScheme::Stock) stock_friction(m, s);
}

}  // namespace dressguard::sim
