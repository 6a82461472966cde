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

// What a hand-written file gets wrong, named for what it is: a decimal comma ('friction 0,3' is
// two records, 'friction 0' and '3', and was refused as "parameter '3' has no value"), a UTF-8
// byte-order mark (an invisible character made the first name unknown), and a leading '+'
// (refused as "not a number").
TEST(SimParams, DecimalCommaByteOrderMarkAndPlusSign) {
  std::string e = error_of("stretch 0.8\nfriction 0,3\n");
  EXPECT_NE(e.find("p.txt:2: '0,3': a comma separates parameters; use '.' for decimals (0.3)"), std::string::npos)
      << e;
  e = error_of("{\"bend\": 0,5}\n");  // the same in flat JSON
  EXPECT_NE(e.find("p.txt:1: '0,5': a comma separates parameters; use '.' for decimals (0.5)"), std::string::npos)
      << e;
  e = error_of("friction 0.3\n7\n");  // a number alone on its line: no comma to blame
  EXPECT_NE(e.find("p.txt:2: '7' is a number where a parameter's name goes"), std::string::npos) << e;
  e = error_of("friction\n");  // a name without a value is still said so
  EXPECT_NE(e.find("p.txt:1: parameter 'friction' has no value"), std::string::npos) << e;
  const std::string bom = "\xEF\xBB\xBF" "friction 0.3\nbend 0.4\n";
  EXPECT_EQ(error_of(bom), "");
  if (error_of(bom).empty()) {
    EXPECT_EQ(parse_params(bom, "p.txt").friction, 0.3);
    EXPECT_EQ(parse_params(bom, "p.txt").bend, 0.4);
  }
  const std::string plus = "friction +0.3\narm_lateral +0.05\n";
  EXPECT_EQ(error_of(plus), "");
  if (error_of(plus).empty()) {
    EXPECT_EQ(parse_params(plus, "p.txt").friction, 0.3);
    EXPECT_EQ(parse_params(plus, "p.txt").arm_lateral, 0.05);
  }
  for (const char* bad : {"friction +-0.3\n", "friction ++0.3\n", "friction +\n"}) {
    e = error_of(bad);
    EXPECT_NE(e.find("is not a number"), std::string::npos) << bad << ": " << e;
  }
}
