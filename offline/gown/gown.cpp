// load_gown and the mesh comparisons used to check a reduction.
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include <Eigen/Geometry>

#include "files.h"
#include "gown.h"

namespace dressguard::gown {

std::filesystem::path measured_gown_path() {
  const auto shared = shared_dir();
  if (shared.empty()) return {};
  auto p = shared / "data" / "gown" / "fullgown.obj";
  return std::filesystem::exists(p) ? p : std::filesystem::path{};
}

namespace {

// A gown read already in W is where the file puts it, and the jaws holding some of it does not
// make it a scene: the parametric gown moved 1 m along x has its other sleeve's rim in the jaws
// (the two openings are 1.06 m apart), that opening faces away from the fist and the sleeves' tube
// runs through the arm. A placement starts the cloth clear of the arm at every height (placement.h,
// vertices_in_arm); a file that does not is refused, naming the height and a vertex inside.
void check_clear_of_arm(const GownMesh& mesh, const PaperScene& scene, const std::filesystem::path& path) {
  const std::pair<const char*, double> heights[] = {
      {"high", 0.0}, {"middle", scene.arm_offset_middle}, {"low", scene.arm_offset_low}};
  for (const auto& [name, offset] : heights) {
    const std::vector<int> inside = vertices_in_arm(mesh, scene, offset);
    if (inside.empty()) continue;
    const Eigen::Vector3d& p = mesh.x[inside.front()];
    throw_input_error(path, 0, format_string("the gown where the file puts it (already in W) starts inside the arm: at "
                                             "the %s arm height %zu of its vertices lie within it (vertex %d at %.3f, "
                                             "%.3f, %.3f m); the jaws hold it elsewhere than at a sleeve opening ahead "
                                             "of the arm (place it without --in-world, or move it)",
                                             name, inside.size(), inside.front() + 1, p.x(), p.y(), p.z()));
  }
}

// How the refusals of a grasp name the gown: its file, or the parametric gown (no file).
std::string gown_name(const std::filesystem::path& path) {
  return path.empty() ? std::string("parametric gown") : path.string();
}

// The grasp box, for the refusals of a grasp: "the gripper's jaws (x lo..hi, y lo..hi, z lo..hi m)".
std::string jaws_text(const PaperScene& scene) {
  const Eigen::Vector3d lo = scene.grasp_box_center_W() - scene.grasp_box_half_extent_W();
  const Eigen::Vector3d hi = scene.grasp_box_center_W() + scene.grasp_box_half_extent_W();
  return format_string("the gripper's jaws (x %g..%g, y %g..%g, z %g..%g m)", lo.x(), hi.x(), lo.y(), hi.y(), lo.z(),
                       hi.z());
}

// What put the gown where the jaws are, for the same refusals: the grip (with what to change) or
// the file's own place.
std::string held_how(const GownOptions& options, const std::filesystem::path& path) {
  if (path.empty() || (!options.already_in_W && options.placement == GownPlacement::Opening)) {
    const OpeningGrip g = options.grip.value_or(own_grip(path.empty()));
    return "with grip depth " + format_number(g.depth) + " m and rim_ahead " + format_number(g.rim_ahead) +
           " m (placement.h, OpeningGrip: the sleeve's top behind its rim lies below the lower jaw; hold the "
           "rim nearer the jaws or grip deeper)";
  }
  return options.already_in_W ? "where the file puts it (already in W)" : "in the paper's placement";
}

// Whether every corner of some triangle of `mesh` is among the `held` vertices.
bool holds_a_triangle(const GownMesh& mesh, const std::vector<int>& held) {
  std::vector<bool> is_held(mesh.x.size(), false);
  for (int v : held) is_held[static_cast<size_t>(v)] = true;
  for (const auto& t : mesh.triangles)
    if (is_held[static_cast<size_t>(t[0])] && is_held[static_cast<size_t>(t[1])] && is_held[static_cast<size_t>(t[2])])
      return true;
  return false;
}

}  // namespace

GownMesh load_gown(const GownOptions& options) {
  const std::filesystem::path path =
      options.parametric ? std::filesystem::path{} : (options.obj.empty() ? measured_gown_path() : options.obj);
  GownMesh mesh = path.empty() ? (options.grip ? make_parametric_gown(*options.grip) : make_parametric_gown())
                               : read_obj(path, options.scale);
  // Before the placement: it looks for the sleeve among the loops, and without two of them it
  // failed with an error that named no file.
  if (mesh.boundary_loops.size() < 2)
    throw_input_error(path.empty() ? "parametric gown" : path, 0,
                      "the mesh has " + std::to_string(mesh.boundary_loops.size()) +
                          " boundary loop(s); a gown needs its body opening and a sleeve opening");
  if (!path.empty() && !options.already_in_W) {
    if (options.placement == GownPlacement::Opening)
      place_at_opening(mesh, options.scene, options.grip.value_or(OpeningGrip{}));
    else
      place_like_paper(mesh, options.scene);
  }
  // The jaws must hold some of the cloth. A file already in W that puts its sleeve elsewhere, or a
  // grip that misses the measured sleeve's top, which falls away behind its rim (placement.h,
  // OpeningGrip: nothing from 8.31 cm ahead at the default depth), grasped nothing: `gown` said
  // "grasped vertices: 0" and exited 0, and the simulator failed later or a calibration ended.
  // Before the reduction, which keeps the grasped vertices as they are.
  const std::vector<int> held = grasp_vertices(mesh, options.scene);
  if (held.empty())
    throw NothingGrasped(format_string("%s: %s hold no vertex of the gown %s", gown_name(path).c_str(),
                                       jaws_text(options.scene).c_str(), held_how(options, path).c_str()));
  if (!path.empty() && options.already_in_W) check_clear_of_arm(mesh, options.scene, path);
  // Jaws clamp a strip of cloth, which fixes how the gown hangs from them. Holding no whole
  // triangle, they hold a vertex (a ball joint) or vertices along edges (hinges), about which the
  // gown swings freely: the measured gown with its rim 8.1-8.3 cm ahead of the jaws held 1 vertex.
  if (!holds_a_triangle(mesh, held))
    throw NothingGrasped(format_string("%s: %s hold %zu vertices of the gown but no whole triangle of it %s: a "
                                       "point or a line the gown would swing about, not a clamp of its cloth",
                                       gown_name(path).c_str(), jaws_text(options.scene).c_str(), held.size(),
                                       held_how(options, path).c_str()));
  mesh.areal_density = options.areal_density;
  if (options.target_triangles > 0) {
    std::vector<bool> frozen(mesh.x.size(), false);
    for (int v : grasp_vertices(mesh, options.scene)) frozen[v] = true;
    mesh = reduce_gown(mesh, options.target_triangles, frozen);
  }
  label_sleeve(mesh, options.scene);
  return mesh;
}

namespace {

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5: the
// Voronoi regions of the vertices, the edges and the face, in that order).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = va + vb + vc;
  if (denom == 0) return a;  // degenerate triangle
  return a + ab * (vb / denom) + ac * (vc / denom);
}

}  // namespace

