// The .dgm model file: round trip, size, and every rejection FORMAT.md promises, each with a
// message that names the problem; the shipped default model's checksum.
#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <future>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "dgm.h"

using namespace dressguard::model;

namespace {

// A valid 3-class, 10-state left-right model with a few unique values to patch in the bytes.
OutcomeModel sample_model() {
  OutcomeModel m;
  m.tool_version = "dressguard test";
  m.created = "2026-11-21T00:00:00Z";
  m.source_dataset = "synthetic";
  m.training_summary = "none";
  m.features.offset[0] = -2.5;
  m.features.scale[0] = 1.75;
  m.features.offset[1] = 0.25;
  m.features.scale[1] = 0.5;
  const char* names[] = {"good", "missed", "caught"};
  for (int c = 0; c < 3; ++c) {
    ClassHmm h = left_right_chain(10, 0.875);
    h.name = names[c];
    for (int j = 0; j < 10; ++j) {
      GaussianEmission e;
      e.mean[0] = 0.5 * j + c;
      e.mean[1] = -0.25 * j;
      e.cov[0][0] = 0.5;
      e.cov[0][1] = e.cov[1][0] = 0.125;
      e.cov[1][1] = 0.75;
      h.emission.push_back(e);
    }
    h.log_prior = std::log(1.0 / 3.0);
    m.classes.push_back(h);
  }
  // Unique markers (values that occur nowhere else in the file).
  m.classes[1].emission[2].mean[0] = 1.2345678901;
  m.classes[2].transition[3 * 10 + 3] = 0.8765432109;
  m.classes[2].transition[3 * 10 + 4] = 1.0 - 0.8765432109;
  m.classes[0].emission[5].cov[1][1] = 0.6543210987;
  return m;
}

void fix_crc(std::vector<uint8_t>& b) {
  const uint32_t c = crc32(b.data(), b.size() - 4);
  for (int i = 0; i < 4; ++i) b[b.size() - 4 + i] = static_cast<uint8_t>(c >> (8 * i));
}

// Replaces the (unique) little-endian double `from` by `to` in `b`; patched() does so in the
// sample model's bytes and repairs the CRC, so the check under test is the semantic one.
void replace_double(std::vector<uint8_t>& b, double from, double to) {
  uint8_t f[8], t[8];
  std::memcpy(f, &from, 8);
  std::memcpy(t, &to, 8);
  int hits = 0;
  for (size_t i = 0; i + 8 <= b.size(); ++i)
    if (std::memcmp(&b[i], f, 8) == 0) std::memcpy(&b[i], t, 8), ++hits;
  EXPECT_EQ(hits, 1) << "marker not unique";
}
std::vector<uint8_t> patched(double from, double to) {
  auto b = encode_model(sample_model());
  replace_double(b, from, to);
  fix_crc(b);
  return b;
}

// Decoding `b` throws ModelError whose message contains `what` and the source name.
void expect_rejected(const std::vector<uint8_t>& b, const std::string& what) {
  try {
    decode_model(b.data(), b.size(), "bad.dgm");
    ADD_FAILURE() << "accepted a file that should fail with: " << what;
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("bad.dgm: ", 0), 0u) << e.what();
  }
}

}  // namespace

// The chain the tests and benchmarks build their models on: stays, moves on by 1..band states in
// equal shares, absorbs at the end, starts in state 0; every row a distribution.
TEST(LeftRightChain, StaysMovesOnWithinTheBandAndAbsorbsAtTheEnd) {
  const ClassHmm a = left_right_chain(4, 0.75);
  const std::vector<double> expect = {0.75, 0.25, 0, 0,  0, 0.75, 0.25, 0,  0, 0, 0.75, 0.25,  0, 0, 0, 1};
  EXPECT_EQ(a.n_states, 4);
  EXPECT_EQ(a.transition, expect);
  EXPECT_EQ(a.initial, (std::vector<double>{1, 0, 0, 0}));
  const ClassHmm b = left_right_chain(4, 0.5, 2);  // reach 2, 2, 1, 0
  const std::vector<double> band2 = {0.5, 0.25, 0.25, 0,  0, 0.5, 0.25, 0.25,  0, 0, 0.5, 0.5,  0, 0, 0, 1};
  EXPECT_EQ(b.transition, band2);
  EXPECT_EQ(left_right_chain(1, 0.9).transition, std::vector<double>{1.0});
  EXPECT_THROW(left_right_chain(0, 0.9), std::invalid_argument);
}

// The standard check value of CRC-32/IEEE.
TEST(ModelFile, Crc32KnownAnswer) {
  const char* s = "123456789";
  EXPECT_EQ(crc32(reinterpret_cast<const uint8_t*>(s), 9), 0xCBF43926u);
}

