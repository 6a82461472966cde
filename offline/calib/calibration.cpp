// Simulator calibration, see calibration.h.
#include "calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "cmaes.h"
#include "files.h"

namespace dressguard::calib {

double cloth_value(const ClothValues& c, int i) {
  switch (i) {
    case 0: return c.stretch;
    case 1: return c.shear;
    case 2: return c.bend;
    case 3: return c.friction;
    default: return c.self_friction;
  }
}

void set_cloth_value(ClothValues& c, int i, double v) {
  switch (i) {
    case 0: c.stretch = v; break;
    case 1: c.shear = v; break;
    case 2: c.bend = v; break;
    case 3: c.friction = v; break;
    default: c.self_friction = v; break;
  }
}

double person_value(const ClothValues& c, int i) {
  switch (i) {
    case kArmCompliance: return c.arm_compliance;
    case kFistShift: return c.fist_shift;
    case kRimShift: return c.rim_shift;
    case kArmLateral: return c.arm_lateral;
    case kFistLateral: return c.fist_lateral;
    case kSupportDepth: return c.support_depth;
    case kSupportLateral: return c.support_lateral;
    default: return c.areal_density;
  }
}

void set_person_value(ClothValues& c, int i, double v) {
  switch (i) {
    case kArmCompliance: c.arm_compliance = v; break;
    case kFistShift: c.fist_shift = v; break;
    case kRimShift: c.rim_shift = v; break;
    case kArmLateral: c.arm_lateral = v; break;
    case kFistLateral: c.fist_lateral = v; break;
    case kSupportDepth: c.support_depth = v; break;
    case kSupportLateral: c.support_lateral = v; break;
    default: c.areal_density = v; break;
  }
}

Bounds default_bounds() {
  Bounds b;
  // The start is the plausibility grid's best point against participant 4
  // (offline/sim/MEASUREMENTS.md: the best of stretch {0.2, 0.6} x friction {0.2, 0.35, 0.5} at
  // bend 0.7, with the fixed arm and with the compliant one), not the simulator's defaults: from
  // it, 6 x 10 candidates at sigma0 0.1 calibrated participants 2, 4, 5, 7 to L 2.50, 1.11, 1.15,
  // 2.26 where the defaults' start (stretch 0.8, bend 0.5, friction 0.5) at sigma0 0.3 gave 3.35,
  // 1.86, 1.52, 3.45 (MEASUREMENTS.md, session 7).
  b.cloth[0] = {0.0, 1.0, 0.2};   // stretch
  b.cloth[1] = {0.0, 1.0, 0.5};   // shear
  b.cloth[2] = {0.0, 1.0, 0.7};   // bend
  b.cloth[3] = {0.0, 2.0, 0.35};  // friction
  b.cloth[4] = {0.0, 2.0, 0.2};  // self_friction
  b.arm_offset = {-0.06, 0.06, 0.0};
  b.person[kArmCompliance] = {0.0, 0.01, 0.004};
  b.person[kFistShift] = {-0.05, 0.15, 0.0};
  b.person[kRimShift] = {-0.04, 0.04, 0.0};
  b.person[kArealDensity] = {0.04, 0.25, kPaperArealDensity};
  b.person[kArmLateral] = {-0.05, 0.05, 0.0};
  b.person[kFistLateral] = {-0.05, 0.05, 0.0};
  b.person[kSupportDepth] = {0.6, 1.0, 0.85};
  b.person[kSupportLateral] = {-0.2, 0.05, -0.1};
  return b;
}

Bounds read_bounds(const std::filesystem::path& path) {
  Bounds b = default_bounds();
  std::istringstream in(read_file(path));
  std::string line;
  long n = 0;
  std::map<std::string, long> seen;  // each name's line: a second box for it is refused
  while (std::getline(in, line)) {
    ++n;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream row(line);
    std::string name;
    if (!(row >> name)) continue;  // blank or comment
    // Each number a whole finite word: `row >> double` stopped at "initial=0.4" and the line was
    // taken with its midpoint as the start (session 84's review, finding 3).
    std::vector<std::string> words;
    for (std::string w; words.size() < 3 && row >> w;) words.push_back(w);
    if (words.size() < 2) throw_input_error(path, n, "expected 'name lower upper [initial]'");
    std::string extra;
    if (row >> extra) throw_input_error(path, n, "unexpected '" + extra + "' after the bounds of " + name);
    auto number = [&](const std::string& word, const char* what) {
      char* end = nullptr;
      const double v = std::strtod(word.c_str(), &end);
      if (end != word.c_str() + word.size() || !std::isfinite(v))
        throw_input_error(path, n, std::string(what) + " of " + name + ": '" + word + "' is not a number");
      return v;
    };
    ParamBound pb;
    pb.lower = number(words[0], "lower bound");
    pb.upper = number(words[1], "upper bound");
    if (!(pb.lower < pb.upper)) throw_input_error(path, n, "lower bound must be below upper bound for " + name);
    pb.initial = words.size() == 3 ? number(words[2], "initial value") : 0.5 * (pb.lower + pb.upper);
    pb.line = n;
    if (pb.initial < pb.lower || pb.initial > pb.upper)
      throw_input_error(path, n, "initial value of " + name + " is outside its bounds");
    if (const auto [at, fresh] = seen.emplace(name, n); !fresh)
      throw_input_error(path, n, name + " was given on line " + std::to_string(at->second) + " already");
    // The heights share one box, named "arm_offset" here; find_param knows each height's name.
    std::optional<ParamRef> ref = ParamRef{ParamRef::Kind::Offset, 0};
    if (name != "arm_offset") {
      ref = find_param(name);
      if (ref && ref->kind == ParamRef::Kind::Offset)
        throw_input_error(path, n, "the heights' offsets share one box: name it arm_offset, not " + name);
    }
    if (!ref) {
      std::string known = "stretch, shear, bend, friction, self_friction, arm_offset";
      for (const PersonParamInfo& info : kPersonParamInfo) known += std::string(", ") + info.name;
      throw_input_error(path, n, "unknown parameter '" + name + "' (expected " + known + ")");
    }
    if (ref->kind == ParamRef::Kind::Offset && (pb.lower < -kMaxArmOffset || pb.upper > kMaxArmOffset))
      throw_input_error(path, n, "arm_offset must lie within +-" + std::to_string(kMaxArmOffset).substr(0, 3) +
                                     " m (a calibration file holds no more)");
    if (ref->kind == ParamRef::Kind::Person) {
      const PersonParamInfo& info = kPersonParamInfo[ref->index];
      if (pb.lower < info.lowest || pb.upper > info.highest) throw_input_error(path, n, name + " " + info.range);
    }
    if (ref->kind == ParamRef::Kind::Cloth) {
      const ClothParamLimits& lim = kClothParamLimits[ref->index];
      if (pb.lower < lim.lowest || pb.upper > lim.highest) throw_input_error(path, n, name + " " + lim.range);
    }
    box_of(b, *ref) = pb;
  }
  return b;
}

namespace {
double to_unit(const ParamBound& b, double v) { return (v - b.lower) / (b.upper - b.lower); }
// u is within [0, 1] (CMA-ES hands out repaired points); the clamp keeps the rounding of u = 1
// from landing past the box (-0.05 + 1 x 0.2 = 0.15000000000000002), where --start refuses it.
double from_unit(const ParamBound& b, double u) {
  return std::clamp(b.lower + u * (b.upper - b.lower), b.lower, b.upper);
}
}  // namespace

Eigen::VectorXd ParameterSpace::initial_unit() const {
  Eigen::VectorXd x(dimension());
  for (int i = 0; i < kClothParams; ++i) x[i] = to_unit(bounds.cloth[i], bounds.cloth[i].initial);
  for (std::size_t k = 0; k < offset_heights.size(); ++k)
    x[kClothParams + static_cast<long>(k)] =
        to_unit(bounds.arm_offset, bounds.offset_initial[static_cast<int>(offset_heights[k])].value_or(bounds.arm_offset.initial));
  long k = kClothParams + static_cast<long>(offset_heights.size());
  for (int i = 0; i < kPersonParams; ++i)
    if (person[i].fit) x[k++] = to_unit(bounds.person[i], bounds.person[i].initial);
  return x;
}

ClothValues ParameterSpace::cloth(const Eigen::VectorXd& unit) const {
  ClothValues c;
  for (int i = 0; i < kClothParams; ++i) set_cloth_value(c, i, from_unit(bounds.cloth[i], unit[i]));
  long k = kClothParams + static_cast<long>(offset_heights.size());
  for (int i = 0; i < kPersonParams; ++i)
    set_person_value(c, i, person[i].fit ? from_unit(bounds.person[i], unit[k++]) : person[i].value);
  c.hem_width = hem_width;
  c.hem_bend_ratio = hem_bend_ratio;
  c.friction_scheme = friction_scheme;
  return c;
}

bool friction_scheme_known(const std::string& name) {
  return std::find(kFrictionSchemes.begin(), kFrictionSchemes.end(), name) != kFrictionSchemes.end();
}

std::string friction_scheme_choices() {
  std::string s;
  for (std::size_t k = 0; k < kFrictionSchemes.size(); ++k) {
    if (k > 0) s += k + 1 == kFrictionSchemes.size() ? " or " : ", ";
    s += kFrictionSchemes[k];
  }
  return s;
}

std::array<double, 3> ParameterSpace::offsets(const Eigen::VectorXd& unit) const {
  std::array<double, 3> o{};
  for (std::size_t k = 0; k < offset_heights.size(); ++k)
    o[static_cast<int>(offset_heights[k])] = from_unit(bounds.arm_offset, unit[kClothParams + static_cast<long>(k)]);
  return o;
}

std::vector<std::string> ParameterSpace::names() const {
  std::vector<std::string> n(kClothParamNames.begin(), kClothParamNames.end());
  for (ArmHeight h : offset_heights) n.push_back("arm_offset_" + std::string(arm_height_name(h)));
  for (int i = 0; i < kPersonParams; ++i)
    if (person[i].fit) n.push_back(kPersonParamInfo[i].name);
  return n;
}

std::vector<ParamBound> ParameterSpace::boxes() const {
  std::vector<ParamBound> out;
  for (const std::string& n : names()) out.push_back(box_of(bounds, *find_param(n)));
  return out;
}

std::optional<ParamRef> find_param(std::string_view name) {
  for (int i = 0; i < kClothParams; ++i)
    if (name == kClothParamNames[i]) return ParamRef{ParamRef::Kind::Cloth, i};
  for (int i = 0; i < kPersonParams; ++i)
    if (name == kPersonParamInfo[i].name) return ParamRef{ParamRef::Kind::Person, i};
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low})
    if (name == "arm_offset_" + std::string(arm_height_name(h))) return ParamRef{ParamRef::Kind::Offset, static_cast<int>(h)};
  return std::nullopt;
}

