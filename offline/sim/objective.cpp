#include "objective.h"

#include <algorithm>
#include <cmath>

namespace dressguard::sim {
namespace {

double force(const HapticSample& s, Axis a) { return a == Axis::Motion ? s.f_motion : s.f_vertical; }

}  // namespace

double curve_error(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured, Axis axis, double w) {
  if (sim.empty() || measured.empty()) return 0;
  const size_t m = sim.size() - 1, n = measured.size() - 1;
  double e = 0;
  for (size_t i = 1; i <= std::max(n, m); ++i) {
    if (i <= m && i <= n) {
      const double dx = std::abs(measured[i].travel - measured[i - 1].travel);
      e += dx * std::abs(force(sim[i], axis) - force(measured[i], axis));
    } else if (i <= m) {
      const double dx = std::abs(sim[i].travel - sim[i - 1].travel);
      e += w * dx * std::abs(force(sim[i], axis) - force(measured[n], axis));
    } else {
      const double dx = std::abs(measured[i].travel - measured[i - 1].travel);
      e += w * dx * std::abs(force(sim[m], axis) - force(measured[i], axis));
    }
  }
  return e;
}

double paper_objective(const std::vector<HapticSample>& sim, const std::vector<HapticSample>& measured, double w) {
  return curve_error(sim, measured, Axis::Vertical, w) + curve_error(sim, measured, Axis::Motion, w);
}

}  // namespace dressguard::sim
