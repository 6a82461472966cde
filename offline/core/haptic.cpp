#include "haptic.h"

#include <algorithm>
#include <cmath>

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

double pull_time_at(double travel, double speed, double acceleration) {
  const double ramp = speed * speed / (2.0 * acceleration);  // [m] travelled while accelerating
  if (travel <= ramp) return std::sqrt(2.0 * std::max(travel, 0.0) / acceleration);
  return travel / speed + speed / (2.0 * acceleration);
}

std::size_t unrecorded_samples(const HapticSequence& trial) {
  if (trial.samples.empty() || trial.samples.front().travel <= kLateStart) return 0;
  const double period = trial.samples.size() >= 2 ? mean_sample_period(trial) : 0.01;
  if (!(period > 0.0)) return 0;  // a recording without time: nothing to say where it began
  if (!(trial.speed > 0.0)) return 0;  // no speed to read the stamp's time by
  return static_cast<std::size_t>(std::lround(trial.samples.front().travel / trial.speed / period));
}

double mean_sample_period(const HapticSequence& trial) {
  const size_t n = trial.samples.size();
  return n >= 2 ? (trial.samples.back().t - trial.samples.front().t) / static_cast<double>(n - 1) : 0.0;
}

double nominal_sample_period(double mean_s) {
  const double us = std::round(mean_s * 1e6);
  return us >= 1.0 ? us / 1e6 : mean_s;
}

bool records_from(const std::vector<HapticSample>& samples, double travel) {
  return !samples.empty() && samples.front().travel <= std::max(travel, 0.0) + kLateStart;
}

}  // namespace dressguard
