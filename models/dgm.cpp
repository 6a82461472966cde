// The .dgm model file: encoding, decoding and validation. The byte layout is FORMAT.md's.
#include "dgm.h"
#include "utf8.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace dressguard::model {

namespace {
// The symmetric matrix [[a b][b d]] the filter and the trainer use for a stored covariance (b the
// mean of the two off-diagonals), and its determinant: one function, so that validation checks
// the very det that emission_terms inverts.
struct SymmetricCovariance {
  double a, b, d, det;
};
SymmetricCovariance symmetric_covariance(const GaussianEmission& e) noexcept {
  const double a = e.cov[0][0], b = 0.5 * (e.cov[0][1] + e.cov[1][0]), d = e.cov[1][1];
  return {a, b, d, a * d - b * b};
}
}  // namespace

EmissionTerms emission_terms(const GaussianEmission& e) noexcept {
  constexpr double kLog2Pi = 1.8378770664093454835606594728112;  // log(2 pi)
  const auto [a, b, d, det] = symmetric_covariance(e);
  return {e.mean[0], e.mean[1], d / det, -b / det, a / det, -kLog2Pi - 0.5 * std::log(det)};
}

int OutcomeModel::class_index(std::string_view name) const {
  for (size_t i = 0; i < classes.size(); ++i)
    if (classes[i].name == name) return static_cast<int>(i);
  return -1;
}

ClassHmm left_right_chain(int n_states, double stay, int band) {
  if (n_states < 1) throw std::invalid_argument("left_right_chain: n_states must be >= 1");
  const int n = n_states;
  ClassHmm h;
  h.n_states = n;
  h.initial.assign(n, 0.0);
  h.initial[0] = 1.0;
  h.transition.assign(n * n, 0.0);
  for (int i = 0; i < n; ++i) {
    const int reach = std::min(band, n - 1 - i);
    if (reach <= 0) {
      h.transition[i * n + i] = 1.0;
      continue;
    }
    h.transition[i * n + i] = stay;
    for (int d = 1; d <= reach; ++d) h.transition[i * n + i + d] = (1.0 - stay) / reach;
  }
  return h;
}

