// The default scene (trial.h): which gown, which options.
#include "meshes.h"
#include "trial.h"

namespace dressguard::sim {

Scene make_default_scene(GownResolution res) {
  // Vertices around x along: full ~20k triangles, reduced ~5k, coarse ~1.3k (tests).
  int nu = 40, nv = 64;
  if (res == GownResolution::Full) { nu = 80; nv = 128; }
  if (res == GownResolution::Coarse) { nu = 20; nv = 32; }
  ClothMesh mesh = sleeve_gown(nu, nv);
  SceneOptions opt;
  // The jaws pinch the cuff's top edge: 6 cm along the sleeve, 12 cm across, 2.4 cm deep.
  opt.jaw_centre = {-0.03, 0.0, -0.006};
  opt.jaw_half = {0.031, 0.06, 0.012};
  // Self-collision distance: the data README's 0.008 m at full resolution; coarser meshes need
  // a larger one so that cloth layers cannot pass between vertices.
  opt.self_distance = res == GownResolution::Full ? 0.008 : res == GownResolution::Reduced ? 0.012 : 0.02;
  return make_scene(mesh, opt);
}

}  // namespace dressguard::sim
