// The person's arm as a held, compliant body: how far the arm gives under the cloth's pull.
//
// The paper's simulator (and ours by default) holds the arm fixed. A seated person holding the
// arm out is not a fixed collider: the hand's postural stiffness is a few hundred N/m
// (Mussa-Ivaldi, Hogan and Bizzi 1985 measured about 300-800 N/m at the hand), so the 10 N at the
// end of a good trial moves the arm by centimetres, and the gripper travels that much further
// before the rig's force limit. Model: the arm translates rigidly (no rotation) as a mass on an
// isotropic, critically damped spring about its pose at the start of the pull,
//     M d'' + c d' + k d = F(t) - F0,    k = 1 / compliance,  c = 2 sqrt(k M),
// driven by the cloth's contact force on it, F (the sum of the contact forces of eq. 2), less its
// load at the start of the pull, F0 (the person holds the arm where it is against the settled
// gown, as the sensor bias is removed: the calibrated arm height stays the height at the start).
//
// Stepping: F is held constant over a step of h (the trial passes one 100 Hz sample's mean
// force, so the arm lags the cloth by one sample, 10 ms, against its own ~0.5 s response). With
// F constant the critically damped equation has the exact solution, with w = sqrt(k / M) and
// e = d - (F - F0) / k the distance from the force's equilibrium,
//     e(t) = (e0 + (u0 + w e0) t) exp(-w t),
//     u(t) = (u0 - w (u0 + w e0) t) exp(-w t),
// used here: no overshoot and no step-size limit of its own (only the explicit coupling with the
// cloth, whose contact stiffness the 2 kg arm sees at h = 10 ms: stable while w_c h < 2).
#pragma once

#include <cmath>

#include "model.h"

namespace dressguard::sim {

struct ArmSpring {
  double compliance = 0;  // [m/N] 1 / k; 0: a rigid (fixed) arm, the paper's
  double mass = 2.0;      // [kg] forearm and hand (about 2.2 % of body mass, Winter's tables)
  V3 d{0, 0, 0};          // [m] displacement from the pose at the start of the pull
  V3 u{0, 0, 0};          // [m/s] its velocity

  bool rigid() const { return compliance <= 0; }

  // Advances by h [s] under the force `load` [N] (F - F0), held constant over the step.
  void advance(V3 load, double h) {
    if (rigid()) return;
    const double w = std::sqrt(1.0 / (compliance * mass));
    const V3 e0 = d - compliance * load;
    const V3 a = u + w * e0;
    const double decay = std::exp(-w * h);
    d = compliance * load + decay * (e0 + h * a);
    u = decay * (u - (w * h) * a);
  }
};

}  // namespace dressguard::sim