// ---------------------------------------------------------------------------------------------
// CRC-32 (IEEE, reflected), table built once at compile time.
namespace {
constexpr std::array<uint32_t, 256> make_crc_table() {
  std::array<uint32_t, 256> t{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}
constexpr std::array<uint32_t, 256> kCrcTable = make_crc_table();
}  // namespace

uint32_t crc32(const uint8_t* data, size_t size) noexcept {
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < size; ++i) c = kCrcTable[(c ^ data[i]) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

namespace {

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw ModelError(source + ": " + what);
}

// A number for a message, to 6 significant digits at any magnitude (1e-320 too).
std::string short_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

// A number for a message where the difference is in the last digits: every digit a double has.
std::string precise_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

// Longest string field the loader accepts (metadata, class names): keeps a corrupt length from
// asking for gigabytes.
constexpr uint32_t kMaxString = 65536;
// Fixed part: magic(8) + version(4) + size(4); trailer: CRC(4).
constexpr size_t kHeaderBytes = 16, kTrailerBytes = 4;

// The largest file the format allows (FORMAT.md's layout with every count and string at its
// limit), which kMaxFileBytes must not refuse.
constexpr size_t kLargestString = 4 + kMaxString;
constexpr size_t kLargestHmm = 8 * (kMaxStates + kMaxStates * kMaxStates + 6 * kMaxStates);  // pi, A, emissions
constexpr size_t kLargestClass = kLargestString + 4 + 8 + kLargestHmm;  // name, state count, log prior
constexpr size_t kLargestFile = kHeaderBytes + 4 * kLargestString + kFeatures * (4 + 3 * 8) + (8 + 4) + 3 * 8 +
                                4 + kMaxClasses * kLargestClass + kTrailerBytes;
static_assert(kLargestFile == 866564 && kLargestFile <= kMaxFileBytes, "dgm.h's kMaxFileBytes comment is stale");

// Closes a descriptor on every way out of a scope (read_model's, write_model's error paths).
struct FdGuard {
  int fd = -1;
  ~FdGuard() {
    if (fd >= 0) ::close(fd);
  }
};

// What a stat mode is, for "not a regular file" messages.
const char* file_kind(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "of another kind";
}

std::string too_large(uintmax_t size) {
  return std::to_string(size) + " bytes is larger than any model file (at most " + std::to_string(kMaxFileBytes) +
         " bytes read; FORMAT.md)";
}

// ---- validation: one small function per rule --------------------------------------------------

void check_finite(double v, const std::string& source, const std::string& what) {
  if (!std::isfinite(v)) fail(source, what + " is not finite (" + std::to_string(v) + ")");
}

// A probability vector: entries in [0,1], |sum - 1| <= kStochasticTolerance.
void check_stochastic(const double* p, int n, const std::string& source, const std::string& what) {
  double sum = 0.0;
  for (int j = 0; j < n; ++j) {
    check_finite(p[j], source, what + " entry " + std::to_string(j));
    if (p[j] < 0.0 || p[j] > 1.0)
      fail(source, what + " entry " + std::to_string(j) + " = " + precise_number(p[j]) + " is not a probability");
    sum += p[j];
  }
  if (std::fabs(sum - 1.0) > kStochasticTolerance)
    fail(source, what + " sums to " + precise_number(sum) + ", not 1 (tolerance 1e-9)");
}

// Covariance [[a b][c d]]: symmetric (|b - c| <= 1e-12 sqrt(|a| |d|): the scale of the
// off-diagonal itself, |b| < sqrt(a d) when positive definite; max(|a|, |d|) let an asymmetry
// larger than any valid off-diagonal through when a and d differ by orders of magnitude), and
// positive definite as the filter sees it, [[a m][m d]] with m = (b + c) / 2 (symmetric_covariance):
// a > 0 and det = a d - m^2 > 0 (Sylvester's criterion for 2x2), with det relative to a d above
// 1e-12 so the inverse the filter precomputes is meaningful; and det a normal double and that
// inverse (emission_terms) finite, so that it can be computed at all.
void check_covariance(const GaussianEmission& e, const std::string& source, const std::string& what) {
  for (int r = 0; r < kFeatures; ++r) {
    check_finite(e.mean[r], source, what + " mean[" + std::to_string(r) + "]");
    for (int k = 0; k < kFeatures; ++k)
      check_finite(e.cov[r][k], source, what + " cov[" + std::to_string(r) + "][" + std::to_string(k) + "]");
  }
  const double b = e.cov[0][1], c = e.cov[1][0];
  const auto [a, m, d, det] = symmetric_covariance(e);
  // sqrt of each, not of the product: a d may overflow (or sink to 0) where the bound does not.
  if (std::fabs(b - c) > 1e-12 * std::sqrt(std::fabs(a)) * std::sqrt(std::fabs(d)))
    fail(source, what + " covariance is not symmetric (cov[0][1] " + precise_number(b) + ", cov[1][0] " +
                     precise_number(c) + ")");
  const std::string text = short_number(det);  // to_string's %f said "det 0.000000" of 1e-20
  if (!(a > 0.0) || !(d > 0.0) || !(det > 0.0))
    fail(source, what + " covariance is not positive definite (det " + text + ")");
  // Positive, but a d can overflow or sink below the normal doubles (so can det): the inverse and
  // log-determinant that the filter and the trainer compute (emission_terms) are then inf, 0 or
  // rounding's, every likelihood -inf or NaN, and the relative test below cannot see it.
  if (!(det >= std::numeric_limits<double>::min() && det <= std::numeric_limits<double>::max()))
    fail(source, what + " covariance is degenerate: its determinant " + text +
                     " is outside the normal doubles, so its inverse and log-determinant are lost to rounding");
  if (!(det > 1e-12 * a * d)) fail(source, what + " covariance is not positive definite (det " + text + ")");
  const EmissionTerms t = emission_terms(e);
  if (!std::isfinite(t.ip) || !std::isfinite(t.iq) || !std::isfinite(t.ir) || !std::isfinite(t.lconst))
    fail(source, what + " covariance is degenerate: its inverse is not finite (det " + text + ", cov[0][0] " +
                     short_number(a) + ", cov[1][1] " + short_number(d) + ")");
}

void check_features(const FeatureConvention& f, const std::string& source) {
  if (f.axis[0] == kAxisNone && f.axis[1] == kAxisNone) fail(source, "both features are 'none' (axis 3)");
  for (int k = 0; k < kFeatures; ++k) {
    const std::string w = "feature " + std::to_string(k);
    if (f.axis[k] < 0 || f.axis[k] > kAxisNone)
      fail(source, w + " axis " + std::to_string(f.axis[k]) + " is not 0, 1, 2 or 3 (none)");
    if (f.sign[k] != 1.0 && f.sign[k] != -1.0) fail(source, w + " sign is not +1 or -1");
    check_finite(f.offset[k], source, w + " offset");
    check_finite(f.scale[k], source, w + " scale");
    if (!(f.scale[k] > 0.0)) fail(source, w + " scale is not positive");
    // FORMAT.md: an unused feature stores offset 0 and scale 1 (it is 0 for every sample).
    if (f.axis[k] == kAxisNone && (f.offset[k] != 0.0 || f.scale[k] != 1.0))
      fail(source, w + " is 'none' (axis 3) but its offset is not 0 or its scale not 1");
  }
}

// The training conditions (format version 3); 0 is unknown. A period is a sensor's: above 1 s
// no force sensor the predictor runs on samples. Speeds above 2 m/s are no dressing pull.
void check_training_period(double period_s, const std::string& source) {
  check_finite(period_s, source, "sample_period_s");
  if (period_s != 0.0 && !(period_s > 0.0 && period_s <= 1.0))
    fail(source, "sample_period_s " + short_number(period_s) + " s is not in (0, 1] (or 0, unknown)");
}

// Both speeds known, or both unknown (0): a range with one end is no range.
void check_training_speeds(double min_m_s, double max_m_s, const std::string& source) {
  check_finite(min_m_s, source, "speed_min_m_s");
  check_finite(max_m_s, source, "speed_max_m_s");
  if (min_m_s == 0.0 && max_m_s == 0.0) return;
  const std::string range =
      " (speed_min_m_s " + short_number(min_m_s) + ", speed_max_m_s " + short_number(max_m_s) + ")";
  if (min_m_s == 0.0 || max_m_s == 0.0)
    fail(source, "speed range is half known" + range + ": both 0 (unknown) or both set");
  if (!(min_m_s > 0.0)) fail(source, "speed_min_m_s is not positive" + range);
  if (!(max_m_s <= 2.0)) fail(source, "speed_max_m_s is above 2 m/s" + range);
  if (!(min_m_s <= max_m_s)) fail(source, "speed_min_m_s is above speed_max_m_s" + range);
}

// A class name is what messages, `model show`, the predictor's logs and JSON print and what
// "caught" is looked up by: at most kMaxString bytes (what the reader accepts: a longer one was
// written and then refused), UTF-8 as FORMAT.md says, and no NUL (printed through %s it cut the
// name short, so two names could look the same). `index` names it where the name cannot.
void check_class_name(const std::string& name, size_t index, const std::string& source) {
  const std::string w = "class " + std::to_string(index) + "'s name";
  if (name.empty()) fail(source, "class " + std::to_string(index) + " has an empty name");
  if (name.size() > kMaxString)
    fail(source, w + " is " + std::to_string(name.size()) + " bytes long (at most " + std::to_string(kMaxString) + ")");
  if (const size_t at = name.find('\0'); at != std::string::npos)
    fail(source, w + " holds a NUL byte (byte " + std::to_string(at) + ")");
  if (const size_t at = invalid_utf8_at(name); at != std::string_view::npos)
    fail(source, w + " is not UTF-8 (byte " + std::to_string(at) + ")");
}

void check_class(const ClassHmm& h, const std::string& source) {
  const std::string w = "class '" + h.name + "'";
  if (h.n_states < 1 || h.n_states > kMaxStates)
    fail(source, w + " has " + std::to_string(h.n_states) + " states (1.." + std::to_string(kMaxStates) + " allowed)");
  const size_t n = static_cast<size_t>(h.n_states);
  if (h.initial.size() != n || h.transition.size() != n * n || h.emission.size() != n)
    fail(source, w + " arrays do not match its state count");
  check_finite(h.log_prior, source, w + " log prior");
  // A prior of 1 is log 0; one normalised in logs (log p - log z) can come out an ulp or so above
  // 0, which 1e-12 allows (the priors' sum, within 1e-9 of 1, bounds it anyway).
  if (h.log_prior > 1e-12)
    fail(source, w + " log prior " + precise_number(h.log_prior) + " is above 0 (a prior above 1; 1e-12 allowed)");
  check_stochastic(h.initial.data(), h.n_states, source, w + " initial distribution");
  for (int i = 0; i < h.n_states; ++i)
    check_stochastic(h.transition.data() + i * n, h.n_states, source, w + " transition row " + std::to_string(i));
  for (int j = 0; j < h.n_states; ++j) check_covariance(h.emission[j], source, w + " state " + std::to_string(j));
}

// ---- little-endian writer and bounds-checked reader --------------------------------------------

class Writer {
 public:
  void bytes(const void* p, size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    out_.insert(out_.end(), b, b + n);
  }
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) out_.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void i32(int32_t v) { u32(static_cast<uint32_t>(v)); }
  void f64(double v) {
    uint64_t u;
    std::memcpy(&u, &v, 8);
    for (int i = 0; i < 8; ++i) out_.push_back(static_cast<uint8_t>(u >> (8 * i)));
  }
  void str(const std::string& s) {
    u32(static_cast<uint32_t>(s.size()));
    bytes(s.data(), s.size());
  }
  std::vector<uint8_t>& data() { return out_; }

 private:
  std::vector<uint8_t> out_;
};

class Reader {
 public:
  Reader(const uint8_t* p, size_t end, size_t pos, const std::string& source) : p_(p), end_(end), pos_(pos), source_(source) {}
  void need(size_t n, const char* what) {
    if (n > end_ - pos_)
      fail(source_, "truncated: " + std::string(what) + " at byte " + std::to_string(pos_) + " needs " +
                        std::to_string(n) + " bytes, only " + std::to_string(end_ - pos_) + " left");
  }
  uint32_t u32(const char* what) {
    need(4, what);
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(p_[pos_ + i]) << (8 * i);
    pos_ += 4;
    return v;
  }
  int32_t i32(const char* what) { return static_cast<int32_t>(u32(what)); }
  double f64(const char* what) {
    need(8, what);
    uint64_t u = 0;
    for (int i = 0; i < 8; ++i) u |= static_cast<uint64_t>(p_[pos_ + i]) << (8 * i);
    pos_ += 8;
    double v;
    std::memcpy(&v, &u, 8);
    return v;
  }
  std::string str(const char* what) {
    const uint32_t n = u32(what);
    if (n > kMaxString) fail(source_, std::string(what) + " length " + std::to_string(n) + " exceeds " + std::to_string(kMaxString));
    need(n, what);
    std::string s(reinterpret_cast<const char*>(p_ + pos_), n);
    pos_ += n;
    return s;
  }
  size_t pos() const { return pos_; }

