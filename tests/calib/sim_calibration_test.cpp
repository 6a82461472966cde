// The calibration with the real cloth simulator (dg_sim), on the measured data. Built only when
// dg_sim is. Kept small (coarse gown, one generation of 4): each simulation costs seconds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <thread>

#include "calibration.h"
#include "discrepancy.h"
#include "fake_sim.h"
#include "prediction.h"
#include "gown.h"
#include "objective.h"
#include "gown_scene.h"
#include "sim_bridge.h"
#include "synthesis.h"
#include "trial.h"

namespace dressguard::calib {
namespace {

// A calibration's values reach the simulator whole: the five cloth values, the person's arm and
// the gown's cuff and its density (calibrate --hem / --density record them in the file,
// synthesis simulates with them).
// Every field gets a value of its own, none the simulator's default, so that a copy dropped
// (the default would stand in) or two swapped shows (session 90's test audit: half of them were
// set to their defaults or not checked).
TEST(SimCalibration, ClothParamsCarryEveryCalibratedValue) {
  ClothValues c;
  c.stretch = 0.11;
  c.shear = 0.22;
  c.bend = 0.33;
  c.friction = 0.44;
  c.self_friction = 0.55;
  c.arm_compliance = 0.006;
  c.fist_shift = 0.05;
  c.hem_width = 0.03;
  c.hem_bend_ratio = 30;
  c.rim_shift = 0.01;  // not a ClothParams: it picks the scene (make_cloth_simulator)
  c.areal_density = 0.1;
  c.arm_lateral = 0.011;
  c.fist_lateral = -0.012;
  c.support_depth = 0.65;
  c.support_lateral = 0.013;
  const sim::ClothParams d;  // the defaults, none of which may equal a value above
  for (double v : {d.stretch, d.shear, d.bend, d.friction, d.self_friction, d.arm_compliance, d.fist_shift,
                   d.hem_width, d.hem_bend_ratio, d.areal_density, d.arm_lateral, d.fist_lateral, d.support_depth,
                   d.support_lateral})
    for (double set : {0.11, 0.22, 0.33, 0.44, 0.55, 0.006, 0.05, 0.03, 30.0, 0.1, 0.011, -0.012, 0.65, 0.013})
      ASSERT_NE(v, set) << "a default equals a value the test sets: it could not tell a dropped copy";
  const sim::ClothParams p = cloth_params_of(c);
  EXPECT_EQ(p.stretch, 0.11);
  EXPECT_EQ(p.shear, 0.22);
  EXPECT_EQ(p.bend, 0.33);
  EXPECT_EQ(p.friction, 0.44);
  EXPECT_EQ(p.self_friction, 0.55);
  EXPECT_EQ(p.arm_compliance, 0.006);
  EXPECT_EQ(p.fist_shift, 0.05);
  EXPECT_EQ(p.hem_width, 0.03);
  EXPECT_EQ(p.hem_bend_ratio, 30.0);
  EXPECT_EQ(p.areal_density, 0.1);
  EXPECT_EQ(p.arm_lateral, 0.011);
  EXPECT_EQ(p.fist_lateral, -0.012);
  EXPECT_EQ(p.support_depth, 0.65);
  EXPECT_EQ(p.support_lateral, 0.013);
  EXPECT_EQ(p.damping, d.damping);  // not calibrated (paper IV-B.2)
}

// The bridge is deterministic and thread-safe: the same trial simulated on two threads at once
// and once more on this thread gives the same samples, bit for bit (calibration's independence
// of the thread count rests on this).
TEST(SimCalibration, BridgeIsDeterministicAcrossThreads) {
  const ClothSimulator both = make_cloth_simulator("coarse");
  const TrialSimulator& sim = both.trial;
  TrialRequest r;
  r.height = ArmHeight::Low;
  r.max_travel = 0.3;  // short: this test checks identity, not physics
  SimulatedTrial a, b;
  std::thread ta([&] { a = sim(ClothValues{}, r); });
  std::thread tb([&] { b = sim(ClothValues{}, r); });
  ta.join();
  tb.join();
  const SimulatedTrial c = sim(ClothValues{}, r);
  ASSERT_FALSE(a.samples.empty());
  ASSERT_EQ(a.samples.size(), b.samples.size());
  ASSERT_EQ(a.samples.size(), c.samples.size());
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    EXPECT_EQ(a.samples[i].f_motion, b.samples[i].f_motion);
    EXPECT_EQ(a.samples[i].f_vertical, c.samples[i].f_vertical);
  }
  EXPECT_NEAR(a.samples.back().travel, 0.3, 0.002);  // the travel limit reaches the simulator
  // The batch form (one settling for both heights) gives each trial the one-trial form's bits.
  TrialRequest high = r;
  high.height = ArmHeight::High;
  const std::vector<SimulatedTrial> ab = both.trials(ClothValues{}, {r, high});
  const SimulatedTrial h = sim(ClothValues{}, high);
  ASSERT_EQ(ab.size(), 2u);
  ASSERT_EQ(ab[0].samples.size(), a.samples.size());
  ASSERT_EQ(ab[1].samples.size(), h.samples.size());
  for (std::size_t i = 0; i < a.samples.size(); ++i) EXPECT_EQ(ab[0].samples[i].f_motion, a.samples[i].f_motion);
  for (std::size_t i = 0; i < h.samples.size(); ++i) EXPECT_EQ(ab[1].samples[i].f_vertical, h.samples[i].f_vertical);
  EXPECT_EQ(ab[1].outcome, h.outcome);
}

// The cloth simulator keeps a cut trial's rest (SimulatedTrial::rest, sim::resume_trial): it is
// the uncut trial to the bit, for the one-trial and the batch forms, and it outlives its scene in
// the bridge's cache (a cloth with its own grasp, then four other grasps that push its scene out
// of the cache: the rest keeps it).
TEST(SimCalibration, CutTrialsRestIsTheUncutTrial) {
  const ClothSimulator both = make_cloth_simulator("coarse");
  ClothValues cloth;
  cloth.rim_shift = 0.01;
  TrialRequest low;
  low.height = ArmHeight::Low;
  low.max_travel = 0.3;  // short: this test checks identity, not physics
  TrialRequest high = low;
  high.height = ArmHeight::High;
  const std::vector<SimulatedTrial> whole = both.trials(cloth, {low, high});
  std::vector<TrialRequest> watched{low, high};
  for (TrialRequest& r : watched) r.watch = [](const std::vector<HapticSample>& so_far, bool) { return so_far.back().travel >= 0.15; };
  std::vector<SimulatedTrial> cut = both.trials(cloth, watched);
  cut.push_back(both.trial(cloth, watched[0]));
  ClothValues other = cloth;
  TrialRequest brief = low;
  brief.max_travel = 0.005;
  for (double shift : {0.002, 0.004, 0.006, 0.008}) {
    other.rim_shift = shift;
    both.trial(other, brief);
  }
  for (std::size_t k = 0; k < cut.size(); ++k) {
    const SimulatedTrial& w = whole[k % 2];
    ASSERT_TRUE(cut[k].cut) << "trial " << k;
    ASSERT_TRUE(cut[k].rest) << "trial " << k;
    ASSERT_LT(cut[k].samples.size(), w.samples.size()) << "trial " << k;
    const SimulatedTrial rest = cut[k].rest();
    EXPECT_FALSE(rest.cut);
    EXPECT_FALSE(rest.rest);
    ASSERT_EQ(rest.samples.size(), w.samples.size()) << "trial " << k;
    EXPECT_EQ(0, std::memcmp(rest.samples.data(), w.samples.data(), w.samples.size() * sizeof(HapticSample))) << "trial " << k;
    EXPECT_EQ(rest.outcome, w.outcome) << "trial " << k;
    EXPECT_EQ(rest.d_behind, w.d_behind) << "trial " << k;
    EXPECT_EQ(rest.d_ahead, w.d_ahead) << "trial " << k;
    // The cloth time: the cut part and its rest make the whole trial's.
    EXPECT_GT(cut[k].simulated_s, 0.0) << "trial " << k;
    EXPECT_GT(rest.simulated_s, 0.0) << "trial " << k;
    EXPECT_NEAR(cut[k].simulated_s + rest.simulated_s, w.simulated_s, 1e-9) << "trial " << k;
  }
  EXPECT_FALSE(whole[0].rest);
  // The batch's cloth time is its one settling and each pull's own part: the one-trial form's
  // trials add up to more by a settling and the shared part of the pull.
  const SimulatedTrial low_alone = both.trial(cloth, low);
  EXPECT_NEAR(low_alone.simulated_s, whole[0].simulated_s, 1e-9) << "the batch's first trial settles and pulls alone";
  EXPECT_GT(low_alone.simulated_s, low_alone.samples.back().t + 1.0) << "at least a second of settling";
  EXPECT_LT(whole[1].simulated_s, whole[1].samples.back().t) << "the high arm's pull began shared and its settling too";
}

// A calibration's rim_shift reaches the simulator as the scene's grasp: a cloth with the rim
// 2 cm further ahead of the jaws gives, bit for bit, the trial of the scene that `simulate
// --rim-ahead` builds (make_default_scene with grasp_of's grip), and another trial than the
// gown's own grasp. A shift that puts the rim behind the jaws is refused with its numbers.
TEST(SimCalibration, RimShiftIsTheScenesGrasp) {
  const ClothSimulator both = make_cloth_simulator("coarse");
  TrialRequest r;
  r.height = ArmHeight::High;
  r.max_travel = 0.2;  // short: identity, not physics
  ClothValues shifted;
  shifted.rim_shift = 0.02;
  const bool parametric = gown::measured_gown_path().empty();
  const auto grip = grasp_of(0.02, parametric);
  ASSERT_TRUE(grip.has_value());
  EXPECT_DOUBLE_EQ(grip->rim_ahead, (parametric ? gown::kParametricGrip.rim_ahead : gown::kOpeningRimAhead) + 0.02);
  EXPECT_FALSE(grasp_of(0.0, parametric).has_value());  // the gown's own: make_default_scene(res)
  const sim::Scene scene = sim::make_default_scene(sim::GownResolution::Coarse, parametric, *grip);
  sim::TrialSpec spec;
  spec.height = r.height;
  spec.max_travel = r.max_travel;
  const sim::TrialResult direct = sim::simulate_trial(scene, cloth_params_of(shifted), spec);
  const SimulatedTrial a = both.trial(shifted, r);
  const SimulatedTrial own = both.trial(ClothValues{}, r);
  const std::vector<SimulatedTrial> batch = both.trials(shifted, {r});
  ASSERT_EQ(a.samples.size(), direct.seq.samples.size());
  ASSERT_EQ(batch.at(0).samples.size(), a.samples.size());
  bool differs = a.samples.size() != own.samples.size();
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    EXPECT_EQ(a.samples[i].f_motion, direct.seq.samples[i].f_motion);
    EXPECT_EQ(a.samples[i].f_vertical, direct.seq.samples[i].f_vertical);
    EXPECT_EQ(batch[0].samples[i].f_motion, a.samples[i].f_motion);
    if (i < own.samples.size()) differs |= a.samples[i].f_vertical != own.samples[i].f_vertical;
  }
  EXPECT_TRUE(differs) << "the rim shift did not reach the simulation";
  try {
    grasp_of(-0.05, parametric);
    ADD_FAILURE() << "a rim behind the jaws was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("behind the jaws"), std::string::npos) << e.what();
  }
}

