// Trials of the simulator on the default gown (measured when shared/data is present, else the
// gown module's parametric gown), coarse resolution to keep the suite fast.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "dataset.h"
#include "files.h"
#include "gown.h"
#include "gown_scene.h"
#include "meshes.h"
#include "model.h"
#include "objective.h"
#include "params.h"
#include "trial.h"

using namespace dressguard;
using namespace dressguard::sim;

namespace {

const Scene& coarse_scene() {
  static const Scene scene = make_default_scene(GownResolution::Coarse);
  return scene;
}

// Where the fist, forearm, elbow and upper arm are among the arm's colliders (a test fails when
// one is absent).
struct ArmParts {
  std::size_t fist, forearm, elbow, upper;
};
ArmParts arm_parts_of(const std::vector<std::string>& names) {
  auto index = [&](const char* name) {
    const auto k = static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
    EXPECT_LT(k, names.size()) << "the arm has no " << name;
    return std::min(k, names.size() - 1);
  };
  return {index("fist"), index("forearm"), index("elbow"), index("upper_arm")};
}

// The coarse scene's model with `p`, its arm placed 1 cm above the high arm.
GownModel arm_model(const ClothParams& p) {
  return make_model(coarse_scene().data(), p, FrictionScheme::Improved, true, 0.01);
}

}  // namespace

// Same inputs, same bits (single thread, no fast-math, fixed orders everywhere); the seed of the
// perturbation must change the result.
TEST(SimTrial, DeterministicBits) {
  TrialSpec spec;
  spec.gown_noise = true;
  spec.seed = 7;
  spec.max_travel = 0.05;
  const TrialResult a = simulate_trial(coarse_scene(), ClothParams{}, spec);
  const TrialResult b = simulate_trial(coarse_scene(), ClothParams{}, spec);
  ASSERT_EQ(a.seq.samples.size(), b.seq.samples.size());
  ASSERT_FALSE(a.seq.samples.empty());
  EXPECT_EQ(0, std::memcmp(a.seq.samples.data(), b.seq.samples.data(), a.seq.samples.size() * sizeof(HapticSample)));
  spec.seed = 8;
  const TrialResult c = simulate_trial(coarse_scene(), ClothParams{}, spec);
  EXPECT_NE(a.seq.samples.back().f_motion, c.seq.samples.back().f_motion) << "the seed must matter";
}

// The AVX2 constraint kernels mirror the scalar constraint functions operation for operation
// (kernels.h), and the gripper's force is summed in one order on both paths: a trial with arm
// contact, self-collision, grasp and perturbation gives the same bits on both (exact: any
// difference means a kernel strayed from its scalar function). Both paths are exercised
// whatever the CPU: the scalar one always; the AVX2 one where the CPU has it (else skipped).
TEST(SimTrial, Avx2AndScalarKernelsGiveTheSameBits) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2: only the scalar kernels run here";
  gown::GownOptions go;
  go.target_triangles = target_triangles(GownResolution::Coarse);
  const gown::GownMesh mesh = gown::load_gown(go);
  SceneOptions opt;
  opt.self_distance = 0.02;  // as make_default_scene(Coarse)
  const Scene simd = make_scene(mesh, gown::PaperScene{}, opt);
  opt.simd = false;
  const Scene scalar = make_scene(mesh, gown::PaperScene{}, opt);
  EXPECT_EQ(make_model(simd.data(), ClothParams{}, FrictionScheme::Improved, true, 0).path, KernelPath::Avx2);
  EXPECT_EQ(make_model(scalar.data(), ClothParams{}, FrictionScheme::Improved, true, 0).path, KernelPath::Scalar);
  TrialSpec spec;
  spec.height = ArmHeight::Middle;  // the arm catches the sleeve: contacts and friction run
  spec.gown_noise = true;
  spec.seed = 3;
  spec.max_travel = 0.3;
  const TrialResult a = simulate_trial(simd, ClothParams{}, spec);
  const TrialResult b = simulate_trial(scalar, ClothParams{}, spec);
  ASSERT_EQ(a.seq.samples.size(), b.seq.samples.size());
  ASSERT_FALSE(a.seq.samples.empty());
  EXPECT_FALSE(a.contacts.empty()) << "the trial should touch the arm";
  EXPECT_EQ(0, std::memcmp(a.seq.samples.data(), b.seq.samples.data(), a.seq.samples.size() * sizeof(HapticSample)));
  EXPECT_EQ(a.area_ratio, b.area_ratio);
}

// No explosion: a trial that ends at the 10 N stop (the gown caught on the arm) keeps every
// position and force finite and the gown's area within 5% of its rest area (the bound;
// the stretch constraints at default stiffness hold it within about 1%). Which arm height
// catches the gown depends on the gown (the measured one: middle; the parametric one, without
// shared/data: high), so the first height whose trial is labelled caught is checked.
TEST(SimTrial, NoExplosionAtTheTenNewtonStop) {
  TrialResult r;
  for (ArmHeight h : {ArmHeight::Middle, ArmHeight::High, ArmHeight::Low}) {
    TrialSpec spec;
    spec.height = h;
    r = simulate_trial(coarse_scene(), ClothParams{}, spec);
    if (r.outcome == Outcome::Caught) break;
  }
  ASSERT_EQ(r.outcome, Outcome::Caught) << "no arm height caught the gown";
  ASSERT_TRUE(r.stopped_by_force) << "expected the 10 N stop; ended at travel " << r.travel;
  EXPECT_TRUE(r.finite);
  EXPECT_NEAR(r.area_ratio, 1.0, 0.05);
  const HapticSample& last = r.seq.samples.back();
  EXPECT_GE(std::max(std::abs(last.f_motion), std::abs(last.f_vertical)), 10.0);
  EXPECT_LT(std::max(std::abs(last.f_motion), std::abs(last.f_vertical)), 30.0) << "one 10 ms sample overshoots little";
  double total = 0;
  for (const ContactForce& c : r.contacts)
    for (double f : c.force) {
      ASSERT_TRUE(std::isfinite(f));
      total += std::abs(f);
    }
  EXPECT_GT(total, 0.0) << "the caught gown presses on the arm (paper eq. 2 contact forces)";
}

// The haptic samples follow the rig: 100 Hz, travel from the 1 m/s^2 profile, bias removed.
TEST(SimTrial, SamplesFollowTheRig) {
  TrialSpec spec;
  spec.height = ArmHeight::Low;  // the settled gown hangs clear of the arm
  spec.max_travel = 0.03;
  spec.speed = 0.15;
  const TrialResult r = simulate_trial(coarse_scene(), ClothParams{}, spec);
  ASSERT_GE(r.seq.samples.size(), 10u);
  for (size_t k = 0; k < r.seq.samples.size(); ++k) {
    const double t = 0.01 * (k + 1);
    EXPECT_NEAR(r.seq.samples[k].t, t, 1e-9);
    const double ta = 0.15;  // v / a
    const double s = t < ta ? 0.5 * t * t : 0.5 * ta * ta + 0.15 * (t - ta);
    EXPECT_NEAR(r.seq.samples[k].travel, std::min(s, 0.03), 1e-9);
  }
  EXPECT_EQ(r.outcome, Outcome::Missed) << "full (short) travel is labelled missed";
  // The bias is the settled gown's weight: raw F_z = -m g (1%: HangingGownWeightOnTheGripper).
  EXPECT_NEAR(-r.bias[2], r.weight, 0.01 * r.weight);
}

namespace {

// A 3 x 3 patch held whole by the gripper, no arm: nothing but the gripper moves it, and no force
// stops its pull.
Scene held_patch_scene() {
  ClothMesh mesh = grid_patch({0, 0, 0}, {0.5, 0, 0}, {0, 0.5, 0}, 3, 3);
  for (int i = 0; i < 9; ++i) mesh.grasp.push_back(i);
  SceneOptions opt;
  opt.with_arm = false;
  opt.jaw_close_steps = 0;
  return make_scene(mesh, opt);
}

}  // namespace

