// Small parametric cloth meshes for the simulator's tests: a flat patch (or strip) and a tube.
// The gowns come from the gown module (offline/gown): the measured gown, or without shared/data
// its parametric gown (gown::make_parametric_gown); make_default_scene() uses one of those.
#pragma once

#include "trial.h"

namespace dressguard::sim {

// A flat rectangular grid: origin o, edge vectors a (nu-1 cells) and b (nv-1 cells), vertex
// (iu, iv) at index iv * nu + iu; alternating diagonals so the patch has no preferred shear.
ClothMesh grid_patch(std::array<double, 3> o, std::array<double, 3> a, std::array<double, 3> b, int nu, int nv);

// A tube of radius r around the x axis from x = x0 to x = x1, nu vertices around and nv along;
// vertex (iu, iv) at index iv * nu + iu, angle 2 pi iu / nu from +y toward +z.
ClothMesh tube(double r, double x0, double x1, int nu, int nv);

}  // namespace dressguard::sim
