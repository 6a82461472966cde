// The predictor's logic, without a bus: everything the daemon does with a frame, so that the
// daemon, `dressguard replay`, the unit tests and the benchmark run the very same code.
//
// Per F/T sample (paper section V-B, run online):
//   1. E2E check of the frame (protocol::E2EChecker): good, repeated, lost, late or corrupted;
//   2. scaling: counts -> newtons (0.01 N per count);
//   3. sensor mounting: sensor axes -> the rig's axes (motion, lateral, vertical) with signs and
//      the sensor bias, f_rig[k] = sign[k] * f_sensor[axis[k]] - bias[k];
//   4. one ForwardFilter step (the model's FeatureConvention maps rig axes to its two features);
//   5. the StopPolicy: stop when
//        - P(caught | x_1..t) > threshold for k consecutive samples (threshold and k from the
//          model, overridable in the config);
//        - |f_motion| or |f_vertical| > the hard limit (10 N, the study's own stop);
//        - fail-safe: no accepted sample for sensor_timeout (checked on every tick), more bad
//          frames than the budget allows (a leaky bucket, see BadFrameBudget), or no model
//          (a model that did not load refuses every trial).
//   6. if it fires: the stop frame, handed to the sink in the same call.
// The stop is latched until the next TrialStart; its transmission is confirmed by the stop
// socket's own echo and retried on every tick until then. A stop still pending at the next
// TrialStart is dropped (it names a trial that is over); if it had waited stop_retry_ns or more
// for its echo, the stop socket cannot send, and that trial is refused with a stop_unconfirmed
// stop of its own.
//
// Real-time contract: the constructor allocates (the filter's storage); on_frame, on_tick,
// on_stop_echo, on_kernel_drops and on_bus_error allocate nothing, lock nothing, log nothing and
// throw nothing. Everything worth logging goes to the sink as a flat Event.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "dg_protocol.h"
#include "dgm.h"
#include "forward_filter.h"