// simulate_trial() checks its spec before it simulates and names the field: a speed or an
// acceleration of 0 pulled forever (the travel never reached max_travel, and the time limit,
// max_time_of(), was infinite), and so did an infinite end of travel; a NaN arm offset or frame
// time, a negative settling or a height beyond the three were taken too. simulate_trials()
// checks every spec alike. With the gripper holding the whole patch no force stops a pull.
TEST(SimTrial, ABadSpecIsRefusedNamingItsField) {
  const Scene scene = held_patch_scene();
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* field;
    std::function<void(TrialSpec&)> spoil;
  };
  // The ones that ended without the check first, then the ones that ran forever.
  const std::vector<Case> cases = {
      {"settle_steps", [](TrialSpec& s) { s.settle_steps = -1; }},
      {"height", [](TrialSpec& s) { s.height = static_cast<ArmHeight>(7); }},
      {"arm_offset", [&](TrialSpec& s) { s.arm_offset = nan; }},
      {"frame_times", [&](TrialSpec& s) { s.frame_times = {0.1, nan}; }},
      {"max_travel", [](TrialSpec& s) { s.max_travel = 0; }},
      {"acceleration", [](TrialSpec& s) { s.acceleration = -1; }},
      {"speed", [](TrialSpec& s) { s.speed = -0.1; }},
      {"max_travel", [&](TrialSpec& s) { s.max_travel = inf; }},
      {"acceleration", [](TrialSpec& s) { s.acceleration = 0; }},
      {"speed", [](TrialSpec& s) { s.speed = 0; }},
      {"speed", [&](TrialSpec& s) { s.speed = nan; }},
  };
  auto refusal = [](const std::function<void()>& run) -> std::string {
    try {
      run();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "(taken)";
  };
  for (const Case& c : cases) {
    TrialSpec spec;
    spec.max_travel = 0.01;
    spec.self_collision = false;
    c.spoil(spec);
    const std::string field = std::string("TrialSpec::") + c.field + " must be";
    std::string e = refusal([&] { simulate_trial(scene, ClothParams{}, spec); });
    EXPECT_NE(e.find(field), std::string::npos) << c.field << ": " << e;
    TrialSpec fine;
    fine.max_travel = 0.01;
    e = refusal([&] { simulate_trials(scene, ClothParams{}, {fine, spec}); });
    EXPECT_NE(e.find(field), std::string::npos) << c.field << " in simulate_trials: " << e;
  }
}

// The gripper's acceleration in each output step is the change of the rig's speed over that
// step, and the pull's time is counted in steps, not summed. A patch held whole by the gripper
// (no free vertex, no arm) loads it with nothing but its mass times the gripper's acceleration,
// so each sample's F_motion is -M times the mean acceleration over its 3 steps. On the rig's
// 1 m/s^2 ramp exactly 30 steps carry it at 0.1 m/s and 45 at 0.15 m/s; with a ramp that ends
// inside a step (0.7 m/s^2) the steps' accelerations still add up to the pull's speed. The time
// summed 1/300 at a time was 0.09999999999999994 after 30 steps, short of v / a = 0.1, so a
// 31st (46th) step carried the whole 1 m/s^2, and the samples' times were off by ulps.
TEST(SimTrial, GripperAccelerationAddsUpToThePullSpeed) {
  const Scene scene = held_patch_scene();
  struct Case {
    double speed, acceleration;
    int ramp_steps;  // output steps that carry the acceleration; -1: the ramp ends inside one
  };
  for (const Case& c : {Case{0.1, 1.0, 30}, Case{0.15, 1.0, 45}, Case{0.1, 0.7, -1}}) {
    TrialSpec spec;
    spec.speed = c.speed;
    spec.acceleration = c.acceleration;
    spec.max_travel = 0.05;
    spec.self_collision = false;
    const TrialResult r = simulate_trial(scene, ClothParams{}, spec);
    ASSERT_GE(r.seq.samples.size(), 20u);
    const double mass = r.weight / 9.81;
    double speed = 0;  // the gripper's, summed from its accelerations
    double steps = 0;  // output steps at the ramp's acceleration
    for (std::size_t k = 0; k < r.seq.samples.size(); ++k) {
      const HapticSample& s = r.seq.samples[k];
      EXPECT_EQ(s.t, static_cast<double>(3 * (k + 1)) / 300.0) << "sample " << k;
      EXPECT_LE(std::abs(s.t - 0.01 * static_cast<double>(k + 1)), std::nextafter(s.t, 1e9) - s.t) << "sample " << k;
      const double a = -s.f_motion / mass;  // the mean over the sample's 3 steps
      speed += a * 3 / 300.0;
      steps += 3 * a / c.acceleration;
    }
    EXPECT_NEAR(speed, c.speed, 1e-9) << c.speed << " m/s at " << c.acceleration << " m/s^2";
    if (c.ramp_steps >= 0) {
      EXPECT_NEAR(steps, c.ramp_steps, 1e-6) << c.speed << " m/s";
    }
  }
}

namespace {

// A tube held at one end by its top vertices, the free end's ring its opening: a small mesh with
// everything a labelled trial needs.
ClothMesh held_tube() {
  ClothMesh mesh = tube(0.075, -0.4, 0.0, 16, 20);
  const int top = 19 * 16 + 4;
  mesh.grasp = {top - 1, top, top + 1};
  for (int iu = 0; iu < 16; ++iu) mesh.sleeve_opening.push_back(iu);
  return mesh;
}

}  // namespace

// A trial whose gown did not stay finite has no label (paper V-A's label needs the opening
// where it is): here the masses are NaN (a NaN areal density), so the gown blows up while it
// settles and the pull gives no sample. Its d_max stayed 0, and it was labelled good.
TEST(SimTrial, ATrialThatBlewUpHasNoLabel) {
  SceneOptions opt;
  opt.jaw_close_steps = 0;
  opt.arm.fist_x = 0.0;
  const Scene scene = make_scene(held_tube(), opt);
  ClothParams blows_up;
  blows_up.areal_density = std::numeric_limits<double>::quiet_NaN();
  TrialSpec spec;
  spec.max_travel = 0.05;
  spec.settle_speed = 0;  // the fixed 500 steps: a NaN gown never comes to rest
  const TrialResult r = simulate_trial(scene, blows_up, spec);
  ASSERT_FALSE(r.finite);
  EXPECT_TRUE(r.seq.samples.empty());
  EXPECT_FALSE(r.outcome.has_value()) << "labelled " << label_name(r);
  EXPECT_FALSE(r.seq.label.has_value());
  EXPECT_EQ(label_name(r), std::string_view("none"));
  EXPECT_EQ(r.d_max, 0.0);
  const std::vector<TrialResult> both = simulate_trials(scene, blows_up, {spec, spec});
  for (const TrialResult& b : both) EXPECT_FALSE(b.outcome.has_value()) << "simulate_trials: " << label_name(b);
  // The same scene with a finite gown is labelled.
  const TrialResult fine = simulate_trial(scene, ClothParams{}, spec);
  EXPECT_TRUE(fine.finite);
  EXPECT_TRUE(fine.outcome.has_value());
  EXPECT_EQ(fine.seq.label, fine.outcome);
}

// A scene with the arm needs a sleeve opening: the label of a trial that the force limit stops
// is the opening's lower half against the elbow, and without one d_max stayed 0, so every such
// trial was labelled good. make_scene says so; a scene without the arm needs none.
TEST(SimTrial, AnArmWithoutASleeveOpeningIsRefused) {
  ClothMesh mesh = held_tube();
  mesh.sleeve_opening.clear();
  try {
    make_scene(mesh, SceneOptions{});
    ADD_FAILURE() << "a scene with the arm and no opening was built";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'tube' has no sleeve opening"), std::string::npos) << e.what();
  }
  SceneOptions no_arm;
  no_arm.with_arm = false;
  EXPECT_NO_THROW(make_scene(mesh, no_arm));
  EXPECT_NO_THROW(make_scene(held_tube(), SceneOptions{}));
}

TEST(SimTrial, LabelRule) {
  EXPECT_EQ(label_outcome(true, 0.0), Outcome::Missed);
  EXPECT_EQ(label_outcome(false, 0.07), Outcome::Good);
  EXPECT_EQ(label_outcome(false, 0.0701), Outcome::Caught);
}

TEST(SimParams, ParseFormats) {
  const ClothParams a = parse_params("friction 0.3\n# comment\nstretch = 0.7\n", "x");
  EXPECT_DOUBLE_EQ(a.friction, 0.3);
  EXPECT_DOUBLE_EQ(a.stretch, 0.7);
  const ClothParams b = parse_params("{\"bend\": 0.25, \"self_friction\": 0.1}", "x");
  EXPECT_DOUBLE_EQ(b.bend, 0.25);
  EXPECT_DOUBLE_EQ(b.self_friction, 0.1);
  const ClothParams c = parse_params(format_params(a), "x");
  EXPECT_EQ(std::memcmp(&a, &c, sizeof a), 0);
  EXPECT_THROW(parse_params("frction 0.3\n", "p.txt"), InputError);
  EXPECT_EQ(parse_params("fist_shift 0.08\n", "x").fist_shift, 0.08);
  EXPECT_THROW(parse_params("fist_shift 0.25\n", "p.txt"), InputError);  // beyond kMaxFistShift
  EXPECT_EQ(parse_params("arm_lateral -0.02\nfist_lateral 0.03\n", "x").fist_lateral, 0.03);
  EXPECT_THROW(parse_params("arm_lateral 0.15\n", "p.txt"), InputError);  // beyond kMaxArmLateral
  EXPECT_THROW(parse_params("fist_lateral -0.15\n", "p.txt"), InputError);
  EXPECT_EQ(parse_params("support_depth 0.6\nsupport_lateral -0.1\n", "x").support_lateral, -0.1);
  EXPECT_THROW(parse_params("support_depth 1.6\n", "p.txt"), InputError);  // beyond kMaxSupportDepth
  EXPECT_THROW(parse_params("support_depth -0.1\n", "p.txt"), InputError);
  EXPECT_THROW(parse_params("support_lateral 0.4\n", "p.txt"), InputError);  // beyond kMaxSupportLateral
  // A stiffness is a position on its compliance scale: beyond [0, 1] compliance_of() would clamp it
  // and the file's value would not be the one simulated.
  EXPECT_EQ(parse_params("stretch 0\nshear 1\nbend 0\n", "x").shear, 1.0);
  EXPECT_THROW(parse_params("stretch -0.1\n", "p.txt"), InputError);
  EXPECT_THROW(parse_params("bend 1.2\n", "p.txt"), InputError);
  EXPECT_THROW(parse_params("friction -0.2\n", "p.txt"), InputError);
  EXPECT_THROW(parse_params("self_friction -0.2\n", "p.txt"), InputError);
  try {
    parse_params("friction 0.3\nbend x\n", "p.txt");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("p.txt:2"), std::string::npos) << e.what();
  }
}

