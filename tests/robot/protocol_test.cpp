// The CAN protocol: CRCs against their published check values, E2E status classification, the
// byte-exact examples of PROTOCOL.md (parsed out of the document), the candump log format, and the
// in-process CAN bus's SocketCAN semantics.
#include <gtest/gtest.h>

#include <fstream>
#include <cstdint>
#include <cstring>
#include <map>
#include <sstream>
#include <string>
#include <system_error>

#include "can_port.h"
#include "candump_log.h"
#include "dg_protocol.h"

using namespace dressguard::protocol;

namespace {

const uint8_t kCheckInput[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};

TEST(Crc, SaeJ1850MatchesPublishedCheckValue) {
  // AUTOSAR SWS CRC Library, CRC-8 SAE J1850: check value 0x4B for "123456789".
  EXPECT_EQ(crc8_sae_j1850_final(crc8_sae_j1850(kCheckInput, 9)), 0x4B);
}

TEST(Crc, H2FMatchesPublishedCheckValue) {
  // AUTOSAR SWS CRC Library, CRC-8H2F (poly 0x2F): check value 0xDF for "123456789".
  EXPECT_EQ(crc8_h2f_final(crc8_h2f(kCheckInput, 9)), 0xDF);
}

TEST(Crc, H2FIsIncremental) {
  // The E2E CRC is computed in two pieces (data ID, then payload): chaining must equal one pass.
  const uint8_t first = crc8_h2f(kCheckInput, 4);
  EXPECT_EQ(crc8_h2f_final(crc8_h2f(kCheckInput + 4, 5, first)), 0xDF);
}

TEST(Crc, EverySingleBitFlipOfAFrameIsDetected) {
  // CRC-8H2F has Hamming distance >= 2 for any length: each single-bit error must be caught.
  const Frame good = encode(FtForce{7, -1234, 56, 789});
  for (int bit = 0; bit < 64; ++bit) {
    Frame f = good;
    f.data[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
    EXPECT_NE(e2e_crc(data_id_of(MsgId::FtForce), f.data), f.data[0]) << "bit " << bit;
  }
}

TEST(Crc, DataIdSeparatesMessages) {
  // A force frame's bytes relabelled as a torque frame must fail the torque checker's CRC.
  Frame f = encode(FtForce{1, 100, 200, 300});
  f.id = id_of(MsgId::FtTorque);
  E2EChecker torque(MsgId::FtTorque);
  uint32_t lost = 0;
  EXPECT_EQ(torque.check(f, lost), E2EStatus::Corrupted);
}

TEST(Scaling, CountsRoundAndSaturate) {
  EXPECT_EQ(to_counts(-10.004, kForceCountsPerNewton), -1000);  // 0.01 N resolution, rounds
  EXPECT_EQ(to_counts(-10.005, kForceCountsPerNewton), -1001);
  EXPECT_EQ(to_counts(1.2345, kTorqueCountsPerNewtonMetre), 1235);
  EXPECT_EQ(to_counts(1000.0, kForceCountsPerNewton), 32767);  // saturates, never wraps
  EXPECT_EQ(to_counts(-1000.0, kForceCountsPerNewton), -32768);
  EXPECT_DOUBLE_EQ(force_newtons(-1000), -10.0);
}

TEST(E2E, ClassifiesGoodRepeatedLostLateCorrupted) {
  E2EChecker chk(MsgId::FtForce, 3);
  uint32_t lost = 99;
  EXPECT_EQ(chk.check(encode(FtForce{250, 0, 0, 0}), lost), E2EStatus::Initial);
  EXPECT_EQ(lost, 0u);
  EXPECT_EQ(chk.check(encode(FtForce{251, 0, 0, 0}), lost), E2EStatus::Ok);
  EXPECT_EQ(chk.check(encode(FtForce{251, 0, 0, 0}), lost), E2EStatus::Repeated);
  EXPECT_EQ(chk.check(encode(FtForce{254, 0, 0, 0}), lost), E2EStatus::OkSomeLost);  // 252, 253 lost
  EXPECT_EQ(lost, 2u);
  EXPECT_EQ(chk.check(encode(FtForce{1, 0, 0, 0}), lost), E2EStatus::OkSomeLost);  // wraps: 255, 0 lost
  EXPECT_EQ(lost, 2u);
  EXPECT_EQ(chk.check(encode(FtForce{0, 0, 0, 0}), lost), E2EStatus::Late);  // delayed frame
  EXPECT_EQ(chk.check(encode(FtForce{10, 0, 0, 0}), lost), E2EStatus::WrongSequence);  // 8 lost
  EXPECT_EQ(lost, 8u);
  Frame bad = encode(FtForce{11, 5, 5, 5});
  bad.data[3] ^= 0x10;
  EXPECT_EQ(chk.check(bad, lost), E2EStatus::Corrupted);
  // A corrupted frame leaves the checker where it was: the next good one is in sequence.
  EXPECT_EQ(chk.check(encode(FtForce{11, 0, 0, 0}), lost), E2EStatus::Ok);
  Frame short_frame = encode(FtForce{12, 0, 0, 0});
  short_frame.len = 6;
  EXPECT_EQ(chk.check(short_frame, lost), E2EStatus::BadLength);
  EXPECT_TRUE(accepted(E2EStatus::WrongSequence));
  EXPECT_FALSE(accepted(E2EStatus::Late));
}

// How many of the nine decoders take `f`: a frame of the protocol is exactly one message.
int decoders_taking(const Frame& f) {
  FtForce a{};
  FtTorque b{};
  TrialStart c{};
  TrialEnd d{};
  Stop e{};
  PredictorStatus g{};
  Posteriors h{};
  HeartbeatBridge i{};
  HeartbeatPredictor j{};
  return decode(f, a) + decode(f, b) + decode(f, c) + decode(f, d) + decode(f, e) + decode(f, g) + decode(f, h) +
         decode(f, i) + decode(f, j);
}

// Encodes `m`, checks the frame's envelope as the header documents it (the identifier in the
// MsgId comment, kFrameLength bytes, the alive counter in byte 1, a CRC the receiver's E2E check
// accepts under that identifier), that its own decoder and no other takes it and none takes it
// at 7 bytes, and returns what its decoder makes of it.
template <class M>
M round_trip(const M& m, uint32_t documented_id) {
  const Frame f = encode(m);
  EXPECT_EQ(f.id, documented_id);
  EXPECT_EQ(f.len, 8);
  EXPECT_EQ(f.data[1], m.counter) << "the alive counter is byte 1";
  E2EChecker chk(static_cast<MsgId>(documented_id));
  uint32_t lost = 0;
  EXPECT_EQ(chk.check(f, lost), E2EStatus::Initial) << "byte 0 is not the E2E CRC under this identifier";
  EXPECT_EQ(decoders_taking(f), 1) << "decode must refuse a frame of another identifier";
  Frame short_frame = f;
  short_frame.len = 7;
  EXPECT_EQ(decoders_taking(short_frame), 0) << "decode must refuse a frame of another length";
  M back{};  // all zero: every field below is non-zero, so a field decode leaves alone shows
  EXPECT_TRUE(decode(f, back));
  return back;
}

// Every message of the header, each field a distinct non-zero value (16-bit ones with two
// different non-zero bytes, enums not their first enumerator), so that a field dropped, written
// over a neighbour's bytes, swapped with another or byte-swapped shows; every field is compared
// after decoding. (The byte layout itself is ProtocolDocument's: PROTOCOL.md's examples.)
TEST(Messages, RoundTripEveryMessage) {
  {
    SCOPED_TRACE("FtForce");
    const FtForce m{0x11, -12345, 23456, -3210};
    const FtForce b = round_trip(m, 0x100);
    EXPECT_EQ(b.counter, m.counter);
    EXPECT_EQ(b.fx, m.fx);
    EXPECT_EQ(b.fy, m.fy);
    EXPECT_EQ(b.fz, m.fz);
  }
  {
    SCOPED_TRACE("FtTorque");
    const FtTorque m{0x22, 4321, -8765, 30001};
    const FtTorque b = round_trip(m, 0x101);
    EXPECT_EQ(b.counter, m.counter);
    EXPECT_EQ(b.mx, m.mx);
    EXPECT_EQ(b.my, m.my);
    EXPECT_EQ(b.mz, m.mz);
  }
  {
    SCOPED_TRACE("TrialStart");
    const TrialStart m{0x33, 0x1234, 450, HeightClass::Low};
    const TrialStart b = round_trip(m, 0x180);
    EXPECT_EQ(b.counter, m.counter);
    EXPECT_EQ(b.trial_id, m.trial_id);
    EXPECT_EQ(b.speed_mm_s, m.speed_mm_s);
    EXPECT_EQ(b.height, m.height);
  }
  {
    SCOPED_TRACE("TrialEnd");
    const TrialEnd m{0x44, 0x2345, 3000, TrialEndReason::StoppedByPredictor};
    const TrialEnd b = round_trip(m, 0x181);
    EXPECT_EQ(b.counter, m.counter);
    EXPECT_EQ(b.trial_id, m.trial_id);
    EXPECT_EQ(b.samples, m.samples);
    EXPECT_EQ(b.reason, m.reason);
  }
  {
    SCOPED_TRACE("Stop");
    const Stop m{0x55, StopReason::StopUnconfirmed, 200, 0x3456, 0x0321};
    const Stop b = round_trip(m, 0x080);
    EXPECT_EQ(b.counter, m.counter);
    EXPECT_EQ(b.reason, m.reason);
    EXPECT_EQ(b.p_caught, m.p_caught);
    EXPECT_EQ(b.trial_id, m.trial_id);
    EXPECT_EQ(b.sample, m.sample);
  }
  {
    SCOPED_TRACE("PredictorStatus");
    const PredictorStatus m{0x66, 5, PredictorState::Fault, 0x4567, 0x5678};
    const PredictorStatus b = round_trip(m, 0x300);
    EXPECT_EQ(b.counter, m.counter);
    EXPECT_EQ(b.page, m.page);
    EXPECT_EQ(b.state, m.state);
    EXPECT_EQ(b.value0, m.value0);
    EXPECT_EQ(b.value1, m.value1);
  }
  {
    SCOPED_TRACE("Posteriors");
    const Posteriors m{0x77, 0x6789, {10, 200, 45}, PredictorState::InTrial};
    const Posteriors b = round_trip(m, 0x301);
    EXPECT_EQ(b.counter, m.counter);
    EXPECT_EQ(b.sample, m.sample);
    EXPECT_EQ(b.p[0], m.p[0]);
    EXPECT_EQ(b.p[1], m.p[1]);
    EXPECT_EQ(b.p[2], m.p[2]);
    EXPECT_EQ(b.state, m.state);
  }
  {
    SCOPED_TRACE("HeartbeatBridge");
    const HeartbeatBridge m{0x88, BridgeState::StopLatched, 9, 0x789A, 3600};
    const HeartbeatBridge b = round_trip(m, 0x700);
    EXPECT_EQ(b.counter, m.counter);
    EXPECT_EQ(b.state, m.state);
    EXPECT_EQ(b.sensor_errors, m.sensor_errors);
    EXPECT_EQ(b.reconnects, m.reconnects);
    EXPECT_EQ(b.uptime_s, m.uptime_s);
  }
  {
    SCOPED_TRACE("HeartbeatPredictor");
    const HeartbeatPredictor m{0x99, PredictorState::Stopped, 1, 0x89AB, 7200};
    const HeartbeatPredictor b = round_trip(m, 0x701);
    EXPECT_EQ(b.counter, m.counter);
    EXPECT_EQ(b.state, m.state);
    EXPECT_EQ(b.model_loaded, m.model_loaded);
    EXPECT_EQ(b.trial_id, m.trial_id);
    EXPECT_EQ(b.uptime_s, m.uptime_s);
  }
}

// ---- PROTOCOL.md examples -------------------------------------------------------------------

std::map<std::string, long> fields_of(std::istringstream& in) {
  std::map<std::string, long> m;
  std::string tok;
  while (in >> tok) {
    if (tok == "=>") break;
    const auto eq = tok.find('=');
    if (eq == std::string::npos) ADD_FAILURE() << "bad field '" << tok << "'";
    else m[tok.substr(0, eq)] = std::stol(tok.substr(eq + 1), nullptr, 0);
  }
  return m;
}

Frame encode_example(const std::string& name, std::map<std::string, long> v) {
  auto u8 = [&](const char* k) { return static_cast<uint8_t>(v.at(k)); };
  auto u16 = [&](const char* k) { return static_cast<uint16_t>(v.at(k)); };
  auto i16 = [&](const char* k) { return static_cast<int16_t>(v.at(k)); };
  if (name == "FtForce") return encode(FtForce{u8("counter"), i16("fx"), i16("fy"), i16("fz")});
  if (name == "FtTorque") return encode(FtTorque{u8("counter"), i16("mx"), i16("my"), i16("mz")});
  if (name == "TrialStart")
    return encode(TrialStart{u8("counter"), u16("trial"), u16("speed_mm_s"), static_cast<HeightClass>(u8("height"))});
  if (name == "TrialEnd")
    return encode(TrialEnd{u8("counter"), u16("trial"), u16("samples"), static_cast<TrialEndReason>(u8("reason"))});
  if (name == "Stop")
    return encode(Stop{u8("counter"), static_cast<StopReason>(u8("reason")), u8("p_caught"), u16("trial"), u16("sample")});
  if (name == "PredictorStatus")
    return encode(PredictorStatus{u8("counter"), u8("page"), static_cast<PredictorState>(u8("state")), u16("value0"), u16("value1")});
  if (name == "Posteriors")
    return encode(Posteriors{u8("counter"), u16("sample"), {u8("p0"), u8("p1"), u8("p2")}, static_cast<PredictorState>(u8("state"))});
  if (name == "HeartbeatBridge")
    return encode(HeartbeatBridge{u8("counter"), static_cast<BridgeState>(u8("state")), u8("sensor_errors"), u16("reconnects"), u16("uptime_s")});
  if (name == "HeartbeatPredictor")
    return encode(HeartbeatPredictor{u8("counter"), static_cast<PredictorState>(u8("state")), u8("model_loaded"), u16("trial"), u16("uptime_s")});
  ADD_FAILURE() << "unknown message " << name;
  return {};
}

TEST(ProtocolDocument, ByteExactExamplesMatchTheCode) {
  const std::string path = std::string(DRESSGUARD_SOURCE_DIR) + "/firmware-bridge/PROTOCOL.md";
  std::ifstream in(path);
  ASSERT_TRUE(in) << "cannot open " << path;
  std::string line;
  bool in_block = false;
  int examples = 0, crc_examples = 0;
  std::map<std::string, int> seen;
  while (std::getline(in, line)) {
    if (line.rfind("```", 0) == 0) {
      in_block = line == "```e2e-examples";
      continue;
    }
    if (!in_block || line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::string name;
    ls >> name;
    if (name == "crc8_h2f" || name == "crc8_sae_j1850") {
      std::string input, arrow, expect;
      ls >> input >> arrow >> expect;
      const auto* p = reinterpret_cast<const uint8_t*>(input.data());
      const uint8_t got = name == "crc8_h2f" ? crc8_h2f_final(crc8_h2f(p, input.size()))
                                             : crc8_sae_j1850_final(crc8_sae_j1850(p, input.size()));
      EXPECT_EQ(got, std::stoi(expect, nullptr, 16)) << line;
      ++crc_examples;
      continue;
    }
    const auto fields = fields_of(ls);
    std::string expected;
    ls >> expected;
    const Frame f = encode_example(name, fields);
    const std::string got = format_candump_line(0, "x", f).substr(std::string("(0.000000) x ").size());
    EXPECT_EQ(got, expected) << "PROTOCOL.md example: " << line;
    // And the documented bytes pass the receiver's E2E check under their identifier.
    LoggedFrame lf;
    std::string why;
    ASSERT_TRUE(parse_candump_line("(0.000000) x " + expected, lf, why)) << why;
    E2EChecker chk(static_cast<MsgId>(lf.frame.id));
    uint32_t lost = 0;
    EXPECT_EQ(chk.check(lf.frame, lost), E2EStatus::Initial) << line;
    ++examples;
    seen[name]++;
  }
  EXPECT_EQ(crc_examples, 2);
  EXPECT_EQ(seen.size(), 9u) << "every message type has an example";
  EXPECT_GE(examples, 9);
}

// ---- candump log ------------------------------------------------------------------------------

TEST(CandumpLog, FormatAndParseRoundTrip) {
  const Frame f = encode(FtForce{5, -1000, 2, 3});
  const std::string line = format_candump_line(1700000000123456LL, "vcan0", f);
  EXPECT_EQ(line.substr(0, 25), "(1700000000.123456) vcan0");
  LoggedFrame lf;
  std::string why;
  ASSERT_TRUE(parse_candump_line(line, lf, why)) << why;
  EXPECT_EQ(lf.time_us, 1700000000123456LL);
  EXPECT_EQ(lf.frame.id, 0x100u);
  EXPECT_EQ(lf.frame.len, 8);
  EXPECT_EQ(std::memcmp(lf.frame.data, f.data, 8), 0);
}

TEST(CandumpLog, ParsesCandumpOutputVerbatim) {
  // Lines as `candump -l` writes them (can-utils 2021.08, Debian 12), including a short frame.
  const auto frames = parse_candump_log("(1700000000.000100) vcan0 123#DEADBEEF\n\n(1700000000.000200) vcan0 080#\n", "x.log");
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].frame.len, 4);
  EXPECT_EQ(frames[0].line, 1);
  EXPECT_EQ(frames[1].frame.len, 0);
  EXPECT_EQ(frames[1].line, 3);
}

// parse_candump_log's error message on `text`, or "" when it parses.
std::string log_error(const std::string& text, const std::string& name) {
  try {
    parse_candump_log(text, name);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// candump stamps frames with the wall clock: a clock stepped back makes the log run backwards,
// and a replay would judge every deadline on it wrongly. The line and the step are named.
TEST(CandumpLog, TimeGoingBackIsAnError) {
  const std::string e =
      log_error("(100.000000) vcan0 100#00\n(100.010000) vcan0 100#00\n(90.010000) vcan0 100#00\n", "t.log");
  EXPECT_NE(e.find("t.log:3: time goes back 10.000000 s from line 2"), std::string::npos) << e;
  EXPECT_EQ(parse_candump_log("(1.000000) vcan0 100#00\n(1.000000) vcan0 101#00\n", "same.log").size(), 2u);
}

TEST(CandumpLog, BadLinesNameFileAndLine) {
  const std::string e = log_error("(1.000000) vcan0 100#00\n(2.0) vcan0 100#00\n", "trial.log");
  EXPECT_NE(e.find("trial.log:2:"), std::string::npos) << e;
  LoggedFrame lf;
  std::string why;
  EXPECT_FALSE(parse_candump_line("(1.000000) vcan0 12345678#00", lf, why));
  EXPECT_FALSE(parse_candump_line("(1.000000) vcan0 100#0", lf, why));
  EXPECT_FALSE(parse_candump_line("(1.000000) vcan0 100##100", lf, why));
}

// What can-utils' candump writes, verbatim ("(%010lu.%06lu) %*s %s%s"): `candump -l can0 vcan0`
// pads the shorter name to the longer one, `candump -l -x` ends a line with the direction, R or
// T. Both were refused ("expected an interface name", "data is not 0..8 bytes of hex"), so a
// log recorded on two interfaces or with -x could not be replayed at all (session 84's review).
TEST(CandumpLog, ReadsPaddedNamesAndDirection) {
  const auto frames = parse_candump_log(
      "(1700000000.000100)  can0 100#A5010A00F6FF3200\n"
      "(1700000000.000200) vcan0 080#0102 R\n"
      "(1700000000.000300)  can0 080# T\n",
      "x.log");
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].iface, "can0");
  EXPECT_EQ(frames[0].frame.id, 0x100u);
  EXPECT_EQ(frames[0].frame.len, 8);
  EXPECT_EQ(frames[1].iface, "vcan0");
  EXPECT_EQ(frames[1].frame.len, 2);
  EXPECT_EQ(frames[1].frame.data[1], 0x02);
  EXPECT_EQ(frames[2].iface, "can0");
  EXPECT_EQ(frames[2].frame.len, 0);
  // Nothing else may follow the frame.
  const std::string e = log_error("(1.000000) vcan0 100#00 X\n", "x.log");
  EXPECT_NE(e.find("x.log:1: unexpected text after the frame"), std::string::npos) << e;
}

// Why parse_candump_line refuses a line holding `frame` (it must refuse it).
std::string why_of(const std::string& frame) {
  LoggedFrame lf;
  std::string why;
  EXPECT_FALSE(parse_candump_line("(1700000000.012345) vcan0 " + frame, lf, why)) << frame;
  return why;
}

// What candump writes but the protocol has no use for is refused, and the reason says what it
// is: an error frame was "identifier is not 3 hex digits", a lower-case remote frame "data is not
// 0..8 bytes of hex".
TEST(CandumpLog, RefusedFramesAreNamed) {
  EXPECT_NE(why_of("60000040#0000000000000000").find("bits above CAN_ERR_FLAG"), std::string::npos);
  EXPECT_NE(why_of("12345678#00").find("extended (29-bit) identifier"), std::string::npos);
  EXPECT_NE(why_of("100#r").find("remote frame"), std::string::npos);
  EXPECT_NE(why_of("100#R").find("remote frame"), std::string::npos);
  EXPECT_NE(why_of("100##1A5").find("CAN FD frame (##)"), std::string::npos);
  EXPECT_NE(why_of("123456789#00").find("not 3 hex digits"), std::string::npos);
  EXPECT_NE(why_of("10#00").find("not 3 hex digits"), std::string::npos);
}

// candump -e (or an error mask) logs controller error frames: 8 digits, CAN_ERR_FLAG and the
// class, 8 data bytes. They were refused, so a log recorded while diagnosing a bus could not be
// replayed at all; now they are read with that id (the socket's can_id) and written back the same.
// candump -8 marks an 8-byte frame whose raw DLC is 9..15 with "_D": the 8 bytes are read, the
// raw DLC dropped; it was "data is not 0..8 bytes of hex" (session 85's note).
TEST(CandumpLog, ReadsErrorFramesAndRawDlcSuffixes) {
  const auto frames = parse_candump_log(
      "(1700000000.000100) can0 20000040#0000000000000000\n"
      "(1700000000.000200) can0 20000004#0004000000000000 R\n"
      "(1700000000.000300) can0 100#A5010A00F6FF3200_F\n"
      "(1700000000.000400) can0 100#A5010A00F6FF3200_9 R\n",
      "e.log");
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_TRUE(is_error_frame(frames[0].frame));
  EXPECT_EQ(error_class_of(frames[0].frame), 0x40u);  // CAN_ERR_BUSOFF
  EXPECT_EQ(error_class_of(frames[1].frame), 0x04u);  // CAN_ERR_CRTL
  EXPECT_EQ(frames[1].frame.len, 8);
  EXPECT_EQ(frames[1].frame.data[1], 0x04);
  EXPECT_EQ(format_candump_line(frames[0].time_us, "can0", frames[0].frame),
            "(1700000000.000100) can0 20000040#0000000000000000");
  for (int i : {2, 3}) {
    EXPECT_FALSE(is_error_frame(frames[i].frame));
    EXPECT_EQ(frames[i].frame.id, 0x100u);
    EXPECT_EQ(frames[i].frame.len, 8);
    EXPECT_EQ(frames[i].frame.data[7], 0x00);
    EXPECT_EQ(frames[i].frame.data[6], 0x32);
  }
  EXPECT_NE(why_of("100#A5010A00F6FF32_9").find("after other than 8 data bytes"), std::string::npos);
  EXPECT_NE(why_of("100#A5010A00F6FF3200_8").find("not one hex digit 9..F"), std::string::npos);
  EXPECT_NE(why_of("100#A5010A00F6FF3200_").find("not one hex digit 9..F"), std::string::npos);
  EXPECT_NE(why_of("100#A5010A00F6FF3200_AB").find("not one hex digit 9..F"), std::string::npos);
}

// canplayer skips every line that does not begin with '(' (its -h says so): comments, candump
// -d's DROPCOUNT notes. They were refused ("expected '(' starting a timestamp"); now they are
// skipped as canplayer skips them, and the frames keep their own line numbers. Text with no frame
// line at all is still an error: it is not an empty log.
TEST(CandumpLog, SkipsLinesCanplayerSkips) {
  const auto frames = parse_candump_log(
      "# recorded with candump -l -d vcan0\n"
      "(1700000000.000100) vcan0 100#00\n"
      "DROPCOUNT: dropped 1 CAN frame on 'vcan0' socket (total drops 1)\n"
      " (1700000000.000150) vcan0 100#01\n"
      "(1700000000.000200) vcan0 100#02\n",
      "c.log");
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].line, 2);
  EXPECT_EQ(frames[1].line, 5);
  EXPECT_EQ(frames[1].frame.data[0], 0x02);
  const std::string e = log_error("\n  vcan0  100   [1]  00\n", "plain.log");
  EXPECT_NE(e.find("plain.log:2: not a candump -l log"), std::string::npos) << e;
  EXPECT_TRUE(parse_candump_log("", "empty.log").empty());
  EXPECT_TRUE(parse_candump_log("\n \n", "blank.log").empty());
}

