// The calibrated simulator against other people's measured sequences, see prediction.h.
#include "prediction.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "discrepancy.h"
#include "files.h"

namespace dressguard::calib {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A simulated curve travels through run_batch's fixed-size blocks of doubles (so that the
// prediction spreads over ranks like every other batch): the scores, the sample count, then the
// samples' t, travel, F_motion, F_vertical, F_lateral in five columns of one length, sized before
// simulating from the slowest and longest target (block_samples): the rig's longest pull, 0.85 m
// at 0.1 m/s after a 1 m/s^2 start, is 8.55 s, 856 samples at 100 Hz, but a dataset may hold
// pulls down to kMinSpeed over up to kMaxTravel (a fixed 1500 once stopped one at 0.04 m/s with
// an internal error after the whole batch had been simulated).
enum Slot { kObjective, kSign, kSimEnd, kOutcome, kCount, kColumns };
constexpr int kColumnCount = 5;      // t, travel, F_motion, F_vertical, F_lateral
constexpr double kSampleRate = 100;  // [Hz] the sensor's and the simulator's (sim/trial.h)
// [s] a simulated pull may run past its time to the end of travel (pull_time_at): the cloth
// simulator gives up 5 s after it (sim::max_time_of), and the sample at t = 0 comes on top.
constexpr double kSpareTime = 5.0;

// The most samples one target's simulated pull can have: the time to its end of travel at its
// speed (request_for) and the spare, at 100 Hz. Ample for the study (8.55 s + 5 s: 1357 samples
// a target); at the reader's extremes (kMaxTravel at kMinSpeed) 2005 s, 8 MB a target.
int samples_for(const TrialRequest& r) {
  return static_cast<int>(std::ceil((pull_time_at(r.max_travel, r.speed) + kSpareTime) * kSampleRate)) + 1;
}

double median_of(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return std::isnan(x); }), v.end());
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

bool predictable(const HapticSequence& t) { return t.label && *t.label != Outcome::Caught && !t.samples.empty(); }

// The targets (indices) in groups of one height (one arm placement: the calibration's offset for
// it), so that each group settles the gown once whether or not the arm touches it while it
// settles (sim::simulate_trials); at most kPredictionGroup a group, and at least `workers` groups
// where there are enough targets (the largest group split in two until then). Any grouping gives
// the same results (the batch simulator's contract); this one keeps the workers busy.
std::vector<std::vector<int>> groups_by_height(const std::vector<const HapticSequence*>& targets, int workers) {
  const int n = static_cast<int>(targets.size());
  std::vector<std::vector<int>> groups;
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low}) {
    std::vector<int> of_h;
    for (int k = 0; k < n; ++k)
      if (targets[static_cast<std::size_t>(k)]->height == h) of_h.push_back(k);
    const int parts = (static_cast<int>(of_h.size()) + kPredictionGroup - 1) / kPredictionGroup;
    for (int q = 0; q < parts; ++q)  // consecutive, nearly equal parts
      groups.emplace_back(of_h.begin() + of_h.size() * q / parts, of_h.begin() + of_h.size() * (q + 1) / parts);
  }
  while (static_cast<int>(groups.size()) < workers) {
    auto largest = std::max_element(groups.begin(), groups.end(),
                                    [](const auto& x, const auto& y) { return x.size() < y.size(); });
    if (largest->size() < 2) break;
    std::vector<int> back(largest->begin() + largest->size() / 2, largest->end());
    largest->resize(largest->size() / 2);
    groups.push_back(std::move(back));
  }
  return groups;
}

}  // namespace

std::vector<const HapticSequence*> prediction_targets(const Dataset& ds, const std::string& calibrated) {
  std::vector<const HapticSequence*> out;
  for (const auto& t : ds.trials)
    if (predictable(t) && t.participant != calibrated) {
      require_simulated_rate(ds, t);
      out.push_back(&t);
    }
  return out;
}