// The three outcomes from the arm height alone (issue 5): sweeping the arm from the high setting
// down past the low one (5 cm steps) with the default parameters gives good, then caught, then
// missed, each at least once and in that order (a return to an earlier outcome fails). On the
// reduced measured gown: the coarse gown's 5 cm edges cannot hold a 0.47 m opening in shape
// (its sweep mixes the outcomes), and the label rule's 7 cm is finer than they are. What the
// sweep shows physically: at the high setting the fist enters the opening and the sleeve's rim
// ends against the upper arm (d_max ~ 6 cm); a few cm lower the fist meets the rim's lower edge
// or the sleeve rides over the forearm and jams at the elbow (caught); lower still the gown
// slides over the arm to the end of travel (missed). The trials run on two threads
// (simulate_trial is thread-safe; each result is the same bits on any thread).
TEST(SimTrial, ThreeOutcomesFromArmHeightAlone) {
  if (gown::measured_gown_path().empty())
    GTEST_SKIP() << "shared/data/gown/fullgown.obj is not present: the sweep is a property of the measured gown";
  const Scene scene = make_default_scene(GownResolution::Reduced);
  const std::vector<double> offsets = {0.0, -0.05, -0.10, -0.15, -0.20, -0.25};
  std::vector<TrialResult> results(offsets.size());
  auto run = [&](size_t first) {
    for (size_t k = first; k < offsets.size(); k += 2) {
      TrialSpec spec;
      spec.height = ArmHeight::High;
      spec.arm_offset = offsets[k];
      results[k] = simulate_trial(scene, ClothParams{}, spec);
    }
  };
  std::thread other(run, 1);
  run(0);
  other.join();
  std::vector<Outcome> seen;
  for (size_t k = 0; k < offsets.size(); ++k) {
    const TrialResult& r = results[k];
    std::printf("arm offset %+.2f m: %-7s travel %.3f m, d_max %.3f m (behind the elbow %.3f, past it %.3f)\n", offsets[k],
                std::string(label_name(r)).c_str(), r.travel, r.d_max, r.d_behind, r.d_ahead);
    // The label's two sides make up its unsigned distance; a missed trial has neither.
    EXPECT_EQ(r.d_max, std::max(r.d_behind, r.d_ahead)) << offsets[k];
    if (r.outcome == Outcome::Missed) {
      EXPECT_EQ(r.d_behind, 0.0);
      EXPECT_EQ(r.d_ahead, 0.0);
    }
    ASSERT_TRUE(r.outcome.has_value()) << offsets[k];
    if (seen.empty() || seen.back() != *r.outcome) seen.push_back(*r.outcome);
  }
  const std::vector<Outcome> want = {Outcome::Good, Outcome::Caught, Outcome::Missed};
  EXPECT_EQ(seen, want);
}

// Plausibility against the measured trials of participant 4 (good/3 at the high arm, miss/2 at
// the low arm; and the lateral force's sign at the end of the missed trial) after a coarse grid over friction {0.35, 0.5} and stretch {0.2, 0.6} at arm offset
// 0 (bend 0.7, the default), reduced gown: among the grid points whose low-arm trial is a miss
// (the check is about a simulated missed trial), the one with the smallest objective (eq. 3-5)
// is kept; its high-arm trial must end at the 10 N stop within 0.1 m of the measured travel, and
// its low-arm trial's final drag must be within 50% of the measured one (the issue's
// tolerances). The low-arm trial runs to 0.72 m, where the rig stopped miss/2
// (rig_end_of_travel, as calibration does), so both drags are read at the same travel.
// Measured on this grid (dg_sim_fit, offline/sim/MEASUREMENTS.md): friction 0.35 / stretch 0.2 wins
// (L 4.33 + 0.69; stop 0.559 m against 0.607, drag -2.58 N against -3.99). What the test does not
// hide: at friction 0.2 the objective would pick stretch 0.2 (L 3.54 + 0.88), whose drag is
// -2.16 N, 54% short: the good trial's term dominates the sum and prefers less friction than
// the missed trial's drag needs (calibration, with arm offsets, settles at friction 0.44). At
// the paper's offset -0.02 m our high arm catches or misses the sleeve; our offsets are ours.
// The coarse gown cannot hold the opening's shape (its drag at 0.72 m is -0.3 to -1.1 N), so
// the grid runs on the reduced gown, its four points on two threads (about 30 s).
TEST(SimTrial, PlausibleAgainstMeasuredParticipant4) {
  const auto study = study_dir();
  if (study.empty()) GTEST_SKIP() << "shared/data is not present (needs the study's measured trials)";
  if (gown::measured_gown_path().empty()) GTEST_SKIP() << "shared/data/gown/fullgown.obj is not present";
  const auto good = read_study_trial(study / "good/subject4/3.txt");
  const auto miss = read_study_trial(study / "miss/subject4/2.txt");
  const Scene scene = make_default_scene(GownResolution::Reduced);
  struct Point {
    double friction, stretch;
    TrialResult g, m;
  };
  std::vector<Point> grid;
  for (double friction : {0.35, 0.5})
    for (double stretch : {0.2, 0.6}) grid.push_back({friction, stretch, {}, {}});
  auto run = [&](size_t first) {
    for (size_t k = first; k < grid.size(); k += 2) {
      ClothParams p;
      p.friction = grid[k].friction;
      p.stretch = grid[k].stretch;
      TrialSpec sg, sm;
      sg.height = ArmHeight::High;
      sm.height = ArmHeight::Low;
      sg.speed = estimate_speed(good);
      sm.speed = estimate_speed(miss);
      sm.max_travel = rig_end_of_travel(miss);  // 0.72 m: where the rig stopped miss/2
      grid[k].g = simulate_trial(scene, p, sg);
      grid[k].m = simulate_trial(scene, p, sm);
    }
  };
  std::thread other(run, 1);
  run(0);
  other.join();
  double best = 1e300;
  const Point* chosen = nullptr;
  for (const Point& q : grid) {
    const double l = calib::area_objective(q.g.seq.samples, good) + calib::area_objective(q.m.seq.samples, miss);
    std::printf("friction %.2f stretch %.2f: L %.3f (high: %s %.3f m, low: %s %.3f m, %.2f N)\n", q.friction, q.stretch, l,
                std::string(label_name(q.g)).c_str(), q.g.travel, std::string(label_name(q.m)).c_str(),
                q.m.travel, q.m.seq.samples.back().f_motion);
    if (q.m.outcome == Outcome::Missed && l < best) best = l, chosen = &q;
  }
  ASSERT_NE(chosen, nullptr) << "no grid point gives a missed low-arm trial";
  EXPECT_TRUE(chosen->g.stopped_by_force);
  EXPECT_NEAR(chosen->g.travel, good.back().travel, 0.1);
  EXPECT_NEAR(chosen->m.travel, miss.back().travel, 1e-6) << "the low-arm trial ends where the rig stopped";
  EXPECT_NEAR(chosen->m.seq.samples.back().f_motion, miss.back().f_motion, 0.5 * std::abs(miss.back().f_motion));
  // The rig's lateral axis (trial.h): over the last 0.1 m of a missed trial the sleeve lies on the
  // forearm and the gown pulls toward the upper arm's side; miss/2 reads +0.15 N there, as 13 of
  // the 14 measured missed trials read a positive F_lateral. The simulated trial must too.
  auto late_lateral = [](const std::vector<HapticSample>& seq) {
    double sum = 0;
    int n = 0;
    for (const HapticSample& s : seq)
      if (s.travel >= seq.back().travel - 0.1) sum += s.f_lateral, ++n;
    return sum / n;
  };
  std::printf("F_lateral over the last 0.1 m: measured %+.3f N, simulated %+.3f N\n", late_lateral(miss),
              late_lateral(chosen->m.seq.samples));
  EXPECT_GT(late_lateral(miss), 0.0);
  EXPECT_GT(late_lateral(chosen->m.seq.samples), 0.0);
}

