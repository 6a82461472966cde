// The gown mesh: loading (OBJ), the project's own parametric gown, reduction to a coarser mesh
// that keeps the shape, boundary loops (the sleeve openings) and the lumped vertex masses.
//
// Frames. Everything the simulator sees is in the world frame W, shared by gown and sim:
//   z up, gravity along -z, the gripper moves along +x.
// W is the paper's public-simulator frame P (y up, gripper moving toward -x) rotated:
//   x_W = -x_P,  y_W = z_P,  z_W = y_P      (a proper rotation, det = +1)
// The scene constants of that simulator (gripper jaws, arm spheres, gown transform) are in
// placement.h (`PaperScene`), so that gown and sim use the same numbers. A file's gown is placed
// by default with its sleeve opening held by the jaws and facing the fist (`place_at_opening`,
// GownPlacement::Opening); the paper's code's own transform is GownPlacement::Paper.
//
// How the simulator uses it (sim/gown_scene.h, make_scene):
//   GownOptions opt;                       // defaults: measured gown if present, its scale 1.679
//   opt.target_triangles = 5000;           // or 0 for the full 20k-triangle mesh
//   GownMesh g = load_gown(opt);           // placed in W, loops found, sleeve labelled
//   auto held = grasp_vertices(g, opt.scene);   // then hold them at z = opt.scene.pinch_z_W()
//   g.boundary_loops[g.sleeve_loop]        // the opening: sim::ClothMesh::sleeve_opening
// vertex_masses(g) lumps the masses as the simulator does (which computes its own, at the
// trial's ClothParams::areal_density; the paper's simulator gives every particle the same mass,
// total area * density / n); `dressguard gown` reports them.
//
// Data: the measured gown is gt-rad/learning-forces, physx_simulation/Mesh/fullgown.obj (read in
// place from shared/data/gown/, never copied into the project).
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "files.h"
#include "placement.h"

