// How rugged the calibration objective is around a calibrated point: the noise floor under which
// two L values cannot be told apart by a search.
//
//   bench_calib_landscape --calibration CAL.json --data DATASET [--scales 0.0001,0.001,0.01]
//                         [--samples 16] [--seed 1] [--threads T] [--points FILE.csv]
//
// The file's point is simulated again on the sequences it was fitted to (the baseline of the run:
// it must give the recorded L of each sequence, to the bit). Then, for each scale s, `samples`
// points around it: every parameter the calibration searched (its provenance names them) moved by
// s times its box's width (the file's recorded box, else default_bounds) times a standard normal
// draw, clamped to the box.
// The draws are the same at every scale (common random numbers), so the scales differ in the step
// alone. Prints, per scale and sequence, the min / median / max of L, how many points keep every
// sequence at L <= 0.3 (issue 4), and the combined objective (the file's --combine) against the
// file's. A smooth objective moves in proportion to s (quadratically at a minimum); one ruled by
// the chaos of the catch (which vertex slips first past the fist) jumps even at the smallest s.
// Deterministic for one seed on one machine (std::normal_distribution is the library's).
// --points writes every point: its scale, the step of each parameter as a share of its box (after
// clamping) and each sequence's L and the combined one, for fitting models of the objective (a
// surrogate's ranking: offline/calib/MEASUREMENTS.md, session 79).
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "calibration.h"
#include "dataset.h"
#include "files.h"
#include "objective.h"
#include "runner.h"
#include "sim_bridge.h"

using namespace dressguard;
using namespace dressguard::calib;

