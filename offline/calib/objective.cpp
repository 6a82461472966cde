// The calibration objective, see objective.h (paper eq. 3-5).
#include "objective.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace dressguard::calib {

std::string_view objective_name(ObjectiveKind k) {
  return k == ObjectiveKind::Area ? "area" : "position-weighted";
}

std::optional<ObjectiveKind> parse_objective(std::string_view s) {
  if (s == "area") return ObjectiveKind::Area;
  if (s == "position-weighted") return ObjectiveKind::PositionWeighted;
  return std::nullopt;
}

namespace {

double force(const HapticSample& s, ForceAxis a) {
  switch (a) {
    case ForceAxis::Motion: return s.f_motion;
    case ForceAxis::Lateral: return s.f_lateral;
    default: return s.f_vertical;
  }
}

// |x_i - x_{i-1}|: the travel between two frames (never negative, even if the stamp jitters).
double step(const std::vector<HapticSample>& seq, std::size_t i) {
  return std::abs(seq[i].travel - seq[i - 1].travel);
}

void require_samples(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured) {
  if (sim.empty() || measured.empty()) throw std::invalid_argument("objective: a sequence has no samples");
}

// Linear interpolation of a sequence's force at travel x (clamped to its ends). Travel is
// non-decreasing in both measured and simulated sequences; equal travels take the later sample.
double force_at(const std::vector<HapticSample>& seq, double x, ForceAxis a) {
  if (x <= seq.front().travel) return force(seq.front(), a);
  if (x >= seq.back().travel) return force(seq.back(), a);
  const auto it = std::upper_bound(seq.begin(), seq.end(), x,
                                   [](double v, const HapticSample& s) { return v < s.travel; });
  const HapticSample& hi = *it;
  const HapticSample& lo = *(it - 1);
  const double span = hi.travel - lo.travel;
  if (span <= 1e-12) return force(hi, a);
  const double t = (x - lo.travel) / span;
  return (1.0 - t) * force(lo, a) + t * force(hi, a);
}

// The first index of `seq` with travel >= x, or its last index.
std::size_t first_at_or_beyond(const std::vector<HapticSample>& seq, double x) {
  const auto it = std::lower_bound(seq.begin(), seq.end(), x,
                                   [](const HapticSample& s, double v) { return s.travel < v; });
  return std::min(static_cast<std::size_t>(it - seq.begin()), seq.size() - 1);
}

// The speed of a recording's stamp [m/s]: (x_last - x_first) / (t_last - t_first). The stamp is a
// constant-speed profile (core/haptic.h), so this is the pull's speed; 0 when the sequence has no
// span of time or travel to tell it by.
double stamp_speed(const std::vector<HapticSample>& seq) {
  const double dt = seq.back().t - seq.front().t, dx = seq.back().travel - seq.front().travel;
  const double v = dt > 0.0 ? dx / dt : 0.0;
  return std::isfinite(v) && v > 0.0 ? v : 0.0;
}

// The index of `seq` whose time is nearest to t (the later one of a tie; its ends beyond them).
std::size_t nearest_in_time(const std::vector<HapticSample>& seq, double t) {
  const auto it = std::lower_bound(seq.begin(), seq.end(), t, [](const HapticSample& s, double v) { return s.t < v; });
  if (it == seq.begin()) return 0;
  if (it == seq.end()) return seq.size() - 1;
  const std::size_t k = static_cast<std::size_t>(it - seq.begin());
  return t - seq[k - 1].t < seq[k].t - t ? k - 1 : k;
}

// paired_start's first indices (its count left 0).
PairedStart first_pair(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured) {
  const double xs = sim.front().travel, xm = measured.front().travel;
  const double v = stamp_speed(measured);
  if (xm - xs > kLateStart) {
    // The recording starts late: its first sample is x_m / v into the pull by the stamp, and the
    // simulation's clock is the pull's.
    if (v > 0.0) return {nearest_in_time(sim, xm / v), 0, 0};
    return {first_at_or_beyond(sim, xm), 0, 0};
  }
  if (xs - xm > kLateStart) {
    // The simulation starts late (a pull simulated from further along): the measured sample
    // whose stamp is where the pull is at the simulation's first time.
    return {0, first_at_or_beyond(measured, v > 0.0 ? v * sim.front().t : xs), 0};
  }
  return {};  // within kLateStart, or a travel that is not a number: paired by index
}

}  // namespace

PairedStart paired_start(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured) {
  require_samples(sim, measured);
  PairedStart p = first_pair(sim, measured);
  p.count = std::min(sim.size() - p.sim, measured.size() - p.measured);
  return p;
}

std::vector<HapticSample> measured_on_simulated_travel(const std::vector<HapticSample>& sim,
                                                       const std::vector<HapticSample>& measured) {
  if (sim.empty() || measured.empty()) return {};
  const PairedStart p = paired_start(sim, measured);
  std::vector<HapticSample> out(measured.begin() + static_cast<std::ptrdiff_t>(p.measured),
                                measured.begin() + static_cast<std::ptrdiff_t>(p.measured + p.count));
  for (std::size_t k = 0; k < p.count; ++k) out[k].travel = sim[p.sim + k].travel;
  return out;
}