TEST(ModelFile, RoundTripIsExactAndSmall) {
  const auto m = sample_model();
  const auto b = encode_model(m);
  // 3 classes x 10 states: 3 x (8 x (10 + 100 + 60) + 20) bytes of HMM + metadata: ~4.2 KB.
  EXPECT_LT(b.size(), 8192u);
  EXPECT_EQ(std::memcmp(b.data(), "DGMODEL", 8), 0);
  const auto d = decode_model(b.data(), b.size(), "mem");
  EXPECT_EQ(encode_model(d), b);  // bit-exact
  EXPECT_EQ(d.created, m.created);
  EXPECT_EQ(d.classes[2].name, "caught");
  EXPECT_EQ(d.classes[1].emission[2].mean[0], 1.2345678901);
  EXPECT_EQ(d.features.scale[0], 1.75);
  EXPECT_EQ(d.class_index("missed"), 1);
  EXPECT_EQ(d.class_index("nope"), -1);
  const std::string text = describe_model(d);
  EXPECT_NE(text.find("class 'caught': 10 states"), std::string::npos) << text;
  EXPECT_NE(text.find("f_vertical"), std::string::npos) << text;
}

TEST(ModelFile, WriteIsAtomicAndReadBack) {
  const auto dir = std::filesystem::temp_directory_path() / ("dgm_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "m.dgm";
  write_model(path, sample_model());
  const auto first = read_model(path);
  EXPECT_EQ(first.classes.size(), 3u);
  // Writing an invalid model fails before touching the file: the old file stays whole.
  auto bad = sample_model();
  bad.classes[0].transition[0] = 0.5;
  EXPECT_THROW(write_model(path, bad), ModelError);
  EXPECT_NO_THROW(read_model(path));
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1) << "a temporary file was left behind";
  try {
    read_model(dir / "absent.dgm");
    ADD_FAILURE();
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("absent.dgm"), std::string::npos);
  }
  std::filesystem::remove_all(dir);
}

namespace {
std::vector<uint8_t> file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
int regular_files_in(const std::filesystem::path& dir) {
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files += e.is_regular_file();
  return files;
}
// What write_model says: the ModelError's message, or "written".
std::string write_error(const std::filesystem::path& path, const OutcomeModel& m) {
  try {
    write_model(path, m);
    return "written";
  } catch (const ModelError& e) {
    return e.what();
  }
}
}  // namespace