double param_value(const ParamRef& p, const ClothValues& c, const std::array<double, 3>& offsets) {
  switch (p.kind) {
    case ParamRef::Kind::Cloth: return cloth_value(c, p.index);
    case ParamRef::Kind::Person: return person_value(c, p.index);
    case ParamRef::Kind::Offset: return offsets[p.index];
  }
  return 0.0;
}

void set_param_value(const ParamRef& p, ClothValues& c, std::array<double, 3>& offsets, double v) {
  switch (p.kind) {
    case ParamRef::Kind::Cloth: set_cloth_value(c, p.index, v); break;
    case ParamRef::Kind::Person: set_person_value(c, p.index, v); break;
    case ParamRef::Kind::Offset: offsets[p.index] = v; break;
  }
}

const ParamBound& box_of(const Bounds& b, const ParamRef& p) {
  switch (p.kind) {
    case ParamRef::Kind::Cloth: return b.cloth[p.index];
    case ParamRef::Kind::Person: return b.person[p.index];
    case ParamRef::Kind::Offset: break;
  }
  return b.arm_offset;  // the heights share one box
}

ParamBound& box_of(Bounds& b, const ParamRef& p) {
  return const_cast<ParamBound&>(box_of(std::as_const(b), p));  // one switch for both
}

bool set_person_param(ParameterSpace& space, int i, const std::string& word) {
  if (word == "fit") {
    space.person[i].fit = true;
    return true;
  }
  double v = kPersonParamInfo[i].paper;
  if (word != "fixed") {
    char* end = nullptr;
    v = std::strtod(word.c_str(), &end);
    if (word.empty() || *end != '\0' || !std::isfinite(v) || v < kPersonParamInfo[i].lowest ||
        v > kPersonParamInfo[i].highest)
      return false;
  }
  space.person[i] = {false, v};
  return true;
}

std::vector<double> grasp_probes(double lower, double upper) {
  const int gaps = std::max(1, static_cast<int>(std::ceil((upper - lower) / kGraspProbeStep - 1e-9)));
  std::vector<double> at;
  for (int i = 0; i <= gaps; ++i) at.push_back(i == gaps ? upper : lower + i * (upper - lower) / gaps);
  return at;
}

bool fit_rim_shift_to_gown(ParameterSpace& space, double rim_ahead, const std::filesystem::path& bounds_file) {
  const PersonParamInfo& info = kPersonParamInfo[kRimShift];
  const ParameterSpace::Person& p = space.person[kRimShift];
  ParamBound& box = space.bounds.person[kRimShift];
  const double lowest = -rim_ahead;
  const std::string why = "this gown's sleeve opening is held " + format_number(rim_ahead) +
                          " m ahead of the jaws, so a rim_shift below " + format_number(lowest) +
                          " m puts it behind them";
  if (!p.fit) {
    if (p.value < lowest) throw std::invalid_argument(why + ", not " + format_number(p.value) + " m");
    return false;
  }
  if (box.lower >= lowest) return false;
  if (box.line > 0)
    throw_input_error(bounds_file, box.line, std::string(info.name) + "'s box starts at " +
                                                 format_number(box.lower) + " m: " + why);
  if (box.initial < lowest)
    throw std::invalid_argument("its start " + format_number(box.initial) + " m is below " + format_number(lowest) +
                                " m: " + why);
  box.lower = lowest;
  return true;
}

void require_simulated_rate(const Dataset& ds, const HapticSequence& t) {
  const double period = mean_sample_period(t);
  if (!(period > 0.0)) return;  // fewer than two samples, no period (a dataset's readers refuse it)
  if (std::abs(period - kSimulatedSamplePeriod) <= kRecordingPeriodTolerance * kSimulatedSamplePeriod) return;
  char what[200];
  std::snprintf(what, sizeof what,
                " is sampled every %.9g s and the simulator every %g s: eq. 3-5 pairs the two curves sample by "
                "sample (resample it to %g Hz)",
                period, kSimulatedSamplePeriod, 1.0 / kSimulatedSamplePeriod);
  throw InputError(trial_file_name(ds, t) + what);
}

std::vector<HapticSequence> select_inputs(const Dataset& ds, const std::string& participant, std::uint64_t seed) {
  std::vector<HapticSequence> out;
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low}) {
    std::vector<const HapticSequence*> pool;
    for (const auto& t : ds.trials)
      if (t.participant == participant && t.height == h && t.label && *t.label != Outcome::Caught) pool.push_back(&t);
    if (pool.empty()) continue;  // e.g. a middle height with only caught trials: 2 sequences
    std::sort(pool.begin(), pool.end(), [](auto* a, auto* b) { return a->id < b->id; });
    const std::uint64_t pick = mix_seed(seed, 100 + static_cast<std::uint64_t>(h)) % pool.size();
    require_simulated_rate(ds, *pool[pick]);
    out.push_back(*pool[pick]);
  }
  if (out.empty())
    throw InputError("participant '" + participant + "' has no labelled good or missed trial in the dataset");
  return out;
}

std::vector<HapticSequence> inputs_by_id(const Dataset& ds, const std::string& participant,
                                         const std::vector<std::string>& ids) {
  if (ids.empty()) throw InputError("no trial named: give one to three trial ids, one per arm height");
  std::array<const HapticSequence*, 3> by_height{};  // the chosen trial of each ArmHeight
  for (const std::string& id : ids) {
    const auto t = std::find_if(ds.trials.begin(), ds.trials.end(), [&](const auto& s) { return s.id == id; });
    if (t == ds.trials.end()) throw InputError("trial '" + id + "' is not in the dataset");
    if (t->participant != participant)
      throw InputError("trial '" + id + "' is participant " + t->participant + "'s, not " + participant + "'s");
    if (!t->label) throw InputError("trial '" + id + "' has no outcome label");
    if (*t->label == Outcome::Caught)
      throw InputError("trial '" + id + "' is caught; calibration fits good and missed trials only (IV-B.1)");
    require_simulated_rate(ds, *t);
    const HapticSequence*& slot = by_height[static_cast<int>(t->height)];
    if (slot)
      throw InputError("trials '" + slot->id + "' and '" + id + "' are both at the " +
                       std::string(arm_height_name(t->height)) + " arm; give one per height (IV-B.1)");
    slot = &*t;
  }
  std::vector<HapticSequence> out;
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low})
    if (by_height[static_cast<int>(h)]) out.push_back(*by_height[static_cast<int>(h)]);
  return out;
}

