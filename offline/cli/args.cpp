#include "args.h"

#include "files.h"

#include <cstdlib>

#include <charconv>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <sstream>

namespace dressguard::cli {

std::vector<std::string> split_in_order(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::set<std::string> split_list(const std::string& s) {
  const auto items = split_in_order(s);
  return {items.begin(), items.end()};
}

std::vector<std::string> distinct_files(const std::string& option, const std::string& list, const std::string& noun,
                                        const std::string& why_once) {
  std::vector<std::string> given;
  for (const std::string& d : split_in_order(list)) {
    // same_file: one file under two spellings (study, ./study) or through a symlink.
    for (const std::string& before : given)
      if (same_file(before, d))
        throw UsageError("--" + option + " names the " + noun + " " + d + " twice" +
                         (before == d ? "" : " (as " + before + " and " + d + ")") + ": " + why_once);
    given.push_back(d);
  }
  return given;
}

std::vector<std::filesystem::path> dataset_list(const std::string& option, const std::string& list,
                                                const std::string& why_once) {
  const std::vector<std::string> given = distinct_files(option, list, "dataset", why_once);
  if (given.empty()) throw UsageError("--" + option + " names no dataset");
  return {given.begin(), given.end()};
}

std::filesystem::path plot_script(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path rel = fs::path("tools") / "plot" / name;
  if (const char* src = std::getenv("DRESSGUARD_SOURCE_DIR"); src && fs::exists(fs::path(src) / rel))
    return fs::path(src) / rel;
  std::error_code ec;
  for (fs::path p = fs::read_symlink("/proc/self/exe", ec).parent_path(); !ec && p.has_relative_path();
       p = p.parent_path())
    if (fs::exists(p / rel)) return p / rel;
  if (fs::exists(rel)) return fs::absolute(rel);
  return {};
}

namespace {

// One word for the shell, whatever it holds: single-quoted, each ' as '\''.
std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

int run_plot_script(const std::filesystem::path& script, const std::vector<std::string>& args) {
  std::string cmd = "/usr/bin/python3 " + shell_quote(script.string());
  for (const std::string& a : args) cmd += " " + shell_quote(a);
  return std::system(cmd.c_str());
}

void require_known_participants(const std::string& option, const std::set<std::string>& given, const Dataset& ds,
                                const std::string& data) {
  std::set<std::string> known;
  for (const auto& t : ds.trials) known.insert(t.participant);
  std::string unknown, names;
  int n = 0;
  for (const auto& p : given)
    if (!known.count(p)) unknown += (n++ ? ", '" : "'") + p + "'";
  if (n == 0) return;
  for (const auto& p : known) names += (names.empty() ? "" : ", ") + p;
  throw UsageError("--" + option + ": " + data + " has no participant" + (n > 1 ? "s " : " ") + unknown +
                   " (its participants: " + (names.empty() ? "none" : names) + ")");
}

Args::Args(int argc, char** argv, std::set<std::string> flags) {
  for (int i = 0; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--", 0) == 0 && a.size() > 2) {
      std::string name = a.substr(2);
      if (auto eq = name.find('='); eq != std::string::npos) {
        // A switch takes no value: "--json=no" would otherwise switch JSON on.
        if (flags.count(name.substr(0, eq))) throw UsageError("option --" + name.substr(0, eq) + " takes no value");
        values_[name.substr(0, eq)].push_back(name.substr(eq + 1));
      } else if (flags.count(name)) {
        flags_set_.insert(name);
      } else {
        if (i + 1 >= argc) throw UsageError("option --" + name + " needs a value");
        values_[name].push_back(argv[++i]);
      }
    } else {
      positional_.push_back(a);
    }
  }
}

bool Args::has(const std::string& name) const { return flags_set_.count(name) || values_.count(name); }

std::optional<std::string> Args::get(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  if (it->second.size() > 1) {
    throw UsageError("option --" + name + " given " + std::to_string(it->second.size()) + " times ('" +
                     it->second.front() + "', '" + it->second.back() + "'): give it once");
  }
  return it->second.front();
}

std::vector<std::string> Args::all(const std::string& name) const {
  auto it = values_.find(name);
  return it == values_.end() ? std::vector<std::string>{} : it->second;
}

std::string Args::require(const std::string& name) const {
  auto v = get(name);
  if (!v) throw UsageError("missing required option --" + name);
  return *v;
}

std::string Args::require_output_file(const std::string& name) const {
  const std::string path = require(name);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw UsageError("option --" + name + ": '" + path + "' is a folder; give the file to write");
  return path;
}

double Args::number(const std::string& name, double fallback) const {
  auto v = get(name);
  if (!v) return fallback;
  double x = 0;
  auto [p, ec] = std::from_chars(v->data(), v->data() + v->size(), x);
  if (ec != std::errc() || p != v->data() + v->size() || !std::isfinite(x)) {
    throw UsageError("option --" + name + ": not a number: '" + *v + "'");
  }
  return x;
}

long Args::integer(const std::string& name, long fallback, long lo, long hi) const {
  auto v = get(name);
  if (!v) return fallback;
  long x = 0;
  auto [p, ec] = std::from_chars(v->data(), v->data() + v->size(), x);
  if (ec != std::errc() || p != v->data() + v->size()) {
    throw UsageError("option --" + name + ": not an integer: '" + *v + "'");
  }
  if (x < lo || x > hi)
    throw UsageError("option --" + name + ": " + *v + " is outside " + std::to_string(lo) + "-" + std::to_string(hi));
  return x;
}

std::uint64_t Args::unsigned64(const std::string& name, std::uint64_t fallback) const {
  auto v = get(name);
  if (!v) return fallback;
  if (!v->empty() && v->front() == '-')
    throw UsageError("option --" + name + ": must not be negative, not " + *v + " (0 to 18446744073709551615)");
  std::uint64_t x = 0;
  auto [p, ec] = std::from_chars(v->data(), v->data() + v->size(), x);
  if (ec == std::errc::result_out_of_range && p == v->data() + v->size())
    throw UsageError("option --" + name + ": " + *v + " is beyond 18446744073709551615 (2^64 - 1)");
  if (ec != std::errc() || p != v->data() + v->size())
    throw UsageError("option --" + name + ": not an integer: '" + *v + "'");
  return x;
}

void Args::allow_only(const std::set<std::string>& known, std::size_t max_positional) const {
  for (const auto& [k, v] : values_) if (!known.count(k)) throw UsageError("unknown option --" + k);
  for (const auto& k : flags_set_) if (!known.count(k)) throw UsageError("unknown option --" + k);
  if (positional_.size() > max_positional)
    throw UsageError("unexpected word '" + positional_[max_positional] + "' (options start with --)");
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);  // thread-safe, unlike std::gmtime
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace dressguard::cli
