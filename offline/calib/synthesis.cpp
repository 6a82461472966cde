// Haptic data synthesis, see synthesis.h (paper section V-A).
#include "synthesis.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <sstream>

#include "files.h"

namespace dressguard::calib {

namespace fs = std::filesystem;

std::string synthesis_trial_id(ArmHeight height, int index) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "sim-%s-%03d", std::string(arm_height_name(height)).c_str(), index);
  return buf;
}

const char* middle_arm_name(MiddleArm m) { return m == MiddleArm::CaughtEdge ? "caught-edge" : "nominal"; }
const char* high_low_arm_name(HighLowArm a) { return a == HighLowArm::RepeatBand ? "repeat-band" : "paper"; }
std::optional<MiddleArm> parse_middle_arm(std::string_view s) {
  for (MiddleArm m : {MiddleArm::Nominal, MiddleArm::CaughtEdge})
    if (s == middle_arm_name(m)) return m;
  return std::nullopt;
}

std::optional<HighLowArm> parse_high_low_arm(std::string_view s) {
  for (HighLowArm a : {HighLowArm::Paper, HighLowArm::RepeatBand})
    if (s == high_low_arm_name(a)) return a;
  return std::nullopt;
}

TrialRequest synthesis_request(const Calibration& cal, ArmHeight height, int index, const SynthesisOptions& o,
                               double middle_base, const ArmBand& band) {
  const std::uint64_t key = static_cast<std::uint64_t>(height) * 1000003ull + static_cast<std::uint64_t>(index);
  const std::uint64_t stream = mix_seed(o.seed, key);
  const double u = static_cast<double>(stream >> 11) * 0x1.0p-53;  // U[0, 1)
  TrialRequest r;
  r.height = height;
  // The study's protocol: half the trials at 0.1 m/s, half at 0.15 m/s.
  r.speed = index < o.per_height / 2 ? 0.1 : 0.15;
  r.gown_noise = o.gown_noise;
  r.seed = mix_seed(stream, 1);
  r.max_travel = cal.rig_travel;  // the calibrated participant's rig (calibration.h, rig_travel_of)
  if (height == ArmHeight::Middle) {
    // Middle: noise on the nominal height (or the simulator's edge), U[-6, 0] cm (the paper's
    // gravity compensation).
    r.arm_offset = middle_base + (o.arm_noise ? kArmNoiseMiddleLow * u : 0.0);
  } else if (o.high_low == HighLowArm::RepeatBand) {
    // High and low: calibrated offset + U[lower, upper], the repeat band.
    r.arm_offset =
        cal.offsets[static_cast<int>(height)] + (o.arm_noise ? band.lower + (band.upper - band.lower) * u : 0.0);
  } else {
    // High and low: calibrated offset + U[-1.5, 1.5] cm.
    r.arm_offset = cal.offsets[static_cast<int>(height)] + (o.arm_noise ? kArmNoiseHighLow * (2.0 * u - 1.0) : 0.0);
  }
  return r;
}

