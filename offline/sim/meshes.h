// Small parametric cloth meshes for tests and for running without the measured gown:
// a flat patch, a strip, a tube, and the simulator's own sleeve gown (a sleeve tube that bends
// down into a flared body tube). The gown module (offline/gown) provides the measured gown and
// its own parametric gown; make_default_scene() prefers those when they are present.
#pragma once

#include "trial.h"

namespace dressguard::sim {

// A flat rectangular grid: origin o, edge vectors a (nu-1 cells) and b (nv-1 cells), vertex
// (iu, iv) at index iv * nu + iu; alternating diagonals so the patch has no preferred shear.
ClothMesh grid_patch(std::array<double, 3> o, std::array<double, 3> a, std::array<double, 3> b, int nu, int nv);

// A tube of radius r around the x axis from x = x0 to x = x1, nu vertices around and nv along;
// vertex (iu, iv) at index iv * nu + iu, angle 2 pi iu / nu from +y toward +z.
ClothMesh tube(double r, double x0, double x1, int nu, int nv);

// The simulator's sleeve gown in the trial frame (trial.h): the cuff (sleeve opening) is a ring
// of radius 0.075 m (0.47 m perimeter, as the measured gown's openings) in the plane x = 0,
// hanging from the grasp point at its top, (0, 0, 0); the sleeve runs 0.45 m toward -x, bends down
// and flares into a 0.6 m body tube of radius 0.22 m. The grasped vertices are those in the jaw
// box at the cuff's top; sleeve_opening is the cuff ring. `nu` vertices around, `nv` along.
ClothMesh sleeve_gown(int nu, int nv);

}  // namespace dressguard::sim