// A rim_shift whose grasp holds none of the measured gown (its sleeve's top lies below the lower
// jaw from the rim 8.31 cm ahead of the jaws on: placement.h, OpeningGrip) is an
// UnbuildableCandidate naming it, which calibrate ranks last; it was make_scene's
// std::invalid_argument, which ended the whole calibration. So is one whose jaws hold vertices but
// no whole triangle of it (from the rim 7.0 cm ahead: 2 vertices at 0.04 ahead of the gown's own,
// the rim 8 cm ahead); 0.025 ahead (6.5 cm) still holds one triangle.
TEST(SimCalibration, AGraspThatHoldsNothingIsAnUnbuildableCandidate) {
  if (gown::measured_gown_path().empty()) GTEST_SKIP() << "shared/data/gown not present (the measured gown's grip)";
  const ClothSimulator cs = make_cloth_simulator("coarse");
  TrialRequest r;
  r.height = ArmHeight::High;
  r.max_travel = 0.01;
  ClothValues c;
  c.rim_shift = 0.05;
  try {
    cs.trials(c, {r});
    ADD_FAILURE() << "a grasp that holds nothing was simulated";
  } catch (const UnbuildableCandidate& e) {
    EXPECT_NE(std::string(e.what()).find("rim_shift 0.05 m: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("hold no vertex of the gown with grip depth 0.015 m and rim_ahead 0.09 m"),
              std::string::npos) << e.what();
  }
  EXPECT_THROW(cs.trial(c, r), UnbuildableCandidate);
  EXPECT_THROW(cs.build_grasp(0.05), UnbuildableCandidate);  // what calibrate asks of a held rim_shift
  try {
    cs.build_grasp(0.04);
    ADD_FAILURE() << "a grasp of 2 vertices and no triangle was built";
  } catch (const UnbuildableCandidate& e) {
    EXPECT_NE(std::string(e.what()).find("hold 2 vertices of the gown but no whole triangle of it with grip depth "
                                         "0.015 m and rim_ahead 0.08 m"),
              std::string::npos) << e.what();
  }
  c.rim_shift = 0.025;
  EXPECT_FALSE(cs.trial(c, r).samples.empty());
  EXPECT_NO_THROW(cs.build_grasp(0.025));
  EXPECT_NO_THROW(cs.build_grasp(0.0));
}

// A calibration's friction scheme reaches the simulator: each named scheme gives, bit for bit,
// the trial that sim::simulate_trial gives with that TrialSpec::friction_scheme, in both forms,
// and the three differ from each other (the low arm, where the sleeve drags on the forearm). A
// name the simulator does not know is refused with the name. The two lists of names agree.
TEST(SimCalibration, FrictionSchemeIsTheTrialsScheme) {
  const ClothSimulator both = make_cloth_simulator("coarse");
  const sim::Scene scene = sim::make_default_scene(sim::GownResolution::Coarse);  // the bridge's own grasp
  TrialRequest r;
  r.height = ArmHeight::Low;
  r.max_travel = 0.25;  // short: identity, not physics
  std::vector<SimulatedTrial> runs;
  for (std::size_t k = 0; k < kFrictionSchemes.size(); ++k) {
    SCOPED_TRACE(kFrictionSchemes[k]);
    const sim::FrictionScheme f = k == 0 ? sim::FrictionScheme::Improved : k == 1 ? sim::FrictionScheme::Constraint
                                                                                 : sim::FrictionScheme::Stock;
    ASSERT_STREQ(sim::friction_scheme_name(f), kFrictionSchemes[k]);
    sim::FrictionScheme parsed = sim::FrictionScheme::Stock;
    if (f == parsed) parsed = sim::FrictionScheme::Improved;  // so a parse that writes nothing fails
    ASSERT_TRUE(sim::parse_friction_scheme(kFrictionSchemes[k], &parsed));
    EXPECT_EQ(parsed, f);
    EXPECT_TRUE(friction_scheme_known(kFrictionSchemes[k]));
    ClothValues c;
    c.friction_scheme = kFrictionSchemes[k];
    sim::TrialSpec spec;
    spec.height = r.height;
    spec.max_travel = r.max_travel;
    spec.friction_scheme = f;
    const sim::TrialResult direct = sim::simulate_trial(scene, cloth_params_of(c), spec);
    runs.push_back(both.trial(c, r));
    const std::vector<SimulatedTrial> batch = both.trials(c, {r});
    ASSERT_EQ(runs.back().samples.size(), direct.seq.samples.size());
    ASSERT_EQ(batch.at(0).samples.size(), direct.seq.samples.size());
    for (std::size_t i = 0; i < direct.seq.samples.size(); ++i) {
      EXPECT_EQ(runs.back().samples[i].f_motion, direct.seq.samples[i].f_motion);
      EXPECT_EQ(batch[0].samples[i].f_motion, direct.seq.samples[i].f_motion);
    }
  }
  for (std::size_t a = 0; a < runs.size(); ++a)
    for (std::size_t b = a + 1; b < runs.size(); ++b) {
      bool differs = runs[a].samples.size() != runs[b].samples.size();
      for (std::size_t i = 0; i < std::min(runs[a].samples.size(), runs[b].samples.size()); ++i)
        differs |= runs[a].samples[i].f_motion != runs[b].samples[i].f_motion;
      EXPECT_TRUE(differs) << kFrictionSchemes[a] << " and " << kFrictionSchemes[b] << " gave the same trial";
    }
  ClothValues unknown;
  unknown.friction_scheme = "sticky";
  EXPECT_FALSE(friction_scheme_known("sticky"));
  sim::FrictionScheme untouched = sim::FrictionScheme::Constraint;
  EXPECT_FALSE(sim::parse_friction_scheme("sticky", &untouched));
  EXPECT_EQ(untouched, sim::FrictionScheme::Constraint);
  try {
    both.trial(unknown, r);
    ADD_FAILURE() << "an unknown friction scheme was simulated";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'sticky'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(friction_scheme_choices()), std::string::npos) << e.what();
  }
  // Every error that names the schemes lists them from kFrictionSchemes, the default first.
  EXPECT_EQ(friction_scheme_choices(), "improved, constraint or stock");
}