std::pair<double, int> real_person_median(const Dataset& ds, const HapticSequence& target, const std::string& calibrated,
                                          ObjectiveKind kind) {
  std::vector<double> l;
  for (const auto& other : ds.trials)
    if (predictable(other) && other.height == target.height && same_pull_speed(other.speed, target.speed) &&
        other.participant != target.participant && other.participant != calibrated)
      l.push_back(sequence_objective(kind, other.samples, target.samples));
  return {median_of(l), static_cast<int>(l.size())};
}

std::string simulated_source(const Prediction& p) { return p.discrepancy ? "simulated+discrepancy" : "simulated"; }

void add_discrepancy(Prediction& p, const Discrepancy& d, const Dataset& ds, ObjectiveKind kind) {
  for (auto& t : p.trials) {
    const HapticSequence* measured = find_trial(ds, t.trial_id);
    if (!measured) throw std::invalid_argument("add_discrepancy: the dataset holds no trial '" + t.trial_id + "'");
    HapticSequence corrected{t.trial_id, t.participant, t.height, t.speed, std::nullopt, std::move(t.simulated)};
    apply_discrepancy(d, corrected);
    t.simulated = std::move(corrected.samples);
    if (std::isfinite(t.objective)) t.objective = sequence_objective(kind, t.simulated, measured->samples);
    t.vertical_sign = vertical_sign_agreement(t.simulated, measured->samples);
  }
  p.discrepancy = true;
}

Prediction predict_others(const Calibration& cal, const Dataset& ds, const TrialSimulator& sim, int threads,
                          const Comm& comm, const std::function<void(const PredictionProgress&)>& progress) {
  return predict_others(cal, ds, one_by_one(sim), threads, comm, progress);
}