namespace {

// eq. 3-4; `sim_goes_on`: the simulation may have samples still to come, so the terms that its
// last sample decides (measurement longer, s_m) are left out.
double area_error_of(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured, ForceAxis axis,
                     double w, bool sim_goes_on) {
  const PairedStart p = paired_start(sim, measured);
  // i counts pairs from p; m and n are the last pair indices, as in eq. 4.
  const std::size_t m = sim.size() - 1 - p.sim, n = measured.size() - 1 - p.measured;
  auto s = [&](std::size_t i) { return force(sim[p.sim + i], axis); };
  auto r = [&](std::size_t i) { return force(measured[p.measured + i], axis); };
  double e = 0.0;
  // i = 0 has no travel before it: d = 0. Both running: dx |s_i - r_i| with the measured dx.
  for (std::size_t i = 1; i <= std::min(m, n); ++i) e += step(measured, p.measured + i) * std::abs(s(i) - r(i));
  // Simulation longer: w dx |s_i - r_n|, dx the simulation's travel.
  for (std::size_t i = n + 1; i <= m; ++i) e += w * step(sim, p.sim + i) * std::abs(s(i) - r(n));
  // Measurement longer: w dx |s_m - r_i|, dx the measurement's travel.
  if (!sim_goes_on)
    for (std::size_t i = m + 1; i <= n; ++i) e += w * step(measured, p.measured + i) * std::abs(s(m) - r(i));
  return e;
}

}  // namespace

double area_error(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured, ForceAxis axis,
                  double w) {
  return area_error_of(sim, measured, axis, w, false);
}

double area_objective(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured, double w) {
  return area_error(sim, measured, ForceAxis::Vertical, w) + area_error(sim, measured, ForceAxis::Motion, w);
}

double area_objective_so_far(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured,
                             double w) {
  if (measured.empty()) throw std::invalid_argument("objective: the measured sequence has no samples");
  if (sim.empty()) return 0.0;  // nothing simulated yet: nothing known
  return area_error_of(sim, measured, ForceAxis::Vertical, w, true) +
         area_error_of(sim, measured, ForceAxis::Motion, w, true);
}

double position_weighted_objective(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured) {
  require_samples(sim, measured);
  const double x_sim_end = sim.back().travel;
  const double x_meas_end = measured.back().travel;
  auto both = [](double dm, double dv) { return std::abs(dm) + std::abs(dv); };
  double score = 0.0;
  for (std::size_t i = 1; i < measured.size(); ++i) {
    const HapticSample& r = measured[i];
    const double dx = r.travel - measured[i - 1].travel;
    if (r.travel > x_sim_end) {
      // Measurement beyond the simulation's end: 1.5 exp(x_i + x_S) |r_i - s_end|.
      const double diff = both(r.f_motion - sim.back().f_motion, r.f_vertical - sim.back().f_vertical);
      score += 1.5 * std::exp(r.travel + x_sim_end) * diff * dx;
    } else {
      // Inside: exp(x_i) |r_i - s(x_i)|, s interpolated on the simulated travel.
      const double diff = both(r.f_motion - force_at(sim, r.travel, ForceAxis::Motion),
                               r.f_vertical - force_at(sim, r.travel, ForceAxis::Vertical));
      score += std::exp(r.travel) * diff * dx;
    }
  }
  if (x_meas_end < x_sim_end) {
    // Simulation beyond the measurement's end: 1.5 exp(x_j - x_R) |s_j - r_end| dx_j, from the
    // first simulated sample at or after x_R.
    const auto first = std::lower_bound(sim.begin(), sim.end(), x_meas_end,
                                        [](const HapticSample& s, double v) { return s.travel < v; });
    for (auto it = std::max(first, sim.begin() + 1); it != sim.end(); ++it) {
      const double diff = both(it->f_motion - measured.back().f_motion, it->f_vertical - measured.back().f_vertical);
      score += 1.5 * std::exp(it->travel - x_meas_end) * diff * (it->travel - (it - 1)->travel);
    }
  }
  return score;
}

double vertical_sign_agreement(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured,
                               double threshold) {
  require_samples(sim, measured);
  const PairedStart p = paired_start(sim, measured);
  double asked = 0.0, agreed = 0.0;
  for (std::size_t k = 1; k < p.count; ++k) {
    const HapticSample& r = measured[p.measured + k];
    if (std::abs(r.f_vertical) <= threshold) continue;
    const double dx = step(measured, p.measured + k);
    const double s = sim[p.sim + k].f_vertical;
    asked += dx;
    if ((s > 0) == (r.f_vertical > 0) && s != 0) agreed += dx;
  }
  return asked > 0 ? agreed / asked : std::numeric_limits<double>::quiet_NaN();
}

double contrast_error(const std::vector<HapticSample>& sim_high, const std::vector<HapticSample>& sim_lower,
                      const std::vector<HapticSample>& measured_high, const std::vector<HapticSample>& measured_lower,
                      double up_to) {
  require_samples(sim_high, measured_high);
  require_samples(sim_lower, measured_lower);
  const double end = std::min({up_to, sim_high.back().travel, sim_lower.back().travel, measured_high.back().travel,
                               measured_lower.back().travel});
  double e = 0.0;
  // x_j from the index, not accumulated, so that the grid is the same for every candidate.
  for (int j = 0;; ++j) {
    const double x = (j + 0.5) * kContrastStep;
    if (!(x < end)) break;
    for (ForceAxis a : {ForceAxis::Motion, ForceAxis::Vertical}) {
      const double simulated = force_at(sim_high, x, a) - force_at(sim_lower, x, a);
      const double measured = force_at(measured_high, x, a) - force_at(measured_lower, x, a);
      e += kContrastStep * std::abs(simulated - measured);
    }
  }
  return e;
}

double sequence_objective(ObjectiveKind kind, const std::vector<HapticSample>& sim,
                          const std::vector<HapticSample>& measured) {
  return kind == ObjectiveKind::Area ? area_objective(sim, measured) : position_weighted_objective(sim, measured);
}

}  // namespace dressguard::calib
