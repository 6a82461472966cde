// The cloth simulator (dg_sim) as a calibration TrialSimulator. Built only when dg_sim is
// (DRESSGUARD_HAVE_SIM); the commands check that macro and say so otherwise.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "calibration.h"
#include "placement.h"
#include "trial.h"

namespace dressguard::calib {

// The cloth simulator in both forms, over one Scene (constant model) per grasp: the gown's own
// placement built once, and a cloth whose rim_shift moves the rim (ClothValues) on a scene of
// that grasp, built when first asked for (about 0.3 s for the reduced gown) and kept among the
// last few; sim::simulate_trial() and simulate_trials() keep their mutable state per call, so
// both functions may run on any number of threads. `trials` settles a cloth once for all its
// arm heights where that is exact (sim::simulate_trials) and gives the same bits as `trial`.
// Both throw UnbuildableCandidate (calibration.h) naming the rim_shift when its grasp holds none
// of the gown (gown::NothingGrasped).
struct ClothSimulator {
  TrialSimulator trial;
  TrialBatchSimulator trials;
  // Peirce's bending length [m] that a bend value gives on this simulator's gown mesh
  // (sim::bending_length in offline/sim/model.h): what the calibrated `bend` means as a fabric.
  std::function<double(double bend, double areal_density)> bending_length;
  // Builds (and keeps, as `trial` would) the scene of a rim_shift's grasp, throwing
  // UnbuildableCandidate as `trial` does: calibrate refuses a held rim_shift with it before the
  // search, whose every candidate would otherwise be unbuildable.
  std::function<void(double rim_shift)> build_grasp;
};

// "full" (the measured 20k-triangle gown), "reduced" (the default for calibration and synthesis)
// or "coarse" (small, for tests). Throws std::invalid_argument for another name.
ClothSimulator make_cloth_simulator(const std::string& gown);

// The simulator's parameters for a calibration's cloth and person values (damping and areal
// density keep the simulator's defaults: not calibrated, paper IV-B.2). rim_shift is the scene's
// (grasp_of), not a ClothParams field.
sim::ClothParams cloth_params_of(const ClothValues& c);

// How the jaws hold the gown for a rim_shift: nullopt for 0 (the gown's own placement, the
// scene make_default_scene(res) builds), else the default grasp of the gown in use (measured:
// gown::OpeningGrip{}; parametric: gown::kParametricGrip) with its rim `rim_shift` further ahead.
// Throws std::invalid_argument when that puts the rim behind the jaws.
std::optional<gown::OpeningGrip> grasp_of(double rim_shift, bool parametric);

// [m] How far ahead of the jaws the gown the simulator runs on holds its sleeve opening's rim
// at rim_shift 0: the measured gown's (gown::OpeningGrip{}) when shared/data holds it, else the
// parametric gown's (gown::kParametricGrip), as make_cloth_simulator chooses. What a rim_shift
// may take away (fit_rim_shift_to_gown).
double gown_rim_ahead();

// True (this file is only compiled with dg_sim); lets tests ask without the macro.
bool cloth_simulator_available();

}  // namespace dressguard::calib
