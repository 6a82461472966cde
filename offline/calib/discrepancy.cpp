#include "discrepancy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "files.h"
#include "objective.h"

namespace dressguard::calib {
namespace {

// The three forces of a sample in Discrepancy's order.
std::array<double, 3> forces(const HapticSample& s) { return {s.f_motion, s.f_lateral, s.f_vertical}; }

// r at x on one height's grid (non-empty) that the curves covered up to `end`.
std::array<double, 3> on_grid(const std::vector<std::array<double, 3>>& r, double end, const DiscrepancyOptions& o,
                              double x) {
  if (x <= 0) return r.front();
  const double u = x / o.step;
  const auto last = static_cast<double>(r.size() - 1);
  if (u >= last) {
    const double keep = std::max(0.0, 1.0 - std::max(0.0, x - std::max(end, last * o.step)) / o.fade);
    std::array<double, 3> v = r.back();
    for (double& f : v) f *= keep;
    return v;
  }
  const auto i = static_cast<std::size_t>(u);
  const double a = u - static_cast<double>(i);
  std::array<double, 3> v{};
  for (int k = 0; k < 3; ++k) v[k] = (1 - a) * r[i][k] + a * r[i + 1][k];
  return v;
}

}  // namespace

Discrepancy measure_discrepancy(const std::vector<HapticSequence>& inputs,
                                const std::vector<SimulatedTrial>& simulated, const DiscrepancyOptions& o) {
  if (inputs.size() != simulated.size())
    throw std::invalid_argument("measure_discrepancy: " + std::to_string(inputs.size()) + " inputs but " +
                                std::to_string(simulated.size()) + " simulated curves");
  if (!(o.step > 0) || !(o.window > 0) || !(o.fade > 0))
    throw std::invalid_argument("measure_discrepancy: step, window and fade must be positive");
  Discrepancy d;
  d.options = o;
  std::array<int, 3> count{};
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const auto& measured = inputs[i].samples;
    const auto& sim = simulated[i].samples;
    if (measured.empty() || sim.empty()) continue;
    // Pair k: sim[ps.sim + k] and measured[ps.measured + k], one moment of the pull.
    const PairedStart ps = paired_start(sim, measured);
    const double end = sim[ps.sim + ps.count - 1].travel;
    const int h = static_cast<int>(inputs[i].height);
    std::vector<std::array<double, 3>> r;
    for (int j = 0; j * o.step <= end; ++j) {
      const double x = j * o.step, lo = x - o.window / 2, hi = x + o.window / 2;
      std::array<double, 3> sum{};
      int n = 0;
      for (std::size_t k = 0; k < ps.count; ++k) {
        const HapticSample& s = sim[ps.sim + k];
        if (s.travel < lo || s.travel >= hi) continue;
        const auto fm = forces(measured[ps.measured + k]), fs = forces(s);
        for (int a = 0; a < 3; ++a) sum[a] += fm[a] - fs[a];
        ++n;
      }
      // A window without a pair (before a late-starting recording's first one) keeps the
      // previous grid point's value (the curves are continuous; 0 before the first).
      if (n == 0) {
        r.push_back(r.empty() ? std::array<double, 3>{} : r.back());
      } else {
        r.push_back({sum[0] / n, sum[1] / n, sum[2] / n});
      }
    }
    if (r.empty()) continue;
    auto& dst = d.by_height[h];
    if (count[h] == 0) {
      dst = r;
      d.end[h] = end;
    } else {  // a running mean over the inputs of this height, on the grid and travel they share
      d.end[h] = std::min(d.end[h], end);
      dst.resize(std::min(dst.size(), r.size()));
      for (std::size_t j = 0; j < dst.size(); ++j)
        for (int k = 0; k < 3; ++k) dst[j][k] += (r[j][k] - dst[j][k]) / (count[h] + 1);
    }
    ++count[h];
  }
  return d;
}

std::array<double, 3> discrepancy_at(const Discrepancy& d, ArmHeight h, double x) {
  const auto& own = d.by_height[static_cast<int>(h)];
  if (!own.empty()) return on_grid(own, d.end[static_cast<int>(h)], d.options, x);
  std::array<double, 3> sum{};
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    if (d.by_height[k].empty()) continue;
    const auto v = on_grid(d.by_height[k], d.end[k], d.options, x);
    for (int j = 0; j < 3; ++j) sum[j] += v[j];
    ++n;
  }
  if (n > 0)
    for (double& f : sum) f /= n;
  return sum;
}

void apply_discrepancy(const Discrepancy& d, HapticSequence& trial) {
  for (auto& s : trial.samples) {
    const auto r = discrepancy_at(d, trial.height, s.travel);
    s.f_motion += r[0];
    s.f_lateral += r[1];
    s.f_vertical += r[2];
  }
}

std::vector<HapticSequence> calibration_inputs(const Calibration& cal, const std::filesystem::path& cal_file,
                                               const Dataset& measured, const std::filesystem::path& where) {
  if (cal.fits.empty())
    throw_input_error(cal_file, 0, "records no calibrated sequence ('sequences' is empty): nothing to measure a "
                                   "discrepancy on");
  std::vector<HapticSequence> inputs;
  for (const auto& fit : cal.fits) {
    const HapticSequence* t = find_trial(measured, fit.trial_id);
    if (!t)
      throw_input_error(where, 0,
                        "holds no trial '" + fit.trial_id + "', an input of participant " + cal.participant +
                            "'s calibration (give the dataset it was calibrated on)");
    require_simulated_rate(measured, *t);
    inputs.push_back(*t);
  }
  return inputs;
}

Discrepancy discrepancy_of(const Calibration& cal, const std::vector<HapticSequence>& inputs,
                           const TrialBatchSimulator& sim, const DiscrepancyOptions& o) {
  return measure_discrepancy(inputs, simulate_inputs(sim, cal.cloth, cal.offsets, inputs), o);
}

std::string discrepancy_csv(const std::vector<std::pair<std::string, Discrepancy>>& named) {
  std::string out = "calibration,height,travel,r_motion,r_lateral,r_vertical\n";
  char line[160];
  for (const auto& [name, d] : named)
    for (int h = 0; h < 3; ++h)
      for (std::size_t j = 0; j < d.by_height[h].size(); ++j) {
        const auto& r = d.by_height[h][j];
        std::snprintf(line, sizeof line, ",%s,%.3f,%.6f,%.6f,%.6f\n",
                      std::string(arm_height_name(static_cast<ArmHeight>(h))).c_str(),
                      static_cast<double>(j) * d.options.step, r[0], r[1], r[2]);
        out += name + line;
      }
  return out;
}

}  // namespace dressguard::calib
