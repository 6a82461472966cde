// dg_sim behind the calibration's TrialSimulator, see sim_bridge.h.
#include "sim_bridge.h"

#include <cstdio>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

#include "gown.h"
#include "gown_scene.h"
#include "model.h"
#include "synthesis.h"
#include "trial.h"

namespace dressguard::calib {

bool cloth_simulator_available() { return true; }

sim::ClothParams cloth_params_of(const ClothValues& c) {
  sim::ClothParams p;  // damping and density keep the simulator's defaults (not calibrated, paper IV-B.2)
  p.stretch = c.stretch;
  p.shear = c.shear;
  p.bend = c.bend;
  p.friction = c.friction;
  p.self_friction = c.self_friction;
  p.arm_compliance = c.arm_compliance;
  p.fist_shift = c.fist_shift;
  p.arm_lateral = c.arm_lateral;
  p.fist_lateral = c.fist_lateral;
  p.support_depth = c.support_depth;
  p.support_lateral = c.support_lateral;
  p.hem_width = c.hem_width;
  p.hem_bend_ratio = c.hem_bend_ratio;
  p.areal_density = c.areal_density;
  return p;
}

namespace {

// The calibration's range for the fist (calibration.h, which cannot include the simulator) is the
// simulator's own limit.
static_assert(kPersonParamInfo[kFistShift].highest == sim::kMaxFistShift &&
                  kPersonParamInfo[kFistShift].lowest == -sim::kMaxFistShift,
              "fist_shift's range differs between calibration.h and sim/trial.h");
static_assert(kPersonParamInfo[kArmLateral].highest == sim::kMaxArmLateral &&
                  kPersonParamInfo[kArmLateral].lowest == -sim::kMaxArmLateral,
              "arm_lateral's range differs between calibration.h and sim/trial.h");
static_assert(kPersonParamInfo[kFistLateral].highest == sim::kMaxArmLateral &&
                  kPersonParamInfo[kFistLateral].lowest == -sim::kMaxArmLateral,
              "fist_lateral's range differs between calibration.h and sim/trial.h");
static_assert(kPersonParamInfo[kSupportDepth].highest == sim::kMaxSupportDepth && kPersonParamInfo[kSupportDepth].lowest == 0 &&
                  kPersonParamInfo[kSupportLateral].highest == sim::kMaxSupportLateral &&
                  kPersonParamInfo[kSupportLateral].lowest == -sim::kMaxSupportLateral,
              "the support's range differs between calibration.h and sim/trial.h");
// The middle arm's nominal height below the high one (synthesis.h) is the simulator's.
constexpr double kSimMiddleBelowHigh = sim::ArmGeometry{}.z_rel[0] - sim::ArmGeometry{}.z_rel[1];
static_assert(kPaperArealDensity == sim::ClothParams{}.areal_density,
              "the paper's areal density differs between calibration.h and sim/trial.h");
static_assert(kMaxHemWidth == sim::kMaxHemWidth && kMaxHemBendRatio == sim::kMaxHemBendRatio,
              "the cuff's limits differ between calibration.h and sim/trial.h");
static_assert(kSimMiddleBelowHigh - kMiddleBelowHigh < 1e-12 && kMiddleBelowHigh - kSimMiddleBelowHigh < 1e-12,
              "the middle arm's nominal height differs between synthesis.h and sim/trial.h");

// The simulator's scheme of a calibration's name for it (ClothValues::friction_scheme).
sim::FrictionScheme friction_scheme_of(const std::string& name) {
  sim::FrictionScheme f{};
  if (sim::parse_friction_scheme(name, &f)) return f;
  throw std::invalid_argument("unknown friction scheme '" + name + "' (expected " + friction_scheme_choices() + ")");
}

sim::TrialSpec spec_of(const ClothValues& c, const TrialRequest& r) {
  sim::TrialSpec spec;
  spec.friction_scheme = friction_scheme_of(c.friction_scheme);
  spec.height = r.height;
  spec.arm_offset = r.arm_offset;
  spec.speed = r.speed;
  spec.seed = r.seed;
  spec.gown_noise = r.gown_noise;
  spec.max_travel = r.max_travel;
  spec.pull_watch = r.watch;
  return spec;
}

// [s] the pull's time after `from` [s] (its samples' times; one sample is three output steps).
double pull_time_after(const sim::TrialResult& res, double from) {
  return res.seq.samples.empty() ? 0.0 : res.seq.samples.back().t - from;
}

// The time of the last sample pulled as one with another trial (TrialResult::pull_shared_travel),
// 0 when the pull was its own from the start.
double shared_pull_time(const sim::TrialResult& res) {
  double t = 0.0;
  if (res.pull_shared_travel > 0)
    for (const HapticSample& h : res.seq.samples) {
      if (h.travel > res.pull_shared_travel) break;
      t = h.t;
    }
  return t;
}

// `scene`: the one that simulated `res`; a cut trial's rest keeps it alive (the paused model
// points into it, and the scene cache below may drop it meanwhile). `resumed_at`: for a rest,
// the time of the sample it was cut at (the pull before it was simulated already); else < 0.
SimulatedTrial simulated(sim::TrialResult&& res, const std::shared_ptr<const sim::Scene>& scene, double resumed_at = -1) {
  SimulatedTrial out;
  out.simulated_s = resumed_at >= 0 ? pull_time_after(res, resumed_at)
                                    : (res.settle_shared ? 0.0 : res.settle_time) + pull_time_after(res, shared_pull_time(res));
  out.samples = std::move(res.seq.samples);
  out.outcome = res.outcome;
  out.finite = res.finite;
  out.settled = res.settled;
  out.d_behind = res.d_behind;
  out.d_ahead = res.d_ahead;
  out.cut = res.cut;
  if (res.paused) {
    const double cut_at = out.samples.empty() ? 0.0 : out.samples.back().t;
    out.rest = [scene, paused = std::move(res.paused), cut_at] {
      return simulated(sim::resume_trial(*paused), scene, cut_at);
    };
  }
  return out;
}

// The scenes of one gown resolution by rim_shift: the gown's own placement (0) always, and the
// last kKept others. A calibration asks for a new rim_shift with every candidate, synthesis for
// one over and over; keeping a few serves both without holding a scene per candidate.
class SceneCache {
 public:
  explicit SceneCache(sim::GownResolution res)
      : res_(res), parametric_(gown::measured_gown_path().empty()),
        own_(std::make_shared<const sim::Scene>(sim::make_default_scene(res))) {}

