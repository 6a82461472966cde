// The discrepancy term (discrepancy.h) against answers known in closed form: a "measured" curve
// made as the simulated one plus a chosen function of travel must give that function back, the
// fade and the heights without an input follow their stated rules, and bad input names itself.
// The same on the real simulator and the study's data: sim_calibration_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "dataset.h"
#include "discrepancy.h"
#include "fake_sim.h"
#include "files.h"

namespace dressguard::calib {
namespace {

// A simulated curve of the stand-in simulator (samples every 1 mm of travel at 0.1 m/s).
SimulatedTrial simulated_curve(ArmHeight h) {
  TrialRequest r;
  r.height = h;
  r.speed = 0.1;
  r.max_travel = 0.5;
  return testing::fake_simulate(ClothValues{}, r);
}

// The "measured" sequence: the simulated curve plus (motion, lateral, vertical) = g(x).
template <class G>
HapticSequence measured_from(const SimulatedTrial& sim, ArmHeight h, G g) {
  HapticSequence s;
  s.id = std::string("m-") + std::string(arm_height_name(h));
  s.height = h;
  s.samples = sim.samples;
  for (auto& x : s.samples) {
    const auto d = g(x.travel);
    x.f_motion += d[0], x.f_lateral += d[1], x.f_vertical += d[2];
  }
  return s;
}

TEST(Discrepancy, GivesBackTheDifferenceItWasMadeWith) {
  // g linear in travel. Both curves are sampled at the same travels, so each grid point's value
  // is g at the mean travel of the window's samples, 1 mm apart in [x - 1 cm, x + 1 cm): 19 to 21
  // of them as the edges round, their mean within 1 mm of x. So |r(x) - g(x)| <= |g'| x 1 mm.
  const auto sim = simulated_curve(ArmHeight::High);
  const double slope[3] = {-2.0, 0.5, 1.5};
  auto g = [&](double x) { return std::array<double, 3>{0.3 + slope[0] * x, -0.1 + slope[1] * x, 0.05 + slope[2] * x}; };
  const auto d = measure_discrepancy({measured_from(sim, ArmHeight::High, g)}, {sim});
  const auto& r = d.by_height[static_cast<int>(ArmHeight::High)];
  ASSERT_GE(r.size(), 40u);  // the stand-in's high arm pulls past 0.4 m before its 10 N stop
  EXPECT_TRUE(d.by_height[static_cast<int>(ArmHeight::Low)].empty());
  for (std::size_t j = 2; j + 2 < r.size(); ++j) {  // windows inside both curves
    const double x = 0.01 * static_cast<double>(j);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(r[j][k], g(x)[k], std::abs(slope[k]) * 1e-3) << "grid point " << j << ", force " << k;
  }
}

// An input whose recording starts 0.0958 m into the pull (s0-middlemiss-10), made as the
// simulated curve plus 1 N of F_motion. Its pairs begin at the simulated sample of its first
// sample's time (objective.h, paired_start), so a window holding the start holds only pairs of one
// moment: 1 N, where the means of the recording's few samples and of the simulator's whole window
// would differ by the high arm's drag, steep in travel. Windows without a pair keep 0.
TEST(Discrepancy, ALateStartIsMeasuredFromItsFirstPair) {
  const auto sim = simulated_curve(ArmHeight::High);
  HapticSequence late = measured_from(sim, ArmHeight::High, [](double) { return std::array<double, 3>{1.0, 0, 0}; });
  late.samples.erase(late.samples.begin(), std::find_if(late.samples.begin(), late.samples.end(),
                                                        [](const HapticSample& x) { return x.travel >= 0.0958; }));
  const auto d = measure_discrepancy({late}, {sim});
  const auto& r = d.by_height[static_cast<int>(ArmHeight::High)];
  ASSERT_GE(r.size(), 12u);
  for (int j = 0; j <= 8; ++j) EXPECT_EQ(r[static_cast<std::size_t>(j)][0], 0.0) << "grid point " << j;  // to 0.09 m
  for (int j : {9, 10, 11}) EXPECT_NEAR(r[static_cast<std::size_t>(j)][0], 1.0, 1e-12) << "grid point " << j;
}

// The pairs are those of time, not of travel: a recording stamped as the study's are, with the
// constant-speed profile's travel (v t, 5 mm ahead of the ramped pull at 0.1 m/s once the ramp is
// over: core/haptic.h), made as the ramped simulated curve plus 0.2 N, gives 0.2 N at every grid
// point. Windows of equal travel would set each simulated mean against the measured one 5 mm
// further on, and the drag's slope would show in the term.
TEST(Discrepancy, PairsAreMomentsOfThePullNotEqualTravels) {
  // The stand-in's curve with its travel put on the rig's ramp.
  SimulatedTrial sim = simulated_curve(ArmHeight::High);
  HapticSequence measured = measured_from(sim, ArmHeight::High, [](double) { return std::array<double, 3>{0.2, 0.2, 0.2}; });
  for (std::size_t i = 0; i < sim.samples.size(); ++i) {
    const double t = sim.samples[i].t;
    sim.samples[i].travel = testing::rig_travel_at(t, 0.1);
    measured.samples[i].travel = 0.1 * t;
  }
  const auto d = measure_discrepancy({measured}, {sim});
  const auto& r = d.by_height[static_cast<int>(ArmHeight::High)];
  ASSERT_GE(r.size(), 40u);
  for (std::size_t j = 0; j < r.size(); ++j)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(r[j][k], 0.2, 1e-12) << "grid point " << j << ", force " << k;
}

TEST(Discrepancy, AddedToTheSimulatedCurveGivesTheMeasuredOne) {
  // A constant difference per force: exact at every sample, whatever the windows hold.
  const auto sim = simulated_curve(ArmHeight::Low);
  auto g = [](double) { return std::array<double, 3>{-0.4, 0.1, 0.25}; };
  const HapticSequence measured = measured_from(sim, ArmHeight::Low, g);
  const auto d = measure_discrepancy({measured}, {sim});
  HapticSequence corrected;
  corrected.height = ArmHeight::Low;
  corrected.samples = sim.samples;
  apply_discrepancy(d, corrected);
  // To the end of both curves: the last grid point's value holds up to it.
  EXPECT_EQ(d.end[static_cast<int>(ArmHeight::Low)], sim.samples.back().travel);
  for (std::size_t i = 0; i < sim.samples.size(); ++i) {
    EXPECT_NEAR(corrected.samples[i].f_motion, measured.samples[i].f_motion, 1e-12);
    EXPECT_NEAR(corrected.samples[i].f_lateral, measured.samples[i].f_lateral, 1e-12);
    EXPECT_NEAR(corrected.samples[i].f_vertical, measured.samples[i].f_vertical, 1e-12);
  }
}

TEST(Discrepancy, InterpolatesBetweenGridPointsAndFadesBeyondTheLast) {
  Discrepancy d;  // step 1 cm, fade 5 cm
  d.by_height[0] = {{0.0, 0.0, 0.0}, {1.0, -2.0, 4.0}, {3.0, -2.0, 0.0}};
  auto at = [&](double x) { return discrepancy_at(d, ArmHeight::High, x); };
  EXPECT_NEAR(at(0.015)[0], 2.0, 1e-12);        // halfway between 1 and 3
  EXPECT_NEAR(at(0.0025)[2], 1.0, 1e-12);       // a quarter of the way from 0 to 4
  EXPECT_NEAR(at(-0.01)[1], 0.0, 1e-12);        // before 0: the first value
  EXPECT_NEAR(at(0.02 + 0.025)[0], 1.5, 1e-12);  // half the fade: half the last value
  EXPECT_NEAR(at(0.02 + 0.05)[0], 0.0, 1e-12);   // the fade's end and beyond: nothing
  EXPECT_NEAR(at(0.5)[1], 0.0, 1e-12);
  // Curves that went on to 0.03 m: the last value holds to there, the fade starts there.
  d.end[0] = 0.03;
  EXPECT_NEAR(at(0.028)[0], 3.0, 1e-12);
  EXPECT_NEAR(at(0.03 + 0.025)[0], 1.5, 1e-12);
}

TEST(Discrepancy, AHeightWithoutItsOwnInputTakesTheMeanOfTheOthers) {
  Discrepancy d;
  d.by_height[static_cast<int>(ArmHeight::High)] = {{1.0, 2.0, 3.0}, {1.0, 2.0, 3.0}};
  d.by_height[static_cast<int>(ArmHeight::Low)] = {{-3.0, 0.0, 1.0}, {-3.0, 0.0, 1.0}};
  const auto m = discrepancy_at(d, ArmHeight::Middle, 0.005);
  EXPECT_NEAR(m[0], -1.0, 1e-12);
  EXPECT_NEAR(m[1], 1.0, 1e-12);
  EXPECT_NEAR(m[2], 2.0, 1e-12);
  // No input at all: no correction.
  EXPECT_EQ(discrepancy_at(Discrepancy{}, ArmHeight::Middle, 0.1), (std::array<double, 3>{}));
}

TEST(Discrepancy, BadInputNamesWhatIsWrong) {
  const auto sim = simulated_curve(ArmHeight::High);
  EXPECT_THROW(measure_discrepancy({}, {sim}), std::invalid_argument);
  DiscrepancyOptions zero;
  zero.window = 0;
  EXPECT_THROW(measure_discrepancy({}, {}, zero), std::invalid_argument);
  Calibration cal;
  cal.participant = "4";
  try {
    calibration_inputs(cal, "cal4.json", Dataset{}, "study/manifest.csv");
    FAIL() << "no error for a calibration without sequences";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cal4.json: records no calibrated sequence"), std::string::npos) << e.what();
  }
  cal.fits.push_back({"s4-good-3", ArmHeight::High, 0.1, 0.2, {}, {}, {}});
  Dataset ds;
  ds.trials.push_back(HapticSequence{"s4-miss-2", "4", ArmHeight::Low, 0.1, Outcome::Missed, {}});
  try {
    calibration_inputs(cal, "cal4.json", ds, "study/manifest.csv");
    FAIL() << "no error for an input the dataset does not hold";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("study/manifest.csv"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'s4-good-3'"), std::string::npos) << e.what();
  }
  ds.trials.push_back(HapticSequence{"s4-good-3", "4", ArmHeight::High, 0.1, Outcome::Good, {}});
  const auto inputs = calibration_inputs(cal, "cal4.json", ds, "study/manifest.csv");
  ASSERT_EQ(inputs.size(), 1u);
  EXPECT_EQ(inputs[0].id, "s4-good-3");
}

TEST(Discrepancy, CsvHasOneRowPerGridPointOfEachCalibration) {
  Discrepancy d;
  d.by_height[static_cast<int>(ArmHeight::High)] = {{1.0, 2.0, 3.0}, {0.5, 0.25, -1.0}};
  d.by_height[static_cast<int>(ArmHeight::Low)] = {{-3.0, 0.0, 1.0}};
  const std::string csv = discrepancy_csv({{"cal4.json", d}});
  EXPECT_EQ(csv,
            "calibration,height,travel,r_motion,r_lateral,r_vertical\n"
            "cal4.json,high,0.000,1.000000,2.000000,3.000000\n"
            "cal4.json,high,0.010,0.500000,0.250000,-1.000000\n"
            "cal4.json,low,0.000,-3.000000,0.000000,1.000000\n");
}

}  // namespace
}  // namespace dressguard::calib