// The prediction of other people through the batch form (one settling per group of targets)
// gives the one-trial form's bits. The targets are three trials of another person, one per arm
// height, cut at 0.15 m so that the pulls are short; their curves come from the stand-in
// (only their heights, speeds and ends of travel reach the simulator).
TEST(SimCalibration, PredictionWithSharedSettlingHasTheSameBits) {
  const ClothSimulator both = make_cloth_simulator("coarse");
  Dataset ds;
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low}) {
    TrialRequest r;
    r.height = h;
    r.max_travel = 0.15;
    HapticSequence s;
    s.id = "p2-" + std::string(arm_height_name(h));
    s.participant = "2";
    s.height = h;
    s.speed = r.speed;
    s.label = h == ArmHeight::High ? Outcome::Good : Outcome::Missed;
    s.samples = testing::fake_simulate(ClothValues{}, r).samples;
    ds.trials.push_back(std::move(s));
  }
  Calibration cal;
  cal.participant = "1";
  cal.offsets = {0.01, 0.0, -0.01};
  const Prediction shared = predict_others(cal, ds, both.trials, 1, Comm::world());
  const Prediction single = predict_others(cal, ds, both.trial, 1, Comm::world());
  ASSERT_EQ(shared.trials.size(), 3u);
  for (const PredictedTrial& t : shared.trials) {
    EXPECT_NEAR(t.simulated_end, 0.15, 0.002) << t.trial_id;  // the targets' travel reached the simulator
    EXPECT_TRUE(std::isfinite(t.objective)) << t.trial_id;
  }
  EXPECT_EQ(prediction_csv(shared), prediction_csv(single));
  EXPECT_EQ(prediction_curves_csv(shared, ds), prediction_curves_csv(single, ds));
}