TrialRequest request_for(const HapticSequence& input, const std::array<double, 3>& offsets) {
  TrialRequest r;
  r.height = input.height;
  r.arm_offset = offsets[static_cast<int>(input.height)];
  r.speed = input.speed;
  r.seed = 0;
  r.gown_noise = false;
  r.max_travel = rig_end_of_travel(input.samples, r.max_travel);
  return r;
}

std::vector<SimulatedTrial> simulate_inputs(const TrialBatchSimulator& sim, const ClothValues& cloth,
                                            const std::array<double, 3>& offsets,
                                            const std::vector<HapticSequence>& inputs,
                                            const std::vector<TrialWatch>& watches) {
  if (!watches.empty() && watches.size() != inputs.size())
    throw std::logic_error("simulate_inputs: one watch per input, or none");
  std::vector<TrialRequest> rs;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    rs.push_back(request_for(inputs[k], offsets));
    if (!watches.empty()) rs.back().watch = watches[k];
  }
  std::vector<SimulatedTrial> sts = sim(cloth, rs);
  if (sts.size() != inputs.size()) throw std::logic_error("calibrate: the simulator returned a wrong count");
  return sts;
}

bool stopped_by_force(const HapticSequence& s) { return ended_at_force_limit(s.samples); }

double rig_travel_of(const std::vector<HapticSequence>& inputs) {
  double travel = 0;
  for (const auto& s : inputs)
    if (!stopped_by_force(s) && !s.samples.empty()) travel = std::max(travel, s.samples.back().travel);
  return travel > 0 ? travel : 0.85;
}

Calibration calibration_of(const std::string& participant, const CalibrationResult& r,
                           const ParameterSpace& space, const CalibrationOptions& o,
                           const std::vector<HapticSequence>& inputs) {
  Calibration cal;
  cal.participant = participant;
  cal.cloth = r.cloth;
  cal.offsets = r.offsets;
  for (ArmHeight h : space.offset_heights) cal.offset_calibrated[static_cast<int>(h)] = true;
  cal.objective = r.objective;
  cal.fits = r.fits;
  cal.contrast_weight = o.contrast_weight;
  cal.contrast = r.contrast;
  cal.lateral_weight = o.lateral_weight;
  cal.lateral = r.lateral;
  cal.objective_kind = std::string(objective_name(o.objective));
  cal.combine = std::string(combine_name(o.combine));
  cal.gown = o.gown;
  cal.rig_travel = rig_travel_of(inputs);
  return cal;
}

void rescore(Calibration& c, const std::vector<HapticSequence>& inputs, const std::vector<SimulatedTrial>& simulated,
             const std::string& why, const std::string& when) {
  if (inputs.size() != c.fits.size() || simulated.size() != inputs.size())
    throw std::invalid_argument("rescore: the file has " + std::to_string(c.fits.size()) + " sequences, given " +
                                std::to_string(inputs.size()) + " inputs and " + std::to_string(simulated.size()) +
                                " simulated trials");
  const auto kind = parse_objective(c.objective_kind);
  const auto combine = parse_combine(c.combine);
  if (!kind || !combine)
    throw std::invalid_argument("rescore: unknown objective '" + c.objective_kind + "' or combination '" + c.combine +
                                "'");
  // A curve that blew up scores infinity, which a calibration file cannot hold (JSON has no inf:
  // it was written as null, and read_calibration refused the file it had just written).
  for (std::size_t k = 0; k < inputs.size(); ++k)
    if (!simulated[k].finite || simulated[k].samples.empty())
      throw std::runtime_error("rescore: " + inputs[k].id + "'s simulation did not stay finite in this build, so its "
                               "L would be infinite; the file's values give no calibration here");
  Json before = Json::object();
  before.set("objective", c.objective);
  Json fits = Json::object();
  std::vector<double> terms;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    if (inputs[k].id != c.fits[k].trial_id)
      throw std::invalid_argument("rescore: input " + std::to_string(k) + " is " + inputs[k].id + ", the file's is " +
                                  c.fits[k].trial_id);
    fits.set(c.fits[k].trial_id, c.fits[k].objective);
    c.fits[k].objective = sequence_term(*kind, simulated[k], inputs[k]);
    terms.push_back(c.fits[k].objective);
  }
  before.set("fits", fits);
  before.set("contrast", c.contrast);
  before.set("lateral", c.lateral);
  c.contrast = contrast_term(inputs, simulated, c.contrast_weight);
  c.lateral = lateral_term(inputs, simulated, c.lateral_weight);
  if (c.contrast_weight > 0) terms.push_back(c.contrast);
  if (c.lateral_weight > 0) terms.push_back(c.lateral);
  c.objective = combined_objective(terms.data(), static_cast<int>(inputs.size()), static_cast<int>(terms.size()),
                                   *combine);
  measure_axis_fits(c.fits, inputs, simulated);
  Json r = Json::object();
  r.set("when", when);
  r.set("why", why);
  r.set("before", before);
  // A file rescored twice keeps the first figures too: each entry says what it replaced.
  Json history = c.provenance.has("rescored") ? c.provenance.at("rescored") : Json::array();
  history.push(r);
  c.provenance.set("rescored", history);
}

// ---- one candidate's objective ------------------------------------------------------------------

double sequence_term(ObjectiveKind kind, const SimulatedTrial& st, const HapticSequence& measured) {
  if (!st.finite || st.samples.empty()) return std::numeric_limits<double>::infinity();
  if (st.cut && kind != ObjectiveKind::Area)
    throw std::logic_error("sequence_term: a cut trial has a lower bound only under the area objective");
  const double v = st.cut ? area_objective_so_far(st.samples, measured.samples)
                          : sequence_objective(kind, st.samples, measured.samples);
  return std::isfinite(v) ? v : std::numeric_limits<double>::infinity();
}

std::string_view combine_name(SequenceCombine c) {
  switch (c) {
    case SequenceCombine::Worst: return "worst";
    case SequenceCombine::Bar: return "bar";
    case SequenceCombine::Count: return "count";
    case SequenceCombine::Sum: break;
  }
  return "sum";
}

std::optional<SequenceCombine> parse_combine(std::string_view s) {
  for (auto c : {SequenceCombine::Sum, SequenceCombine::Worst, SequenceCombine::Bar,
                 SequenceCombine::Count})
    if (s == combine_name(c)) return c;
  return std::nullopt;
}

double combined_objective(const double* terms, int K, int T, SequenceCombine c) {
  double sum = 0.0, worst = -std::numeric_limits<double>::infinity(), excess = 0.0;
  int over = 0;
  for (int k = 0; k < K; ++k) {
    if (!std::isfinite(terms[k])) return std::numeric_limits<double>::infinity();
    sum += terms[k];
    worst = std::max(worst, terms[k]);
    excess += std::max(0.0, terms[k] - kSequenceBar);
    over += terms[k] > kSequenceBar;
  }
  // Sum: the same additions in the same order as before the option existed (shipped files keep
  // their bits).
  double f = sum;
  if (c == SequenceCombine::Worst) f = worst + kWorstRho * sum;
  if (c == SequenceCombine::Bar) f = excess + kWorstRho * sum;
  if (c == SequenceCombine::Count) f = over + (excess + kWorstRho * sum);
  for (int k = K; k < T; ++k) f += terms[k];
  return std::isfinite(f) ? f : std::numeric_limits<double>::infinity();
}

// ---- checkpoint ---------------------------------------------------------------------------------