namespace dressguard::gown {

// A triangle mesh of the gown with what the simulator needs to know about it.
struct GownMesh {
  std::vector<Eigen::Vector3d> x;                // vertex positions in W [m] (file frame right after read_obj)
  std::vector<std::array<int, 3>> triangles;     // vertex indices, 0-based, consistently oriented
  std::vector<std::vector<int>> boundary_loops;  // each ordered around the loop; longest first
  int sleeve_loop = -1;                          // index into boundary_loops: the opening the arm enters
  // The lower half of that opening as the mesh is placed (its vertices below the loop's
  // centroid), for looking at: `dressguard gown` reports and writes it, tools/plot/gown.py
  // draws it. The simulator does not read it: a trial labels its outcome (paper V-A) from the
  // lower half of the opening as it hangs after settling (the loop's vertices at or below
  // their mean height then, sim/trial.cpp, settle()), which can differ from this one.
  std::vector<int> sleeve_lower_half;
  double areal_density = 0.145;                  // [kg/m^2], the paper's simulator value
};

struct GownOptions {
  std::filesystem::path obj;  // empty: the measured gown shared/data/gown/fullgown.obj if present,
                              // else the parametric gown
  // File units -> metres. Unset: the file's own, 1 for one to_obj wrote (its first line says it
  // is in metres, kObjMetresHeader), else kMeasuredGownScale. read_obj refuses any other than 1
  // for a file in metres.
  std::optional<double> scale;
  int target_triangles = 0;   // 0: full resolution; e.g. 5000 for the reduced gown
  double areal_density = 0.145;
  bool parametric = false;    // use the parametric gown even when the measured one is present
  bool already_in_W = false;  // the file is already placed in W (as `dressguard gown --out` writes
                              // it, in metres): skip the paper's transform
  PaperScene scene{};         // placement of a file's mesh and the grasp box that picks the sleeve
  GownPlacement placement = GownPlacement::Opening;  // how a file's mesh is placed (placement.h)
  // How the jaws hold the sleeve (placement.h): unset, each gown's own (kOpeningGripDepth and
  // kOpeningRimAhead for a file's mesh, kParametricGrip for the parametric gown). Ignored with
  // the Paper placement and for a mesh already in W (their grasp is wherever the box finds it).
  std::optional<OpeningGrip> grip;
};

// shared/data/gown/fullgown.obj when shared/data is present, else empty.
std::filesystem::path measured_gown_path();

// What load_gown throws when the gripper's jaws hold no vertex of the gown, or no whole triangle
// of it (a point or a line of cloth the gown would swing about, not a clamp): an InputError (the
// grip or the file is at fault) that a calibration takes for a candidate it cannot simulate
// (offline/calib, sim_bridge.h) rather than for a defect that ends it.
class NothingGrasped : public InputError {
 public:
  using InputError::InputError;
};

// The gown the simulator runs on: loaded (or generated), placed in W like the paper's simulator,
// reduced if asked (keeping the grasped vertices as they are), its boundary loops found and the
// sleeve opening labelled. Throws InputError for a malformed file or a mesh with fewer than two
// boundary loops, and NothingGrasped, naming the mesh and the grip, when the jaws hold none of
// its vertices: a file already in W that puts its sleeve elsewhere, or a grip that misses the
// measured sleeve's top (placement.h, OpeningGrip: from 8.31 cm ahead at the default depth), or
// no whole triangle of it (from 7.0 cm ahead; checked after the arm below).
// A file already in W is also refused (InputError) when its cloth starts inside the arm at any
// of the three heights (placement.h, vertices_in_arm): the jaws may then hold another part of the
// gown, as the parametric gown moved 1 m along x has its other sleeve's rim in them.
GownMesh load_gown(const GownOptions& options);

// Reads v/f lines of an OBJ (1-based and negative indices; "f a/b/c", "a//c" and "a/b" forms;
// polygons fan-triangulated from their first corner, and refused when that fan folds them, as
// for a concave polygon whose first corner does not see the others; other lines ignored).
// Positions are multiplied by `scale` and stay in the file's frame (no placement); unset, the
// scale is 1 for a file whose first line is kObjMetresHeader (to_obj wrote it, in metres) and
// kMeasuredGownScale for any other, and a file in metres with a scale other than 1 is refused at
// line 1 (it was scaled a second time without a word: a 4.55 m^2 gown). Boundary loops
// are found; the sleeve is not labelled. InputError names file:line on a malformed line or an
// index out of range. Words are split at any isspace blank, '#' starts a comment anywhere on a
// line, a line ends at LF, CRLF or a lone CR, and a coordinate may be subnormal.
// A mesh the simulator can take is also checked: every vertex within kMaxObjCoordinate of the
// file's origin after the scale (a unit slip in `scale` shows here) and used by some face, every
// triangle at least kMinObjFaceArea, no triangle twice, no edge shared by three or more and one
// fan of triangles around every vertex (a cloth is a 2-manifold: no pinched vertex). A UTF-8
// byte-order mark and leading blanks are skipped; a word that begins with v or f but is none of
// v, vt, vn, vp and f ("V", "F", "v0.5", the old face keyword "fo") is an error rather than a
// skipped line that would shift every later index or drop faces.
inline constexpr double kMaxObjCoordinate = 100.0;  // [m]
inline constexpr double kMinObjFaceArea = 1e-12;    // [m^2]; the measured gown's smallest: 1e-5
// File units -> metres of the measured gown (fullgown.obj), as the paper's simulator scales it.
inline constexpr double kMeasuredGownScale = 1.679;
// The first line to_obj writes: the file is in metres, placed in W.
inline constexpr std::string_view kObjMetresHeader =
    "# dressguard gown mesh, world frame W (z up, gripper moves along +x), metres";
GownMesh read_obj(const std::filesystem::path& path, std::optional<double> scale = std::nullopt);

// The project's own gown (no shared data needed): a body panel with a sleeve tube, the measured
// gown's dimensions (area ~1.6 m^2, sleeve opening perimeter 0.47 m, ~1.4 cm mean edge), already
// placed in W with its sleeve opening near the grasp box, loops found and the sleeve labelled.
// Its sleeve is a flattened tube, so the jaws reach both layers (3 cm) with the cuff 1 cm ahead.
inline constexpr OpeningGrip kParametricGrip{0.03, 0.01};
GownMesh make_parametric_gown(const OpeningGrip& grip = kParametricGrip);
// How the jaws hold a gown unless told otherwise: the parametric gown's kParametricGrip, a mesh
// file's OpeningGrip{} (kOpeningGripDepth, kOpeningRimAhead).
inline OpeningGrip own_grip(bool parametric) { return parametric ? kParametricGrip : OpeningGrip{}; }

// Quadric-error-metric edge collapse (Garland & Heckbert 1997) down to about `target_triangles`.
// Boundary loops keep their shape (boundary vertices move only along the boundary, with a
// boundary quadric), the mesh stays manifold, collapses that would flip a triangle or create a
// sliver are refused. Deterministic (ties broken by edge index). Loops are found again and the
// sleeve labelling is carried over (same loop, lower half recomputed) when the input had one.
GownMesh reduce_gown(const GownMesh& mesh, int target_triangles);
// The same, with vertices that neither move nor disappear (frozen[v], sized like mesh.x or
// shorter). load_gown freezes the grasped vertices, so every resolution holds the same patch.
GownMesh reduce_gown(const GownMesh& mesh, int target_triangles, const std::vector<bool>& frozen);

// Loops of edges used by exactly one triangle, each ordered by walking along the boundary,
// longest (most vertices) first. A vertex where two loops touch is followed consistently.
std::vector<std::vector<int>> find_boundary_loops(const std::vector<std::array<int, 3>>& tris, int n_vertices);

// Lumped masses [kg]: each triangle gives area * density / 3 to each of its vertices.
std::vector<double> vertex_masses(const GownMesh& mesh);

// Indices of the vertices inside the axis-aligned box center_W +- half_extent (inclusive).
std::vector<int> vertices_in_box(const GownMesh& mesh, const Eigen::Vector3d& center_W,
                                 const Eigen::Vector3d& half_extent);

double total_area(const GownMesh& mesh);  // [m^2]

// --- small helpers used by the command, the tests and the simulator -------------------------

double loop_perimeter(const GownMesh& mesh, int loop);            // [m], closed polygon length
Eigen::Vector3d loop_centroid(const GownMesh& mesh, int loop);    // mean of the loop's vertices
double mean_edge_length(const GownMesh& mesh);                    // over unique edges [m]

// One-sided distance [m]: the largest distance from a vertex of `from` to the surface of `to`
// (exact point-triangle distances, triangles found through a uniform grid of `search_radius`
// cells). Infinity when some vertex has no triangle of `to` within about search_radius.
double max_distance_to_surface(const GownMesh& from, const GownMesh& to, double search_radius = 0.05);

// The smallest interior angle of any triangle [rad] (slivers have small ones).
double min_triangle_angle(const GownMesh& mesh);

// The whole mesh as OBJ text (v and f lines, 1-based), for `dressguard gown --out`: the first
// line is kObjMetresHeader, so read_obj takes it at scale 1.
std::string to_obj(const GownMesh& mesh);

}  // namespace dressguard::gown
