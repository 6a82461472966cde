// JSON values for the commands' --json summaries, which carry user text (paths, ids) that may
// hold a '"', a '\' or a control character.
#pragma once

#include <string>
#include <string_view>

namespace dressguard {

// A JSON string literal (quotes included): '"' and '\' escaped, control characters as \u00XX.
std::string json_string(std::string_view s);
// A JSON number; non-finite values become null (JSON has no NaN).
std::string json_number(double v);

}  // namespace dressguard
