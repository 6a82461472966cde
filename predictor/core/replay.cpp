// Replay of a candump log through the Predictor, with simulated ticks.
#include "replay.h"

#include <algorithm>

namespace dressguard::predictor {
namespace {

constexpr int64_t kQuietTicksNs = 60'000'000'000;  // 60 s

// Records stops and confirms each stop frame at once, as the stop socket's echo would.
class ReplaySink final : public PredictorSink {
 public:
  uint8_t transmit_stop(const Frame& f) noexcept override {
    pending = f;
    has_pending = true;
    ++stop_frames;
    return 0;
  }
  uint8_t transmit(const Frame&) noexcept override { return 0; }
  void event(const Event&) noexcept override {}
  Frame pending;
  bool has_pending = false;
  int stop_frames = 0;
};

}  // namespace

ReplayResult replay_frames(const model::OutcomeModel* model, const PredictorConfig& cfg,
                           const std::vector<protocol::LoggedFrame>& frames, int64_t tick_ns) {
  ReplaySink sink;
  Predictor p(model, cfg, sink);
  ReplayResult out;
  out.frames = frames.size();
  if (frames.empty()) return out;
  const int caught = p.caught_class();
  int64_t next_tick = frames.front().time_us * 1000;
  int64_t trial_start_ns = 0;
  int current = -1;
  auto confirm = [&](int64_t now) {
    if (sink.has_pending) {
      sink.has_pending = false;
      p.on_stop_echo(sink.pending, now);
    }
  };
  auto record_stop = [&](int64_t now) {
    if (current < 0) return;
    ReplayTrial& t = out.trials[current];
    const Decision& d = p.decision();
    if (t.stopped || d.reason == StopReason::None || d.trial != t.trial) return;
    t.stopped = true;
    t.reason = d.reason;
    t.stop_sample = d.stop_sample;
    t.stop_time = d.stop_sample * cfg.sample_period_s;
    t.travel = commanded_travel(d.speed_m_s, cfg.acceleration_m_s2, t.stop_time);
    t.log_time = (now - trial_start_ns) * 1e-9;
    std::copy(d.stop_p, d.stop_p + 3, t.p);
    t.f_motion = d.stop_f_motion;
    t.f_vertical = d.stop_f_vertical;
  };
  // Through a long silence (a log left running between sessions, a clock stepped forward) the
  // ticks stop after kQuietTicksNs plus the sensor deadline: by then the deadline has fired, and
  // nothing else a replay records happens on a tick. The next tick is the last one before the
  // frame, in phase. (Ticking every millisecond through a jump of years took hours.)
  auto tick_until = [&](int64_t t_ns) {
    const int64_t quiet_end = next_tick + kQuietTicksNs + cfg.sensor_timeout_ns;
    while (next_tick <= t_ns) {
      if (next_tick > quiet_end && t_ns - next_tick > tick_ns) next_tick += (t_ns - next_tick) / tick_ns * tick_ns;
      p.on_tick(next_tick);
      record_stop(next_tick);
      confirm(next_tick);
      next_tick += tick_ns;
    }
  };
  for (const auto& lf : frames) {
    const int64_t now = lf.time_us * 1000;
    tick_until(now);
    const uint32_t started_before = p.trials_started();
    // A controller error frame goes where the daemon sends it (daemon.cpp: info.error_frame).
    if (protocol::is_error_frame(lf.frame)) p.on_bus_error(protocol::error_class_of(lf.frame), now);
    else p.on_frame(lf.frame, now);
    const Decision& d = p.decision();
    if (p.trials_started() != started_before) {
      out.trials.push_back(ReplayTrial{});
      current = static_cast<int>(out.trials.size()) - 1;
      out.trials[current].trial = d.trial;
      trial_start_ns = now;
    }
    record_stop(now);
    confirm(now);
    if (current >= 0 && d.trial == out.trials[current].trial) {
      ReplayTrial& t = out.trials[current];
      t.samples = d.sample + 1;
      if (const auto* f = p.filter(); f && caught >= 0 && d.state == protocol::PredictorState::InTrial)
        t.max_p_caught = std::max(t.max_p_caught, f->posterior(caught));
    }
  }
  tick_until(frames.back().time_us * 1000 + cfg.sensor_timeout_ns + 2 * tick_ns);
  for (int c = 0; c < static_cast<int>(protocol::StatusCounter::Count); ++c)
    out.counters.push_back(p.counter(static_cast<protocol::StatusCounter>(c)));
  out.stop_frames = sink.stop_frames;
  return out;
}

}  // namespace dressguard::predictor
