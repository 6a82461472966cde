// Trials of the simulator: determinism, stability at the 10 N stop, the outcomes.
#include <gtest/gtest.h>

#include <cstring>

#include "model.h"
#include "trial.h"

using namespace dressguard;
using namespace dressguard::sim;

// Same inputs, same bits (single thread, no fast-math, fixed orders everywhere).
TEST(SimTrial, DeterministicBits) {
  const Scene scene = make_default_scene(GownResolution::Coarse);
  TrialSpec spec;
  spec.gown_noise = true;
  spec.seed = 7;
  spec.max_travel = 0.05;
  const TrialResult a = simulate_trial(scene, ClothParams{}, spec);
  const TrialResult b = simulate_trial(scene, ClothParams{}, spec);
  ASSERT_EQ(a.seq.samples.size(), b.seq.samples.size());
  ASSERT_FALSE(a.seq.samples.empty());
  EXPECT_EQ(0, std::memcmp(a.seq.samples.data(), b.seq.samples.data(), a.seq.samples.size() * sizeof(HapticSample)));
  spec.seed = 8;
  const TrialResult c = simulate_trial(scene, ClothParams{}, spec);
  EXPECT_NE(a.seq.samples.back().f_motion, c.seq.samples.back().f_motion) << "the seed must matter";
}