 private:
  const uint8_t* p_;
  size_t end_, pos_;
  const std::string& source_;
};

}  // namespace

void validate_model(const OutcomeModel& m, const std::string& source) {
  check_features(m.features, source);
  if (m.classes.empty() || m.classes.size() > static_cast<size_t>(kMaxClasses))
    fail(source, std::to_string(m.classes.size()) + " classes (1.." + std::to_string(kMaxClasses) + " allowed)");
  std::set<std::string> names;
  double prior_sum = 0.0;
  for (size_t c = 0; c < m.classes.size(); ++c) {
    const ClassHmm& h = m.classes[c];
    check_class_name(h.name, c, source);
    check_class(h, source);
    if (!names.insert(h.name).second) fail(source, "class name '" + h.name + "' appears twice");
    prior_sum += std::exp(h.log_prior);
  }
  // Priors are stored as logs; their exponentials must form a distribution (1e-9 as for rows).
  if (std::fabs(prior_sum - 1.0) > kStochasticTolerance)
    fail(source, "class priors sum to " + precise_number(prior_sum) + ", not 1 (tolerance 1e-9)");
  check_finite(m.stop_threshold, source, "stop threshold");
  if (!(m.stop_threshold > 0.0 && m.stop_threshold < 1.0))
    fail(source, "stop threshold " + precise_number(m.stop_threshold) + " is not in (0, 1)");
  if (m.stop_consecutive < 1 || m.stop_consecutive > 100000)
    fail(source, "stop_consecutive " + std::to_string(m.stop_consecutive) + " is not in 1..100000");
  check_training_period(m.sample_period_s, source);
  check_training_speeds(m.speed_min_m_s, m.speed_max_m_s, source);
  for (const std::string* s : {&m.tool_version, &m.created, &m.source_dataset, &m.training_summary})
    if (s->size() > kMaxString) fail(source, "a metadata string is longer than 65536 bytes");
}

