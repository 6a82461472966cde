// The XPBD "small steps" solver (Macklin et al. 2019): one output step = collision detection
// once, then `substeps` x (integrate, solve each constraint once in a fixed Gauss-Seidel order,
// resolve contacts with friction, update velocities). Allocation-free: every buffer lives in
// GownState. Deterministic: fixed orders everywhere (constraint lists, hash buckets, pairs).
#include <algorithm>
#include <cmath>

#include "constraints.h"
#include "model.h"

namespace dressguard::sim {
namespace {

// Arm candidates of every free vertex within a margin of the surface: the exact distance is
// re-evaluated every substep against these (at most two round cones per vertex, enough at the
// elbow where the forearm and upper arm meet).
void detect_arm(const GownModel& m, GownState& s) {
  const SceneData& sc = *m.scene;
  const double base = sc.opt.contact_offset + 0.01;
  const int n = static_cast<int>(s.x.size());
  const int shapes = static_cast<int>(m.arm.size());
  for (int i = 0; i < n; ++i) {
    ArmCandidates c;
    if (!sc.grasped[i] && shapes > 0) {
      const double margin = base + 2.0 * norm(s.v[i]) * m.dt;
      double best[2] = {1e300, 1e300};
      for (int k = 0; k < shapes; ++k) {
        V3 nrm;
        const double phi = round_cone_distance(m.arm[k], s.x[i], &nrm);
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
    }
    s.cand[i] = c;
    if (c.c[0] < 0) s.anchored[i] = 0;
  }
}

inline uint32_t hash_cell(int64_t ix, int64_t iy, int64_t iz, uint32_t mask) {
  const uint64_t h = static_cast<uint64_t>(ix) * 73856093ULL ^ static_cast<uint64_t>(iy) * 19349663ULL ^
                     static_cast<uint64_t>(iz) * 83492791ULL;
  return static_cast<uint32_t>(h) & mask;
}

// Self-collision candidates (paper IV-A.3): a spatial hash of the vertices with cells as wide as
// the search radius, built once per output step by a counting sort; pairs closer than the search
// radius, excluding pairs whose rest distance is already within 1.5 collision distances (mesh
// neighbours) and pairs of two grasped vertices.
void detect_self(const GownModel& m, GownState& s) {
  const SceneData& sc = *m.scene;
  s.pair_count = 0;
  const int n = static_cast<int>(s.x.size());
  const double ds = sc.opt.self_distance;
  double vmax = 0;
  for (int i = 0; i < n; ++i) vmax = std::max(vmax, dot(s.v[i], s.v[i]));
  vmax = std::sqrt(vmax);
  const double r = ds + std::clamp(2.0 * vmax * m.dt, 0.5 * ds, 2.0 * ds);
  const double inv = 1.0 / r;
  const uint32_t table = static_cast<uint32_t>(s.cell_start.size() - 1);
  const uint32_t mask = table - 1;
  std::fill(s.cell_start.begin(), s.cell_start.end(), 0);
  for (int i = 0; i < n; ++i) {
    const V3 q = s.x[i];
    const uint32_t h = hash_cell(static_cast<int64_t>(std::floor(q.x * inv)), static_cast<int64_t>(std::floor(q.y * inv)),
                                 static_cast<int64_t>(std::floor(q.z * inv)), mask);
    s.cell_of[i] = h;
    s.cell_start[h + 1]++;
  }
  for (uint32_t k = 0; k < table; ++k) s.cell_start[k + 1] += s.cell_start[k];
  // Scatter in vertex order using cell_start as cursors, then restore the starts.
  for (int i = 0; i < n; ++i) s.cell_sorted[s.cell_start[s.cell_of[i]]++] = i;
  for (uint32_t k = table; k > 0; --k) s.cell_start[k] = s.cell_start[k - 1];
  s.cell_start[0] = 0;
  const double r2 = r * r, excl2 = (1.5 * ds) * (1.5 * ds);
  const size_t cap = s.pairs.size();
  for (int i = 0; i < n; ++i) {
    const V3 q = s.x[i];
    const int64_t cx = static_cast<int64_t>(std::floor(q.x * inv)), cy = static_cast<int64_t>(std::floor(q.y * inv)),
                  cz = static_cast<int64_t>(std::floor(q.z * inv));
    uint32_t seen[27];
    int nseen = 0;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const uint32_t h = hash_cell(cx + dx, cy + dy, cz + dz, mask);
          bool dup = false;
          for (int k = 0; k < nseen; ++k) dup |= seen[k] == h;
          if (dup) continue;
          seen[nseen++] = h;
          for (int32_t a = s.cell_start[h]; a < s.cell_start[h + 1]; ++a) {
            const int j = s.cell_sorted[a];
            if (j <= i) continue;
            if (sc.grasped[i] && sc.grasped[j]) continue;
            const V3 d = s.x[j] - q;
            if (dot(d, d) >= r2) continue;
            const V3 dr = sc.rest[j] - sc.rest[i];
            if (dot(dr, dr) < excl2) continue;
            if (s.pair_count < cap) {
              s.pairs[s.pair_count++] = {i, j};
            } else {
              s.pairs_dropped++;
            }
          }
        }
  }
}

void substep(const GownModel& m, GownState& s, V3 grip, V3 grip_accel, bool last_of_sample_unused) {
  const SceneData& sc = *m.scene;
  const int n = static_cast<int>(s.x.size());
  const double h = m.h, inv_h = 1.0 / h, inv_h2 = 1.0 / (h * h);
  const double decay = m.damping_factor;
  // Integrate: the grasped vertices follow the gripper, the others fall.
  for (int i = 0; i < n; ++i) {
    s.p[i] = s.x[i];
    if (sc.grasped[i]) {
      s.x[i] = sc.rest[i] + grip;
      continue;
    }
    V3 v = decay * s.v[i];
    v += h * (m.gravity + m.w[i] * s.ext_force[i]);
    s.v[i] = v;
    s.x[i] += h * v;
  }
  V3 force{0, 0, 0};  // of the gown on the gripper, this substep
  // Stretch and shear: distance constraints.
  const double at_stretch = m.alpha_stretch * inv_h2, at_shear = m.alpha_shear * inv_h2, at_bend = m.alpha_bend * inv_h2;
  for (const DistanceLink& l : sc.stretch) {
    V3 nrm;
    const double dl = distance_constraint(s.x[l.i], s.x[l.j], m.w[l.i], m.w[l.j], l.rest, at_stretch, &nrm);
    if (sc.grasped[l.i]) force += (dl * inv_h2) * nrm;
    if (sc.grasped[l.j]) force -= (dl * inv_h2) * nrm;
  }
  for (const DistanceLink& l : sc.shear) {
    V3 nrm;
    const double dl = distance_constraint(s.x[l.i], s.x[l.j], m.w[l.i], m.w[l.j], l.rest, at_shear, &nrm);
    if (sc.grasped[l.i]) force += (dl * inv_h2) * nrm;
    if (sc.grasped[l.j]) force -= (dl * inv_h2) * nrm;
  }
  // Bending.
  for (const BendStencil& b : sc.bend) {
    const double w4[4] = {m.w[b.v[0]], m.w[b.v[1]], m.w[b.v[2]], m.w[b.v[3]]};
    V3 kx{0, 0, 0};
    const bool touches = sc.grasped[b.v[0]] | sc.grasped[b.v[1]] | sc.grasped[b.v[2]] | sc.grasped[b.v[3]];
    if (touches)
      for (int a = 0; a < 4; ++a) kx += b.k[a] * s.x[b.v[a]];
    const double dl = bending_constraint(&s.x[b.v[0]], &s.x[b.v[1]], &s.x[b.v[2]], &s.x[b.v[3]], w4, b.k, at_bend);
    if (touches && dl != 0) {
      const V3 nrm = (1.0 / norm(kx)) * kx;
      for (int a = 0; a < 4; ++a)
        if (sc.grasped[b.v[a]]) force += (b.k[a] * dl * inv_h2) * nrm;
    }
  }
  // Contacts with the arm (and test planes), friction by the chosen scheme.
  const double off = sc.opt.contact_offset;
  const double mu = m.friction;
  for (int i = 0; i < n; ++i) {
    s.contact_dn[i] = 0;
    if (sc.grasped[i]) continue;
    const V3 before = s.x[i];
    for (int k = 0; k < 2; ++k) {
      const int c = s.cand[i].c[k];
      if (c < 0) break;
      V3 nrm;
      const double phi = round_cone_distance(m.arm[c], s.x[i], &nrm);
      const double dn = contact_constraint(s.x[i], phi, nrm, off);
      if (dn <= 0) continue;
      s.contact_n[i] = nrm;
      s.contact_dn[i] = dn;
      if (m.scheme == FrictionScheme::Improved) {
        friction_position(s.x[i], s.p[i], nrm, dn, mu);
      } else if (m.scheme == FrictionScheme::Constraint) {
        if (!s.anchored[i]) {
          s.anchor[i] = s.p[i];
          s.anchored[i] = 1;
        }
        friction_anchor(s.x[i], s.anchor[i], nrm, dn, mu, mu * sc.opt.kinetic_ratio);
      }
    }
    for (const HalfSpace& pl : sc.planes) {
      const double phi = dot(pl.n, s.x[i]) - pl.d;
      const double dn = contact_constraint(s.x[i], phi, pl.n, off);
      if (dn <= 0) {
        if (phi - off > 1e-3) s.anchored[i] = 0;
        continue;
      }
      s.contact_n[i] = pl.n;
      s.contact_dn[i] = dn;
      if (m.scheme == FrictionScheme::Improved) {
        friction_position(s.x[i], s.p[i], pl.n, dn, mu);
      } else if (m.scheme == FrictionScheme::Constraint) {
        if (!s.anchored[i]) {
          s.anchor[i] = s.p[i];
          s.anchored[i] = 1;
        }
        friction_anchor(s.x[i], s.anchor[i], pl.n, dn, mu, mu * sc.opt.kinetic_ratio);
      }
    }
    // Paper eq. 2: the collision force on the vertex is m dx_col / h^2.
    if (s.contact_dn[i] > 0) s.contact_acc[i] += (m.mass[i] * inv_h2) * (s.x[i] - before);
  }
  // Self-collision with self-friction (paper IV-A.3), vertex-vertex at distance ds.
  if (m.self_collision) {
    const double ds = sc.opt.self_distance, mus = m.self_friction;
    for (size_t k = 0; k < s.pair_count; ++k) {
      const int i = s.pairs[k].i, j = s.pairs[k].j;
      s.pair_dn[k] = 0;
      const double wi = m.w[i], wj = m.w[j], wsum = wi + wj;
      if (wsum <= 0) continue;
      const V3 d = s.x[i] - s.x[j];
      const double len = norm(d);
      if (len >= ds || len < 1e-12) continue;
      const V3 nrm = (1.0 / len) * d;
      const double dl = (ds - len) / wsum;
      s.x[i] += (wi * dl) * nrm;
      s.x[j] -= (wj * dl) * nrm;
      s.pair_dn[k] = ds - len;
      s.pair_n[k] = nrm;
      if (m.scheme != FrictionScheme::Stock && mus > 0) {
        // Relative tangential slip this substep, removed up to mus * (normal correction).
        const V3 u = (s.x[i] - s.p[i]) - (s.x[j] - s.p[j]);
        const V3 ut = u - dot(u, nrm) * nrm;
        const double lt = norm(ut);
        if (lt > 1e-15) {
          const double f = std::min(1.0, mus * (ds - len) / lt) / wsum;
          s.x[i] -= (wi * f) * ut;
          s.x[j] += (wj * f) * ut;
        }
      }
    }
  }
  // Velocities from positions.
  for (int i = 0; i < n; ++i) {
    if (sc.grasped[i]) {
      s.v[i] = inv_h * (s.x[i] - s.p[i]);
      continue;
    }
    s.v[i] = inv_h * (s.x[i] - s.p[i]);
    if (m.scheme == FrictionScheme::Stock && s.contact_dn[i] > 0)
      friction_velocity(s.v[i], s.contact_n[i], s.contact_dn[i], mu, h);
  }
  if (m.scheme == FrictionScheme::Stock && m.self_collision && m.self_friction > 0) {
    for (size_t k = 0; k < s.pair_count; ++k) {
      if (s.pair_dn[k] <= 0) continue;
      const int i = s.pairs[k].i, j = s.pairs[k].j;
      const double wi = m.w[i], wj = m.w[j], wsum = wi + wj;
      const V3 nrm = s.pair_n[k];
      const V3 u = s.v[i] - s.v[j];
      const V3 ut = u - dot(u, nrm) * nrm;
      const double lt = norm(ut);
      if (lt < 1e-15) continue;
      const double f = std::min(1.0, m.self_friction * s.pair_dn[k] / (h * lt)) / wsum;
      s.v[i] -= (wi * f) * ut;
      s.v[j] += (wj * f) * ut;
    }
  }
  // The grasped vertices' own weight and inertia also load the gripper.
  for (int g : sc.grasp_list) force += m.mass[g] * (m.gravity - grip_accel);
  s.force_acc += force;
  s.force_count++;
}

}  // namespace

void step(const GownModel& m, GownState& s, V3 grip_from, V3 grip_to, V3 grip_accel) {
  detect_arm(m, s);
  if (m.self_collision) detect_self(m, s);
  for (int k = 0; k < m.substeps; ++k) {
    const double f = static_cast<double>(k + 1) / m.substeps;
    const V3 grip = grip_from + f * (grip_to - grip_from);
    s.grip_offset = grip;
    substep(m, s, grip, grip_accel, false);
  }
}

}  // namespace dressguard::sim