// Arm-height noise (paper V-A): +-1.5 cm around the high and low heights, -6..0 cm at the middle,
// drawn from the trial's seed.
TEST(SimTrial, ArmHeightNoiseRanges) {
  TrialSpec spec;
  spec.arm_noise = true;
  spec.settle_steps = 3;
  spec.settle_speed = 0;  // exactly 3 steps: only the drawn offset is checked
  spec.max_travel = 1e-4;
  std::vector<double> seen;
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low})
    for (uint64_t seed : {1u, 2u, 3u}) {
      spec.height = h;
      spec.seed = seed;
      const double o = simulate_trial(coarse_scene(), ClothParams{}, spec).arm_offset;
      if (h == ArmHeight::Middle) {
        EXPECT_GE(o, -0.06);
        EXPECT_LE(o, 0.0);
      } else {
        EXPECT_GE(o, -0.015);
        EXPECT_LE(o, 0.015);
      }
      seen.push_back(o);
    }
  EXPECT_NE(seen[0], seen[1]);
}

// The default gown (measured when present) hanging still from the closed jaws, the arm out of
// the way: before the bias removal the gripper's vertical force is the gown's weight within 1%
// (the tolerance) and its horizontal force vanishes. The trial's own settling is used
// (TrialSpec::settle_speed): the bias it takes is what every trial subtracts.
TEST(SimTrial, HangingGownWeightOnTheGripper) {
  TrialSpec spec;
  spec.max_travel = 1e-4;
  spec.arm_offset = -2.0;
  const TrialResult r = simulate_trial(coarse_scene(), ClothParams{}, spec);
  ASSERT_TRUE(r.settled) << "RMS speed " << r.settle_speed << " m/s after " << r.settle_time << " s";
  EXPECT_NEAR(-r.bias[2], r.weight, 0.01 * r.weight);
  EXPECT_NEAR(std::hypot(r.bias[0], r.bias[1]), 0.0, 0.01 * r.weight);
}

// The support under the gown (ClothParams::support_depth) carries what the gown lays on it and
// the gripper the rest: at rest their vertical forces add up to the gown's weight (statics; 1 %,
// as for the gown hanging from the gripper alone), and the support carries a real share of it. It
// rose into its place while the gown settled, so at the start of the pull no vertex lies inside
// it (within the contact offset, 1 mm for the last substep's slack). Without one it carries
// nothing. The arm is 2 m below, out of the way.
TEST(SimTrial, SupportAndGripperShareTheGownsWeight) {
  TrialSpec spec;
  spec.max_travel = 1e-4;
  spec.arm_offset = -2.0;
  spec.keep_frames = true;
  spec.frame_times = {0.0};
  ClothParams p;
  p.support_depth = 0.6;
  p.support_lateral = -0.1;
  const TrialResult r = simulate_trial(coarse_scene(), p, spec);
  ASSERT_TRUE(r.settled) << "RMS speed " << r.settle_speed << " m/s after " << r.settle_time << " s";
  std::printf("weight %.4f N: gripper %.4f N, support %.4f N\n", r.weight, -r.bias[2], r.support_load);
  EXPECT_GT(r.support_load, 0.1 * r.weight);
  EXPECT_NEAR(-r.bias[2] + r.support_load, r.weight, 0.01 * r.weight);
  const SceneData& sc = coarse_scene().data();
  const RoundCone support = support_collider(sc.opt, p);
  EXPECT_NEAR(support.a.z, sc.opt.grasp_point[2] - 0.6, 1e-12);
  EXPECT_NEAR(support.a.y, -0.1, 1e-12);
  EXPECT_NEAR(support.ra, kSupportRadius, 0);
  ASSERT_GE(r.frames.size(), 1u);
  ASSERT_EQ(r.frames[0].t, 0.0);
  const std::vector<float>& x = r.frames[0].xyz;
  double nearest = 1e9;
  int touching = 0;
  for (size_t i = 0; i + 2 < x.size(); i += 3) {
    V3 n;
    const double phi = round_cone_distance(support, V3{x[i], x[i + 1], x[i + 2]}, &n);
    nearest = std::min(nearest, phi);
    touching += phi < sc.opt.contact_offset + 0.005;
  }
  EXPECT_GT(nearest, sc.opt.contact_offset - 0.001);
  // Several vertices: 6 of the coarse gown's (11 before its hem kept its vertex floor, 64 hem
  // vertices instead of 56, reduce.cpp); the share of the weight above is what counts.
  EXPECT_GE(touching, 5) << "the gown lies on the support";
  const TrialResult none = simulate_trial(coarse_scene(), ClothParams{}, spec);
  EXPECT_EQ(none.support_load, 0.0);
}

// Where the opening hangs (TrialResult::opening) is measured once the gown has settled, from this
// trial's own fist: with the arm far below the gown (it settles alike at both heights) the
// opening is the same, its rim keeps its length within 10 % (the default cloth), and its lowest
// point's height above the fist centre differs between the high and low arm by exactly their
// heights' difference: depth + rim_low_above_fist = -(z_rel + arm offset), the fist's depth below
// the jaws.
TEST(SimTrial, OpeningIsMeasuredFromTheTrialsFist) {
  const SceneOptions& opt = coarse_scene().data().opt;
  TrialResult r[2];
  const ArmHeight heights[2] = {ArmHeight::High, ArmHeight::Low};
  for (int k = 0; k < 2; ++k) {
    TrialSpec spec;
    spec.height = heights[k];
    spec.max_travel = 1e-4;
    spec.arm_offset = -2.0;
    r[k] = simulate_trial(coarse_scene(), ClothParams{}, spec);
    const double fist_below_jaws = -(opt.arm.z_rel[static_cast<int>(heights[k])] + spec.arm_offset);
    EXPECT_NEAR(r[k].opening.depth + r[k].opening.rim_low_above_fist, fist_below_jaws, 1e-9);
    EXPECT_GT(r[k].opening.depth, 0.05);
    EXPECT_LT(r[k].opening.depth, 0.3);
    EXPECT_NEAR(r[k].opening.perimeter_ratio, 1.0, 0.1);
    EXPECT_GT(r[k].opening.width, 0.05);
  }
  std::printf("coarse gown, default cloth: opening %.1f cm below the jaws, %.1f x %.1f cm, rim %.0f %%\n",
              100 * r[0].opening.depth, 100 * r[0].opening.height, 100 * r[0].opening.width,
              100 * r[0].opening.perimeter_ratio);
  EXPECT_EQ(r[0].opening.depth, r[1].opening.depth);
  EXPECT_NEAR(r[0].opening.rim_low_above_fist - r[1].opening.rim_low_above_fist, opt.arm.z_rel[2] - opt.arm.z_rel[0],
              1e-9);
  // The same two trials run together (the low one reuses the high one's settling, no arm touched
  // it): each keeps its own opening, as run alone (the low one used to report the high one's).
  TrialSpec specs[2];
  for (int k = 0; k < 2; ++k) {
    specs[k].height = heights[k];
    specs[k].max_travel = 1e-4;
    specs[k].arm_offset = -2.0;
  }
  const std::vector<TrialResult> both = simulate_trials(coarse_scene(), ClothParams{}, {specs[0], specs[1]});
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(both[k].opening.rim_low_above_fist, r[k].opening.rim_low_above_fist) << k;
    EXPECT_EQ(both[k].opening.depth, r[k].opening.depth) << k;
  }
  EXPECT_TRUE(both[1].settle_shared) << "the case under test: the low trial reused the high one's settling";
}

// Paper V-A: after the perturbation the robot waits for the gown to settle before it pulls. With
// the push (two seeds) the gown is at rest when the pull starts (RMS vertex speed <= 5 mm/s, the
// settling's criterion) and, on the low arm that it does not touch in the first 3 cm, the first
// samples carry only the rig's start: the grasped gown's inertia, m a = 0.23 kg * 1 m/s^2, in
// motion, and nothing in the vertical, so |F_motion| <= 0.5 N and |F_vertical| <= 0.2 N. The
// fixed 1.7 s settling of session 1 left the gown swinging at about 2 m/s RMS and these samples
// at 0.7-2.3 N.
TEST(SimTrial, GownAtRestWhenThePullStarts) {
  for (uint64_t seed : {1u, 2u}) {
    TrialSpec spec;
    spec.height = ArmHeight::Low;
    spec.gown_noise = true;
    spec.seed = seed;
    spec.max_travel = 0.03;
    const TrialResult r = simulate_trial(coarse_scene(), ClothParams{}, spec);
    EXPECT_TRUE(r.settled) << "seed " << seed;
    EXPECT_LE(r.settle_speed, spec.settle_speed) << "seed " << seed;
    EXPECT_GT(r.settle_time, 330 / 300.0) << "settling ends after the push";
    ASSERT_FALSE(r.seq.samples.empty());
    for (const HapticSample& q : r.seq.samples) {
      EXPECT_LE(std::abs(q.f_motion), 0.5) << "seed " << seed << " travel " << q.travel;
      EXPECT_LE(std::abs(q.f_vertical), 0.2) << "seed " << seed << " travel " << q.travel;
    }
  }
}

