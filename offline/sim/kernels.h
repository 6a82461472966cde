// The constraint kernels over the solver's blocks (model.h: StretchBlock, ShearBlock, BendBlock).
// Scalar (solver.cpp): one lane at a time through the constraint functions of constraints.h.
// AVX2 (solver_avx2.cpp): 4 lanes at once, the same operations in the same order on each lane
// and no FMA (-ffp-contract=off), so both paths give the same bits; the gripper's force is summed
// lane by lane in the same order on both, by the functions below.
#pragma once

#include "model.h"

namespace dressguard::sim {

// The force of one constraint on the grasped vertices among its own (XPBD: f_i = grad_i C
// lambda / h^2), added to `force`. Shared by both paths so that the sum has one order. Without
// branches (a term times 1 or 0): which of a constraint's vertices is grasped varies at random
// from one constraint to the next, and mispredicted branches cost more than the arithmetic.
inline void stretch_force(int i, int j, double dl, V3 nrm, const uint8_t* grasped, double inv_h2, V3& force) {
  const double side = static_cast<double>(grasped[i]) - static_cast<double>(grasped[j]);  // grad_i C = n, grad_j C = -n
  force += ((dl * inv_h2) * side) * nrm;
}
inline void shear_force(const int v[3], double dl, const V3 g[3], const uint8_t* grasped, double inv_h2, V3& force) {
  const double c = dl * inv_h2;
  for (int a = 0; a < 3; ++a) force += (c * static_cast<double>(grasped[v[a]])) * g[a];
}
inline void bend_force(const int v[4], const double k[4], V3 dl, const uint8_t* grasped, double inv_h2, V3& force) {
  for (int a = 0; a < 4; ++a) force += ((k[a] * inv_h2) * static_cast<double>(grasped[v[a]])) * dl;
}

// AVX2 kernels over the blocks [b, e) of one colour group. Call only when cpu_has_avx2().
// Free blocks: full, no grasped vertex, no force.
void stretch_free_avx2(const StretchBlock* b, const StretchBlock* e, V3* x);
void shear_free_avx2(const ShearBlock* b, const ShearBlock* e, V3* x);
void bend_free_avx2(const BendBlock* b, const BendBlock* e, V3* x);
// Careful blocks: 1 to 4 lanes (an empty lane's index is -1), the force on grasped vertices added.
void stretch_careful_avx2(const StretchBlock* b, const StretchBlock* e, V3* x, const uint8_t* grasped, double inv_h2,
                          V3& force);
void shear_careful_avx2(const ShearBlock* b, const ShearBlock* e, V3* x, const uint8_t* grasped, double inv_h2,
                        V3& force);
void bend_careful_avx2(const BendBlock* b, const BendBlock* e, V3* x, const uint8_t* grasped, double inv_h2, V3& force);

// The free-vertex integration of integrate() (solver.cpp) with one register per vertex, for all
// n vertices: with `velocities` first v = inv_h (x - p); then p = x, v = decay v + h (g + w f),
// x += h v. f may be null: no external force (g + w 0 = g exactly, so the same bits).
void integrate_avx2(int n, bool velocities, double h, double inv_h, double decay, V3 g, const double* w, const V3* f,
                    V3* x, V3* p, V3* v);

}  // namespace dressguard::sim
