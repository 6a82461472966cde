// The trial runner (paper V-A): grasp, gravity, settling with the optional perturbation, pull,
// stop, label. The haptic samples follow the rig (shared/data/README.md).
#include "trial.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include "arm_spring.h"
#include "files.h"
#include "model.h"

namespace dressguard::sim {
namespace {

// Uniform in [lo, hi) from 53 random bits, the same on every standard library (unlike
// std::uniform_real_distribution, whose algorithm is unspecified).
double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
}

// The rig's motion profile: constant acceleration up to the pull speed, then constant speed.
struct Profile {
  double a, v, max_travel;
  double travel(double t) const {
    const double ta = v / a;
    const double s = t < ta ? 0.5 * a * t * t : 0.5 * a * ta * ta + v * (t - ta);
    return std::min(s, max_travel);
  }
  // The ramp's speed; the stop at max_travel is not in it: the pull ends in the sample that
  // reaches it, and the rig's braking is not modelled (the travel is clamped there).
  double speed(double t) const { return std::min(a * t, v); }
  // The gripper's mean acceleration over [t0, t1], one output step: the change of speed over
  // the step, so that the grasped vertices' inertia (solver.cpp, substep) adds up to exactly
  // their mass times the pull's speed however the ramp's end falls on the step grid. Asking
  // for a at t0 gave a whole step of a to the step in which the ramp ends, or to one after it
  // when t0 was rounded below v / a.
  double accel_over(double t0, double t1, double dt) const { return (speed(t1) - speed(t0)) / dt; }
};

bool all_finite(const GownState& s) {
  for (const V3& q : s.x)
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) return false;
  return true;
}

Frame make_frame(const GownState& s, double t, double travel) {
  Frame f;
  f.t = t;
  f.travel = travel;
  f.xyz.reserve(s.x.size() * 3);
  for (const V3& q : s.x) {
    f.xyz.push_back(static_cast<float>(q.x));
    f.xyz.push_back(static_cast<float>(q.y));
    f.xyz.push_back(static_cast<float>(q.z));
  }
  return f;
}

}  // namespace

Outcome label_outcome(bool full_travel, double d_max) {
  if (full_travel) return Outcome::Missed;
  return d_max <= kGoodLabelDistance ? Outcome::Good : Outcome::Caught;
}

std::string_view label_name(const TrialResult& r) { return r.outcome ? outcome_name(*r.outcome) : "none"; }

namespace {

// Settling (settle()): the gown perturbation's output steps, and the rest check's window and
// period (0.1 s).
constexpr int kPerturbFrom = 180, kPerturbTo = 330, kRestWindow = 30;
int settle_min_steps(const TrialSpec& spec) {
  return std::max(spec.settle_steps, spec.gown_noise ? kPerturbTo + kRestWindow : 0);
}
int settle_max_steps(const TrialSpec& spec) {
  return spec.settle_speed > 0 ? std::max(settle_min_steps(spec), spec.settle_max_steps) : settle_min_steps(spec);
}

}  // namespace

double max_settle_time_of(const TrialSpec& spec, const SceneOptions& opt) {
  // The rest check ends settling on a whole window, at the cap or past it.
  return (settle_max_steps(spec) + kRestWindow - 1) / kRestWindow * kRestWindow / opt.step_hz;
}

