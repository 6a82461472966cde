#include "haptic.h"

namespace dressguard {

std::string_view outcome_name(Outcome o) {
  switch (o) {
    case Outcome::Good: return "good";
    case Outcome::Missed: return "missed";
    case Outcome::Caught: return "caught";
  }
  return "?";
}

std::optional<Outcome> parse_outcome(std::string_view s) {
  if (s == "good") return Outcome::Good;
  if (s == "missed" || s == "miss") return Outcome::Missed;
  if (s == "caught") return Outcome::Caught;
  return std::nullopt;
}

std::string_view arm_height_name(ArmHeight h) {
  switch (h) {
    case ArmHeight::High: return "high";
    case ArmHeight::Middle: return "middle";
    case ArmHeight::Low: return "low";
  }
  return "?";
}

std::optional<ArmHeight> parse_arm_height(std::string_view s) {
  if (s == "high") return ArmHeight::High;
  if (s == "middle") return ArmHeight::Middle;
  if (s == "low") return ArmHeight::Low;
  return std::nullopt;
}

}  // namespace dressguard