// Found by fuzz_candump (session 80): 13 or more digits of seconds overflowed the microseconds
// (undefined behaviour), and a long interface name written back overran the line's buffer.
// (Session 82: a replay's nanoseconds overflowed from 9.2e9 s.)
TEST(CandumpLog, TimestampAndInterfaceNameHaveBounds) {
  LoggedFrame lf;
  std::string why;
  // A replay counts in nanoseconds: the last second whose nanoseconds fit an int64_t is allowed
  // (the year 2255), one more is not, nor 11 digits of seconds.
  ASSERT_TRUE(parse_candump_line("(9000000000.999999) vcan0 100#00", lf, why)) << why;
  EXPECT_EQ(lf.time_us, 9000000000999999LL);
  EXPECT_LT(lf.time_us, INT64_MAX / 1000);
  EXPECT_FALSE(parse_candump_line("(9000000001.000000) vcan0 100#00", lf, why));
  EXPECT_NE(why.find("beyond 9000000000 s"), std::string::npos) << why;
  EXPECT_FALSE(parse_candump_line("(17000000000000.000000) vcan0 100#00", lf, why));
  EXPECT_NE(why.find("10 digits"), std::string::npos) << why;
  const std::string longest(kMaxInterfaceName, 'c');
  ASSERT_TRUE(parse_candump_line("(1.000000) " + longest + " 100#00", lf, why)) << why;
  EXPECT_FALSE(parse_candump_line("(1.000000) " + longest + "c 100#00", lf, why));
  EXPECT_NE(why.find("IFNAMSIZ"), std::string::npos) << why;
  // Writing never depends on the name's length: any name comes back whole.
  const std::string name(200, 'n');
  const std::string line = format_candump_line(1000001, name, encode(FtForce{1, 2, 3, 4}));
  EXPECT_EQ(line, "(1.000001) " + name + " 100#" + line.substr(line.size() - 16));
  EXPECT_EQ(line.size(), std::string("(1.000001) ").size() + name.size() + 5 + 16);
}