namespace {

// The random draws of a trial, in the stream's order: the perturbation force first, then the
// arm-height noise (one random stream per trial).
struct TrialDraws {
  double fx = 0, fy = 0;  // [N] the perturbation (used only with gown_noise)
  double arm_offset = 0;  // [m] spec.arm_offset plus the arm noise
};
TrialDraws draw(const TrialSpec& spec) {
  std::mt19937_64 rng(spec.seed);
  TrialDraws d;
  d.fx = uniform(rng, -6.0, 6.0);
  d.fy = uniform(rng, -6.0, 6.0);
  d.arm_offset = spec.arm_offset;
  if (spec.arm_noise)
    d.arm_offset += spec.height == ArmHeight::Middle ? uniform(rng, -0.06, 0.0) : uniform(rng, -0.015, 0.015);
  return d;
}

// simulate_trial()'s checks of its spec (trial.h): the values that would pull forever (a speed,
// acceleration or end of travel of 0, or not finite: the travel never reaches its end and the
// time limit, max_time_of(), is infinite or NaN), index outside the arm's heights, or sort and
// size settling's frames by NaN or infinite times.
void check_spec(const TrialSpec& spec) {
  auto refuse = [](const char* field, const std::string& what, double value) {
    throw std::invalid_argument(std::string("simulate_trial: TrialSpec::") + field + " must be " + what + ", not " +
                                format_number(value));
  };
  if (!(spec.speed > 0 && std::isfinite(spec.speed))) refuse("speed", "a positive finite speed [m/s]", spec.speed);
  if (!(spec.acceleration > 0 && std::isfinite(spec.acceleration)))
    refuse("acceleration", "a positive finite acceleration [m/s^2]", spec.acceleration);
  if (!(spec.max_travel > 0 && std::isfinite(spec.max_travel)))
    refuse("max_travel", "a positive finite travel [m]", spec.max_travel);
  if (spec.settle_steps < 0) refuse("settle_steps", "0 or more output steps", spec.settle_steps);
  if (!std::isfinite(spec.arm_offset)) refuse("arm_offset", "a finite offset [m]", spec.arm_offset);
  const int h = static_cast<int>(spec.height);
  if (h < 0 || h > 2) refuse("height", "high, middle or low (0, 1 or 2)", h);
  for (double t : spec.frame_times)
    if (!std::isfinite(t)) refuse("frame_times", "finite times [s]", t);
}

double arm_dz_of(const SceneData& sc, const TrialSpec& spec, double arm_offset) {
  const int hi = static_cast<int>(spec.height);
  return sc.opt.arm.z_rel[hi] - sc.opt.arm.z_rel[0] + arm_offset;
}

OpeningShape opening_shape(const GownModel& m, const GownState& s) {
  const SceneData& sc = *m.scene;
  const size_t k = sc.opening.size();
  const double grasp_z = sc.opt.grasp_point[2];
  double zlo = s.x[sc.opening[0]].z, zhi = zlo, ylo = s.x[sc.opening[0]].y, yhi = ylo, ysum = 0, now = 0, rest = 0;
  for (size_t a = 0; a < k; ++a) {
    const int32_t v = sc.opening[a], u = sc.opening[(a + 1) % k];
    zlo = std::min(zlo, s.x[v].z), zhi = std::max(zhi, s.x[v].z);
    ylo = std::min(ylo, s.x[v].y), yhi = std::max(yhi, s.x[v].y);
    ysum += s.x[v].y;
    now += norm(s.x[u] - s.x[v]);
    rest += norm(sc.rest[u] - sc.rest[v]);
  }
  OpeningShape o;
  o.depth = grasp_z - zlo;
  o.height = zhi - zlo;
  o.width = yhi - ylo;
  o.centre_y = ysum / k;
  o.perimeter_ratio = rest > 0 ? now / rest : 0;
  o.rim_low_above_fist = zlo - m.elbow.z;  // every arm sphere's centre lies at the elbow's height
  return o;
}

// What the settling leaves for the pull besides the state and r's settle_* fields.
struct Settled {
  V3 bias{0, 0, 0};             // the raw gripper force at rest (the sensor's bias)
  std::vector<int32_t> lower;   // the lower half of the sleeve opening as it hangs
  bool arm_touched = false;     // the arm, or one of the watched arms, touched the gown
};

// Grasp, gravity, the optional perturbation and settling until the gown is at rest (see
// TrialSpec). Fills r's settle_* fields, weight, bias, wall_settle and the frames before the
// pull. `probe_dz`: other arm placements (relative to m's) watched with watch_arms() while no
// arm has touched the gown; Settled::arm_touched is set when m's own arm corrected a vertex or
// a watched arm would have (TrialResult::settle_arm_near when one came within contact reach).
Settled settle(GownModel& m, GownState& s, const TrialSpec& spec, const TrialDraws& d,
               const std::vector<double>& probe_dz, TrialResult& r) {
  const SceneData& sc = *m.scene;
  const int n = static_cast<int>(s.x.size());
  Settled out;
  double total_mass = 0;
  for (double q : m.mass) total_mass += q;
  r.weight = total_mass * 9.81;

  std::vector<double> frame_times = spec.frame_times;
  std::sort(frame_times.begin(), frame_times.end());

  // Perturbation (paper V-A): one random horizontal force, uniform in X and lateral up to 6 N,
  // spread equally over all vertices for 0.5 s (output steps 180-330), then settling until the
  // gown is at rest (TrialSpec::settle_speed).
  const auto clock0 = std::chrono::steady_clock::now();
  const bool adaptive = spec.settle_speed > 0;
  const int min_steps = settle_min_steps(spec);
  const int max_steps = settle_max_steps(spec);
  const double cloth_decay = m.damping_factor;
  const double settle_decay = std::min(cloth_decay, std::exp(-std::max(0.0, spec.settle_damping) * m.h));
  const V3 zero{0, 0, 0};
  // Settling's frames: the pull's start is known only at the end, so snapshots every 15 steps
  // (0.05 s) as far back as the earliest requested negative time are kept and matched then.
  const double earliest = frame_times.empty() ? 0.0 : std::min(0.0, frame_times.front());
  const size_t keep_snaps = spec.keep_frames ? static_cast<size_t>(-earliest / (15 * m.dt)) + 2 : 0;
  std::vector<std::pair<int, Frame>> snaps;  // (steps done, positions)
  std::vector<V3> x_window = s.x;
  const bool own_arm_probe = sc.planes.empty();  // with planes every free vertex is a contact
  // The support comes up into its place over the first kSupportRiseSteps steps (trial.h).
  auto lift_at = [](int step) { return kSupportDrop * std::max(0.0, 1.0 - static_cast<double>(step) / kSupportRiseSteps); };
  int k = 0;
  for (;;) {
    const bool on = spec.gown_noise && k >= kPerturbFrom && k < kPerturbTo;
    const bool was_on = spec.gown_noise && k - 1 >= kPerturbFrom && k - 1 < kPerturbTo;
    if (on != was_on)
      for (int i = 0; i < n; ++i) s.ext_force[i] = on ? V3{d.fx / n, d.fy / n, 0} : zero;
    m.damping_factor = on ? cloth_decay : settle_decay;
    if (k % 3 == 0) {  // the bias sample is the last 3 steps before the pull (settling ends on k % 3 == 0)
      s.force_acc = zero;
      s.support_acc = zero;
      s.force_count = 0;
    }
    s.support_lift_from = lift_at(k);
    s.support_lift_to = lift_at(k + 1);
    const int close = sc.opt.jaw_close_steps;
    s.jaw_closed = close > 0 ? std::min(1.0, (k + 1.0) / close) : 1.0;
    if (!out.arm_touched && watch_arms(m, s, probe_dz)) r.settle_arm_near = true;
    step(m, s, zero, zero, zero);
    if (!out.arm_touched) {
      // The own arm corrected a vertex when a normal correction was made this step (a
      // candidate that stayed outside the contact offset moved nothing).
      const bool own_touched = !own_arm_probe || s.arm_corrected;
      // Listed for the arm (or the planes), not only for the support.
      for (size_t q = 0; q < s.contact_count && !r.settle_arm_near; ++q)
        r.settle_arm_near = !own_arm_probe || s.cand[s.contact_list[q]].c[0] >= 0;
      if (own_touched || s.watch_touched) {
        out.arm_touched = true;
        s.watch.clear();
      }
    }
    ++k;
    if (keep_snaps > 0 && k % 15 == 0) {
      if (snaps.size() == keep_snaps) snaps.erase(snaps.begin());
      snaps.emplace_back(k, make_frame(s, 0.0, 0.0));
    }
    if (k % kRestWindow == 0) {
      double v2 = 0;
      long free_count = 0;
      for (int i = 0; i < n; ++i)
        if (m.w[i] > 0) {
          const V3 dx = s.x[i] - x_window[i];
          v2 += dot(dx, dx), ++free_count;
        }
      r.settle_speed = free_count ? std::sqrt(v2 / free_count) / (kRestWindow * m.dt) : 0.0;
      x_window = s.x;
    }
    if (k < min_steps || k % 3 != 0) continue;
    if (!adaptive) break;
    if (k % kRestWindow == 0 && (r.settle_speed <= spec.settle_speed || k >= max_steps)) break;
  }
  s.watch.clear();
  s.watch_touched = false;
  r.settle_steps = k;
  r.settle_time = k * m.dt;
  r.settled = !adaptive || r.settle_speed <= spec.settle_speed;
  m.damping_factor = cloth_decay;
  for (size_t f = 0; f < frame_times.size() && frame_times[f] < -1e-9; ++f) {
    // The snapshot nearest to the requested time before the pull.
    const double want = frame_times[f];
    const std::pair<int, Frame>* best = nullptr;
    for (const auto& sn : snaps)
      if (!best || std::abs((sn.first - k) * m.dt - want) < std::abs((best->first - k) * m.dt - want)) best = &sn;
    if (!best) continue;
    r.frames.push_back(best->second);
    r.frames.back().t = (best->first - k) * m.dt;
  }
  for (int i = 0; i < n; ++i) s.ext_force[i] = zero;
  // The sensor is biased at the start of the trial (data README): the settled gown's force,
  // mainly its weight, is removed from every sample.
  out.bias = s.force_count ? (1.0 / s.force_count) * s.force_acc : zero;
  // The support pushes the gown up by what the gown lays on it (the same last 3 steps).
  r.support_load = s.force_count ? s.support_acc.z / s.force_count : 0.0;
  s.support_lift_from = s.support_lift_to = 0;
  r.bias = {out.bias.x, out.bias.y, out.bias.z};
  // The lower half of the sleeve opening as it hangs after settling (paper Fig. 3b, red dots).
  if (!sc.opening.empty()) {
    double zmean = 0;
    for (int v : sc.opening) zmean += s.x[v].z;
    zmean /= sc.opening.size();
    for (int v : sc.opening)
      if (s.x[v].z <= zmean) out.lower.push_back(v);
    r.opening = opening_shape(m, s);
  }
  r.wall_settle = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
  return out;
}

// A pull under way: everything its sample loop carries from one sample to the next, so that
// trials whose pulls agree so far can go on from a copy of it (simulate_trials()).
struct Pulling {
  GownState s;
  TrialResult r;
  ArmSpring arm;                 // a compliant arm (arm_spring.h) moves once per sample
  V3 arm_load0{0, 0, 0};         // its load at the first sample, counted from
  bool first_sample = true;
  // Output steps since the start of the pull, and their time [s], step / step_hz. The time is
  // computed from the count, not summed step by step: 1/300 added 30 times is
  // 0.09999999999999994, short of a 0.1 s ramp, and the samples' times drifted by ulps.
  long step = 0;
  double t = 0;
  size_t next_frame = 0;         // into the sorted non-negative frame times
  bool ended = false, full = false;
};

// [s] the time of the pull's output step `step` (Pulling::step).
double pull_time(const GownModel& m, long step) { return static_cast<double>(step) / m.scene->opt.step_hz; }

std::vector<double> pull_frame_times(const TrialSpec& spec) {
  std::vector<double> times;
  for (double t : spec.frame_times)
    if (t >= -1e-9) times.push_back(t);
  std::sort(times.begin(), times.end());
  return times;
}

void maybe_frame(Pulling& p, const TrialSpec& spec, const std::vector<double>& times, double travel) {
  while (spec.keep_frames && p.next_frame < times.size() && times[p.next_frame] <= p.t + 1e-9) {
    p.r.frames.push_back(make_frame(p.s, p.t, travel));
    ++p.next_frame;
  }
}

// The pull's start from the settled state `s`; r holds what the settling wrote.
Pulling start_pull(const GownModel& m, GownState s, const TrialSpec& spec, TrialResult r) {
  Pulling p{std::move(s), std::move(r), ArmSpring{m.arm_compliance}};
  p.r.seq.height = spec.height;
  p.r.seq.speed = spec.speed;
  p.r.seq.id = std::string("sim-") + std::string(arm_height_name(spec.height)) + "-" + std::to_string(spec.seed);
  p.r.finite = all_finite(p.s);
  maybe_frame(p, spec, pull_frame_times(spec), 0.0);
  p.ended = !p.r.finite;
  return p;
}

// One sample of the pull (3 output steps), until max_travel or the force limit (Pulling::ended).
// `touched` (may be null): set when the model's arm corrected a vertex in these steps, or when a
// watched arm (`watch_dz`, watch_arms()) would have.
void pull_sample(const GownModel& m, Pulling& p, const TrialSpec& spec, const Settled& at_rest,
                 const std::vector<double>& watch_dz = {}, bool* touched = nullptr) {
  GownState& s = p.s;
  TrialResult& r = p.r;
  const int n = static_cast<int>(s.x.size());
  const V3 zero{0, 0, 0};
  const auto clock = std::chrono::steady_clock::now();
  const Profile prof{spec.acceleration, spec.speed, spec.max_travel};
  const std::vector<double> frame_times = spec.keep_frames ? pull_frame_times(spec) : std::vector<double>{};
  s.force_acc = zero;
  s.force_count = 0;
  for (int i = 0; i < n; ++i) s.contact_acc[i] = zero;
  s.part_acc.fill(zero);
  // A compliant arm moves toward where the last sample's contact force puts it, linearly over
  // this sample's steps; its load is counted from the first sample.
  const V3 arm0 = s.arm_shift_to, arm1 = p.arm.d;
  for (int k = 0; k < 3; ++k) {
    const double t1 = pull_time(m, p.step + 1);
    const V3 g0{prof.travel(p.t), 0, 0}, g1{prof.travel(t1), 0, 0};
    if (!p.arm.rigid()) {
      s.arm_shift_from = arm0 + (k / 3.0) * (arm1 - arm0);
      s.arm_shift_to = arm0 + ((k + 1) / 3.0) * (arm1 - arm0);
    }
    if (touched && !*touched) watch_arms(m, s, watch_dz);
    step(m, s, g0, g1, V3{prof.accel_over(p.t, t1, m.dt), 0, 0});
    if (touched && !*touched) {
      *touched = s.arm_corrected || s.watch_touched;
    }
    ++p.step;
    p.t = t1;
    maybe_frame(p, spec, frame_times, g1.x);
  }
  s.watch.clear();
  s.watch_touched = false;
  if (!p.arm.rigid()) {
    V3 load{0, 0, 0};  // the cloth's force on the arm: minus the arm's on the cloth (eq. 2)
    for (int i = 0; i < n; ++i) load -= s.contact_acc[i];
    load = (1.0 / s.force_count) * load;
    if (p.first_sample) p.arm_load0 = load;
    p.arm.advance(load - p.arm_load0, 3 * m.dt);
    r.arm_shift_max = std::max(r.arm_shift_max, norm(s.arm_shift));
  }
  p.first_sample = false;
  const V3 f = (1.0 / s.force_count) * s.force_acc - at_rest.bias;
  const double travel = prof.travel(p.t);
  r.seq.samples.push_back({p.t, travel, f.x, -f.y, f.z});  // the rig's lateral axis points to -y (trial.h)
  if (spec.record_arm_parts) {
    ArmPartLoads loads;
    for (int k = 0; k < kArmParts; ++k) {
      const V3 c = (-1.0 / s.force_count) * s.part_acc[static_cast<size_t>(k)];
      loads.f[static_cast<size_t>(k)] = {c.x, c.y, c.z};
    }
    V3 momentum{0, 0, 0};
    for (int i = 0; i < n; ++i)
      if (!m.scene->grasped[static_cast<size_t>(i)]) momentum += m.mass[static_cast<size_t>(i)] * s.v[static_cast<size_t>(i)];
    loads.momentum = {momentum.x, momentum.y, momentum.z};
    r.arm_parts.push_back(loads);
  }
  r.finite = all_finite(s);
  if (r.contact_t < 0)
    for (int i = 0; i < n; ++i)
      if (s.contact_acc[i].x != 0 || s.contact_acc[i].y != 0 || s.contact_acc[i].z != 0) {
        r.contact_t = p.t;
        r.contact_travel = travel;
        break;
      }
  if (std::abs(f.x) >= spec.force_limit || std::abs(f.z) >= spec.force_limit) {
    r.stopped_by_force = true;
    p.ended = true;
  } else if (travel >= spec.max_travel - kTravelEndTolerance) {
    p.full = true;
    p.ended = true;
  } else if (!r.finite || p.t >= max_time_of(spec)) {
    p.ended = true;
  }
  r.wall_pull += std::chrono::duration<double>(std::chrono::steady_clock::now() - clock).count();
}

// The label and the end-of-pull figures, once Pulling::ended.
TrialResult finish_pull(const GownModel& m, Pulling& p, const TrialSpec& spec, const Settled& at_rest) {
  GownState& s = p.s;
  TrialResult& r = p.r;
  const int n = static_cast<int>(s.x.size());
  r.travel = Profile{spec.acceleration, spec.speed, spec.max_travel}.travel(p.t);
  r.self_pairs_dropped = s.pairs_dropped;
  r.d_max = r.d_behind = r.d_ahead = 0;
  if (!p.full && r.finite) {
    // The elbow where the (compliant) arm has it now.
    for (int v : at_rest.lower) {
      const double dx = s.x[v].x - (m.elbow.x + s.arm_shift.x);
      r.d_behind = std::max(r.d_behind, -dx);
      r.d_ahead = std::max(r.d_ahead, dx);
    }
    r.d_max = std::max(r.d_behind, r.d_ahead);  // the paper's unsigned distance
  }
  // A gown that blew up has no opening to measure (its NaN distances left d_max at 0): no label.
  r.outcome = r.finite ? std::optional<Outcome>(label_outcome(p.full, r.d_max)) : std::nullopt;
  r.seq.label = r.outcome;
  r.area_ratio = current_area(m, s) / m.scene->rest_area;
  r.arm_shift = {s.arm_shift.x, s.arm_shift.y, s.arm_shift.z};
  // Contact force of the cloth on the arm per vertex, averaged over the last sample.
  if (s.force_count > 0)
    for (int i = 0; i < n; ++i) {
      const V3 c = (-1.0 / s.force_count) * s.contact_acc[i];
      if (c.x != 0 || c.y != 0 || c.z != 0) r.contacts.push_back({i, {c.x, c.y, c.z}});
    }
  if (spec.keep_frames && (r.frames.empty() || r.frames.back().t < p.t - 1e-9))
    r.frames.push_back(make_frame(s, p.t, r.travel));
  return std::move(r);
}

// The caller's watch after one of the trial's own samples (TrialSpec::pull_watch): a pull that
// it stops ends here, cut.
void ask_watch(Pulling& p, const TrialSpec& spec) {
  if (!spec.pull_watch) return;
  if (spec.pull_watch(p.r.seq.samples, p.ended) && !p.ended) {
    p.ended = true;
    p.r.cut = true;
  }
}

}  // namespace