MiddleEdge locate_middle_edge(const Calibration& cal, const TrialSimulator& sim, int threads, const Comm& comm,
                              double tolerance) {
  if (!(tolerance > 0)) throw std::invalid_argument("locate_middle_edge: tolerance must be positive");
  MiddleEdge e;
  // Two arm offsets (from the nominal middle) per round; result block: outcome code.
  auto outcomes = [&](double a, double b) {
    const double at[2] = {a, b};
    const std::vector<double> res = run_batch(2, 1, thread_count(threads), comm, [&](int t, double* r) {
      TrialRequest q;
      q.height = ArmHeight::Middle;
      q.arm_offset = at[t];
      q.speed = 0.1;
      q.max_travel = cal.rig_travel;
      const SimulatedTrial st = sim(cal.cloth, q);
      if (!st.finite) throw std::runtime_error("locate_middle_edge: the simulation did not stay finite");
      r[0] = static_cast<double>(st.outcome.value());
    });
    e.trials += 2;
    return std::array<Outcome, 2>{static_cast<Outcome>(static_cast<int>(res[0])),
                                  static_cast<Outcome>(static_cast<int>(res[1]))};
  };
  double hi = kMiddleBelowHigh + cal.offsets[static_cast<int>(ArmHeight::High)], lo = 0.0;
  const auto ends = outcomes(hi, lo);
  if (ends[0] != Outcome::Good || ends[1] == Outcome::Good)
    throw std::runtime_error(std::string("locate_middle_edge: no good/not-good edge between the high arm (") +
                             std::string(outcome_name(ends[0])) + ") and the nominal middle (" +
                             std::string(outcome_name(ends[1])) + "); use the nominal middle");
  Outcome below = ends[1];
  // Invariant: hi is good, lo is not.
  while (hi - lo > tolerance) {
    const double a = hi - (hi - lo) / 3.0, b = hi - 2.0 * (hi - lo) / 3.0;
    const auto o = outcomes(a, b);
    if (o[0] != Outcome::Good) {
      lo = a;
      below = o[0];
    } else if (o[1] != Outcome::Good) {
      hi = a;
      lo = b;
      below = o[1];
    } else {
      hi = b;
    }
  }
  e.offset = lo;
  e.good_at = hi;
  e.below = below;
  return e;
}

ArmBand locate_repeat_band(const Calibration& cal, const TrialSimulator& sim, ArmHeight height, int threads,
                           const Comm& comm, double step) {
  if (height == ArmHeight::Middle)
    throw std::invalid_argument("locate_repeat_band: the middle arm has no calibrated height to scan around");
  const int k_max = static_cast<int>(std::lround(kArmNoiseHighLow / step));
  if (!(step > 0) || k_max < 1)
    throw std::invalid_argument("locate_repeat_band: step must be positive and at most 1.5 cm");
  auto request = [&](double offset) {
    TrialRequest q;
    q.height = height;
    q.arm_offset = cal.offsets[static_cast<int>(height)] + offset;
    q.speed = 0.1;
    q.max_travel = cal.rig_travel;
    return q;
  };
  const char* name = height == ArmHeight::High ? "high" : "low";
  // R: every rank simulates it (deterministic, so the same bits everywhere); one trial's time.
  const SimulatedTrial reference = sim(cal.cloth, request(0.0));
  if (!reference.finite || reference.samples.empty())
    throw std::runtime_error(std::string("locate_repeat_band: the calibrated ") + name +
                             " arm's trial did not stay finite");
  ArmBand b;
  b.at_calibrated = reference.outcome.value();
  b.tolerance = b.at_calibrated == Outcome::Missed ? kRepeatDistanceMissed : kRepeatDistanceGood;
  for (int k = -k_max; k <= k_max; ++k)
    if (k != 0) b.offsets.push_back(k * step);
  const int n = static_cast<int>(b.offsets.size());
  b.distances = run_batch(n, 1, thread_count(threads), comm, [&](int t, double* r) {
    const SimulatedTrial st = sim(cal.cloth, request(b.offsets[t]));
    // A trial that blew up is as far from R as a trial can be (finite, so the band's file holds it).
    r[0] = st.finite && !st.samples.empty() ? area_objective(st.samples, reference.samples) : 1e9;
  });
  b.trials = n + 1;
  // offsets[k_max - 1] is -step, offsets[k_max] is +step: walk outwards from 0 on each side.
  b.lower = 0.0;
  for (int t = k_max - 1; t >= 0 && b.distances[t] <= b.tolerance; --t) b.lower = b.offsets[t];
  b.upper = 0.0;
  for (int t = k_max; t < n && b.distances[t] <= b.tolerance; ++t) b.upper = b.offsets[t];
  return b;
}