namespace {

constexpr const char* kCheckpointMagic = "dressguard-calibration-checkpoint";

std::string hexd(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

// Whether the search has scored any candidate finitely: CMA-ES keeps its initial best_f (1e300)
// until then, as it ranks a failed evaluation as DBL_MAX.
bool found(const Cmaes& es) { return es.best_f() < CmaesState{}.best_f; }

// [s] the cloth time a candidate's simulated inputs cost (SimulatedTrial::simulated_s).
double simulated_time(const std::vector<SimulatedTrial>& sts) {
  double s = 0.0;
  for (const SimulatedTrial& t : sts) s += t.simulated_s;
  return s;
}

// Every rank runs ask() and tell() itself and they must agree to the bit: the candidates a rank
// simulates are its share of its own ask(). On one machine kind they do (runner.h); nodes of
// different kinds need not, since glibc picks exp, log and pow variants by CPU (with or without
// FMA), and diverged ranks would then simulate shares of different generations and sum them
// into a search that no one ran, without a sign. So after each tell() every rank compares its
// state (the checkpoint's exact text) with rank 0's, and all end when any differs. One
// broadcast of a few kB a generation, beside minutes of simulation.
void require_one_state(const Cmaes& es, const Comm& comm, int generation) {
  if (comm.size() == 1) return;
  const std::string mine = es.save_state();
  std::string root = mine;
  comm.broadcast(root);
  std::vector<double> differ{root == mine ? 0.0 : 1.0};
  comm.allreduce_sum(differ);
  if (differ[0] > 0)
    throw std::runtime_error("generation " + std::to_string(generation) + ": the CMA-ES state of " +
                             std::to_string(static_cast<int>(differ[0])) + " of " + std::to_string(comm.size()) +
                             " ranks differs from rank 0's (this rank's " + (root == mine ? "agrees" : "differs") +
                             "): the ranks compute differently (nodes of different CPU kinds, or other arguments); "
                             "run on one node kind");
}

// What must match for a checkpoint to continue this run.
std::string fingerprint(const std::vector<HapticSequence>& inputs, const ParameterSpace& space,
                        const CalibrationOptions& o) {
  std::ostringstream f;
  f << "seed=" << o.seed << ";population=" << o.population << ";generations=" << o.generations
    << ";sigma0=" << hexd(o.sigma0) << ";objective=" << objective_name(o.objective);
  if (o.contrast_weight > 0) f << ";contrast=" << hexd(o.contrast_weight);  // (older checkpoints resume)
  if (o.lateral_weight > 0) f << ";lateral=" << hexd(o.lateral_weight);     // likewise
  if (o.combine != SequenceCombine::Sum) f << ";combine=" << combine_name(o.combine);  // likewise
  // The gown when it is not the default reduced one (likewise). Before session 49 it was not
  // carried, and a reduced-gown checkpoint would have resumed a full-gown run.
  if (o.gown != "reduced") f << ";gown=" << o.gown;
  if (o.prune > 0) f << ";prune=" << hexd(o.prune);  // likewise
  f << ";names=";
  for (const auto& n : space.names()) f << n << ',';
  f << ";bounds=";
  for (const auto& b : space.bounds.cloth) f << hexd(b.lower) << ',' << hexd(b.upper) << ',' << hexd(b.initial) << ',';
  f << hexd(space.bounds.arm_offset.lower) << ',' << hexd(space.bounds.arm_offset.upper) << ','
    << hexd(space.bounds.arm_offset.initial);
  // Per-height starts only when there are any (older checkpoints resume).
  for (int h = 0; h < 3; ++h)
    if (space.bounds.offset_initial[h])
      f << ",offset" << h << '=' << hexd(*space.bounds.offset_initial[h]);
  // A person parameter only when it is fitted or held at other than the paper's value (older
  // checkpoints resume; those of runs with a held density, before it could be fitted, do not).
  for (int i = 0; i < kPersonParams; ++i) {
    const ParamBound& b = space.bounds.person[i];
    if (space.person[i].fit)
      f << ',' << kPersonParamInfo[i].name << ':' << hexd(b.lower) << ',' << hexd(b.upper) << ',' << hexd(b.initial);
    else if (space.person[i].value != kPersonParamInfo[i].paper)
      f << ',' << kPersonParamInfo[i].name << '=' << hexd(space.person[i].value);
  }
  // The cuff only when there is one (older checkpoints resume).
  if (space.hem_width > 0) f << ";hem=" << hexd(space.hem_width) << ',' << hexd(space.hem_bend_ratio);
  // The friction scheme only when it is not the paper's (older checkpoints resume).
  if (space.friction_scheme != kFrictionSchemes[0]) f << ";friction=" << space.friction_scheme;
  f << ";inputs=";
  for (const auto& s : inputs) f << s.id << '/' << s.samples.size() << ',';
  return f.str();
}

// The inputs' arm heights and pull speeds, which request_for simulates them at: a manifest whose
// row was corrected (a speed, a height) changes the run as much as its samples would.
std::string inputs_runs(const std::vector<HapticSequence>& inputs) {
  std::string out;
  for (const auto& s : inputs) out += std::string(arm_height_name(s.height)) + '@' + hexd(s.speed) + ',';
  return out;
}

// Which part of two fingerprints differs first (their ';'-separated "key=value" fields), for the
// refusal to say what is another run: "its seed= (here 12, in the checkpoint 11)".
std::string first_difference(const std::string& here, const std::string& there) {
  const auto fields = [](const std::string& f) {
    std::vector<std::string> out;
    std::size_t b = 0;
    for (std::size_t e; (e = f.find(';', b)) != std::string::npos; b = e + 1) out.push_back(f.substr(b, e - b));
    out.push_back(f.substr(b));
    return out;
  };
  const auto key_of = [](const std::string& field) { return field.substr(0, field.find('=') + 1); };
  const auto cut = [](const std::string& v) { return v.size() > 60 ? v.substr(0, 57) + "..." : v; };
  const std::vector<std::string> a = fields(here), b = fields(there);
  for (const std::string& x : a) {
    const auto y = std::find_if(b.begin(), b.end(), [&](const std::string& f) { return key_of(f) == key_of(x); });
    if (y == b.end()) return "its " + key_of(x) + " (here " + cut(x.substr(key_of(x).size())) + ", not in the checkpoint)";
    if (*y != x)
      return "its " + key_of(x) + " (here " + cut(x.substr(key_of(x).size())) + ", in the checkpoint " +
             cut(y->substr(key_of(x).size())) + ")";
  }
  for (const std::string& y : b)
    if (std::none_of(a.begin(), a.end(), [&](const std::string& f) { return key_of(f) == key_of(y); }))
      return "the checkpoint's " + key_of(y) + " (" + cut(y.substr(key_of(y).size())) + ", not set here)";
  return "nothing that can be named";
}

// FNV-1a (64 bits) over the bit patterns of every sample of the inputs: a checkpoint's inputs are
// the same data, not only the same trial ids and lengths (a corrected file once resumed).
std::string samples_hash(const std::vector<HapticSequence>& inputs) {
  uint64_t h = 0xcbf29ce484222325ULL;
  const auto mix = [&h](double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    for (int k = 0; k < 8; ++k) h = (h ^ ((bits >> (8 * k)) & 0xFF)) * 0x100000001b3ULL;
  };
  for (const auto& seq : inputs)
    for (const auto& x : seq.samples) {
      mix(x.t);
      mix(x.travel);
      mix(x.f_motion);
      mix(x.f_lateral);
      mix(x.f_vertical);
    }
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

struct Checkpoint {
  std::string fingerprint;
  int generations_done = 0;
  std::vector<double> best_fits;
  std::string cmaes_state;
};

std::string encode_checkpoint(const Checkpoint& c) {
  std::ostringstream o;
  o << kCheckpointMagic << " 1\n" << "fingerprint " << c.fingerprint << "\n"
    << "generations_done " << c.generations_done << "\n" << "best_fits " << c.best_fits.size();
  for (double v : c.best_fits) o << ' ' << hexd(v);
  o << "\ncmaes\n" << c.cmaes_state;
  return o.str();
}

Checkpoint decode_checkpoint(const std::string& text, const std::filesystem::path& path) {
  std::istringstream in(text);
  Checkpoint c;
  std::string word;
  int version = 0;
  if (!(in >> word >> version) || word != kCheckpointMagic || version != 1)
    throw_input_error(path, 1, "not a dressguard calibration checkpoint (version 1)");
  if (!(in >> word) || word != "fingerprint") throw_input_error(path, 2, "expected 'fingerprint'");
  in.get();
  std::getline(in, c.fingerprint);
  std::size_t nfits = 0;
  if (!(in >> word >> c.generations_done) || word != "generations_done" || c.generations_done < 0)
    throw_input_error(path, 3, "expected 'generations_done' and a count of 0 or more");
  if (!(in >> word >> nfits) || word != "best_fits" || nfits > 16) throw_input_error(path, 4, "expected 'best_fits'");
  c.best_fits.resize(nfits);
  for (auto& v : c.best_fits) {
    if (!(in >> word)) throw_input_error(path, 4, "truncated best_fits");
    // A fit is an area between curves (eq. 3-5): not negative; infinite until the search found a
    // candidate it could simulate.
    char* end = nullptr;
    v = std::strtod(word.c_str(), &end);
    if (end != word.c_str() + word.size() || !(v >= 0))
      throw_input_error(path, 4, "best_fits: '" + word + "' is not a fit (a number of 0 or more, or inf)");
  }
  if (!(in >> word) || word != "cmaes") throw_input_error(path, 5, "expected 'cmaes'");
  in.get();
  std::ostringstream rest;
  rest << in.rdbuf();
  c.cmaes_state = rest.str();
  return c;
}

}  // namespace

std::vector<int> cut_candidates_to_finish(const Cmaes& es, const std::vector<double>& f, const std::vector<char>& cut) {
  // The cut candidates that must be whole for the mu lowest of `v` to be whole ones: the lowest
  // first, `mu minus the whole ones at or below every cut one` of them.
  auto needed_by = [&](const std::vector<double>& v) {
    std::vector<int> cuts;
    for (std::size_t c = 0; c < v.size(); ++c)
      if (cut[c]) cuts.push_back(static_cast<int>(c));
    if (cuts.empty()) return cuts;
    std::stable_sort(cuts.begin(), cuts.end(), [&](int a, int b) { return v[a] < v[b]; });
    int below = 0;
    for (std::size_t c = 0; c < v.size(); ++c) below += !cut[c] && v[c] <= v[cuts.front()] ? 1 : 0;
    const int need = std::min(es.mu() - below, static_cast<int>(cuts.size()));
    cuts.resize(static_cast<std::size_t>(std::max(need, 0)));
    return cuts;
  };
  std::vector<int> out = needed_by(es.ranking_values(f));  // those that set the mean
  for (int c : needed_by(f))                                 // the best point and its L
    if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
  return out;
}

void probe_checkpoint(const std::filesystem::path& path, const Comm& comm) {
  try {
    comm.on_root([&] {
      if (std::filesystem::is_directory(path)) throw std::runtime_error("it is a folder");
      std::filesystem::path probe = path;
      probe += ".probe";
      write_file_atomic(probe, "");
      std::filesystem::remove(probe);
    });
  } catch (const std::exception& e) {
    throw_input_error(path, 0, "cannot write a checkpoint there: " + std::string(e.what()));
  }
}

TrialBatchSimulator one_by_one(TrialSimulator sim) {
  return [sim = std::move(sim)](const ClothValues& c, const std::vector<TrialRequest>& rs) {
    std::vector<SimulatedTrial> out;
    out.reserve(rs.size());
    for (const TrialRequest& r : rs) out.push_back(sim(c, r));
    return out;
  };
}

double contrast_term(const std::vector<HapticSequence>& inputs, const std::vector<SimulatedTrial>& simulated,
                     double weight) {
  if (!(weight > 0)) return 0.0;
  const auto high = std::find_if(inputs.begin(), inputs.end(), [](const HapticSequence& s) {
    return s.height == ArmHeight::High;
  });
  if (high == inputs.end()) return 0.0;
  const std::size_t h = static_cast<std::size_t>(high - inputs.begin());
  double c = 0.0;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    if (inputs[k].height == ArmHeight::High) continue;
    const SimulatedTrial& sh = simulated[h];
    const SimulatedTrial& sk = simulated[k];
    // A blown-up simulation scores infinity, as in eq. 3-5.
    if (!sh.finite || !sk.finite || sh.samples.empty() || sk.samples.empty())
      return std::numeric_limits<double>::infinity();
    c += contrast_error(sh.samples, sk.samples, inputs[h].samples, inputs[k].samples, kLatestCut);
  }
  return weight * c;
}

double lateral_term(const std::vector<HapticSequence>& inputs, const std::vector<SimulatedTrial>& simulated,
                    double weight) {
  if (!(weight > 0)) return 0.0;
  double l = 0.0;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const SimulatedTrial& s = simulated[k];
    if (!s.finite || s.samples.empty()) return std::numeric_limits<double>::infinity();  // as eq. 3-5
    l += area_error(s.samples, inputs[k].samples, ForceAxis::Lateral, 0.0);
  }
  return weight * l;
}