// A cut pull as it stood after its last sample: everything pull_sample() reads and writes, so
// that going on from it computes what the uncut pull computed. The model is a copy (its arm is
// the trial's own; simulate_trials() keeps a model per trial only while it runs).
struct PausedPull {
  GownModel m;
  Pulling p;        // p.r: the result so far, not yet finished (finish_pull), not marked cut
  TrialSpec spec;   // without its watch
  Settled at_rest;
};

namespace {

// The rest of a trial's pull on its own, from wherever p is. A pull that ended before (in a
// shared part, or not finite at the start) is still told to the watch, once. A pull the watch
// cuts keeps its state in p.r.paused (resume_trial()): one copy of the gown, the model and the
// spec per cut trial, against the seconds of simulation it saves when the caller needs the rest.
void pull_alone(const GownModel& m, Pulling& p, const TrialSpec& spec, const Settled& at_rest) {
  if (p.ended) {
    ask_watch(p, spec);
    return;
  }
  while (!p.ended) {
    pull_sample(m, p, spec, at_rest);
    ask_watch(p, spec);
  }
  if (p.r.cut) {
    auto paused = std::make_shared<PausedPull>(PausedPull{m, p, spec, at_rest});
    paused->p.ended = false;
    paused->p.r.cut = false;
    paused->spec.pull_watch = nullptr;
    p.r.paused = std::move(paused);
  }
}

// The whole pull of one trial from the settled state.
TrialResult pull(const GownModel& m, GownState s, const TrialSpec& spec, const Settled& at_rest, TrialResult r) {
  Pulling p = start_pull(m, std::move(s), spec, std::move(r));
  pull_alone(m, p, spec, at_rest);
  return finish_pull(m, p, spec, at_rest);
}

// Whether two trials' settlings are the same computation up to the arm's height.
bool same_settling(const TrialSpec& a, const TrialDraws& da, const TrialSpec& b, const TrialDraws& db) {
  if (a.keep_frames || b.keep_frames) return false;  // frames are kept per trial
  return a.gown_noise == b.gown_noise && (!a.gown_noise || (da.fx == db.fx && da.fy == db.fy)) &&
         a.friction_scheme == b.friction_scheme && a.self_collision == b.self_collision &&
         a.settle_steps == b.settle_steps && a.settle_max_steps == b.settle_max_steps &&
         a.settle_speed == b.settle_speed && a.settle_damping == b.settle_damping;
}

}  // namespace

