// Placement of the gown (ours at the opening, or the paper's public simulator's), and the sleeve
// labelling.
#include "placement.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "files.h"
#include "gown.h"

namespace dressguard::gown {

void place_like_paper(GownMesh& mesh, const PaperScene& scene) {
  const Eigen::Matrix3d R = scene.rotation_WF();
  const Eigen::Vector3d t = scene.translation_W();
  for (auto& p : mesh.x) p = R * p + t;
}

void check_grip(const OpeningGrip& grip, const PaperScene& scene) {
  // The grasp box spans the lower jaw's travel up to the upper jaw: a deeper grip would put the
  // sleeve's top under the lower jaw, which then grasps nothing of it.
  const double box_depth = 2 * scene.grasp_box_half_extent_W().z();
  if (!(grip.depth > 0 && grip.depth < box_depth))
    throw std::invalid_argument("grip depth " + std::to_string(grip.depth) + " m outside (0, " +
                                std::to_string(box_depth) + ") m, the depth of the grasp box");
  if (!(grip.rim_ahead >= 0 && grip.rim_ahead < rim_ahead_limit(scene)))
    throw std::invalid_argument(format_string("rim ahead of the jaws %g m outside [0, %g) m: from %g m the rim starts "
                                              "level with or past the fist's back, the hand inside the sleeve "
                                              "(placement.h, rim_ahead_limit)",
                                              grip.rim_ahead, rim_ahead_limit(scene), rim_ahead_limit(scene)));
}

void place_at_opening(GownMesh& mesh, const PaperScene& scene, const OpeningGrip& grip, int loop_index) {
  check_grip(grip, scene);
  if (loop_index < 0) {
    // The sleeve: the paper's placement decides which of the two openings the arm enters.
    GownMesh paper = mesh;
    place_like_paper(paper, scene);
    label_sleeve(paper, scene);
    loop_index = paper.sleeve_loop;
  }
  if (loop_index >= static_cast<int>(mesh.boundary_loops.size()))
    throw std::runtime_error("place_at_opening: boundary loop " + std::to_string(loop_index) + " does not exist");
  const std::vector<int>& loop = mesh.boundary_loops[loop_index];
  const Eigen::Vector3d c = loop_centroid(mesh, loop_index);
  // Best-fit plane of the loop: its normal is the eigenvector of the smallest eigenvalue of the
  // loop's scatter matrix (the opening of a sleeve is a roughly planar ring).
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int v : loop) scatter += (mesh.x[v] - c) * (mesh.x[v] - c).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  Eigen::Vector3d into = eig.eigenvectors().col(0);
  // Into the sleeve: the side where the loop's neighbours off the loop lie.
  std::vector<char> on_loop(mesh.x.size(), 0);
  for (int v : loop) on_loop[v] = 1;
  double side = 0;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      if (on_loop[t[k]])
        for (int j = 0; j < 3; ++j)
          if (!on_loop[t[j]]) side += (mesh.x[t[j]] - c).dot(into);
  if (side < 0) into = -into;
  // Down: toward the gown's centroid, normal to the sleeve's axis.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : mesh.x) centroid += p;
  centroid /= static_cast<double>(mesh.x.size());
  Eigen::Vector3d down = (centroid - c) - (centroid - c).dot(into) * into;
  if (down.norm() < 1e-9) down = into.unitOrthogonal();
  down.normalize();
  // Rows: the file-frame directions that become +x_W, +y_W, +z_W (e_y = e_z x e_x: det R = +1).
  const Eigen::Vector3d ex = -into, ez = -down, ey = ez.cross(ex);
  Eigen::Matrix3d R;
  R.row(0) = ex.transpose();
  R.row(1) = ey.transpose();
  R.row(2) = ez.transpose();
  for (auto& p : mesh.x) p = R * (p - c);
  int top = loop.front();
  for (int v : loop)
    if (mesh.x[v].z() > mesh.x[top].z()) top = v;
  const Eigen::Vector3d rim_top(opening_rim_x_W(scene, grip.rim_ahead), scene.upper_jaw_center_W.y(),
                                sleeve_top_z_W(scene, grip.depth));
  const Eigen::Vector3d shift = rim_top - mesh.x[top];
  for (auto& p : mesh.x) p += shift;
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

namespace {

// Whether p lies within the tapered capsule from sphere (a, ra) to sphere (b, rb), its radius
// taken at the closest point of the axis.
bool in_tapered_capsule(const Eigen::Vector3d& p, const Eigen::Vector3d& a, double ra, const Eigen::Vector3d& b,
                        double rb) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm() < ra + t * (rb - ra);
}

}  // namespace

std::vector<int> vertices_in_arm(const GownMesh& mesh, const PaperScene& scene, double offset) {
  const Eigen::Vector3d fist = scene.fist_W(offset), wrist = scene.wrist_W(offset);
  const Eigen::Vector3d elbow = scene.elbow_W(offset), shoulder = scene.shoulder_W(offset);
  std::vector<int> out;
  for (int v = 0; v < static_cast<int>(mesh.x.size()); ++v) {
    const Eigen::Vector3d& p = mesh.x[v];
    if ((p - fist).norm() < scene.r_fist || in_tapered_capsule(p, wrist, scene.r_wrist, elbow, scene.r_elbow) ||
        in_tapered_capsule(p, elbow, scene.r_elbow, shoulder, scene.r_shoulder))
      out.push_back(v);
  }
  return out;
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