namespace dressguard::predictor {

using protocol::Frame;
using protocol::StopReason;

// How the sensor is mounted: rig axis k (0 motion, 1 lateral, 2 vertical) reads sensor axis
// axis[k] (0 x, 1 y, 2 z) times sign[k], minus bias[k] newtons.
struct SensorMount {
  int axis[3] = {0, 1, 2};
  double sign[3] = {1.0, 1.0, 1.0};
  double bias[3] = {0.0, 0.0, 0.0};
};

struct PredictorConfig {
  // StopPolicy. A threshold outside (0,1) or consecutive <= 0 means "take the model's".
  double stop_threshold = -1.0;
  int stop_consecutive = 0;
  double hard_limit_n = 10.0;            // |f| above this on the motion or vertical axis stops
  int64_t sensor_timeout_ns = 50'000'000;  // no accepted sample for this long in a trial: stop
  // Bad-frame budget (leaky bucket): every corrupted frame, lost frame or bad length adds
  // `bad_frame_weight`, every accepted sample removes 1; above budget * weight: stop. With the
  // defaults, 6 bad frames in a burst stop the robot, one in 20 samples forever does not.
  int bad_frame_budget = 5;
  int bad_frame_weight = 20;
  uint8_t max_delta_counter = 3;         // E2E: up to 2 lost frames in a row count as in sequence
  // Periodic frames (on ticks).
  int64_t status_period_ns = 100'000'000;
  int64_t heartbeat_period_ns = 100'000'000;
  int64_t posteriors_period_ns = 100'000'000;
  int64_t stop_retry_ns = 2'000'000;     // resend the stop when unconfirmed for this long
  // Logical time and the reconstructed travel (the study's rig: 100 Hz, 1 m/s^2 ramps).
  double sample_period_s = 0.01;
  double acceleration_m_s2 = 1.0;
  SensorMount mount;
};

// Reads "key = value" lines ('#' comments). Keys are PredictorConfig's names plus
// mount_axes (e.g. "x y z" or "-x z y": each sensor axis once), mount_bias ("0 0 0" N, each
// within 1000 N), sensor_timeout_ms, status_period_ms, heartbeat_period_ms, posteriors_period_ms,
// stop_retry_ms (each in (0, 600000]). Counts are whole numbers in a range (stop_consecutive
// 1..1e6, bad_frame_budget 0..1e6, bad_frame_weight 1..1e6, max_delta_counter 1..127);
// hard_limit_n is in [0.01, 1000] N, and with the mount bias's motion and vertical components
// below the 327.67 N where the protocol's forces saturate. Unknown keys, a key given twice and bad or
// out-of-range values throw std::runtime_error naming `name`, the line and the key. Keys it does not own
// (the daemon's: interface, model, rt_priority, ...) are returned in `others` when given.
struct ConfigEntry {
  std::string key, value;
  long line;
  std::string where;  // "NAME:LINE", or "--set N" (parse_config_with_sets): for its errors
};
PredictorConfig parse_predictor_config(const std::string& text, const std::string& name,
                                       std::vector<ConfigEntry>* others = nullptr);
// The daemon's configuration as dressguard-predictor and `dressguard replay` both take it: the
// file's text (empty without --config), then each --set KEY=VALUE on a line of its own, a later
// entry winning (the file itself gives each key once). As parse_predictor_config, but an error,
// and each entry's `where`, names the file's line or "--set N" (the Nth --set), never a line past
// the file's end.
PredictorConfig parse_config_with_sets(const std::string& file_text, const std::string& file_name,
                                       const std::vector<std::string>& sets, std::vector<ConfigEntry>* others);
// The keys of the daemon's config file that are not the predictor's (predictor/daemon/main.cpp
// reads them). A replay of the same file accepts and ignores them; any other key is an error.
inline constexpr const char* kDaemonConfigKeys[] = {"interface", "model",   "rt_priority", "cpu",
                                                    "mlock",     "tick_ms", "log_level",   "rt_required"};
// A daemon key's value as a whole number in lo..hi; else std::runtime_error
// "WHERE: KEY: 'VALUE' is not a whole number in LO-HI".
long config_whole_number(const ConfigEntry& e, long lo, long hi);
// The longest timer period, tick_ms (and replay's --tick-ms), that `cfg` allows: the sensor
// deadline is checked on each tick, so a tick longer than sensor_timeout_ms would let a silent
// sensor run on for up to a tick. At least 1.
long max_tick_ms(const PredictorConfig& cfg);

// Whether a model may run at the config's sample period (models/FORMAT.md, version 3). The HMMs'
// dwell times are in samples: a model trained at another rate expects every phase of a pull to
// take another number of samples. The daemon and `dressguard replay` both ask, at start-up.
enum class PeriodVerdict { Same, Unknown, Differs };
struct PeriodCheck {
  PeriodVerdict verdict = PeriodVerdict::Same;
  std::string message;  // one line naming the model file and both periods (Unknown: a warning)
};
// Differs when the model's known period and `sample_period_s` differ by more than
// model::kPeriodTolerance (relative); Unknown for a model that does not say (format 1 or 2).
PeriodCheck check_model_period(const model::OutcomeModel& m, const std::string& model_path, double sample_period_s);

// Commanded travel [m] after t seconds of a pull at `speed` with ramp `accel` (trapezoid start):
//   x(t) = a t^2 / 2                      for t < v/a
//   x(t) = v^2 / (2a) + v (t - v/a)       after.
double commanded_travel(double speed, double accel, double t) noexcept;

enum class EventKind : uint8_t {
  TrialStarted, TrialEnded, BadFrame, LostFrames, KernelDrops, StopSent, StopConfirmed, StopRetry,
  TxError, BusError, ModelMissing, Posteriors,
  StopDropped,  // a stop still unconfirmed when the next trial started (younger than a retry period)
  ReceiveError,  // the host port's recvmsg failed: value = errno, sample = failures so far, can_id = socket
};
const char* event_kind_name(EventKind k);

// A flat record of something worth logging (no pointers, no strings: it crosses a lock-free queue).
struct Event {
  EventKind kind = EventKind::TrialStarted;
  int64_t time_ns = 0;
  uint16_t trial = 0;
  uint32_t sample = 0;
  uint32_t can_id = 0;
  uint32_t value = 0;                         // lost frames, retries, error class, ...
  protocol::E2EStatus status = protocol::E2EStatus::Ok;
  StopReason reason = StopReason::None;
  uint8_t send_result = 0;                    // can::SendResult of a failed send
  double f_motion = 0, f_vertical = 0;        // [N] rig axes at the event
  double p[3] = {0, 0, 0};                    // posteriors of classes 0..2
};

// Where the predictor's output goes. transmit_stop returns a can::SendResult value (0 = ok).
class PredictorSink {
 public:
  virtual ~PredictorSink() = default;
  virtual uint8_t transmit_stop(const Frame& f) noexcept = 0;
  virtual uint8_t transmit(const Frame& f) noexcept = 0;
  virtual void event(const Event& e) noexcept = 0;
};

// The decision state after the last sample (for replay, tests and the benchmark).
struct Decision {
  protocol::PredictorState state = protocol::PredictorState::Idle;
  StopReason reason = StopReason::None;
  uint16_t trial = 0;
  uint32_t sample = 0;       // index in the trial of the last sample (logical time)
  uint32_t stop_sample = 0;  // index of the sample that stopped (when reason != None)
  double stop_p[3] = {0, 0, 0};
  double stop_f_motion = 0, stop_f_vertical = 0;
  double speed_m_s = 0.1;
};

class Predictor {
 public:
  // `model` may be null: the model did not load (`model_error` says why, for the log); every
  // trial is then refused with a ModelError stop. Throws model::ModelError if the model has no
  // "caught" class. Allocates here and nowhere else.
  Predictor(const model::OutcomeModel* model, const PredictorConfig& cfg, PredictorSink& sink);

