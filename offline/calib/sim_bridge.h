// The cloth simulator (dg_sim) as a calibration TrialSimulator. Built only when dg_sim is
// (DRESSGUARD_HAVE_SIM); the commands check that macro and say so otherwise.
#pragma once

#include <functional>
#include <string>

#include "calibration.h"
#include "trial.h"

namespace dressguard::calib {

// The cloth simulator in both forms, over one Scene (constant model) built once and shared by
// every call; sim::simulate_trial() and simulate_trials() keep their mutable state per call, so
// both functions may run on any number of threads. `trials` settles a cloth once for all its
// arm heights where that is exact (sim::simulate_trials) and gives the same bits as `trial`.
struct ClothSimulator {
  TrialSimulator trial;
  TrialBatchSimulator trials;
  // Peirce's bending length [m] that a bend value gives on this simulator's gown mesh
  // (sim::bending_length in offline/sim/model.h): what the calibrated `bend` means as a fabric.
  std::function<double(double bend)> bending_length;
};

// "full" (the measured 20k-triangle gown), "reduced" (the default for calibration and synthesis)
// or "coarse" (small, for tests). Throws std::invalid_argument for another name.
ClothSimulator make_cloth_simulator(const std::string& gown);

// The simulator's parameters for a calibration's cloth and person values (damping and areal
// density keep the simulator's defaults: not calibrated, paper IV-B.2).
sim::ClothParams cloth_params_of(const ClothValues& c);

// True (this file is only compiled with dg_sim); lets tests ask without the macro.
bool cloth_simulator_available();

}  // namespace dressguard::calib