bool same_period(double a_s, double b_s, double tolerance) noexcept {
  return std::fabs(a_s - b_s) <= tolerance * std::max(std::fabs(a_s), std::fabs(b_s));
}

uint32_t format_version_of(const OutcomeModel& m) noexcept {
  if (m.knows_period() || m.knows_speeds()) return 3;
  for (int k = 0; k < kFeatures; ++k)
    if (m.features.axis[k] == kAxisNone) return 2;
  return 1;
}

std::vector<uint8_t> encode_model(const OutcomeModel& m) {
  validate_model(m, "model to encode");
  Writer w;
  w.bytes(kMagic, 8);
  w.u32(format_version_of(m));
  w.u32(0);  // total size, patched below
  w.str(m.tool_version);
  w.str(m.created);
  w.str(m.source_dataset);
  w.str(m.training_summary);
  for (int k = 0; k < kFeatures; ++k) {
    w.i32(m.features.axis[k]);
    w.f64(m.features.sign[k]);
    w.f64(m.features.offset[k]);
    w.f64(m.features.scale[k]);
  }
  w.f64(m.stop_threshold);
  w.i32(m.stop_consecutive);
  if (format_version_of(m) >= 3) {
    w.f64(m.sample_period_s);
    w.f64(m.speed_min_m_s);
    w.f64(m.speed_max_m_s);
  }
  w.u32(static_cast<uint32_t>(m.classes.size()));
  for (const auto& h : m.classes) {
    w.str(h.name);
    w.u32(static_cast<uint32_t>(h.n_states));
    w.f64(h.log_prior);
    for (double v : h.initial) w.f64(v);
    for (double v : h.transition) w.f64(v);
    for (const auto& e : h.emission) {
      w.f64(e.mean[0]);
      w.f64(e.mean[1]);
      w.f64(e.cov[0][0]);
      w.f64(e.cov[0][1]);
      w.f64(e.cov[1][0]);
      w.f64(e.cov[1][1]);
    }
  }
  auto& out = w.data();
  const uint32_t total = static_cast<uint32_t>(out.size() + kTrailerBytes);
  for (int i = 0; i < 4; ++i) out[12 + i] = static_cast<uint8_t>(total >> (8 * i));
  w.u32(crc32(out.data(), out.size()));
  return std::move(out);
}

