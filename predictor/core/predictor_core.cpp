// The predictor's logic (see predictor_core.h for the per-sample steps and the real-time contract).
#include "predictor_core.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace dressguard::predictor {

using protocol::E2EStatus;
using protocol::MsgId;
using protocol::PredictorState;
using protocol::StatusCounter;

const char* event_kind_name(EventKind k) {
  switch (k) {
    case EventKind::TrialStarted: return "trial_started";
    case EventKind::TrialEnded: return "trial_ended";
    case EventKind::BadFrame: return "bad_frame";
    case EventKind::LostFrames: return "lost_frames";
    case EventKind::KernelDrops: return "kernel_drops";
    case EventKind::StopSent: return "stop_sent";
    case EventKind::StopConfirmed: return "stop_confirmed";
    case EventKind::StopRetry: return "stop_retry";
    case EventKind::TxError: return "tx_error";
    case EventKind::ReceiveError: return "receive_error";
    case EventKind::BusError: return "bus_error";
    case EventKind::ModelMissing: return "model_missing";
    case EventKind::StopDropped: return "stop_dropped";
    case EventKind::Posteriors: return "posteriors";
  }
  return "unknown";
}

double commanded_travel(double speed, double accel, double t) noexcept {
  if (t <= 0.0 || speed <= 0.0) return 0.0;
  if (accel <= 0.0) return speed * t;
  const double t_ramp = speed / accel;
  if (t < t_ramp) return 0.5 * accel * t * t;
  return speed * speed / (2.0 * accel) + speed * (t - t_ramp);
}

// ---------------------------------------------------------------------------------------------
// Configuration file

