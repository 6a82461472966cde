// The outcome model: one left-right HMM per task outcome (paper section V-B), the feature
// convention that turns raw force samples into the HMMs' two features, and the stop defaults the
// predictor applies. This header is the model file's in-memory form; `FORMAT.md` documents the
// `.dgm` bytes that `write_model`/`read_model` exchange. Depends on the standard library only, so
// the robot-side predictor can link it without anything from offline/.
//
// Model (constant) only: the mutable per-trial state lives in filter::ForwardFilter.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace dressguard::model {

// The HMMs see two features, F_motion ("X") and F_vertical ("Y"), paper section V-B.
inline constexpr int kFeatures = 2;
// Limits the loader enforces; they bound the predictor's fixed storage.
inline constexpr int kMaxStates = 32, kMaxClasses = 8;
// Raw sample axes, in the rig's convention (offline/core/haptic.h): drag negative, up positive.
// kAxisNone: a feature the model does not use; it is 0 for every sample, so its emission factor
// is the same constant for every state of every class and changes no likelihood ratio (a model
// trained on simulated data whose vertical force the simulator gets wrong, offline/calib/stc.h).
inline constexpr int kAxisMotion = 0, kAxisLateral = 1, kAxisVertical = 2, kAxisNone = 3;

// How one raw sample (f_motion, f_lateral, f_vertical) in the rig's convention becomes the
// feature vector x the HMMs model:
//     x[k] = (sign[k] * raw[axis[k]] - offset[k]) / scale[k]
// Training sets offset/scale to the training data's mean and standard deviation so that the
// covariance floor means the same thing for both features. The likelihoods are densities of x
// (not of the raw forces); the Jacobian 1/(scale0*scale1) is the same for every class and does not
// change any classification.
struct FeatureConvention {
  int axis[kFeatures] = {kAxisMotion, kAxisVertical};  // 0 motion, 1 lateral, 2 vertical, 3 none
  double sign[kFeatures] = {1.0, 1.0};                 // +1 or -1
  double offset[kFeatures] = {0.0, 0.0};               // [N], subtracted after the sign
  double scale[kFeatures] = {1.0, 1.0};                // [N], > 0

  // The feature vector of one raw sample (formula above; raw[kAxisNone] = 0).
  void apply(double f_motion, double f_lateral, double f_vertical, double x[kFeatures]) const noexcept {
    const double raw[4] = {f_motion, f_lateral, f_vertical, 0.0};
    for (int k = 0; k < kFeatures; ++k) x[k] = (sign[k] * raw[axis[k]] - offset[k]) / scale[k];
  }
};

// A bivariate Gaussian with full covariance (symmetric, positive definite), in feature units.
struct GaussianEmission {
  double mean[kFeatures] = {0.0, 0.0};
  double cov[kFeatures][kFeatures] = {{1.0, 0.0}, {0.0, 1.0}};
};

// The constants of one emission's log density, computed once per model by the trainer and the
// online filter alike. For S = [[a b][b d]], b the mean of cov[0][1] and cov[1][0] (a valid model
// holds them within 1e-12 sqrt(a d) of each other), and z = x - mean:
//     S^-1 = [[ip iq][iq ir]] = [[d -b][-b a]] / det,   det = a d - b^2
//     log N(x; mean, S) = lconst - (ip z0^2 + 2 iq z0 z1 + ir z1^2) / 2,   lconst = -log(2 pi) - log(det) / 2
struct EmissionTerms {
  double mean0, mean1, ip, iq, ir, lconst;
};
EmissionTerms emission_terms(const GaussianEmission& e) noexcept;

// One class's HMM. Left-right models have zeros below the diagonal of `transition`; the file
// stores the full matrix, so any topology loads, and the filter detects the band.
struct ClassHmm {
  std::string name;                        // e.g. "good", "missed", "caught"
  int n_states = 0;                        // 1..kMaxStates
  std::vector<double> initial;             // n_states, sums to 1
  std::vector<double> transition;          // n_states*n_states row-major, A[i*n+j] = P(j | i)
  std::vector<GaussianEmission> emission;  // n_states
  double log_prior = 0.0;                  // log P(class), from the training counts
};

// A left-right chain of n states, starting in state 0: each state stays with probability
// `stay` (a mean dwell of 1 / (1 - stay) samples) and moves on by 1..band states with equal shares
// of the rest, (1 - stay) / reach, reach = min(band, n - 1 - i); the last state absorbs. The
// name, the emissions and the prior are left for the caller (tests, benchmarks, fixtures).
ClassHmm left_right_chain(int n_states, double stay, int band = 1);

struct OutcomeModel {
  // Creation metadata: which tool made the file, when, from what, and how the training went.
  std::string tool_version;      // e.g. "dressguard 0.1.0"
  std::string created;           // UTC ISO-8601, e.g. "2026-11-21T23:59:00Z"
  std::string source_dataset;    // the dataset path or a description
  std::string training_summary;  // free text: sequences, iterations, log-likelihoods per class