namespace {
// Why a model is written at version `v` (format_version_of), for messages.
const char* version_reason(uint32_t v) {
  if (v == 3) return "a training condition is known";
  if (v == 2) return "a feature is 'none', no training condition is known";
  return "no feature is 'none', no training condition is known";
}
}  // namespace

OutcomeModel decode_model(const uint8_t* data, size_t size, const std::string& source) {
  if (size < kHeaderBytes + kTrailerBytes)
    fail(source, "truncated: " + std::to_string(size) + " bytes, shorter than the 20-byte header and CRC");
  if (std::memcmp(data, kMagic, 8) != 0) fail(source, "wrong magic: not a dressguard model file (.dgm)");
  Reader head(data, size, 8, source);
  const uint32_t version = head.u32("format version");
  if (version < 1 || version > kFormatVersion)
    fail(source, "unsupported format version " + std::to_string(version) + " (this build reads versions 1 to " +
                     std::to_string(kFormatVersion) + ")");
  const uint32_t total = head.u32("file size");
  if (total > size) fail(source, "truncated: header says " + std::to_string(total) + " bytes, file has " + std::to_string(size));
  if (total < size) fail(source, "trailing data: header says " + std::to_string(total) + " bytes, file has " + std::to_string(size));
  const size_t body_end = size - kTrailerBytes;
  Reader crc_reader(data, size, body_end, source);
  const uint32_t stored = crc_reader.u32("CRC-32");
  const uint32_t actual = crc32(data, body_end);
  if (stored != actual) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "bad CRC-32: stored %08x, computed %08x (file corrupted)", stored, actual);
    fail(source, buf);
  }

  Reader r(data, body_end, kHeaderBytes, source);
  OutcomeModel m;
  m.tool_version = r.str("tool version");
  m.created = r.str("creation time");
  m.source_dataset = r.str("source dataset");
  m.training_summary = r.str("training summary");
  for (int k = 0; k < kFeatures; ++k) {
    m.features.axis[k] = r.i32("feature axis");
    if (version < 2 && m.features.axis[k] == kAxisNone)
      fail(source, "feature " + std::to_string(k) + " axis 3 (none) needs format version 2, the file says 1");
    m.features.sign[k] = r.f64("feature sign");
    m.features.offset[k] = r.f64("feature offset");
    m.features.scale[k] = r.f64("feature scale");
  }
  m.stop_threshold = r.f64("stop threshold");
  m.stop_consecutive = r.i32("stop consecutive");
  if (version >= 3) {
    m.sample_period_s = r.f64("sample period");
    m.speed_min_m_s = r.f64("speed min");
    m.speed_max_m_s = r.f64("speed max");
    // The writer writes version 3 only for a model that knows one of them: every file it accepts
    // re-writes to its own bytes.
    if (!m.knows_period() && !m.knows_speeds())
      fail(source, "format version 3 with sample_period_s, speed_min_m_s and speed_max_m_s all 0 (unknown): "
                   "such a model is written as version 1 or 2");
  }
  const uint32_t n_classes = r.u32("class count");
  if (n_classes < 1 || n_classes > static_cast<uint32_t>(kMaxClasses))
    fail(source, std::to_string(n_classes) + " classes (1.." + std::to_string(kMaxClasses) + " allowed)");
  for (uint32_t c = 0; c < n_classes; ++c) {
    ClassHmm h;
    h.name = r.str("class name");
    const uint32_t n = r.u32("state count");
    if (n < 1 || n > static_cast<uint32_t>(kMaxStates))
      fail(source, "class '" + h.name + "' has " + std::to_string(n) + " states (1.." + std::to_string(kMaxStates) + " allowed)");
    h.n_states = static_cast<int>(n);
    h.log_prior = r.f64("log prior");
    r.need(8 * (n + n * n + 6 * n), "HMM parameters");
    h.initial.resize(n);
    for (auto& v : h.initial) v = r.f64("initial");
    h.transition.resize(n * n);
    for (auto& v : h.transition) v = r.f64("transition");
    h.emission.resize(n);
    for (auto& e : h.emission) {
      e.mean[0] = r.f64("mean");
      e.mean[1] = r.f64("mean");
      e.cov[0][0] = r.f64("covariance");
      e.cov[0][1] = r.f64("covariance");
      e.cov[1][0] = r.f64("covariance");
      e.cov[1][1] = r.f64("covariance");
    }
    m.classes.push_back(std::move(h));
  }
  if (r.pos() != body_end)
    fail(source, std::to_string(body_end - r.pos()) + " unexplained bytes before the CRC at byte " + std::to_string(r.pos()));
  validate_model(m, source);
  // The writer writes each model at exactly one version (format_version_of), so every file the
  // loader accepts re-writes to its own bytes (FORMAT.md, Versioning): a version-2 file without
  // a 'none' axis was accepted and re-written as version 1. The checks above name the version-1
  // and version-3 cases; this one covers what they do not.
  if (const uint32_t own = format_version_of(m); version != own)
    fail(source, "format version " + std::to_string(version) + " for a model the writer writes as version " +
                     std::to_string(own) + " (" + version_reason(own) + "): a file must carry its model's version");
  return m;
}