namespace {

// What the synthesized trials depend on, and only that: a calibration file rewritten with more
// diagnostics (axis fits, provenance) still resumes its synthesis. Version 2 of the record
// (2026-11-23); version 1 held the whole calibration file and is read through the same fields.
std::string settings_record_of(const Json& calibration, const Json& per_height, const Json& gown_noise,
                               const Json& arm_noise, const Json& seed, MiddleArm middle = MiddleArm::Nominal,
                               HighLowArm high_low = HighLowArm::Paper) {
  Json c = Json::object();
  for (const char* key : {"participant", "cloth", "arm_offsets", "gown", "rig_travel_m"})
    c.set(key, calibration.at(key));
  Json j = Json::object();
  j.set("format", "dressguard-synthesis 2");
  j.set("calibration", c);
  j.set("per_height", per_height);
  j.set("gown_noise", gown_noise);
  j.set("arm_noise", arm_noise);
  j.set("seed", seed);
  // Only when not the paper's: records written before the option existed still match.
  if (middle != MiddleArm::Nominal) j.set("middle", middle_arm_name(middle));
  if (high_low != HighLowArm::Paper) j.set("high_low", high_low_arm_name(high_low));
  return j.dump() + "\n";
}

std::string settings_record(const Calibration& cal, const SynthesisOptions& o) {
  return settings_record_of(calibration_to_json(cal), Json(o.per_height), Json(o.gown_noise), Json(o.arm_noise),
                            Json(std::to_string(o.seed)), o.middle, o.high_low);
}

// A folder's record in version 2, whichever version it was written in ("" when unreadable).
std::string stored_record(const fs::path& path) {
  const std::string text = read_file(path);
  try {
    const Json j = Json::parse(text, path);
    if (j.at("format").string() == "dressguard-synthesis 1")
      return settings_record_of(j.at("calibration"), j.at("per_height"), j.at("gown_noise"), j.at("arm_noise"),
                                j.at("seed"));
  } catch (const std::exception&) {
    return "";
  }
  return text;
}

fs::path marker_path(const fs::path& out, const std::string& id) { return out / ".synth" / (id + ".done"); }

// The marker of a trial whose simulation did not stay finite (no CSV beside it).
constexpr const char* kNotFiniteMarker = "not-finite\n";
constexpr double kNotFiniteCode = -1.0;  // its label code in the results

// A finished trial's marker: its label, then the label's evidence (d_behind d_ahead, exact), and
// a third line "unsettled" when its gown had not settled. Markers of earlier versions hold the
// label alone (their evidence reads as NaN, unknown) or no third line (taken as settled).
std::string marker_text(const SimulatedTrial& st) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s\n%.17g %.17g\n%s", std::string(outcome_name(st.outcome.value())).c_str(),
                st.d_behind, st.d_ahead, st.settled ? "" : "unsettled\n");
  return buf;
}
struct Marker {
  Outcome label = Outcome::Missed;
  double d_behind = std::numeric_limits<double>::quiet_NaN(), d_ahead = std::numeric_limits<double>::quiet_NaN();
  bool settled = true;
};
std::optional<Marker> read_marker(const fs::path& file) {
  const std::string text = read_file(file);
  const std::size_t eol = text.find('\n');
  const auto label = parse_outcome(text.substr(0, eol));
  if (!label) return std::nullopt;
  Marker m;
  m.label = *label;
  if (eol != std::string::npos) {
    double b = 0, a = 0;
    if (std::sscanf(text.c_str() + eol + 1, "%lf %lf", &b, &a) == 2) m.d_behind = b, m.d_ahead = a;
  }
  m.settled = text.find("\nunsettled\n") == std::string::npos;
  return m;
}

// labels.csv: one row per trial, what decided its label (paper V-A): the arm's offset from its
// height's nominal, the travel at the end, and the opening's lower half behind and past the
// elbow centre. An unknown value (a marker from before this file existed) is an empty field.
std::string labels_csv(const std::vector<HapticSequence>& trials, const std::vector<double>& arm_offsets,
                       const std::vector<double>& d_behind, const std::vector<double>& d_ahead) {
  std::string out = "trial_id,height,speed,arm_offset_m,label,travel_m,d_behind_m,d_ahead_m\n";
  auto num = [](double v) {
    if (std::isnan(v)) return std::string();
    char b[32];
    std::snprintf(b, sizeof b, "%.6f", v);
    return std::string(b);
  };
  for (std::size_t t = 0; t < trials.size(); ++t) {
    const HapticSequence& q = trials[t];
    out += q.id + "," + std::string(arm_height_name(q.height)) + "," + num(q.speed) + "," + num(arm_offsets[t]) + "," +
           std::string(outcome_name(*q.label)) + "," + num(q.samples.empty() ? 0.0 : q.samples.back().travel) + "," +
           num(d_behind[t]) + "," + num(d_ahead[t]) + "\n";
  }
  return out;
}