double least_max_travel_of(const TrialSpec& spec, const SceneOptions& opt) {
  const double first_sample_t = 3 / opt.step_hz;  // pull_sample: one sample per 3 output steps
  const Profile unbounded{spec.acceleration, spec.speed, std::numeric_limits<double>::infinity()};
  return unbounded.travel(first_sample_t) + kTravelEndTolerance;
}

double max_time_of(const TrialSpec& spec) {
  return spec.max_travel / spec.speed + spec.speed / spec.acceleration + 5.0;
}

TrialResult simulate_trial(const Scene& scene, const ClothParams& params, const TrialSpec& spec) {
  check_spec(spec);
  const SceneData& sc = scene.data();
  const TrialDraws d = draw(spec);
  GownModel m = make_model(sc, params, spec.friction_scheme, spec.self_collision, arm_dz_of(sc, spec, d.arm_offset));
  GownState s = make_state(m);
  TrialResult r;
  r.arm_offset = d.arm_offset;
  const Settled at_rest = settle(m, s, spec, d, {}, r);
  return pull(m, std::move(s), spec, at_rest, std::move(r));
}

TrialResult resume_trial(const PausedPull& paused) {
  PausedPull q = paused;
  pull_alone(q.m, q.p, q.spec, q.at_rest);
  return finish_pull(q.m, q.p, q.spec, q.at_rest);
}

