// libFuzzer target for the .dgm loader (models/dgm.cpp), built with clang's
// -fsanitize=fuzzer,address,undefined. The first input byte chooses a mode:
//   bit 0 clear: the rest is fed to decode_model as is (mostly rejected by the CRC: tests the
//                header, size and CRC checks);
//   bit 0 set:   the size field and the CRC are repaired first, so mutations reach the field
//                parser and the semantic checks.
// Every accepted input must re-encode to its own bytes (FORMAT.md, Versioning: every file the
// loader accepts re-writes to its own bytes), be describable, and drive a ForwardFilter for a few
// samples without fault.
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "dgm.h"
#include "forward_filter.h"

using namespace dressguard;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  std::vector<uint8_t> buf(data + 1, data + size);
  if ((data[0] & 1) && buf.size() >= 20) {
    const uint32_t n = static_cast<uint32_t>(buf.size());
    for (int i = 0; i < 4; ++i) buf[12 + i] = static_cast<uint8_t>(n >> (8 * i));
    const uint32_t c = model::crc32(buf.data(), buf.size() - 4);
    for (int i = 0; i < 4; ++i) buf[buf.size() - 4 + i] = static_cast<uint8_t>(c >> (8 * i));
  }
  model::OutcomeModel m;
  try {
    m = model::decode_model(buf.data(), buf.size(), "fuzz");
  } catch (const model::ModelError&) {
    return 0;  // rejected with a message: the expected outcome for almost every input
  }
  const std::vector<uint8_t> again = model::encode_model(m);
  if (again != buf) std::abort();  // an accepted file that would re-write to other bytes
  const model::OutcomeModel m2 = model::decode_model(again.data(), again.size(), "re-encoded");
  (void)model::describe_model(m2);
  filter::ForwardFilter f(m2);
  const double samples[4][3] = {{-3.0, 0.1, 0.5}, {0.0, 0.0, 0.0}, {1e6, -1e6, 1e6}, {-1.5, 0.0, -2.0}};
  for (const auto& s : samples) f.step(s[0], s[1], s[2]);
  volatile double sink = f.posterior(0) + f.log_likelihood(f.classes() - 1);
  (void)sink;
  return 0;
}
