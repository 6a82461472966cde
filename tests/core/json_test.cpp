// json_string (offline/core/json.h): what every --json summary's text goes through. JSON is
// UTF-8 (RFC 8259, section 8.1) and holds no raw control character in a string (section 7); the
// text it carries (paths, trial ids, class names) may be any bytes but NUL.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>

#include "json.h"
#include "utf8.h"

using dressguard::json_string;
using dressguard::model::invalid_utf8_at;

namespace {

const std::string kReplacement = "\xEF\xBF\xBD";  // U+FFFD in UTF-8

TEST(JsonString, EscapesQuotesBackslashesAndControlCharacters) {
  EXPECT_EQ(json_string(""), "\"\"");
  EXPECT_EQ(json_string("s4-good-3"), "\"s4-good-3\"");
  EXPECT_EQ(json_string("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(json_string("a\tb\nc\x1f"), "\"a\\u0009b\\u000ac\\u001f\"");
  EXPECT_EQ(json_string("\x7f"), "\"\x7f\"");  // DEL is no control character to JSON
}

TEST(JsonString, KeepsUtf8AndReplacesEachByteThatIsNot) {
  EXPECT_EQ(json_string("caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80"), "\"caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80\"");
  EXPECT_EQ(json_string("a\xff" "b"), "\"a" + kReplacement + "b\"");
  EXPECT_EQ(json_string("\xc0\xaf"), "\"" + kReplacement + kReplacement + "\"");      // overlong '/'
  EXPECT_EQ(json_string("\xe2\x82"), "\"" + kReplacement + kReplacement + "\"");      // cut short
  EXPECT_EQ(json_string("\xed\xa0\x80"), "\"" + kReplacement + kReplacement + kReplacement + "\"");  // U+D800
  EXPECT_EQ(json_string("\xc3\""), "\"" + kReplacement + "\\\"\"");  // a lead whose next byte is a quote
}

// Any bytes in, well-formed UTF-8 with no raw control character out; and text that is UTF-8
// without quotes, backslashes or controls comes out as it went in, between the quotes.
TEST(JsonString, AnyBytesGiveUtf8WithoutControls) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> byte(1, 255), length(0, 24);
  int kept = 0;
  for (int k = 0; k < 20000; ++k) {
    std::string s(static_cast<size_t>(length(rng)), ' ');
    for (char& c : s) c = static_cast<char>(byte(rng));
    const std::string j = json_string(s);
    ASSERT_EQ(invalid_utf8_at(j), std::string::npos) << k;
    for (char c : j) ASSERT_GE(static_cast<unsigned char>(c), 0x20u) << k;
    bool plain = invalid_utf8_at(s) == std::string::npos;
    for (char c : s) plain = plain && c != '"' && c != '\\' && static_cast<unsigned char>(c) >= 0x20;
    if (plain) {
      EXPECT_EQ(j, "\"" + s + "\"") << k;
      ++kept;
    }
  }
  EXPECT_GT(kept, 100);  // the second half was tried on more than a handful of strings
}

}  // namespace