  FeatureConvention features;
  std::vector<ClassHmm> classes;  // 1..kMaxClasses, unique non-empty names

  // The predictor's StopPolicy defaults: stop when P(stop class | samples) > stop_threshold for
  // stop_consecutive samples in a row. The stop class is "caught" when present.
  double stop_threshold = 0.9;
  int stop_consecutive = 5;

  // The training conditions (format version 3), so that a predictor running at another sensor
  // rate can refuse the model and a pull faster or slower than any it was trained on can be
  // noticed. 0 = unknown: what a version 1 or 2 file reads as. The period is known or not on its
  // own; the speed range is known as a pair (both 0 or both set).
  double sample_period_s = 0.0;  // the training sequences' sample period [s], in (0, 1]
  double speed_min_m_s = 0.0;    // the slowest training pull [m/s], 0 < min <= max <= 2
  double speed_max_m_s = 0.0;    // the fastest training pull [m/s]
  bool knows_period() const noexcept { return sample_period_s != 0.0; }
  bool knows_speeds() const noexcept { return speed_min_m_s != 0.0 || speed_max_m_s != 0.0; }

  int class_index(std::string_view name) const;  // -1 if absent
};

// A model file that cannot be read or is not valid; the message names the file and the problem.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The largest file read_model reads: 1 MiB. The largest valid file is 866,564 bytes (version 3, 8
// classes of 32 states, the four metadata strings and eight class names each at the 65,536-byte
// limit; dgm.cpp checks the sum at compile time), so no valid model is refused, and a wrong file
// costs at most this much memory and time to refuse.
inline constexpr size_t kMaxFileBytes = size_t{1} << 20;

// Loading checks everything FORMAT.md lists (magic, version, size, CRC-32, bounds, finite
// numbers, stochastic rows within kStochasticTolerance, positive-definite covariances). Before
// reading a byte it refuses what is not a regular file (a FIFO would block the predictor until a
// writer came; /dev/zero never ends) and a file larger than kMaxFileBytes, naming the path.
OutcomeModel read_model(const std::filesystem::path& path);
// Validates and encodes `m`, then writes it to a new temporary file beside `path` (fsynced and
// closed, each checked), renames that onto `path` and fsyncs the folder: a reader sees the old
// file or the new one, never a torn one, and once it returns a crash keeps the new one. A missing
// folder is created. Any failure is a ModelError naming the path and the system's reason; it
// removes the temporary file and leaves an existing model at `path` as it was.
void write_model(const std::filesystem::path& path, const OutcomeModel& m);
// The file's bytes; throws ModelError if `m` is not valid (the same checks as loading).
std::vector<uint8_t> encode_model(const OutcomeModel& m);
// Parses and validates bytes; `source_name` names them in error messages (e.g. the file path).
OutcomeModel decode_model(const uint8_t* data, size_t size, const std::string& source_name);
// Human-readable description (what `dressguard model show` prints).
std::string describe_model(const OutcomeModel& m);
// Throws ModelError naming `source_name` and the first problem of `m` (used by encode/decode).
void validate_model(const OutcomeModel& m, const std::string& source_name);

// A probability vector (the initial distribution, a transition row) is accepted when every
// entry is in [0, 1] and |sum - 1| <= kStochasticTolerance.
inline constexpr double kStochasticTolerance = 1e-9;

// The file format's identity (FORMAT.md).
inline constexpr char kMagic[8] = {'D', 'G', 'M', 'O', 'D', 'E', 'L', '\0'};
// Version 2 (2026-11-23) only adds the axis value kAxisNone; the writer writes version 1 for a
// model without it, so that readers of version 1 still read every model they can understand.
// Version 3 (2026-12-07) adds the training conditions (sample period, speed range); the writer
// writes it only when one of them is known, so a model read from an older file re-writes to the
// same bytes.
inline constexpr uint32_t kFormatVersion = 3;
// 3 when a training condition is known, else 2 when a feature is kAxisNone, else 1.
uint32_t format_version_of(const OutcomeModel& m) noexcept;
// The largest relative difference between two nominal sample periods (a model's, a config's) that
// counts as the same rate.
inline constexpr double kPeriodTolerance = 1e-6;
// Whether two sample periods agree within `tolerance` relative to the larger (measured periods of
// recordings take a looser one: offline/core/haptic.h, kRecordingPeriodTolerance).
bool same_period(double a_s, double b_s, double tolerance = kPeriodTolerance) noexcept;

// CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320, init and final xor 0xFFFFFFFF), the one
// zlib and PNG use: crc32("123456789") == 0xCBF43926.
uint32_t crc32(const uint8_t* data, size_t size) noexcept;

}  // namespace dressguard::model