namespace {

// One trial per arm height (high, middle, low), pulled to `max_travel`.
std::vector<TrialSpec> three_heights(double max_travel) {
  std::vector<TrialSpec> specs;
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low}) {
    TrialSpec s;
    s.height = h;
    s.max_travel = max_travel;
    specs.push_back(s);
  }
  return specs;
}

void expect_same_trial(const TrialResult& a, const TrialResult& b, const char* what) {
  ASSERT_EQ(a.seq.samples.size(), b.seq.samples.size()) << what;
  ASSERT_FALSE(a.seq.samples.empty()) << what;
  EXPECT_EQ(0, std::memcmp(a.seq.samples.data(), b.seq.samples.data(), a.seq.samples.size() * sizeof(HapticSample)))
      << what;
  EXPECT_EQ(a.bias, b.bias) << what;
  EXPECT_EQ(a.settle_steps, b.settle_steps) << what;
  EXPECT_EQ(a.outcome, b.outcome) << what;
  EXPECT_EQ(a.d_max, b.d_max) << what;
  EXPECT_EQ(a.arm_offset, b.arm_offset) << what;
  EXPECT_EQ(a.travel, b.travel) << what;
  EXPECT_EQ(a.contact_travel, b.contact_travel) << what;
  EXPECT_EQ(a.arm_shift, b.arm_shift) << what;
  EXPECT_EQ(a.seq.id, b.seq.id) << what;
}

}  // namespace

// simulate_trials() settles one cloth once for the three arm heights (the arm is far from the
// hanging gown until the pull) and still gives each trial the bits of its own simulate_trial():
// the sharing is exact, not an approximation. With the perturbation and arm noise of one seed the
// settling is shared too (same push; the arm noise moves only the arm); a different seed's push
// is not.
TEST(SimTrial, SharedSettlingGivesEachTrialItsOwnBits) {
  std::vector<TrialSpec> specs = three_heights(0.12);
  TrialSpec pushed = specs[0];
  pushed.gown_noise = true;
  pushed.arm_noise = true;
  pushed.seed = 5;
  specs.push_back(pushed);
  pushed.height = ArmHeight::Low;
  specs.push_back(pushed);
  pushed.seed = 6;
  specs.push_back(pushed);
  const std::vector<TrialResult> together = simulate_trials(coarse_scene(), ClothParams{}, specs);
  ASSERT_EQ(together.size(), specs.size());
  for (size_t i = 0; i < specs.size(); ++i) {
    const TrialResult alone = simulate_trial(coarse_scene(), ClothParams{}, specs[i]);
    expect_same_trial(together[i], alone, ("trial " + std::to_string(i)).c_str());
  }
  EXPECT_FALSE(together[0].settle_shared);
  EXPECT_TRUE(together[1].settle_shared) << "middle should start from high's settling";
  EXPECT_TRUE(together[2].settle_shared) << "low should start from high's settling";
  EXPECT_FALSE(together[3].settle_shared) << "a pushed gown settles differently from an unpushed one";
  // The same seed pushes the same way: on the measured gown the pushed gown stays out of both
  // arms' reach and the settling is shared. The parametric gown (no shared/data) swings within
  // the probe's reach of an arm after the push, so there the two settle apart (same bits still).
  if (!gown::measured_gown_path().empty()) {
    EXPECT_TRUE(together[4].settle_shared) << "the same seed pushes the same way";
  }
  EXPECT_FALSE(together[5].settle_shared) << "another seed pushes another way";
}

// The support is not the arm: it touches the gown in every settling, and the three heights'
// trials still start from one settling when no arm touched the gown, each with its own bits, and
// pull as one until an arm touches it (SharedSettlingGivesEachTrialItsOwnBits with a support).
// 0.8 m down: on the coarse gown a support at 0.6 m lifts the hem's cloth within reach of the high
// arm while it settles, and then (rightly) nothing is shared.
TEST(SimTrial, SettlingOnTheSupportIsShared) {
  ClothParams p;
  p.support_depth = 0.8;
  p.support_lateral = -0.1;
  const std::vector<TrialSpec> specs = three_heights(0.12);
  const std::vector<TrialResult> together = simulate_trials(coarse_scene(), p, specs);
  ASSERT_EQ(together.size(), specs.size());
  for (size_t i = 0; i < specs.size(); ++i) {
    const TrialResult alone = simulate_trial(coarse_scene(), p, specs[i]);
    expect_same_trial(together[i], alone, ("trial " + std::to_string(i)).c_str());
    EXPECT_GT(alone.support_load, 0.0);
  }
  EXPECT_TRUE(together[1].settle_shared) << "middle should start from high's settling";
  EXPECT_TRUE(together[2].settle_shared) << "low should start from high's settling";
}

// Where an arm touches the gown while it settles, no settling is shared between different arm
// heights, whether it is the first trial's own arm or another trial's arm found by the probe
// (arm_in_reach()): a tube held at one end falls onto a fist placed under the grasp at the high
// height; the low arm is far below it. Each order gives every trial its own bits. Trials with
// the same arm share the settling even so (it is the same simulation to the bit), before or
// after a trial of the other height.
TEST(SimTrial, NoSharedSettlingWhereAnArmTouchesTheGown) {
  ClothMesh mesh = tube(0.075, -0.4, 0.0, 16, 20);
  const int top = 19 * 16 + 4;
  mesh.grasp = {top - 1, top, top + 1};
  for (int iu = 0; iu < 16; ++iu) mesh.sleeve_opening.push_back(iu);  // the free end's ring (labels)
  SceneOptions opt;
  opt.jaw_close_steps = 0;
  opt.arm.fist_x = 0.0;                    // the fist right under the grasp
  opt.arm.z_rel = {-0.25, -1.0, -2.0};     // high: inside the hanging tube; low: 2 m below
  const Scene scene = make_scene(mesh, opt);
  TrialSpec high, low;
  high.height = ArmHeight::High;
  low.height = ArmHeight::Low;
  high.max_travel = low.max_travel = 0.05;
  const TrialResult h = simulate_trial(scene, ClothParams{}, high);
  const TrialResult l = simulate_trial(scene, ClothParams{}, low);
  ASSERT_NE(h.bias, l.bias) << "the fist should hold part of the tube while it settles";
  for (const auto& order : {std::vector<TrialSpec>{high, low}, std::vector<TrialSpec>{low, high}}) {
    const std::vector<TrialResult> r = simulate_trials(scene, ClothParams{}, order);
    const bool high_first = order[0].height == ArmHeight::High;
    expect_same_trial(r[0], high_first ? h : l, "first");
    expect_same_trial(r[1], high_first ? l : h, "second");
    EXPECT_FALSE(r[0].settle_shared || r[1].settle_shared);
  }
  TrialSpec high_on = high, low_on = low;
  high_on.max_travel = low_on.max_travel = 0.08;  // a longer pull from the same settling
  const std::vector<TrialResult> r = simulate_trials(scene, ClothParams{}, {high, low, high_on, low_on});
  expect_same_trial(r[0], h, "high");
  expect_same_trial(r[1], l, "low");
  expect_same_trial(r[2], simulate_trial(scene, ClothParams{}, high_on), "high, longer");
  expect_same_trial(r[3], simulate_trial(scene, ClothParams{}, low_on), "low, longer");
  EXPECT_FALSE(r[0].settle_shared || r[1].settle_shared);
  EXPECT_TRUE(r[2].settle_shared) << "the same high arm settles the same way, touching or not";
  EXPECT_TRUE(r[3].settle_shared) << "the same low arm too";
}

// Coming within contact reach is not touching: an arm whose candidates stay outside the contact
// offset corrects no vertex, so trials of that arm height still share the settling, with their
// own bits. The tube held at one end swings down past a second arm placed at a sweep of heights
// under the grasp (the first trial's own arm is 2 m below, out of reach). Some heights are
// touched (not shared), some only neared (shared, which the reach-only rule refused), and every
// trial has the bits of its own simulate_trial().
TEST(SimTrial, SharedSettlingWhereAnArmCameNearButDidNotTouch) {
  ClothMesh mesh = tube(0.075, -0.4, 0.0, 16, 20);
  const int top = 19 * 16 + 4;
  mesh.grasp = {top - 1, top, top + 1};
  for (int iu = 0; iu < 16; ++iu) mesh.sleeve_opening.push_back(iu);  // the free end's ring (labels)
  int near_shared = 0, touched = 0;
  for (int mm = 310; mm <= 350; mm += 5) {
    SceneOptions opt;
    opt.jaw_close_steps = 0;
    opt.arm.fist_x = 0.0;
    opt.arm.z_rel = {-2.0, -0.001 * mm, -3.0};
    const Scene scene = make_scene(mesh, opt);
    TrialSpec far, swept;
    far.height = ArmHeight::High;
    swept.height = ArmHeight::Middle;
    far.max_travel = swept.max_travel = 0.02;
    const std::vector<TrialResult> r = simulate_trials(scene, ClothParams{}, {far, swept});
    const std::string at = "second arm " + std::to_string(mm) + " mm below the grasp";
    expect_same_trial(r[0], simulate_trial(scene, ClothParams{}, far), (at + ", first").c_str());
    expect_same_trial(r[1], simulate_trial(scene, ClothParams{}, swept), (at + ", second").c_str());
    if (r[1].settle_shared) {
      near_shared += r[0].settle_arm_near;
    } else {
      ++touched;
      EXPECT_TRUE(r[0].settle_arm_near) << at << ": not shared, so the arm should have come near";
    }
  }
  EXPECT_GT(near_shared, 0) << "no height where the arm came within reach without touching";
  EXPECT_GT(touched, 0) << "no height where the swinging tube touched the arm";
}

