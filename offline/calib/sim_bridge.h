// The cloth simulator (dg_sim) as a calibration TrialSimulator. Built only when dg_sim is
// (DRESSGUARD_HAVE_SIM); the commands check that macro and say so otherwise.
#pragma once

#include <string>

#include "calibration.h"

namespace dressguard::calib {

// "full" (the measured 20k-triangle gown), "reduced" (the default for calibration and synthesis)
// or "coarse" (small, for tests). Throws std::invalid_argument for another name.
// The Scene (constant model) is built once here and shared by every call; simulate_trial() keeps
// its mutable state per call, so the returned function may run on any number of threads.
TrialSimulator make_cloth_simulator(const std::string& gown);

// True (this file is only compiled with dg_sim); lets tests ask without the macro.
bool cloth_simulator_available();

}  // namespace dressguard::calib
