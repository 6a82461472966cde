// A dataset: a folder with manifest.csv (one row per trial) and one CSV per trial.
//
//   manifest.csv  trial_id,participant,height,speed,label,file
//                 height in {high, middle, low}; speed in m/s; label in {good, missed, caught}
//                 or empty when unknown; file relative to the dataset folder.
//   <file>.csv    t,travel,f_motion,f_lateral,f_vertical   (see haptic.h for units and signs)
//                 and, after them, any further named columns, which readers skip: `dressguard
//                 simulate` adds label,height,speed,arm_offset,seed (one value per trial, on every
//                 row), so that its CSV alone says what it is; a dataset's trial CSVs have none.
//
// Simulated and measured trials share the format, so every command reads both alike.
//
// What a reader accepts (else InputError naming file and line): at least two samples per trial
// (one is no force sequence); every number finite; t increasing; travel in [kMinTravel,
// kMaxTravel] metres, never going back by more than kTravelJitter; each force within
// +-kMaxForce; speed in [kMinSpeed, kMaxSpeed] m/s; a trial that starts late (haptic.h,
// unrecorded_samples) at most kMaxUnrecordedSamples into its pull; a trial id and a file named
// once per manifest. The bounds are far outside any dressing pull; what they catch is a unit
// slip (travel in mm, speed in mm/s) or a glitch, which would otherwise train a model without a
// word or ask the HMMs for 10^300 unrecorded samples.
// A UTF-8 byte-order mark at the start of a file is skipped; CRLF line ends are accepted.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "haptic.h"

namespace dressguard {

inline constexpr double kMinTravel = -0.01;   // [m] an encoder's zero a centimetre off
inline constexpr double kMaxTravel = 2.0;     // [m] the study's rig runs 0.85 m
inline constexpr double kTravelJitter = 1e-3; // [m] the study's travel never decreases at all
inline constexpr double kMaxForce = 1000.0;   // [N] the study's rig stops at 10 N
inline constexpr double kMinSpeed = 1e-3, kMaxSpeed = 2.0;  // [m/s] the study pulls at 0.1, 0.15
inline constexpr std::size_t kMaxUnrecordedSamples = 100000;  // 1000 s at 100 Hz

struct Dataset {
  std::vector<HapticSequence> trials;
  // The files it was read from (load_dataset: the manifest, then each trial's file), so that a
  // command can refuse to write over its own input (same_file); empty for one made in memory.
  std::vector<std::filesystem::path> files;
  // Each trial's own file, parallel to `trials` (load_dataset); empty for one made in memory.
  std::vector<std::filesystem::path> trial_files;
};

// What names `t` (one of ds.trials) in an error: its file where `ds` knows it, else its id.
std::string trial_file_name(const Dataset& ds, const HapticSequence& t);

// Trial CSV (header then rows). Throws InputError naming file and line on malformed rows, and on
// a row with another number of fields than the header has names.
std::vector<HapticSample> read_trial_csv(const std::filesystem::path& path);
// One column after the five, with the same value on every row (`dressguard simulate`'s label and
// metadata). Neither may hold a comma, a quote or a line end (plain CSV, no quoting).
struct ConstantColumn {
  std::string name, value;
};
std::string format_trial_csv(const std::vector<HapticSample>& samples,
                             const std::vector<ConstantColumn>& constant_columns = {});

// Reads manifest.csv and every trial it names.
Dataset load_dataset(const std::filesystem::path& dir);

// The dataset's trial with this id (ids are unique within one dataset), or null.
const HapticSequence* find_trial(const Dataset& ds, const std::string& id);

// Several datasets read as one, their trials in the order given (a pooled training set: the
// synthesized trials of several people's simulators). Trial ids may repeat from one dataset to
// the next (every synthesized set names its trials sim-high-000, ...); within one they may not.
Dataset load_datasets(const std::vector<std::filesystem::path>& dirs);

// Writes every trial file and then the manifest, each atomically. The manifest is the commit
// point: a save that fails anywhere leaves the previous dataset whole, because a trial file the
// previous manifest names is never overwritten with other content. Trial files are named
// <id>.csv, or <id>.1.csv (.2, ...) while the previous manifest still names <id>.csv with
// other samples; a file whose content is unchanged is not rewritten. After the new manifest is in
// place, the files only the previous one named (plain names in the folder) are removed.
// Throws InputError, before writing anything, for a trial id that is empty, repeats or holds a
// comma, a slash, a backslash or a control character, starts with '.', or a participant with a
// comma or a control character (the manifest could not be read back).
void save_dataset(const Dataset& ds, const std::filesystem::path& dir);

// Why `id` cannot name a trial in a manifest and its file (see save_dataset), or empty if it can.
std::string trial_id_problem(std::string_view id);

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