// Pulls that start from one settling at the same speed are the same computation until an arm
// touches the gown: simulate_trials() pulls them as one that far and forks them in the sample of
// the first touch, and each trial still has the bits of its own simulate_trial(). The fork comes
// one sample (1 mm at 0.1 m/s) before the first contact of any of them; a trial at another speed
// pulls alone, and a different end of travel (0.25 m) is no reason to fork before it.
TEST(SimTrial, SharedPullUntilAnArmTouchesGivesEachTrialItsOwnBits) {
  ClothParams cloth;
  cloth.arm_compliance = 0.005;  // a compliant arm, at rest until touched
  std::vector<TrialSpec> specs(4);
  specs[0].height = ArmHeight::Low;  // first: the pull watches the arms that touch sooner
  specs[1].height = ArmHeight::Middle;
  specs[2].height = ArmHeight::High;
  specs[3].height = ArmHeight::Low;
  for (TrialSpec& s : specs) s.max_travel = 0.3;
  specs[1].max_travel = 0.25;
  specs[3].speed = 0.15;
  const std::vector<TrialResult> together = simulate_trials(coarse_scene(), cloth, specs);
  double first_contact = 1e9;
  for (size_t i = 0; i < specs.size(); ++i) {
    const TrialResult alone = simulate_trial(coarse_scene(), cloth, specs[i]);
    expect_same_trial(together[i], alone, ("trial " + std::to_string(i)).c_str());
    ASSERT_GT(alone.contact_travel, 0) << "trial " << i << " should touch the arm by 0.25 m";
    if (i < 3) first_contact = std::min(first_contact, alone.contact_travel);
  }
  ASSERT_TRUE(together[1].settle_shared && together[2].settle_shared) << "the coarse gown settles clear of the arms";
  EXPECT_EQ(together[0].pull_shared_travel, 0.0) << "the first trial's pull is its own";
  for (int i : {1, 2}) {
    EXPECT_LT(together[i].pull_shared_travel, first_contact) << "trial " << i << ": shared past the first touch";
    EXPECT_GT(together[i].pull_shared_travel, first_contact - 0.0011) << "trial " << i << ": forked before the sample of the first touch";
  }
  EXPECT_EQ(together[3].pull_shared_travel, 0.0) << "another speed pulls alone";
}

// TrialSpec::pull_watch (calibrate --prune): it is asked after every sample of a trial's own
// pull and once at its end, it stops a pull where it says so (cut), and the samples it lets
// through are the uncut trial's to the bit, also after a pull that simulate_trials() shared.
TEST(SimTrial, PullWatchCutsThePullAndKeepsItsBits) {
  std::vector<TrialSpec> specs(2);
  specs[0].height = ArmHeight::Low;
  specs[1].height = ArmHeight::High;
  for (TrialSpec& s : specs) s.max_travel = 0.2;
  const std::vector<TrialResult> whole = simulate_trials(coarse_scene(), ClothParams{}, specs);
  ASSERT_GT(whole[1].pull_shared_travel, 0.0) << "the high arm's pull should begin shared with the low arm's";

  // A watch that lets every sample through: asked once per sample after the shared part, told
  // of the end once, and nothing cut.
  std::vector<size_t> asked(2, 0), ended(2, 0);
  std::vector<TrialSpec> watched = specs;
  for (size_t k = 0; k < 2; ++k)
    watched[k].pull_watch = [&asked, &ended, k](const std::vector<HapticSample>&, bool end) {
      ++asked[k];
      if (end) ++ended[k];
      return false;
    };
  const std::vector<TrialResult> seen = simulate_trials(coarse_scene(), ClothParams{}, watched);
  for (size_t k = 0; k < 2; ++k) {
    expect_same_trial(seen[k], whole[k], ("watched trial " + std::to_string(k)).c_str());
    EXPECT_FALSE(seen[k].cut);
    EXPECT_EQ(ended[k], 1u) << "trial " << k;
    // Both pulls (the first one's too) were one up to the second's pull_shared_travel.
    const auto shared = static_cast<size_t>(std::count_if(
        whole[k].seq.samples.begin(), whole[k].seq.samples.end(),
        [&](const HapticSample& h) { return h.travel <= whole[1].pull_shared_travel; }));
    EXPECT_EQ(asked[k], whole[k].seq.samples.size() - shared) << "trial " << k;
  }

  // A watch that stops each pull at 0.1 m: cut there, the samples before it the same bits.
  std::vector<TrialSpec> cut = specs;
  for (TrialSpec& s : cut)
    s.pull_watch = [](const std::vector<HapticSample>& so_far, bool) { return so_far.back().travel >= 0.1; };
  const std::vector<TrialResult> short_ = simulate_trials(coarse_scene(), ClothParams{}, cut);
  for (size_t k = 0; k < 2; ++k) {
    const auto& got = short_[k].seq.samples;
    EXPECT_TRUE(short_[k].cut) << "trial " << k;
    ASSERT_FALSE(got.empty());
    EXPECT_GE(got.back().travel, 0.1);
    EXPECT_LT(got[got.size() - 2].travel, 0.1) << "trial " << k << " went on past the watch";
    ASSERT_LT(got.size(), whole[k].seq.samples.size());
    EXPECT_EQ(0, std::memcmp(got.data(), whole[k].seq.samples.data(), got.size() * sizeof(HapticSample))) << "trial " << k;
  }
}

// resume_trial() (calibrate --prune keeps the mu best exact without simulating a cut candidate
// again): a cut pull goes on from its paused state to the uncut trial's bits, with a compliant
// arm (its spring state carries over) and after a pull that simulate_trials() shared; the cut is
// placed past each trial's first contact, so the arm has moved and the contacts are live. The
// paused state is left as it was (a second resume gives the same bits), and a trial that was not
// cut keeps none.
TEST(SimTrial, ACutPullResumesToTheUncutTrialsBits) {
  ClothParams cloth;
  cloth.arm_compliance = 0.005;
  std::vector<TrialSpec> specs(2);
  specs[0].height = ArmHeight::Low;
  specs[1].height = ArmHeight::High;
  for (TrialSpec& s : specs) s.max_travel = 0.3;
  const std::vector<TrialResult> whole = simulate_trials(coarse_scene(), cloth, specs);
  std::vector<TrialSpec> cut = specs;
  for (size_t k = 0; k < 2; ++k) {
    ASSERT_GT(whole[k].contact_travel, 0.0) << "trial " << k << " never touches the arm";
    ASSERT_LT(whole[k].contact_travel + 0.05, whole[k].travel) << "trial " << k << " ends too soon after its contact";
    EXPECT_FALSE(whole[k].paused) << "trial " << k;
    const double at = whole[k].contact_travel + 0.03;
    cut[k].pull_watch = [at](const std::vector<HapticSample>& so_far, bool) { return so_far.back().travel >= at; };
  }
  ASSERT_GT(whole[1].pull_shared_travel, 0.0) << "the high arm's pull should begin shared with the low arm's";
  const std::vector<TrialResult> short_ = simulate_trials(coarse_scene(), cloth, cut);
  for (size_t k = 0; k < 2; ++k) {
    const std::string what = "trial " + std::to_string(k);
    ASSERT_TRUE(short_[k].cut) << what;
    ASSERT_TRUE(short_[k].paused) << what;
    ASSERT_LT(short_[k].seq.samples.size(), whole[k].seq.samples.size()) << what;
    for (int twice = 0; twice < 2; ++twice) {
      const TrialResult rest = resume_trial(*short_[k].paused);
      expect_same_trial(rest, whole[k], (what + " resumed").c_str());
      EXPECT_FALSE(rest.cut) << what;
      EXPECT_FALSE(rest.paused) << what;
      EXPECT_EQ(rest.stopped_by_force, whole[k].stopped_by_force) << what;
      EXPECT_EQ(rest.area_ratio, whole[k].area_ratio) << what;
      EXPECT_EQ(rest.arm_shift_max, whole[k].arm_shift_max) << what;
      EXPECT_EQ(rest.pull_shared_travel, whole[k].pull_shared_travel) << what;
      ASSERT_EQ(rest.contacts.size(), whole[k].contacts.size()) << what;
      for (size_t i = 0; i < rest.contacts.size(); ++i) {
        EXPECT_EQ(rest.contacts[i].vertex, whole[k].contacts[i].vertex) << what;
        EXPECT_EQ(rest.contacts[i].force, whole[k].contacts[i].force) << what;
      }
    }
  }
  EXPECT_GT(whole[0].arm_shift_max, 0.0) << "the compliant arm should have moved";
}

