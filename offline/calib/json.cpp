// Minimal JSON, see json.h.
#include "json.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "files.h"

namespace dressguard::calib {

void Json::wrong_type(const char* expected) const {
  static constexpr const char* kNames[] = {"null", "true or false", "a number", "a string", "an array", "an object"};
  const int t = static_cast<int>(type_);
  throw JsonError(std::string("json: expected ") + expected + ", found " +
                      (t >= 0 && t < 6 ? kNames[t] : "another value"),
                  line_);
}
double Json::number() const {
  if (type_ != Type::Number) wrong_type("a number");
  return num_;
}
const std::string& Json::string() const {
  if (type_ != Type::String) wrong_type("a string");
  return str_;
}
bool Json::boolean() const {
  if (type_ != Type::Bool) wrong_type("true or false");
  return bool_;
}
const std::vector<Json>& Json::items() const {
  if (type_ != Type::Array) wrong_type("an array");
  return arr_;
}
const std::vector<std::pair<std::string, Json>>& Json::members() const {
  if (type_ != Type::Object) wrong_type("an object");
  return obj_;
}
bool Json::has(const std::string& key) const {
  if (type_ != Type::Object) return false;
  for (const auto& [k, v] : obj_)
    if (k == key) return true;
  return false;
}
const Json& Json::at(const std::string& key) const {
  for (const auto& [k, v] : members())
    if (k == key) return v;
  throw JsonError("json: missing key \"" + key + "\" in the object", line_);
}
Json& Json::push(Json v) {
  if (type_ != Type::Array) throw std::runtime_error("json: push on a non-array");
  arr_.push_back(std::move(v));
  return arr_.back();
}
Json& Json::set(const std::string& key, Json v) {
  if (type_ != Type::Object) throw std::runtime_error("json: set on a non-object");
  for (auto& [k, old] : obj_)
    if (k == key) return old = std::move(v);
  obj_.emplace_back(key, std::move(v));
  return obj_.back().second;
}

namespace {
void escape(std::string& out, const std::string& s) {
  out += '"';
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  out += '"';
}
}  // namespace

void Json::dump_to(std::string& out, int indent, int depth) const {
  auto newline = [&](int d) {
    if (indent <= 0) return;
    out += '\n';
    out.append(static_cast<std::size_t>(indent * d), ' ');
  };
  switch (type_) {
    case Type::Null: out += "null"; break;
    case Type::Bool: out += bool_ ? "true" : "false"; break;
    case Type::Number: {
      if (!std::isfinite(num_)) {
        out += "null";  // JSON has no inf/NaN
        break;
      }
      char buf[40];
      std::snprintf(buf, sizeof buf, "%.17g", num_);
      out += buf;
      break;
    }
    case Type::String: escape(out, str_); break;
    case Type::Array: {
      // Arrays of numbers stay on one line (curves, parameter vectors).
      bool flat = true;
      for (const auto& v : arr_) flat = flat && (v.type_ != Type::Array && v.type_ != Type::Object);
      out += '[';
      for (std::size_t i = 0; i < arr_.size(); ++i) {
        if (i) out += flat ? ", " : ",";
        if (!flat) newline(depth + 1);
        arr_[i].dump_to(out, indent, depth + 1);
      }
      if (!flat && !arr_.empty()) newline(depth);
      out += ']';
      break;
    }
    case Type::Object: {
      out += '{';
      for (std::size_t i = 0; i < obj_.size(); ++i) {
        if (i) out += ',';
        newline(depth + 1);
        escape(out, obj_[i].first);
        out += indent > 0 ? ": " : ":";
        obj_[i].second.dump_to(out, indent, depth + 1);
      }
      if (!obj_.empty()) newline(depth);
      out += '}';
      break;
    }
  }
}

std::string Json::dump(int indent) const {
  std::string out;
  dump_to(out, indent, 0);
  return out;
}

namespace {
struct Parser {
  const std::string& s;
  const std::filesystem::path& source;
  std::size_t i = 0;