// The middle arm's edge on the real simulator (synthesis.h, MiddleArm::CaughtEdge): participant
// 4's calibration on the reduced measured gown goes in at its high arm and misses at the nominal
// middle; between them it catches (session 10's sweep: good down to 0 cm from the high arm,
// caught from -1 to -4 cm, missed below). A coarse trisection (2 cm) must land in that band.
TEST(SimCalibration, MiddleEdgeOfParticipant4sSimulator) {
  if (gown::measured_gown_path().empty()) GTEST_SKIP() << "shared/data/gown not present (the band is the measured gown's)";
  const Calibration cal = read_calibration(std::filesystem::path(DRESSGUARD_SOURCE_DIR) / "models/participant4-simulator.json");
  const MiddleEdge e = locate_middle_edge(cal, make_cloth_simulator("reduced").trial, 2, Comm::world(), 0.02);
  std::printf("  participant 4's simulator: good at %+.4f m, %s at %+.4f m from the nominal middle (%d trials)\n",
              e.good_at, std::string(outcome_name(e.below)).c_str(), e.offset, e.trials);
  EXPECT_EQ(e.below, Outcome::Caught);
  EXPECT_LE(e.good_at - e.offset, 0.02);
  const double high = kMiddleBelowHigh + cal.offsets[0];
  EXPECT_LE(e.good_at, high);
  EXPECT_GE(e.offset, high - 0.05);  // within the 1-5 cm caught band below the high arm
}

// The repeat band on the real simulator (synthesis.h, HighLowArm::RepeatBand). Participant 4's
// committee member has its high arm just above the height where the sleeve's rim catches on the
// fist: 1.5 cm lower the trial is caught (it stops early, and eq. 3-5 charges the missing part at
// w = 20); 0.75 cm lower it still goes in but drags -1.10 N at 0.20-0.25 m of travel against the
// calibrated -0.15 N (offline/calib/MEASUREMENTS.md, session 27). Both are further from the
// calibrated trial than two measured repeats of one person's good trial (0.108), so the band stops
// above -0.75 cm. Upwards the distance grows too (0.17 at +0.75 cm, 0.73 at +1.5 cm; session
// 29): the simulated good trial is more sensitive to the arm's height than a person's repeats in both
// directions, and more so towards the fist. A coarse scan (0.75 cm: four trials beside the
// calibrated one) is enough to see it; the synthesis scans at 0.25 cm.
TEST(SimCalibration, RepeatBandOfParticipant4sHighArmStopsAboveTheFist) {
  if (gown::measured_gown_path().empty()) GTEST_SKIP() << "shared/data/gown not present (the edge is the measured gown's)";
  const Calibration cal = read_calibration(std::filesystem::path(DRESSGUARD_SOURCE_DIR) / "models/participant4-contrast.json");
  const ArmBand b = locate_repeat_band(cal, make_cloth_simulator(cal.gown).trial, ArmHeight::High, 2, Comm::world(), 0.0075);
  ASSERT_EQ(b.offsets.size(), 4u);
  for (std::size_t k = 0; k < b.offsets.size(); ++k)
    std::printf("  high arm %+.2f cm: distance %.3f (repeat tolerance %.3f)\n", 100 * b.offsets[k], b.distances[k],
                b.tolerance);
  EXPECT_EQ(b.at_calibrated, Outcome::Good);
  EXPECT_DOUBLE_EQ(b.tolerance, kRepeatDistanceGood);
  EXPECT_EQ(b.trials, 5);
  // -1.5 cm: caught at 0.455 m where the calibrated trial goes on to 0.603 m; eq. 3-5 charges
  // that missing part at w = 20 (19.9 here), far above any difference between two good trials.
  EXPECT_GT(b.distances[0], 1.0) << "-1.5 cm should catch on the fist";
  // -0.75 cm: still good, but dragging like the edge; further than a repeat, and further than the
  // same step up, where the rim clears the fist.
  EXPECT_GT(b.distances[1], kRepeatDistanceGood);
  EXPECT_GT(b.distances[1], b.distances[2]);
  EXPECT_EQ(b.lower, 0.0);
  // Away from the calibrated height the trial only moves further away: the scan is monotone.
  EXPECT_GT(b.distances[0], b.distances[1]);
  EXPECT_GT(b.distances[3], b.distances[2]);
  // The upper end is the scan's: +0.75 cm when that step is within a repeat, 0 otherwise.
  EXPECT_EQ(b.upper, b.distances[2] <= kRepeatDistanceGood ? b.offsets[2] : 0.0);
}

// Participant 4's calibration pulls one cloth over his high and low arms, which touch the gown
// only during the pull. The stiff calibrated gown springs from its measured shape at the grasp
// (vertices at up to 18 m/s in the first step), which brings the low arm within contact reach
// but not into contact: the two trials settle once and are pulled as one until the high arm
// touches the gown, 0.13 m into the pull (sim::simulate_trials; its bits are tested in
// tests/sim). A candidate costs 4,458 output steps this way instead of 5,682.
TEST(SimCalibration, Participant4sTrialsShareTheirSettlingAndPullPrefix) {
  if (gown::measured_gown_path().empty()) GTEST_SKIP() << "shared/data/gown not present (the spring is the measured gown's)";
  const Calibration cal = read_calibration(std::filesystem::path(DRESSGUARD_SOURCE_DIR) / "models/participant4-simulator.json");
  ASSERT_EQ(cal.cloth.rim_shift, 0.0) << "this test builds the gown's own scene";
  sim::TrialSpec high, low;
  high.height = ArmHeight::High;
  high.arm_offset = cal.offsets[static_cast<int>(ArmHeight::High)];
  low.height = ArmHeight::Low;
  low.arm_offset = cal.offsets[static_cast<int>(ArmHeight::Low)];
  high.max_travel = low.max_travel = 0.2;  // past the first touch
  const std::vector<sim::TrialResult> r = sim::simulate_trials(sim::make_default_scene(sim::GownResolution::Reduced),
                                                               cloth_params_of(cal.cloth), {high, low});
  ASSERT_EQ(r.size(), 2u);
  EXPECT_TRUE(r[0].settle_arm_near) << "the gown's spring at the grasp should bring the low arm within reach";
  EXPECT_TRUE(r[1].settle_shared) << "no arm touches the settling gown";
  ASSERT_GT(r[0].contact_travel, 0) << "the high arm should touch the gown by 0.2 m";
  EXPECT_GT(r[1].pull_shared_travel, r[0].contact_travel - 0.0011);
  EXPECT_LT(r[1].pull_shared_travel, r[0].contact_travel);
}

