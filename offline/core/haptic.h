// Haptic data of one sleeve-pulling trial, measured or simulated, in the rig's convention.
//
// The rig's convention (shared/data/README.md): F_motion along the gripper's direction of
// motion, negative when the gown resists (drag); F_vertical up positive; F_lateral sideways.
// Travel is the gripper's distance from its start, in metres. The paper's HMMs use only
// F_motion ("X") and F_vertical ("Y"), section V-B.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dressguard {

// One sample of the force-torque sensor at the gripper, 100 Hz in the study.
struct HapticSample {
  double t = 0.0;           // [s] since the start of the pull
  double travel = 0.0;      // [m] gripper travel along the motion direction
  double f_motion = 0.0;    // [N] along the motion, drag negative
  double f_lateral = 0.0;   // [N] sideways
  double f_vertical = 0.0;  // [N] up positive, static weight removed (sensor bias)
};

// The three outcomes of the task (paper section V-A).
enum class Outcome { Good = 0, Missed = 1, Caught = 2 };
inline constexpr int kOutcomeCount = 3;
// Paper V-A's label rule for a pull that stopped before the end of travel: good when no vertex of
// the sleeve opening's lower half ended farther than this from the elbow centre along the pull [m].
inline constexpr double kGoodLabelDistance = 0.07;

// The three controlled arm heights of the study; the real arm deviates from them.
enum class ArmHeight { High = 0, Middle = 1, Low = 2 };

std::string_view outcome_name(Outcome o);            // "good", "missed", "caught"
std::optional<Outcome> parse_outcome(std::string_view s);  // also accepts "miss"
std::string_view arm_height_name(ArmHeight h);       // "high", "middle", "low"
std::optional<ArmHeight> parse_arm_height(std::string_view s);

// One trial's samples and what is known about it.
struct HapticSequence {
  std::string id;                  // unique within a dataset, e.g. "s4-good-3"
  std::string participant;         // e.g. "4"; empty for simulated trials
  ArmHeight height = ArmHeight::High;
  double speed = 0.1;              // [m/s] commanded pull speed
  std::optional<Outcome> label;    // empty when unknown
  std::vector<HapticSample> samples;
};

}  // namespace dressguard
