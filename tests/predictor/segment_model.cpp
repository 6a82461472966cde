// dg_segment_model: a test model from a labelled dataset without Baum-Welch, so the robot-side
// tests do not depend on the HMM trainer's numbers.
//
// For each class, each sequence is cut into S equal segments (the standard left-right HMM
// initialisation, and a one-pass segmental estimate): state j's Gaussian is the mean and full
// covariance of every sample in segment j of every sequence (plus a floor on the diagonal),
// its self-transition is 1 - 1/L_j with L_j the mean segment length (a geometric dwell time of
// mean L_j), and the last state absorbs. Features: F_motion and F_vertical in newtons, identity
// scaling. Priors uniform. Stop policy: the model file's fields, from the options.
//
//   dg_segment_model DATASET OUT.dgm [--states S] [--threshold P] [--consecutive K]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "dataset.h"
#include "dgm.h"

using namespace dressguard;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: dg_segment_model DATASET OUT.dgm [--states S] [--threshold P] [--consecutive K]\n");
    return 2;
  }
  int states = 10, consecutive = 10;
  double threshold = 0.95;
  for (int i = 3; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--states")) states = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--threshold")) threshold = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--consecutive")) consecutive = std::atoi(argv[i + 1]);
    else {
      std::fprintf(stderr, "dg_segment_model: unknown option %s\n", argv[i]);
      return 2;
    }
  }
  try {
    const Dataset ds = load_dataset(argv[1]);
    model::OutcomeModel m;
    m.tool_version = "dg_segment_model (tests)";
    m.created = "1970-01-01T00:00:00Z";  // fixed: the same dataset gives the same bytes
    m.source_dataset = argv[1];
    m.training_summary = "equal-segment estimate, " + std::to_string(states) + " states per class";
    m.stop_threshold = threshold;
    m.stop_consecutive = consecutive;
    for (const char* name : {"good", "missed", "caught"}) {
      model::ClassHmm c;
      c.name = name;
      c.n_states = states;
      c.initial.assign(states, 0.0);
      c.initial[0] = 1.0;
      c.transition.assign(states * states, 0.0);
      c.log_prior = std::log(1.0 / 3.0);
      std::vector<double> s0(states), s1(states), s00(states), s01(states), s11(states), n(states);
      int seqs = 0;
      for (const auto& t : ds.trials) {
        if (!t.label || outcome_name(*t.label) != name) continue;
        ++seqs;
        const size_t len = t.samples.size();
        for (size_t i = 0; i < len; ++i) {
          const int j = static_cast<int>(i * states / len);
          const double x = t.samples[i].f_motion, y = t.samples[i].f_vertical;
          s0[j] += x; s1[j] += y; s00[j] += x * x; s01[j] += x * y; s11[j] += y * y; n[j] += 1;
        }
      }
      if (seqs == 0) throw std::runtime_error(std::string("no trials labelled ") + name);
      for (int j = 0; j < states; ++j) {
        model::GaussianEmission e;
        const double mx = s0[j] / n[j], my = s1[j] / n[j];
        e.mean[0] = mx;
        e.mean[1] = my;
        // [N^2] (0.32 N): wider than the slow wobble (0.1 N) and the start-to-start spread, so
        // that the near-zero opening phase, alike in every class, does not pick a class by
        // its noise level alone.
        const double floor = 0.1;
        e.cov[0][0] = s00[j] / n[j] - mx * mx + floor;
        e.cov[1][1] = s11[j] / n[j] - my * my + floor;
        e.cov[0][1] = e.cov[1][0] = s01[j] / n[j] - mx * my;
        c.emission.push_back(e);
        const double mean_len = n[j] / seqs;
        if (j + 1 < states) {
          c.transition[j * states + j] = 1.0 - 1.0 / mean_len;
          c.transition[j * states + j + 1] = 1.0 / mean_len;
        } else {
          c.transition[j * states + j] = 1.0;
        }
      }
      m.classes.push_back(std::move(c));
    }
    model::write_model(argv[2], m);
    std::printf("wrote %s (%d states per class)\n", argv[2], states);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dg_segment_model: %s\n", e.what());
    return 1;
  }
  return 0;
}