Prediction predict_others(const Calibration& cal, const Dataset& ds, const TrialBatchSimulator& sim, int threads,
                          const Comm& comm, const std::function<void(const PredictionProgress&)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<const HapticSequence*> targets = prediction_targets(ds, cal.participant);
  if (targets.empty())
    throw InputError("the dataset holds no labelled, non-caught trial of a participant other than '" +
                     cal.participant + "' to predict");
  const ObjectiveKind kind = parse_objective(cal.objective_kind).value_or(ObjectiveKind::Area);
  const int n = static_cast<int>(targets.size());
  // Every target's request, and the block's columns sized for the longest of them, before any
  // simulation.
  std::vector<TrialRequest> requests;
  int samples = 0;
  for (const HapticSequence* t : targets) {
    requests.push_back(request_for(*t, cal.offsets));
    samples = std::max(samples, samples_for(requests.back()));
  }
  const int per_target = kColumns + kColumnCount * samples;
  const std::vector<std::vector<int>> groups = groups_by_height(targets, thread_count(threads) * comm.size());
  std::size_t per_group = 0;
  std::vector<std::size_t> slot_of(static_cast<std::size_t>(n));  // target -> its block in `out`
  for (const auto& g : groups) per_group = std::max(per_group, g.size());
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (std::size_t j = 0; j < groups[g].size(); ++j) slot_of[static_cast<std::size_t>(groups[g][j])] = g * per_group + j;
  // This rank runs the groups g with g % size == rank (run_batch); its targets, for progress.
  int mine = 0;
  for (std::size_t g = static_cast<std::size_t>(comm.rank()); g < groups.size(); g += static_cast<std::size_t>(comm.size()))
    mine += static_cast<int>(groups[g].size());
  int done = 0;
  std::mutex progress_mutex;
  const int block = static_cast<int>(per_group) * per_target;
  const std::vector<double> out = run_batch(static_cast<int>(groups.size()), block, threads, comm, [&](int g, double* group_block) {
    const std::vector<int>& members = groups[static_cast<std::size_t>(g)];
    std::vector<TrialRequest> group;
    for (int k : members) group.push_back(requests[static_cast<std::size_t>(k)]);
    const std::vector<SimulatedTrial> sims = sim(cal.cloth, group);
    if (sims.size() != group.size())
      throw std::logic_error("predict_others: the batch simulator returned " + std::to_string(sims.size()) +
                             " trials for " + std::to_string(group.size()));
    for (std::size_t j = 0; j < members.size(); ++j) {
      const HapticSequence& target = *targets[static_cast<std::size_t>(members[j])];
      const SimulatedTrial& st = sims[j];
      if (st.samples.empty() || static_cast<int>(st.samples.size()) > samples)
        throw std::logic_error("predict_others: the simulated pull of trial '" + target.id + "' has " +
                               std::to_string(st.samples.size()) + " samples, outside [1, " + std::to_string(samples) +
                               "] (its speed " + format_number(target.speed) + " m/s, end of travel " +
                               format_number(group[j].max_travel) + " m)");
      double* b = group_block + j * per_target;
      b[kObjective] = st.finite ? sequence_objective(kind, st.samples, target.samples)
                                : std::numeric_limits<double>::infinity();
      b[kSign] = vertical_sign_agreement(st.samples, target.samples);
      b[kSimEnd] = st.samples.back().travel;
      b[kOutcome] = st.outcome ? static_cast<double>(static_cast<int>(*st.outcome)) : -1.0;  // -1: none
      b[kCount] = static_cast<double>(st.samples.size());
      double* col = b + kColumns;
      for (std::size_t i = 0; i < st.samples.size(); ++i) {
        col[i] = st.samples[i].t;
        col[samples + i] = st.samples[i].travel;
        col[2 * samples + i] = st.samples[i].f_motion;
        col[3 * samples + i] = st.samples[i].f_vertical;
        col[4 * samples + i] = st.samples[i].f_lateral;
      }
    }
    // Counted under the lock, so that the reports come in order.
    std::lock_guard<std::mutex> lock(progress_mutex);
    done += static_cast<int>(members.size());
    if (progress && comm.is_root()) {
      PredictionProgress pp;
      pp.done = done;
      pp.total = mine;
      pp.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      pp.eta_s = pp.elapsed_s / done * (mine - done);
      progress(pp);
    }
  });
  Prediction p;
  p.participant = cal.participant;
  p.gown = cal.gown;
  for (int k = 0; k < n; ++k) {
    const HapticSequence& target = *targets[static_cast<std::size_t>(k)];
    const double* b = out.data() + slot_of[static_cast<std::size_t>(k)] * per_target;
    PredictedTrial t;
    t.trial_id = target.id;
    t.participant = target.participant;
    t.height = target.height;
    t.speed = target.speed;
    t.objective = b[kObjective];
    std::tie(t.real_median, t.real_count) = real_person_median(ds, target, cal.participant, kind);
    t.vertical_sign = b[kSign];
    t.simulated_end = b[kSimEnd];
    t.measured_end = target.samples.back().travel;
    if (b[kOutcome] >= 0) t.simulated_outcome = static_cast<Outcome>(static_cast<int>(b[kOutcome]));
    const double* col = b + kColumns;
    for (int i = 0; i < static_cast<int>(b[kCount]); ++i)
      t.simulated.push_back(
          {col[i], col[samples + i], col[2 * samples + i], col[4 * samples + i], col[3 * samples + i]});
    p.trials.push_back(std::move(t));
  }
  return p;
}

std::vector<PredictionSummary> summarize(const Prediction& p) {
  std::vector<PredictionSummary> out;
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low}) {
    PredictionSummary s;
    s.height = h;
    std::vector<double> l, real, sign;
    for (const auto& t : p.trials) {
      if (t.height != h) continue;
      ++s.trials;
      l.push_back(t.objective);
      real.push_back(t.real_median);
      sign.push_back(t.vertical_sign);
      s.no_worse += t.objective <= t.real_median;  // false for a NaN median: no yardstick, no claim
    }
    s.objective_median = median_of(l);
    s.real_median = median_of(real);
    s.vertical_sign_median = median_of(sign);
    out.push_back(s);
  }
  return out;
}