// A shipped calibration simulated again from its file: its own sequences (one per height,
// selected by the run's seed 1) fit at L <= 0.3 each, near the floor of two repeats of one
// person's trial (issue 4: 0.09 good, 0.22 missed), and give the objectives the search recorded,
// to the bit: the file holds everything the simulation needs, and the simulator has not changed
// since the search or the file's last `calibrate --rescore` (its provenance's "rescored").
// Each sequence at L <= at_most (the 0.3 unless said), and a contrast term, where the
// file records one, to the bit too.
// `fits`, when given, receives each sequence's L (empty when the test was skipped).
void expect_fits_own_sequences_to_the_bit(const std::string& file, double at_most = 0.3,
                                          std::vector<double>* fits = nullptr) {
  const auto dir = study_dir();
  if (dir.empty()) GTEST_SKIP() << "shared/data/kapusta2016-calibration-trials not present";
  if (gown::measured_gown_path().empty()) GTEST_SKIP() << "shared/data/gown not present (calibrated on the measured gown)";
  const Calibration cal = read_calibration(std::filesystem::path(DRESSGUARD_SOURCE_DIR) / "models" / file);
  // The inputs as `dressguard import` then `calibrate --data` read them: through the dataset's
  // CSV files, whose rounding moves L in the ninth digit. One folder per file, not per person:
  // ctest runs the tests of one person's files at once.
  const std::filesystem::path data =
      std::filesystem::path(::testing::TempDir()) / ("dg_own_" + std::filesystem::path(file).stem().string());
  std::filesystem::remove_all(data);
  save_dataset(import_study(dir), data);
  std::vector<std::string> ids;  // the trials the file was fitted to (calibrate's seed or --inputs)
  for (const SequenceFit& f : cal.fits) ids.push_back(f.trial_id);
  const auto inputs = inputs_by_id(load_dataset(data), cal.participant, ids);
  std::filesystem::remove_all(data);
  ASSERT_EQ(inputs.size(), cal.fits.size());
  const std::vector<SimulatedTrial> sts = simulate_inputs(make_cloth_simulator(cal.gown).trials, cal.cloth, cal.offsets, inputs);
  ASSERT_EQ(sts.size(), inputs.size());
  // Scored again as `calibrate --rescore` scores a file (the file's objective kind and
  // combination, the extra terms), on a copy: every figure must come back to the bit.
  Calibration again = cal;
  rescore(again, inputs, sts, "sim_calibration_test", "now");
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const double L = again.fits[k].objective;
    std::printf("  %s: L = %.4f (recorded %.4f)\n", inputs[k].id.c_str(), L, cal.fits[k].objective);
    EXPECT_EQ(L, cal.fits[k].objective);
    EXPECT_LE(L, at_most);
    if (fits) fits->push_back(L);
  }
  EXPECT_EQ(again.contrast, cal.contrast);
  if (cal.contrast_weight > 0) std::printf("  the heights' contrast term: %.4f (weight %g)\n", cal.contrast, cal.contrast_weight);
  EXPECT_EQ(again.lateral, cal.lateral);
  if (cal.lateral_weight > 0) std::printf("  the lateral term: %.4f (weight %g)\n", cal.lateral, cal.lateral_weight);
  // The recorded objective is what the search minimised (--combine sum, worst, bar or count), to the bit.
  EXPECT_EQ(again.objective, cal.objective);
}

// Participant 4 at the paper's budget (50 x 32 from the default start; session 15).
TEST(SimCalibration, Participant4sPaperBudgetCalibrationFitsHisSequences) {
  expect_fits_own_sequences_to_the_bit("participant4-paper-budget.json");
}

// Participant 4 with the worst sequence first (calibrate --combine worst, 12 x 32, sigma0 0.03,
// seed 2, from participant4-paper-budget.json; session 36): good 0.2337, missed 0.2341. The worse
// sequence is below the paper-budget file's (0.256); each is above the paper's simulator's (0.22,
// 0.23) by 0.014 and 0.004; the sum 0.468 is below the file's 0.471. Bounded here by 0.235.
TEST(SimCalibration, Participant4sWorstFirstCalibrationFitsHisSequences) {
  expect_fits_own_sequences_to_the_bit("participant4-worst.json", 0.235);
}

// Participant 4 in small steps (8 x 32, sigma0 0.001, --combine worst, seed 1, from
// participant4-worst.json; session 38): good 0.2287, missed 0.2058, sum 0.435 against the paper's
// simulator's 0.22 / 0.23 (sum 0.45): the missed sequence below the paper's, the good one 0.009
// above it. Bounded here by 0.229.
TEST(SimCalibration, Participant4sSmallStepCalibrationFitsHisSequences) {
  expect_fits_own_sequences_to_the_bit("participant4-fine.json", 0.229);
}

// Participant 4, a second small-step round (12 x 32, sigma0 0.001, --combine worst, seed 1,
// from participant4-fine.json; session 40): good 0.2257, missed 0.1913, sum 0.417; the good
// sequence still 0.006 above the paper's simulator's 0.22. Bounded here by 0.226.
TEST(SimCalibration, Participant4sSecondSmallStepRoundFitsHisSequences) {
  expect_fits_own_sequences_to_the_bit("participant4-fine2.json", 0.226);
}

// Participant 4, a third small-step round (the same, 12 x 32 from participant4-fine2.json,
// one thread; session 41): good 0.2244, missed 0.1916; 0.004 above the paper's 0.22. Bounded
// here by 0.225.
TEST(SimCalibration, Participant4sThirdSmallStepRoundFitsHisSequences) {
  expect_fits_own_sequences_to_the_bit("participant4-fine3.json", 0.225);
}

// Participant 5 (24 x 32 from their session-9 calibration's values; session 16).
TEST(SimCalibration, Participant5sCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant5-simulator.json");
}

// Participant 4 with the heights' contrast in the objective (calibrate --contrast-weight 5, 16 x
// 24 from the paper-budget file; session 17): both sequences still within 0.3.
TEST(SimCalibration, Participant4sContrastCalibrationFitsHisSequences) {
  expect_fits_own_sequences_to_the_bit("participant4-contrast.json");
}

// Participant 1 (20 x 32 from their session-9 values; session 17). Not at the 0.3: 0.428
// and 0.414, bounded here by 0.45, below their session-9 fit's 0.537 and 0.560.
TEST(SimCalibration, Participant1sCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant1-simulator.json", 0.45);
}

// Participant 1 at the paper's budget (50 x 32 from the default start, sigma0 0.3: participant
// 4's recipe unchanged; sessions 33-34): L 0.573 from the 20 x 32 search's 0.842. The good
// sequence reaches the 0.3 (0.268); the missed one stops just above it (0.305; its best
// was 0.298 at generation 43, when the sum was 0.580), bounded here by 0.31.
TEST(SimCalibration, Participant1sPaperBudgetCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant1-paper-budget.json", 0.31);
}