OutcomeModel read_model(const std::filesystem::path& path) {
  const std::string name = path.string();
  // stat before open: opening a FIFO for reading waits for a writer, and a device may never end.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) fail(name, std::string("cannot open: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) fail(name, "is a folder, not a model file");
  if (!S_ISREG(st.st_mode)) fail(name, std::string("not a regular file (") + file_kind(st.st_mode) + ")");
  if (static_cast<uintmax_t>(st.st_size) > kMaxFileBytes) fail(name, too_large(static_cast<uintmax_t>(st.st_size)));
  // O_NONBLOCK: should the path have become a FIFO since the stat, open does not wait (the fstat
  // then refuses it); it changes nothing for a regular file.
  FdGuard in{::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK)};
  if (in.fd < 0) fail(name, std::string("cannot open: ") + std::strerror(errno));
  if (::fstat(in.fd, &st) != 0) fail(name, std::string("cannot stat: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) fail(name, std::string("not a regular file (") + file_kind(st.st_mode) + ")");
  // At most one byte past the limit: a file that grew since the stat is refused as too large.
  std::vector<uint8_t> bytes(kMaxFileBytes + 1);
  size_t got = 0;
  while (got < bytes.size()) {
    const ssize_t n = ::read(in.fd, bytes.data() + got, bytes.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(name, std::string("read error: ") + std::strerror(errno));
    if (n == 0) break;
    got += static_cast<size_t>(n);
  }
  if (got > kMaxFileBytes)
    fail(name, "grew while being read to more than " + std::to_string(kMaxFileBytes) +
                   " bytes, larger than any model file (FORMAT.md)");
  bytes.resize(got);
  return decode_model(bytes.data(), bytes.size(), name);
}

namespace {
// Writes all of [p, p + n) to `fd` through short writes and signals; false with errno set.
bool write_all(int fd, const uint8_t* p, size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w < 0) return false;
    p += w;
    n -= static_cast<size_t>(w);
  }
  return true;
}
}  // namespace