  // A received frame (any identifier; unknown ones are ignored) at monotonic time now_ns.
  void on_frame(const Frame& f, int64_t now_ns) noexcept;
  // The periodic timer: sensor deadline, stop retries, status, heartbeat, posteriors.
  void on_tick(int64_t now_ns) noexcept;
  // Our stop frame came back on the stop socket: it is on the bus.
  void on_stop_echo(const Frame& f, int64_t now_ns) noexcept;
  // Cumulative kernel drop count of the receive socket (SO_RXQ_OVFL).
  void on_kernel_drops(uint32_t cumulative, int64_t now_ns) noexcept;
  // A controller error frame (bus-off, ...): counted and logged; a pending stop keeps retrying.
  void on_bus_error(uint32_t error_class, int64_t now_ns) noexcept;
  // SIGTERM: stops the robot if a trial is running (the guard is going away), and refuses every
  // trial that starts after it with a Shutdown stop (the daemon may still be waiting for the
  // echo of its last stop then; a trial it let run would be unguarded once it has gone).
  void on_shutdown(int64_t now_ns) noexcept;

  const Decision& decision() const noexcept { return decision_; }
  uint32_t counter(protocol::StatusCounter c) const noexcept { return counters_[static_cast<int>(c)]; }
  bool stop_pending() const noexcept { return stop_pending_; }
  uint32_t trials_started() const noexcept { return trials_started_; }
  // Trials whose TrialStart speed lay outside the model's training speed range by more than
  // kSpeedSlackMmS (models/FORMAT.md, version 3): a pull the model never saw. Not a status
  // counter: the protocol's status pages have no free field (firmware-bridge/PROTOCOL.md).
  uint32_t trials_outside_training_speeds() const noexcept { return trials_outside_speeds_; }
  static constexpr int kSpeedSlackMmS = 5;
  bool has_model() const noexcept { return filter_.has_value(); }
  double threshold() const noexcept { return threshold_; }
  int consecutive() const noexcept { return consecutive_needed_; }
  int caught_class() const noexcept { return caught_; }
  const filter::ForwardFilter* filter() const noexcept { return filter_ ? &*filter_ : nullptr; }

