// Placement of the gown like the paper's public simulator, and the sleeve labelling.
#include "placement.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "gown.h"

namespace dressguard::gown {

void place_like_paper(GownMesh& mesh, const PaperScene& scene) {
  const Eigen::Matrix3d R = scene.rotation_WF();
  const Eigen::Vector3d t = scene.translation_W();
  for (auto& p : mesh.x) p = R * p + t;
}

void label_sleeve(GownMesh& mesh, const PaperScene& scene) {
  if (mesh.boundary_loops.size() < 2)
    throw std::runtime_error("gown mesh has " + std::to_string(mesh.boundary_loops.size()) +
                             " boundary loop(s); need the body opening and at least one sleeve opening");
  // Loop 0 is the longest (hem and body opening); the sleeve openings are the others. The arm
  // enters the one the gripper holds: its centroid is nearest the grasp box.
  const Eigen::Vector3d g = scene.grasp_box_center_W();
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (int l = 1; l < static_cast<int>(mesh.boundary_loops.size()); ++l) {
    const double d = (loop_centroid(mesh, l) - g).norm();
    if (d < best_d) best_d = d, best = l;
  }
  set_sleeve_loop(mesh, best);
}

void set_sleeve_loop(GownMesh& mesh, int loop) {
  mesh.sleeve_loop = loop;
  const int best = loop;
  // Lower half (paper Fig. 3b): the loop's vertices below its centroid in z_W, i.e. the part of
  // the opening that hangs away from the grip and meets the arm's underside.
  const double zc = loop_centroid(mesh, best).z();
  mesh.sleeve_lower_half.clear();
  for (int v : mesh.boundary_loops[best])
    if (mesh.x[v].z() < zc) mesh.sleeve_lower_half.push_back(v);
}

std::vector<int> grasp_vertices(const GownMesh& mesh, const PaperScene& scene) {
  return vertices_in_box(mesh, scene.grasp_box_center_W(), scene.grasp_box_half_extent_W());
}

std::vector<Eigen::Vector3d> crude_hang(const GownMesh& m, const PaperScene& s, double seconds) {
  std::vector<std::array<int, 2>> edges;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) edges.push_back({std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])});
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<double> rest(edges.size());
  for (size_t e = 0; e < edges.size(); ++e) rest[e] = (m.x[edges[e][0]] - m.x[edges[e][1]]).norm();
  std::vector<double> w(m.x.size(), 1.0);  // inverse masses: uniform, only the shape matters here
  std::vector<Eigen::Vector3d> x = m.x, v(m.x.size(), Eigen::Vector3d::Zero()), p(m.x.size());
  for (int g : grasp_vertices(m, s)) w[g] = 0, x[g].z() = s.pinch_z_W();
  const double dt = 1.0 / 300;
  const Eigen::Vector3d gravity(0, 0, -9.81);
  const int steps = static_cast<int>(seconds / dt);
  for (int step = 0; step < steps; ++step) {
    for (size_t i = 0; i < x.size(); ++i) {
      if (w[i] > 0) v[i] = 0.99 * v[i] + dt * gravity;
      p[i] = x[i] + dt * v[i];
    }
    for (int pass = 0; pass < 20; ++pass)
      for (size_t e = 0; e < edges.size(); ++e) {
        // C = |p_a - p_b| - L;  dp_a = -w_a C n / (w_a + w_b),  dp_b = +w_b C n / (w_a + w_b).
        const int a = edges[e][0], b = edges[e][1];
        const double ws = w[a] + w[b];
        if (ws == 0) continue;
        const Eigen::Vector3d d = p[a] - p[b];
        const double len = d.norm();
        if (len == 0) continue;
        const Eigen::Vector3d c = (len - rest[e]) / (len * ws) * d;
        p[a] -= w[a] * c;
        p[b] += w[b] * c;
      }
    for (size_t i = 0; i < x.size(); ++i) {
      if (w[i] > 0) v[i] = (p[i] - x[i]) / dt;
      x[i] = p[i];
    }
  }
  return x;
}

}  // namespace dressguard::gown