namespace {

// Whether two trials' pulls are the same computation up to the arm (and where the rig's travel
// ends, which pull_together() keeps out of the shared part).
bool same_pull(const TrialSpec& a, const TrialSpec& b) {
  return a.speed == b.speed && a.acceleration == b.acceleration && a.force_limit == b.force_limit &&
         a.record_arm_parts == b.record_arm_parts && !a.keep_frames && !b.keep_frames;
}

// The pulls of `trials` (indices into specs/out; models[k] is trials[k]'s, rest the settled gown
// they all start from, out[] what its settling wrote) pulled as one while no arm has touched the
// gown: the first trial's pull, watching the other arms (watch_arms()), with a copy of it kept at
// the start of every sample. In the sample where an arm touches the gown (or where the rig
// would stop one of them), each trial goes on from that copy on its own. Until then no arm
// corrected a vertex and every arm was at rest, so each trial would have computed the same bits.
void pull_together(const std::vector<GownModel>& models, const std::vector<size_t>& trials,
                   const std::vector<TrialSpec>& specs, const std::vector<double>& dz, GownState rest,
                   const Settled& at_rest, std::vector<TrialResult>& out) {
  const GownModel& m = models[0];
  const TrialSpec& lead = specs[trials[0]];
  std::vector<double> watch;
  for (size_t k = 1; k < trials.size(); ++k)
    if (dz[k] != dz[0]) watch.push_back(dz[k] - dz[0]);
  Pulling common = start_pull(m, std::move(rest), lead, out[trials[0]]);
  Pulling fork;
  bool at_common = false;  // every trial goes on from `common` itself, not from `fork`
  for (;;) {
    // The rig's profile and its stops agree while no trial's end of travel (or time) is near.
    const double t_next = pull_time(m, common.step + 3);
    const double travel_next = Profile{lead.acceleration, lead.speed, 1e300}.travel(t_next);
    bool near_end = common.ended;
    for (size_t b : trials)
      near_end = near_end || travel_next >= specs[b].max_travel - 1e-9 || t_next >= max_time_of(specs[b]);
    if (near_end) {
      at_common = true;
      break;
    }
    fork = common;  // vectors keep their storage: no allocation after the first sample
    bool touched = false;
    pull_sample(m, common, lead, at_rest, watch, &touched);
    if (touched || common.ended) break;
  }
  const Pulling& base = at_common ? common : fork;
  const double shared_travel = base.r.seq.samples.empty() ? 0.0 : base.r.seq.samples.back().travel;
  for (size_t k = 0; k < trials.size(); ++k) {
    const size_t b = trials[k];
    Pulling p = base;
    // The trial's own fields over the first trial's; its samples so far are the shared ones.
    p.r.arm_offset = out[b].arm_offset;
    p.r.settle_shared = out[b].settle_shared;
    p.r.wall_settle = out[b].wall_settle;
    p.r.opening = out[b].opening;
    if (k > 0) p.r.wall_pull = 0;
    p.r.seq.height = specs[b].height;
    p.r.seq.id = std::string("sim-") + std::string(arm_height_name(specs[b].height)) + "-" + std::to_string(specs[b].seed);
    p.r.pull_shared_travel = k > 0 ? shared_travel : 0.0;
    pull_alone(models[k], p, specs[b], at_rest);
    out[b] = finish_pull(models[k], p, specs[b], at_rest);
  }
}

}  // namespace