// A write that fails part-way leaves the old model as it was and no temporary file, and says why
// with the path and the system's reason. The file-size limit (1 KiB of the 4.3 KB) makes the
// write fail as root too, whom a read-only folder does not stop; the short write it first gets
// goes through the write loop. It said "write failed", without the reason.
TEST(ModelFile, AFailedWriteLeavesTheOldFileAndNoTemporary) {
  const auto dir = std::filesystem::temp_directory_path() / ("dgm_write_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "m.dgm";
  write_model(path, sample_model());
  const std::vector<uint8_t> old = file_bytes(path);
  auto other = sample_model();
  other.created = "2026-12-31T00:00:00Z";
  rlimit saved{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
  rlimit small = saved;
  small.rlim_cur = 1024;
  const auto handler = std::signal(SIGXFSZ, SIG_IGN);  // else exceeding the limit kills the process
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string what = write_error(path, other);
  ::setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, handler);
  EXPECT_EQ(what.rfind(path.string() + ": cannot write the temporary file " + path.string() + ".tmp.", 0), 0u)
      << what;
  EXPECT_NE(what.find(std::string(": ") + std::strerror(EFBIG)), std::string::npos) << what;
  EXPECT_EQ(file_bytes(path), old) << "the old model was changed";
  EXPECT_EQ(regular_files_in(dir), 1) << "a temporary file was left behind";
  // A folder that cannot exist (its parent is a file): named, with the reason, nothing made.
  const auto under = path / "m.dgm";
  what = write_error(under, other);
  EXPECT_EQ(what.rfind(under.string() + ": cannot create the temporary file ", 0), 0u) << what;
  EXPECT_NE(what.find(std::strerror(ENOTDIR)), std::string::npos) << what;
  EXPECT_EQ(file_bytes(path), old);
  EXPECT_EQ(regular_files_in(dir), 1);
  // And the write itself, once nothing is in the way: the new model replaces the old.
  EXPECT_EQ(write_error(path, other), "written");
  EXPECT_EQ(file_bytes(path), encode_model(other));
  EXPECT_EQ(regular_files_in(dir), 1);
  std::filesystem::remove_all(dir);
}

TEST(ModelFileRejects, WrongMagic) {
  auto b = encode_model(sample_model());
  b[0] = 'X';
  expect_rejected(b, "wrong magic");
}

TEST(ModelFileRejects, WrongVersion) {
  for (uint8_t v : {uint8_t{0}, uint8_t{4}}) {
    auto b = encode_model(sample_model());
    b[8] = v;
    fix_crc(b);
    expect_rejected(b, "unsupported format version " + std::to_string(v));
  }
}

// A feature the model does not use (axis 3, none): it is 0 whatever the sample, the file says
// version 2 (a model without it stays version 1, readable by version-1 readers), and it
// round-trips; a version-1 file with axis 3 is refused.
TEST(ModelFile, UnusedFeatureIsZeroAndNeedsVersion2) {
  auto m = sample_model();
  EXPECT_EQ(encode_model(m)[8], 1);
  m.features.axis[1] = kAxisNone;
  m.features.offset[1] = 0.0;
  m.features.scale[1] = 1.0;
  double x[kFeatures], y[kFeatures];
  m.features.apply(-3.0, 0.5, 2.0, x);
  m.features.apply(-3.0, -7.0, -9.0, y);
  EXPECT_EQ(x[1], 0.0);
  EXPECT_EQ(y[1], 0.0);
  EXPECT_EQ(x[0], y[0]);
  EXPECT_DOUBLE_EQ(x[0], (-3.0 + 2.5) / 1.75);
  const auto b = encode_model(m);
  EXPECT_EQ(b[8], 2);
  const auto d = decode_model(b.data(), b.size(), "mem");
  EXPECT_EQ(d.features.axis[1], kAxisNone);
  EXPECT_EQ(encode_model(d), b);
  EXPECT_NE(describe_model(d).find("feature 1 = none"), std::string::npos) << describe_model(d);
  auto v1 = b;
  v1[8] = 1;
  fix_crc(v1);
  expect_rejected(v1, "needs format version 2");
  // The reverse: a version-2 file that uses no axis 3 was accepted and re-written as version 1;
  // every accepted file must re-write to its own bytes (FORMAT.md, Versioning).
  auto v2 = encode_model(sample_model());
  v2[8] = 2;
  fix_crc(v2);
  expect_rejected(v2, "format version 2 for a model the writer writes as version 1 (no feature is 'none'");
  auto both = m;
  both.features.axis[0] = kAxisNone;
  EXPECT_THROW(encode_model(both), ModelError);
  auto scaled = m;  // FORMAT.md: offset 0 and scale 1 where the axis is none
  scaled.features.scale[1] = 2.0;
  EXPECT_THROW(encode_model(scaled), ModelError);
}

namespace {
// The sample model with its training conditions known, each a unique marker in the bytes.
constexpr double kPeriodMarker = 0.0123456789, kSpeedMinMarker = 0.1234567891, kSpeedMaxMarker = 0.3456789123;
OutcomeModel trained_at_known_conditions() {
  auto m = sample_model();
  m.sample_period_s = kPeriodMarker;
  m.speed_min_m_s = kSpeedMinMarker;
  m.speed_max_m_s = kSpeedMaxMarker;
  return m;
}
std::vector<uint8_t> v3_patched(double from, double to) {
  auto b = encode_model(trained_at_known_conditions());
  replace_double(b, from, to);
  fix_crc(b);
  return b;
}
// Where the marker `v` starts in `b`.
size_t offset_of(const std::vector<uint8_t>& b, double v) {
  uint8_t f[8];
  std::memcpy(f, &v, 8);
  for (size_t i = 0; i + 8 <= b.size(); ++i)
    if (std::memcmp(&b[i], f, 8) == 0) return i;
  ADD_FAILURE() << "marker not found";
  return 0;
}
}  // namespace

// Format version 3: the training conditions round-trip bit-exactly right after the stop policy,
// `model show` prints them, and either kind alone (a period, a speed range) is version 3 too.
TEST(ModelFileV3, TrainingConditionsRoundTrip) {
  const auto m = trained_at_known_conditions();
  const auto b = encode_model(m);
  EXPECT_EQ(b[8], 3);
  EXPECT_EQ(b.size(), encode_model(sample_model()).size() + 24);
  const auto d = decode_model(b.data(), b.size(), "mem");
  EXPECT_EQ(d.sample_period_s, kPeriodMarker);
  EXPECT_EQ(d.speed_min_m_s, kSpeedMinMarker);
  EXPECT_EQ(d.speed_max_m_s, kSpeedMaxMarker);
  EXPECT_EQ(encode_model(d), b);
  const std::string text = describe_model(d);
  EXPECT_NE(text.find("sample period: 0.0123456789 s"), std::string::npos) << text;
  EXPECT_NE(text.find("training speeds: 0.123457 to 0.345679 m/s"), std::string::npos) << text;
  // Layout: the three f64 follow the stop consecutive count and precede the class count.
  const size_t at = offset_of(b, kPeriodMarker);
  EXPECT_EQ(offset_of(b, kSpeedMinMarker), at + 8);
  EXPECT_EQ(offset_of(b, kSpeedMaxMarker), at + 16);
  EXPECT_EQ(b[at - 4], 5);   // stop consecutive 5, little-endian
  EXPECT_EQ(b[at + 24], 3);  // class count 3
  auto period_only = sample_model();
  period_only.sample_period_s = 0.01;
  auto speeds_only = sample_model();
  speeds_only.speed_min_m_s = speeds_only.speed_max_m_s = 0.2;
  for (const auto& one : {period_only, speeds_only}) {
    const auto e = encode_model(one);
    EXPECT_EQ(e[8], 3);
    const auto back = decode_model(e.data(), e.size(), "mem");
    EXPECT_EQ(back.sample_period_s, one.sample_period_s);
    EXPECT_EQ(back.speed_max_m_s, one.speed_max_m_s);
  }
  EXPECT_NE(describe_model(period_only).find("training speeds: unknown (format version 3)"), std::string::npos);
  // Version 3 keeps version 2's unused axis.
  auto none = m;
  none.features.axis[1] = kAxisNone;
  none.features.offset[1] = 0.0;
  none.features.scale[1] = 1.0;
  const auto n = encode_model(none);
  EXPECT_EQ(n[8], 3);
  EXPECT_EQ(decode_model(n.data(), n.size(), "mem").features.axis[1], kAxisNone);
}

// A model that knows none of them is written as before, byte for byte: version 1 (or 2 with an
// unused axis) reads as unknown and re-writes to the same bytes.
TEST(ModelFileV3, OldVersionsReadAsUnknownAndRewriteByteIdentically) {
  auto none = sample_model();
  none.features.axis[0] = kAxisNone;
  none.features.offset[0] = 0.0;
  none.features.scale[0] = 1.0;
  for (const auto& [m, version] : {std::pair{sample_model(), 1}, std::pair{none, 2}}) {
    const auto b = encode_model(m);
    EXPECT_EQ(b[8], version);
    const auto d = decode_model(b.data(), b.size(), "old.dgm");
    EXPECT_FALSE(d.knows_period());
    EXPECT_FALSE(d.knows_speeds());
    EXPECT_EQ(encode_model(d), b);
    const std::string text = describe_model(d);
    const std::string unknown = "unknown (format version " + std::to_string(version) + ")";
    EXPECT_NE(text.find("sample period: " + unknown), std::string::npos) << text;
    EXPECT_NE(text.find("training speeds: " + unknown), std::string::npos) << text;
  }
  // The shipped default model (bundled, so its absence is a failure): re-writes to its own bytes,
  // and knows its training conditions exactly when its version says so (3 since session 89).
  const auto path = std::filesystem::path(DRESSGUARD_SOURCE_DIR) / "models/default.dgm";
  ASSERT_TRUE(std::filesystem::exists(path)) << path << " is missing: the project bundles it";
  std::ifstream in(path, std::ios::binary);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 8u);
  const auto d = read_model(path);
  EXPECT_EQ(d.knows_period() || d.knows_speeds(), bytes[8] >= 3);
  EXPECT_EQ(encode_model(d), bytes);
}

