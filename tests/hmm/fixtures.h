// Known HMMs and datasets synthesized from them, shared by the HMM, filter and CLI tests.
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "dataset.h"
#include "dgm.h"
#include "hmm.h"

namespace dressguard::fx {

// A left-right HMM with n states: state j has its mean on a smooth curve that progresses with j
// (as a force profile progresses with travel; neighbours >= 5 standard deviations apart), covariance [[0.30 0.08][0.08 0.20]] scaled by `spread`, stay probability `stay`
// (mean dwell 1/(1-stay) samples), the last state absorbing. `phase` makes different classes.
inline model::ClassHmm known_left_right(int n, double stay, double phase = 0.0, double spread = 1.0, int band = 1) {
  model::ClassHmm h = model::left_right_chain(n, stay, band);
  h.name = "class";
  for (int j = 0; j < n; ++j) {
    model::GaussianEmission e;
    e.mean[0] = 3.0 * j - 1.5 * n + phase;
    e.mean[1] = 1.5 * std::sin(0.9 * j + 2.0 * phase);
    e.cov[0][0] = 0.30 * spread;
    e.cov[0][1] = e.cov[1][0] = 0.08 * spread;
    e.cov[1][1] = 0.20 * spread;
    h.emission.push_back(e);
  }
  return h;
}

// `count` sequences of random length in [min_len, max_len] drawn from h, deterministic for `seed`.
inline std::vector<hmm::FeatureSequence> draw(const model::ClassHmm& h, int count, size_t min_len, size_t max_len,
                                              uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<hmm::FeatureSequence> out;
  for (int i = 0; i < count; ++i) {
    const size_t T = min_len + rng() % (max_len - min_len + 1);
    out.push_back(hmm::sample(h, T, rng));
  }
  return out;
}

// Three outcome classes from three different known HMMs, as a dataset in raw newtons:
// f_motion = 2 x0 - 3 (drag), f_vertical = 0.5 x1 + 1, f_lateral = noise the model must ignore.
// Travel advances 1 mm per sample (0.1 m/s at 100 Hz).
inline Dataset synthetic_dataset(int per_class, size_t min_len, size_t max_len, uint64_t seed, int n_states = 5,
                                 const std::string& participant = "") {
  Dataset ds;
  std::mt19937_64 rng(seed);
  for (int o = 0; o < kOutcomeCount; ++o) {
    const model::ClassHmm h = known_left_right(n_states, 0.97, 0.9 * o, 1.0 + 0.5 * o);
    for (int i = 0; i < per_class; ++i) {
      const size_t T = min_len + rng() % (max_len - min_len + 1);
      const hmm::FeatureSequence f = hmm::sample(h, T, rng);
      HapticSequence s;
      s.id = std::string(outcome_name(static_cast<Outcome>(o))) + "-" + participant + "-" + std::to_string(i);
      s.participant = participant;
      s.label = static_cast<Outcome>(o);
      for (size_t t = 0; t < T; ++t) {
        HapticSample smp;
        smp.t = 0.01 * t;
        smp.travel = 0.001 * t;
        smp.f_motion = 2.0 * f.at(t)[0] - 3.0;
        smp.f_vertical = 0.5 * f.at(t)[1] + 1.0;
        smp.f_lateral = static_cast<double>(rng() % 1000) / 100.0 - 5.0;
        s.samples.push_back(smp);
      }
      ds.trials.push_back(std::move(s));
    }
  }
  return ds;
}

inline std::vector<const HapticSequence*> pointers(const Dataset& ds) {
  std::vector<const HapticSequence*> v;
  for (const auto& t : ds.trials) v.push_back(&t);
  return v;
}

}  // namespace dressguard::fx
