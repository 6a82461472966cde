// The calibrated simulator against other people's measured sequences, see prediction.h.
#include "prediction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "files.h"

namespace dressguard::calib {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A simulated curve travels through run_batch's fixed-size blocks of doubles (so that the
// prediction spreads over ranks like every other batch): the scores, the sample count, then the
// samples' t, travel, F_motion, F_vertical in four fixed-size columns. The longest pull the rig
// makes, 0.85 m at 0.1 m/s after a 1 m/s^2 start, is 8.55 s: 856 samples at 100 Hz.
constexpr int kMaxSamples = 1500;
enum Slot { kObjective, kSign, kSimEnd, kOutcome, kCount, kColumns };
constexpr int kBlock = kColumns + 4 * kMaxSamples;

double median_of(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return std::isnan(x); }), v.end());
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

bool predictable(const HapticSequence& t) { return t.label && *t.label != Outcome::Caught && !t.samples.empty(); }

}  // namespace

std::vector<const HapticSequence*> prediction_targets(const Dataset& ds, const std::string& calibrated) {
  std::vector<const HapticSequence*> out;
  for (const auto& t : ds.trials)
    if (predictable(t) && t.participant != calibrated) out.push_back(&t);
  return out;
}

std::pair<double, int> real_person_median(const Dataset& ds, const HapticSequence& target, const std::string& calibrated,
                                          ObjectiveKind kind) {
  std::vector<double> l;
  for (const auto& other : ds.trials)
    if (predictable(other) && other.height == target.height && other.participant != target.participant &&
        other.participant != calibrated)
      l.push_back(sequence_objective(kind, other.samples, target.samples));
  return {median_of(l), static_cast<int>(l.size())};
}

Prediction predict_others(const Calibration& cal, const Dataset& ds, const TrialSimulator& sim, int threads,
                          const Comm& comm) {
  return predict_others(cal, ds, one_by_one(sim), threads, comm);
}

Prediction predict_others(const Calibration& cal, const Dataset& ds, const TrialBatchSimulator& sim, int threads,
                          const Comm& comm) {
  const std::vector<const HapticSequence*> targets = prediction_targets(ds, cal.participant);
  if (targets.empty())
    throw InputError("the dataset holds no labelled, non-caught trial of a participant other than '" +
                     cal.participant + "' to predict");
  const ObjectiveKind kind = parse_objective(cal.objective_kind).value_or(ObjectiveKind::Area);
  const int n = static_cast<int>(targets.size());
  // Group g holds targets g, g + G, g + 2G, ...: a mix of heights and speeds in each, so that the
  // groups cost about the same. Any G gives the same results (the batch simulator's contract).
  const int groups = std::min(n, thread_count(threads) * comm.size());
  const int per_group = (n + groups - 1) / groups;
  const std::vector<double> out = run_batch(groups, per_group * kBlock, threads, comm, [&](int g, double* group_block) {
    std::vector<int> members;
    std::vector<TrialRequest> requests;
    for (int k = g; k < n; k += groups) {
      members.push_back(k);
      requests.push_back(request_for(*targets[static_cast<std::size_t>(k)], cal.offsets));
    }
    const std::vector<SimulatedTrial> sims = sim(cal.cloth, requests);
    if (sims.size() != requests.size())
      throw std::logic_error("predict_others: the batch simulator returned " + std::to_string(sims.size()) +
                             " trials for " + std::to_string(requests.size()));
    for (std::size_t j = 0; j < members.size(); ++j) {
      const HapticSequence& target = *targets[static_cast<std::size_t>(members[j])];
      const SimulatedTrial& st = sims[j];
      if (st.samples.empty() || static_cast<int>(st.samples.size()) > kMaxSamples)
        throw std::logic_error("predict_others: a simulated pull of " + std::to_string(st.samples.size()) + " samples");
      double* b = group_block + j * kBlock;
      b[kObjective] = st.finite ? sequence_objective(kind, st.samples, target.samples)
                                : std::numeric_limits<double>::infinity();
      b[kSign] = vertical_sign_agreement(st.samples, target.samples);
      b[kSimEnd] = st.samples.back().travel;
      b[kOutcome] = static_cast<double>(static_cast<int>(st.outcome));
      b[kCount] = static_cast<double>(st.samples.size());
      double* col = b + kColumns;
      for (std::size_t i = 0; i < st.samples.size(); ++i) {
        col[i] = st.samples[i].t;
        col[kMaxSamples + i] = st.samples[i].travel;
        col[2 * kMaxSamples + i] = st.samples[i].f_motion;
        col[3 * kMaxSamples + i] = st.samples[i].f_vertical;
      }
    }
  });
  Prediction p;
  p.participant = cal.participant;
  for (int k = 0; k < n; ++k) {
    const HapticSequence& target = *targets[static_cast<std::size_t>(k)];
    // Target k is member k / groups of group k % groups.
    const double* b = out.data() + (static_cast<std::size_t>(k % groups) * per_group + k / groups) * kBlock;
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
    t.simulated_outcome = static_cast<Outcome>(static_cast<int>(b[kOutcome]));
    const double* col = b + kColumns;
    for (int i = 0; i < static_cast<int>(b[kCount]); ++i)
      t.simulated.push_back({col[i], col[kMaxSamples + i], col[2 * kMaxSamples + i], 0.0, col[3 * kMaxSamples + i]});
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
       "simulated_outcome\n";
  for (const auto& t : p.trials)
    o << t.trial_id << ',' << t.participant << ',' << arm_height_name(t.height) << ',' << t.speed << ',' << t.objective
      << ',' << t.real_median << ',' << t.real_count << ',' << t.vertical_sign << ',' << t.simulated_end << ','
      << t.measured_end << ',' << outcome_name(t.simulated_outcome) << '\n';
  return o.str();
}

std::string prediction_curves_csv(const Prediction& p, const Dataset& ds) {
  std::ostringstream o;
  o.precision(7);
  o << "trial_id,source,travel,f_motion,f_vertical\n";
  auto rows = [&](const std::string& id, const char* source, const std::vector<HapticSample>& s) {
    for (const auto& x : s) o << id << ',' << source << ',' << x.travel << ',' << x.f_motion << ',' << x.f_vertical << '\n';
  };
  for (const auto& t : p.trials) {
    for (const auto& m : ds.trials)
      if (m.id == t.trial_id) rows(t.trial_id, "measured", m.samples);
    rows(t.trial_id, "simulated", t.simulated);
  }
  return o.str();
}

}  // namespace dressguard::calib
