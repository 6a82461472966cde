// The candump log format of can-utils (`candump -l`, read by `canplayer` and `log2asc`), in one
// place for every tool of the project that reads or writes it:
//
//   (1700000000.012345) vcan0 100#A5010A00F6FF3200
//   (seconds.microseconds) interface id#data-in-hex
//
// candump writes "(%010lu.%06lu) %*s %s%s": with several interfaces the names are padded to the
// longest, so one or more spaces may come before a name; with -x the line ends in the
// direction, " R" (received) or " T" (sent by the recording host). Both are read, and the
// direction is dropped: either way the frame was on the bus. With -8 an 8-byte frame whose raw
// DLC is 9..15 ends in "_D" (D one hex digit 9..F); it is read as the 8 bytes it carries.
//
// Classic frames (3 hex digits of identifier, 0..8 data bytes) and controller error frames
// (candump -e, or an error mask in a filter: 8 digits with CAN_ERR_FLAG 0x20000000 and the
// CAN_ERR_* class bits, as the socket's can_id carries them; read with that id, so that a
// replay hands them to the predictor as the daemon does: is_error_frame), timestamps of at
// most 10 digits of seconds, interface names of at most 15 characters. What candump writes
// beyond that is refused with its name: 29-bit identifiers (8 digits), remote frames (id#R),
// CAN FD frames (id##flags+data). Host side: allocates.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "dg_protocol.h"

namespace dressguard::protocol {

// Linux interface names are at most IFNAMSIZ - 1 characters; a longer one is not a log line.
inline constexpr size_t kMaxInterfaceName = 15;

// Why `name` cannot be a log line's interface name, or nullptr when it can: 1 to 15 characters
// and no whitespace (a space ends the name in the line, canplayer's "%s" stops at any). The
// reader checks each line's name with it, a writer its name before the first line.
const char* interface_name_error(std::string_view name);

// A controller error frame's identifier: CAN_ERR_FLAG with the CAN_ERR_* class bits below it
// (linux/can/error.h; CAN_ERR_BUSOFF is 0x40).
inline constexpr uint32_t kCanErrFlag = 0x20000000u;
inline constexpr uint32_t kCanErrMask = 0x1FFFFFFFu;
constexpr bool is_error_frame(const Frame& f) { return (f.id & kCanErrFlag) != 0; }
constexpr uint32_t error_class_of(const Frame& f) { return f.id & kCanErrMask; }

struct LoggedFrame {
  int64_t time_us = 0;  // timestamp in microseconds
  std::string iface;
  Frame frame;
  long line = 0;        // 1-based line in the log (0 when built in memory)
};

// "(sec.usec) iface id#data" (no newline; an error frame's id in 8 digits). Writes `iface` as given: a writer that takes the
// name from its user checks it with interface_name_error first.
std::string format_candump_line(int64_t time_us, std::string_view iface, const Frame& f);

// Parses one line; returns false with `why` set when it is not a classic candump frame line.
bool parse_candump_line(std::string_view line, LoggedFrame& out, std::string& why);

// The latest timestamp a line may carry [s] (the year 2255): its nanoseconds fit an int64_t.
inline constexpr int64_t kMaxLogSeconds = 9'000'000'000;

// Whole log text. As canplayer does, lines that do not begin with '(' are skipped (blank lines,
// comments, candump -d's DROPCOUNT notes); a line that does and is not a frame line above
// throws std::runtime_error with "name:line: what" (callers pass the file name for the
// message); so does a timestamp earlier than the line before's (a clock step: candump stamps
// with the wall clock), and text with lines but no frame line at all (not a candump -l log).
std::vector<LoggedFrame> parse_candump_log(std::string_view text, const std::string& name);

}  // namespace dressguard::protocol
