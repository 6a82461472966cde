// The calibration file's JSON reader (offline/calib/json.h): numbers only as JSON spells them,
// a nesting limit instead of a stack overflow, \u escapes of exactly four hex digits; each
// refusal an InputError that names the file and the line.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <utility>

#include <string>

#include "files.h"
#include "json.h"

namespace dressguard::calib {
namespace {

// The error Json::parse gives `text` read from "x.json", or "" when it parses.
std::string error_of(const std::string& text) {
  try {
    Json::parse(text, "x.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// strtod took nan, inf, hex and a leading '+' (a NaN arm offset passed read_calibration, and the
// summary it led to had a bare nan that Python's json cannot read), and 1e999 as infinity.
TEST(Json, NumbersAreJsonNumbers) {
  for (const char* bad : {"nan", "NaN", "-nan", "inf", "-inf", "Infinity", "0x10", "+1", "1.", ".5", "01", "-", "1e",
                          "1e+", "--1", "1e999", "-1e999"}) {
    const std::string text = std::string("{\"a\":\n[1, ") + bad + "]}";
    EXPECT_NE(error_of(text).find("x.json:2: JSON: "), std::string::npos) << bad << ": " << error_of(text);
  }
  const Json j = Json::parse("[0, -0, 12, -3.25, 1.5e-3, 2E+2, 7e0, 1e308, 4.9e-324]");
  const std::vector<double> want = {0, -0.0, 12, -3.25, 1.5e-3, 200, 7, 1e308, 4.9e-324};
  ASSERT_EQ(j.items().size(), want.size());
  for (std::size_t k = 0; k < want.size(); ++k) EXPECT_EQ(j.items()[k].number(), want[k]) << k;
  EXPECT_TRUE(std::signbit(j.items()[1].number())) << "-0 read as +0 (EXPECT_EQ cannot tell them apart)";
  EXPECT_FALSE(std::signbit(j.items()[0].number()));
  // An accessor's error says what it found and the line its value begins on (JsonError), for a
  // reader to name the file and line; a value built in code has line 0.
  const Json doc = Json::parse("{\n  \"a\": 1,\n  \"b\":\n    \"text\",\n  \"c\": [true]\n}\n");
  const auto error = [](const std::function<void()>& f) -> std::pair<std::string, long> {
    try {
      f();
    } catch (const JsonError& e) {
      return {e.what(), e.line()};
    }
    return {"accepted", -1};
  };
  EXPECT_EQ(error([&] { doc.at("b").number(); }), std::make_pair(std::string("json: expected a number, found a string"), 4L));
  EXPECT_EQ(error([&] { doc.at("c").items()[0].string(); }).second, 5L);
  EXPECT_EQ(error([&] { doc.at("z"); }), std::make_pair(std::string("json: missing key \"z\" in the object"), 1L));
  EXPECT_EQ(error([] { Json(1.0).string(); }).second, 0L);
  EXPECT_EQ(doc.at("a").line(), 2L);
  // What dump() writes reads back to the same double (17 significant digits).
  const double third = 1.0 / 3.0;
  EXPECT_EQ(Json::parse(Json(third).dump()).number(), third);
}

// 200000 '[' overflowed value()'s recursion (SIGSEGV, exit 139) instead of naming the file.
TEST(Json, NestingIsLimited) {
  EXPECT_NE(error_of("\n" + std::string(200000, '[')).find("x.json:2: JSON: arrays and objects nested deeper than 256"),
            std::string::npos);
  EXPECT_EQ(error_of(std::string(256, '[') + std::string(256, ']')), "");
  EXPECT_NE(error_of(std::string(257, '[') + std::string(257, ']')).find("nested deeper"), std::string::npos);
  // Objects count alike, and so do both mixed.
  auto objects = [](int depth) {
    std::string text;
    for (int k = 0; k < depth; ++k) text += k % 2 ? "[" : "{\"a\": ";
    text += "1";
    for (int k = depth - 1; k >= 0; --k) text += k % 2 ? "]" : "}";
    return text;
  };
  EXPECT_EQ(error_of(objects(256)), "");
  EXPECT_NE(error_of(objects(257)).find("nested deeper than 256"), std::string::npos);
  EXPECT_NE(error_of(objects(100000)).find("nested deeper than 256"), std::string::npos);
}

// \u takes exactly four hex digits: strtol without an end check took "00zz" as 0.
TEST(Json, UnicodeEscapesTakeFourHexDigits) {
  EXPECT_EQ(Json::parse("\"\\u0041\\u006a\"").string(), "Aj");
  for (const char* bad : {"\"\\u00zz\"", "\"\\u12\"", "\"\\u004\"", "\"\\u-041\"", "\"\\u 041\""})
    EXPECT_NE(error_of(bad).find("x.json:1: JSON: \\u needs four hex digits"), std::string::npos)
        << bad << ": " << error_of(bad);
}

}  // namespace
}  // namespace dressguard::calib
