// The trial runner (paper V-A): grasp, gravity, settling with the optional perturbation, pull,
// stop, label. The haptic samples follow the rig (shared/data/README.md).
#include "trial.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

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
  double accel(double t) const { return t < v / a ? a : 0.0; }
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
  return d_max <= 0.07 ? Outcome::Good : Outcome::Caught;
}

TrialResult simulate_trial(const Scene& scene, const ClothParams& params, const TrialSpec& spec) {
  const SceneData& sc = scene.data();
  const int hi = static_cast<int>(spec.height);
  // One random stream per trial: the perturbation force first, then the arm-height noise.
  std::mt19937_64 rng(spec.seed);
  const double fx = uniform(rng, -6.0, 6.0), fy = uniform(rng, -6.0, 6.0);
  double arm_offset = spec.arm_offset;
  if (spec.arm_noise)
    arm_offset += spec.height == ArmHeight::Middle ? uniform(rng, -0.06, 0.0) : uniform(rng, -0.015, 0.015);
  const double arm_dz = sc.opt.arm.z_rel[hi] - sc.opt.arm.z_rel[0] + arm_offset;
  GownModel m = make_model(sc, params, spec.friction_scheme, spec.self_collision, arm_dz);
  GownState s = make_state(m);
  TrialResult r;
  r.arm_offset = arm_offset;
  double total_mass = 0;
  for (double q : m.mass) total_mass += q;
  r.weight = total_mass * 9.81;
  const int n = static_cast<int>(s.x.size());

  std::vector<double> frame_times = spec.frame_times;
  std::sort(frame_times.begin(), frame_times.end());
  size_t next_frame = 0;
  auto maybe_frame = [&](double t, double travel) {
    while (spec.keep_frames && next_frame < frame_times.size() && frame_times[next_frame] <= t + 1e-9) {
      r.frames.push_back(make_frame(s, t, travel));
      ++next_frame;
    }
  };

  // Perturbation (paper V-A): one random horizontal force, uniform in X and lateral up to 6 N,
  // spread equally over all vertices for 0.5 s (output steps 180-330), then settling until the
  // gown is at rest (TrialSpec::settle_speed).
  const auto clock0 = std::chrono::steady_clock::now();
  const int perturb_from = 180, perturb_to = 330;
  constexpr int kWindow = 30;  // 0.1 s: the rest check's window and period
  const bool adaptive = spec.settle_speed > 0;
  const int min_steps = std::max(spec.settle_steps, spec.gown_noise ? perturb_to + kWindow : 0);
  const int max_steps = adaptive ? std::max(min_steps, spec.settle_max_steps) : min_steps;
  const double cloth_decay = m.damping_factor;
  const double settle_decay = std::min(cloth_decay, std::exp(-std::max(0.0, spec.settle_damping) * m.h));
  const V3 zero{0, 0, 0};
  // Settling's frames: the pull's start is known only at the end, so snapshots every 15 steps
  // (0.05 s) as far back as the earliest requested negative time are kept and matched then.
  const double earliest = frame_times.empty() ? 0.0 : std::min(0.0, frame_times.front());
  const size_t keep_snaps = spec.keep_frames ? static_cast<size_t>(-earliest / (15 * m.dt)) + 2 : 0;
  std::vector<std::pair<int, Frame>> snaps;  // (steps done, positions)
  std::vector<V3> x_window = s.x;
  int k = 0;
  for (;;) {
    const bool on = spec.gown_noise && k >= perturb_from && k < perturb_to;
    const bool was_on = spec.gown_noise && k - 1 >= perturb_from && k - 1 < perturb_to;
    if (on != was_on)
      for (int i = 0; i < n; ++i) s.ext_force[i] = on ? V3{fx / n, fy / n, 0} : zero;
    m.damping_factor = on ? cloth_decay : settle_decay;
    if (k % 3 == 0) {  // the bias sample is the last 3 steps before the pull (settling ends on k % 3 == 0)
      s.force_acc = zero;
      s.force_count = 0;
    }
    const int close = sc.opt.jaw_close_steps;
    s.jaw_closed = close > 0 ? std::min(1.0, (k + 1.0) / close) : 1.0;
    step(m, s, zero, zero, zero);
    ++k;
    if (keep_snaps > 0 && k % 15 == 0) {
      if (snaps.size() == keep_snaps) snaps.erase(snaps.begin());
      snaps.emplace_back(k, make_frame(s, 0.0, 0.0));
    }
    if (k % kWindow == 0) {
      double v2 = 0;
      long free_count = 0;
      for (int i = 0; i < n; ++i)
        if (m.w[i] > 0) {
          const V3 d = s.x[i] - x_window[i];
          v2 += dot(d, d), ++free_count;
        }
      r.settle_speed = free_count ? std::sqrt(v2 / free_count) / (kWindow * m.dt) : 0.0;
      x_window = s.x;
    }
    if (k < min_steps || k % 3 != 0) continue;
    if (!adaptive) break;
    if (k % kWindow == 0 && (r.settle_speed <= spec.settle_speed || k >= max_steps)) break;
  }
  r.settle_steps = k;
  r.settle_time = k * m.dt;
  r.settled = !adaptive || r.settle_speed <= spec.settle_speed;
  m.damping_factor = cloth_decay;
  for (; next_frame < frame_times.size() && frame_times[next_frame] < -1e-9; ++next_frame) {
    // The snapshot nearest to the requested time before the pull.
    const double want = frame_times[next_frame];
    const std::pair<int, Frame>* best = nullptr;
    for (const auto& sn : snaps)
      if (!best || std::abs((sn.first - k) * m.dt - want) < std::abs((best->first - k) * m.dt - want)) best = &sn;
    if (!best) continue;
    r.frames.push_back(best->second);
    r.frames.back().t = (best->first - k) * m.dt;
  }
  maybe_frame(0.0, 0.0);
  for (int i = 0; i < n; ++i) s.ext_force[i] = zero;
  // The sensor is biased at the start of the trial (data README): the settled gown's force,
  // mainly its weight, is removed from every sample.
  const V3 bias = s.force_count ? (1.0 / s.force_count) * s.force_acc : zero;
  r.bias = {bias.x, bias.y, bias.z};
  // The lower half of the sleeve opening as it hangs after settling (paper Fig. 3b, red dots).
  std::vector<int32_t> lower;
  if (!sc.opening.empty()) {
    double zmean = 0;
    for (int v : sc.opening) zmean += s.x[v].z;
    zmean /= sc.opening.size();
    for (int v : sc.opening)
      if (s.x[v].z <= zmean) lower.push_back(v);
  }

  const auto clock1 = std::chrono::steady_clock::now();
  r.wall_settle = std::chrono::duration<double>(clock1 - clock0).count();
  const Profile prof{spec.acceleration, spec.speed, spec.max_travel};
  r.seq.height = spec.height;
  r.seq.speed = spec.speed;
  r.seq.id = std::string("sim-") + std::string(arm_height_name(spec.height)) + "-" + std::to_string(spec.seed);
  double t = 0;
  bool full = false;
  r.finite = all_finite(s);
  const double max_time = spec.max_travel / spec.speed + spec.speed / spec.acceleration + 5.0;
  while (r.finite && t < max_time) {
    s.force_acc = zero;
    s.force_count = 0;
    for (int i = 0; i < n; ++i) s.contact_acc[i] = zero;
    for (int k = 0; k < 3; ++k) {
      const double t1 = t + m.dt;
      const V3 g0{prof.travel(t), 0, 0}, g1{prof.travel(t1), 0, 0};
      step(m, s, g0, g1, V3{prof.accel(t), 0, 0});
      t = t1;
      maybe_frame(t, g1.x);
    }
    const V3 f = (1.0 / s.force_count) * s.force_acc - bias;
    const double travel = prof.travel(t);
    r.seq.samples.push_back({t, travel, f.x, f.y, f.z});
    r.finite = all_finite(s);
    if (r.contact_t < 0)
      for (int i = 0; i < n; ++i)
        if (s.contact_acc[i].x != 0 || s.contact_acc[i].y != 0 || s.contact_acc[i].z != 0) {
          r.contact_t = t;
          r.contact_travel = travel;
          break;
        }
    if (std::abs(f.x) >= spec.force_limit || std::abs(f.z) >= spec.force_limit) {
      r.stopped_by_force = true;
      break;
    }
    if (travel >= spec.max_travel - 1e-12) {
      full = true;
      break;
    }
  }
  r.wall_pull = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock1).count();
  r.travel = prof.travel(t);
  r.self_pairs_dropped = s.pairs_dropped;
  r.d_max = 0;
  if (!full) {
    for (int v : lower) r.d_max = std::max(r.d_max, std::abs(s.x[v].x - m.elbow.x));
  }
  r.outcome = label_outcome(full, r.d_max);
  r.seq.label = r.outcome;
  r.area_ratio = current_area(m, s) / sc.rest_area;
  // Contact force of the cloth on the arm per vertex, averaged over the last sample.
  if (s.force_count > 0)
    for (int i = 0; i < n; ++i) {
      const V3 c = (-1.0 / s.force_count) * s.contact_acc[i];
      if (c.x != 0 || c.y != 0 || c.z != 0) r.contacts.push_back({i, {c.x, c.y, c.z}});
    }
  if (spec.keep_frames && (r.frames.empty() || r.frames.back().t < t - 1e-9)) r.frames.push_back(make_frame(s, t, r.travel));
  return r;
}

}  // namespace dressguard::sim
