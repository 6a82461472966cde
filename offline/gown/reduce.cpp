// Mesh reduction by quadric-error-metric edge collapse (Garland & Heckbert, SIGGRAPH 1997),
// adapted to a cloth mesh that a simulator will run on:
//  - the cost of collapsing edge (a, b) into a point v is
//        E(v) = v^T (Q_a + Q_b) v  +  alpha * (|v - a|^2 + |v - b|^2)
//    where Q is the sum of the squared-distance quadrics of the planes of the original faces
//    around a vertex (G-H eq. 2) plus, for boundary edges, planes through the edge perpendicular
//    to its face (weight kBoundaryWeight, G-H section 5), so the openings keep their shape.
//    The alpha term (a point quadric) makes E strictly convex, so the optimum is one 3x3 solve,
//    and it makes flat regions (where Q alone is ~0 everywhere) collapse their shortest edges
//    first, at their midpoints: the reduced cloth keeps near-uniform triangles.
//  - frozen vertices (load_gown freezes the grasped patch, so the gripper holds the same cloth at
//    every resolution) neither move nor go; an edge's other end collapses onto them;
//  - a boundary vertex stays on its loop: two boundary vertices collapse only along a boundary
//    edge, an interior vertex collapses onto a boundary vertex's position;
//  - the link condition (the two end points share exactly the edge's opposite vertices) keeps
//    the mesh manifold; a collapse that turns a face by more than 60 degrees or leaves a face
//    with quality q = 4 sqrt(3) A / (l1^2 + l2^2 + l3^2) < 0.3 (equilateral 1) that was better
//    before is refused (no slivers).
// Deterministic: the queue orders by (cost, a, b); no hashing or pointers decide anything.
#include <algorithm>
#include <cmath>
#include <queue>
#include <stdexcept>

#include <Eigen/Dense>

#include "gown.h"
#include "placement.h"

namespace dressguard::gown {
namespace {

constexpr double kAlpha = 0.01;           // weight of the point quadrics (uniformity vs. shape)
constexpr double kBoundaryWeight = 10.0;  // weight of the boundary planes relative to face planes
constexpr double kMinQuality = 0.3;       // sliver threshold on q (an isosceles 120-30-30 has 0.58)
constexpr double kMaxTurnCos = 0.5;       // a face may not turn by more than 60 degrees

using Quadric = Eigen::Matrix4d;

Quadric plane_quadric(const Eigen::Vector3d& n, const Eigen::Vector3d& p, double w) {
  Eigen::Vector4d pl;
  pl << n, -n.dot(p);
  return w * pl * pl.transpose();
}

Quadric point_quadric(const Eigen::Vector3d& p, double w) {
  // |v - p|^2 = v.v - 2 p.v + p.p as a 4x4 quadric in homogeneous v.
  Quadric q = Quadric::Zero();
  q.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity();
  q.topRightCorner<3, 1>() = -p;
  q.bottomLeftCorner<1, 3>() = -p.transpose();
  q(3, 3) = p.squaredNorm();
  return w * q;
}

double eval(const Quadric& q, const Eigen::Vector3d& v) {
  const Eigen::Vector4d h(v.x(), v.y(), v.z(), 1.0);
  return h.dot(q * h);
}

double quality(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double s = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  const double area = 0.5 * (b - a).cross(c - a).norm();
  return s > 0 ? 4.0 * std::sqrt(3.0) * area / s : 0.0;
}

struct Candidate {
  double cost;
  int a, b;  // collapse b into a
  int stamp_a, stamp_b;
  Eigen::Vector3d target;
  bool operator>(const Candidate& o) const {
    if (cost != o.cost) return cost > o.cost;
    if (a != o.a) return a > o.a;
    return b > o.b;
  }
};

class Reducer {
 public:
  Reducer(const GownMesh& m, std::vector<bool> frozen) : x_(m.x), tris_(m.triangles), frozen_(std::move(frozen)) {
    const int nv = static_cast<int>(x_.size());
    frozen_.resize(nv, false);
    vf_.resize(nv);
    for (int f = 0; f < static_cast<int>(tris_.size()); ++f)
      for (int v : tris_[f]) vf_[v].push_back(f);
    alive_f_.assign(tris_.size(), true);
    alive_v_.assign(nv, true);
    stamp_.assign(nv, 0);
    boundary_.assign(nv, false);
    loop_of_.assign(nv, -1);
    Q_.assign(nv, Quadric::Zero());
    n_faces_ = static_cast<int>(tris_.size());
    for (const auto& t : tris_) {
      const Eigen::Vector3d n = (x_[t[1]] - x_[t[0]]).cross(x_[t[2]] - x_[t[0]]);
      if (n.norm() == 0) continue;
      const Quadric q = plane_quadric(n.normalized(), x_[t[0]], 1.0);
      for (int v : t) Q_[v] += q;
    }
    const auto loops = find_boundary_loops(tris_, nv);
    loop_count_.resize(loops.size());
    loop_min_.resize(loops.size());
    for (size_t l = 0; l < loops.size(); ++l) {
      const int n = static_cast<int>(loops[l].size());
      loop_count_[l] = n;
      // A loop keeps at least a quarter of its vertices and never fewer than 12: a 12-gon
      // inscribed in a circle has 98.9% of its perimeter.
      loop_min_[l] = std::max(12, n / 4);
      for (int i = 0; i < n; ++i) {
        const int a = loops[l][i], b = loops[l][(i + 1) % n];
        boundary_[a] = true;
        loop_of_[a] = static_cast<int>(l);
        // The plane through the boundary edge, perpendicular to its face.
        const auto faces = common_faces(a, b);
        if (faces.empty()) continue;
        const auto& t = tris_[faces.front()];
        const Eigen::Vector3d fn = (x_[t[1]] - x_[t[0]]).cross(x_[t[2]] - x_[t[0]]);
        const Eigen::Vector3d e = x_[b] - x_[a];
        const Eigen::Vector3d pn = e.cross(fn);
        if (pn.norm() == 0) continue;
        const Quadric q = plane_quadric(pn.normalized(), x_[a], kBoundaryWeight);
        Q_[a] += q;
        Q_[b] += q;
      }
    }
  }