// The repeat bands of a synthesis, kept beside its markers so that a resumed run does not scan
// again (the settings record guarantees they belong to the same calibration and seed).
Json band_to_json(const ArmBand& b) {
  Json j = Json::object();
  j.set("lower_m", b.lower);
  j.set("upper_m", b.upper);
  j.set("tolerance", b.tolerance);
  j.set("at_calibrated", std::string(outcome_name(b.at_calibrated)));
  Json offsets = Json::array(), distances = Json::array();
  for (std::size_t k = 0; k < b.offsets.size(); ++k) {
    offsets.push(b.offsets[k]);
    distances.push(b.distances[k]);
  }
  j.set("offsets_m", offsets);
  j.set("distances", distances);
  j.set("trials", b.trials);
  return j;
}

ArmBand band_from_json(const Json& j, const fs::path& file) {
  ArmBand b;
  b.lower = j.at("lower_m").number();
  b.upper = j.at("upper_m").number();
  b.tolerance = j.at("tolerance").number();
  const auto at = parse_outcome(j.at("at_calibrated").string());
  if (!at) throw_input_error(file, 0, "at_calibrated is not an outcome");
  b.at_calibrated = *at;
  for (const Json& v : j.at("offsets_m").items()) b.offsets.push_back(v.number());
  for (const Json& v : j.at("distances").items()) b.distances.push_back(v.number());
  b.trials = static_cast<int>(j.at("trials").number());
  // A band is a span around the calibrated height within the paper's +-1.5 cm (locate_repeat_band
  // never writes another); an edited or damaged file must not move the synthesized arms elsewhere.
  if (!(b.lower <= 0.0 && b.upper >= 0.0 && b.lower >= -kArmNoiseHighLow - 1e-12 && b.upper <= kArmNoiseHighLow + 1e-12))
    throw_input_error(file, 0, "a band must hold 0 and lie within +-" + std::to_string(kArmNoiseHighLow) +
                                   " m (lower_m " + std::to_string(b.lower) + ", upper_m " + std::to_string(b.upper) + ")");
  return b;
}

}  // namespace

std::vector<std::string> ambiguous_labels(const fs::path& set, double margin) {
  const fs::path file = set / "labels.csv";
  if (!fs::exists(file))
    throw_input_error(file, 0,
                      "not found: --label-margin needs a set that `synthesize` wrote with its label evidence (this "
                      "one is measured, or older than labels.csv: synthesize it again)");
  std::istringstream in(read_file(file));
  std::string line;
  std::getline(in, line);
  const std::string header = "trial_id,height,speed,arm_offset_m,label,travel_m,d_behind_m,d_ahead_m";
  if (line != header) throw_input_error(file, 1, "the header is not '" + header + "'");
  std::vector<std::string> out;
  for (long n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::size_t a = 0;
    for (std::size_t b; (b = line.find(',', a)) != std::string::npos; a = b + 1) f.push_back(line.substr(a, b - a));
    f.push_back(line.substr(a));
    if (f.size() != 8) throw_input_error(file, n, "expected 8 fields, found " + std::to_string(f.size()));
    const auto label = parse_outcome(f[4]);
    if (!label) throw_input_error(file, n, "'" + f[4] + "' is not an outcome");
    if (*label == Outcome::Missed) continue;  // ran the whole travel: the 7 cm does not apply
    if (f[6].empty() || f[7].empty())
      throw_input_error(file, n, "trial " + f[0] + " stopped early but has no label evidence (its marker predates "
                                 "labels.csv): remove .synth/" + f[0] + ".done and synthesize again");
    double behind = 0, ahead = 0;
    try {
      behind = std::stod(f[6]);
      ahead = std::stod(f[7]);
    } catch (const std::exception&) {
      throw_input_error(file, n, "d_behind_m or d_ahead_m of trial " + f[0] + " is not a number");
    }
    if (std::abs(std::max(behind, ahead) - kGoodLabelDistance) < margin) out.push_back(f[0]);
  }
  return out;
}

