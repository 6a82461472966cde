// One small stateless function per constraint (XPBD, Macklin, Mueller, Chentanez 2016).
//
// Each takes positions, inverse masses w and the time-scaled compliance alpha_t = alpha / h^2,
// applies its corrections in place and returns the Lagrange multiplier increment dlambda. With
// "small steps" (Macklin et al. 2019) every substep solves each constraint once starting from
// lambda = 0, so the XPBD update
//     dlambda = (-C - alpha_t lambda) / (sum_i w_i |grad_i C|^2 + alpha_t),  dx_i = w_i grad_i C dlambda
// is used with lambda = 0, and dlambda is the substep's multiplier. The force the constraint
// exerts on vertex i is f_i = grad_i C * lambda / h^2 (XPBD eq. 17), which is how the gripper's
// force is read off the constraints that touch grasped (kinematic, w = 0) vertices.
#pragma once

#include "model.h"

namespace dressguard::sim {

// Distance (stretch along mesh edges, shear across the edge of two triangles):
//   C = |x_i - x_j| - L,   grad_i C = n = (x_i - x_j) / |x_i - x_j|,   grad_j C = -n.
// Writes n (the gradient on i); returns dlambda (0 if degenerate or both vertices fixed).
inline double distance_constraint(V3& xi, V3& xj, double wi, double wj, double rest, double alpha_t, V3* n_out) {
  const V3 d = xi - xj;
  const double len = norm(d);
  const double denom = wi + wj + alpha_t;
  if (len < 1e-12 || denom <= 0) {
    *n_out = {0, 0, 0};
    return 0;
  }
  const double inv_len = 1.0 / len;
  const V3 n = inv_len * d;
  const double dl = -(len - rest) / denom;
  xi += (wi * dl) * n;
  xj -= (wj * dl) * n;
  *n_out = n;
  return dl;
}

// Isometric bending (Bergou, Wardetzky, Harmon, Zorin, Grinspun 2006, "A quadratic bending
// model for inextensible surfaces"): for the edge (x0, x1) with opposite vertices x2, x3 the
// discrete mean-curvature vector is  K x = sum_i k_i x_i,  k = (c03 + c04, c01 + c02,
// -(c01 + c03), -(c02 + c04)) with c_ab the cotangents of the rest triangles' angles, scaled by
// sqrt(3 / (A0 + A1)). Bergou's energy  E = (1/2) (1/alpha) |K x|^2  is XPBD's energy of
//   C = |K x|,  grad_i C = k_i n,  n = K x / |K x|
// with compliance alpha = 1 / bending stiffness [1/(N m)]. The rest state is flat (cloth has no
// rest curvature: a sewn sleeve is flat fabric), and K is constant, so the constraint costs one
// weighted sum. C vanishes on a flat or cylindrically bent-free stencil; skip when |K x| ~ 0.
inline double bending_constraint(V3& x0, V3& x1, V3& x2, V3& x3, const double w[4], const double k[4],
                                 double alpha_t, V3* n_out) {
  const V3 kx = k[0] * x0 + k[1] * x1 + k[2] * x2 + k[3] * x3;
  const double c2 = dot(kx, kx);
  if (c2 < 1e-24) return 0;
  const double c = std::sqrt(c2);
  const double denom = alpha_t + w[0] * k[0] * k[0] + w[1] * k[1] * k[1] + w[2] * k[2] * k[2] + w[3] * k[3] * k[3];
  const V3 n = (1.0 / c) * kx;
  const double dl = -c / denom;
  x0 += (w[0] * k[0] * dl) * n;
  x1 += (w[1] * k[1] * dl) * n;
  x2 += (w[2] * k[2] * dl) * n;
  x3 += (w[3] * k[3] * dl) * n;
  *n_out = n;
  return dl;
}

// Contact with a static collider (arm or plane), a one-sided constraint:
//   C = phi(x) - offset >= 0,  grad C = n (collider normal),  dx = -min(C, 0) n.
// Returns the normal correction depth (>= 0).
inline double contact_constraint(V3& x, double phi, V3 n, double offset) {
  const double c = phi - offset;
  if (c >= 0) return 0;
  x -= c * n;
  return -c;
}

// Position-level Coulomb friction for one contact against a static collider (paper IV-A.2,
// the "improved" scheme; also Macklin et al. 2014 eq. 24): the tangential displacement made
// during this substep, u_t = ((x - p) - ((x - p).n) n), is removed up to the friction cone
// mu * dn, where dn is the substep's normal correction:
//   dx = -u_t * min(1, mu dn / |u_t|).
// Returns the correction applied.
inline V3 friction_position(V3& x, V3 p, V3 n, double dn, double mu) {
  const V3 u = x - p;
  const V3 ut = u - dot(u, n) * n;
  const double lt = norm(ut);
  if (lt < 1e-15) return {0, 0, 0};
  const double s = std::min(1.0, mu * dn / lt);
  const V3 dx = (-s) * ut;
  x += dx;
  return dx;
}

// Static friction as a positional constraint with memory (Constraint scheme, Macklin 2014 and
// Mueller et al. 2020): the contact sticks to its anchor a (where it first touched) while the
// tangential correction needed to return there, |(x - a)_t|, stays within mu_s * dn; beyond it,
// the contact slides with the dynamic bound mu_k * dn and the anchor follows it.
//   C_t = (x - a)_t,  |lambda_t| <= mu lambda_n   (lambda's in position units for one vertex)
inline V3 friction_anchor(V3& x, V3& anchor, V3 n, double dn, double mu_s, double mu_k) {
  const V3 u = x - anchor;
  const V3 ut = u - dot(u, n) * n;
  const double lt = norm(ut);
  V3 dx{0, 0, 0};
  if (lt <= mu_s * dn) {
    dx = (-1.0) * ut;  // stick: back to the anchor (tangentially)
  } else if (lt > 1e-15) {
    dx = (-std::min(1.0, mu_k * dn / lt)) * ut;  // slide, the anchor follows
  }
  x += dx;
  anchor = x;
  return dx;
}

// Velocity-level friction of stock PBD (the Stock scheme): after the velocity update, the
// tangential velocity loses at most mu dn / h; the substep's position is left as it is.
inline void friction_velocity(V3& v, V3 n, double dn, double mu, double h) {
  const V3 vt = v - dot(v, n) * n;
  const double lt = norm(vt);
  if (lt < 1e-15) return;
  const double s = std::min(1.0, mu * dn / (h * lt));
  v -= s * vt;
}

}  // namespace dressguard::sim