// Each bound, on load and on write, with a message naming the field.
TEST(ModelFileV3Rejects, EachBoundNamingTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  expect_rejected(v3_patched(kPeriodMarker, -0.01), "sample_period_s -0.01 s is not in (0, 1]");
  expect_rejected(v3_patched(kPeriodMarker, 1.5), "sample_period_s 1.5 s is not in (0, 1]");
  expect_rejected(v3_patched(kPeriodMarker, nan), "sample_period_s is not finite");
  expect_rejected(v3_patched(kPeriodMarker, inf), "sample_period_s is not finite");
  expect_rejected(v3_patched(kSpeedMinMarker, nan), "speed_min_m_s is not finite");
  expect_rejected(v3_patched(kSpeedMaxMarker, inf), "speed_max_m_s is not finite");
  expect_rejected(v3_patched(kSpeedMinMarker, -0.1), "speed_min_m_s is not positive");
  expect_rejected(v3_patched(kSpeedMaxMarker, 2.5), "speed_max_m_s is above 2 m/s");
  expect_rejected(v3_patched(kSpeedMinMarker, 0.5), "speed_min_m_s is above speed_max_m_s");
  expect_rejected(v3_patched(kSpeedMinMarker, 0.0), "speed range is half known");
  expect_rejected(v3_patched(kSpeedMaxMarker, 0.0), "speed range is half known");
  // 1 s and 2 m/s themselves are inside.
  auto edge = trained_at_known_conditions();
  edge.sample_period_s = 1.0;
  edge.speed_min_m_s = edge.speed_max_m_s = 2.0;
  EXPECT_NO_THROW(encode_model(edge));
  auto bad = trained_at_known_conditions();
  bad.sample_period_s = 0.0;
  bad.speed_max_m_s = 0.0;
  try {
    encode_model(bad);
    ADD_FAILURE() << "wrote a half-known speed range";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("speed range is half known"), std::string::npos) << e.what();
  }
  // A version-3 file that knows nothing: the writer never makes one.
  auto b = encode_model(trained_at_known_conditions());
  for (double v : {kPeriodMarker, kSpeedMinMarker, kSpeedMaxMarker}) replace_double(b, v, 0.0);
  fix_crc(b);
  expect_rejected(b, "format version 3 with sample_period_s, speed_min_m_s and speed_max_m_s all 0");
}

// A file whose size field and CRC agree but whose body ends inside the new fields.
TEST(ModelFileV3Rejects, TruncatedInsideTheTrainingConditions) {
  const auto b = encode_model(trained_at_known_conditions());
  const size_t at = offset_of(b, kPeriodMarker);
  const std::pair<size_t, const char*> cuts[] = {
      {at + 3, "truncated: sample period at byte"}, {at + 8, "truncated: speed min at byte"},
      {at + 20, "truncated: speed max at byte"}};
  for (const auto& [body, what] : cuts) {
    std::vector<uint8_t> c(b.begin(), b.begin() + body);
    c.resize(body + 4);  // room for the CRC
    const uint32_t size = static_cast<uint32_t>(c.size());
    for (int i = 0; i < 4; ++i) c[12 + i] = static_cast<uint8_t>(size >> (8 * i));
    fix_crc(c);
    expect_rejected(c, what);
  }
}

// A folder given as the model is named as such (the stream's own message named no path).
TEST(ModelFileRejects, AFolder) {
  try {
    read_model(std::filesystem::temp_directory_path());
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("is a folder, not a model file"), std::string::npos) << e.what();
  }
}

