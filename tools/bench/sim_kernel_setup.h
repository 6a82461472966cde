// What bench_sim_elements and bench_sim_kernels share: the `--reps N` argument and one gown's
// solver model with participant 4's paper-budget cloth (models/participant4-paper-budget.json:
// stretch 0.193, shear 0.529, bend 0.733), with the start positions every timing begins from:
// each vertex moved off its rest place by N(0, 1 mm) per coordinate (seed 1), so that every
// constraint has work to do.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include "model.h"
#include "trial.h"

namespace dressguard::bench {

// `--reps N` (default 5, at least 1) or nothing; 0 after printing the usage or the reason.
inline int parse_reps(int argc, char** argv, const char* program) {
  int reps = 5;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--reps") == 0 && i + 1 < argc) {
      reps = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: %s [--reps N]\n", program);
      return 0;
    }
  }
  if (reps < 1) {
    std::fprintf(stderr, "%s: --reps must be at least 1\n", program);
    return 0;
  }
  return reps;
}

struct KernelSetup {
  sim::Scene scene;
  sim::GownModel model;
  std::vector<sim::V3> start;
};

inline KernelSetup kernel_setup(sim::GownResolution res) {
  KernelSetup k{sim::make_default_scene(res), {}, {}};
  sim::ClothParams p;
  p.stretch = 0.19266707117227413;
  p.shear = 0.52909917993358069;
  p.bend = 0.73316639164263386;
  const sim::SceneData& s = k.scene.data();
  k.model = sim::make_model(s, p, sim::FrictionScheme::Improved, true, 0.0);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> jitter(0, 1e-3);
  k.start.resize(s.rest.size());
  for (std::size_t i = 0; i < k.start.size(); ++i) k.start[i] = s.rest[i] + sim::V3{jitter(rng), jitter(rng), jitter(rng)};
  return k;
}

}  // namespace dressguard::bench