// Participant 1 with the worst sequence first (calibrate --combine worst, 12 x 32, sigma0 0.03,
// seed 2, from participant1-paper-budget.json; session 35): good 0.254, missed 0.3004, both below
// the paper-budget file's (0.268, 0.305), their sum too (0.555 against 0.573). The missed one is
// 0.0004 above the 0.3, bounded here by 0.301. The recorded objective is max + 0.1 sum.
TEST(SimCalibration, Participant1sWorstFirstCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant1-worst.json", 0.301);
}

// Participant 1, a second worst-first round (10 x 32, sigma0 0.03, seed 1, from
// participant1-worst.json; session 37): good 0.2764, missed 0.2984, both within the 0.3.
// The combined objective moved by 0.0001 (0.3559 to 0.3558): the missed sequence crossed 0.3 at
// the good one's cost (0.254 to 0.276). Bounded here by 0.2985.
TEST(SimCalibration, Participant1sSecondWorstFirstRoundFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant1-worst2.json", 0.2985);
}

// Participant 1 in small steps (4 x 32, sigma0 0.001, from participant1-worst2.json; session 37:
// bench_calib_landscape found half of the points 0.1 % of each box away better, none at 1 %):
// good 0.2511, missed 0.2923, sum 0.543, the lowest of his files. Bounded here by 0.2925.
TEST(SimCalibration, Participant1sSmallStepCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant1-fine.json", 0.2925);
}

// Participant 0, three sequences (8 x 24 from their session-11 values; session 18). Far from the
// issue's 0.3: 0.705, 1.522 and 0.873 as searched; the middle 0.888 since session 45 paired its
// late-starting recording from the same travel (objective.h; the file rescored: calibrate
// --rescore), 0.907 since session 92 paired it at the same time of the pull, read from its
// stamp (objective.h, "Where the pairs begin"; rescored again). Bounded here by 0.91.
TEST(SimCalibration, Participant0sCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant0-simulator.json", 0.91);
}

// Participant 2, three sequences (6 x 16 from their session-12 values as that session's table
// gives them, the rim fitted too; session 20). Not at the 0.3: 0.468, 0.643 and 0.535,
// bounded here by 0.65, below session 12's worst, 0.852.
TEST(SimCalibration, Participant2sCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant2-simulator.json", 0.65);
}

// Participant 3, three sequences (4 x 16 from their session-12 values as that session's table
// gives them, the rim fitted too; session 20). Not at the 0.3: 0.407, 0.783 and 0.639,
// bounded here by 0.8, below session 12's worst, 0.794.
TEST(SimCalibration, Participant3sCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant3-simulator.json", 0.8);
}

// Participant 7, three sequences (4 x 16 from their session-10 values as session 12's table
// gives them, the rim fitted too; session 20). Not at the 0.3: 0.431, 0.619 and 0.436,
// bounded here by 0.65.
TEST(SimCalibration, Participant7sCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant7-simulator.json", 0.65);
}

// Participant 7 searched longer (20 x 32, sigma0 0.1, from participant7-simulator.json; session
// 24): L 1.261 from 1.486. The low arm's missed sequence reaches the 0.3 (0.296, was
// 0.436); good 0.388 (0.431) and middle missed 0.577 (0.619) do not, bounded here by 0.6.
TEST(SimCalibration, Participant7sLongerCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant7-longer.json", 0.6);
}

// Participant 7 searched on from participant7-longer.json by `--combine count` (session 66: 8 x
// 32 at sigma0 0.003, seed 1): good 0.3737, middle missed 0.5410, missed 0.2981, the good and
// middle arms' below -longer's 0.3881 / 0.5767 and the missed one kept within the 0.3
// (0.2963 before). Bounded here by 0.542.
TEST(SimCalibration, Participant7sCountCalibrationKeepsTheirMissedSequence) {
  std::vector<double> fits;
  expect_fits_own_sequences_to_the_bit("participant7-count.json", 0.542, &fits);
  if (fits.empty()) return;  // skipped
  ASSERT_EQ(fits.size(), 3u);
  EXPECT_LE(fits[2], 0.3) << "s7-miss-0";
}

// Participant 3 searched longer (20 x 32, sigma0 0.1, from participant3-simulator.json; session
// 25): L 1.409 from 1.829. Every sequence gained (good 0.362 from 0.407, middle missed 0.629 from
// 0.783, missed 0.417 from 0.639) and none reaches the 0.3; bounded here by 0.65.
TEST(SimCalibration, Participant3sLongerCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant3-longer.json", 0.65);
}

// Participant 3 in smaller steps (8 x 32, sigma0 0.03, by the sum, seed 1, from
// participant3-longer.json; sessions 42-43, resumed from its checkpoint): L 1.371 from 1.409, good
// 0.324, middle missed 0.606, missed 0.441 (0.362 / 0.629 / 0.417 before). Not at the issue's
// 0.3; bounded here by 0.607.
TEST(SimCalibration, Participant3sSmallerStepCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant3-fine.json", 0.607);
}

// A round from it at the small step (5 x 32, sigma0 0.001, by the sum, seed 1, one thread;
// session 48), where 5 of the landscape's 16 points lay below it: 0.3164, 0.6041 and 0.4354, sum
// 1.3558 from 1.3713; every sequence lower. Bounded here by 0.605.
TEST(SimCalibration, Participant3sSmallStepRoundFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant3-fine2.json", 0.605);
}

// A second round the same way from it (session 48): 0.3101, 0.6000 and 0.4384, sum 1.3485; the
// worst and the sum lower, the low arm's missed sequence 0.003 higher. Bounded here by 0.6001.
TEST(SimCalibration, Participant3sSecondSmallStepRoundFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant3-fine3.json", 0.6001);
}

// Participant 3 with the support under the gown's body searched with the cloth (session 58:
// 13 parameters, rounds of 8 x 32 at sigma0 0.03 by the sum from that file's values with the
// support placed at 0.95 m / -0.15 m): good 0.2790, middle missed 0.5149, missed 0.4760, sum
// 1.2699. Bounded here by 0.515, below the worst of the file without the support (0.6000).
// The support's path (its rise while the gown settles, its contacts) is simulated again to the
// bit.
TEST(SimCalibration, Participant3sSupportCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant3-support.json", 0.515);
}

// Participant 2 searched longer (20 x 32, sigma0 0.1, from participant2-simulator.json; sessions
// 25-26): L 1.292 from 1.646. Every sequence gained (good 0.384 from 0.468, middle missed 0.549
// from 0.643, missed 0.359 from 0.535) and none reaches the 0.3; bounded here by 0.6.
TEST(SimCalibration, Participant2sLongerCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant2-longer.json", 0.6);
}