CalibrationResult calibrate(const std::vector<HapticSequence>& inputs, const ParameterSpace& space,
                            const TrialSimulator& sim, const CalibrationOptions& options, const Comm& comm,
                            const std::function<void(const GenerationProgress&)>& progress) {
  return calibrate(inputs, space, one_by_one(sim), options, comm, progress);
}

CalibrationResult calibrate(const std::vector<HapticSequence>& inputs, const ParameterSpace& space,
                            const TrialBatchSimulator& sim, const CalibrationOptions& options, const Comm& comm,
                            const std::function<void(const GenerationProgress&)>& progress) {
  if (inputs.empty()) throw std::invalid_argument("calibrate: no input sequences");
  if (options.generations < 1 || options.population < 2)
    throw std::invalid_argument("calibrate: need at least 1 generation and a population of 2");
  const auto t0 = std::chrono::steady_clock::now();
  const int K = static_cast<int>(inputs.size());
  if (options.contrast_weight < 0 || !std::isfinite(options.contrast_weight))
    throw std::invalid_argument("calibrate: the contrast weight must be 0 or positive");
  if (options.lateral_weight < 0 || !std::isfinite(options.lateral_weight))
    throw std::invalid_argument("calibrate: the lateral weight must be 0 or positive");
  if (options.prune < 0 || !std::isfinite(options.prune))
    throw std::invalid_argument("calibrate: the prune factor must be 0 (off) or positive");
  if (options.prune > 0 && options.objective != ObjectiveKind::Area)
    throw std::invalid_argument("calibrate: pruning needs the area objective (its lower bound, objective.h)");
  // The terms of a candidate's objective: one per input sequence, then the contrast term and the
  // lateral term when they are asked for, at `ic` and `il` (-1: none), so that a run without them
  // keeps its old layout and its checkpoints resume.
  const int ic = options.contrast_weight > 0 ? K : -1;
  const int il = options.lateral_weight > 0 ? K + (ic >= 0 ? 1 : 0) : -1;
  const int T = K + (ic >= 0 ? 1 : 0) + (il >= 0 ? 1 : 0);

  CmaesSettings cs;
  cs.x0 = space.initial_unit();
  cs.sigma0 = options.sigma0;
  cs.lambda = options.population;
  cs.seed = options.seed;
  cs.lower = Eigen::VectorXd::Zero(space.dimension());
  cs.upper = Eigen::VectorXd::Ones(space.dimension());
  cs.max_generations = options.generations;
  Cmaes es(cs);

  // Checkpoints carry the samples' hash since session 82; an older one (without it) still resumes
  // on the rest of the fingerprint, as it did.
  // The fingerprint a checkpoint must carry, and the shorter ones of older checkpoints, which
  // resume with a note of what they could not confirm: before session 90 the inputs' heights
  // and speeds were not recorded, before the samples' hash only their ids and lengths.
  const std::string fp_before_hash = fingerprint(inputs, space, options);
  const std::string fp_before_runs = fp_before_hash + ";samples=" + samples_hash(inputs);
  const std::string fp = fp_before_runs + ";runs=" + inputs_runs(inputs);
  std::string resume_note;
  // The search's best candidate's terms; infinite until a candidate scores a finite objective
  // (they were zeros, which a search where every simulation failed reported as L = 0 for each
  // sequence: session 84's review, finding 5).
  std::vector<double> best_fits(static_cast<std::size_t>(T), std::numeric_limits<double>::infinity());
  int done = 0;
  bool resumed = false;
  // Resume: every rank reads rank 0's checkpoint text (broadcast), so all start from one state.
  if (!options.checkpoint.empty()) {
    probe_checkpoint(options.checkpoint, comm);
    std::string text;
    comm.on_root([&] {
      if (std::filesystem::exists(options.checkpoint)) text = read_file(options.checkpoint);
    });
    comm.broadcast(text);
    if (!text.empty()) {
      const Checkpoint c = decode_checkpoint(text, options.checkpoint);
      if (c.fingerprint == fp_before_runs)
        resume_note = "the checkpoint predates the inputs' heights and speeds in its fingerprint; they were taken "
                      "as this run's";
      else if (c.fingerprint == fp_before_hash)
        resume_note = "the checkpoint predates its inputs' samples, heights and speeds in its fingerprint (only their "
                      "ids and lengths were checked); they were taken as this run's";
      else if (c.fingerprint != fp)
        throw_input_error(options.checkpoint, 2,
                          "checkpoint belongs to a different calibration: " + first_difference(fp, c.fingerprint) +
                              " differs (inputs, seed, budget, bounds, gown or objective); remove it or choose "
                              "another --checkpoint");
      if (static_cast<int>(c.best_fits.size()) != T) throw_input_error(options.checkpoint, 4, "wrong number of fits");
      try {
        es.restore_state(c.cmaes_state);
      } catch (const std::runtime_error& e) {
        throw_input_error(options.checkpoint, 6, e.what());
      }
      best_fits = c.best_fits;
      done = c.generations_done;
      resumed = true;
    }
  }

  // The candidates' objective terms (candidate c's at [c T, c T + T)).
  // One task per candidate, all its sequences in one batch: the cloth simulator settles the
  // gown once for them (sim::simulate_trials; 15-25% of a candidate's time). Session 2 ran one
  // task per (candidate, sequence) for finer grains; with 10-32 candidates a generation the
  // coarser grain still keeps 2 cores busy.
  // `generation`: which one these candidates are (0: the start), for candidate_progress alone.
  // `bound` (pruning, see calibration.h): a candidate whose objective's lower bound passes it is
  // cut; infinity: none is.
  // Each candidate's block: its T terms, 1 when it was cut (else 0), its simulated cloth time.
  const int W = T + 2;
  std::mutex progress_mutex;
  // A candidate's block from its simulated inputs; `work`: the cloth time they cost.
  auto score = [&](const std::vector<SimulatedTrial>& sts, double work, double* out) {
    bool cut = false;
    for (int k = 0; k < K; ++k) {
      out[k] = sequence_term(options.objective, sts[k], inputs[k]);
      cut = cut || sts[k].cut;
    }
    out[T + 1] = work;
    if (ic >= 0) out[ic] = cut ? 0.0 : contrast_term(inputs, sts, options.contrast_weight);
    if (il >= 0) out[il] = cut ? 0.0 : lateral_term(inputs, sts, options.lateral_weight);
    out[T] = cut ? 1.0 : 0.0;
  };
  // A candidate's inputs simulated; one whose scene cannot be built (UnbuildableCandidate) as
  // failed simulations, which score infinity and rank it last.
  auto simulate_candidate = [&](const Eigen::VectorXd& x, const std::vector<TrialWatch>& watches) {
    try {
      return simulate_inputs(sim, space.cloth(x), space.offsets(x), inputs, watches);
    } catch (const UnbuildableCandidate&) {
      std::vector<SimulatedTrial> failed(inputs.size());
      for (SimulatedTrial& t : failed) t.finite = false;
      return failed;
    }
  };
  auto report = [&](CandidateProgress& cp, std::chrono::steady_clock::time_point began) {
    if (!options.candidate_progress || !comm.is_root()) return;
    std::lock_guard<std::mutex> lock(progress_mutex);
    ++cp.done;
    cp.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
    options.candidate_progress(cp);
  };
  // Pruning: the simulated inputs of the generation's cut candidates (held[c]), on the rank that
  // simulated them, until the generation is ranked; a cut candidate that must be known whole
  // goes on from them (finish_cut).
  std::vector<std::vector<SimulatedTrial>> held;
  // When the generation's evaluation began: its finishing pass reports its time from there too.
  std::chrono::steady_clock::time_point generation_began;
  auto evaluate = [&](const std::vector<Eigen::VectorXd>& xs, int generation, double bound) {
    const int n = static_cast<int>(xs.size());
    const auto began = generation_began = std::chrono::steady_clock::now();
    CandidateProgress cp;
    cp.generation = generation;
    cp.total = (n + comm.size() - 1) / comm.size();  // run_batch: the root takes indices 0, size, ...
    held.assign(static_cast<std::size_t>(n), {});
    return run_batch(n, W, thread_count(options.threads), comm, [&](int c, double* out) {
      // The candidate's terms as far as they are known: each sequence's bound while it runs, its
      // whole L once it ended; the extra terms 0 (>= 0, known only at the end).
      std::vector<double> known(static_cast<std::size_t>(T), 0.0);
      std::vector<TrialWatch> watches;
      if (bound < std::numeric_limits<double>::infinity())
        for (int k = 0; k < K; ++k)
          watches.push_back([&, k](const std::vector<HapticSample>& so_far, bool ended) {
            const auto& measured = inputs[static_cast<std::size_t>(k)].samples;
            known[static_cast<std::size_t>(k)] =
                !ended ? area_objective_so_far(so_far, measured)
                       : (so_far.empty() ? std::numeric_limits<double>::infinity() : area_objective(so_far, measured));
            return combined_objective(known.data(), K, T, options.combine) > bound;
          });
      std::vector<SimulatedTrial> sts = simulate_candidate(xs[c], watches);
      score(sts, simulated_time(sts), out);
      if (out[T] != 0.0) held[static_cast<std::size_t>(c)] = std::move(sts);  // each c on one thread
      report(cp, began);
    });
  };
  // The cut candidates `again` of the generation `xs` simulated in whole: each cut input goes on
  // from where it was cut (SimulatedTrial::rest; the same bits as simulating it again), or, when
  // the simulator kept no state, the candidate is simulated again. The batch runs over all of the
  // generation's indices so that each candidate lands on the rank that holds its trials.
  auto finish_cut = [&](const std::vector<Eigen::VectorXd>& xs, const std::vector<int>& again, int generation) {
    const int n = static_cast<int>(xs.size());
    std::vector<char> wanted(static_cast<std::size_t>(n), 0);
    for (int c : again) wanted[static_cast<std::size_t>(c)] = 1;
    const auto began = generation_began;
    CandidateProgress cp;
    cp.generation = generation;
    cp.finishing = true;
    for (int c = comm.rank(); c < n; c += comm.size()) cp.total += wanted[static_cast<std::size_t>(c)];
    return run_batch(n, W, thread_count(options.threads), comm, [&](int c, double* out) {
      if (!wanted[static_cast<std::size_t>(c)]) return;
      std::vector<SimulatedTrial>& sts = held[static_cast<std::size_t>(c)];
      if (static_cast<int>(sts.size()) != K)
        throw std::logic_error("calibrate: cut candidate " + std::to_string(c) + "'s trials are not on this rank");
      const bool resumable = std::all_of(sts.begin(), sts.end(), [](const SimulatedTrial& t) { return !t.cut || t.rest; });
      double work = 0.0;
      if (resumable) {
        for (SimulatedTrial& t : sts)
          if (t.cut) {
            t = t.rest();
            if (t.cut) throw std::logic_error("calibrate: the rest of a cut trial came back cut (SimulatedTrial::rest)");
            work += t.simulated_s;
          }
      } else {
        sts = simulate_candidate(xs[c], {});
        work = simulated_time(sts);
      }
      score(sts, work, out);
      sts = {};  // its paused simulations are not needed again
      report(cp, began);
    });
  };

  // The start is a candidate too. CMA-ES samples around its initial mean but never evaluates it,
  // and with a small budget from a start known to fit (a grid's best point, another person's
  // calibration) every sample can be worse than the start: participant 4 from the plausibility
  // grid's point (L 1.367), 6 x 10 candidates at sigma0 0.3, best 1.884. So the start is
  // evaluated once before the search (again on a resume: it is deterministic, so the result has
  // the same bits as an uninterrupted run) and returned if nothing the search found beats it.
  // The search itself is unchanged: the start does not enter CMA-ES's update.
  const Eigen::VectorXd start = space.initial_unit();
  const double no_bound = std::numeric_limits<double>::infinity();
  std::vector<double> start_fits = evaluate({start}, 0, no_bound);
  double simulated_total = start_fits[static_cast<std::size_t>(T) + 1];
  start_fits.resize(static_cast<std::size_t>(T));
  const double start_f = combined_objective(start_fits.data(), K, T, options.combine);

  int done_here = 0;
  long pruned_total = 0, resimulated_total = 0;
  while (!es.stopped()) {
    if (options.stop_after_generations > 0 && done_here >= options.stop_after_generations) break;
    const std::vector<Eigen::VectorXd> xs = es.ask();
    const int lambda = static_cast<int>(xs.size());
    const auto& medians = es.state().median_history;
    const double bound = options.prune > 0 && !medians.empty() ? options.prune * medians.back() : no_bound;
    std::vector<double> per = evaluate(xs, done + 1, bound);
    std::vector<double> f(static_cast<std::size_t>(lambda), 0.0);
    std::vector<char> cut(static_cast<std::size_t>(lambda), 0);
    auto take = [&](int c) {
      f[c] = combined_objective(per.data() + static_cast<std::size_t>(c) * W, K, T, options.combine);
      cut[c] = per[static_cast<std::size_t>(c) * W + T] != 0.0;
    };
    double work = 0.0;  // the generation's simulated cloth time
    for (int c = 0; c < lambda; ++c) {
      take(c);
      work += per[static_cast<std::size_t>(c) * W + T + 1];
    }
    const int pruned = static_cast<int>(std::count(cut.begin(), cut.end(), 1));
    // Keep the mu best exact (calibration.h): finish in whole the cut candidates of the lowest
    // bounds until mu fully simulated ones score at or below every bound left.
    int resimulated = 0;
    for (std::vector<int> again; !(again = cut_candidates_to_finish(es, f, cut)).empty();) {
      const std::vector<double> redo = finish_cut(xs, again, done + 1);
      for (int c : again) {
        std::copy_n(redo.begin() + static_cast<long>(c) * W, W, per.begin() + static_cast<long>(c) * W);
        take(c);
        work += redo[static_cast<std::size_t>(c) * W + T + 1];
      }
      resimulated += static_cast<int>(again.size());
    }
    held.clear();
    pruned_total += pruned;
    resimulated_total += resimulated;
    simulated_total += work;
    const double best_before = es.best_f();
    const int arg = static_cast<int>(std::min_element(f.begin(), f.end()) - f.begin());
    es.tell(f);
    if (f[arg] < best_before)
      for (int k = 0; k < T; ++k) best_fits[k] = per[static_cast<std::size_t>(arg) * W + k];
    ++done;
    ++done_here;
    require_one_state(es, comm, done);
    if (!options.checkpoint.empty()) {
      // Rank 0 writes it, and every rank learns whether it could: a failure ends them all. The
      // other ranks used to go on to the next generation and wait in its MPI_Allreduce for a rank
      // 0 that had died (a full quota held a Slurm job to its time limit: finding 1).
      try {
        comm.on_root([&] {
          write_file_atomic(options.checkpoint, encode_checkpoint(Checkpoint{fp, done, best_fits, es.save_state()}));
        });
      } catch (const std::exception& e) {
        throw std::runtime_error("the checkpoint of generation " + std::to_string(done) + " could not be written: " +
                                 e.what());
      }
    }
    // A library caller's progress may throw too (the CLI's prints): on rank 0 alone, told to all.
    comm.on_root([&] {
      if (progress) {
        GenerationProgress p;
        p.generation = done;
        p.generations = options.generations;
        const bool start_best = !found(es) || !(es.best_f() <= start_f);  // as the result chooses, below
        p.best = start_best ? start_f : es.best_f();
        p.best_fits = start_best ? start_fits : best_fits;
        p.best_contrast = ic >= 0 ? p.best_fits[static_cast<std::size_t>(ic)] : 0.0;
        p.best_lateral = il >= 0 ? p.best_fits[static_cast<std::size_t>(il)] : 0.0;
        p.best_fits.resize(static_cast<std::size_t>(K));
        p.generation_best = f[arg];
        p.pruned = pruned;
        p.resimulated = resimulated;
        p.prune_bound = bound;
        p.simulated_s = work;
        p.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        p.eta_s = p.elapsed_s / done_here * std::max(0, options.generations - done);
        p.resumed = resumed;
        progress(p);
      }
    });
  }

  CalibrationResult r;
  r.resume_note = resume_note;
  r.complete = es.stopped();
  if (r.complete) r.stopped_by = stop_reason_name(es.stop_reason());
  r.generations_done = done;
  r.evaluations = es.state().evaluations + 1;  // and the start
  r.pruned = pruned_total;
  r.resimulated = resimulated_total;
  r.simulated_s = simulated_total;
  r.start_objective = start_f;
  const bool keep_start = !found(es) || !(es.best_f() <= start_f);
  r.objective = keep_start ? start_f : es.best_f();
  r.best_unit = keep_start ? start : es.best_x();
  r.cloth = space.cloth(r.best_unit);
  r.offsets = space.offsets(r.best_unit);
  for (int k = 0; k < K; ++k)
    r.fits.push_back({inputs[k].id, inputs[k].height, inputs[k].speed,
                      keep_start ? start_fits[static_cast<std::size_t>(k)] : best_fits[k], {}, {}, {}});
  const std::vector<double>& terms = keep_start ? start_fits : best_fits;
  if (ic >= 0) r.contrast = terms[static_cast<std::size_t>(ic)];
  if (il >= 0) r.lateral = terms[static_cast<std::size_t>(il)];
  r.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Nothing to calibrate to: the start and every candidate failed (calibration.h). A stopped
  // run may still find something when it resumes.
  if (r.complete && !std::isfinite(r.objective))
    throw std::runtime_error("no candidate could be simulated: the start and all " +
                             std::to_string(r.evaluations - 1) + " candidates of the search failed (a simulation "
                             "that blew up or gave no samples, or a scene that could not be built, such as a grasp "
                             "that holds none of the gown, scores infinity)");
  return r;
}

