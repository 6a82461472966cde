// A minimal JSON value, parser and writer for the calibration file and progress lines.
//
// Only what dg_calib writes: objects, arrays, strings (with \" \\ \n \t \uXXXX for ASCII),
// numbers, true/false/null. Numbers are written with 17 significant digits, so a value read back
// is the same double. Parse errors throw InputError naming the file and line; among them a
// number not spelt as JSON spells it (nan, inf, hex, a leading '+') or beyond a double's range,
// a \u without four hex digits, and arrays and objects nested more than 256 deep.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace dressguard::calib {

// What a typed accessor (number(), at(), ...) throws: what was wrong, and the line of the source
// text where the value it was asked of begins (0 for a value built in code), so that a reader of
// a file can name the file and the line (throw_input_error).
class JsonError : public std::runtime_error {
 public:
  JsonError(const std::string& what, long line) : std::runtime_error(what), line_(line) {}
  long line() const { return line_; }

 private:
  long line_;
};

class Json {
 public:
  enum class Type { Null, Bool, Number, String, Array, Object };
  Json() = default;
  Json(double v) : type_(Type::Number), num_(v) {}  // NOLINT: implicit on purpose
  Json(int v) : type_(Type::Number), num_(v) {}
  Json(long v) : type_(Type::Number), num_(static_cast<double>(v)) {}
  Json(bool v) : type_(Type::Bool), bool_(v) {}
  Json(const char* s) : type_(Type::String), str_(s) {}
  Json(std::string s) : type_(Type::String), str_(std::move(s)) {}
  static Json array() { Json j; j.type_ = Type::Array; return j; }
  static Json object() { Json j; j.type_ = Type::Object; return j; }

  Type type() const { return type_; }
  bool is_number() const { return type_ == Type::Number; }
  // Accessors throw std::runtime_error naming the expected type.
  double number() const;
  const std::string& string() const;
  bool boolean() const;
  const std::vector<Json>& items() const;
  const std::vector<std::pair<std::string, Json>>& members() const;
  bool has(const std::string& key) const;
  const Json& at(const std::string& key) const;  // throws naming the missing key
  // The line of the parsed text where this value begins; 0 for one built in code.
  long line() const { return line_; }
  Json& from_line(long line) {  // the parser's
    line_ = line;
    return *this;
  }
  // Building.
  Json& push(Json v);
  Json& set(const std::string& key, Json v);  // replaces an existing key, keeps insertion order

  std::string dump(int indent = 2) const;
  static Json parse(const std::string& text, const std::filesystem::path& source = "<json>");

 private:
  void dump_to(std::string& out, int indent, int depth) const;
  Type type_ = Type::Null;
  double num_ = 0;
  bool bool_ = false;
  std::string str_;
  std::vector<Json> arr_;
  std::vector<std::pair<std::string, Json>> obj_;
  long line_ = 0;
  [[noreturn]] void wrong_type(const char* expected) const;
};

}  // namespace dressguard::calib
