// candump log lines: "(sec.usec) iface id#data".
#include "candump_log.h"

#include <cstdio>
#include <stdexcept>

namespace dressguard::protocol {
namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

const char* interface_name_error(std::string_view name) {
  if (name.empty()) return "expected an interface name";
  if (name.size() > kMaxInterfaceName) return "interface name longer than 15 characters (IFNAMSIZ)";
  for (const char c : name)
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f')
      return "interface name has whitespace in it";
  return nullptr;
}

std::string format_candump_line(int64_t time_us, std::string_view iface, const Frame& f) {
  // The timestamp and the frame in fixed buffers of known size; the interface name as given.
  char ts[48];
  const int nt = std::snprintf(ts, sizeof ts, "(%lld.%06lld) ", static_cast<long long>(time_us / 1000000),
                               static_cast<long long>(time_us % 1000000));
  char fr[1 + 8 + 1 + 16 + 1];
  int nf = is_error_frame(f) ? std::snprintf(fr, sizeof fr, " %08X#", static_cast<unsigned>(f.id & (kCanErrFlag | kCanErrMask)))
                             : std::snprintf(fr, sizeof fr, " %03X#", static_cast<unsigned>(f.id & 0x7FF));
  for (int i = 0; i < f.len && i < 8; ++i) nf += std::snprintf(fr + nf, sizeof fr - nf, "%02X", f.data[i]);
  std::string line(ts, nt);
  line.append(iface);
  line.append(fr, nf);
  return line;
}

bool parse_candump_line(std::string_view line, LoggedFrame& out, std::string& why) {
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\n')) line.remove_suffix(1);
  if (line.size() < 3 || line[0] != '(') return why = "expected '(' starting a timestamp", false;
  const size_t close = line.find(')');
  if (close == std::string_view::npos) return why = "timestamp has no ')'", false;
  const std::string_view ts = line.substr(1, close - 1);
  const size_t dot = ts.find('.');
  if (dot == std::string_view::npos || dot == 0 || ts.size() - dot - 1 != 6)
    return why = "timestamp is not seconds.microseconds (6 digits)", false;
  // Nanoseconds since the epoch must fit an int64_t (a replay counts in them): up to 9.2e9 s,
  // the year 2262. 10 digits of seconds, then the value.
  if (dot > 10) return why = "timestamp has more than 10 digits of seconds", false;
  int64_t sec = 0, usec = 0;
  for (size_t i = 0; i < ts.size(); ++i) {
    if (i == dot) continue;
    if (ts[i] < '0' || ts[i] > '9') return why = "timestamp has a non-digit", false;
    (i < dot ? sec : usec) = (i < dot ? sec : usec) * 10 + (ts[i] - '0');
  }
  std::string_view rest = line.substr(close + 1);
  if (rest.empty() || rest[0] != ' ') return why = "expected a space after the timestamp", false;
  // candump -l on several interfaces pads each name to the longest ("%*s"): one or more spaces.
  while (!rest.empty() && rest[0] == ' ') rest.remove_prefix(1);
  const size_t sp = rest.find(' ');
  if (sp == std::string_view::npos) return why = "expected an interface name and a frame", false;
  if (const char* bad = interface_name_error(rest.substr(0, sp))) return why = bad, false;
  out.iface = std::string(rest.substr(0, sp));
  std::string_view fr = rest.substr(sp + 1);
  // candump -x appends the direction, " R" (received) or " T" (sent by this host): both are
  // frames on the bus, and the reader takes them alike. Anything else after the frame is not a
  // candump line.
  if (const size_t end = fr.find(' '); end != std::string_view::npos) {
    const std::string_view extra = fr.substr(end);
    if (extra != " R" && extra != " T")
      return why = "unexpected text after the frame (only candump -x's direction, R or T)", false;
    fr = fr.substr(0, end);
  }
  const size_t hash = fr.find('#');
  if (hash == std::string_view::npos) return why = "frame has no '#'", false;
  uint32_t id = 0;
  for (size_t i = 0; i < hash; ++i) {
    if (i == 8) return why = "identifier is not 3 hex digits (only classic 11-bit frames)", false;
    const int v = hex_value(fr[i]);
    if (v < 0) return why = "identifier is not hex", false;
    id = id * 16 + static_cast<uint32_t>(v);
  }
  // 8 digits: can-utils' 29-bit identifier, or with CAN_ERR_FLAG (0x20000000) an error frame,
  // which candump logs when error frames are subscribed (-e, or an error mask in a filter).
  const bool error_frame = hash == 8 && (id & kCanErrFlag);
  if (error_frame && id > (kCanErrFlag | kCanErrMask))
    return why = "error frame's identifier has bits above CAN_ERR_FLAG (candump never writes them)", false;
  if (hash == 8 && !error_frame)
    return why = "extended (29-bit) identifier not supported (only classic 11-bit frames)", false;
  if (hash != 3 && !error_frame) return why = "identifier is not 3 hex digits (only classic 11-bit frames)", false;
  if (!error_frame && id > 0x7FF) return why = "identifier above 0x7FF", false;
  std::string_view hex = fr.substr(hash + 1);
  // candump -8 (--len8-dlc) writes a classic frame of 8 bytes whose raw DLC is 9..15 as
  // "data_D" (one hex digit, can-utils' lib.c): still 8 data bytes, can_frame.len 8 (the raw
  // DLC is in len8_dlc, which the predictor does not read), so it is dropped, as the direction is.
  if (const size_t u = hex.find('_'); u != std::string_view::npos) {
    if (u != 16) return why = "raw DLC suffix (candump -8's _D) after other than 8 data bytes", false;
    const int dlc = hex.size() == 18 ? hex_value(hex[17]) : -1;
    if (dlc < 9) return why = "raw DLC suffix is not one hex digit 9..F (candump -8's _D)", false;
    hex = hex.substr(0, 16);
  }
  if (!hex.empty() && hex[0] == '#') return why = "CAN FD frame (##) not supported (only classic frames)", false;
  if (!hex.empty() && (hex[0] == 'R' || hex[0] == 'r'))
    return why = "remote frame (RTR) not supported: the protocol has none", false;
  if (hex.size() % 2 != 0 || hex.size() > 16) return why = "data is not 0..8 bytes of hex", false;
  Frame f;
  f.id = id;
  f.len = static_cast<uint8_t>(hex.size() / 2);
  for (size_t i = 0; i < f.len; ++i) {
    const int hi = hex_value(hex[2 * i]), lo = hex_value(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) return why = "data is not hex", false;
    f.data[i] = static_cast<uint8_t>(hi * 16 + lo);
  }
  if (sec > kMaxLogSeconds) return why = "timestamp beyond 9000000000 s (the year 2255): its nanoseconds would overflow", false;
  out.time_us = sec * 1000000 + usec;
  out.frame = f;
  return true;
}

std::vector<LoggedFrame> parse_candump_log(std::string_view text, const std::string& name) {
  std::vector<LoggedFrame> frames;
  long line_no = 0;
  size_t pos = 0;
  long first_skipped = 0;  // the first line with text that is not a frame line
  std::string why;
  while (pos < text.size()) {
    size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    std::string_view line = text.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    // canplayer skips every line that does not begin with '(': comments, candump -d's
    // "DROPCOUNT:" notes (what they report shows up here as lost frames anyway), blank lines.
    if (line.empty() || line[0] != '(') {
      if (!first_skipped && line.find_first_not_of(" \t\r") != std::string_view::npos) first_skipped = line_no;
      continue;
    }
    LoggedFrame lf;
    if (!parse_candump_line(line, lf, why)) throw std::runtime_error(name + ":" + std::to_string(line_no) + ": " + why);
    if (!frames.empty() && lf.time_us < frames.back().time_us) {
      char back[64];
      std::snprintf(back, sizeof back, "%.6f", (frames.back().time_us - lf.time_us) * 1e-6);
      throw std::runtime_error(name + ":" + std::to_string(line_no) + ": time goes back " + back + " s from line " +
                               std::to_string(frames.back().line) + " (a clock step?): a log is read in time order");
    }
    lf.line = line_no;
    frames.push_back(std::move(lf));
  }
  // Text without a single frame line is no log at all (candump without -l, say): not an empty one.
  if (frames.empty() && first_skipped)
    throw std::runtime_error(name + ":" + std::to_string(first_skipped) +
                             ": not a candump -l log: no line starts with '(' and a timestamp");
  return frames;
}

}  // namespace dressguard::protocol
