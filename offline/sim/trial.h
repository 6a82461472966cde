// The haptic simulation of one sleeve-pulling trial (paper section IV-A and V-A).
//
// A Scene is the constant model of the trial (gown mesh, masses, constraints, the arm's tapered
// capsules, the gripper's grasp), built once and reused for thousands of trials, the way MuJoCo
// separates mjModel from mjData. simulate_trial() creates its own mutable state, so any number of
// threads may simulate trials of one Scene at once (no shared mutable state).
//
// Frame (world, metres): x = the gripper's direction of motion (from the fist toward the elbow),
// y = lateral (the upper arm goes toward -y), z = up; gravity -9.81 m/s^2 along z. The gripper
// starts at x = 0 and pulls along +x. The reported forces use the rig's convention (core/haptic.h):
// f_motion = F.x (drag negative), f_lateral = -F.y, f_vertical = F.z, with F the force that the
// gown exerts on the gripper, biased to zero at the start of the pull like the real sensor.
// F_lateral's sign: the data README does not give the rig's lateral axis. It points toward the
// person's side (-y): at the end of 21 of the study's 22 trials, when the sleeve lies on the
// forearm and reaches toward the upper arm, the measured F_lateral is positive (+0.05 to +0.83
// N), and there the simulated gown pulls the gripper toward the upper arm (-y) at every arm
// height (offline/sim/MEASUREMENTS.md, "The lateral force"). Before 2026-11-25 f_lateral was +F.y.
//
// Time (paper IV-A, V-A; Macklin et al. 2019 "small steps"): 300 Hz output steps, each split into
// `substeps` (20) XPBD substeps that each integrate and solve every constraint once; collision
// candidates (arm and self) are found once per output step; one haptic sample per 3 output steps
// (100 Hz), the force averaged over the sample's 60 substeps.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "haptic.h"