namespace {

// The self-collision pairs that step() must find from positions x, by brute force over all
// pairs, in (i, j) order: closer than the search radius r = 1.5 self_distance (with the same
// arithmetic as detect_self()), not both grasped, and not within r of each other at rest.
std::vector<SelfPair> brute_force_pairs(const GownModel& m, const std::vector<V3>& x) {
  const SceneData& sc = *m.scene;
  const double r = 1.5 * sc.opt.self_distance, r2 = r * r;
  std::vector<SelfPair> out;
  const int n = static_cast<int>(x.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const V3 d = x[j] - x[i], dr = sc.rest[j] - sc.rest[i];
      if (dot(d, d) < r2 && !(sc.grasped[i] && sc.grasped[j]) && dot(dr, dr) >= r2) out.push_back({i, j});
    }
  return out;
}

// One step() from positions x; its pair list (found from x, before the substeps move them).
std::vector<SelfPair> detected_pairs(const GownModel& m, GownState& s, const std::vector<V3>& x) {
  s.x = x;
  s.p = x;
  step(m, s, {}, {}, {});
  EXPECT_EQ(s.pairs_dropped, 0);
  return {s.pairs.begin(), s.pairs.begin() + static_cast<long>(s.pair_count)};
}

void expect_same_pairs(const std::vector<SelfPair>& got, const std::vector<SelfPair>& want, const char* what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(got[k].i, want[k].i) << what << ", pair " << k;
    EXPECT_EQ(got[k].j, want[k].j) << what << ", pair " << k;
  }
}

}  // namespace

// The spatial hash of detect_self() finds exactly the pairs of the brute-force search, in (i, j)
// order, whatever the hash: on the reduced gown settled against the arm (the folds of a hanging
// gown, a few hundred pairs), and on a random cloud of the coarse gown's vertices in a 0.3 m box
// around the origin (negative cell coordinates, a few neighbours per vertex, grasped vertices
// among them, and some vertices on top of each other).
TEST(SimSelfCollision, PairsAreTheBruteForceSet) {
  {
    const Scene scene = make_default_scene(GownResolution::Reduced);
    const GownModel m = make_model(scene.data(), ClothParams{}, FrictionScheme::Improved, true, 0);
    GownState s = make_state(m);
    for (int k = 0; k < 150; ++k) step(m, s, {}, {}, {});
    const std::vector<V3> x = s.x;
    const std::vector<SelfPair> want = brute_force_pairs(m, x);
    EXPECT_GT(want.size(), 50u) << "the settled gown should have folds";
    expect_same_pairs(detected_pairs(m, s, x), want, "settled reduced gown");
  }
  {
    const GownModel m = make_model(coarse_scene().data(), ClothParams{}, FrictionScheme::Improved, true, 0);
    GownState s = make_state(m);
    std::vector<V3> x(s.x.size());
    uint64_t state = 12345;
    auto uniform = [&state] {  // splitmix64, in [0, 1)
      uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
      return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
    };
    for (V3& q : x) q = {0.3 * uniform() - 0.15, 0.3 * uniform() - 0.15, 0.3 * uniform() - 0.15};
    for (size_t i = 0; i + 1 < x.size(); i += 37) x[i + 1] = x[i];
    const std::vector<SelfPair> want = brute_force_pairs(m, x);
    EXPECT_GT(want.size(), x.size()) << "the cloud should be dense";
    expect_same_pairs(detected_pairs(m, s, x), want, "random cloud");
  }
}

// A compliant arm (ClothParams::arm_compliance, arm_spring.h) gives way along the cloth's pull:
// at the 10 N stop its displacement is the compliance times the load it carries (the load on the
// arm less the one at the start of the pull), short of it by the critically damped spring's lag
// behind a rising load (2 / w for a ramp, w = sqrt(1 / (c M)); at most about a third of the load
// here) and never beyond it; the gripper travels farther before the stop than with a fixed arm.
// A fixed arm (compliance 0) stays where it is.
TEST(SimTrial, CompliantArmGivesWayByItsCompliance) {
  TrialSpec spec;
  spec.height = ArmHeight::High;
  ClothParams fixed;
  const TrialResult r0 = simulate_trial(coarse_scene(), fixed, spec);
  ASSERT_TRUE(r0.stopped_by_force) << "expected the 10 N stop at the high arm, ended at " << r0.travel;
  EXPECT_EQ(r0.arm_shift_max, 0.0);
  ClothParams soft = fixed;
  soft.arm_compliance = 0.004;  // 250 N/m
  const TrialResult r = simulate_trial(coarse_scene(), soft, spec);
  ASSERT_TRUE(r.stopped_by_force) << "ended at " << r.travel;
  V3 load{0, 0, 0};
  for (const ContactForce& c : r.contacts) load += V3{c.force[0], c.force[1], c.force[2]};
  std::printf("fixed arm: stop at %.3f m; compliant: stop at %.3f m, arm moved (%.4f, %.4f, %.4f) m under (%.2f, %.2f, %.2f) N\n",
              r0.travel, r.travel, r.arm_shift[0], r.arm_shift[1], r.arm_shift[2], load.x, load.y, load.z);
  // The pull is along +x: the arm is dragged along it by several millimetres.
  EXPECT_GT(r.arm_shift[0], 0.5 * soft.arm_compliance * load.x);
  EXPECT_LT(r.arm_shift[0], 1.05 * soft.arm_compliance * load.x + 1e-3);
  EXPECT_GT(r.arm_shift[0], 0.005);
  EXPECT_GT(r.travel, r0.travel + 0.5 * r.arm_shift[0]);
  EXPECT_NEAR(r.area_ratio, 1.0, 0.05);
}

// The arm's load per part (TrialSpec::record_arm_parts). (1) Bookkeeping: in the last sample the
// parts' loads add up to the per-vertex contact forces of eq. 2 (TrialResult::contacts, the same
// corrections summed by vertex instead of by collider). (2) Physics, the gown's momentum along
// the pull (x; gravity has no x part): over every 0.05 m of travel at the pull's constant speed,
// the change of the free vertices' momentum P equals the impulses of the gripper (-f_motion
// before the bias: the grasped vertices do not accelerate, so f is the constraints' pull alone),
// of the arm (minus the parts' x loads) and of damping (-c P, c = 2/s, taken with the samples'
// mean momentum). Self-collision, stretch, shear and bending corrections are internal. What is
// left is the damping's discretisation (P sampled every 0.01 s instead of every substep), well
// under 1 mN here against an arm load of newtons; the bound, 5 mN, is 0.1 % of the 10 N stop.
// ClothParams::fist_shift moves the fist (and the forearm's distal end) along the forearm toward
// the elbow; the elbow, the upper arm and the label's reference stay where they were, to the bit,
// and a shift of 0 is the scene's arm itself.
TEST(SimTrial, FistShiftMovesTheFistAndKeepsTheElbow) {
  const Scene& scene = coarse_scene();
  const std::vector<std::string> names = arm_part_names(scene);
  const auto [fist, forearm, elbow, upper] = arm_parts_of(names);
  const auto& arm0 = scene.data().arm;
  ClothParams p;
  const GownModel same = arm_model(p);
  p.fist_shift = 0.05;
  const GownModel m = arm_model(p);
  ASSERT_EQ(m.arm.size(), arm0.size());
  for (std::size_t k = 0; k < arm0.size(); ++k) {
    EXPECT_EQ(same.arm[k].a.x, arm0[k].a.x) << names[k];
    EXPECT_EQ(same.arm[k].b.z, arm0[k].b.z + 0.01) << names[k];
  }
  EXPECT_NEAR(m.arm[fist].a.x, arm0[fist].a.x + 0.05, 1e-15);
  EXPECT_EQ(m.arm[fist].ra, arm0[fist].ra);
  EXPECT_NEAR(m.arm[forearm].a.x, arm0[forearm].a.x + 0.05, 1e-15);  // the wrist
  EXPECT_EQ(m.arm[forearm].b.x, arm0[forearm].b.x);                   // the elbow's end
  EXPECT_NEAR(m.arm[forearm].len, arm0[forearm].len - 0.05, 1e-12);
  for (std::size_t k : {elbow, upper}) {
    EXPECT_EQ(m.arm[k].a.x, arm0[k].a.x) << names[k];
    EXPECT_EQ(m.arm[k].b.y, arm0[k].b.y) << names[k];
  }
  EXPECT_EQ(m.elbow.x, same.elbow.x);
  EXPECT_EQ(m.elbow.z, same.elbow.z);
  // The scene picture (tools/plot/sim_scene.py) draws the trial's arm, not the scene's: the
  // fist's sphere is the first entry with the fist's radius and sits at the shifted x.
  TrialSpec spec;
  const std::string json = scene_json(scene, p, spec, TrialResult{});
  char fist_at[64];
  std::snprintf(fist_at, sizeof fist_at, "{\"a\": [%g,", arm0[fist].a.x + 0.05);
  EXPECT_NE(json.find(fist_at), std::string::npos) << "no arm part at the shifted fist in: " << json.substr(0, 400);
  std::snprintf(fist_at, sizeof fist_at, "{\"a\": [%g,", arm0[fist].a.x);
  EXPECT_EQ(json.find(fist_at), std::string::npos) << "the scene's unshifted fist is drawn";
}

