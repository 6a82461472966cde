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