std::vector<TrialResult> simulate_trials(const Scene& scene, const ClothParams& params,
                                         const std::vector<TrialSpec>& specs) {
  for (const TrialSpec& sp : specs) check_spec(sp);
  const SceneData& sc = scene.data();
  std::vector<TrialResult> out(specs.size());
  std::vector<TrialDraws> draws;
  for (const TrialSpec& sp : specs) draws.push_back(draw(sp));
  std::vector<uint8_t> done(specs.size(), 0);
  for (size_t a = 0; a < specs.size(); ++a) {
    if (done[a]) continue;
    // The trials after `a` that settle the same way, and the other arms among them relative to
    // a's (a trial whose arm is where a's is, to the bit, settles exactly as a does whether or
    // not the arm touches the gown: it needs no probe).
    const double dz_a = arm_dz_of(sc, specs[a], draws[a].arm_offset);
    std::vector<size_t> group;
    std::vector<double> probe;
    for (size_t b = a + 1; b < specs.size(); ++b)
      if (!done[b] && same_settling(specs[a], draws[a], specs[b], draws[b])) {
        group.push_back(b);
        const double dz = arm_dz_of(sc, specs[b], draws[b].arm_offset) - dz_a;
        if (dz != 0) probe.push_back(dz);
      }
    GownModel m = make_model(sc, params, specs[a].friction_scheme, specs[a].self_collision, dz_a);
    GownState s = make_state(m);
    TrialResult& r = out[a];
    r.arm_offset = draws[a].arm_offset;
    const Settled at_rest = settle(m, s, specs[a], draws[a], probe, r);
    done[a] = 1;
    // A trial of the group starts its pull from this settling when its arm is a's (the same
    // model, the same bits), or when no arm touched the gown while it settled (then no arm acted
    // on it, and every watched arm height would have settled to these bits; watch_arms()). The
    // others settle on their own later, grouped among themselves. Of those starting here, the
    // ones whose pulls agree with a's are pulled as one until an arm touches (pull_together()).
    std::vector<size_t> together{a};
    std::vector<GownModel> models;  // together's, a's first once another joins
    std::vector<double> dz{dz_a};
    for (size_t b : group) {
      const double dz_b = arm_dz_of(sc, specs[b], draws[b].arm_offset);
      if (at_rest.arm_touched && dz_b != dz_a) continue;
      // r holds only what the settling wrote (weight, bias, settle_*; no frames in a group).
      out[b] = r;
      out[b].arm_offset = draws[b].arm_offset;
      out[b].wall_settle = 0;
      out[b].settle_shared = true;
      done[b] = 1;
      GownModel mb = m;
      place_arm(mb, dz_b);
      // The opening was measured against a's fist: b's own lies dz_b - dz_a away.
      if (!sc.opening.empty()) out[b].opening = opening_shape(mb, s);
      if (same_pull(specs[a], specs[b])) {
        if (models.empty()) models.push_back(m);
        together.push_back(b);
        models.push_back(std::move(mb));
        dz.push_back(dz_b);
      } else {
        out[b] = pull(mb, s, specs[b], at_rest, std::move(out[b]));
      }
    }
    if (together.size() > 1) {
      pull_together(models, together, specs, dz, std::move(s), at_rest, out);
    } else {
      out[a] = pull(m, std::move(s), specs[a], at_rest, std::move(out[a]));
    }
  }
  return out;
}

}  // namespace dressguard::sim
