// JSON values for the commands' --json summaries, which carry user text (paths, ids) that may
// hold a '"', a '\' or a control character.
#pragma once

#include <string>
#include <string_view>

namespace dressguard {

// A JSON string literal (quotes included): '"' and '\' escaped, control characters as \u00XX,
// well-formed UTF-8 as it is, and each byte that begins no well-formed UTF-8 sequence (a path
// may hold any byte but NUL; models/utf8.h) as U+FFFD, so that the text is UTF-8 as JSON must be
// (RFC 8259, section 8.1) and a JSON reader takes it. Such a path is then shown, not given back.
std::string json_string(std::string_view s);
// A JSON number; non-finite values become null (JSON has no NaN).
std::string json_number(double v);

}  // namespace dressguard