void write_model(const std::filesystem::path& path, const OutcomeModel& m) {
  const std::vector<uint8_t> bytes = encode_model(m);
  const std::string name = path.string();
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);  // if it cannot be made, opening the temporary file says why
  // The temporary file sits beside the target, so the rename replaces it in one step; O_EXCL, so
  // it is never a file or symlink someone else left under that name (such a name is skipped).
  static std::atomic<unsigned> serial{0};
  std::string tmp;
  FdGuard out;
  for (int attempt = 0; out.fd < 0; ++attempt) {
    tmp = name + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(serial++);
    out.fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (out.fd < 0 && (errno != EEXIST || attempt == 100)) {
      const int error = errno;
      fail(name, "cannot create the temporary file " + tmp + ": " + std::strerror(error));
    }
  }
  // Every failure from here on removes the temporary file; errno is read before anything else.
  const auto give_up = [&](const char* verb, const char* after = "") {
    const int error = errno;
    if (out.fd >= 0) ::close(out.fd);
    out.fd = -1;
    ::unlink(tmp.c_str());
    fail(name, std::string("cannot ") + verb + " the temporary file " + tmp + after + ": " + std::strerror(error));
  };
  if (!write_all(out.fd, bytes.data(), bytes.size())) give_up("write");
  // The bytes reach the disk before the rename makes them the model: else a crash could leave
  // the new name on a file whose data never arrived.
  if (::fsync(out.fd) != 0) give_up("fsync");
  const int fd = out.fd;
  out.fd = -1;
  if (::close(fd) != 0) give_up("close");  // NFS, for one, reports a failed write only here
  if (::rename(tmp.c_str(), name.c_str()) != 0) give_up("rename", " into place");
  // The rename itself is durable once the folder is. Some file systems cannot fsync a folder
  // (EINVAL): the model is in place, only that promise is weaker, which is no error.
  FdGuard folder{::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)};
  if (folder.fd < 0 || (::fsync(folder.fd) != 0 && errno != EINVAL)) {
    const int error = errno;
    fail(name, "written, but its folder " + dir.string() + " cannot be fsynced: " + std::strerror(error));
  }
}

