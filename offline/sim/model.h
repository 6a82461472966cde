// The simulator's data, apart from its solvers (MuJoCo's mjModel / mjData idea):
//   SceneData  (constant): rest shape, topology, constraint lists, bending weights, arm, grasp.
//   GownModel  (constant per trial): SceneData plus the masses and compliances of ClothParams.
//   GownState  (mutable): positions, velocities, collision candidates and every scratch buffer,
//              allocated once by make_state(); the step functions allocate nothing.
//
// Precision: double. A substep is 1/6000 s, so gravity moves a vertex by g h^2 = 2.7e-7 m per
// substep, only about 4 ulps of a float at 1 m from the origin: float positions would round the
// physics away. Measured (README, "Single precision, measured"): with positions stored as floats
// the hanging gown weighs 2 % more on the gripper and a patch 1 mrad inside the friction cone
// slides. Layout: positions as an array of xyz structs padded to 32 bytes, because the
// constraint solvers gather vertices by index: one vertex is one aligned AVX2 register (the
// bending and integration kernels work on it as it is), or two 16-byte halves that the stretch
// and shear kernels transpose into x, y, z lanes of four vertices (solver_avx2.cpp).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "trial.h"

namespace dressguard::sim {

// A 3-vector padded to 32 bytes (pad stays 0; no arithmetic reads it), see the layout above.
struct alignas(32) V3 {
  double x = 0, y = 0, z = 0;
  double pad = 0;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline V3& operator+=(V3& a, V3 b) { a.x += b.x; a.y += b.y; a.z += b.z; return a; }
inline V3& operator-=(V3& a, V3 b) { a.x -= b.x; a.y -= b.y; a.z -= b.z; return a; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double norm(V3 a) { return std::sqrt(dot(a, a)); }

// A distance constraint between two vertices (the stretch edges).
struct DistanceLink {
  int32_t i, j;
  double rest;  // [m]
};

// A triangle's in-plane shear: its vertices, the inverse rest-frame matrix and its rest area.
struct ShearTri {
  int32_t v[3];
  double dm_inv[4];  // [[a, b], [c, d]] row-major
  double area;       // [m^2]
};

// An isometric bending stencil (Bergou et al. 2006): edge (v0, v1), opposite vertices v2, v3,
// and the weights k (the cotangent weights scaled by sqrt(3 / (A0 + A1))), see bending_constraint().
struct BendStencil {
  int32_t v[4];
  double k[4];
};

// A round cone (tapered capsule): the convex hull of sphere (a, ra) and sphere (b, rb).
// A sphere is a round cone with a == b.
struct RoundCone {
  V3 a, b;
  double ra = 0, rb = 0;
  // Precomputed: axis u, length L, and the slant: sin_phi = (ra - rb) / L.
  V3 u;
  double len = 0, sin_phi = 0, cos_phi = 1;
};
RoundCone make_round_cone(V3 a, double ra, V3 b, double rb);

// Signed distance from p to the round cone's surface and the outward normal there.
double round_cone_distance(const RoundCone& c, V3 p, V3* normal);

// A half-space {p : dot(n, p) >= d} used as a floor or an incline in tests.
struct HalfSpace {
  V3 n;
  double d = 0;
};

struct SceneData {
  ClothMesh mesh;                    // rest mesh, world frame
  SceneOptions opt;
  std::vector<V3> rest;              // rest positions
  std::vector<double> vertex_area;   // [m^2] one third of the adjacent triangles' area
  double rest_area = 0;              // [m^2]
  std::vector<DistanceLink> stretch; // every mesh edge
  std::vector<ShearTri> shear;       // one per triangle
  std::vector<BendStencil> bend;     // one per interior edge
  // Colour groups of the three lists (SceneOptions::colour_order): group g is
  // [colours[g], colours[g + 1]); no two constraints of a group share a vertex (checked again
  // per block by make_model). Empty in mesh order (colour_order off).
  std::vector<int32_t> stretch_colours, shear_colours, bend_colours;
  std::vector<uint8_t> grasped;      // 1 when held by the gripper (kinematic)
  std::vector<int32_t> grasp_list;
  std::vector<V3> grasp_target;      // where the closed jaws hold each vertex (rest elsewhere)
  std::vector<int32_t> opening;      // sleeve opening loop
  std::vector<double> rim_distance;  // [m] rest distance of each vertex to the nearest opening vertex (inf: none)
  // Colliders: the arm's round cones (index 0 is the elbow sphere, used for the label) and
  // planes for tests. The arm is placed at a trial's height by translating these along z.
  std::vector<RoundCone> arm;        // at arm height offset 0 relative to z_rel[High] (see arm_at())
  std::vector<std::string> arm_names;  // one per collider of `arm` (arm_part_names())
  std::vector<HalfSpace> planes;
  V3 elbow;                          // elbow centre at the High height
};

// The constraint lists as the solver reads them, built by make_model() (refresh_constraints())
// from SceneData and the trial's masses and compliances, with what is constant per trial
// precomputed (inverse masses per vertex, inverse denominators). AoSoA: 4 constraints a block,
// one AVX2 iteration per block, each field a 4-lane row (index -1: an empty lane); a block's
// constraints share no vertex. Per colour group, the first blocks are "free": full, touching no
// grasped vertex; the rest are "careful": the group's remainder and every constraint touching a
// grasped vertex, whose force the gripper reads (summed lane by lane in one order on every path).
struct alignas(32) StretchBlock {  // distance_constraint()
  int32_t i[4], j[4];
  double rest[4], wi[4], wj[4];
  // 1 / (wi + wj + alpha_t) in tension, the same with alpha_c in compression (0 if not positive)
  double inv_t[4], inv_c[4];
};
struct alignas(32) ShearBlock {  // shear_constraint()
  int32_t v[3][4];
  int32_t unused[4];
  double a[4], b[4], c[4], d[4];  // Dm^-1 = [[a, b], [c, d]]
  double w0[4], w1[4], w2[4];
  double alpha_t[4];              // alpha_shear / (A h^2)
};
struct alignas(32) BendBlock {  // bending_constraint()
  int32_t v[4][4];
  double k[4][4];                 // k[a][lane]
  double wk[4][4];                // w_a k_a
  double neg_inv_denom[4];        // -1 / (alpha_t + sum_a w_a k_a^2)
};
// The blocks of one colour group: [begin, simd_end) free, [simd_end, end) careful.
struct BlockSpan {
  int32_t begin, simd_end, end;
};

// Which constraint kernels run (SceneOptions::simd; both give the same bits, see README).
enum class KernelPath : uint8_t { Scalar, Avx2 };
// True when this CPU runs the AVX2 kernels.
bool cpu_has_avx2();

// The per-trial constant model: compliances and masses for one ClothParams.
struct GownModel {
  const SceneData* scene = nullptr;
  double h = 0;                       // [s] substep
  double dt = 0;                      // [s] output step
  int substeps = 0;
  std::vector<double> mass;           // [kg]
  std::vector<double> w;              // inverse mass (0 for grasped vertices)
  double alpha_stretch = 0, alpha_shear = 0, alpha_bend = 0;  // XPBD compliances
  double alpha_compress = 0;          // stretch edges under compression (SceneOptions::compression_softening)
  double friction = 0, self_friction = 0;
  double arm_compliance = 0;          // [m/N] ClothParams::arm_compliance (0: fixed arm)
  double fist_shift = 0;              // [m] ClothParams::fist_shift (place_arm)
  double arm_lateral = 0;             // [m] ClothParams::arm_lateral (place_arm)
  double fist_lateral = 0;            // [m] ClothParams::fist_lateral (place_arm)
  double hem_width = 0;               // [m] ClothParams::hem_width (refresh_constraints)
  double hem_bend_ratio = 1;          // ClothParams::hem_bend_ratio
  double damping_factor = 1;          // per substep
  FrictionScheme scheme = FrictionScheme::Improved;
  bool self_collision = true;
  std::vector<RoundCone> arm;         // placed at the trial's height
  V3 elbow;
  // The support under the gown (ClothParams::support_depth), where it ends up; it does not move
  // with the arm. GownState::support_lift says how far below that it is.
  bool has_support = false;
  RoundCone support;
  V3 gravity{0, 0, -9.81};
  // Derived by refresh_constraints() (call it again after changing mass, w or a compliance).
  KernelPath path = KernelPath::Scalar;
  std::vector<StretchBlock> stretch_blocks;
  std::vector<ShearBlock> shear_blocks;
  std::vector<BendBlock> bend_blocks;
  std::vector<BlockSpan> stretch_spans, shear_spans, bend_spans;
};

// Compliance from a stiffness in [0, 1]: log-linear between alpha_soft (k = 0) and alpha_stiff.
double compliance_of(double k, double alpha_soft, double alpha_stiff);

// The calibrated parameters' compliance ranges (ClothParams in trial.h: k = 0 soft ... k = 1 stiff).
inline constexpr double kStretchComplianceSoft = 1e-2, kStretchComplianceStiff = 1e-7;
inline constexpr double kShearComplianceSoft = 1e0, kShearComplianceStiff = 1e-5;
inline constexpr double kBendComplianceSoft = 1e7, kBendComplianceStiff = 1e1;  // [1/(N m)]

// What the bending parameter means as a material. The isometric bending energy (constraints.h)
// of a mesh bent to a constant curvature kappa is  1/2 (1/alpha) sum_e |K_e X|^2, and a plate's
// is 1/2 B kappa^2 A: so the mesh represents a bending rigidity
//   B = f / alpha,   f = sum_e |K_e X|^2 / (kappa^2 A)   (dimensionless; 4.5 on the reduced gown, 3.6 full, 7.7 coarse),
// where f depends on the triangulation and on the direction of bending. For a flat stencil
// (x_i in its unfolded plane) the curvature field X = x + kappa/2 (x.d)^2 n gives
// K_e X = kappa/2 sum_i k_i (x_i.d)^2 n, since K annihilates linear fields; averaged over the
// directions d in the plane:
//   <(sum_i k_i (x_i.d)^2)^2> = ((Sa + Sc)/2)^2 + ((Sa - Sc)/2)^2 / 2 + Sb^2 / 2,
//   Sa = sum k_i u_i^2, Sb = sum k_i u_i v_i, Sc = sum k_i v_i^2   (u, v: the unfolded coordinates).
// bend_mesh_factor() returns that direction-averaged f over all stencils of the rest mesh, each
// unfolded about its hinge (the rest shape's own curvature plays no part: the rest state is flat).
// The cantilever test (tests/sim/physics_test.cpp) checks B against the simulated droop.
double bend_mesh_factor(const SceneData& s);
// B [N m] of bend parameter k on a mesh of factor f.
inline double bending_rigidity(double bend, double mesh_factor) {
  return mesh_factor / compliance_of(bend, kBendComplianceSoft, kBendComplianceStiff);
}
// Peirce's bending length c = (B / (rho g))^(1/3) [m]: a strip of length 2c, held flat at one end,
// droops 41.5 degrees (the cantilever test of fabrics, ASTM D1388). Light woven fabrics 1.5-3 cm.
inline double bending_length(double rigidity, double areal_density) {
  return std::cbrt(rigidity / (areal_density * 9.81));
}
GownModel make_model(const SceneData& s, const ClothParams& p, FrictionScheme scheme, bool self_collision,
                     double arm_dz);
// Rebuilds the solver's blocks from the model's masses, inverse masses and compliances (make_model
// calls it; a test that edits w afterwards calls it again). Chooses the kernel path: AVX2 when
// SceneOptions::simd is set and the CPU has it, else scalar.
void refresh_constraints(GownModel& m);

// Up to two arm colliders near a vertex, found once per output step.
struct ArmCandidates {
  int8_t c[2] = {-1, -1};
};

struct SelfPair {
  int32_t i, j;
};

// A free vertex within contact reach of a watched arm (watch_arms()) this output step.
struct ArmWatch {
  int32_t vertex;
  double dz;  // [m] the watched arm's placement, along z from the model's arm
};

struct GownState {
  std::vector<V3> x, p, v;            // positions, positions at the substep's start, velocities
  std::vector<V3> anchor;             // Constraint friction: stick point of each arm contact
  std::vector<uint8_t> anchored;
  std::vector<ArmCandidates> cand;
  // The free vertices with an arm candidate (or all free vertices when there are planes), in
  // vertex order, listed once per output step so that the substeps' contact pass skips the rest.
  std::vector<int32_t> contact_list;
  size_t contact_count = 0;
  std::vector<V3> contact_n;          // last contact normal of the output step (Stock friction)
  std::vector<double> contact_dn;     // sum of normal corrections over the output step [m]
  std::vector<V3> contact_acc;        // sum over substeps of the contact force on each vertex
  // The same per arm collider (index of m.arm; m dx / h^2 of its corrections): which part of the
  // arm carries the load (TrialResult::arm_parts).
  std::array<V3, kArmParts> part_acc{};
  // An arm collider (or a test plane) corrected a vertex during the last step(): the arm touched
  // the gown (the support, which is not the arm, does not count).
  bool arm_corrected = false;
  // The support (GownModel::support): the free vertices within its reach this output step, and
  // how far below its place it is, linearly from support_lift_from to support_lift_to over the
  // step's substeps (settle() raises it; 0 during the pull). support_acc: the sum over substeps of
  // its force on the gown (m dx / h^2), as force_acc is the gripper's.
  std::vector<uint8_t> support_cand;
  double support_lift_from = 0, support_lift_to = 0;
  V3 support_acc{0, 0, 0};
  std::vector<V3> ext_force;          // per-vertex external force (the perturbation)
  bool ext_force_on = false;          // any non-zero ext_force this output step (set by step())
  // Self-collision: spatial hash and pair list, capacities fixed in make_state().
  std::vector<int32_t> cell_start, cell_sorted;
  std::vector<uint32_t> cell_of;
  std::vector<V3> cell_x;             // positions in cell_sorted's order
  std::vector<int32_t> self_scratch;  // one vertex's candidates (n + 8)
  std::vector<SelfPair> pairs;
  size_t pair_count = 0;
  long pairs_dropped = 0;
  V3 grip_offset;                     // gripper displacement from its start
  // The arm's displacement from where m.arm has it (a compliant arm, arm_spring.h): step()
  // moves it linearly from arm_shift_from to arm_shift_to over its substeps, as it moves the
  // gripper; arm_shift is the current substep's, arm_move its change over that substep (the
  // arm's surface motion, which friction acts against). All zero for a fixed arm.
  V3 arm_shift_from{0, 0, 0}, arm_shift_to{0, 0, 0};
  V3 arm_shift{0, 0, 0}, arm_move{0, 0, 0};
  double jaw_closed = 1;              // 0: grasped vertices at rest positions, 1: at grasp_target
  V3 grip_accel;                      // gripper acceleration (inertia of the grasped vertices)
  V3 force_acc;                       // sum over substeps of the force of the gown on the gripper
  long force_count = 0;
  // Other placements of the arm, watched while the gown settles (watch_arms()).
  std::vector<ArmWatch> watch;        // this step's vertices within their contact reach
  bool watch_touched = false;         // one came within the contact offset of its watched arm
};

GownState make_state(const GownModel& m);

// One output step: collision candidates (arm, self-collision hash), then `substeps` substeps of
// integrate + solve. `grip_from`/`grip_to` are the gripper offsets at the step's start and end
// (linearly interpolated over the substeps), `grip_accel` its acceleration.
void step(const GownModel& m, GownState& s, V3 grip_from, V3 grip_to, V3 grip_accel);

// The arm's colliders (fist, hand when ArmGeometry::hand > 0, forearm, upper arm; the elbow's
// sphere first, the label's reference), with the fist moved by fist_shift along the forearm and by
// fist_lateral sideways, the elbow where it was (ClothParams::fist_shift, fist_lateral). `names`
// (may be null) gets each collider's name.
std::vector<RoundCone> arm_colliders(const SceneOptions& opt, double fist_shift, double fist_lateral,
                                     std::vector<std::string>* names = nullptr);

// The support under the gown where it ends up (ClothParams::support_depth > 0; trial.h): a
// capsule of radius kSupportRadius along x under the grasp point, fixed in the world.
RoundCone support_collider(const SceneOptions& opt, const ClothParams& p);

// The arm of the scene with its fist moved by m.fist_shift toward the elbow and by m.fist_lateral
// sideways, then the whole arm moved by m.arm_lateral along y and by arm_dz along z (the trial's
// height): m.arm and m.elbow.
void place_arm(GownModel& m, double arm_dz);

// Watching other placements of the arm while the gown settles: may trials with other arm heights
// start their pulls from this settling (simulate_trials())? A watched arm is m's arm moved by
// `dz` along z; it acts on nothing. Had an arm been there, it would have changed the gown only
// through contact corrections, and solve_contacts() corrects only a vertex that detect_arm() made
// its candidate and that then lies within the contact offset of it in a substep (a candidate that
// stays outside moves no bit). So, before each step():
// - watch_arms() lists in s.watch the free vertices within contact reach of each watched arm
//   (detect_arm()'s margin, 1 um wider for the rounding of the move) and returns whether it
//   listed any;
// - then every substep checks the listed vertices against all of that arm's cones and sets
//   s.watch_touched when one lies within the contact offset (plus 1 um).
// While watch_touched stays false, an arm at any watched placement would have left the gown
// with the same bits. Clear s.watch to stop watching.
bool watch_arms(const GownModel& m, GownState& s, const std::vector<double>& dz);

// Total triangle area of the current positions.
double current_area(const GownModel& m, const GownState& s);

}  // namespace dressguard::sim