std::string prediction_csv(const Prediction& p) {
  std::ostringstream o;
  o.precision(9);
  o << "trial_id,participant,height,speed,objective,real_median,real_count,vertical_sign,simulated_end,measured_end,"
       "simulated_outcome,gown,discrepancy\n";
  for (const auto& t : p.trials)
    o << t.trial_id << ',' << t.participant << ',' << arm_height_name(t.height) << ',' << t.speed << ',' << t.objective
      << ',' << t.real_median << ',' << t.real_count << ',' << t.vertical_sign << ',' << t.simulated_end << ','
      << t.measured_end << ',' << (t.simulated_outcome ? outcome_name(*t.simulated_outcome) : "") << ',' << p.gown
      << ',' << (p.discrepancy ? 1 : 0) << '\n';
  return o.str();
}

std::string prediction_curves_csv(const Prediction& p, const Dataset& ds) {
  std::ostringstream o;
  o.precision(7);
  o << "trial_id,source,travel,f_motion,f_vertical\n";
  const std::string simulated = simulated_source(p);
  auto rows = [&](const std::string& id, const std::string& source, const std::vector<HapticSample>& s) {
    for (const auto& x : s) o << id << ',' << source << ',' << x.travel << ',' << x.f_motion << ',' << x.f_vertical << '\n';
  };
  for (const auto& t : p.trials) {
    if (const HapticSequence* m = find_trial(ds, t.trial_id)) rows(t.trial_id, "measured", m->samples);
    rows(t.trial_id, simulated, t.simulated);
  }
  return o.str();
}

// ---- the residual over travel ----------------------------------------------------------------------

bool ResidualWindow::outside(int axis) const {
  const double r = residual(axis);
  return people >= kResidualMinPeople && std::isfinite(r) && std::fabs(r) > std::max(spread[axis], kResidualFloor);
}

namespace {

// Mean F_motion and F_vertical of the samples with from <= travel < to; false when there is none.
bool window_mean(const std::vector<HapticSample>& s, double from, double to, double out[kForces]) {
  double sum[kForces] = {};
  int n = 0;
  for (const auto& x : s)
    if (x.travel >= from && x.travel < to) {
      sum[0] += x.f_motion;
      sum[1] += x.f_vertical;
      sum[2] += x.f_lateral;
      ++n;
    }
  if (n == 0) return false;
  for (int ax = 0; ax < kForces; ++ax) out[ax] = sum[ax] / n;
  return true;
}

}  // namespace

std::vector<ResidualWindow> residual_windows(const Prediction& p, const Dataset& ds, double window) {
  if (!(window > 0)) throw std::invalid_argument("residual_windows: the window must be positive");
  struct Pair {
    ArmHeight height;
    const std::string* participant;
    std::vector<HapticSample> measured;  // on the simulator's travel (objective.h)
    const std::vector<HapticSample>* simulated;
  };
  std::vector<Pair> pairs;
  double longest = 0;
  for (const auto& t : p.trials) {
    const HapticSequence* m = find_trial(ds, t.trial_id);
    if (m == nullptr || m->samples.empty() || t.simulated.empty()) continue;
    pairs.push_back({t.height, &t.participant, measured_on_simulated_travel(t.simulated, m->samples), &t.simulated});
    longest = std::max(longest, m->samples.back().travel);
  }
  // Window k is [k w, (k + 1) w): computed from k, not accumulated, so the edges are exact
  // multiples and every height's windows line up.
  const int count = static_cast<int>(std::ceil(longest / window - 1e-9));
  std::vector<ResidualWindow> out;
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low}) {
    if (std::none_of(pairs.begin(), pairs.end(), [&](const Pair& q) { return q.height == h; })) continue;
    for (int k = 0; k < count; ++k) {
      ResidualWindow w;
      w.height = h;
      w.from = k * window;
      w.to = (k + 1) * window;
      // Per person: the sums of their trials' window means, measured and simulated, and how many.
      struct Person {
        double measured[kForces] = {}, simulated[kForces] = {};
        int trials = 0;
      };
      std::map<std::string, Person> people;
      for (const Pair& q : pairs) {
        // Both curves through the whole window: a recording that starts late (haptic.h) covers
        // it only from its start, which its mean would pair with the simulator's whole window.
        if (q.height != h || !records_from(q.measured, w.from) || q.measured.back().travel < w.to ||
            q.simulated->back().travel < w.to)
          continue;
        double a[kForces], b[kForces];
        if (!window_mean(q.measured, w.from, w.to, a) || !window_mean(*q.simulated, w.from, w.to, b)) continue;
        Person& person = people[*q.participant];
        for (int ax = 0; ax < kForces; ++ax) {
          person.measured[ax] += a[ax];
          person.simulated[ax] += b[ax];
        }
        ++person.trials;
        ++w.trials;
      }
      w.people = static_cast<int>(people.size());
      for (int ax = 0; ax < kForces; ++ax) {
        if (w.people == 0) {
          w.measured[ax] = w.spread[ax] = w.simulated[ax] = kNaN;
          continue;
        }
        // Each person's mean over their trials first, so that a person with two trials counts
        // once in the mean, the spread and n (prediction.h).
        std::vector<double> meas;
        double sim_sum = 0;
        for (const auto& [id, person] : people) {
          meas.push_back(person.measured[ax] / person.trials);
          sim_sum += person.simulated[ax] / person.trials;
        }
        double mean = 0;
        for (double v : meas) mean += v;
        mean /= w.people;
        double ss = 0;
        for (double v : meas) ss += (v - mean) * (v - mean);
        w.measured[ax] = mean;
        w.spread[ax] = w.people > 1 ? std::sqrt(ss / (w.people - 1)) : kNaN;
        w.simulated[ax] = sim_sum / w.people;
      }
      out.push_back(w);
    }
  }
  return out;
}

