// A dataset: a folder with manifest.csv (one row per trial) and one CSV per trial.
//
//   manifest.csv  trial_id,participant,height,speed,label,file
//                 height in {high, middle, low}; speed in m/s; label in {good, missed, caught}
//                 or empty when unknown; file relative to the dataset folder.
//   <file>.csv    t,travel,f_motion,f_lateral,f_vertical   (see haptic.h for units and signs)
//
// Simulated and measured trials share the format, so every command reads both alike.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "haptic.h"

namespace dressguard {

struct Dataset {
  std::vector<HapticSequence> trials;
};

// Trial CSV (header then rows). Throws InputError naming file and line on malformed rows.
std::vector<HapticSample> read_trial_csv(const std::filesystem::path& path);
std::string format_trial_csv(const std::vector<HapticSample>& samples);

// Reads manifest.csv and every trial it names.
Dataset load_dataset(const std::filesystem::path& dir);

// The dataset's trial with this id (ids are unique within one dataset), or null.
const HapticSequence* find_trial(const Dataset& ds, const std::string& id);

// Several datasets read as one, their trials in the order given (a pooled training set: the
// synthesized trials of several people's simulators). Trial ids may repeat from one dataset to
// the next (every synthesized set names its trials sim-high-000, ...); within one they may not.
Dataset load_datasets(const std::vector<std::filesystem::path>& dirs);

// Writes every trial file and then the manifest, each atomically: an interrupted save leaves
// the previous manifest in place. Trial files are named <id>.csv.
void save_dataset(const Dataset& ds, const std::filesystem::path& dir);

// One trial file of the study (shared/data/kapusta2016-calibration-trials): space-separated
// "t position F_motion F_lateral F_vertical" rows. Already in the rig's convention.
std::vector<HapticSample> read_study_trial(const std::filesystem::path& path);

// Converts the study's layout <outcome>/subject<N>/<k>.txt into a dataset in memory:
// good -> high arm, label good; miss -> low arm, label missed; caughtmiss -> middle arm,
// label missed. The speed is estimated from the travel (0.1 or 0.15 m/s, nearest).
Dataset import_study(const std::filesystem::path& study_dir);

// The study folder inside shared/, or empty if absent.
std::filesystem::path study_dir();

// Pull speed estimated from the travel's steady slope, snapped to the nearer of 0.1 and 0.15 m/s.
double estimate_speed(const std::vector<HapticSample>& samples);

// True when a measured trial ended at the force threshold (|F| >= 9.5 N on motion or vertical at
// its last sample; the rig's limit is 10 N, the last sample may sit just under it).
bool ended_at_force_limit(const std::vector<HapticSample>& samples);

// Where the rig stopped a measured trial that did not end at the force limit: its last travel
// (the study's rig did not always run the full 0.85 m; participant 4's miss/2 ends at 0.72 m).
// A simulation of that trial must stop there too, or the paper's objective charges the extra
// length with w = 20 (eq. 5). `full` for a trial that ended at the force limit (or is empty).
double rig_end_of_travel(const std::vector<HapticSample>& samples, double full = 0.85);

}  // namespace dressguard