  std::shared_ptr<const sim::Scene> own() const { return own_; }

  std::shared_ptr<const sim::Scene> get(double rim_shift) {
    if (rim_shift == 0.0) return own_;
    const std::optional<gown::OpeningGrip> grip = grasp_of(rim_shift, parametric_);
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [shift, scene] : kept_)
      if (shift == rim_shift) return scene;
    // Built under the lock: a thread that wants another grasp waits about 0.3 s, once per
    // candidate, against the candidate's seconds of simulation. A grasp that holds none of the
    // gown is the candidate's, not a defect: calibrate ranks it last (UnbuildableCandidate).
    std::shared_ptr<const sim::Scene> scene;
    try {
      scene = std::make_shared<const sim::Scene>(sim::make_default_scene(res_, parametric_, *grip));
    } catch (const gown::NothingGrasped& e) {
      throw UnbuildableCandidate("rim_shift " + format_number(rim_shift) + " m: " + e.what());
    }
    if (kept_.size() == kKept) kept_.erase(kept_.begin());
    kept_.emplace_back(rim_shift, scene);
    return scene;
  }

 private:
  static constexpr std::size_t kKept = 4;
  sim::GownResolution res_;
  bool parametric_;
  std::shared_ptr<const sim::Scene> own_;
  std::mutex mutex_;
  std::vector<std::pair<double, std::shared_ptr<const sim::Scene>>> kept_;
};

}  // namespace

std::optional<gown::OpeningGrip> grasp_of(double rim_shift, bool parametric) {
  if (rim_shift == 0.0) return std::nullopt;
  gown::OpeningGrip g = gown::own_grip(parametric);
  g.rim_ahead += rim_shift;
  if (!(g.rim_ahead >= 0.0)) {
    char b[200];
    std::snprintf(b, sizeof b, "rim_shift %g m puts the sleeve opening's rim %g m behind the jaws (this gown's is held %g m ahead)",
                  rim_shift, -g.rim_ahead, g.rim_ahead - rim_shift);
    throw std::invalid_argument(b);
  }
  return g;
}

double gown_rim_ahead() { return gown::own_grip(gown::measured_gown_path().empty()).rim_ahead; }

ClothSimulator make_cloth_simulator(const std::string& gown) {
  sim::GownResolution res;
  if (gown == "full") res = sim::GownResolution::Full;
  else if (gown == "reduced") res = sim::GownResolution::Reduced;
  else if (gown == "coarse") res = sim::GownResolution::Coarse;
  else throw std::invalid_argument("unknown gown '" + gown + "' (expected full, reduced or coarse)");
  auto scenes = std::make_shared<SceneCache>(res);
  ClothSimulator cs;
  cs.trial = [scenes](const ClothValues& c, const TrialRequest& r) {
    const std::shared_ptr<const sim::Scene> scene = scenes->get(c.rim_shift);
    return simulated(sim::simulate_trial(*scene, cloth_params_of(c), spec_of(c, r)), scene);
  };
  cs.trials = [scenes](const ClothValues& c, const std::vector<TrialRequest>& rs) {
    std::vector<sim::TrialSpec> specs;
    for (const TrialRequest& r : rs) specs.push_back(spec_of(c, r));
    const std::shared_ptr<const sim::Scene> scene = scenes->get(c.rim_shift);
    std::vector<sim::TrialResult> res = sim::simulate_trials(*scene, cloth_params_of(c), specs);
    std::vector<SimulatedTrial> out;
    for (sim::TrialResult& r : res) out.push_back(simulated(std::move(r), scene));
    return out;
  };
  cs.build_grasp = [scenes](double rim_shift) { scenes->get(rim_shift); };
  // The bending length is the mesh's: a grasp moves the gown, it does not change its triangles.
  const double factor = sim::bend_mesh_factor(scenes->own()->data());
  cs.bending_length = [factor](double bend, double areal_density) {
    return sim::bending_length(sim::bending_rigidity(bend, factor), areal_density);
  };
  return cs;
}

}  // namespace dressguard::calib
