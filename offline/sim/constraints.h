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

// Stretch along a mesh edge, a distance constraint:
//   C = |x_i - x_j| - L,   grad_i C = n = (x_i - x_j) / |x_i - x_j|,   grad_j C = -n,
//   dlambda = -C / (w_i + w_j + alpha),
// with compliance alpha_t in tension and alpha_c (softer) in compression: woven fabric buckles
// under almost no compressive load, so a sleeve tube must not stand up like a straw (PhysX's
// cloth has a separate, soft compression stiffness for the same reason). The two inverse
// denominators are constant per trial and come precomputed (inv_t, inv_c; 0 when both vertices
// are fixed). Writes n (the gradient on i); returns dlambda (0 if degenerate).
// Mirrored over 4 lanes by stretch_kernel() (solver_avx2.cpp), operation for operation.
inline double distance_constraint(V3& xi, V3& xj, double wi, double wj, double rest, double inv_t, double inv_c,
                                  V3* n_out) {
  const V3 d = xi - xj;
  const double len = std::sqrt(dot(d, d));
  if (len < 1e-12) {
    *n_out = {0, 0, 0};
    return 0;
  }
  const double inv_len = 1.0 / len;
  const V3 n = inv_len * d;
  const double dl = (rest - len) * (len < rest ? inv_c : inv_t);
  xi += (wi * dl) * n;
  xj -= (wj * dl) * n;
  *n_out = n;
  return dl;
}

// In-plane shear of one triangle (strain based, Mueller et al. 2014 "Strain based dynamics"):
// with the rest frame (e1 along the first edge, e2 normal to it in the plane) and
// Dm^-1 = [[a, b], [c, d]], the deformation gradient's columns are
//   f1 = (x1 - x0) a + (x2 - x0) c,   f2 = (x1 - x0) b + (x2 - x0) d,
// and the shear strain  C = f1 . f2  (0 at rest: the frame's axes stay perpendicular), with
//   grad_1 C = a f2 + b f1,  grad_2 C = c f2 + d f1,  grad_0 C = -(grad_1 C + grad_2 C).
// Energy (1/2) C^2 / alpha per triangle, alpha = 1 / (G A) for shear modulus G [N/m]: the caller
// passes alpha_t = alpha_shear / (A h^2). Purely in-plane: it neither resists bending nor
// remembers a curved rest shape (a cross-edge distance would do both).
// Mirrored over 4 lanes by shear_kernel() (solver_avx2.cpp), operation for operation. Always
// inlined: out of line, the caller's gradient array had to be zeroed first (V3 has initialisers)
// and that zeroing took a quarter of the scalar solver's time.
[[gnu::always_inline]] inline double shear_constraint(V3& x0, V3& x1, V3& x2, double w0, double w1, double w2, const double dm_inv[4],
                               double alpha_t, V3 g_out[3]) {
  const double a = dm_inv[0], b = dm_inv[1], c = dm_inv[2], d = dm_inv[3];
  const V3 e1 = x1 - x0, e2 = x2 - x0;
  const V3 f1 = a * e1 + c * e2, f2 = b * e1 + d * e2;
  const double C = dot(f1, f2);
  const V3 g1 = a * f2 + b * f1, g2 = c * f2 + d * f1;
  const V3 g0 = (-1.0) * (g1 + g2);
  const double denom = w0 * dot(g0, g0) + w1 * dot(g1, g1) + w2 * dot(g2, g2) + alpha_t;
  if (denom <= 1e-300) return 0;
  const double dl = -C / denom;
  x0 += (w0 * dl) * g0;
  x1 += (w1 * dl) * g1;
  x2 += (w2 * dl) * g2;
  g_out[0] = g0;
  g_out[1] = g1;
  g_out[2] = g2;
  return dl;
}

// Isometric bending (Bergou, Wardetzky, Harmon, Zorin, Grinspun 2006, "A quadratic bending
// model for inextensible surfaces"): for the edge (x0, x1) with opposite vertices x2, x3 the
// discrete mean-curvature vector is  K x = sum_i k_i x_i,  k = (c03 + c04, c01 + c02,
// -(c01 + c03), -(c02 + c04)) with c_ab the cotangents of the rest triangles' angles, scaled by
// sqrt(3 / (A0 + A1)). Bergou's energy  E = (1/2) (1/alpha) |K x|^2  is the XPBD energy of the
// *vector* constraint
//   C = K x = 0 (3 components, linear in x),   grad_i C = k_i I,
// so one update serves all three components, with no square root and no kink at the flat state
// (the scalar |K x| has one, and its flipping direction chatters):
//   dlambda = -(K x) / (sum_i w_i k_i^2 + alpha_t),   dx_i = w_i k_i dlambda.
// alpha = 1 / bending stiffness [1/(N m)]. The rest state is flat (cloth has no rest curvature:
// a sewn sleeve is flat fabric), and K is constant, so the denominator is constant per trial:
// the caller passes wk_i = w_i k_i and neg_inv_denom = -1 / (alpha_t + sum_i w_i k_i^2).
// Returns the vector dlambda. Mirrored over 4 lanes by bend_kernel() (solver_avx2.cpp).
inline V3 bending_constraint(V3& x0, V3& x1, V3& x2, V3& x3, const double k[4], const double wk[4],
                             double neg_inv_denom) {
  const V3 kx = k[0] * x0 + k[1] * x1 + k[2] * x2 + k[3] * x3;
  const V3 dl = neg_inv_denom * kx;
  x0 += wk[0] * dl;
  x1 += wk[1] * dl;
  x2 += wk[2] * dl;
  x3 += wk[3] * dl;
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