namespace {

// Names line `line` of the text being parsed: "FILE:LINE", or "--set N" for an override.
using LineName = std::function<std::string(long)>;

[[noreturn]] void config_error(const LineName& name, long line, const std::string& what) {
  throw std::runtime_error(name(line) + ": " + what);
}

// The largest period or deadline (10 min) and force (1 kN: three times a Robotiq FT 300's range).
constexpr double kMaxConfigMs = 600'000.0;
constexpr double kMaxConfigNewtons = 1000.0;

// A bound as a person writes it: 0.001, 127, 1e+06.
std::string config_text(double d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", d);
  return buf;
}

double config_number(const LineName& name, long line, const std::string& key, const std::string& v) {
  size_t used = 0;
  double d = 0;
  try {
    d = std::stod(v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != v.size() || !std::isfinite(d)) config_error(name, line, key + ": '" + v + "' is not a number");
  return d;
}

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

// A key the file gives twice: the last would win in silence (a line appended at the end by
// someone who did not see the first), so it is an error naming both lines. Lines past
// `file_lines` are --set overrides, which may repeat a key: overriding is what they are for.
void check_given_once(std::map<std::string, long>& first_line, const std::string& key, long line, long file_lines,
                      const LineName& name) {
  if (line > file_lines) return;
  const auto [first, fresh] = first_line.emplace(key, line);
  if (!fresh) config_error(name, line, "key '" + key + "' given twice (first on " + name(first->second) + ")");
}

PredictorConfig parse_config_text(const std::string& text, const LineName& name, std::vector<ConfigEntry>* others,
                                  long file_lines) {
  PredictorConfig c;
  std::istringstream in(text);
  std::string raw;
  long line = 0;
  long limit_line = 0, bias_line = 0;  // where hard_limit_n and mount_bias were given
  std::map<std::string, long> first_line;  // each key's line in the file
  while (std::getline(in, raw)) {
    ++line;
    const size_t hash = raw.find('#');
    const std::string s = trim(hash == std::string::npos ? raw : raw.substr(0, hash));
    if (s.empty()) continue;
    const size_t eq = s.find('=');
    if (eq == std::string::npos) config_error(name, line, "expected 'key = value'");
    const std::string key = trim(s.substr(0, eq)), v = trim(s.substr(eq + 1));
    check_given_once(first_line, key, line, file_lines, name);
    auto num = [&] { return config_number(name, line, key, v); };
    // Every value has a range: beyond it a typo would overflow the integer it is stored in (in
    // practice a negative count or a deadline already past, silently) or make no physical sense.
    auto bounded = [&](double d, double lo, double hi, const std::string& given) {
      if (d < lo || d > hi) config_error(name, line, key + " must be in [" + config_text(lo) + ", " + config_text(hi) + "], not " + given);
      return d;
    };
    auto in_range = [&](double lo, double hi) { return bounded(num(), lo, hi, v); };
    auto whole = [&](double lo, double hi) {  // a count: 2.5 samples is a typo, not 2
      const double d = in_range(lo, hi);
      if (d != std::floor(d)) config_error(name, line, key + " must be a whole number, not " + v);
      return static_cast<int>(d);
    };
    auto ms = [&] { return static_cast<int64_t>(in_range(0.001, kMaxConfigMs) * 1e6); };
    if (key == "stop_threshold") {
      c.stop_threshold = num();
      if (!(c.stop_threshold > 0.0 && c.stop_threshold < 1.0)) config_error(name, line, "stop_threshold must be in (0, 1)");
    } else if (key == "stop_consecutive") {
      c.stop_consecutive = whole(1, 1e6);
    } else if (key == "hard_limit_n") {
      c.hard_limit_n = in_range(0.01, kMaxConfigNewtons);
      limit_line = line;
    } else if (key == "sensor_timeout_ms") {
      c.sensor_timeout_ns = ms();
    } else if (key == "bad_frame_budget") {
      c.bad_frame_budget = whole(0, 1e6);
    } else if (key == "bad_frame_weight") {
      c.bad_frame_weight = whole(1, 1e6);
    } else if (key == "max_delta_counter") {
      c.max_delta_counter = static_cast<uint8_t>(whole(1, 127));
    } else if (key == "status_period_ms") {
      c.status_period_ns = ms();
    } else if (key == "heartbeat_period_ms") {
      c.heartbeat_period_ns = ms();
    } else if (key == "posteriors_period_ms") {
      c.posteriors_period_ns = ms();
    } else if (key == "stop_retry_ms") {
      c.stop_retry_ns = ms();
    } else if (key == "sample_period_ms") {
      c.sample_period_s = in_range(0.001, kMaxConfigMs) / 1000.0;
    } else if (key == "acceleration_m_s2") {
      c.acceleration_m_s2 = in_range(0.0, 1000.0);
    } else if (key == "mount_axes") {
      // Three tokens, one per rig axis (motion, lateral, vertical): [-]x|y|z.
      std::istringstream t(v);
      std::string tok;
      int k = 0;
      bool used[3] = {false, false, false};  // each sensor axis once: "x x z" would read x twice
      while (t >> tok) {
        if (k == 3) config_error(name, line, "mount_axes takes three axes");
        double sign = 1.0;
        if (tok[0] == '-' || tok[0] == '+') {
          sign = tok[0] == '-' ? -1.0 : 1.0;
          tok = tok.substr(1);
        }
        if (tok != "x" && tok != "y" && tok != "z") config_error(name, line, "mount_axes: '" + tok + "' is not x, y or z");
        if (used[tok[0] - 'x']) config_error(name, line, "mount_axes: sensor axis " + tok + " given twice");
        used[tok[0] - 'x'] = true;
        c.mount.axis[k] = tok[0] - 'x';
        c.mount.sign[k] = sign;
        ++k;
      }
      if (k != 3) config_error(name, line, "mount_axes takes three axes");
    } else if (key == "mount_bias") {
      std::istringstream t(v);
      for (int k = 0; k < 3; ++k) {
        std::string tok;
        if (!(t >> tok)) config_error(name, line, "mount_bias takes three numbers [N]");
        c.mount.bias[k] = bounded(config_number(name, line, key, tok), -kMaxConfigNewtons, kMaxConfigNewtons, tok);
      }
      bias_line = line;
    } else if (others) {
      others->push_back({key, v, line, name(line)});
    } else {
      config_error(name, line, "unknown key '" + key + "'");
    }
  }
  // A saturated reading (+-327.67 N, the protocol's int16 counts) less the mount bias must still
  // be beyond the hard limit on both axes it watches, in both directions: else saturation would
  // hide the very stop the limit is for.
  const double saturated = protocol::force_newtons(32767);
  for (const int k : {0, 2}) {
    if (c.hard_limit_n + std::fabs(c.mount.bias[k]) < saturated) continue;
    config_error(name, limit_line ? limit_line : bias_line,
                 "hard_limit_n " + config_text(c.hard_limit_n) + " N plus the mount bias's " +
                     config_text(std::fabs(c.mount.bias[k])) + " N on the " + (k == 0 ? "motion" : "vertical") +
                     " axis must stay below the " + config_text(saturated) +
                     " N where the protocol's forces saturate (a saturated reading would never pass it)");
  }
  return c;
}

}  // namespace

PredictorConfig parse_predictor_config(const std::string& text, const std::string& name, std::vector<ConfigEntry>* others) {
  return parse_config_text(text, [&](long line) { return name + ":" + std::to_string(line); }, others,
                           std::numeric_limits<long>::max());
}

PredictorConfig parse_config_with_sets(const std::string& file_text, const std::string& file_name,
                                       const std::vector<std::string>& sets, std::vector<ConfigEntry>* others) {
  // One text, so that the cross-key checks (hard_limit_n against mount_bias) see the final
  // values, and a line-by-line name for it. A file without a final newline would otherwise join
  // the first --set to its last line.
  std::string text = file_text;
  if (!text.empty() && text.back() != '\n') text += '\n';
  std::vector<std::string> names;  // names[i]: line i + 1
  for (char ch : text)
    if (ch == '\n') names.push_back(file_name + ":" + std::to_string(names.size() + 1));
  const long file_lines = static_cast<long>(names.size());
  for (size_t k = 0; k < sets.size(); ++k) {
    text += sets[k] + "\n";
    const std::string set = "--set " + std::to_string(k + 1);
    for (char ch : sets[k] + "\n")  // a value with a newline in it is still that --set
      if (ch == '\n') names.push_back(set);
  }
  auto name = [&](long line) {
    return line >= 1 && line <= static_cast<long>(names.size()) ? names[line - 1] : file_name;
  };
  return parse_config_text(text, name, others, file_lines);
}

long config_whole_number(const ConfigEntry& e, long lo, long hi) {
  try {
    size_t used = 0;
    const long v = std::stol(e.value, &used);
    if (used == e.value.size() && v >= lo && v <= hi) return v;
  } catch (const std::exception&) {
  }
  throw std::runtime_error(e.where + ": " + e.key + ": '" + e.value + "' is not a whole number in " +
                           std::to_string(lo) + "-" + std::to_string(hi));
}

long max_tick_ms(const PredictorConfig& cfg) {
  return std::max<long>(1, static_cast<long>(cfg.sensor_timeout_ns / 1'000'000));
}

namespace {
// A sample period in milliseconds as the config writes it ("10", "8.5").
std::string period_ms(double period_s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", period_s * 1000.0);
  return buf;
}
}  // namespace

// The messages are joined strings, not one fixed buffer: a model path may be as long as PATH_MAX.
PeriodCheck check_model_period(const model::OutcomeModel& m, const std::string& model_path, double sample_period_s) {
  if (!m.knows_period())
    return {PeriodVerdict::Unknown, model_path + " does not say at which sample period it was trained (format version " +
                                        std::to_string(model::format_version_of(m)) +
                                        "): it is run at sample_period_ms " + period_ms(sample_period_s) + " unchecked"};
  if (model::same_period(m.sample_period_s, sample_period_s)) return {};
  return {PeriodVerdict::Differs, model_path + " was trained at a sample period of " + period_ms(m.sample_period_s) +
                                      " ms, the config's sample_period_ms is " + period_ms(sample_period_s) +
                                      ": refusing it (its HMMs count time in samples; retrain at this rate or fix "
                                      "sample_period_ms)"};
}

// ---------------------------------------------------------------------------------------------
// Predictor

Predictor::Predictor(const model::OutcomeModel* model, const PredictorConfig& cfg, PredictorSink& sink)
    : cfg_(cfg),
      sink_(sink),
      chk_force_(MsgId::FtForce, cfg.max_delta_counter),
      chk_torque_(MsgId::FtTorque, cfg.max_delta_counter),
      chk_start_(MsgId::TrialStart, 127),
      chk_end_(MsgId::TrialEnd, 127),
      chk_hb_(MsgId::HeartbeatBridge, 127) {
  if (model) {
    caught_ = model->class_index("caught");
    if (caught_ < 0) throw model::ModelError("model has no class named 'caught': the predictor cannot stop on it");
    filter_.emplace(*model);
    threshold_ = model->stop_threshold;
    consecutive_needed_ = model->stop_consecutive;
    if (model->knows_speeds()) {  // in mm/s as the TrialStart says it
      speed_min_mm_s_ = static_cast<int>(std::lround(model->speed_min_m_s * 1000.0));
      speed_max_mm_s_ = static_cast<int>(std::lround(model->speed_max_m_s * 1000.0));
    }
  }
  if (cfg_.stop_threshold > 0.0 && cfg_.stop_threshold < 1.0) threshold_ = cfg_.stop_threshold;
  if (cfg_.stop_consecutive > 0) consecutive_needed_ = cfg_.stop_consecutive;
  if (consecutive_needed_ < 1) consecutive_needed_ = 1;
  decision_.state = filter_ ? PredictorState::Idle : PredictorState::Fault;
}

bool Predictor::outside_training_speeds(uint16_t speed_mm_s) const noexcept {
  if (speed_max_mm_s_ == 0) return false;  // the model does not say
  return speed_mm_s < speed_min_mm_s_ - kSpeedSlackMmS || speed_mm_s > speed_max_mm_s_ + kSpeedSlackMmS;
}

Event Predictor::make_event(EventKind k, int64_t now_ns) const noexcept {
  Event e;
  e.kind = k;
  e.time_ns = now_ns;
  e.trial = decision_.trial;
  e.sample = decision_.sample;
  return e;
}

bool Predictor::checked(protocol::E2EChecker& chk, const Frame& f, int64_t now_ns, uint32_t& lost,
                        bool charge_lost) noexcept {
  const E2EStatus s = chk.check(f, lost);
  switch (s) {
    case E2EStatus::Ok:
    case E2EStatus::Initial: return true;
    case E2EStatus::OkSomeLost:
    case E2EStatus::WrongSequence: {
      if (s == E2EStatus::WrongSequence) count(StatusCounter::WrongSequence);
      count(StatusCounter::LostFrames, lost);
      Event e = make_event(EventKind::LostFrames, now_ns);
      e.can_id = f.id;
      e.status = s;
      e.value = lost;
      emit(e);
      if (charge_lost) charge_bad(lost, now_ns);
      return true;
    }
    case E2EStatus::Repeated: count(StatusCounter::Repeated); break;
    case E2EStatus::Late: count(StatusCounter::Late); break;
    case E2EStatus::Corrupted: count(StatusCounter::Corrupted); charge_bad(1, now_ns); break;
    case E2EStatus::BadLength: count(StatusCounter::BadLength); charge_bad(1, now_ns); break;
  }
  Event e = make_event(EventKind::BadFrame, now_ns);
  e.can_id = f.id;
  e.status = s;
  emit(e);
  return false;
}

// Leaky bucket: +weight per bad frame, -1 per accepted sample (in on_force), stop above
// budget * weight. Repeated and late frames are not charged: they carry no new data, and a
// sensor that only repeats itself is caught by the deadline.
void Predictor::charge_bad(uint32_t frames, int64_t now_ns) noexcept {
  bad_score_ += static_cast<int64_t>(frames) * cfg_.bad_frame_weight;
  if (decision_.state == PredictorState::InTrial &&
      bad_score_ > static_cast<int64_t>(cfg_.bad_frame_budget) * cfg_.bad_frame_weight)
    stop(StopReason::BadFrames, now_ns);
}

void Predictor::on_frame(const Frame& f, int64_t now_ns) noexcept {
  if (start_ns_ < 0) start_ns_ = now_ns;
  uint32_t lost = 0;
  switch (f.id) {
    case protocol::id_of(MsgId::FtForce): on_force(f, now_ns); break;
    case protocol::id_of(MsgId::FtTorque):
      // Torques are E2E-checked and counted; the outcome models use forces only (section V-B).
      checked(chk_torque_, f, now_ns, lost);
      break;
    case protocol::id_of(MsgId::TrialStart): on_trial_start(f, now_ns); break;
    case protocol::id_of(MsgId::TrialEnd): on_trial_end(f, now_ns); break;
    case protocol::id_of(MsgId::HeartbeatBridge): checked(chk_hb_, f, now_ns, lost); break;
    default: break;  // the kernel filters let nothing else through; replay may see anything
  }
}

// Trial frames are sporadic: a counter seen again after a long silence is a restarted robot
// controller, not a duplicate, so their checkers resynchronise after kEventResyncNs.
void Predictor::resync_events(int64_t now_ns) noexcept {
  if (last_event_ns_ >= 0 && now_ns - last_event_ns_ > kEventResyncNs) {
    chk_start_.reset();
    chk_end_.reset();
  }
  last_event_ns_ = now_ns;
}

void Predictor::on_trial_start(const Frame& f, int64_t now_ns) noexcept {
  uint32_t lost = 0;
  resync_events(now_ns);
  if (!checked(chk_start_, f, now_ns, lost, false)) return;
  chk_end_.reset();  // this trial's end is the first of its kind
  // The sample stream resynchronises at a trial start: its first sample is sample 0, and a
  // counter jump since the previous trial is no loss inside this one.
  chk_force_.reset();
  chk_torque_.reset();
  protocol::TrialStart m;
  protocol::decode(f, m);
  // A pending stop names a trial that is over: it is not resent into this one (the robot would
  // be latched with another trial's reason and id). If it has waited a whole retry period or
  // more for its echo, the stop socket cannot send, and this trial is refused: a guard that
  // cannot send a stop cannot guard it. A younger one (decided moments ago) is simply dropped;
  // its echo, if it comes, is ignored.
  const bool unconfirmed = stop_pending_ && now_ns - stop_decided_ns_ >= cfg_.stop_retry_ns;
  if (stop_pending_ && !unconfirmed) {
    // Logged: a stop nobody saw leave is worth a line even when it no longer matters.
    Event e = make_event(EventKind::StopDropped, now_ns);  // names the finished trial
    e.reason = decision_.reason;
    e.value = static_cast<uint32_t>((now_ns - stop_decided_ns_) / 1000);  // [us] < stop_retry_ns
    emit(e);
  }
  stop_pending_ = false;
  trial_ended_ = false;
  decision_ = Decision{};
  ++trials_started_;
  decision_.trial = m.trial_id;
  decision_.speed_m_s = m.speed_mm_s / 1000.0;
  if (outside_training_speeds(m.speed_mm_s)) ++trials_outside_speeds_;
  decision_.state = filter_ ? PredictorState::InTrial : PredictorState::Fault;
  consecutive_ = 0;
  bad_score_ = 0;
  samples_started_ = false;
  trial_start_ns_ = now_ns;
  last_sample_ns_ = now_ns;  // the deadline runs from the trial start until the first sample
  emit(make_event(EventKind::TrialStarted, now_ns));
  if (filter_) filter_->reset();
  if (shutting_down_) {
    stop(StopReason::Shutdown, now_ns);
  } else if (!filter_) {
    emit(make_event(EventKind::ModelMissing, now_ns));
    stop(StopReason::ModelError, now_ns);
  } else if (unconfirmed) {
    stop(StopReason::StopUnconfirmed, now_ns);
  }
}

void Predictor::on_trial_end(const Frame& f, int64_t now_ns) noexcept {
  uint32_t lost = 0;
  resync_events(now_ns);
  if (!checked(chk_end_, f, now_ns, lost, false)) return;
  protocol::TrialEnd m;
  protocol::decode(f, m);
  if (m.trial_id != decision_.trial) return;  // the end of a trial we never saw start
  Event e = make_event(EventKind::TrialEnded, now_ns);
  e.reason = decision_.reason;
  e.value = m.samples;
  emit(e);
  trial_ended_ = true;
  // A stop stays latched while its frame is unconfirmed (on_stop_echo rests it then).
  if (decision_.state == PredictorState::InTrial || (decision_.state == PredictorState::Stopped && !stop_pending_))
    decision_.state = rest_state();
}

void Predictor::on_force(const Frame& f, int64_t now_ns) noexcept {
  uint32_t lost = 0;
  if (!checked(chk_force_, f, now_ns, lost, false)) return;
  count(StatusCounter::Samples);
  if (decision_.state != PredictorState::InTrial) {
    charge_bad(lost, now_ns);  // outside a trial it stops nothing
    return;
  }
  // Logical time: the sensor's counter, lost samples included (the first sample of a trial is 0).
  if (samples_started_) decision_.sample += 1 + lost;
  samples_started_ = true;
  last_sample_ns_ = now_ns;
  // The lost samples, charged now: a bad-frames stop names this sample, the one that decided.
  charge_bad(lost, now_ns);
  if (decision_.state != PredictorState::InTrial) return;
  if (bad_score_ > 0) --bad_score_;

  // Scaling and mounting: sensor counts -> rig axes [N].
  protocol::FtForce m;
  protocol::decode(f, m);
  const double fs[3] = {protocol::force_newtons(m.fx), protocol::force_newtons(m.fy), protocol::force_newtons(m.fz)};
  double rig[3];
  for (int k = 0; k < 3; ++k) rig[k] = cfg_.mount.sign[k] * fs[cfg_.mount.axis[k]] - cfg_.mount.bias[k];

  filter_->step(rig[0], rig[1], rig[2]);
  decision_.stop_f_motion = rig[0];
  decision_.stop_f_vertical = rig[2];

  // StopPolicy, hard limit first: it needs no model to be right.
  if (std::fabs(rig[0]) > cfg_.hard_limit_n || std::fabs(rig[2]) > cfg_.hard_limit_n) {
    stop(StopReason::HardLimit, now_ns);
    return;
  }
  // Posteriors that are NaN would never exceed the threshold: a filter that failed is a fault.
  if (filter_->failed()) {
    stop(StopReason::ModelError, now_ns);
    return;
  }
  if (filter_->posterior(caught_) > threshold_) {
    if (++consecutive_ >= consecutive_needed_) stop(StopReason::Caught, now_ns);
  } else {
    consecutive_ = 0;
  }
}

void Predictor::stop(StopReason r, int64_t now_ns) noexcept {
  if (decision_.state == PredictorState::Stopped) return;
  decision_.state = PredictorState::Stopped;
  decision_.reason = r;
  decision_.stop_sample = decision_.sample;
  for (int c = 0; c < 3; ++c) decision_.stop_p[c] = (filter_ && c < filter_->classes()) ? filter_->posterior(c) : 0.0;
  count(StatusCounter::Stops);
  const double pc = (filter_ && caught_ >= 0) ? filter_->posterior(caught_) : 0.0;
  stop_frame_ = protocol::encode(protocol::Stop{0, r, static_cast<uint8_t>(std::lround(pc * 255.0)), decision_.trial,
                                                static_cast<uint16_t>(decision_.sample)});
  stop_pending_ = true;
  stop_decided_ns_ = now_ns;
  stop_retries_ = 0;
  send_stop_frame(now_ns);
  Event e = make_event(EventKind::StopSent, now_ns);
  e.reason = r;
  e.f_motion = decision_.stop_f_motion;
  e.f_vertical = decision_.stop_f_vertical;
  for (int c = 0; c < 3; ++c) e.p[c] = decision_.stop_p[c];
  emit(e);
}

// Every (re)transmission takes a fresh alive counter, so the receiver's E2E check never
// discards a retry as "repeated"; the echo is matched by that counter.
void Predictor::send_stop_frame(int64_t now_ns) noexcept {
  stop_frame_.data[1] = ctr_stop_.next();
  protocol::protect(stop_frame_, MsgId::Stop);
  stop_sent_ns_ = now_ns;
  const uint8_t r = sink_.transmit_stop(stop_frame_);
  if (r != 0) {
    count(StatusCounter::TxErrors);
    Event e = make_event(EventKind::TxError, now_ns);
    e.can_id = stop_frame_.id;
    e.send_result = r;
    emit(e);
  }
}

void Predictor::on_stop_echo(const Frame& f, int64_t now_ns) noexcept {
  if (!stop_pending_ || f.id != stop_frame_.id || f.data[1] != stop_frame_.data[1]) return;
  stop_pending_ = false;
  Event e = make_event(EventKind::StopConfirmed, now_ns);
  e.reason = decision_.reason;
  e.value = stop_retries_;
  emit(e);
  if (trial_ended_ && decision_.state == PredictorState::Stopped) decision_.state = rest_state();
}

void Predictor::on_kernel_drops(uint32_t cumulative, int64_t now_ns) noexcept {
  if (cumulative == kernel_drops_seen_) return;
  const uint32_t d = cumulative - kernel_drops_seen_;
  kernel_drops_seen_ = cumulative;
  count(StatusCounter::KernelDrops, d);
  Event e = make_event(EventKind::KernelDrops, now_ns);
  e.value = d;
  emit(e);
}

void Predictor::on_bus_error(uint32_t error_class, int64_t now_ns) noexcept {
  count(StatusCounter::TxErrors);
  Event e = make_event(EventKind::BusError, now_ns);
  e.value = error_class;
  emit(e);
}

void Predictor::on_shutdown(int64_t now_ns) noexcept {
  shutting_down_ = true;
  if (decision_.state == PredictorState::InTrial) stop(StopReason::Shutdown, now_ns);
}

void Predictor::on_tick(int64_t now_ns) noexcept {
  if (start_ns_ < 0) {
    start_ns_ = now_ns;
    next_status_ns_ = next_hb_ns_ = next_post_ns_ = now_ns;
  }
  // Sensor deadline (E2E has no timeout of its own).
  if (decision_.state == PredictorState::InTrial && now_ns - last_sample_ns_ > cfg_.sensor_timeout_ns) {
    count(StatusCounter::Timeouts);
    // The deciding "sample" of a timeout is the one that never came.
    if (samples_started_) decision_.sample += 1;
    stop(StopReason::SensorTimeout, now_ns);
  }
  // Unconfirmed stop: resend (ENOBUFS, bus-off recovery, or a lost echo).
  if (stop_pending_ && now_ns - stop_sent_ns_ >= cfg_.stop_retry_ns) {
    ++stop_retries_;
    count(StatusCounter::TxRetries);
    Event e = make_event(EventKind::StopRetry, now_ns);
    e.value = stop_retries_;
    emit(e);
    send_stop_frame(now_ns);
  }
  const auto u16 = [](uint32_t v) { return static_cast<uint16_t>(v > 0xFFFF ? 0xFFFF : v); };
  const uint16_t uptime_s = u16(static_cast<uint32_t>((now_ns - start_ns_) / 1000000000));
  if (now_ns >= next_hb_ns_) {
    next_hb_ns_ = now_ns + cfg_.heartbeat_period_ns;
    sink_.transmit(protocol::encode(protocol::HeartbeatPredictor{ctr_hb_.next(), decision_.state,
                                                                 static_cast<uint8_t>(filter_ ? 1 : 0), decision_.trial,
                                                                 uptime_s}));
  }
  if (now_ns >= next_status_ns_) {
    next_status_ns_ = now_ns + cfg_.status_period_ns;
    const uint8_t p = status_page_;
    status_page_ = static_cast<uint8_t>((status_page_ + 1) % protocol::kStatusPages);
    // Samples is sent mod 65536 (it wraps by design); the others saturate.
    const uint32_t v0 = counters_[2 * p], v1 = counters_[2 * p + 1];
    const bool samples_page = 2 * p == static_cast<int>(StatusCounter::Samples);
    sink_.transmit(protocol::encode(protocol::PredictorStatus{ctr_status_.next(), p, decision_.state,
                                                              samples_page ? static_cast<uint16_t>(v0) : u16(v0), u16(v1)}));
  }
  if (filter_ && decision_.state != PredictorState::Idle && now_ns >= next_post_ns_) {
    next_post_ns_ = now_ns + cfg_.posteriors_period_ns;
    protocol::Posteriors m{ctr_post_.next(), static_cast<uint16_t>(decision_.sample), {0, 0, 0}, decision_.state};
    for (int c = 0; c < 3 && c < filter_->classes(); ++c)
      m.p[c] = static_cast<uint8_t>(std::lround(filter_->posterior(c) * 255.0));
    sink_.transmit(protocol::encode(m));
  }
}

}  // namespace dressguard::predictor
