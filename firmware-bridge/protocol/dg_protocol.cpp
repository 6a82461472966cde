// Encoding and decoding of the dressguard CAN messages (layouts in PROTOCOL.md). Freestanding.
#include "dg_protocol.h"

namespace dressguard::protocol {
namespace {

Frame start(MsgId m, uint8_t counter) {
  Frame f;
  f.id = id_of(m);
  f.len = kFrameLength;
  f.data[1] = counter;
  return f;
}

Frame finish(Frame f, MsgId m) {
  protect(f, m);
  return f;
}

bool is(const Frame& f, MsgId m) { return f.id == id_of(m) && f.len == kFrameLength; }

}  // namespace

const char* stop_reason_name(StopReason r) {
  switch (r) {
    case StopReason::None: return "none";
    case StopReason::Caught: return "caught";
    case StopReason::HardLimit: return "hard_limit";
    case StopReason::SensorTimeout: return "sensor_timeout";
    case StopReason::BadFrames: return "bad_frames";
    case StopReason::ModelError: return "model_error";
    case StopReason::Shutdown: return "shutdown";
    case StopReason::StopUnconfirmed: return "stop_unconfirmed";
  }
  return "unknown";
}

const char* predictor_state_name(PredictorState s) {
  switch (s) {
    case PredictorState::Idle: return "idle";
    case PredictorState::InTrial: return "in_trial";
    case PredictorState::Stopped: return "stopped";
    case PredictorState::Fault: return "fault";
  }
  return "unknown";
}

const char* status_counter_name(StatusCounter c) {
  switch (c) {
    case StatusCounter::Corrupted: return "corrupted";
    case StatusCounter::Repeated: return "repeated";
    case StatusCounter::WrongSequence: return "wrong_sequence";
    case StatusCounter::LostFrames: return "lost_frames";
    case StatusCounter::Late: return "late";
    case StatusCounter::BadLength: return "bad_length";
    case StatusCounter::KernelDrops: return "kernel_drops";
    case StatusCounter::Timeouts: return "timeouts";
    case StatusCounter::TxRetries: return "tx_retries";
    case StatusCounter::TxErrors: return "tx_errors";
    case StatusCounter::Samples: return "samples";
    case StatusCounter::Stops: return "stops";
    case StatusCounter::Count: break;
  }
  return "unknown";
}

const char* e2e_status_name(E2EStatus s) {
  switch (s) {
    case E2EStatus::Ok: return "ok";
    case E2EStatus::Initial: return "initial";
    case E2EStatus::OkSomeLost: return "ok_some_lost";
    case E2EStatus::WrongSequence: return "wrong_sequence";
    case E2EStatus::Repeated: return "repeated";
    case E2EStatus::Late: return "late";
    case E2EStatus::Corrupted: return "corrupted";
    case E2EStatus::BadLength: return "bad_length";
  }
  return "unknown";
}

Frame encode(const FtForce& m) {
  Frame f = start(MsgId::FtForce, m.counter);
  put_i16(f.data + 2, m.fx);
  put_i16(f.data + 4, m.fy);
  put_i16(f.data + 6, m.fz);
  return finish(f, MsgId::FtForce);
}

Frame encode(const FtTorque& m) {
  Frame f = start(MsgId::FtTorque, m.counter);
  put_i16(f.data + 2, m.mx);
  put_i16(f.data + 4, m.my);
  put_i16(f.data + 6, m.mz);
  return finish(f, MsgId::FtTorque);
}

Frame encode(const TrialStart& m) {
  Frame f = start(MsgId::TrialStart, m.counter);
  put_u16(f.data + 2, m.trial_id);
  put_u16(f.data + 4, m.speed_mm_s);
  f.data[6] = static_cast<uint8_t>(m.height);
  return finish(f, MsgId::TrialStart);
}

Frame encode(const TrialEnd& m) {
  Frame f = start(MsgId::TrialEnd, m.counter);
  put_u16(f.data + 2, m.trial_id);
  put_u16(f.data + 4, m.samples);
  f.data[6] = static_cast<uint8_t>(m.reason);
  return finish(f, MsgId::TrialEnd);
}

Frame encode(const Stop& m) {
  Frame f = start(MsgId::Stop, m.counter);
  f.data[2] = static_cast<uint8_t>(m.reason);
  f.data[3] = m.p_caught;
  put_u16(f.data + 4, m.trial_id);
  put_u16(f.data + 6, m.sample);
  return finish(f, MsgId::Stop);
}

Frame encode(const PredictorStatus& m) {
  Frame f = start(MsgId::PredictorStatus, m.counter);
  f.data[2] = m.page;
  f.data[3] = static_cast<uint8_t>(m.state);
  put_u16(f.data + 4, m.value0);
  put_u16(f.data + 6, m.value1);
  return finish(f, MsgId::PredictorStatus);
}

Frame encode(const Posteriors& m) {
  Frame f = start(MsgId::Posteriors, m.counter);
  put_u16(f.data + 2, m.sample);
  f.data[4] = m.p[0];
  f.data[5] = m.p[1];
  f.data[6] = m.p[2];
  f.data[7] = static_cast<uint8_t>(m.state);
  return finish(f, MsgId::Posteriors);
}

Frame encode(const HeartbeatBridge& m) {
  Frame f = start(MsgId::HeartbeatBridge, m.counter);
  f.data[2] = static_cast<uint8_t>(m.state);
  f.data[3] = m.sensor_errors;
  put_u16(f.data + 4, m.reconnects);
  put_u16(f.data + 6, m.uptime_s);
  return finish(f, MsgId::HeartbeatBridge);
}

Frame encode(const HeartbeatPredictor& m) {
  Frame f = start(MsgId::HeartbeatPredictor, m.counter);
  f.data[2] = static_cast<uint8_t>(m.state);
  f.data[3] = m.model_loaded;
  put_u16(f.data + 4, m.trial_id);
  put_u16(f.data + 6, m.uptime_s);
  return finish(f, MsgId::HeartbeatPredictor);
}

bool decode(const Frame& f, FtForce& m) {
  if (!is(f, MsgId::FtForce)) return false;
  m = {f.data[1], get_i16(f.data + 2), get_i16(f.data + 4), get_i16(f.data + 6)};
  return true;
}

bool decode(const Frame& f, FtTorque& m) {
  if (!is(f, MsgId::FtTorque)) return false;
  m = {f.data[1], get_i16(f.data + 2), get_i16(f.data + 4), get_i16(f.data + 6)};
  return true;
}

bool decode(const Frame& f, TrialStart& m) {
  if (!is(f, MsgId::TrialStart)) return false;
  m = {f.data[1], get_u16(f.data + 2), get_u16(f.data + 4), static_cast<HeightClass>(f.data[6])};
  return true;
}

bool decode(const Frame& f, TrialEnd& m) {
  if (!is(f, MsgId::TrialEnd)) return false;
  m = {f.data[1], get_u16(f.data + 2), get_u16(f.data + 4), static_cast<TrialEndReason>(f.data[6])};
  return true;
}

bool decode(const Frame& f, Stop& m) {
  if (!is(f, MsgId::Stop)) return false;
  m = {f.data[1], static_cast<StopReason>(f.data[2]), f.data[3], get_u16(f.data + 4), get_u16(f.data + 6)};
  return true;
}

bool decode(const Frame& f, PredictorStatus& m) {
  if (!is(f, MsgId::PredictorStatus)) return false;
  m = {f.data[1], f.data[2], static_cast<PredictorState>(f.data[3]), get_u16(f.data + 4), get_u16(f.data + 6)};
  return true;
}

bool decode(const Frame& f, Posteriors& m) {
  if (!is(f, MsgId::Posteriors)) return false;
  m = {f.data[1], get_u16(f.data + 2), {f.data[4], f.data[5], f.data[6]}, static_cast<PredictorState>(f.data[7])};
  return true;
}

bool decode(const Frame& f, HeartbeatBridge& m) {
  if (!is(f, MsgId::HeartbeatBridge)) return false;
  m = {f.data[1], static_cast<BridgeState>(f.data[2]), f.data[3], get_u16(f.data + 4), get_u16(f.data + 6)};
  return true;
}

bool decode(const Frame& f, HeartbeatPredictor& m) {
  if (!is(f, MsgId::HeartbeatPredictor)) return false;
  m = {f.data[1], static_cast<PredictorState>(f.data[2]), f.data[3], get_u16(f.data + 4), get_u16(f.data + 6)};
  return true;
}

}  // namespace dressguard::protocol
