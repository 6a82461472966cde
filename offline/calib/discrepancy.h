// What a calibrated simulator still gets wrong, as a term of the model: the discrepancy of
// Kennedy and O'Hagan (2001, "Bayesian calibration of computer models", eq. 5), measured = simulator
// + discrepancy + noise. After calibration the simulator's error on the person's own sequences
// is not noise: it has a shape over travel that repeats in every trial of that arm height (the
// sleeve resting on the fist early, then lagging the measured ramp; offline/sim/MEASUREMENTS.md,
// "What the simulation gets wrong"). That shape is measured here from the same 2-3 sequences the
// calibration was fitted to, and can be added to the simulator's synthesized trials, so that a
// classifier trained on them (the STC) learns the outcomes' differences as the sensor shows
// them rather than as the simulator makes them.
//
//   r_h(x) = mean of (R_i - S_i) over the pairs i whose simulated travel x_i is in [x - w/2, x + w/2)
//
// per arm height h with an input, per force (motion, lateral, vertical), on a grid of travel x,
// the pairs those of eq. 3: one moment of the pull (objective.h, paired_start), so the term is
// the calibration's own residual, smoothed over the simulator's travel, which is the travel of
// the trials it is added to. Until session 94 it was the difference of two window means at equal
// travel, the measured one by the recording's stamp: the stamp is a constant-speed profile and
// leads the ramped pull by v^2 / 2a (5 mm at 0.1 m/s; core/haptic.h), which moved the term by a
// median of 0.006-0.017 N and up to 0.55 N (calib/MEASUREMENTS.md, session 93), and a
// late-starting recording needed its own rule (records_from). A window without a pair (before a
// late-starting recording's first) keeps the previous point's value (0 before the first).
// It uses only the calibrating person's inputs: a classifier tested on other people never sees
// their data through it.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "calibration.h"
#include "dataset.h"
#include "haptic.h"

namespace dressguard::calib {

struct DiscrepancyOptions {
  double step = 0.01;    // [m] grid spacing of r_h
  double window = 0.02;  // [m] w: the mean over the window smooths the sensor's noise, which a
                         // correction added to every trial would otherwise copy into all of them
  double fade = 0.05;    // [m] beyond a height's last grid point r_h falls linearly to 0 over this
};

struct Discrepancy {
  DiscrepancyOptions options;
  // Per ArmHeight: r_h at x = 0, step, 2 step, ... up to the travel both curves cover; empty when
  // the height had no input.
  std::array<std::vector<std::array<double, 3>>, 3> by_height;  // (motion, lateral, vertical) [N]
  // Per ArmHeight, the simulated travel of the last pair (the shorter curve's end) [m]: r_h keeps
  // its last grid value up to it and fades only beyond (0: from the last grid point).
  std::array<double, 3> end{};
};

// r_h of each input against its simulated curve (simulate_inputs: the calibrated cloth and
// offsets), inputs and curves in the same order, both at the simulator's rate (calibration_inputs
// requires it: pairs by index are pairs in time only then). An input or curve without samples
// adds nothing. Two inputs of one height are averaged (never
// the case with select_inputs, one per height). Throws std::invalid_argument when the counts
// differ or the options are not positive.
Discrepancy measure_discrepancy(const std::vector<HapticSequence>& inputs,
                                const std::vector<SimulatedTrial>& simulated, const DiscrepancyOptions& o = {});

// r_h at travel x for height h [N]: linear between grid points, the first value before 0, the
// last one up to the height's end, the fade after it. A height without its own input takes the
// mean of the heights that have one (the people's middle arm is a missed or a caught trial,
// between the two others).
std::array<double, 3> discrepancy_at(const Discrepancy& d, ArmHeight h, double x);

// Adds r_h(travel) to every sample of `trial` (h = trial.height).
void apply_discrepancy(const Discrepancy& d, HapticSequence& trial);

// The sequences calibration `cal` (read from `cal_file`) was fitted to (its fits' trial ids, in
// the file's order), from the measured dataset `measured` read from `where`. Throws InputError
// naming `cal_file` when it records no sequence, or `where` and the first id it does not hold.
std::vector<HapticSequence> calibration_inputs(const Calibration& cal, const std::filesystem::path& cal_file,
                                               const Dataset& measured, const std::filesystem::path& where);

// The calibrated simulator's discrepancy: its inputs simulated with the calibration's cloth and
// offsets (simulate_inputs, the very curves `calibrate` wrote), measured against them.
Discrepancy discrepancy_of(const Calibration& cal, const std::vector<HapticSequence>& inputs,
                           const TrialBatchSimulator& sim, const DiscrepancyOptions& o = {});

// CSV for plots and reading, one row per grid point of each named discrepancy (a calibration
// file's name): calibration,height,travel,r_motion,r_lateral,r_vertical.
std::string discrepancy_csv(const std::vector<std::pair<std::string, Discrepancy>>& named);

}  // namespace dressguard::calib
