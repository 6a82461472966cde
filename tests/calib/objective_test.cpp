// The calibration objective (paper eq. 3-5): closed-form cases, and the yardstick on the
// measured repeats of one person's trial.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "dataset.h"
#include "objective.h"
#include "synthesis.h"

namespace dressguard::calib {
namespace {

// A pull at constant speed: travel i*h, forces constant.
std::vector<HapticSample> constant_curve(int samples, double h, double f_motion, double f_vertical) {
  std::vector<HapticSample> s(samples);
  for (int i = 0; i < samples; ++i) s[i] = {i * 0.01, i * h, f_motion, 0.0, f_vertical};
  return s;
}

// Two curves of equal length offset by c (motion) and d (vertical): the area between them is
// (|c| + |d|) times the distance travelled, exactly (eq. 3-4 with no length mismatch).
TEST(Objective, ConstantOffsetGivesOffsetTimesDistance) {
  const int n = 501;
  const double h = 0.001;  // 0.5 m of travel
  const auto r = constant_curve(n, h, -2.0, 0.5);
  const auto s = constant_curve(n, h, -2.3, 0.4);
  const double distance = (n - 1) * h;
  EXPECT_NEAR(area_error(s, r, ForceAxis::Motion), 0.3 * distance, 1e-12);
  EXPECT_NEAR(area_error(s, r, ForceAxis::Vertical), 0.1 * distance, 1e-12);
  EXPECT_NEAR(area_objective(s, r), 0.4 * distance, 1e-12);
  EXPECT_DOUBLE_EQ(area_objective(r, r), 0.0);
}

// A simulation that runs k samples longer than the measurement, with force s_extra there:
// eq. 4's second case adds w * k * h * |s_extra - r_n| per axis.
TEST(Objective, LengthMismatchIsPenalisedWithW) {
  const double h = 0.001;
  const auto r = constant_curve(301, h, -1.0, 0.0);
  auto s = constant_curve(301, h, -1.0, 0.0);
  for (int i = 301; i < 351; ++i) s.push_back({i * 0.01, i * h, -4.0, 0.0, 0.0});  // 50 more samples at -4 N
  const double expected = kLengthPenaltyWeight * 50 * h * 3.0;  // w k h |-4 - (-1)|
  EXPECT_NEAR(area_objective(s, r), expected, 1e-12);
  // The third case (measurement longer) is the mirror image: the same value with roles swapped.
  EXPECT_NEAR(area_objective(r, s), expected, 1e-12);
  EXPECT_NEAR(area_objective(s, r, /*w=*/1.0), expected / kLengthPenaltyWeight, 1e-12);
}

// area_objective_so_far (calibrate --prune) on every prefix of a simulation: it never decreases
// as samples come, never exceeds the whole simulation's L, and is exact in closed form. A
// simulation 50 samples longer than the measurement at -4 N against -1: each prefix of k <= 301
// samples scores the offset 0.3 N over its (k - 1) h of travel (no measurement-longer term), and
// beyond the measurement's end w h |-4 - (-1)| more per sample, reaching area_objective at the
// end. The mirror case (a measurement longer than the finished simulation) keeps its w terms
// only in the whole L: the bound of the whole simulation is L less those terms.
TEST(Objective, SoFarIsALowerBoundThatGrowsToTheWholeL) {
  const double h = 0.001;
  const auto r = constant_curve(301, h, -1.0, 0.0);
  auto s = constant_curve(301, h, -1.3, 0.0);
  for (int i = 301; i < 351; ++i) s.push_back({i * 0.01, i * h, -4.0, 0.0, 0.0});
  const double whole = area_objective(s, r);
  double last = 0.0;
  for (std::size_t k = 1; k <= s.size(); ++k) {
    const std::vector<HapticSample> prefix(s.begin(), s.begin() + static_cast<long>(k));
    const double b = area_objective_so_far(prefix, r);
    const double beyond = k > 301 ? kLengthPenaltyWeight * static_cast<double>(k - 301) * h * 3.0 : 0.0;
    ASSERT_NEAR(b, 0.3 * static_cast<double>(std::min<std::size_t>(k, 301) - 1) * h + beyond, 1e-12) << k;
    ASSERT_GE(b, last) << k;
    ASSERT_LE(b, whole + 1e-12) << k;
    last = b;
  }
  EXPECT_NEAR(last, whole, 1e-12);
  // A simulation that stopped 100 samples short of the measurement, -1.3 N where it stopped.
  const std::vector<HapticSample> stopped(s.begin(), s.begin() + 201);
  EXPECT_NEAR(area_objective_so_far(stopped, r), 0.3 * 200 * h, 1e-12);
  EXPECT_NEAR(area_objective(stopped, r), 0.3 * 200 * h + kLengthPenaltyWeight * 100 * h * 0.3, 1e-12);
  EXPECT_DOUBLE_EQ(area_objective_so_far({}, r), 0.0);
}

// Position-weighted (the public code's variant): identical curves give 0; a constant offset c on
// travel [0, X] gives sum exp(x_i) c h -> c (e^X - 1) as h -> 0 (right Riemann sum: relative
// error about h/2, 5e-4 here, so 1e-3 relative tolerance).
TEST(Objective, PositionWeightedClosedForm) {
  const double h = 0.001;
  const auto r = constant_curve(801, h, -2.0, 0.0);
  EXPECT_DOUBLE_EQ(position_weighted_objective(r, r), 0.0);
  const auto s = constant_curve(801, h, -2.5, 0.0);
  const double expected = 0.5 * (std::exp(0.8) - 1.0);
  EXPECT_NEAR(position_weighted_objective(s, r), expected, 1e-3 * expected);
  // Simulation that stops early at 0.4 m with the same force: nothing to penalise.
  EXPECT_DOUBLE_EQ(position_weighted_objective(constant_curve(401, h, -2.0, 0.0), r), 0.0);
  // ... and 1 N off: inside exp(x) * 1 N * h, beyond 0.4 m 1.5 exp(x + 0.4) * 1 N * h.
  auto early_off = constant_curve(401, h, -1.0, 0.0);
  double tail2 = 0, inside = 0;
  for (int i = 1; i < 801; ++i) {
    const double x = i * h;
    if (x > 0.4 + 1e-12) tail2 += 1.5 * std::exp(x + 0.4) * 1.0 * h;
    else inside += std::exp(x) * 1.0 * h;
  }
  EXPECT_NEAR(position_weighted_objective(early_off, r), inside + tail2, 1e-9);
}

// The heights' contrast in closed form. Measured: high F_motion -0.3, F_vertical +0.2; low -0.5
// and -0.1 (contrast +0.2, +0.3 N), both to 0.5 m (1 mm steps).
// - A simulator 1 N off on every curve alike shows the same contrast: error 0.
// - One whose vertical contrast is reversed (high -0.2, low +0.1: -0.3 N) is 0.6 N off over the
//   first 0.30 m: 0.18 N m (60 cells of 5 mm), and nothing beyond the cut counts.
// - Cut short by a simulated low curve that ends at 0.2 m: 0.6 x 0.2 = 0.12 N m.
// - A ramp: simulated high F_motion 2x (x in m) over a measured contrast of 0 gives the area under
//   2x to 0.3 m, 0.09 N m, exactly on the cell midpoints.
TEST(Objective, ContrastErrorClosedForm) {
  const auto mh = constant_curve(501, 0.001, -0.3, 0.2), ml = constant_curve(501, 0.001, -0.5, -0.1);
  EXPECT_NEAR(contrast_error(constant_curve(501, 0.001, 0.7, 1.2), constant_curve(501, 0.001, 0.5, 0.9), mh, ml,
                             kLatestCut), 0.0, 1e-12);
  const auto sh = constant_curve(501, 0.001, -0.3, -0.2), sl = constant_curve(501, 0.001, -0.5, 0.1);
  EXPECT_NEAR(contrast_error(sh, sl, mh, ml, kLatestCut), 0.18, 1e-12);
  EXPECT_NEAR(contrast_error(sh, sl, mh, ml, 0.5), 0.30, 1e-12);
  EXPECT_NEAR(contrast_error(sh, constant_curve(201, 0.001, -0.5, 0.1), mh, ml, kLatestCut), 0.12, 1e-12);
  auto ramp = constant_curve(501, 0.001, 0.0, 0.0);
  for (auto& x : ramp) x.f_motion = 2 * x.travel;
  const auto flat = constant_curve(501, 0.001, 0.0, 0.0);
  EXPECT_NEAR(contrast_error(ramp, flat, flat, flat, kLatestCut), 0.09, 1e-12);
  EXPECT_THROW(contrast_error({}, flat, flat, flat, kLatestCut), std::invalid_argument);
}

// A recording that starts late (objective.h, "Where the pairs begin"). The measured curve is the
// simulated one from 0.96 s on, sample for sample (a pull at 0.1 m/s from the start, forces a
// function of travel only; the recording's clock its own, from 0): paired from the simulation's
// first sample its L would be the area between the curve and itself shifted by 0.096 m plus the
// w = 20 tail; paired from the same time of the pull, 0.096 m / 0.1 m/s, it is 0, exactly. A
// simulation that starts late (its clock the pull's) pairs the same way round. A start within
// kLateStart pairs as the paper pairs (index 0 with 0).
TEST(Objective, LateStartPairsFromTheSameTimeOfThePull) {
  const double h = 0.001;
  auto f = [](int k) { return -0.01 * k; };  // F_motion -10 N/m of travel, sample k at k mm
  std::vector<HapticSample> sim, late, late_sim;
  for (int k = 0; k <= 850; ++k) sim.push_back({k * 0.01, k * h, f(k), 0.0, 0.5 * f(k)});
  for (int k = 96; k <= 850; ++k) late.push_back({(k - 96) * 0.01, k * h, f(k), 0.0, 0.5 * f(k)});
  for (int k = 96; k <= 850; ++k) late_sim.push_back({k * 0.01, k * h, f(k), 0.0, 0.5 * f(k)});
  const PairedStart p = paired_start(sim, late);
  EXPECT_EQ(p.sim, 96u);
  EXPECT_EQ(p.measured, 0u);
  EXPECT_EQ(p.count, 755u);  // both to the end: samples 96-850 of the simulation
  EXPECT_EQ(area_objective(sim, late), 0.0);
  EXPECT_EQ(paired_start(late_sim, sim).sim, 0u);
  EXPECT_EQ(paired_start(late_sim, sim).measured, 96u);
  EXPECT_EQ(area_objective(late_sim, sim), 0.0);
  // Shifted back to start with the pull, the same samples are 0.096 m off: 0.96 N (and 0.48 N)
  // over 0.754 m, plus the simulation's 96 extra samples at w = 20, all in closed form.
  auto early = late;
  for (std::size_t i = 0; i < early.size(); ++i) early[i].travel = static_cast<double>(i) * h;
  double tail = 0;
  for (int k = 755; k <= 850; ++k) tail += kLengthPenaltyWeight * h * 1.5 * std::abs(f(k) - f(850));
  EXPECT_NEAR(area_objective(sim, early), 1.5 * 0.96 * 0.754 + tail, 1e-9);
  // 4 mm late: within kLateStart, paired by index as eq. 3 does.
  std::vector<HapticSample> near(sim.begin() + 4, sim.end());
  EXPECT_EQ(paired_start(sim, near).sim, 0u);
  EXPECT_EQ(paired_start(sim, near).measured, 0u);
  // A simulation that stops before the late start pairs its last sample with the first measured
  // one; the rest is the measurement running longer (eq. 4's third case).
  const std::vector<HapticSample> short_sim(sim.begin(), sim.begin() + 51);
  EXPECT_EQ(paired_start(short_sim, late).sim, 50u);
  EXPECT_EQ(paired_start(short_sim, late).count, 1u);  // its last sample, the one pair
  double longer = 0;
  for (int k = 97; k <= 850; ++k) longer += kLengthPenaltyWeight * h * 1.5 * std::abs(f(50) - f(k));
  EXPECT_NEAR(area_objective(short_sim, late), longer, 1e-9);
  // A recording whose stamp does not advance has no speed to read its time by: paired from the
  // same travel.
  std::vector<HapticSample> still = late;
  for (auto& x : still) x.travel = late.front().travel;
  EXPECT_EQ(paired_start(sim, still).sim, 96u);
  // A first travel that is not a number (a simulation that blew up) starts nowhere: paired by
  // index, not taken for a late start.
  std::vector<HapticSample> blown = late_sim;
  blown.front().travel = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(paired_start(blown, sim).sim, 0u);
  EXPECT_EQ(paired_start(blown, sim).measured, 0u);
}

// The simulation's travel is the ramped profile's (from rest at 1 m/s^2 to 0.15 m/s), the
// recording's the constant-speed stamp's (core/haptic.h): v t. A recording that starts 0.64 s
// into a pull, stamped at 0.096 m, of forces that are the same function of the pull's time as the
// simulation's (the gripper where the simulated one is at that time), pairs with the simulated
// sample at 0.64 s, and the two curves are one: L = 0 up to rounding. The simulated sample at the
// same travel, 0.096 m, is 0.075 s (v / 2a) later (0.715 s, the sample at 0.72 s): paired there
// (sessions 45-91) every pair was 8 samples apart.
TEST(Objective, ALateRecordingPairsAtItsStampsTimeOnTheRampedPull) {
  const double v = 0.15, a = kRigAcceleration, ramp_end = v / a;
  auto ramped = [&](double t) { return t < ramp_end ? 0.5 * a * t * t : v * (t - 0.5 * ramp_end); };
  auto g = [](double t) { return -2.0 * t; };  // F_motion [N] against the pull's time [s]
  std::vector<HapticSample> sim, late;
  for (int k = 0; k < 500; ++k) {
    const double t = (k + 1) * 0.01;  // the simulator's first sample is one step into the pull
    sim.push_back({t, ramped(t), g(t), 0.0, 0.5 * g(t)});
  }
  for (int j = 0; j < 437; ++j) {  // 0.64 s to 5.0 s of the pull: both end at its sample at 5.0 s
    const double t = 0.64 + j * 0.01;
    late.push_back({j * 0.01, v * t, g(t), 0.0, 0.5 * g(t)});
  }
  const PairedStart p = paired_start(sim, late);
  EXPECT_EQ(p.sim, 63u) << "the simulated sample at 0.64 s";
  EXPECT_EQ(p.measured, 0u);
  EXPECT_NEAR(area_objective(sim, late), 0.0, 1e-12);
  // The same travel is later in the ramped pull.
  std::size_t same_travel = 0;
  while (sim[same_travel].travel < late.front().travel) ++same_travel;
  EXPECT_EQ(same_travel, 71u) << "0.096 m is reached at 0.715 s: the sample at 0.72 s";
}

TEST(Objective, ParseNames) {
  EXPECT_EQ(parse_objective("area"), ObjectiveKind::Area);
  EXPECT_EQ(parse_objective("position-weighted"), ObjectiveKind::PositionWeighted);
  EXPECT_FALSE(parse_objective("mse").has_value());
}

const HapticSequence& trial(const Dataset& ds, const std::string& id) {
  for (const auto& t : ds.trials)
    if (t.id == id) return t;
  throw std::runtime_error("no trial " + id);
}

// The yardstick: L between two repeats of one person's trial (w = 20).
//   good   s1 1 vs 3: stated 0.09; ours 0.108.
//   missed s1 1 vs 4: stated 0.22; ours 0.222.
//   middle missed, s2 1 vs 7 and s7 1 vs 3: stated 0.26 = their median; ours 0.137 and 0.378,
//   median 0.257.
// The good pair differs only in the length term: the two trials stop at the 10 N threshold 4
// samples (3.3 mm) apart while the force climbs at ~1 N/cm, and w = 20 on those 4 samples adds
// 0.025 to the 0.083 of the overlapping part. The stated 0.09 is what w = 5 gives (0.089); with
// w = 20 and either choice of dx (measured, simulated or their mean) we get 0.107-0.108, so we
// keep w = 20 as the paper says and accept 0.02 on the good figure. The others agree to 0.005.
TEST(Objective, YardstickOnMeasuredRepeats) {
  const auto dir = study_dir();
  if (dir.empty()) GTEST_SKIP() << "shared/data/kapusta2016-calibration-trials not present";
  const Dataset ds = import_study(dir);
  auto L = [&](const std::string& a, const std::string& b) {
    return area_objective(trial(ds, a).samples, trial(ds, b).samples);
  };
  const double good = L("s1-good-1", "s1-good-3");
  const double missed = L("s1-miss-1", "s1-miss-4");
  const double mid_a = L("s2-middlemiss-1", "s2-middlemiss-7");
  const double mid_b = L("s7-middlemiss-1", "s7-middlemiss-3");
  std::printf("  L good %.4f  missed %.4f  middle %.4f / %.4f (median %.4f)\n", good, missed, mid_a, mid_b,
              0.5 * (mid_a + mid_b));
  EXPECT_NEAR(good, 0.09, 0.02);
  EXPECT_NEAR(area_objective(trial(ds, "s1-good-1").samples, trial(ds, "s1-good-3").samples, 5.0), 0.09, 0.005);
  EXPECT_NEAR(missed, 0.22, 0.005);
  EXPECT_NEAR(0.5 * (mid_a + mid_b), 0.26, 0.005);
  // The repeat band of the synthesis (synthesis.h) uses these two figures as constants: they must
  // be what the study's repeats give, to their printed three digits.
  EXPECT_NEAR(good, kRepeatDistanceGood, 0.0005);
  EXPECT_NEAR(missed, kRepeatDistanceMissed, 0.0005);
  // Symmetry between repeats: swapping the roles moves L by less than 0.001 (dx choice).
  EXPECT_NEAR(L("s1-good-3", "s1-good-1"), good, 1e-3);
  EXPECT_NEAR(L("s1-miss-4", "s1-miss-1"), missed, 1e-3);
}

// The study's starts, which kLateStart rests on: every recording but one starts within 1.1 mm of its
// pull's start; s0-middlemiss-10 (0.15 m/s) starts 0.0958 m in, and only it pairs from a later
// simulated sample against a pull from 0 (here one at 0.1 m/s, its sample k at k * 10 ms).
TEST(Objective, OneStudyRecordingStartsLate) {
  const auto dir = study_dir();
  if (dir.empty()) GTEST_SKIP() << "shared/data/kapusta2016-calibration-trials not present";
  const Dataset ds = import_study(dir);
  const std::vector<HapticSample> pull = constant_curve(901, 0.001, 0.0, 0.0);  // from travel 0
  for (const auto& t : ds.trials) {
    const PairedStart p = paired_start(pull, t.samples);
    if (t.id == "s0-middlemiss-10") {
      EXPECT_NEAR(t.samples.front().travel, 0.0958, 5e-5);
      // By its stamp 0.0958 / 0.15 = 0.639 s into the pull: paired with the simulated sample at
      // 0.64 s, and at its 10.0 ms period the HMMs start their chain 64 samples on (hmm.h,
      // FeatureSequence::unobserved). Read as the ramped profile's travel (until session 92),
      // 0.714 s: the sample at 0.096 m of this pull and 71 samples.
      EXPECT_EQ(p.sim, 64u) << "the simulated sample at 0.64 s";
      EXPECT_EQ(unrecorded_samples(t), 64u);
    } else {
      EXPECT_LT(t.samples.front().travel, 0.0011) << t.id;
      EXPECT_EQ(p.sim, 0u) << t.id;
      EXPECT_EQ(unrecorded_samples(t), 0u) << t.id;
    }
    EXPECT_EQ(p.measured, 0u) << t.id;
  }
}

// The bound on the study's own trials, each prefix of one trial scored against another trial of
// the same person (the late-starting s0-middlemiss-10 among them): never
// above the whole L, never decreasing, equal to it at the end when the first runs at least as
// long as the second.
TEST(Objective, SoFarBoundsTheWholeLOnMeasuredTrials) {
  const auto dir = study_dir();
  if (dir.empty()) GTEST_SKIP() << "shared/data/kapusta2016-calibration-trials not present";
  const Dataset ds = import_study(dir);
  int pairs = 0;
  for (const auto& a : ds.trials)
    for (const auto& b : ds.trials) {
      if (&a == &b || a.participant != b.participant) continue;
      const double whole = area_objective(a.samples, b.samples);
      double last = 0.0;
      for (std::size_t k = 1; k <= a.samples.size(); k += 7) {
        const std::vector<HapticSample> prefix(a.samples.begin(), a.samples.begin() + static_cast<long>(k));
        const double v = area_objective_so_far(prefix, b.samples);
        ASSERT_GE(v, last) << a.id << " against " << b.id << ", " << k << " samples";
        ASSERT_LE(v, whole * (1 + 1e-12) + 1e-12) << a.id << " against " << b.id << ", " << k << " samples";
        last = v;
      }
      const PairedStart p = paired_start(a.samples, b.samples);
      if (a.samples.size() - p.sim >= b.samples.size() - p.measured) {  // no measurement-longer term
        EXPECT_NEAR(area_objective_so_far(a.samples, b.samples), whole, 1e-9 * (1 + whole)) << a.id << " against " << b.id;
      }
      ++pairs;
    }
  EXPECT_GT(pairs, 20);
}

// Across people (same class, different participants): the issue states medians 0.57 (good),
// 0.55 (missed), 0.86 (middle). For missed we get 0.543. For good and middle our medians are far
// larger (1.65, 1.51): across people the trials stop at different travel (good ends at
// 0.62 +- 0.03 m), and w = 20 multiplies the whole unmatched tail; the stated figures are not
// reproduced by any single w (w = 1 gives 0.47 / 0.34 / 0.53). We assert the missed figure and
// that good and middle are above it (the penalty dominates), and print all three.
TEST(Objective, YardstickAcrossPeople) {
  const auto dir = study_dir();
  if (dir.empty()) GTEST_SKIP() << "shared/data/kapusta2016-calibration-trials not present";
  const Dataset ds = import_study(dir);
  std::map<std::string, std::vector<const HapticSequence*>> by_class;
  for (const auto& t : ds.trials) by_class[std::string(arm_height_name(t.height))].push_back(&t);
  std::map<std::string, double> median;
  for (auto& [cls, v] : by_class) {
    std::vector<double> l;
    for (std::size_t a = 0; a < v.size(); ++a)
      for (std::size_t b = a + 1; b < v.size(); ++b)
        if (v[a]->participant != v[b]->participant) l.push_back(area_objective(v[a]->samples, v[b]->samples));
    std::nth_element(l.begin(), l.begin() + l.size() / 2, l.end());
    median[cls] = l.size() % 2 ? l[l.size() / 2] : 0.5 * (l[l.size() / 2] + *std::max_element(l.begin(), l.begin() + l.size() / 2));
    std::printf("  across people %-6s median L %.3f over %zu pairs\n", cls.c_str(), median[cls], l.size());
  }
  EXPECT_NEAR(median["low"], 0.55, 0.02);
  EXPECT_GT(median["high"], median["low"]);
  EXPECT_GT(median["middle"], median["low"]);
}

}  // namespace
}  // namespace dressguard::calib