namespace {
// What read_model says of `path`: the ModelError's message, else what went wrong instead.
std::string read_error(const std::filesystem::path& path) {
  try {
    read_model(path);
    return "accepted";
  } catch (const ModelError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("not a ModelError: ") + e.what();
  }
}
}  // namespace

// read_model refuses, before reading, a file larger than any model (kMaxFileBytes) and what is not
// a regular file, naming the path: it read the whole input first, so a FIFO blocked it for ever,
// /dev/zero ended in std::bad_alloc, and a 300 MB file took seconds and 528 MB.
TEST(ModelFileRejects, TooLargeOrNotARegularFile) {
  const auto dir = std::filesystem::temp_directory_path() / ("dgm_size_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto big = dir / "big.dgm";
  {
    const auto b = encode_model(sample_model());
    std::ofstream out(big, std::ios::binary);
    out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  }
  std::filesystem::resize_file(big, size_t{2} << 20);  // a model followed by zeros, 2 MiB in all
  std::string what = read_error(big);
  EXPECT_EQ(what.rfind(big.string() + ": 2097152 bytes is larger than any model file (at most 1048576", 0), 0u)
      << what;
  // A FIFO with no writer: open() for reading would wait for one. Should read_model wait, the
  // test becomes that writer (open and close: the reader sees an empty file) and fails.
  const auto fifo = dir / "fifo.dgm";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  auto pending = std::async(std::launch::async, [&] { return read_error(fifo); });
  if (pending.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    ADD_FAILURE() << "read_model blocked on a FIFO";
    const int w = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (w >= 0) ::close(w);
  }
  what = pending.get();
  EXPECT_EQ(what, fifo.string() + ": not a regular file (a FIFO)");
  // A device that never ends (it ran out of memory: std::bad_alloc, no path).
  what = read_error("/dev/zero");
  EXPECT_EQ(what, "/dev/zero: not a regular file (a character device)");
  std::filesystem::remove_all(dir);
}

TEST(ModelFileRejects, BadCrc) {
  auto b = encode_model(sample_model());
  b[b.size() / 2] ^= 0x10;
  expect_rejected(b, "bad CRC-32");
}

TEST(ModelFileRejects, Truncated) {
  const auto b = encode_model(sample_model());
  for (size_t keep : {size_t{0}, size_t{7}, size_t{19}, size_t{100}, b.size() - 1}) {
    std::vector<uint8_t> t(b.begin(), b.begin() + keep);
    expect_rejected(t, "truncated");
  }
  // A consistent but lying size field: the body ends before the fields do.
  auto c = b;
  c.resize(200);
  for (int i = 0; i < 4; ++i) c[12 + i] = static_cast<uint8_t>(200u >> (8 * i));
  fix_crc(c);
  expect_rejected(c, "truncated");
  auto extra = b;
  extra.push_back(0);
  expect_rejected(extra, "trailing data");
}

TEST(ModelFileRejects, NonFiniteNumbers) {
  expect_rejected(patched(1.2345678901, std::numeric_limits<double>::quiet_NaN()), "is not finite");
  expect_rejected(patched(1.2345678901, std::numeric_limits<double>::infinity()), "is not finite");
}

TEST(ModelFileRejects, TransitionRowNotSummingToOne) {
  expect_rejected(patched(0.8765432109, 0.8765432109 + 1e-6), "transition row 3 sums to");
  // Within the stated tolerance (1e-9) a row is accepted.
  const auto ok = patched(0.8765432109, 0.8765432109 + 1e-11);
  EXPECT_NO_THROW(decode_model(ok.data(), ok.size(), "ok"));
}

TEST(ModelFileRejects, CovarianceNotPositiveDefinite) {
  expect_rejected(patched(0.6543210987, -0.5), "not positive definite");
  expect_rejected(patched(0.6543210987, 0.125 * 0.125 / 0.5), "not positive definite");  // det = 0
}

// A covariance positive definite by the relative test (det > 1e-12 a d) whose determinant or
// inverse a double cannot hold: with a d overflowing, det is inf and the filter's log density is
// -inf at every sample; with a d subnormal, det passes and its inverse is rounding's; with a at the
// bottom of the subnormals, the inverse overflows and the density at the mean is NaN. Each was
// accepted, in a file and on encode; each is named by class and state.
TEST(ModelFileRejects, CovarianceADoubleCannotInvert) {
  struct Case { double a, d; const char* want; };
  const Case cases[] = {
      {1e155, 1e155, "class 'good' state 5 covariance is degenerate: its determinant inf is outside the normal"},
      {1e-160, 1e-160, "class 'good' state 5 covariance is degenerate: its determinant 9.99989e-321 is outside"},
      {5e-324, 1e300, "class 'good' state 5 covariance is degenerate: its inverse is not finite (det 4.94066e-24"},
  };
  for (const Case& c : cases) {
    // In a file: a valid model whose state 5 of 'good' holds two markers, patched to the case.
    OutcomeModel m = sample_model();
    GaussianEmission& e = m.classes[0].emission[5];
    e.cov[0][1] = e.cov[1][0] = 0.0;
    e.cov[0][0] = 0.4321098765;
    auto b = encode_model(m);
    replace_double(b, 0.4321098765, c.a);
    replace_double(b, 0.6543210987, c.d);
    fix_crc(b);
    expect_rejected(b, c.want);
    // On encode: never written.
    e.cov[0][0] = c.a, e.cov[1][1] = c.d;
    try {
      encode_model(m);
      ADD_FAILURE() << "encoded a model that should fail with: " << c.want;
    } catch (const ModelError& err) {
      EXPECT_NE(std::string(err.what()).find(c.want), std::string::npos) << err.what();
    }
  }
  // The determinant in the message at any magnitude: one ulp of d from singular, det is 2^-58
  // (it read "det 0.000000").
  expect_rejected(patched(0.6543210987, std::nextafter(0.125 * 0.125 / 0.5, 1.0)),
                  "not positive definite (det 3.46945e-18)");
}

namespace {
// The sample model's bytes with its one "caught" (a class name) replaced by `to`, same length.
std::vector<uint8_t> renamed_caught(const std::string& to) {
  auto b = encode_model(sample_model());
  const std::string from = "caught";
  EXPECT_EQ(to.size(), from.size());
  const auto at = std::search(b.begin(), b.end(), from.begin(), from.end());
  EXPECT_NE(at, b.end());
  EXPECT_EQ(std::search(at + 1, b.end(), from.begin(), from.end()), b.end()) << "not unique";
  std::copy(to.begin(), to.end(), at);
  fix_crc(b);
  return b;
}
}  // namespace

// A class name the reader refuses is refused on write too: one over the reader's 65,536 bytes
// was written, and the file then could not be read. A name must also be UTF-8 (FORMAT.md) and
// hold no NUL (printed, it ended there). Each in a file and on encode.
TEST(ModelFileRejects, ClassNamesTheReaderCannotRead) {
  auto m = sample_model();
  m.classes[1].name = std::string(70000, 'm');
  try {
    encode_model(m);
    ADD_FAILURE() << "encoded a 70,000-byte class name";
  } catch (const ModelError& e) {
    EXPECT_STREQ(e.what(), "model to encode: class 1's name is 70000 bytes long (at most 65536)");
  }
  m.classes[1].name = std::string(65536, 'm');  // the limit itself is a name
  const auto at_limit = encode_model(m);
  EXPECT_EQ(decode_model(at_limit.data(), at_limit.size(), "mem").classes[1].name.size(), 65536u);
  expect_rejected(renamed_caught(std::string("cau\0ht", 6)), "class 2's name holds a NUL byte (byte 3)");
  expect_rejected(renamed_caught("caugh\xff"), "class 2's name is not UTF-8 (byte 5)");
  // UTF-8 by RFC 3629: what is refused, and at which byte.
  const std::pair<std::string, std::string> cases[] = {
      {"caf\xc3\xa9", ""},                                // é
      {"\xf0\x9f\x98\x80", ""},                           // U+1F600, 4 bytes
      {"ok\x80", "is not UTF-8 (byte 2)"},                 // a continuation byte with no lead
      {"ok\xc3", "is not UTF-8 (byte 2)"},                 // cut short
      {"\xc3(", "is not UTF-8 (byte 0)"},                  // lead without its continuation
      {"\xc0\xaf", "is not UTF-8 (byte 0)"},               // overlong '/'
      {"a\xe0\x80\xaf", "is not UTF-8 (byte 1)"},          // overlong, 3 bytes
      {"\xed\xa0\x80", "is not UTF-8 (byte 0)"},           // a surrogate, U+D800
      {"\xf4\x90\x80\x80", "is not UTF-8 (byte 0)"},       // U+110000, past Unicode
      {"\xf8\x88\x80\x80\x80", "is not UTF-8 (byte 0)"},   // a 5-byte form
  };
  for (const auto& [name, want] : cases) {
    auto u = sample_model();
    u.classes[0].name = name;
    std::string what = "accepted";
    try {
      encode_model(u);
    } catch (const ModelError& e) {
      what = e.what();
    }
    if (want.empty())
      EXPECT_EQ(what, "accepted") << name;
    else
      EXPECT_EQ(what, "model to encode: class 0's name " + want) << name;
  }
}

// Symmetry is judged against sqrt(cov00 cov11), the scale of the off-diagonal itself (|cov01| <
// sqrt(cov00 cov11) when positive definite), and positive definiteness on the matrix the filter
// inverts, whose off-diagonal is the mean of the two (emission_terms). With the larger diagonal
// as the scale, diagonals 1e10 and 1e-10 let cov01 and cov10 differ by 0.01, far more than any
// valid off-diagonal (< 1): the pair below passed, and its determinant from cov01 alone (2e-7)
// hid that the filter's, from their mean 1, is 0. The second pair is symmetric within 1e-12 and
// positive definite by cov01 alone (det 1.5e-12 > 1e-12 cov00 cov11) but not by their mean
// (0.6e-12). Each in a file and on encode, named by class and state.
TEST(ModelFileRejects, CovarianceAsTheFilterSeesIt) {
  struct Case {
    double a, d, b, c;
    const char* want;
  };
  const double b2 = std::sqrt(1.0 - 1.5e-12);
  const Case cases[] = {
      {1e10, 1e-10, 1.0 - 1e-7, 1.0 - 1e-7 + 2e-7,
       "class 'good' state 5 covariance is not symmetric (cov[0][1] 0.99999990000000005, cov[1][0] 1.0000001"},
      {1.0, 1.0, b2, b2 + 0.9e-12, "class 'good' state 5 covariance is not positive definite (det 6."},
  };
  // Markers for state 5 of 'good': cov00 and the two off-diagonals, unique in the file.
  constexpr double kA = 0.4321098765, kB = 0.0123456789, kC = 0.0123456789 + 1e-15;
  for (const Case& c : cases) {
    OutcomeModel m = sample_model();
    GaussianEmission& e = m.classes[0].emission[5];
    e.cov[0][0] = kA, e.cov[0][1] = kB, e.cov[1][0] = kC;
    auto b = encode_model(m);
    replace_double(b, kA, c.a);
    replace_double(b, 0.6543210987, c.d);
    replace_double(b, kB, c.b);
    replace_double(b, kC, c.c);
    fix_crc(b);
    expect_rejected(b, c.want);
    e.cov[0][0] = c.a, e.cov[1][1] = c.d, e.cov[0][1] = c.b, e.cov[1][0] = c.c;
    try {
      encode_model(m);
      ADD_FAILURE() << "encoded a model that should fail with: " << c.want;
    } catch (const ModelError& err) {
      EXPECT_NE(std::string(err.what()).find(c.want), std::string::npos) << err.what();
    }
  }
}

namespace {
// What encode_model says of `m`: the ModelError's message, or "encoded".
std::string encode_error(const OutcomeModel& m) {
  try {
    encode_model(m);
    return "encoded";
  } catch (const ModelError& e) {
    return e.what();
  }
}
}  // namespace

// Numbers near 1 are printed with every digit a double has (%.17g): "%f" said "class priors sum
// to 1.000000, not 1" and "1.000000 is not a probability", hiding the difference. A log prior is
// at most 1e-12 (a prior of 1 and its rounding), as FORMAT.md now says, and the message says so.
TEST(ModelFileRejects, NumbersNearTheirBoundShowTheDifference) {
  auto m = sample_model();
  m.classes[0].log_prior = std::log(1.0 / 3.0 + 2e-9);
  EXPECT_EQ(encode_error(m), "model to encode: class priors sum to 1.0000000019999999, not 1 (tolerance 1e-9)");
  expect_rejected(patched(0.8765432109, 1.0000000001),
                  "class 'caught' transition row 3 entry 3 = 1.0000000001 is not a probability");
  expect_rejected(patched(0.8765432109, 0.8765432109 + 1e-6),
                  "class 'caught' transition row 3 sums to 1.0000010000000001, not 1 (tolerance 1e-9)");
  OutcomeModel one = sample_model();
  one.classes.resize(1);
  one.classes[0].log_prior = 1e-13;  // a prior of 1, give or take rounding
  EXPECT_EQ(encode_error(one), "encoded");
  one.classes[0].log_prior = 2e-12;
  EXPECT_EQ(encode_error(one),
            "model to encode: class 'good' log prior 2e-12 is above 0 (a prior above 1; 1e-12 allowed)");
}

TEST(ModelFileRejects, SemanticChecksOnEncode) {
  auto m = sample_model();
  m.classes[1].name = "good";
  EXPECT_THROW(encode_model(m), ModelError);
  m = sample_model();
  m.features.scale[1] = 0.0;
  EXPECT_THROW(encode_model(m), ModelError);
  m = sample_model();
  m.classes[0].log_prior = 0.0;  // priors then sum to 5/3
  EXPECT_THROW(encode_model(m), ModelError);
}

namespace {
void put_u32(std::vector<uint8_t>& b, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = static_cast<uint8_t>(v >> (8 * i));
}
void put_f64(std::vector<uint8_t>& b, size_t at, double v) { std::memcpy(&b[at], &v, 8); }
// Where the text `s` starts in `b`; it must occur once.
size_t text_at(const std::vector<uint8_t>& b, const std::string& s) {
  const auto at = std::search(b.begin(), b.end(), s.begin(), s.end());
  EXPECT_NE(at, b.end()) << s;
  EXPECT_EQ(std::search(at + 1, b.end(), s.begin(), s.end()), b.end()) << s << " is not unique";
  return static_cast<size_t>(at - b.begin());
}
}  // namespace

// Every structural and semantic rule FORMAT.md lists that no test above shows on its own: one
// small change to the sample model's file each (the size field and the CRC repaired after it, so
// that the rule under test is what refuses it), refused with a message naming the file and the
// problem.
TEST(ModelFileRejects, EachRuleOnItsOwn) {
  const std::vector<uint8_t> base = encode_model(sample_model());
  // The layout around the markers (FORMAT.md): feature 0 is axis (i32), sign, offset -2.5, scale
  // 1.75; the stop threshold 0.9 is followed by the stop count (i32) and, in version 1, the class
  // count (u32), then class 0's name, 'good', as a str, and its state count.
  const size_t axis0 = offset_of(base, -2.5) - 12, threshold = offset_of(base, 0.9);
  const size_t good = text_at(base, "good"), caught = text_at(base, "caught");
  const size_t class_count = good - 8, state_count = good + 4;
  ASSERT_EQ(threshold + 12, class_count);
  using Mutation = std::function<void(std::vector<uint8_t>&)>;
  const std::string crc_at = std::to_string(base.size() - 4);
  const std::pair<Mutation, std::string> cases[] = {
      {[](auto& b) { b.insert(b.end() - 4, 4, uint8_t{0}); }, "4 unexplained bytes before the CRC at byte " + crc_at},
      {[&](auto& b) { put_u32(b, class_count, 0); }, "0 classes (1..8 allowed)"},
      {[&](auto& b) { put_u32(b, class_count, 9); }, "9 classes (1..8 allowed)"},
      {[&](auto& b) { put_u32(b, state_count, 0); }, "class 'good' has 0 states (1..32 allowed)"},
      {[&](auto& b) { put_u32(b, state_count, 33); }, "class 'good' has 33 states (1..32 allowed)"},
      {[](auto& b) { put_u32(b, 16, 65537); }, "tool version length 65537 exceeds 65536"},
      {[&](auto& b) { put_u32(b, good - 4, 70000); }, "class name length 70000 exceeds 65536"},
      {[&](auto& b) {
         put_u32(b, good - 4, 0);
         b.erase(b.begin() + static_cast<std::ptrdiff_t>(good), b.begin() + static_cast<std::ptrdiff_t>(good) + 4);
       },
       "class 0 has an empty name"},
      {[&](auto& b) { std::memcpy(&b[caught], "missed", 6); }, "class name 'missed' appears twice"},
      {[&](auto& b) { put_u32(b, axis0, 4); }, "feature 0 axis 4 is not 0, 1, 2 or 3 (none)"},
      {[&](auto& b) { put_u32(b, axis0, 0xFFFFFFFFu); }, "feature 0 axis -1 is not 0, 1, 2 or 3 (none)"},
      {[&](auto& b) { put_f64(b, axis0 + 4, 0.5); }, "feature 0 sign is not +1 or -1"},
      {[&](auto& b) { put_f64(b, axis0 + 20, 0.0); }, "feature 0 scale is not positive"},
      {[&](auto& b) { put_f64(b, threshold, 0.0); }, "stop threshold 0 is not in (0, 1)"},
      {[&](auto& b) { put_f64(b, threshold, 1.0); }, "stop threshold 1 is not in (0, 1)"},
      {[&](auto& b) { put_f64(b, threshold, std::numeric_limits<double>::quiet_NaN()); },
       "stop threshold is not finite"},
      {[&](auto& b) { put_u32(b, threshold + 8, 0); }, "stop_consecutive 0 is not in 1..100000"},
      {[&](auto& b) { put_u32(b, threshold + 8, 100001); }, "stop_consecutive 100001 is not in 1..100000"},
  };
  for (const auto& [mutate, want] : cases) {
    SCOPED_TRACE(want);
    auto b = base;
    mutate(b);
    put_u32(b, 12, static_cast<uint32_t>(b.size()));
    fix_crc(b);
    expect_rejected(b, want);
  }
  // The bounds themselves are inside: 1 and 8 classes, 1 and 32 states, 1 and 100,000 samples.
  auto edges = sample_model();
  edges.stop_consecutive = 100000;
  edges.classes.resize(1);
  edges.classes[0].log_prior = 0.0;
  EXPECT_EQ(encode_error(edges), "encoded");
  edges.stop_consecutive = 1;
  edges.classes.assign(8, left_right_chain(32, 0.5));
  for (int c = 0; c < 8; ++c) {
    edges.classes[c].name = "class" + std::to_string(c);
    edges.classes[c].emission.assign(32, GaussianEmission{});
    edges.classes[c].log_prior = std::log(0.125);
  }
  EXPECT_EQ(encode_error(edges), "encoded");
  edges.classes[0].n_states = 1;  // the arrays no longer match: refused on encode
  EXPECT_EQ(encode_error(edges), "model to encode: class 'class0' arrays do not match its state count");
}

// The shipped default model: its bytes match the recorded SHA-256 and it loads (CRC and all).
TEST(DefaultModel, ChecksumMatches) {
  const std::filesystem::path dir = std::filesystem::path(DRESSGUARD_SOURCE_DIR) / "models";
  const auto model = dir / "default.dgm", sum = dir / "default.dgm.sha256";
  ASSERT_TRUE(std::filesystem::exists(model)) << model << " is missing: the project bundles it";
  ASSERT_TRUE(std::filesystem::exists(sum)) << "models/default.dgm has no default.dgm.sha256 beside it";
  std::ifstream in(sum);
  std::string expected;
  in >> expected;
  ASSERT_EQ(expected.size(), 64u) << "default.dgm.sha256 does not start with a SHA-256 hex digest";
  const std::string cmd = "sha256sum '" + model.string() + "'";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  char buf[65] = {};
  ASSERT_EQ(fread(buf, 1, 64, p), 64u);
  pclose(p);
  EXPECT_EQ(std::string(buf), expected) << "models/default.dgm changed without updating its checksum";
  const auto m = read_model(model);
  EXPECT_GE(m.classes.size(), 2u);
}