// ---- in-process bus ------------------------------------------------------------------------------

TEST(InProcBus, FiltersEchoesAndDrops) {
  using namespace dressguard::can;
  InProcBus bus;
  auto a = bus.open({{0x100}, false, true});
  auto b = bus.open({{0x080}, true, true});
  Frame rx;
  RxInfo info;
  EXPECT_EQ(b->send(encode(Stop{0, StopReason::Caught, 0, 0, 0})), SendResult::Ok);
  ASSERT_EQ(b->receive(rx, info), 1);
  EXPECT_TRUE(info.own_echo) << "the sender asked for its own frames back";
  EXPECT_EQ(a->receive(rx, info), 0) << "a's filter does not include 0x080";
  EXPECT_EQ(b->send(encode(FtForce{0, 1, 2, 3})), SendResult::Ok);
  ASSERT_EQ(a->receive(rx, info), 1);
  EXPECT_FALSE(info.own_echo);
  EXPECT_EQ(rx.id, 0x100u);
  bus.fail_next_sends(1, SendResult::NoBuffers);
  EXPECT_EQ(b->send(encode(FtForce{1, 1, 2, 3})), SendResult::NoBuffers);
  EXPECT_EQ(a->receive(rx, info), 0) << "a failed send delivers nothing";
  // Flood a without reading: the queue fills and further frames are counted as drops.
  for (int i = 0; i < 5000; ++i) b->send(encode(FtForce{static_cast<uint8_t>(i), 0, 0, 0}));
  int got = 0;
  while (a->receive(rx, info) == 1) ++got;
  EXPECT_LT(got, 5000);
  EXPECT_EQ(static_cast<int>(info.kernel_drops), 5000 - got);
}

TEST(SocketCan, OpeningFailsWithANamedReasonWhereTheKernelHasNoCan) {
  using namespace dressguard::can;
  if (socketcan_available()) GTEST_SKIP() << "this kernel has AF_CAN: the VM test covers SocketCAN";
  try {
    open_socketcan("vcan0", {});
    FAIL() << "opened a CAN socket on a kernel without AF_CAN";
  } catch (const std::system_error& e) {
    EXPECT_NE(std::string(e.what()).find("vcan0"), std::string::npos) << e.what();
  }
}

}  // namespace