void measure_axis_fits(std::vector<SequenceFit>& fits, const std::vector<HapticSequence>& inputs,
                       const std::vector<SimulatedTrial>& curves) {
  if (fits.size() != inputs.size() || curves.size() != inputs.size())
    throw std::invalid_argument("measure_axis_fits: fits, inputs and curves differ in number");
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const auto& measured = inputs[k].samples;
    const auto& sim = curves[k].samples;
    if (measured.empty() || sim.empty() || !curves[k].finite) continue;
    // The zero curve over the travel both cover: the measured samples with no force.
    std::vector<HapticSample> zero(measured.begin(), measured.begin() + std::min(measured.size(), sim.size()));
    for (auto& z : zero) z.f_motion = z.f_lateral = z.f_vertical = 0.0;
    fits[k].motion = {area_error(sim, measured, ForceAxis::Motion, 0.0), area_error(zero, measured, ForceAxis::Motion, 0.0)};
    fits[k].vertical = {area_error(sim, measured, ForceAxis::Vertical, 0.0),
                        area_error(zero, measured, ForceAxis::Vertical, 0.0)};
    fits[k].lateral = {area_error(sim, measured, ForceAxis::Lateral, 0.0),
                       area_error(zero, measured, ForceAxis::Lateral, 0.0)};
  }
}

