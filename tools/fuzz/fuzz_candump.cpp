// libFuzzer target for the can-utils log reader (firmware-bridge/protocol/candump_log.h), which
// `dressguard replay` and the tests feed with recorded traffic, under
// -fsanitize=fuzzer,address,undefined. The input is the log's text. Rules:
//
//   errors      a log that does not parse throws std::runtime_error "NAME:LINE: what", LINE a
//               line of the text (1-based), naming what is wrong;
//   round trip  every frame of a log that parses, written back by format_candump_line, parses
//               to the same time, interface, identifier, length and data;
//   lines       a log that parses has one frame per line beginning with '(', in order, and no
//               other: the rest are skipped, as canplayer skips them.
#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "candump_log.h"
#include "traffic.h"

using namespace dressguard;
using fuzz::broken;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<protocol::LoggedFrame> frames;
  try {
    frames = protocol::parse_candump_log(text, "trial.log");
  } catch (const std::runtime_error& e) {
    fuzz::check_error_names_line(e.what(), "trial.log", text);
    return 0;
  }
  long line = 0, k = 0;
  for (size_t pos = 0; pos < text.size(); ++line) {
    const size_t nl = std::min(text.find('\n', pos), text.size());
    if (text[pos] == '(') {
      if (k >= static_cast<long>(frames.size()) || frames[k].line != line + 1)
        broken("a line beginning with '(' is not a frame of the parsed log", line + 1);
      ++k;
    }
    pos = nl + 1;
  }
  if (k != static_cast<long>(frames.size())) broken("a frame of the parsed log from a line not beginning with '('", 0);
  for (const auto& lf : frames) {
    const std::string again = protocol::format_candump_line(lf.time_us, lf.iface, lf.frame);
    protocol::LoggedFrame back;
    std::string why;
    if (!protocol::parse_candump_line(again, back, why)) broken("a parsed frame written back does not parse", lf.line);
    bool same = back.time_us == lf.time_us && back.iface == lf.iface && back.frame.id == lf.frame.id &&
                back.frame.len == lf.frame.len;
    for (int k = 0; k < lf.frame.len; ++k) same = same && back.frame.data[k] == lf.frame.data[k];
    if (!same) broken("a parsed frame written back parses to another frame", lf.line);
  }
  return 0;
}
