// Haptic data synthesis with the calibrated simulator (paper section V-A).
//
// Per arm height, `per_height` trials (paper: 100), the first half at 0.1 m/s and the second
// half at 0.15 m/s (the study's protocol). Two noise models, each switchable for the paper's
// ablations (section VII):
//   gown:  the simulator's initial-state perturbation, a uniform random force up to 6 N in the
//          horizontal plane over all vertices for 0.5 s before the pull (TrialRequest::gown_noise);
//   arm:   high and low: calibrated offset + U[-1.5, +1.5] cm; middle: U[-6, 0] cm added to the
//          nominal middle height directly ("not all participants have an optimised middle arm
//          height", and only negative noise to compensate gravity).
// The pull ends at the calibration's rig travel (the participant's measured end of travel; the
// paper's 0.85 m when unknown) or at 10 N. Labels come from the simulator (paper V-A rule). Every trial's randomness derives from
// (seed, height, index) alone, so the dataset is the same whatever the thread or rank count.
// Resumable: each finished trial is written at once (CSV, then a small ".done" marker holding its
// label, both atomically); a rerun skips trials whose marker and CSV exist.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "calibration.h"
#include "dataset.h"

namespace dressguard::calib {

struct SynthesisOptions {
  int per_height = 100;
  bool gown_noise = true;
  bool arm_noise = true;
  std::uint64_t seed = 1;
  int threads = 0;  // 0 = all cores
};

inline constexpr double kArmNoiseHighLow = 0.015;   // [m] +-1.5 cm at high and low
inline constexpr double kArmNoiseMiddleLow = -0.06;  // [m] [-6, 0] cm at middle

// The request of trial `index` (0-based) at `height`; pure function of its arguments.
TrialRequest synthesis_request(const Calibration& cal, ArmHeight height, int index, const SynthesisOptions& o);
// The trial id used in the dataset, e.g. "sim-high-007".
std::string synthesis_trial_id(ArmHeight height, int index);

struct SynthesisProgress {
  int done = 0, total = 0, skipped = 0;  // skipped: found on disk from an earlier run
  double elapsed_s = 0, eta_s = 0;
};

struct SynthesisSummary {
  int trials = 0, resumed = 0;
  int per_label[kOutcomeCount] = {};
  double elapsed_s = 0;
};

// Simulates the missing trials into `out` (a dataset folder) and writes its manifest. Every rank
// of `comm` calls it; trials are spread over ranks (index % size) and threads; rank 0 writes
// the manifest after all ranks have finished. Returns the same summary on every rank.
SynthesisSummary synthesize(const Calibration& cal, const TrialSimulator& sim, const SynthesisOptions& options,
                            const std::filesystem::path& out, const Comm& comm,
                            const std::function<void(const SynthesisProgress&)>& progress = {});

}  // namespace dressguard::calib