double max_distance_to_surface(const GownMesh& from, const GownMesh& to, double search_radius) {
  const double h = search_radius;
  auto cell = [h](const Eigen::Vector3d& p) {
    return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / h)), static_cast<int>(std::floor(p.y() / h)),
                           static_cast<int>(std::floor(p.z() / h)));
  };
  auto key = [](int i, int j, int k) {
    return (static_cast<int64_t>(i) * 73856093) ^ (static_cast<int64_t>(j) * 19349663) ^
           (static_cast<int64_t>(k) * 83492791);
  };
  std::unordered_map<int64_t, std::vector<int>> grid;
  for (int f = 0; f < static_cast<int>(to.triangles.size()); ++f) {
    const auto& t = to.triangles[f];
    const Eigen::Vector3d lo = to.x[t[0]].cwiseMin(to.x[t[1]]).cwiseMin(to.x[t[2]]);
    const Eigen::Vector3d hi = to.x[t[0]].cwiseMax(to.x[t[1]]).cwiseMax(to.x[t[2]]);
    const Eigen::Vector3i c0 = cell(lo), c1 = cell(hi);
    for (int i = c0.x(); i <= c1.x(); ++i)
      for (int j = c0.y(); j <= c1.y(); ++j)
        for (int k = c0.z(); k <= c1.z(); ++k) grid[key(i, j, k)].push_back(f);
  }
  double worst = 0;
  for (const auto& p : from.x) {
    const Eigen::Vector3i c = cell(p);
    double best = std::numeric_limits<double>::infinity();
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k) {
          const auto it = grid.find(key(c.x() + i, c.y() + j, c.z() + k));
          if (it == grid.end()) continue;
          for (int f : it->second) {
            const auto& t = to.triangles[f];
            best = std::min(best, (closest_on_triangle(p, to.x[t[0]], to.x[t[1]], to.x[t[2]]) - p).norm());
          }
        }
    worst = std::max(worst, best);
  }
  return worst;
}

double min_triangle_angle(const GownMesh& mesh) {
  double worst = M_PI;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d u = mesh.x[t[(k + 1) % 3]] - mesh.x[t[k]];
      const Eigen::Vector3d v = mesh.x[t[(k + 2) % 3]] - mesh.x[t[k]];
      worst = std::min(worst, std::atan2(u.cross(v).norm(), u.dot(v)));
    }
  return worst;
}

}  // namespace dressguard::gown
