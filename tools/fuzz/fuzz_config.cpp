// libFuzzer target for the predictor's configuration file (parse_predictor_config,
// predictor/core/predictor_core.h): the text of /etc/dressguard-predictor.conf or of --set, under
// -fsanitize=fuzzer,address,undefined. Rules:
//
//   errors   a file that does not parse throws std::runtime_error "NAME:LINE: what", LINE a
//            line of the text, and nothing else escapes;
//   ranges   a file that parses gives a configuration inside the documented ranges: threshold
//            in (0, 1) or the model's, k in [1, 1e6] or the model's, the hard limit in
//            [0.01, 1000] N, every period and deadline in (0, 600] s, the budget in [0, 1e6],
//            the weight in [1, 1e6], the E2E delta in [1, 127], the mounting a signed
//            permutation of the sensor's axes with biases within 1000 N;
//   others   with `others` given, every key the parser does not own comes back, with its line.
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "predictor_core.h"
#include "traffic.h"

using namespace dressguard;
using fuzz::broken;

namespace {

bool in(double v, double lo, double hi) { return v >= lo && v <= hi; }
bool period(int64_t ns) { return ns > 0 && ns <= 600'000'000'000LL; }

void check_ranges(const predictor::PredictorConfig& c) {
  if (!(c.stop_threshold == -1.0 || (c.stop_threshold > 0.0 && c.stop_threshold < 1.0))) broken("stop_threshold out of range", 0);
  if (!(c.stop_consecutive == 0 || in(c.stop_consecutive, 1, 1e6))) broken("stop_consecutive out of range", 0);
  if (!in(c.hard_limit_n, 0.01, 1000.0)) broken("hard_limit_n out of range", 0);
  if (!period(c.sensor_timeout_ns) || !period(c.status_period_ns) || !period(c.heartbeat_period_ns) ||
      !period(c.posteriors_period_ns) || !period(c.stop_retry_ns))
    broken("a period or deadline out of (0, 600] s", 0);
  if (!(c.sample_period_s > 0.0 && c.sample_period_s <= 600.0) || !in(c.acceleration_m_s2, 0.0, 1000.0))
    broken("sample_period_ms or acceleration_m_s2 out of range", 0);
  if (!in(c.bad_frame_budget, 0, 1e6) || !in(c.bad_frame_weight, 1, 1e6) || !in(c.max_delta_counter, 1, 127))
    broken("the bad-frame budget, its weight or the E2E delta out of range", 0);
  bool used[3] = {false, false, false};
  for (int k = 0; k < 3; ++k) {
    const int a = c.mount.axis[k];
    if (a < 0 || a > 2 || used[a]) broken("mount_axes is not a permutation of x, y, z", 0);
    used[a] = true;
    if (std::fabs(c.mount.sign[k]) != 1.0 || !in(c.mount.bias[k], -1000.0, 1000.0)) broken("a mount sign or bias out of range", 0);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<predictor::ConfigEntry> others;
  try {
    check_ranges(predictor::parse_predictor_config(text, "p.conf", &others));
  } catch (const std::runtime_error& e) {
    fuzz::check_error_names_line(e.what(), "p.conf", text);
    return 0;
  }
  long lines = 1;
  for (char ch : text) lines += ch == '\n';
  for (const auto& o : others)
    if (o.line < 1 || o.line > lines || text.find(o.key) == std::string::npos) broken("a key not owned came back without its line", o.line);
  return 0;
}