void start_from(Bounds& b, const Calibration& c) {
  // A value past its box by no more than rounding is the box's edge: files written before
  // from_unit() clamped (session 46) end there when their search did (participant0-fine5.json).
  // Returns v, or the edge it is past by rounding alone; throws when it is outside the box.
  auto in_box = [](const ParamBound& pb, double v, const std::string& name) {
    const double slack = 1e-12 * (pb.upper - pb.lower);
    if (v > pb.upper && v <= pb.upper + slack) return pb.upper;
    if (v < pb.lower && v >= pb.lower - slack) return pb.lower;
    if (!(v >= pb.lower && v <= pb.upper)) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "%s %g is outside its bounds [%g, %g]", name.c_str(), v, pb.lower, pb.upper);
      throw std::invalid_argument(buf);
    }
    return v;
  };
  for (int i = 0; i < kClothParams; ++i)
    b.cloth[i].initial = in_box(b.cloth[i], cloth_value(c.cloth, i), kClothParamNames[i]);
  for (int i = 0; i < kPersonParams; ++i) {
    // The paper's value outside the box (no support, where the box holds one) keeps the box's
    // own start: the start file simply did not have it.
    const double v = person_value(c.cloth, i);
    if (v == kPersonParamInfo[i].paper && !(v >= b.person[i].lower && v <= b.person[i].upper)) continue;
    b.person[i].initial = in_box(b.person[i], v, kPersonParamInfo[i].name);
  }
  // The offsets share one box; each calibrated height starts from its own value.
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low}) {
    const int k = static_cast<int>(h);
    if (!c.offset_calibrated[k]) continue;
    b.offset_initial[k] = in_box(b.arm_offset, c.offsets[k], "arm_offset_" + std::string(arm_height_name(h)));
  }
}

// ---- the calibration file -------------------------------------------------------------------------