namespace {

// One searched parameter: where it lives in (cloth, offsets) and its box.
struct Searched {
  std::string name;
  ParamRef ref;
  ParamBound box;
};

// The searched parameters the file's provenance names, each with the box the search worked in:
// the provenance's "boxes" where the file records them (calibrate, since session 40), else the
// default box (the files before it; a bounds file's boxes were not recorded then, said below).
std::vector<Searched> searched_parameters(const Calibration& cal, bool& default_boxes) {
  if (!cal.provenance.has("parameters")) throw std::runtime_error("the calibration file names no searched parameters");
  const std::vector<Json>& names = cal.provenance.at("parameters").items();
  default_boxes = !cal.provenance.has("boxes");
  if (!default_boxes && cal.provenance.at("boxes").items().size() != names.size())
    throw std::runtime_error("the calibration file's provenance has " +
                             std::to_string(cal.provenance.at("boxes").items().size()) + " boxes for " +
                             std::to_string(names.size()) + " parameters");
  const Bounds defaults = default_bounds();
  std::vector<Searched> out;
  for (std::size_t k = 0; k < names.size(); ++k) {
    const std::string& n = names[k].string();
    const std::optional<ParamRef> ref = find_param(n);
    if (!ref) throw std::runtime_error("unknown searched parameter '" + n + "' in the calibration file");
    ParamBound box = box_of(defaults, *ref);
    if (!default_boxes) {
      const std::vector<Json>& ends = cal.provenance.at("boxes").items()[k].items();
      if (ends.size() != 2 || !(ends[0].number() < ends[1].number()))
        throw std::runtime_error("the calibration file's box of " + n + " is not [lower, upper] with lower < upper");
      box.lower = ends[0].number();
      box.upper = ends[1].number();
    }
    out.push_back({n, *ref, box});
  }
  return out;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int run(int argc, char** argv) {
  std::string cal_path, data, points_path, scales_arg = "0.0001,0.001,0.01";
  int samples = 16, threads = 0;
  std::uint64_t seed = 1;
  for (int i = 1; i < argc; i += 2) {
    if (i + 1 >= argc) throw std::runtime_error(std::string("option ") + argv[i] + " needs a value");
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--calibration") cal_path = v;
    else if (k == "--data") data = v;
    else if (k == "--scales") scales_arg = v;
    else if (k == "--samples") samples = std::stoi(v);
    else if (k == "--seed") seed = std::stoull(v);
    else if (k == "--threads") threads = std::stoi(v);
    else if (k == "--points") points_path = v;
    else throw std::runtime_error("unknown option '" + k + "'");
  }
  if (cal_path.empty() || data.empty()) throw std::runtime_error("need --calibration CAL.json and --data DATASET");
  if (samples < 1) throw std::runtime_error("--samples must be at least 1");
  if (!points_path.empty() && std::filesystem::is_directory(points_path))  // said now, not after the run
    throw std::runtime_error("--points " + points_path + " is a folder; give a file name");
  std::vector<double> scales;
  for (std::size_t from = 0; from <= scales_arg.size();) {
    const std::size_t comma = std::min(scales_arg.find(',', from), scales_arg.size());
    const std::string word = scales_arg.substr(from, comma - from);
    char* end = nullptr;
    scales.push_back(std::strtod(word.c_str(), &end));
    if (word.empty() || *end != '\0' || !(scales.back() > 0 && scales.back() <= 1))
      throw std::runtime_error("each scale must be in (0, 1], not '" + word + "' (--scales " + scales_arg + ")");
    from = comma + 1;
  }

  const Calibration cal = read_calibration(cal_path);
  std::vector<std::string> ids;
  for (const SequenceFit& f : cal.fits) ids.push_back(f.trial_id);
  const std::vector<HapticSequence> inputs = inputs_by_id(load_dataset(data), cal.participant, ids);
  bool default_boxes = false;
  const std::vector<Searched> params = searched_parameters(cal, default_boxes);
  const auto combine = parse_combine(cal.combine);
  if (!combine) throw std::runtime_error("unknown combine '" + cal.combine + "' in the calibration file");
  if (default_boxes)
    std::printf("note: the file records no boxes (written before session 40): the steps use the default boxes\n");
  if (cal.contrast_weight > 0 || cal.lateral_weight > 0)
    std::printf("note: the file's contrast / lateral terms are left out of the combined L below\n");
  const ClothSimulator sim = make_cloth_simulator(cal.gown);
  const int K = static_cast<int>(inputs.size());
  const int P = static_cast<int>(params.size());

  // The draws: one standard normal vector per sample, shared by every scale.
  std::mt19937_64 rng(mix_seed(seed, 0x1a4d));
  std::normal_distribution<double> normal;
  std::vector<double> z(static_cast<std::size_t>(samples) * P);
  for (double& x : z) x = normal(rng);

  // Task 0: the file's point; task 1 + s * samples + i: scale s, sample i. Each writes K L values.
  const int S = static_cast<int>(scales.size());
  const int tasks = 1 + S * samples;
  std::printf("bench_calib_landscape: participant %s, %d sequences, %d searched parameters, %d scale(s) x %d "
              "points, %d thread(s), gown %s\n", cal.participant.c_str(), K, P, S, samples, thread_count(threads),
              cal.gown.c_str());
  for (const Searched& p : params)
    std::printf("  %-16s %10.6g in [%g, %g]\n", p.name.c_str(), param_value(p.ref, cal.cloth, cal.offsets),
                p.box.lower, p.box.upper);
  const auto t0 = std::chrono::steady_clock::now();
  // Parameter p's value at task t (t = 0: the file's point), clamped to its box (or to the file's
  // value, where that lies outside it).
  auto value_at = [&](int t, int p) {
    const double v0 = param_value(params[p].ref, cal.cloth, cal.offsets);
    if (t == 0) return v0;
    const int s = (t - 1) / samples, i = (t - 1) % samples;
    const ParamBound& box = params[p].box;
    const double lo = std::min(box.lower, v0), hi = std::max(box.upper, v0);
    return std::clamp(v0 + scales[s] * (box.upper - box.lower) * z[static_cast<std::size_t>(i) * P + p], lo, hi);
  };
  const std::vector<double> L = run_batch(tasks, K, threads, Comm::world(), [&](int t, double* out) {
    ClothValues c = cal.cloth;
    std::array<double, 3> off = cal.offsets;
    for (int p = 0; p < P; ++p) set_param_value(params[p].ref, c, off, value_at(t, p));
    const std::vector<SimulatedTrial> sts = simulate_inputs(sim.trials, c, off, inputs);
    for (int k = 0; k < K; ++k) out[k] = area_objective(sts[k].samples, inputs[k].samples);
  });
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!Comm::world().is_root()) return 0;  // under mpirun the tasks are spread; rank 0 reports

  auto combined = [&](const double* l) { return combined_objective(l, K, K, *combine); };
  std::printf("\nthe file's point, simulated again (baseline):\n");
  bool same = true;
  for (int k = 0; k < K; ++k) {
    std::printf("  %-18s L %.4f (recorded %.4f%s)\n", inputs[k].id.c_str(), L[k], cal.fits[k].objective,
                L[k] == cal.fits[k].objective ? ", the same bits" : ", DIFFERENT");
    same = same && L[k] == cal.fits[k].objective;
  }
  const double base = combined(L.data());
  std::printf("  combined (%s): %.4f\n", cal.combine.c_str(), base);

  std::printf("\n%-9s %-18s %8s %8s %8s %8s   %s\n", "scale", "sequence", "min", "median", "max", "max-min",
              "points with every L <= 0.3");
  for (int s = 0; s < S; ++s) {
    const double* first = L.data() + static_cast<std::size_t>(1 + s * samples) * K;
    int within = 0;
    std::vector<double> comb;
    for (int i = 0; i < samples; ++i) {
      const double* l = first + static_cast<std::size_t>(i) * K;
      within += std::all_of(l, l + K, [](double v) { return v <= 0.3; });
      comb.push_back(combined(l));
    }
    for (int k = 0; k < K; ++k) {
      std::vector<double> v;
      for (int i = 0; i < samples; ++i) v.push_back(first[static_cast<std::size_t>(i) * K + k]);
      const auto [mn, mx] = std::minmax_element(v.begin(), v.end());
      std::printf("%-9g %-18s %8.4f %8.4f %8.4f %8.4f%s\n", scales[s], inputs[k].id.c_str(), *mn, median(v), *mx,
                  *mx - *mn, k == K - 1 ? ("   " + std::to_string(within) + " of " + std::to_string(samples)).c_str() : "");
    }
    const auto [mn, mx] = std::minmax_element(comb.begin(), comb.end());
    const int below = static_cast<int>(std::count_if(comb.begin(), comb.end(), [&](double v) { return v < base; }));
    std::printf("%-9g %-18s %8.4f %8.4f %8.4f %8.4f   %d of %d below the file's %.4f\n", scales[s], "combined", *mn,
                median(comb), *mx, *mx - *mn, below, samples, base);
  }
  std::printf("\n%d simulations of %d sequences in %.1f s\n", tasks, K, elapsed);
  if (!points_path.empty()) {
    std::string csv = "scale,sample";
    for (const Searched& p : params) csv += ",d_" + p.name;
    for (int k = 0; k < K; ++k) csv += ",L_" + inputs[k].id;
    csv += ",L_combined\n";
    char cell[64];
    for (int t = 0; t < tasks; ++t) {
      const int s = t == 0 ? -1 : (t - 1) / samples, i = t == 0 ? 0 : (t - 1) % samples;
      std::snprintf(cell, sizeof cell, "%.17g,%d", s < 0 ? 0.0 : scales[s], i);
      csv += cell;
      for (int p = 0; p < P; ++p) {
        const double v0 = param_value(params[p].ref, cal.cloth, cal.offsets);
        std::snprintf(cell, sizeof cell, ",%.17g", (value_at(t, p) - v0) / (params[p].box.upper - params[p].box.lower));
        csv += cell;
      }
      const double* l = L.data() + static_cast<std::size_t>(t) * K;
      for (int k = 0; k < K; ++k) {
        std::snprintf(cell, sizeof cell, ",%.17g", l[k]);
        csv += cell;
      }
      std::snprintf(cell, sizeof cell, ",%.17g\n", combined(l));
      csv += cell;
    }
    write_file_atomic(points_path, csv);
    std::printf("wrote %s (%d points)\n", points_path.c_str(), tasks);
  }
  return same ? 0 : 1;  // the baseline must reproduce the file
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_calib_landscape: %s\n", e.what());
    return 2;
  }
}
