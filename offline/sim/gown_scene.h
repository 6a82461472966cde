// Scenes from the gown module's mesh (offline/gown): the measured gown (shared/data) or the
// gown module's parametric gown, placed like the paper's public simulator (placement.h).
#pragma once

#include "gown.h"
#include "placement.h"
#include "trial.h"

namespace dressguard::sim {

// The scene of `mesh` with the gripper, jaws and arm of `paper`: the grasp point is the upper
// jaw's centre, the grasped vertices are gown::grasp_vertices(), the sleeve opening is the
// mesh's labelled sleeve loop, and the arm spheres sit where `paper` puts them (fist, wrist,
// elbow, shoulder; High height; the other heights by paper.arm_offset_middle/low).
// `base` supplies the solver options (substeps, contact offset, self-collision distance).
Scene make_scene(const gown::GownMesh& mesh, const gown::PaperScene& paper = {}, SceneOptions base = {});

// make_default_scene (trial.h) with the jaws holding the sleeve as `grip` says (placement.h).
Scene make_default_scene(GownResolution res, bool parametric, const gown::OpeningGrip& grip);

// The gown's triangle count for each GownResolution: Full 0 (no reduction, ~20k), Reduced
// 5000, Coarse 1500.
int target_triangles(GownResolution res);

}  // namespace dressguard::sim