Json calibration_to_json(const Calibration& c) {
  Json j = Json::object();
  j.set("format", "dressguard-calibration 1");
  j.set("participant", c.participant);
  Json cloth = Json::object();
  for (int i = 0; i < kClothParams; ++i) cloth.set(kClothParamNames[i], cloth_value(c.cloth, i));
  // Only a cuff and the person parameters other than the paper's are written: a file without
  // them is the paper's uniform cloth, arm and gown (and synthesis folders made from such a
  // calibration keep their record, which compares the text, so they resume). The cuff comes
  // first, so the density stays where it was before it could be fitted.
  if (c.cloth.hem_width > 0) {
    cloth.set("hem_width", c.cloth.hem_width);
    cloth.set("hem_bend_ratio", c.cloth.hem_bend_ratio);
  }
  for (int i = 0; i < kPersonParams; ++i)
    if (person_value(c.cloth, i) != kPersonParamInfo[i].paper)
      cloth.set(kPersonParamInfo[i].name, person_value(c.cloth, i));
  // The friction scheme only when it is not the paper's, last: older files keep their bytes.
  if (c.cloth.friction_scheme != kFrictionSchemes[0]) cloth.set("friction_scheme", c.cloth.friction_scheme);
  j.set("cloth", cloth);
  Json off = Json::object();
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low}) {
    Json e = Json::object();
    e.set("offset_m", c.offsets[static_cast<int>(h)]);
    e.set("calibrated", c.offset_calibrated[static_cast<int>(h)]);
    off.set(std::string(arm_height_name(h)), e);
  }
  j.set("arm_offsets", off);
  j.set("objective_kind", c.objective_kind);
  j.set("objective", c.objective);
  if (c.combine != "sum") j.set("combine", c.combine);  // (files of the paper's sum keep their text)
  // Only with a contrast term (files without one keep their text).
  if (c.contrast_weight > 0) {
    j.set("contrast_weight", c.contrast_weight);
    j.set("contrast", c.contrast);
  }
  if (c.lateral_weight > 0) {  // likewise
    j.set("lateral_weight", c.lateral_weight);
    j.set("lateral", c.lateral);
  }
  Json fits = Json::array();
  for (const auto& f : c.fits) {
    Json e = Json::object();
    e.set("trial_id", f.trial_id);
    e.set("height", std::string(arm_height_name(f.height)));
    e.set("speed", f.speed);
    e.set("objective", f.objective);
    if (f.motion.measured() && f.vertical.measured()) {
      e.set("motion_error", f.motion.error);
      e.set("motion_zero", f.motion.zero);
      e.set("vertical_error", f.vertical.error);
      e.set("vertical_zero", f.vertical.zero);
    }
    if (f.lateral.measured()) {
      e.set("lateral_error", f.lateral.error);
      e.set("lateral_zero", f.lateral.zero);
    }
    fits.push(e);
  }
  j.set("sequences", fits);
  j.set("gown", c.gown);
  j.set("rig_travel_m", c.rig_travel);
  j.set("provenance", c.provenance);
  return j;
}

Calibration calibration_from_json(const Json& j, const std::filesystem::path& source) {
  Calibration c;
  try {
    if (!j.has("format") || j.at("format").string() != "dressguard-calibration 1")
      throw std::runtime_error("not a dressguard calibration file (format \"dressguard-calibration 1\")");
    c.participant = j.at("participant").string();
    // The simulator's limits, the ones read_bounds and `simulate --params` hold a value to: a
    // file with stretch 7 or friction -1 was read and simulated (session 84's review, finding 4).
    for (int i = 0; i < kClothParams; ++i) {
      const double v = j.at("cloth").at(kClothParamNames[i]).number();
      const ClothParamLimits& lim = kClothParamLimits[i];
      if (!std::isfinite(v)) throw std::runtime_error(std::string("cloth.") + kClothParamNames[i] + " is not finite");
      if (!(v >= lim.lowest && v <= lim.highest))
        throw std::runtime_error(std::string("cloth.") + kClothParamNames[i] + " " + lim.range);
      set_cloth_value(c.cloth, i, v);
    }
    // Files without one have the paper's arm and gown they were calibrated with.
    for (int i = 0; i < kPersonParams; ++i) {
      const PersonParamInfo& info = kPersonParamInfo[i];
      if (!j.at("cloth").has(info.name)) continue;
      const double v = j.at("cloth").at(info.name).number();
      if (!(v >= info.lowest && v <= info.highest))
        throw std::runtime_error(std::string("cloth.") + info.name + " " + info.range);
      set_person_value(c.cloth, i, v);
    }
    if (j.at("cloth").has("hem_width")) {
      c.cloth.hem_width = j.at("cloth").at("hem_width").number();
      c.cloth.hem_bend_ratio = j.at("cloth").at("hem_bend_ratio").number();
      if (!hem_in_range(c.cloth.hem_width, c.cloth.hem_bend_ratio))
        throw std::runtime_error("cloth.hem_width / hem_bend_ratio must be within [0, 0.2] m / [1, 10000]");
    }
    if (j.at("cloth").has("friction_scheme")) {
      c.cloth.friction_scheme = j.at("cloth").at("friction_scheme").string();
      if (!friction_scheme_known(c.cloth.friction_scheme))
        throw std::runtime_error("cloth.friction_scheme '" + c.cloth.friction_scheme +
                                 "' is not one of " + friction_scheme_choices());
    }
    for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low}) {
      const Json& e = j.at("arm_offsets").at(std::string(arm_height_name(h)));
      c.offsets[static_cast<int>(h)] = e.at("offset_m").number();
      c.offset_calibrated[static_cast<int>(h)] = e.at("calibrated").boolean();
      // Written so that NaN fails too (abs(NaN) > 0.5 is false).
      if (!(std::abs(c.offsets[static_cast<int>(h)]) <= kMaxArmOffset))
        throw std::runtime_error("arm_offsets." + std::string(arm_height_name(h)) +
                                 ".offset_m must be a number within +-0.5 m");
    }
    c.objective_kind = j.at("objective_kind").string();
    c.objective = j.at("objective").number();
    if (j.has("combine")) {
      c.combine = j.at("combine").string();
      if (!parse_combine(c.combine))
        throw std::runtime_error("combine must be \"sum\", \"worst\", \"bar\" or \"count\", not \"" + c.combine + "\"");
    }
    if (j.has("contrast_weight")) {
      c.contrast_weight = j.at("contrast_weight").number();
      c.contrast = j.at("contrast").number();
      if (!(c.contrast_weight >= 0)) throw std::runtime_error("contrast_weight must not be negative");
    }
    if (j.has("lateral_weight")) {
      c.lateral_weight = j.at("lateral_weight").number();
      c.lateral = j.at("lateral").number();
      if (!(c.lateral_weight >= 0)) throw std::runtime_error("lateral_weight must not be negative");
    }
    for (const Json& e : j.at("sequences").items()) {
      SequenceFit f;
      f.trial_id = e.at("trial_id").string();
      const auto h = parse_arm_height(e.at("height").string());
      if (!h) throw std::runtime_error("bad height \"" + e.at("height").string() + "\"");
      f.height = *h;
      f.speed = e.at("speed").number();
      f.objective = e.at("objective").number();
      if (e.has("vertical_error")) {  // absent in files written before 2026-11-23
        f.motion = {e.at("motion_error").number(), e.at("motion_zero").number()};
        f.vertical = {e.at("vertical_error").number(), e.at("vertical_zero").number()};
        if (!f.motion.measured() || !f.vertical.measured() || f.motion.error < 0 || f.vertical.error < 0 ||
            f.motion.zero < 0 || f.vertical.zero < 0)
          throw std::runtime_error("sequence " + f.trial_id + ": an axis fit is negative or not finite");
      }
      if (e.has("lateral_error")) {  // absent in files written before 2026-11-25
        f.lateral = {e.at("lateral_error").number(), e.at("lateral_zero").number()};
        if (!f.lateral.measured() || f.lateral.error < 0 || f.lateral.zero < 0)
          throw std::runtime_error("sequence " + f.trial_id + ": the lateral fit is negative or not finite");
      }
      c.fits.push_back(f);
    }
    c.gown = j.at("gown").string();
    c.rig_travel = j.at("rig_travel_m").number();
    if (!(c.rig_travel > 0.1 && c.rig_travel <= 1.5)) throw std::runtime_error("rig_travel_m outside (0.1, 1.5] m");
    if (j.has("provenance")) c.provenance = j.at("provenance");
  } catch (const InputError&) {
    throw;
  } catch (const JsonError& e) {  // a value of the wrong type or a key missing: its line
    throw_input_error(source, e.line(), e.what());
  } catch (const std::exception& e) {
    throw_input_error(source, 0, e.what());
  }
  return c;
}

void write_calibration(const std::filesystem::path& path, const Calibration& c) {
  write_file_atomic(path, calibration_to_json(c).dump() + "\n");
}

Calibration read_calibration(const std::filesystem::path& path) {
  return calibration_from_json(Json::parse(read_file(path), path), path);
}

std::string overlay_csv(const std::vector<HapticSequence>& inputs, const std::vector<SimulatedTrial>& simulated,
                        const std::string& label) {
  std::ostringstream o;
  o << "trial_id,height,source,travel,f_motion,f_vertical,f_lateral\n";
  char buf[160];
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const std::string h(arm_height_name(inputs[k].height));
    for (const auto& s : inputs[k].samples) {
      std::snprintf(buf, sizeof buf, ",%.6g,%.6g,%.6g,%.6g\n", s.travel, s.f_motion, s.f_vertical, s.f_lateral);
      o << inputs[k].id << ',' << h << ",measured" << buf;
    }
    if (k < simulated.size())
      for (const auto& s : simulated[k].samples) {
        std::snprintf(buf, sizeof buf, ",%.6g,%.6g,%.6g,%.6g\n", s.travel, s.f_motion, s.f_vertical, s.f_lateral);
        o << inputs[k].id << ',' << h << ',' << label << buf;
      }
  }
  return o.str();
}

}  // namespace dressguard::calib
