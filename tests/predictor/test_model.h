// Small outcome models built in code for the predictor's tests (no trained file needed), and a
// frame source that plays the bridge and the robot.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "dg_protocol.h"
#include "dgm.h"

namespace dressguard::testkit {

// Three one-state-per-phase left-right classes in raw newtons (identity feature convention):
// "good" drags lightly (-2 N), "missed" barely (-1 N, vertical -0.5 N), "caught" hard (-6 N,
// vertical -1 N). Unit covariances: a sample at -6 N gives caught a likelihood ratio of e^8 over
// good, so the posterior crosses 0.9 within a few samples.
inline model::ClassHmm test_class(const std::string& name, double m0, double m1, int states = 2) {
  model::ClassHmm c = model::left_right_chain(states, 0.9);
  c.name = name;
  for (int i = 0; i < states; ++i) {
    model::GaussianEmission e;
    e.mean[0] = m0;
    e.mean[1] = m1;
    c.emission.push_back(e);
  }
  c.log_prior = std::log(1.0 / 3.0);
  return c;
}

inline model::OutcomeModel test_model() {
  model::OutcomeModel m;
  m.tool_version = "test";
  m.created = "2026-11-21T00:00:00Z";
  m.source_dataset = "built in code";
  m.classes = {test_class("good", -2.0, 0.0), test_class("missed", -1.0, -0.5), test_class("caught", -6.0, -1.0)};
  m.stop_threshold = 0.9;
  m.stop_consecutive = 3;
  return m;
}

// Plays the sensor bridge and the robot: frames with running alive counters.
struct FrameSource {
  uint8_t sample_counter = 0, start_counter = 0, end_counter = 0;
  protocol::Frame trial_start(uint16_t trial, uint16_t speed_mm_s = 100) {
    return protocol::encode(protocol::TrialStart{start_counter++, trial, speed_mm_s, protocol::HeightClass::Middle});
  }
  protocol::Frame trial_end(uint16_t trial, uint16_t samples) {
    return protocol::encode(protocol::TrialEnd{end_counter++, trial, samples, protocol::TrialEndReason::Completed});
  }
  // Rig axes with the identity mount: motion = x, lateral = y, vertical = z.
  protocol::Frame force(double f_motion, double f_vertical, double f_lateral = 0.0) {
    using protocol::kForceCountsPerNewton;
    using protocol::to_counts;
    return protocol::encode(protocol::FtForce{sample_counter, to_counts(f_motion, kForceCountsPerNewton),
                                              to_counts(f_lateral, kForceCountsPerNewton),
                                              to_counts(f_vertical, kForceCountsPerNewton)});
  }
  protocol::Frame torque() { return protocol::encode(protocol::FtTorque{sample_counter, 0, 0, 0}); }
  void next() { ++sample_counter; }
};

}  // namespace dressguard::testkit