// Participant 2 in small steps (6 x 32, sigma0 0.001, --combine worst, seed 1, from
// participant2-longer.json; sessions 39-40): good 0.3504, middle missed 0.4332, missed 0.3665; the worst
// sequence (middle missed) from 0.549, the sum from 1.292. Not at the 0.3; bounded here by
// 0.434.
TEST(SimCalibration, Participant2sSmallStepCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant2-fine.json", 0.434);
}

// Participant 2's second small-step round (12 x 32, sigma0 0.001, --combine worst, seed 1, from
// participant2-fine.json; session 44): good 0.3585, middle missed 0.3970, missed 0.3920; the worst
// sequence from 0.4332, the sum from 1.1501 to 1.1474, the two others given up for it (0.350 and
// 0.366 before). Not at the 0.3; bounded here by 0.398.
TEST(SimCalibration, Participant2sSecondSmallStepRoundFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant2-fine2.json", 0.398);
}

// Participant 2's files with the support: his good and missed sequences (the high and the low
// arm) within the 0.3, the middle arm's bounded by `middle_at_most`.
void expect_fits_participant2s_good_and_missed(const std::string& file, double middle_at_most) {
  std::vector<double> fits;
  expect_fits_own_sequences_to_the_bit(file, middle_at_most, &fits);
  if (fits.empty()) return;  // skipped
  ASSERT_EQ(fits.size(), 3u);
  EXPECT_LE(fits[0], 0.3) << "s2-good-2";
  EXPECT_LE(fits[2], 0.3) << "s2-miss-6";
}

// Participant 2 with the support under the gown's body searched with the cloth (session 64: 13
// parameters, 8 x 32 at sigma0 0.03, --combine worst, seed 1, from participant2-fine2.json's
// values with the support placed at 1.00 m / -0.05 m): good 0.2821, middle missed 0.4642, missed
// 0.2921. His first sequences within the 0.3, two of three; the middle arm's is bounded
// here by 0.465. Without the support the same values give 0.4946 / 0.7693 / 0.3134, so the
// support's path (its rise while the gown settles, its contacts) is part of the fit.
TEST(SimCalibration, Participant2sSupportCalibrationFitsTheirGoodAndMissedSequences) {
  expect_fits_participant2s_good_and_missed("participant2-support.json", 0.465);
}

// Participant 2 searched on from his support file by `--combine count` (session 66: the number of
// sequences over 0.3 first, then each one's excess; 8 x 32 at sigma0 0.003, seed 1, the support
// allowed down to 1.5 m): good 0.2624, middle missed 0.4427, missed 0.2788, each below the support
// file's 0.2821 / 0.4642 / 0.2921. The good and missed sequences within the 0.3; the
// middle arm's bounded here by 0.443.
TEST(SimCalibration, Participant2sCountCalibrationFitsTheirGoodAndMissedSequences) {
  expect_fits_participant2s_good_and_missed("participant2-count.json", 0.443);
}

// Participant 7 in small steps (the same recipe from participant7-longer.json; sessions 39-40):
// good 0.3795, middle missed 0.5374, missed 0.3023; the worst sequence from 0.577, the sum from 1.261.
// The low arm's missed sequence left the 0.3 (0.296 before). Bounded here by 0.538.
TEST(SimCalibration, Participant7sSmallStepCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant7-fine.json", 0.538);
}

// Participant 5 with the heights' contrast in the objective (calibrate --contrast-weight 5, 4 x 16
// from their shipped file; session 20): the early cue of F_motion turned the people's way. The
// missed sequence gave up its 0.3 for it: 0.265 and 0.361, bounded here by 0.4.
TEST(SimCalibration, Participant5sContrastCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant5-contrast.json", 0.4);
}

// Participant 0 with the heights' contrast in the objective (calibrate --contrast-weight 5, 6 x 16,
// sigma0 0.05, from their shipped file; sessions 21-22): every sequence fits better than the
// shipped file's (0.705, 1.522, 0.873): 0.631, 1.231 and 0.829; rescored in session 45, the middle
// 0.764 (as above), 0.788 since session 92 (as above). Bounded here by 0.83.
TEST(SimCalibration, Participant0sContrastCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant0-contrast.json", 0.83);
}

// Participant 0 searched on from it by the paper's sum (8 x 32, sigma0 0.03, seed 1, one thread;
// session 41): 0.502, 1.104 and 0.767, every sequence lower again; rescored in session 45, the
// middle 0.838 (as above; the search had fitted the misaligned curve), 0.836 since session 92.
// Bounded here by 0.84.
TEST(SimCalibration, Participant0sSmallerStepCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant0-fine.json", 0.84);
}

// Participant 0 searched on from that file by the objective that pairs the late recording from
// the same travel (12 x 32, sigma0 0.05, seed 1, two threads; session 45): 0.4095, 0.5397 and
// 0.8050, sum 1.754 from the rescored file's 2.108; the middle 0.535 since session 92 paired it
// at the same time of the pull (sum 1.750). Bounded here by 0.806.
TEST(SimCalibration, Participant0sPairedFromTheSameTravelFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant0-fine2.json", 0.806);
}

// A second round from it (10 x 32, the same command; session 45): 0.2721, 0.4914 and 0.6519, sum
// 1.415; the good sequence within the 0.3. The middle 0.551 since session 92 (sum 1.475:
// these rounds were searched against the pairing at the same travel). Bounded here by 0.652.
TEST(SimCalibration, Participant0sSecondPairedRoundFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant0-fine3.json", 0.652);
}

// A third round from it (5 x 32; session 45): 0.3144, 0.3868 and 0.6410, sum 1.342; the worst and
// the sum lower, the good sequence given back over 0.3 for the middle one. The middle 0.462 since
// session 92 (sum 1.417). Bounded here by 0.6411.
TEST(SimCalibration, Participant0sThirdPairedRoundFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant0-fine4.json", 0.6411);
}

// A fourth round from it (10 x 32; session 46): 0.2606, 0.4413 and 0.6027, sum 1.305; the worst
// and the sum lower again, the good sequence back within 0.3; the fist at its box's edge
// (0.15 m toward the elbow). The middle 0.541 since session 92 (sum 1.404). Bounded here by
// 0.6028.
TEST(SimCalibration, Participant0sFourthPairedRoundFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant0-fine5.json", 0.6028);
}

