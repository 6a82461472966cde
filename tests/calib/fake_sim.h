// A cheap analytic stand-in for the cloth simulator, for unit tests of the calibration and
// synthesis drivers only (the real simulator is tested with them in sim_calibration_test.cpp).
//
// It has the shape of a sleeve pull: the drag grows with travel at a rate set by friction and
// stretch, with a bump set by shear; the vertical force's slope depends on the arm height and its
// offset (bend and self-friction shift it); a compliant arm (arm_compliance) gives way, so the
// drag grows over a longer travel; a fist further along the arm (fist_shift) starts the drag that
// much later; the rim meets the fist at 0.15 m of travel plus fist_shift minus rim_shift (the
// rim held further ahead of the jaws meets it earlier), a 0.5 N bump of drag there; a gown
// heavier than the paper's hangs more on the forearm from 0.3 m of travel on (areal_density, a
// kink in the vertical force that no polynomial term of the others makes); the lateral force
// grows with travel by the arm's height and turns with the arm and the fist sideways
// (arm_lateral, fist_lateral) over the first 0.3 m; the pull stops at 10 N or 0.85 m like the rig.
// Every
// parameter changes the curves, so a calibration against curves made at known parameters must
// find a near-zero objective. The gown noise adds a seeded, smooth disturbance. Deterministic
// and thread-safe (no state).
#pragma once

#include <algorithm>
#include <cmath>

#include "calibration.h"

namespace dressguard::calib::testing {

inline SimulatedTrial fake_simulate(const ClothValues& c, const TrialRequest& r) {
  SimulatedTrial out;
  const double h = r.height == ArmHeight::High ? 0.0 : (r.height == ArmHeight::Middle ? -0.123 : -0.205);
  const double arm = h + r.arm_offset;  // [m] relative to the high setting
  const double noise_amp = r.gown_noise ? 0.3 * static_cast<double>(mix_seed(r.seed, 7) >> 11) * 0x1.0p-53 : 0.0;
  const double catchiness = std::max(0.0, 1.0 + 6.0 * arm);  // high arm: the sleeve tightens on the elbow
  for (int i = 0;; ++i) {
    const double t = i * 0.01;
    const double x = std::min(r.speed * t, r.max_travel);
    const double xa = std::max(0.0, x - c.fist_shift) / (1.0 + 40.0 * c.arm_compliance);  // the travel the cloth feels
    const double drag = (1.5 * c.friction + 2.0 * c.stretch) * xa * (1.0 + 12.0 * catchiness * xa * xa) +
                        0.6 * c.shear * std::sin(6.0 * x) + noise_amp * std::sin(20.0 * x + r.seed % 7) +
                        0.5 * std::exp(-std::pow((x - (0.15 + c.fist_shift - c.rim_shift)) / 0.03, 2));
    const double heavier = (c.areal_density - kPaperArealDensity) / kPaperArealDensity;  // 0 for the paper's gown
    const double vert = (0.5 + 10.0 * arm) * x * (0.5 + c.bend) - 0.8 * c.self_friction * x * x -
                        8.0 * heavier * std::max(0.0, x - 0.3);
    const double lateral = 0.1 * (1.0 + 4.0 * arm) * x - 2.0 * (c.arm_lateral + c.fist_lateral) * std::min(x, 0.3);
    out.samples.push_back({t, x, -drag, lateral, vert});
    if (drag >= 10.0 || std::abs(vert) >= 10.0) {
      out.outcome = arm > -0.05 ? Outcome::Good : Outcome::Caught;
      // The label's evidence as the simulator gives it: a caught sleeve stays on the forearm.
      out.d_behind = arm > -0.05 ? 0.03 : 0.12;
      out.d_ahead = 0.0;
      break;
    }
    if (x >= r.max_travel) {
      out.outcome = Outcome::Missed;
      out.d_behind = out.d_ahead = 0.0;
      break;
    }
    // The watch stops a pull as the cloth simulator's does (sim::TrialSpec::pull_watch), and
    // its rest is the trial without the watch (sim::resume_trial's contract; here simulated
    // again, having no state to go on from), charged with the time after the cut alone.
    if (r.watch && r.watch(out.samples, false)) {
      out.cut = true;
      out.simulated_s = 0.01 * static_cast<double>(out.samples.size());
      TrialRequest plain = r;
      plain.watch = nullptr;
      out.rest = [c, plain, done = out.simulated_s] {
        SimulatedTrial whole = fake_simulate(c, plain);
        whole.simulated_s -= done;
        return whole;
      };
      return out;
    }
  }
  if (r.watch) r.watch(out.samples, true);
  out.simulated_s = 0.01 * static_cast<double>(out.samples.size());  // its sample period
  return out;
}

// [m] where the rig's gripper is `t` [s] into a pull from rest at `v` [m/s] (core/haptic.h):
// a t^2 / 2 on the 1 m/s^2 ramp, v t - v^2 / 2a after it (pull_time_at's inverse). The simulator's
// travel; the study's recordings stamp v t instead.
inline double rig_travel_at(double t, double v) {
  const double a = kRigAcceleration;
  return t <= v / a ? 0.5 * a * t * t : v * t - v * v / (2 * a);
}

}  // namespace dressguard::calib::testing
