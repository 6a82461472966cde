// dg_sim behind the calibration's TrialSimulator, see sim_bridge.h.
#include "sim_bridge.h"

#include <memory>
#include <stdexcept>

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
  p.hem_width = c.hem_width;
  p.hem_bend_ratio = c.hem_bend_ratio;
  return p;
}

namespace {

// The calibration's range for the fist (calibration.h, which cannot include the simulator) is the
// simulator's own limit.
static_assert(kPersonParamInfo[kFistShift].highest == sim::kMaxFistShift &&
                  kPersonParamInfo[kFistShift].lowest == -sim::kMaxFistShift,
              "fist_shift's range differs between calibration.h and sim/trial.h");
// The middle arm's nominal height below the high one (synthesis.h) is the simulator's.
constexpr double kSimMiddleBelowHigh = sim::ArmGeometry{}.z_rel[0] - sim::ArmGeometry{}.z_rel[1];
static_assert(kMaxHemWidth == sim::kMaxHemWidth && kMaxHemBendRatio == sim::kMaxHemBendRatio,
              "the cuff's limits differ between calibration.h and sim/trial.h");
static_assert(kSimMiddleBelowHigh - kMiddleBelowHigh < 1e-12 && kMiddleBelowHigh - kSimMiddleBelowHigh < 1e-12,
              "the middle arm's nominal height differs between synthesis.h and sim/trial.h");

sim::TrialSpec spec_of(const TrialRequest& r) {
  sim::TrialSpec spec;
  spec.height = r.height;
  spec.arm_offset = r.arm_offset;
  spec.speed = r.speed;
  spec.seed = r.seed;
  spec.gown_noise = r.gown_noise;
  spec.max_travel = r.max_travel;
  return spec;
}

SimulatedTrial simulated(sim::TrialResult&& res) {
  SimulatedTrial out;
  out.samples = std::move(res.seq.samples);
  out.outcome = res.outcome;
  out.finite = res.finite;
  return out;
}

}  // namespace

ClothSimulator make_cloth_simulator(const std::string& gown) {
  sim::GownResolution res;
  if (gown == "full") res = sim::GownResolution::Full;
  else if (gown == "reduced") res = sim::GownResolution::Reduced;
  else if (gown == "coarse") res = sim::GownResolution::Coarse;
  else throw std::invalid_argument("unknown gown '" + gown + "' (expected full, reduced or coarse)");
  auto scene = std::make_shared<const sim::Scene>(sim::make_default_scene(res));
  ClothSimulator cs;
  cs.trial = [scene](const ClothValues& c, const TrialRequest& r) {
    return simulated(sim::simulate_trial(*scene, cloth_params_of(c), spec_of(r)));
  };
  cs.trials = [scene](const ClothValues& c, const std::vector<TrialRequest>& rs) {
    std::vector<sim::TrialSpec> specs;
    for (const TrialRequest& r : rs) specs.push_back(spec_of(r));
    std::vector<sim::TrialResult> res = sim::simulate_trials(*scene, cloth_params_of(c), specs);
    std::vector<SimulatedTrial> out;
    for (sim::TrialResult& r : res) out.push_back(simulated(std::move(r)));
    return out;
  };
  const double factor = sim::bend_mesh_factor(scene->data());
  const double density = sim::ClothParams{}.areal_density;
  cs.bending_length = [factor, density](double bend) {
    return sim::bending_length(sim::bending_rigidity(bend, factor), density);
  };
  return cs;
}

}  // namespace dressguard::calib
