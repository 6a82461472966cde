// Placement of the gown like the paper's public simulator, and the sleeve labelling.
#include "placement.h"

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

}  // namespace dressguard::gown