  GownMesh run(int target_triangles, double density) {
    for (int v = 0; v < static_cast<int>(x_.size()); ++v) push_edges(v);
    while (n_faces_ > target_triangles && !heap_.empty()) {
      const Candidate c = heap_.top();
      heap_.pop();
      if (!alive_v_[c.a] || !alive_v_[c.b] || stamp_[c.a] != c.stamp_a || stamp_[c.b] != c.stamp_b) continue;
      if (!collapse_allowed(c.a, c.b, c.target)) continue;
      collapse(c.a, c.b, c.target);
    }
    return compact(density);
  }

 private:
  std::vector<int> common_faces(int a, int b) const {
    std::vector<int> out;
    for (int f : vf_[a])
      if (alive_f_[f] && (tris_[f][0] == b || tris_[f][1] == b || tris_[f][2] == b)) out.push_back(f);
    return out;
  }

  std::vector<int> neighbours(int v) const {
    std::vector<int> out;
    for (int f : vf_[v])
      if (alive_f_[f])
        for (int u : tris_[f])
          if (u != v) out.push_back(u);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  // The best (a <- b) collapse of edge {u, w} with its target, or none when it is not allowed
  // by the boundary rules.
  void push_edge(int u, int w) {
    int a = u, b = w;
    Eigen::Vector3d target;
    const bool bu = boundary_[u], bw = boundary_[w], fu = frozen_[u], fw = frozen_[w];
    if (fu && fw) return;
    if (bu && bw) {
      if (common_faces(u, w).size() != 1) return;  // interior edge between two boundary points
      const int l = loop_of_[u];
      if (l < 0 || loop_of_[w] != l || loop_count_[l] <= loop_min_[l]) return;
    }
    Quadric q = Q_[u] + Q_[w] + point_quadric(x_[u], kAlpha) + point_quadric(x_[w], kAlpha);
    if (fu || fw || bu != bw) {
      // One end stays where it is: the frozen one, else the boundary one. A boundary vertex is
      // never pulled off its loop onto a frozen interior one.
      const int keep = (fu || fw) ? (fu ? u : w) : (bu ? u : w);
      const int gone = keep == u ? w : u;
      if (boundary_[gone] && !boundary_[keep]) return;
      a = keep;
      b = gone;
      target = x_[a];
    } else {
      // Minimise E(v): the upper-left 3x3 of q is positive definite thanks to the point quadrics.
      const Eigen::Matrix3d A = q.topLeftCorner<3, 3>();
      const Eigen::Vector3d rhs = -q.topRightCorner<3, 1>();
      target = A.ldlt().solve(rhs);
      if (!target.allFinite()) target = 0.5 * (x_[u] + x_[w]);
      if (a > b) std::swap(a, b);
    }
    heap_.push({eval(q, target), a, b, stamp_[a], stamp_[b], target});
  }

  void push_edges(int v) {
    for (int u : neighbours(v)) push_edge(std::min(u, v), std::max(u, v));
  }

  bool collapse_allowed(int a, int b, const Eigen::Vector3d& target) const {
    // Link condition: the common neighbours of a and b are exactly the edge's opposite vertices.
    const auto faces_ab = common_faces(a, b);
    if (faces_ab.empty()) return false;
    const auto na = neighbours(a), nb = neighbours(b);
    std::vector<int> common;
    std::set_intersection(na.begin(), na.end(), nb.begin(), nb.end(), std::back_inserter(common));
    if (common.size() != faces_ab.size()) return false;
    if (boundary_[a] && boundary_[b] && faces_ab.size() != 1) return false;
    // The loop's floor again, now: push_edge checked it when the entry was pushed, and an entry
    // whose two ends nothing touched since stays valid while other collapses bring the loop down
    // to its floor (the coarse gown's hem had 56 vertices against its floor of 64).
    if (boundary_[a] && boundary_[b] && loop_count_[loop_of_[a]] <= loop_min_[loop_of_[a]]) return false;
    // Faces that survive the collapse and move: no flips, no slivers.
    for (int v : {a, b})
      for (int f : vf_[v]) {
        if (!alive_f_[f]) continue;
        const auto& t = tris_[f];
        if (std::find(t.begin(), t.end(), a) != t.end() && std::find(t.begin(), t.end(), b) != t.end()) continue;
        std::array<Eigen::Vector3d, 3> p{x_[t[0]], x_[t[1]], x_[t[2]]};
        const Eigen::Vector3d n_old = (p[1] - p[0]).cross(p[2] - p[0]);
        const double q_old = quality(p[0], p[1], p[2]);
        for (int k = 0; k < 3; ++k)
          if (t[k] == v) p[k] = target;
        const Eigen::Vector3d n_new = (p[1] - p[0]).cross(p[2] - p[0]);
        if (n_new.dot(n_old) <= kMaxTurnCos * n_new.norm() * n_old.norm()) return false;
        const double q_new = quality(p[0], p[1], p[2]);
        if (q_new < kMinQuality && q_new < q_old) return false;
      }
    return true;
  }

  void collapse(int a, int b, const Eigen::Vector3d& target) {
    const bool boundary_edge = boundary_[a] && boundary_[b];
    for (int f : vf_[b]) {
      if (!alive_f_[f]) continue;
      auto& t = tris_[f];
      if (std::find(t.begin(), t.end(), a) != t.end()) {
        alive_f_[f] = false;
        --n_faces_;
        continue;
      }
      for (int& v : t)
        if (v == b) v = a;
      vf_[a].push_back(f);
    }
    auto& fa = vf_[a];
    fa.erase(std::remove_if(fa.begin(), fa.end(), [&](int f) { return !alive_f_[f]; }), fa.end());
    vf_[b].clear();
    x_[a] = target;
    Q_[a] += Q_[b];
    alive_v_[b] = false;
    if (boundary_edge) --loop_count_[loop_of_[a]];
    ++stamp_[a];
    // Every neighbour's edges to a changed cost; their other edges did not.
    for (int u : neighbours(a)) ++stamp_[u];
    for (int u : neighbours(a)) push_edges(u);
  }

  GownMesh compact(double density) const {
    GownMesh out;
    out.areal_density = density;
    std::vector<int> remap(x_.size(), -1);
    for (int v = 0; v < static_cast<int>(x_.size()); ++v)
      if (alive_v_[v] && !vf_[v].empty()) {
        remap[v] = static_cast<int>(out.x.size());
        out.x.push_back(x_[v]);
      }
    for (int f = 0; f < static_cast<int>(tris_.size()); ++f)
      if (alive_f_[f]) out.triangles.push_back({remap[tris_[f][0]], remap[tris_[f][1]], remap[tris_[f][2]]});
    out.boundary_loops = find_boundary_loops(out.triangles, static_cast<int>(out.x.size()));
    return out;
  }

  std::vector<Eigen::Vector3d> x_;
  std::vector<std::array<int, 3>> tris_;
  std::vector<std::vector<int>> vf_;
  std::vector<bool> frozen_;  // vertices that neither move nor go (the grasped patch)
  std::vector<bool> alive_f_, alive_v_, boundary_;
  std::vector<int> stamp_, loop_of_, loop_count_, loop_min_;
  std::vector<Quadric> Q_;
  int n_faces_ = 0;
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> heap_;
};

}  // namespace

GownMesh reduce_gown(const GownMesh& mesh, int target_triangles) { return reduce_gown(mesh, target_triangles, {}); }

GownMesh reduce_gown(const GownMesh& mesh, int target_triangles, const std::vector<bool>& frozen) {
  if (target_triangles <= 0) throw std::invalid_argument("reduce_gown: target_triangles must be positive");
  if (target_triangles >= static_cast<int>(mesh.triangles.size())) return mesh;
  GownMesh out = Reducer(mesh, frozen).run(target_triangles, mesh.areal_density);
  if (mesh.sleeve_loop >= 0 && out.boundary_loops.size() >= 2) {
    // The same opening: the reduced loop whose centroid is nearest the old one's.
    const Eigen::Vector3d c = loop_centroid(mesh, mesh.sleeve_loop);
    int best = 1;
    for (int l = 1; l < static_cast<int>(out.boundary_loops.size()); ++l)
      if ((loop_centroid(out, l) - c).norm() < (loop_centroid(out, best) - c).norm()) best = l;
    set_sleeve_loop(out, best);
  }
  return out;
}

}  // namespace dressguard::gown