namespace {

// Calls emit(i, j) for every run [i, j) of consecutive windows (each `from` the previous `to`)
// that begins where starts(v[i]) holds and goes on while joins(v[i], v[k]) holds: the findings'
// runs of a height and force.
template <class Window, class Starts, class Joins, class Emit>
void for_each_run(const std::vector<Window>& v, Starts starts, Joins joins, Emit emit) {
  std::size_t i = 0;
  while (i < v.size()) {
    if (!starts(v[i])) {
      ++i;
      continue;
    }
    std::size_t j = i + 1;
    while (j < v.size() && joins(v[i], v[j]) && std::fabs(v[j].from - v[j - 1].to) < 1e-9) ++j;
    emit(i, j);
    i = j;
  }
}

}  // namespace

std::vector<ResidualFinding> residual_findings(const std::vector<ResidualWindow>& windows) {
  std::vector<ResidualFinding> out;
  for (int ax = 0; ax < kForces; ++ax) {
    // A run: windows of one height, outside the people, residuals of one sign.
    const auto starts = [ax](const ResidualWindow& w) { return w.outside(ax); };
    const auto joins = [ax](const ResidualWindow& a, const ResidualWindow& w) {
      return w.height == a.height && w.outside(ax) && (w.residual(ax) > 0) == (a.residual(ax) > 0);
    };
    for_each_run(windows, starts, joins, [&](std::size_t i, std::size_t j) {
      const ResidualWindow& a = windows[i];
      ResidualFinding f;
      f.height = a.height;
      f.axis = ax;
      f.from = a.from;
      f.to = windows[j - 1].to;
      f.trials = a.trials;
      f.people = a.people;
      for (std::size_t k = i; k < j; ++k) {
        f.residual += windows[k].residual(ax) / static_cast<double>(j - i);
        f.measured += windows[k].measured[ax] / static_cast<double>(j - i);
        f.spread += windows[k].spread[ax] / static_cast<double>(j - i);
        f.trials = std::min(f.trials, windows[k].trials);
        f.people = std::min(f.people, windows[k].people);
      }
      const char* what = ax == 0   ? (f.residual > 0 ? "too little drag" : "too much drag")
                         : ax == 1 ? (f.residual > 0 ? "pulls the gripper up too much" : "pulls the gripper down too much")
                                   : (f.residual > 0 ? "pulls the gripper toward the person too much"
                                                     : "pulls the gripper away from the person too much");
      char buf[320];
      std::snprintf(buf, sizeof buf, "%s arm, %s, %.2f-%.2f m: %s, simulated %+.2f N from the people's mean %.2f N "
                    "(their spread %.2f N over %d people; %d trials, each person's averaged first)",
                    std::string(arm_height_name(f.height)).c_str(), force_name(ax), f.from, f.to, what, f.residual,
                    f.measured, f.spread, f.people, f.trials);
      f.text = buf;
      out.push_back(f);
    });
  }
  std::stable_sort(out.begin(), out.end(), [](const ResidualFinding& x, const ResidualFinding& y) {
    return std::fabs(x.residual) * (x.to - x.from) > std::fabs(y.residual) * (y.to - y.from);
  });
  return out;
}

