// The default scene (trial.h): the gown module's gown (measured when shared/data is present,
// else its parametric gown), reduced to the resolution asked for, placed like the paper.
#include <optional>

#include "gown_scene.h"
#include "trial.h"

namespace dressguard::sim {

namespace {

Scene default_scene(GownResolution res, bool parametric, std::optional<gown::OpeningGrip> grip) {
  gown::GownOptions go;
  go.target_triangles = target_triangles(res);
  go.parametric = parametric;
  go.grip = grip;
  const gown::GownMesh mesh = gown::load_gown(go);
  SceneOptions opt;
  // Self-collision distance: the data README's 0.008 m for the full gown (1.4 cm edges); the
  // reduced meshes' longer edges need a larger one so that layers cannot pass between vertices.
  opt.self_distance = res == GownResolution::Full ? 0.008 : res == GownResolution::Reduced ? 0.012 : 0.02;
  return make_scene(mesh, gown::PaperScene{}, opt);
}

}  // namespace

Scene make_default_scene(GownResolution res, bool parametric) { return default_scene(res, parametric, std::nullopt); }

Scene make_default_scene(GownResolution res, bool parametric, const gown::OpeningGrip& grip) {
  return default_scene(res, parametric, grip);
}

}  // namespace dressguard::sim