namespace dressguard::sim {

// The cloth's calibrated material (paper IV-B.2: isotropic stretch, shear, bending, friction,
// self-friction). The three stiffnesses are dimensionless in [0, 1] and map log-linearly onto
// XPBD compliances (see compliance_of() in model.h), so that an optimizer can search a box:
//   stretch: edge distance compliance 1e-2 (k=0) ... 1e-7 m/N (k=1) in tension (a triangulated
//            membrane's edge stiffness does not depend on the edge length); 1000x softer in
//            compression (SceneOptions::compression_softening)
//   shear:   in-plane shear compliance per triangle (1 / shear modulus) 1e0 (k=0) ... 1e-5 m/N (k=1)
//   bend:    isometric bending compliance alpha 1e7 (k=0) ... 1e1 1/(N m) (k=1). As a fabric
//            (model.h, bending_rigidity() and bending_length()): B = f / alpha with the mesh's
//            factor f (4.5 on the reduced gown), so on the reduced gown k = 0.3 is B = 2.9e-5 N m,
//            Peirce's bending length 2.7 cm (woven garment fabric: a few cm); k = 0.5 is 6.8 cm,
//            the default k = 0.7 17.2 cm (thin card). The solver delivers these within 10 % up
//            to k = 0.8 at the gown meshes' edge lengths (the cantilever test). The default keeps
//            the held sleeve opening round enough for the high arm to enter it (at 0.35-0.5 it
//            sags into a slit or an ellipse whose lower rim the fist catches;
//            offline/sim/MEASUREMENTS.md, "How stiff the gown is"): a model parameter that
//            calibration fits per person, stiffer than the fabric it stands for.
// friction: Coulomb coefficient cloth-arm, [0, 2]; self_friction: cloth-cloth, [0, 2].
// damping [1/s]: velocity decay rate (v *= exp(-damping h) per substep) during the pull and the
// perturbation, fixed by default; 2/s costs the pulled gown only m * 2/s * 0.1 m/s = 0.05 N of
// drag. Settling uses its own, heavier damping (TrialSpec::settle_damping).
// areal_density [kg/m^2]: 0.145 as the paper's simulator, fixed by default.
// arm_compliance [m/N]: how far the person's arm gives per newton of the cloth's pull during the
// pull (arm_spring.h: a 2 kg arm on a critically damped spring of stiffness 1 / arm_compliance);
// 0, the default and the paper's, holds the arm fixed. Not cloth, but a parameter of the scene
// that a calibration may fit per person like the cloth's.
// fist_shift [m]: the fist (and wrist) moved along the forearm toward the elbow, the elbow and
// upper arm fixed, so the forearm is that much shorter (negative: longer). 0, the default, is the
// paper's arm (data README: the elbow 0.53 m ahead of the gripper's start, the fist 0.31 m before
// it). In the paper's simulator the gripper's start is placed from the elbow and the fist from
// the forearm's length, so this is the person's fist-to-elbow length; the measured trials place
// the elbow (the good trials' 10 N stop) but not the fist, and calibration may fit it per person.
// arm_lateral [m]: the whole arm moved sideways along +y (away from the person's body; the upper
// arm goes toward -y), the gripper's line of pull where it was. fist_lateral [m]: the fist (and
// wrist) alone moved sideways, the elbow fixed: the forearm turned about the elbow by about
// fist_lateral / 0.31 m. 0, the defaults and the paper's, put the forearm's axis under the jaws,
// on the sleeve opening's plane of symmetry (its centre is within 1 mm of y = 0), so that the
// gown's pull on the gripper has no lateral part until the cloth reaches the upper arm. The
// people did not hold their arms there: all 8 good trials of the study pull the gripper sideways
// by 0.05-0.15 N from 0.15 m of travel, and the 14 missed ones do not (offline/sim/MEASUREMENTS.md,
// "The lateral force"). A fist beside the opening's centre does that: inside the opening it
// pushes the rim toward its own side; below it, it deflects the sleeve toward the other side.
// Calibration may fit both per person with the lateral force in its objective.
// hem_width [m], hem_bend_ratio: the sleeve's cuff. A garment's opening is hemmed (the fabric
// folded over twice and stitched: three layers, 3x to 27x the fabric's bending rigidity between
// loose and bonded layers), so bending stencils whose hinge lies within hem_width of the sleeve
// opening (rest distance) have hem_bend_ratio times the rigidity of `bend`, and its edges are not
// softened in compression (SceneOptions::compression_softening stands for single fabric buckling
// below the mesh's scale; stitched layers do not, and a softened cuff shrank its rim by 9-22 %).
// 0 and 1, the defaults, are the paper's uniform cloth. A hem holds an opening of soft fabric
// open the way a stiff `bend` holds the whole gown (offline/sim/MEASUREMENTS.md, "How stiff the
// gown is").
// support_depth [m], support_lateral [m]: something under the gown that carries part of its body,
// as the people's small late lateral force says something does in the study
// (offline/sim/MEASUREMENTS.md, "What holds the gown on the person's side"): a horizontal capsule
// of radius kSupportRadius along x, from kSupportBehind behind the grasp point to kSupportAhead
// ahead of it (the paper's elbow), its axis support_depth below the grasp point and support_lateral
// along y (negative: toward the person). It stays where it is whatever the arm's height or place,
// and comes up from kSupportDrop below its place over the first kSupportRiseSteps output steps of
// settling, so that the hanging gown comes to lie on it rather than starting inside it. Its contact
// has the arm's friction. support_depth 0, the default and the paper's, is no support.
struct ClothParams {
  double stretch = 0.8;
  double shear = 0.5;
  double bend = 0.7;
  double friction = 0.5;
  double self_friction = 0.2;
  double damping = 2.0;
  double areal_density = 0.145;
  double arm_compliance = 0.0;
  double fist_shift = 0.0;
  double arm_lateral = 0.0;
  double fist_lateral = 0.0;
  double hem_width = 0.0;
  double hem_bend_ratio = 1.0;
  double support_depth = 0.0;
  double support_lateral = 0.0;
};
// The support's shape and its rise during settling (ClothParams::support_depth). Its radius and
// length are those of the variant that brought participant 4's middle arm nearest the people.
inline constexpr double kSupportRadius = 0.15;   // [m]
inline constexpr double kSupportBehind = 0.13;   // [m] along -x from the grasp point
inline constexpr double kSupportAhead = 0.57;    // [m] along +x from the grasp point
inline constexpr double kSupportDrop = 1.2;      // [m] below its place when settling starts
inline constexpr int kSupportRiseSteps = 300;    // output steps (1 s); settling takes at least 500
// support_depth within [0, kMaxSupportDepth] (0: none; the support's top 0.15 m above its axis);
// |support_lateral| <= kMaxSupportLateral.
inline constexpr double kMaxSupportDepth = 1.5, kMaxSupportLateral = 0.3;
// |fist_shift| beyond this leaves no forearm worth the name (the paper's is 0.31 m).
inline constexpr double kMaxFistShift = 0.2;
// |arm_lateral| beyond this puts the fist (radius 5 cm) beside a 16 cm opening, not in front of it.
inline constexpr double kMaxArmLateral = 0.1;  // and |fist_lateral|
// stretch, shear and bend are positions on their compliance scales, [0, 1] (compliance_of() clamps
// beyond, so a value outside would silently act as its end); friction and self_friction are
// coefficients, not negative.
inline constexpr double kStiffnessLowest = 0.0, kStiffnessHighest = 1.0;
// A cuff's limits: width [m] and how much stiffer than the fabric it may be.
inline constexpr double kMaxHemWidth = 0.2, kMaxHemBendRatio = 1e4;

// Friction of cloth against the arm and itself (paper IV-A.2, the point of the "improved" scheme):
//  Stock:      PBD as in stock PhysX: contacts push vertices out along the normal in every
//              substep, and once per output step the friction impulse (bounded by mu times the
//              step's normal impulse) changes only the velocity; the tangential slip already made
//              by gravity and internal constraints stays, so friction is underestimated (the
//              paper's claim, tested). No cloth-cloth friction (stock PhysX has none, paper
//              IV-A.3).
//  Improved:   the paper's fix: the friction correction is applied to the positions (and so to
//              the velocities) in every substep that resolves the contact; self-friction likewise.
//  Constraint: static friction as a positional stick constraint holding each contact at its anchor
//              while the tangential correction stays within mu times the normal correction, and
//              dynamic friction bounded by mu times the normal correction otherwise (Macklin et
//              al. 2014 "Unified particle physics", XPBD rigid bodies 2020).
enum class FrictionScheme { Stock = 0, Improved = 1, Constraint = 2 };
const char* friction_scheme_name(FrictionScheme s);
// The scheme named `name` (friction_scheme_name's inverse); false, and *out untouched, if none is.
bool parse_friction_scheme(const std::string& name, FrictionScheme* out);

// The pull speeds a trial may ask for [m/s]: the study pulls at 0.1 and 0.15 m/s; half the
// slower to twice the faster leaves room to look around the rig's speeds, and bounds the pull's
// time limit (travel / speed + 5 s) to 22 s at the rig's 0.85 m: a speed near 0 ran for days.
inline constexpr double kMinPullSpeed = 0.05, kMaxPullSpeed = 0.3;

// One trial's conditions.
struct TrialSpec {
  ArmHeight height = ArmHeight::High;
  double arm_offset = 0.0;      // [m] added to the height's nominal arm height (paper IV-B.2)
  double speed = 0.1;           // [m/s] pull speed (0.1 or 0.15 in the study)
  double acceleration = kRigAcceleration;  // [m/s^2] the rig's acceleration up to `speed`
  uint64_t seed = 0;            // drives the perturbation force
  bool gown_noise = false;      // paper V-A: X and lateral force each uniform in [-6, 6] N over all vertices
                                // (the paper's "maximum magnitude 6 N" read per direction: |F| up to 8.5 N)
  bool arm_noise = false;       // paper V-A: arm height + U[-1.5, 1.5] cm (high, low), U[-6, 0] cm (middle)
  double max_travel = 0.85;     // [m] end of the rig's travel
  double force_limit = 10.0;    // [N] stop when |f_motion| or |f_vertical| reaches it
  FrictionScheme friction_scheme = FrictionScheme::Improved;
  bool self_collision = true;
  // Settling (paper V-A: the robot waits for the gown to settle before it pulls). The gown drops
  // from its mesh shape (and, with gown_noise, is pushed during output steps 180-330) and then
  // settles under `settle_damping` [1/s] (the cloth's own damping during the push) until the RMS
  // speed of its free vertices over a 0.1 s window falls below `settle_speed` [m/s], checked
  // every 0.1 s after `settle_steps` output steps and given up at `settle_max_steps` (the result
  // says so). Why: at the cloth's 2/s a 1 m gown's swing decays as e^(-t); after the fixed 500
  // steps (1.7 s) of session 1 the reduced gown still moved at 0.19 m/s RMS without the push and
  // about 2 m/s with it, so every trial started on a swinging gown and the first 0.1 m of the
  // synthesized trials carried up to 7 N of swing. 5/s settles fastest of 2, 5, 10 and 20
  // (heavier damping is overdamped and creeps); damping moves no equilibrium. `settle_speed` 0:
  // exactly `settle_steps` steps, no check.
  int settle_steps = 500;       // minimum output steps of settling after the grasp (300 Hz)
  int settle_max_steps = 3000;
  double settle_speed = 0.005;
  double settle_damping = 5.0;
  bool keep_frames = false;     // keep gown positions at `frame_times` (for pictures)
  bool record_arm_parts = false;  // fill TrialResult::arm_parts (one ArmPartLoads per sample)
  std::vector<double> frame_times;  // [s] since the start of the pull; negative = before the pull
  // Optional: asked after each sample of the trial's own pull with the samples so far and whether
  // the pull has ended; `true` ends a pull that has not (TrialResult::cut). A caller that only
  // needs to know that a trial is worse than some bound stops it there (calibrate --prune). Not
  // asked in a pull that simulate_trials() shares between trials (no arm has touched the gown
  // yet); the first sample after is. It changes no bit of the samples it lets through.
  std::function<bool(const std::vector<HapticSample>& so_far, bool ended)> pull_watch;
};

// Per-vertex contact force on the arm (paper eq. 2, f = m dx_col / dt^2), time-averaged over
// the last sample before the stop; kept for force maps on the arm.
struct ContactForce {
  int vertex = 0;
  std::array<double, 3> force{};  // [N] world frame, force of the cloth on the arm
};

// The arm's colliders, in the order of the scene's list (arm_part_names()): elbow sphere, fist
// sphere, the hand's cone (only when ArmGeometry::hand > 0), forearm cone, upper-arm cone.
inline constexpr int kArmParts = 5;

// The cloth's force on each part of the arm over one haptic sample (paper eq. 2, f = m dx_col /
// h^2, summed over the part's contacts and averaged over the sample's substeps, with the sign
// flipped: the cloth's force on the arm, friction included): which part carries the drag.
// Parts beyond arm_part_names(scene).size() stay zero.
struct ArmPartLoads {
  std::array<std::array<double, 3>, kArmParts> f{};  // [N] world frame
  // The free (not grasped) vertices' momentum, sum of m v, at the sample's end [kg m/s]: with the
  // gripper's force, the arm's and damping, it closes the gown's momentum balance (tests).
  std::array<double, 3> momentum{};
};

// Gown positions at one time, for pictures.
struct Frame {
  double t = 0;                     // [s] since the start of the pull (negative: settling)
  double travel = 0;                // [m]
  std::vector<float> xyz;           // 3 per vertex, world frame
};

// The sleeve opening as it hangs at the start of the pull, after settling: what decides the
// outcome before any force does. Heights are world z relative to the grasp point (the jaws);
// the arm's axis lies at y = 0. The fist passes under a rim whose lowest point is above its top
// (rim_low_above_fist > r_fist), meets the rim with its face when that point lies between its top
// and its underside, and can enter when it is lower (offline/sim/MEASUREMENTS.md, "Where the
// opening must hang"). Zero when the mesh has no opening.
struct OpeningShape {
  double depth = 0;               // [m] the lowest rim vertex below the grasp point
  double height = 0;              // [m] the loop's vertical extent
  double width = 0;               // [m] its lateral (y) extent
  double centre_y = 0;            // [m] the mean y of its vertices
  double perimeter_ratio = 0;     // its length now / at rest (the loop in order, ClothMesh::sleeve_opening)
  double rim_low_above_fist = 0;  // [m] the lowest rim vertex above this trial's fist centre
};

// What resume_trial() goes on from (trial.cpp).
struct PausedPull;

struct TrialResult {
  double arm_offset = 0;            // [m] the arm offset used (spec.arm_offset plus the arm noise)
  HapticSequence seq;               // samples from the start of the pull; label as `outcome`
  // The label of paper V-A; none when the trial did not stay finite (`finite` false). A gown
  // that blew up has no opening to measure: its d_max stayed 0, so a trial that diverged while
  // settling (no pull sample) or before the end of travel was labelled good.
  std::optional<Outcome> outcome;
  double d_max = 0;                 // [m] paper V-A label distance (NaN-free; 0 when missed or not finite)
  // d_max's two sides, 0 when missed: the most a lower-half vertex of the opening lags behind the
  // elbow centre (on the forearm's side, x below it) and the most one has gone past it (x above;
  // the pull runs along +x). d_max = max(d_behind, d_ahead): the paper's distance has no sign.
  double d_behind = 0, d_ahead = 0;  // [m]
  bool stopped_by_force = false;
  double travel = 0;                // [m] gripper travel at the stop
  double contact_t = -1;            // [s] first sample with cloth-arm contact (-1: none)
  double contact_travel = -1;       // [m] travel then
  double weight = 0;                // [N] gown weight m g
  double support_load = 0;          // [N] the settled gown's downward force on the support (0: none)
  std::array<double, 3> bias{};     // [N] raw force at the start of the pull, removed from samples
  int settle_steps = 0;             // output steps of settling done
  double settle_time = 0;           // [s] their duration
  double settle_speed = 0;          // [m/s] RMS speed of the free vertices over the last 0.1 s of it
  bool settled = true;              // settle_speed reached the spec's limit (false: gave up at the cap)
  OpeningShape opening;             // at the start of the pull
  double area_ratio = 1;            // final triangle area / rest area (explosion check)
  std::array<double, 3> arm_shift{};  // [m] the compliant arm's displacement at the stop (0: fixed arm)
  double arm_shift_max = 0;         // [m] its largest magnitude during the pull
  bool finite = true;               // every position stayed finite
  std::vector<ContactForce> contacts;
  std::vector<ArmPartLoads> arm_parts;  // per sample of seq, with TrialSpec::record_arm_parts
  std::vector<Frame> frames;
  long self_pairs_dropped = 0;      // self-collision pairs beyond the preallocated capacity
  double wall_settle = 0, wall_pull = 0;  // [s] wall time of grasp+settling and of the pull
  bool settle_shared = false;       // simulate_trials(): began from another trial's settling (wall_settle 0)
  // An arm came within contact reach of the settling gown: this trial's, or in simulate_trials()
  // another trial's arm that this settling watched (watch_arms()). Reach is not touch: settlings
  // are shared unless an arm touched the gown.
  bool settle_arm_near = false;
  // simulate_trials(): the travel [m] up to which this trial's pull was another's, pulled as one
  // while no arm touched the gown (0: its own from the start).
  double pull_shared_travel = 0;
  // TrialSpec::pull_watch stopped the pull before the rig would have: the samples end there, and
  // the label and the end-of-pull figures are of that moment, not of a whole trial.
  bool cut = false;
  // A cut trial's simulation at the cut (the gown, the arm, the rig; opaque), for resume_trial().
  // Shared by copies of this result; null when not cut.
  std::shared_ptr<const PausedPull> paused;
};

// The arm (data README; paper IV: capsules, fixed, uniform friction). Spheres fist, wrist,
// elbow, shoulder joined by tapered capsules (round cones); forearm along +x pointing at the
// gripper's start, upper arm horizontal toward -y.
struct ArmGeometry {
  double r_fist = 0.05, r_wrist = 0.0365, r_elbow = 0.05, r_shoulder = 0.075;  // [m]
  double hand = 0.0;          // [m] fist centre to wrist centre (0 in the paper's simulator)
  double forearm = 0.31;      // [m] wrist centre to elbow centre
  double upper_arm = 0.32;    // [m] elbow centre to shoulder centre
  double fist_x = 0.22;       // [m] fist centre ahead of the gripper's start along +x
  // Arm axis height relative to the grasp point for each ArmHeight (data README: high arm
  // 0.0885 m below the upper jaw; middle -0.123 m and low -0.205 m from high).
  std::array<double, 3> z_rel = {-0.0885, -0.2115, -0.2935};
};

// A triangle mesh already placed in the world frame, with what the simulator needs to know.
struct ClothMesh {
  std::vector<std::array<double, 3>> x;       // [m] vertex positions
  std::vector<std::array<int, 3>> tris;
  std::vector<int> grasp;                     // vertices held by the gripper (may be empty: use the jaw box)
  std::vector<int> sleeve_opening;            // the sleeve opening's boundary loop, in order (labels, paper V-A)
  std::string name;
};

struct SceneOptions {
  ArmGeometry arm;
  int substeps = 20;              // XPBD substeps per output step
  double step_hz = 300;           // output steps per second
  double contact_offset = 0.004;  // [m] cloth thickness kept from the arm
  double self_distance = 0.008;   // [m] self-collision distance (data README: 0.008)
  double kinetic_ratio = 0.8;     // Constraint scheme: dynamic / static friction coefficient
  double compression_softening = 1000;  // edge compliance in compression / in tension (fabric buckles)
  // Jaw box (centre relative to the grasp point, half extents) used when ClothMesh::grasp is empty.
  std::array<double, 3> jaw_centre{0, 0, 0};
  std::array<double, 3> jaw_half{0.04, 0.06, 0.01};
  std::array<double, 3> grasp_point{0, 0, 0};  // [m] world position of the grasp at travel 0
  // The jaws close on the grasped vertices: over the first `jaw_close_steps` output steps they
  // move from their placed positions onto the plane z = grasp_point.z - jaw_half.z (the upper
  // jaw's lower face), pinched between the jaws as in the paper's simulator. 0: held as placed.
  int jaw_close_steps = 60;
  bool with_arm = true;
  bool colour_order = true;       // false: constraints in mesh order (the benchmark's baseline)
  bool simd = true;               // false: scalar constraint kernels even where AVX2 runs (same bits; tests, benchmark)
  bool require_grasp = true;      // false: no jaw box; only ClothMesh::grasp is held (physics tests)
  std::vector<std::array<double, 4>> planes;  // test colliders {p : n.p >= d} as (n.x, n.y, n.z, d)
};

struct SceneData;  // model.h
// The constant model of a trial. Cheap to copy (shared, immutable).
class Scene {
 public:
  Scene() = default;
  explicit Scene(std::shared_ptr<const SceneData> d) : d_(std::move(d)) {}
  const SceneData& data() const { return *d_; }
  int vertex_count() const;
  int triangle_count() const;
  double gown_mass() const;                   // [kg] at the density the scene was built with
  const ClothMesh& mesh() const;              // rest mesh (world frame)
 private:
  std::shared_ptr<const SceneData> d_;
};

// Builds the constant model: topology, constraint lists (stretch edges, shear triangles,
// bending stencils), rest lengths, bending matrices, the arm, the grasp set. Throws
// std::invalid_argument naming the problem (empty mesh, bad index, no grasped vertex, an arm
// without a sleeve opening: the outcome is labelled from the opening's lower half, and without
// one every trial that the force limit stopped was labelled good).
// Masses are derived from ClothParams::areal_density at trial time.
Scene make_scene(const ClothMesh& mesh, const SceneOptions& opt = {});

// The names of the scene's arm colliders in ArmPartLoads order: "elbow", "fist", ["hand",]
// "forearm", "upper_arm" (none for a scene without the arm).
std::vector<std::string> arm_part_names(const Scene& scene);

// Which gown a default scene uses.
enum class GownResolution { Full = 0, Reduced = 1, Coarse = 2 };

// The default scene: the gown module's gown (gown::load_gown), the measured one when
// shared/data provides it, else the gown module's parametric gown (gown::make_parametric_gown),
// reduced to the resolution's triangles (gown_scene.h, target_triangles: Reduced 5000, Coarse
// 1500 for fast tests) and placed like the paper.
// `parametric`: the gown module's parametric gown even when the measured one is present.
Scene make_default_scene(GownResolution res = GownResolution::Reduced, bool parametric = false);

// One trial: grasp, gravity, settling (with the optional perturbation during output steps
// 180-330, i.e. 0.5 s) until the gown is at rest, then the pull until max_travel or the force
// limit. Deterministic: the same inputs give the same bits (single thread, no fast-math).
// Throws std::invalid_argument naming the TrialSpec field, before simulating anything, for a
// speed, acceleration or max_travel that is not positive and finite (the pull never reached
// its end: a speed or acceleration of 0 ran forever), a negative settle_steps, an arm_offset or
// a frame time that is not finite, or a height that is none of the three.
TrialResult simulate_trial(const Scene& scene, const ClothParams& params, const TrialSpec& spec);
// The pull's time limit [s]: past the rig's whole travel by 5 s (a guard; the travel or the
// force limit ends every pull first).
double max_time_of(const TrialSpec& spec);
// The longest settling [s]: it gives up at `settle_max_steps` output steps (at least the gown
// perturbation's 1.2 s).
double max_settle_time_of(const TrialSpec& spec, const SceneOptions& opt = {});
// The pull ends at the first sample whose travel is within kTravelEndTolerance [m] of max_travel.
inline constexpr double kTravelEndTolerance = 1e-12;
// [m] The max_travel a pull needs to give two samples, the least a trial file holds (a reader
// refuses one sample: core/dataset.h): the travel of its first sample (3 output steps into the
// rig's ramp: 0.05 mm at 1 m/s^2 and 300 Hz) plus kTravelEndTolerance. A max_travel at or below
// it ends the pull at that first sample.
double least_max_travel_of(const TrialSpec& spec, const SceneOptions& opt = {});

// Several trials with one cloth, the same bits as simulate_trial() on each, in the order of
// `specs`, but each settling done once where it can be: trials that settle alike (the same
// perturbation, friction scheme, self-collision and settling settings; no frames kept) start
// their pulls from one settled gown when their arm is placed where the settling trial's is (to
// the bit: the same model), or, for other arm heights, when no arm of theirs touched the gown
// while it settled (watch_arms(), model.h: the arm is fixed, and it corrects only a vertex that
// comes within the contact offset of it; one that merely comes within contact reach, as in the
// first steps after the grasp, when the stiff gown springs from its measured shape, moves no
// bit), so each of those trials would have settled to those same bits on its own. In
// calibration, where one cloth is pulled over 2-3 arm heights, that saves all settlings but one
// while no arm touches the settling gown; in `predict`, the trials of one height share theirs
// always (TrialResult::settle_shared, settle_arm_near). The trials that start from one settling
// at the same speed, acceleration and force limit are then pulled as one while no arm has
// touched the gown (the same argument: an arm that corrects no vertex, and so stays at rest,
// changes no bit), and each goes on alone from the start of the sample in which one touches
// (TrialResult::pull_shared_travel); where the rig stops one of them, they part before. Every
// spec is checked first, as simulate_trial() checks its one.
std::vector<TrialResult> simulate_trials(const Scene& scene, const ClothParams& params,
                                         const std::vector<TrialSpec>& specs);

// The rest of a trial that TrialSpec::pull_watch cut (TrialResult::cut, paused), from the sample
// where it was cut, without the watch: the same bits as the trial simulated whole without one
// (samples, label, forces, frames; not the wall times), because the paused state is the whole
// state of the pull. The paused state stays as it was, so a trial can be resumed more than once.
// The scene that simulated the trial must still exist (the model points into it).
TrialResult resume_trial(const PausedPull& paused);

// The label rule of paper V-A from the final state; exposed for tests.
Outcome label_outcome(bool full_travel, double d_max);
// The trial's label by name (outcome_name), "none" for a trial without one (not finite).
std::string_view label_name(const TrialResult& r);

}  // namespace dressguard::sim
