// The params file reader (sim/params.h): what it refuses, and that its errors name the file and
// the line.
#include <gtest/gtest.h>

#include <string>

#include "files.h"
#include "params.h"

using namespace dressguard;
using namespace dressguard::sim;

namespace {

// The InputError message parse_params gives `text`, or "" when it takes it.
std::string error_of(const std::string& text) {
  try {
    parse_params(text, "p.txt");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SimParams, NegativeDampingIsRefused) {
  const std::string e = error_of("damping -50\n");
  EXPECT_NE(e.find("damping must not be negative"), std::string::npos) << e;
  EXPECT_EQ(parse_params("damping 0\n", "p.txt").damping, 0.0);  // no damping is a damping
}

// A parameter given twice is named with both lines (the second silently won); a value out of
// range is named at its line.
TEST(SimParams, RepeatedKeyAndRangeErrorsNameTheirLines) {
  std::string e = error_of("bend 0.5\nstretch 0.9\n\nbend 0.9\n");
  EXPECT_NE(e.find("p.txt:4: parameter 'bend' given again (first on line 1)"), std::string::npos) << e;
  e = error_of("{\"bend\": 0.5,\n \"friction\": 0.3, \"bend\": 0.6}\n");  // flat JSON, a repeat on line 2
  EXPECT_NE(e.find("p.txt:2: parameter 'bend' given again (first on line 1)"), std::string::npos) << e;
  e = error_of("# a comment\nfriction 0.3\nstretch 1.5\n");
  EXPECT_NE(e.find("p.txt:3: stretch must be within [0, 1]"), std::string::npos) << e;
  e = error_of("bend 0.5\n\nsupport_lateral -0.5\n");
  EXPECT_NE(e.find("p.txt:3: support_lateral must be within"), std::string::npos) << e;
}

// areal_density and arm_compliance are held to the calibration file's limits (core/
// person_limits.h): 145 (g/m^2 by mistake) and 1000 m/N were taken.
TEST(SimParams, DensityAndComplianceWithinTheCalibrationsLimits) {
  std::string e = error_of("areal_density 145\n");
  EXPECT_NE(e.find("areal_density must be within 0.01 and 1 kg/m^2"), std::string::npos) << e;
  e = error_of("areal_density 0.005\n");
  EXPECT_NE(e.find("areal_density must be within"), std::string::npos) << e;
  e = error_of("arm_compliance 1000\n");
  EXPECT_NE(e.find("arm_compliance cannot be negative (0 is a fixed arm) nor above 1 m/N"), std::string::npos) << e;
  const ClothParams p = parse_params("areal_density 1\narm_compliance 1\n", "p.txt");  // the limits themselves
  EXPECT_EQ(p.areal_density, 1.0);
  EXPECT_EQ(p.arm_compliance, 1.0);
}