  [[noreturn]] void fail(const std::string& what) const {
    long line = 1;
    for (std::size_t k = 0; k < i && k < s.size(); ++k) line += s[k] == '\n';
    throw_input_error(source, line, "JSON: " + what);
  }
  void ws() {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\n' || s[i] == '\t' || s[i] == '\r')) ++i;
  }
  bool eat(char c) {
    ws();
    if (i < s.size() && s[i] == c) {
      ++i;
      return true;
    }
    return false;
  }
  void expect(char c) {
    if (!eat(c)) fail(std::string("expected '") + c + "'");
  }
  std::string str() {
    expect('"');
    std::string out;
    while (i < s.size() && s[i] != '"') {
      char c = s[i++];
      if (c == '\\') {
        if (i >= s.size()) fail("unterminated escape");
        char e = s[i++];
        switch (e) {
          case 'n': out += '\n'; break;
          case 't': out += '\t'; break;
          case 'r': out += '\r'; break;
          case 'b': out += '\b'; break;
          case 'f': out += '\f'; break;
          case 'u': {
            // Exactly four hex digits (strtol alone took "00zz" as 0).
            if (i + 4 > s.size() || !std::all_of(s.begin() + static_cast<long>(i), s.begin() + static_cast<long>(i) + 4,
                                                 [](char h) { return std::isxdigit(static_cast<unsigned char>(h)); }))
              fail("\\u needs four hex digits");
            const long code = std::strtol(s.substr(i, 4).c_str(), nullptr, 16);
            i += 4;
            if (code > 0x7f) fail("non-ASCII \\u escape not supported");
            out += static_cast<char>(code);
            break;
          }
          default: out += e;
        }
      } else {
        out += c;
      }
    }
    if (i >= s.size()) fail("unterminated string");
    ++i;
    return out;
  }
  // A number as JSON spells it (RFC 8259, section 6): -? (0 | [1-9][0-9]*) (.[0-9]+)? ([eE][+-]?[0-9]+)?
  // and within a double's range. strtod alone also took nan, inf, hex and a leading '+' (a NaN arm
  // offset passed read_calibration: session 84's review, finding 4), and made 1e999 infinite.
  Json number() {
    const std::size_t from = i;
    auto digits = [&] {
      const std::size_t d = i;
      while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
      return i > d;
    };
    if (i < s.size() && s[i] == '-') ++i;
    if (i < s.size() && s[i] == '0') ++i;
    else if (!(i < s.size() && s[i] >= '1' && s[i] <= '9' && digits())) {
      i = from;
      fail(std::string("unexpected character '") + s[i] + "'");
    }
    if (i < s.size() && s[i] == '.') {
      ++i;
      if (!digits()) fail("a digit must follow the decimal point");
    }
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
      ++i;
      if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
      if (!digits()) fail("a digit must follow the exponent's 'e'");
    }
    const double v = std::strtod(s.substr(from, i - from).c_str(), nullptr);
    if (!std::isfinite(v)) fail("number " + s.substr(from, i - from) + " is beyond a double's range");
    return Json(v);
  }
  // Arrays and objects nest at most this deep: each level is a frame of value()'s recursion,
  // and 200000 '[' overflowed the stack (SIGSEGV) instead of naming the file (finding 7). A
  // calibration file nests 6 deep (provenance "rescored").
  static constexpr int kMaxDepth = 256;
  int depth = 0;
  // The line of position `pos`, counted on from the last position asked (values are met in order).
  std::size_t scanned = 0;
  long line = 1;
  long line_of(std::size_t pos) {
    for (; scanned < pos && scanned < s.size(); ++scanned) line += s[scanned] == '\n';
    return line;
  }
  // A value, which remembers the line it begins on (Json::line, for the accessors' errors).
  Json value() {
    ws();
    const long at = line_of(i);
    Json v = value_here();
    v.from_line(at);
    return v;
  }
  Json value_here() {
    ws();
    if (i >= s.size()) fail("unexpected end");
    const char c = s[i];
    if ((c == '{' || c == '[') && depth == kMaxDepth)
      fail("arrays and objects nested deeper than " + std::to_string(kMaxDepth));
    if (c == '{') {
      ++i;
      ++depth;
      Json o = Json::object();
      if (!eat('}')) {
        do {
          ws();
          std::string k = str();
          expect(':');
          o.set(k, value());
        } while (eat(','));
        expect('}');
      }
      --depth;
      return o;
    }
    if (c == '[') {
      ++i;
      ++depth;
      Json a = Json::array();
      if (!eat(']')) {
        do a.push(value());
        while (eat(','));
        expect(']');
      }
      --depth;
      return a;
    }
    if (c == '"') return Json(str());
    if (s.compare(i, 4, "true") == 0) { i += 4; return Json(true); }
    if (s.compare(i, 5, "false") == 0) { i += 5; return Json(false); }
    if (s.compare(i, 4, "null") == 0) { i += 4; return Json(); }
    return number();
  }
};
}  // namespace

Json Json::parse(const std::string& text, const std::filesystem::path& source) {
  Parser p{text, source};
  Json v = p.value();
  p.ws();
  if (p.i != text.size()) p.fail("trailing characters after the value");
  return v;
}

}  // namespace dressguard::calib