// The person's arm sideways (ClothParams::arm_lateral) is the whole arm translated along y, the
// elbow with it; the fist sideways (fist_lateral) moves the fist and the wrist only, so the forearm
// turns about the elbow and is longer by sqrt(L^2 + d^2) - L. The picture draws the trial's arm.
TEST(SimTrial, ArmAndFistMoveSideways) {
  const Scene& scene = coarse_scene();
  const std::vector<std::string> names = arm_part_names(scene);
  const auto [fist, forearm, elbow, upper] = arm_parts_of(names);
  const auto& arm0 = scene.data().arm;
  ClothParams p;
  const GownModel same = arm_model(p);
  p.arm_lateral = 0.02;
  const GownModel moved = arm_model(p);
  ASSERT_EQ(moved.arm.size(), arm0.size());
  for (std::size_t k = 0; k < arm0.size(); ++k) {
    EXPECT_EQ(moved.arm[k].a.y, same.arm[k].a.y + 0.02) << names[k];
    EXPECT_EQ(moved.arm[k].b.y, same.arm[k].b.y + 0.02) << names[k];
    EXPECT_EQ(moved.arm[k].a.x, same.arm[k].a.x) << names[k];
    EXPECT_EQ(moved.arm[k].b.z, same.arm[k].b.z) << names[k];
    EXPECT_EQ(moved.arm[k].len, same.arm[k].len) << names[k];
  }
  EXPECT_EQ(moved.elbow.y, same.elbow.y + 0.02);
  EXPECT_EQ(moved.elbow.x, same.elbow.x);

  p.arm_lateral = 0.0;
  p.fist_lateral = -0.03;
  const GownModel turned = arm_model(p);
  EXPECT_NEAR(turned.arm[fist].a.y, arm0[fist].a.y - 0.03, 1e-15);
  EXPECT_EQ(turned.arm[fist].a.x, arm0[fist].a.x);
  EXPECT_NEAR(turned.arm[forearm].a.y, arm0[forearm].a.y - 0.03, 1e-15);  // the wrist
  EXPECT_EQ(turned.arm[forearm].b.y, arm0[forearm].b.y);                   // the elbow's end
  const double L = arm0[forearm].len;
  EXPECT_NEAR(turned.arm[forearm].len, std::sqrt(L * L + 0.03 * 0.03), 1e-12);
  for (std::size_t k : {elbow, upper}) {
    EXPECT_EQ(turned.arm[k].a.y, arm0[k].a.y) << names[k];
    EXPECT_EQ(turned.arm[k].b.y, arm0[k].b.y) << names[k];
  }
  EXPECT_EQ(turned.elbow.y, same.elbow.y);
  // The picture: the fist drawn where the trial has it (both moves add up).
  p.arm_lateral = 0.02;
  const std::string json = scene_json(scene, p, TrialSpec{}, TrialResult{});
  char fist_at[96];
  std::snprintf(fist_at, sizeof fist_at, "{\"a\": [%g,%g,", arm0[fist].a.x, arm0[fist].a.y - 0.03 + 0.02);
  EXPECT_NE(json.find(fist_at), std::string::npos) << "no arm part at the moved fist in: " << json.substr(0, 400);
}

// Where the fist sits sideways decides which way the gown pulls the gripper once the high arm's
// fist is in the opening (0.10-0.25 m of travel with the default cloth): the fist pushes the rim
// toward its own side, so a fist moved to +y (away from the body) pulls the gripper toward +y,
// which the rig reports as a negative F_lateral (its lateral axis points toward the person, -y;
// trial.h), and a fist moved to -y the other way. Measured (reduced gown, default cloth):
// fist at +3 cm -0.46 N, at -3 cm +0.39 N over that window. The bound, 0.1 N, is five times the
// sensor's noise (shared/data: 0.017 N) and a quarter of either. Reduced measured gown, two trials
// to 0.3 m on two threads (a few seconds).
TEST(SimTrial, LateralForceFollowsTheFistsSide) {
  if (gown::measured_gown_path().empty())
    GTEST_SKIP() << "shared/data/gown/fullgown.obj is not present: the opening's hang is the measured gown's";
  const Scene scene = make_default_scene(GownResolution::Reduced);
  const double sides[2] = {0.03, -0.03};
  TrialResult r[2];
  auto run = [&](int k) {
    ClothParams p;
    p.fist_lateral = sides[k];
    TrialSpec spec;
    spec.height = ArmHeight::High;
    spec.max_travel = 0.3;
    r[k] = simulate_trial(scene, p, spec);
  };
  std::thread other(run, 1);
  run(0);
  other.join();
  double mean[2] = {};
  for (int k = 0; k < 2; ++k) {
    int n = 0;
    for (const HapticSample& s : r[k].seq.samples)
      if (s.travel >= 0.10 && s.travel < 0.25) mean[k] += s.f_lateral, ++n;
    ASSERT_GT(n, 100) << "the trial did not reach 0.25 m";
    mean[k] /= n;
    std::printf("fist %+.2f m sideways: F_lateral over 0.10-0.25 m %+.3f N\n", sides[k], mean[k]);
  }
  EXPECT_LT(mean[0], -0.1);
  EXPECT_GT(mean[1], 0.1);
}

// The low arm's trial drags the gown over the arm from early on.
TEST(SimTrial, ArmPartLoadsAddUpAndBalanceTheGownsMomentum) {
  TrialSpec spec;
  spec.height = ArmHeight::Low;
  spec.record_arm_parts = true;
  const ClothParams params;
  const TrialResult r = simulate_trial(coarse_scene(), params, spec);
  ASSERT_EQ(r.arm_parts.size(), r.seq.samples.size());
  const std::vector<std::string> names = arm_part_names(coarse_scene());
  ASSERT_EQ(names.size(), 4u);  // the default arm has no hand cone
  V3 by_vertex{0, 0, 0}, by_part{0, 0, 0};
  for (const ContactForce& c : r.contacts) by_vertex += V3{c.force[0], c.force[1], c.force[2]};
  for (const auto& f : r.arm_parts.back().f) by_part += V3{f[0], f[1], f[2]};
  EXPECT_NEAR(by_part.x, by_vertex.x, 1e-9);
  EXPECT_NEAR(by_part.y, by_vertex.y, 1e-9);
  EXPECT_NEAR(by_part.z, by_vertex.z, 1e-9);
  for (std::size_t k = names.size(); k < static_cast<std::size_t>(kArmParts); ++k)
    EXPECT_EQ(r.arm_parts.back().f[k][0], 0.0) << "no collider " << k;
  const double dt = 0.01;  // one haptic sample
  int windows = 0;
  double worst = 0, heaviest = 0;
  for (int w = 1; 0.05 * (w + 1) <= r.travel + 1e-9; ++w) {
    double impulse = 0, held = 0, p_first = 0, p_last = 0;
    int n = 0;
    for (std::size_t i = 1; i < r.seq.samples.size(); ++i) {
      const double x = r.seq.samples[i].travel;
      if (x < 0.05 * w || x >= 0.05 * (w + 1)) continue;
      const double p0 = r.arm_parts[i - 1].momentum[0], p1 = r.arm_parts[i].momentum[0];
      if (n == 0) p_first = p0;
      p_last = p1;
      double arm = 0;
      for (const auto& f : r.arm_parts[i].f) arm += f[0];
      held += arm;
      impulse += (-(r.seq.samples[i].f_motion + r.bias[0]) - arm - params.damping * 0.5 * (p0 + p1)) * dt;
      ++n;
    }
    ASSERT_GT(n, 0);
    worst = std::max(worst, std::abs((p_last - p_first) - impulse) / (n * dt));
    heaviest = std::max(heaviest, held / n);
    ++windows;
  }
  std::printf("low arm: %s at %.3f m, %d windows of 0.05 m, largest mean x load on the arm %.2f N, largest "
              "momentum imbalance %.5f N\n", r.stopped_by_force ? "10 N stop" : "end of travel", r.travel, windows,
              heaviest, worst);
  EXPECT_GE(windows, 4);
  EXPECT_GT(heaviest, 1.0) << "the arm should hold the dragged gown";
  EXPECT_LT(worst, 0.005);
}