std::string residual_csv(const std::vector<ResidualWindow>& windows) {
  std::ostringstream o;
  o.precision(7);
  o << "height,from,to,trials,people";
  for (int ax = 0; ax < kForces; ++ax)
    for (const char* k : {"measured", "spread", "simulated", "residual", "outside"}) o << ',' << k << '_' << force_column(ax);
  o << '\n';
  for (const auto& w : windows) {
    o << arm_height_name(w.height) << ',' << w.from << ',' << w.to << ',' << w.trials << ',' << w.people;
    for (int ax = 0; ax < kForces; ++ax)
      o << ',' << w.measured[ax] << ',' << w.spread[ax] << ',' << w.simulated[ax] << ',' << w.residual(ax) << ','
        << (w.outside(ax) ? 1 : 0);
    o << '\n';
  }
  return o.str();
}


const char* force_name(int axis) {
  static const char* const kNames[kForces] = {"F_motion", "F_vertical", "F_lateral"};
  return axis >= 0 && axis < kForces ? kNames[axis] : "?";
}

const char* force_column(int axis) {
  static const char* const kColumns[kForces] = {"motion", "vertical", "lateral"};
  return axis >= 0 && axis < kForces ? kColumns[axis] : "?";
}

// ---- the contrast between the heights ------------------------------------------------------------

std::string_view contrast_verdict_name(ContrastVerdict v) {
  switch (v) {
    case ContrastVerdict::NoContrast: return "none";
    case ContrastVerdict::Agrees: return "agrees";
    case ContrastVerdict::Misses: return "misses";
    case ContrastVerdict::Reverses: return "reverses";
  }
  return "?";
}

namespace {

// The simulator's verdict on one window's contrast (prediction.h).
ContrastVerdict judge_contrast(double measured, double standard_error, double simulated, bool enough) {
  if (!enough || !std::isfinite(measured) || !std::isfinite(standard_error) ||
      !(std::fabs(measured) > std::max(kResidualFloor, 2 * standard_error)))
    return ContrastVerdict::NoContrast;
  if (!(std::fabs(simulated) > kResidualFloor)) return ContrastVerdict::Misses;
  return (simulated > 0) == (measured > 0) ? ContrastVerdict::Agrees : ContrastVerdict::Reverses;
}

}  // namespace

std::vector<HeightContrast> height_contrasts(const std::vector<ResidualWindow>& windows) {
  std::vector<HeightContrast> out;
  for (ArmHeight lower : {ArmHeight::Middle, ArmHeight::Low})
    for (const ResidualWindow& lo : windows) {
      if (lo.height != lower) continue;
      // The high arm's window at the same travel (every height's windows line up: residual_windows).
      const auto hi = std::find_if(windows.begin(), windows.end(), [&](const ResidualWindow& w) {
        return w.height == ArmHeight::High && std::fabs(w.from - lo.from) < 1e-9;
      });
      if (hi == windows.end()) continue;
      HeightContrast c;
      c.lower = lower;
      c.from = lo.from;
      c.to = lo.to;
      c.trials_high = hi->trials;
      c.trials_lower = lo.trials;
      c.people_high = hi->people;
      c.people_lower = lo.people;
      const bool enough = hi->people >= kResidualMinPeople && lo.people >= kResidualMinPeople;
      for (int ax = 0; ax < kForces; ++ax) {
        c.measured[ax] = hi->measured[ax] - lo.measured[ax];
        c.simulated[ax] = hi->simulated[ax] - lo.simulated[ax];
        c.standard_error[ax] = enough ? std::sqrt(hi->spread[ax] * hi->spread[ax] / hi->people +
                                                  lo.spread[ax] * lo.spread[ax] / lo.people)
                                      : kNaN;
        c.verdict[ax] = judge_contrast(c.measured[ax], c.standard_error[ax], c.simulated[ax], enough);
      }
      out.push_back(c);
    }
  return out;
}

