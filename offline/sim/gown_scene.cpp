#include "gown_scene.h"

#include <stdexcept>

namespace dressguard::sim {

Scene make_scene(const gown::GownMesh& mesh, const gown::PaperScene& paper, SceneOptions opt) {
  ClothMesh cm;
  cm.name = "gown";
  cm.x.reserve(mesh.x.size());
  for (const auto& p : mesh.x) cm.x.push_back({p.x(), p.y(), p.z()});
  cm.tris = mesh.triangles;
  cm.grasp = gown::grasp_vertices(mesh, paper);
  if (cm.grasp.empty()) throw std::invalid_argument("make_scene: no gown vertex inside the gripper's jaws");
  if (mesh.sleeve_loop >= 0) cm.sleeve_opening = mesh.boundary_loops.at(mesh.sleeve_loop);
  const Eigen::Vector3d g = paper.upper_jaw_center_W;
  opt.grasp_point = {g.x(), g.y(), g.z()};
  opt.jaw_half = {0.5 * paper.jaw_size_W.x(), 0.5 * paper.jaw_size_W.y(), 0.5 * paper.jaw_size_W.z()};
  ArmGeometry& a = opt.arm;
  a.r_fist = paper.r_fist;
  a.r_wrist = paper.r_wrist;
  a.r_elbow = paper.r_elbow;
  a.r_shoulder = paper.r_shoulder;
  a.fist_x = paper.fist_W().x() - g.x();
  a.hand = paper.wrist_W().x() - paper.fist_W().x();
  a.forearm = paper.elbow_W().x() - paper.wrist_W().x();
  a.upper_arm = paper.upper_arm_length;
  const double high = paper.arm_height_high_W - g.z();
  a.z_rel = {high, high + paper.arm_offset_middle, high + paper.arm_offset_low};
  return make_scene(cm, opt);
}

int target_triangles(GownResolution res) {
  switch (res) {
    case GownResolution::Full: return 0;
    case GownResolution::Reduced: return 5000;
    case GownResolution::Coarse: return 1500;
  }
  return 0;
}

}  // namespace dressguard::sim