 private:
  void on_force(const Frame& f, int64_t now_ns) noexcept;
  void on_trial_start(const Frame& f, int64_t now_ns) noexcept;
  bool outside_training_speeds(uint16_t speed_mm_s) const noexcept;
  void on_trial_end(const Frame& f, int64_t now_ns) noexcept;
  void resync_events(int64_t now_ns) noexcept;
  static constexpr int64_t kEventResyncNs = int64_t{protocol::kSporadicResyncMs} * 1'000'000;
  // E2E check with counting; true when the frame may be used.
  // `charge_lost`: lost frames go to the bad-frame budget at once. Force frames charge them
  // after advancing the sample index (the stop names the sample that decided); trial frames not
  // at all (sporadic: a lost start or end of another trial says nothing of this one's data).
  bool checked(protocol::E2EChecker& chk, const Frame& f, int64_t now_ns, uint32_t& lost,
               bool charge_lost = true) noexcept;
  // Where a trial that is over rests: Idle, or Fault without a model.
  protocol::PredictorState rest_state() const noexcept {
    return filter_ ? protocol::PredictorState::Idle : protocol::PredictorState::Fault;
  }
  void charge_bad(uint32_t frames, int64_t now_ns) noexcept;
  void stop(StopReason r, int64_t now_ns) noexcept;
  void send_stop_frame(int64_t now_ns) noexcept;
  void count(protocol::StatusCounter c, uint32_t n = 1) noexcept { counters_[static_cast<int>(c)] += n; }
  void emit(Event e) noexcept { sink_.event(e); }
  Event make_event(EventKind k, int64_t now_ns) const noexcept;

  // Constant after construction.
  PredictorConfig cfg_;
  PredictorSink& sink_;
  std::optional<filter::ForwardFilter> filter_;
  int caught_ = -1;
  double threshold_ = 0.9;
  int consecutive_needed_ = 5;
  int speed_min_mm_s_ = 0, speed_max_mm_s_ = 0;  // the model's training speeds; 0: unknown

  // Mutable state.
  protocol::E2EChecker chk_force_{protocol::MsgId::FtForce};
  protocol::E2EChecker chk_torque_{protocol::MsgId::FtTorque};
  protocol::E2EChecker chk_start_{protocol::MsgId::TrialStart};
  protocol::E2EChecker chk_end_{protocol::MsgId::TrialEnd};
  protocol::E2EChecker chk_hb_{protocol::MsgId::HeartbeatBridge};
  Decision decision_;
  std::array<uint32_t, static_cast<int>(protocol::StatusCounter::Count)> counters_{};
  int consecutive_ = 0;
  uint32_t trials_outside_speeds_ = 0;
  int64_t bad_score_ = 0;
  bool samples_started_ = false;  // first sample of the trial seen (sample indices start)
  int64_t last_sample_ns_ = 0;
  int64_t trial_start_ns_ = 0;
  uint32_t kernel_drops_seen_ = 0;
  // Stop transmission.
  bool stop_pending_ = false;
  bool trial_ended_ = false;  // the robot ended the trial (TrialEnd); a stop's echo then rests it
  bool shutting_down_ = false;  // on_shutdown was called: every later trial is refused
  Frame stop_frame_;
  int64_t stop_decided_ns_ = 0;  // first transmission
  int64_t stop_sent_ns_ = 0;     // latest transmission
  uint32_t stop_retries_ = 0;
  // Periodic traffic.
  protocol::AliveCounter ctr_stop_, ctr_status_, ctr_post_, ctr_hb_;
  uint8_t status_page_ = 0;
  int64_t next_status_ns_ = 0, next_hb_ns_ = 0, next_post_ns_ = 0;
  int64_t start_ns_ = -1;
  uint32_t trials_started_ = 0;
  int64_t last_event_ns_ = -1;
};

}  // namespace dressguard::predictor
