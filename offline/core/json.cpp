#include "json.h"

#include <cmath>
#include <cstdio>

#include "utf8.h"

namespace dressguard {

std::string json_string(std::string_view s) {
  std::string o = "\"";
  for (size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c == '"' || c == '\\') {
      o += '\\';
      o += s[i++];
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      o += buf;
      ++i;
    } else if (const size_t len = model::utf8_sequence_at(s, i); len > 0) {
      o.append(s, i, len);
      i += len;
    } else {
      o += "\xEF\xBF\xBD";  // U+FFFD REPLACEMENT CHARACTER, in place of the byte
      ++i;
    }
  }
  return o + "\"";
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace dressguard