SynthesisSummary synthesize(const Calibration& cal, const TrialSimulator& sim, const SynthesisOptions& options,
                            const fs::path& out, const Comm& comm,
                            const std::function<void(const SynthesisProgress&)>& progress) {
  if (options.per_height < 1) throw std::invalid_argument("synthesize: per_height must be at least 1");
  const auto t0 = std::chrono::steady_clock::now();
  // A folder holds one synthesis: resuming with other settings would mix two datasets.
  const std::string record = settings_record(cal, options);
  const fs::path record_path = out / "synthesis.json";
  // Nor may it be another dataset: saving replaces the manifest and removes the files only the
  // old one named (a measured dataset's trials, gone without a word).
  if (!fs::exists(record_path) && fs::exists(out / "manifest.csv"))
    throw_input_error(out / "manifest.csv", 0,
                      "this folder holds a dataset that is not a synthesis (no synthesis.json beside it); "
                      "choose another folder or remove it");
  if (fs::exists(record_path) && stored_record(record_path) != record)
    throw_input_error(record_path, 0,
                      "this folder holds a synthesis with other settings (calibration, count, noise or seed); "
                      "choose another --out or remove it");
  comm.barrier();
  // Files that rank 0 alone writes go through Comm::on_root: a rank 0 that could not write one
  // would otherwise end while the others wait for it at the next barrier, for good.
  comm.on_root([&] { write_file_atomic(record_path, record); });

  MiddleEdge edge;
  double middle_base = 0.0;
  if (options.middle == MiddleArm::CaughtEdge) {
    edge = locate_middle_edge(cal, sim, options.threads, comm);
    middle_base = edge.offset;
  }
  ArmBand high_band, low_band;
  if (options.high_low == HighLowArm::RepeatBand && options.arm_noise) {
    const fs::path band_path = out / ".synth" / "repeat-band.json";
    if (fs::exists(band_path)) {
      try {
        const Json j = Json::parse(read_file(band_path), band_path);
        high_band = band_from_json(j.at("high"), band_path);
        low_band = band_from_json(j.at("low"), band_path);
      } catch (const InputError&) {
        throw;
      } catch (const JsonError& e) {  // a key missing or of another type: name the file and line
        throw_input_error(band_path, e.line(), e.what());
      }
    } else {
      high_band = locate_repeat_band(cal, sim, ArmHeight::High, options.threads, comm);
      low_band = locate_repeat_band(cal, sim, ArmHeight::Low, options.threads, comm);
      comm.on_root([&] {
        Json j = Json::object();
        j.set("high", band_to_json(high_band));
        j.set("low", band_to_json(low_band));
        write_file_atomic(band_path, j.dump() + "\n");
      });
    }
  }
  if (!options.arm_noise) high_band.lower = high_band.upper = low_band.lower = low_band.upper = 0.0;
  auto band_of = [&](ArmHeight h) -> const ArmBand& { return h == ArmHeight::Low ? low_band : high_band; };

  const ArmHeight heights[3] = {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low};
  const int total = 3 * options.per_height;
  std::atomic<int> done{0}, skipped{0};
  std::mutex progress_mutex;
  const int mine = (total - comm.rank() + comm.size() - 1) / comm.size();
  // Result block per trial: label code, resumed flag, d_behind, d_ahead, settled flag.
  constexpr int kBlock = 5;
  const std::vector<double> res =
      run_batch(total, kBlock, thread_count(options.threads), comm, [&](int t, double* r) {
        const ArmHeight h = heights[t / options.per_height];
        const int index = t % options.per_height;
        const std::string id = synthesis_trial_id(h, index);
        const fs::path csv = out / (id + ".csv");
        const fs::path marker = marker_path(out, id);
        bool resumed = false;
        if (fs::exists(marker) && read_file(marker) == kNotFiniteMarker) {
          r[0] = kNotFiniteCode;
          resumed = true;
        } else if (fs::exists(marker) && fs::exists(csv)) {
          if (const auto m = read_marker(marker)) {
            r[0] = static_cast<double>(m->label);
            r[2] = m->d_behind;
            r[3] = m->d_ahead;
            r[4] = m->settled ? 1.0 : 0.0;
            resumed = true;
          }
        }
        if (!resumed) {
          const SimulatedTrial st = sim(cal.cloth, synthesis_request(cal, h, index, options, middle_base, band_of(h)));
          if (!st.finite || st.samples.empty()) {
            write_file_atomic(marker, kNotFiniteMarker);
            r[0] = kNotFiniteCode;
          } else {
            write_file_atomic(csv, format_trial_csv(st.samples));
            write_file_atomic(marker, marker_text(st));
            r[0] = static_cast<double>(st.outcome.value());
            r[2] = st.d_behind;
            r[3] = st.d_ahead;
            r[4] = st.settled ? 1.0 : 0.0;
          }
        }
        r[1] = resumed ? 1.0 : 0.0;
        const int d = ++done;
        if (resumed) ++skipped;
        if (progress && comm.is_root()) {
          std::lock_guard<std::mutex> lock(progress_mutex);
          SynthesisProgress p;
          p.done = d;
          p.total = mine;
          p.skipped = skipped;
          p.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          const int simulated = d - skipped;
          p.eta_s = simulated > 0 ? p.elapsed_s / simulated * (mine - d) : 0.0;
          progress(p);
        }
      });

  SynthesisSummary s;
  s.trials = total;
  s.edge = edge;
  s.high_band = high_band;
  s.low_band = low_band;
  for (int t = 0; t < total; ++t) {
    s.resumed += res[kBlock * t + 1] > 0.5;
    if (res[kBlock * t] == kNotFiniteCode) {
      s.not_finite.push_back(synthesis_trial_id(heights[t / options.per_height], t % options.per_height));
      continue;
    }
    const int label = static_cast<int>(res[kBlock * t]);
    if (res[kBlock * t + 4] < 0.5)
      s.unsettled.push_back(synthesis_trial_id(heights[t / options.per_height], t % options.per_height));
    s.per_label[label]++;
    s.per_height_label[static_cast<int>(heights[t / options.per_height])][label]++;
  }
  if (static_cast<double>(s.not_finite.size()) > kMaxNotFiniteShare * total) {
    std::string ids;
    for (std::size_t k = 0; k < s.not_finite.size() && k < 5; ++k) ids += (k ? ", " : "") + s.not_finite[k];
    throw std::runtime_error(std::to_string(s.not_finite.size()) + " of " + std::to_string(total) +
                             " trials did not stay finite (" + ids + (s.not_finite.size() > 5 ? ", ..." : "") +
                             "), more than one in twenty: the calibrated simulator is unstable where the noise "
                             "models take it; no dataset written (the finished trials are kept in " +
                             out.string() + ")");
  }
  comm.on_root([&] {
    Dataset ds;
    std::vector<double> arm_offsets, d_behind, d_ahead;
    for (int t = 0; t < total; ++t) {
      HapticSequence seq;
      const ArmHeight h = heights[t / options.per_height];
      const int index = t % options.per_height;
      if (res[kBlock * t] == kNotFiniteCode) continue;  // left out (SynthesisSummary::not_finite)
      const TrialRequest request = synthesis_request(cal, h, index, options, middle_base, band_of(h));
      seq.id = synthesis_trial_id(h, index);
      seq.participant = "";
      seq.height = h;
      seq.speed = request.speed;
      seq.label = static_cast<Outcome>(static_cast<int>(res[kBlock * t]));
      seq.samples = read_trial_csv(out / (seq.id + ".csv"));
      ds.trials.push_back(std::move(seq));
      arm_offsets.push_back(request.arm_offset);
      d_behind.push_back(res[kBlock * t + 2]);
      d_ahead.push_back(res[kBlock * t + 3]);
    }
    save_dataset(ds, out);
    write_file_atomic(out / "labels.csv", labels_csv(ds.trials, arm_offsets, d_behind, d_ahead));
  });
  s.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

}  // namespace dressguard::calib