std::vector<ContrastFinding> contrast_findings(const std::vector<HeightContrast>& contrasts) {
  std::vector<ContrastFinding> out;
  for (int ax = 0; ax < kForces; ++ax) {
    // A run: windows of one lower height, one verdict (misses or reverses), the people's
    // contrast of one sign.
    const auto starts = [ax](const HeightContrast& c) {
      return c.verdict[ax] == ContrastVerdict::Misses || c.verdict[ax] == ContrastVerdict::Reverses;
    };
    const auto joins = [ax](const HeightContrast& a, const HeightContrast& c) {
      return c.lower == a.lower && c.verdict[ax] == a.verdict[ax] && (c.measured[ax] > 0) == (a.measured[ax] > 0);
    };
    for_each_run(contrasts, starts, joins, [&](std::size_t i, std::size_t j) {
      const HeightContrast& a = contrasts[i];
      const ContrastVerdict v = a.verdict[ax];
      ContrastFinding f;
      f.lower = a.lower;
      f.axis = ax;
      f.verdict = v;
      f.from = a.from;
      f.to = contrasts[j - 1].to;
      for (std::size_t k = i; k < j; ++k) {
        f.measured += contrasts[k].measured[ax] / static_cast<double>(j - i);
        f.simulated += contrasts[k].simulated[ax] / static_cast<double>(j - i);
      }
      const std::string lower_name(arm_height_name(f.lower));
      char buf[320];
      std::snprintf(buf, sizeof buf,
                    "%s, high against %s, %.2f-%.2f m: the people's high arm reads %+.2f N against their %s arm; "
                    "the simulator's %+.2f N (%s)",
                    force_name(ax), lower_name.c_str(), f.from, f.to, f.measured,
                    lower_name.c_str(), f.simulated,
                    v == ContrastVerdict::Reverses ? "reverses: a classifier trained on it learns the opposite here"
                                                   : "misses: a classifier trained on it learns nothing here");
      f.text = buf;
      out.push_back(f);
    });
  }
  std::stable_sort(out.begin(), out.end(), [](const ContrastFinding& x, const ContrastFinding& y) {
    return x.from != y.from ? x.from < y.from : x.axis < y.axis;
  });
  return out;
}

ContrastTally tally_contrasts(const std::vector<HeightContrast>& contrasts, double up_to) {
  ContrastTally t;
  for (const auto& c : contrasts) {
    if (c.to > up_to + 1e-9) continue;
    for (ContrastVerdict v : c.verdict) {
      t.agrees += v == ContrastVerdict::Agrees;
      t.misses += v == ContrastVerdict::Misses;
      t.reverses += v == ContrastVerdict::Reverses;
    }
  }
  return t;
}

std::string contrast_csv(const std::vector<HeightContrast>& contrasts) {
  std::ostringstream o;
  o.precision(7);
  o << "lower,from,to,trials_high,trials_lower,people_high,people_lower";
  for (int ax = 0; ax < kForces; ++ax)
    for (const char* k : {"measured", "standard_error", "simulated", "verdict"}) o << ',' << k << '_' << force_column(ax);
  o << '\n';
  for (const auto& c : contrasts) {
    o << arm_height_name(c.lower) << ',' << c.from << ',' << c.to << ',' << c.trials_high << ',' << c.trials_lower
      << ',' << c.people_high << ',' << c.people_lower;
    for (int ax = 0; ax < kForces; ++ax)
      o << ',' << c.measured[ax] << ',' << c.standard_error[ax] << ',' << c.simulated[ax] << ','
        << contrast_verdict_name(c.verdict[ax]);
    o << '\n';
  }
  return o.str();
}

}  // namespace dressguard::calib