namespace {
// "unknown (format version N)" where the file does not say: a version 1 or 2 file never does.
std::string describe_training_conditions(const OutcomeModel& m) {
  const std::string unknown = "unknown (format version " + std::to_string(format_version_of(m)) + ")";
  char buf[160];
  std::string out = "  sample period: ";
  if (m.knows_period()) {
    std::snprintf(buf, sizeof buf, "%.9g s (%.6g Hz)", m.sample_period_s, 1.0 / m.sample_period_s);
    out += buf;
  } else {
    out += unknown;
  }
  out += "\n  training speeds: ";
  if (m.knows_speeds()) {
    std::snprintf(buf, sizeof buf, "%.6g to %.6g m/s", m.speed_min_m_s, m.speed_max_m_s);
    out += buf;
  } else {
    out += unknown;
  }
  return out + "\n";
}
}  // namespace

std::string describe_model(const OutcomeModel& m) {
  std::ostringstream o;
  char buf[256];
  o << "dressguard outcome model (format " << format_version_of(m) << ")\n";
  o << "  tool:     " << m.tool_version << "\n  created:  " << m.created << "\n  source:   " << m.source_dataset << "\n";
  o << "  training: " << m.training_summary << "\n";
  static const char* kAxis[] = {"f_motion", "f_lateral", "f_vertical", "none"};
  for (int k = 0; k < kFeatures; ++k) {
    if (m.features.axis[k] == kAxisNone) {
      std::snprintf(buf, sizeof buf, "  feature %d = none (not used: 0 for every sample)\n", k);
      o << buf;
      continue;
    }
    std::snprintf(buf, sizeof buf, "  feature %d = (%s%s - %.6g) / %.6g\n", k, m.features.sign[k] < 0 ? "-" : "+",
                  kAxis[m.features.axis[k]], m.features.offset[k], m.features.scale[k]);
    o << buf;
  }
  std::snprintf(buf, sizeof buf, "  stop policy: P(stop class) > %.4g for %d consecutive samples\n", m.stop_threshold,
                m.stop_consecutive);
  o << buf;
  o << describe_training_conditions(m);
  for (const auto& h : m.classes) {
    std::snprintf(buf, sizeof buf, "  class '%s': %d states, prior %.4f\n", h.name.c_str(), h.n_states, std::exp(h.log_prior));
    o << buf;
    const int n = h.n_states;
    for (int j = 0; j < n; ++j) {
      const auto& e = h.emission[j];
      const double stay = h.transition[j * n + j];
      std::snprintf(buf, sizeof buf,
                    "    state %2d: pi %.3f  stay %.4f  mean (%+.4f, %+.4f)  cov [[%.4g, %.4g], [%.4g, %.4g]]\n", j,
                    h.initial[j], stay, e.mean[0], e.mean[1], e.cov[0][0], e.cov[0][1], e.cov[1][0], e.cov[1][1]);
      o << buf;
    }
  }
  return o.str();
}

}  // namespace dressguard::model