// A fifth round from it at the small step (5 x 32, sigma0 0.001; session 47), where a third of
// the landscape's points lay below it: 0.2310, 0.4074 and 0.5879, sum 1.226; every sequence
// lower. The middle 0.503 since session 92 (sum 1.322). Bounded here by 0.588.
TEST(SimCalibration, Participant0sSmallStepRoundFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant0-fine6.json", 0.588);
}

// Participant 1 likewise (6 x 16, sigma0 0.05; sessions 21-22): good 0.248 (was 0.428), missed
// 0.477 (was 0.414), bounded here by 0.5.
TEST(SimCalibration, Participant1sContrastCalibrationFitsTheirSequences) {
  expect_fits_own_sequences_to_the_bit("participant1-contrast.json", 0.5);
}

// Participant 4 with the support under the gown (calibrate --support-depth fit --support-lateral
// fit --contrast-weight 5 --lateral-weight 1, 10 x 24 from the contrast file's values with the
// support at 0.85 m; session 19): the support's path simulated again to the bit. Not at the
// issue's 0.3: 0.4375 and 0.4216, bounded here by 0.45.
TEST(SimCalibration, Participant4sSupportCalibrationFitsHisSequences) {
  expect_fits_own_sequences_to_the_bit("participant4-support.json", 0.45);
}

// The discrepancy term on a real calibration (discrepancy.h): participant 4's contrast file, his
// two sequences. Added to the simulated curves it must bring them onto the measured ones,
// except for what its 2 cm windows smooth away and the length term (eq. 4's w = 20 part, which
// a force correction cannot move): the area part of L falls to the sensor's noise level, and the
// early cue between the heights (what a classifier of cut sequences learns) becomes the
// measured one.
TEST(SimCalibration, DiscrepancyBringsParticipant4sSimulatorOntoHisSequences) {
  const auto dir = study_dir();
  if (dir.empty()) GTEST_SKIP() << "shared/data/kapusta2016-calibration-trials not present";
  if (gown::measured_gown_path().empty()) GTEST_SKIP() << "shared/data/gown not present (calibrated on the measured gown)";
  const Calibration cal =
      read_calibration(std::filesystem::path(DRESSGUARD_SOURCE_DIR) / "models" / "participant4-contrast.json");
  const auto inputs = calibration_inputs(cal, "participant4-contrast.json", import_study(dir), dir);
  ASSERT_EQ(inputs.size(), 2u);
  ASSERT_EQ(inputs[0].height, ArmHeight::High);
  ASSERT_EQ(inputs[1].height, ArmHeight::Low);
  const auto sts = simulate_inputs(make_cloth_simulator(cal.gown).trials, cal.cloth, cal.offsets, inputs);
  const Discrepancy d = measure_discrepancy(inputs, sts);
  std::vector<HapticSequence> corrected;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    HapticSequence c = inputs[k];
    c.samples = sts[k].samples;
    apply_discrepancy(d, c);
    corrected.push_back(c);
    const double raw = area_objective(sts[k].samples, inputs[k].samples, 0.0);
    const double fixed = area_objective(c.samples, inputs[k].samples, 0.0);
    std::printf("  %s: area part of L %.4f -> %.4f with the discrepancy\n", inputs[k].id.c_str(), raw, fixed);
    // Below the floor of the study's own repeats (two good trials of one person: 0.09; issue 4).
    EXPECT_LT(fixed, 0.09) << inputs[k].id;
    // Paired as eq. 3 pairs (moments of the pull) the term leaves 0.12 and 0.14 of the area;
    // with windows of equal travel, the recording's by its stamp (until session 94), 0.21 and 0.18.
    EXPECT_LT(fixed, 0.2 * raw) << inputs[k].id;
  }
  const double windows[3][2] = {{0.10, 0.15}, {0.15, 0.20}, {0.20, 0.30}};
  for (const auto& w : windows) {
    auto mean = [&](const HapticSequence& s) {
      double sum = 0;
      int n = 0;
      for (const auto& x : s.samples)
        if (x.travel >= w[0] && x.travel < w[1]) sum += x.f_motion, ++n;
      return sum / n;
    };
    // The recordings on the simulator's travel: each measured sample at its pair's (the term
    // pairs moments of the pull, as eq. 3: objective.h, paired_start).
    auto on_simulated_travel = [&](std::size_t k) {
      HapticSequence m = inputs[k];
      const PairedStart ps = paired_start(sts[k].samples, m.samples);
      m.samples.erase(m.samples.begin(), m.samples.begin() + static_cast<std::ptrdiff_t>(ps.measured));
      m.samples.resize(ps.count);
      for (std::size_t i = 0; i < ps.count; ++i) m.samples[i].travel = sts[k].samples[ps.sim + i].travel;
      return m;
    };
    const double measured = mean(on_simulated_travel(0)) - mean(on_simulated_travel(1));
    const double simulated = mean(HapticSequence{"", "", ArmHeight::High, 0.1, {}, sts[0].samples}) -
                             mean(HapticSequence{"", "", ArmHeight::Low, 0.1, {}, sts[1].samples});
    const double fixed = mean(corrected[0]) - mean(corrected[1]);
    std::printf("  high minus low F_motion over %.2f-%.2f m: measured %+.3f, simulated %+.3f, corrected %+.3f N\n",
                w[0], w[1], measured, simulated, fixed);
    // Half the faintest cue the pooled bench counts (0.02 N): the windows' smoothing is finer.
    EXPECT_NEAR(fixed, measured, 0.01) << "over " << w[0] << "-" << w[1] << " m";
  }
}

// One generation on participant 4's sequences (the paper's public code calibrated on the same
// person): every candidate's objective is finite and the per-sequence fits add up to L.
TEST(SimCalibration, OneGenerationOnParticipant4) {
  const auto dir = study_dir();
  if (dir.empty()) GTEST_SKIP() << "shared/data/kapusta2016-calibration-trials not present";
  const Dataset ds = import_study(dir);
  const auto inputs = select_inputs(ds, "4", 1);
  ParameterSpace space;
  space.bounds = default_bounds();
  for (const auto& s : inputs) space.offset_heights.push_back(s.height);
  CalibrationOptions o;
  o.generations = 1;
  o.population = 4;
  const auto r = calibrate(inputs, space, make_cloth_simulator("coarse").trials, o, Comm::world());
  std::printf("  participant 4, one generation of 4 on the coarse gown: L = %.4f\n", r.objective);
  EXPECT_TRUE(std::isfinite(r.objective));
  double sum = 0;
  for (const auto& f : r.fits) sum += f.objective;
  EXPECT_NEAR(sum, r.objective, 1e-9 * std::max(1.0, r.objective));
}

}  // namespace
}  // namespace dressguard::calib
