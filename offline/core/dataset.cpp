#include "dataset.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "files.h"

namespace dressguard {
namespace fs = std::filesystem;

namespace {

std::vector<std::string_view> split(std::string_view line, char sep) {
  std::vector<std::string_view> out;
  size_t start = 0;
  while (true) {
    const size_t pos = line.find(sep, start);
    out.push_back(line.substr(start, pos == std::string_view::npos ? std::string_view::npos : pos - start));
    if (pos == std::string_view::npos) break;
    start = pos + 1;
  }
  return out;
}

std::vector<std::string_view> split_ws(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

double parse_double(std::string_view s, const fs::path& file, long line, std::string_view column) {
  double v = 0.0;
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\r')) s.remove_suffix(1);
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec == std::errc::result_out_of_range && p == s.data() + s.size())
    throw_input_error(file, line, "column " + std::string(column) + ": beyond the range of a double: '" + std::string(s) + "'");
  if (ec != std::errc() || p != s.data() + s.size() || !std::isfinite(v)) {
    throw_input_error(file, line, "column " + std::string(column) + ": not a finite number: '" + std::string(s) + "'");
  }
  return v;
}

// Calls f(line, number) for every line, CR of a CRLF removed, a UTF-8 byte-order mark skipped.
template <typename F>
void for_each_line(const std::string& text, F&& f) {
  long lineno = 0;
  size_t start = text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string_view line(text.data() + start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++lineno;
    f(line, lineno);
    start = end + 1;
  }
}

constexpr const char* kTrialHeader = "t,travel,f_motion,f_lateral,f_vertical";
constexpr const char* kManifestHeader = "trial_id,participant,height,speed,label,file";

// The bounds of dataset.h on one new sample, against the one before it.
void check_sample(const std::vector<HapticSample>& s, const char* const names[5], const fs::path& file, long line) {
  const HapticSample& x = s.back();
  if (!(x.travel >= kMinTravel && x.travel <= kMaxTravel))
    throw_input_error(file, line,
                      std::string("column ") + names[1] + ": " + format_number(x.travel) + " m is outside [" +
                          format_number(kMinTravel) + ", " + format_number(kMaxTravel) + "] m (travel is in metres)");
  const double f[3] = {x.f_motion, x.f_lateral, x.f_vertical};
  for (int k = 0; k < 3; ++k)
    if (std::fabs(f[k]) > kMaxForce)
      throw_input_error(file, line,
                        std::string("column ") + names[2 + k] + ": " + format_number(f[k]) + " N is beyond +-" +
                            format_number(kMaxForce) + " N");
  if (s.size() < 2) return;
  const HapticSample& p = s[s.size() - 2];
  if (!(x.t > p.t)) throw_input_error(file, line, "time does not increase");
  if (x.travel < p.travel - kTravelJitter)
    throw_input_error(file, line,
                      std::string("column ") + names[1] + " goes back " + format_number(p.travel - x.travel) +
                          " m from the line before (more than " + format_number(kTravelJitter) + " m)");
}

// Parses the five fields of one row (names as the file calls its columns) and appends the sample.
void append_sample(const std::vector<std::string_view>& f, const char* const names[5], const fs::path& file,
                   long line, std::vector<HapticSample>& out) {
  double v[5];
  for (int i = 0; i < 5; ++i) v[i] = parse_double(f[i], file, line, names[i]);
  out.push_back({v[0], v[1], v[2], v[3], v[4]});
  check_sample(out, names, file, line);
}

bool is_control(char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7F; }

// The study's trial files are <k>.txt; a copy through another file system may say .TXT.
bool is_trial_file_name(const fs::path& p) {
  std::string e = p.extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e == ".txt";
}

// A trial is a pull's force sequence. One sample is none: it has no sampling period (the late
// start's sample count would be guessed at 100 Hz) and classify would score one force as a whole
// pull. `first_row` is the line of the first sample.
void require_a_sequence(const std::vector<HapticSample>& samples, const fs::path& file, long first_row) {
  if (samples.empty()) throw_input_error(file, 0, "no samples");
  if (samples.size() == 1)
    throw_input_error(file, first_row,
                      "the only sample: a trial is a pull's force sequence, at least 2 samples (one has no "
                      "sampling period, and classify would score one force as a whole pull)");
}

}  // namespace

std::vector<HapticSample> read_trial_csv(const fs::path& path) {
  const std::string text = read_file(path);
  std::vector<HapticSample> out;
  long first_row = 0;
  std::size_t columns = 5;  // the header's: the five, then any named ones the reader skips
  for_each_line(text, [&](std::string_view line, long n) {
    if (n == 1) {
      const std::string_view head(kTrialHeader);
      const bool more = line.size() > head.size() + 1 && line[head.size()] == ',';
      if (line.substr(0, head.size()) != head || !(line.size() == head.size() || more))
        throw_input_error(path, 1, std::string("expected header '") + kTrialHeader + "' (named columns may follow)");
      columns = split(line, ',').size();
      for (const std::string_view name : split(line, ','))
        if (name.empty()) throw_input_error(path, 1, "a column without a name in the header");
      return;
    }
    if (line.empty()) return;
    const auto f = split(line, ',');
    if (f.size() != columns)
      throw_input_error(path, n, "expected " + std::to_string(columns) + " columns, found " + std::to_string(f.size()));
    static constexpr const char* names[] = {"t", "travel", "f_motion", "f_lateral", "f_vertical"};
    append_sample(f, names, path, n, out);
    if (out.size() == 1) first_row = n;
  });
  require_a_sequence(out, path, first_row);
  return out;
}

std::string format_trial_csv(const std::vector<HapticSample>& samples,
                             const std::vector<ConstantColumn>& constant_columns) {
  std::string head = kTrialHeader, tail;
  for (const ConstantColumn& c : constant_columns) {
    for (const std::string* w : {&c.name, &c.value})
      if (w->find_first_of(",\"\r\n") != std::string::npos || (w == &c.name && w->empty()))
        throw std::invalid_argument("format_trial_csv: column '" + c.name + "' = '" + c.value +
                                    "' is no plain CSV field");
    head += "," + c.name;
    tail += "," + c.value;
  }
  std::string out = head + "\n";
  char buf[160];
  for (const auto& s : samples) {
    // %.9g keeps sub-micronewton resolution and round-trips the study's 6-decimal values.
    std::snprintf(buf, sizeof buf, "%.9g,%.9g,%.9g,%.9g,%.9g", s.t, s.travel, s.f_motion, s.f_lateral, s.f_vertical);
    out += buf;
    out += tail;
    out += '\n';
  }
  return out;
}

Dataset load_dataset(const fs::path& dir) {
  const fs::path manifest = dir / "manifest.csv";
  const std::string text = read_file(manifest);
  if (text.empty()) throw_input_error(manifest, 0, std::string("empty file (expected the header '") + kManifestHeader + "')");
  Dataset ds;
  ds.files.push_back(manifest);
  std::map<std::string, long> seen, files;
  for_each_line(text, [&](std::string_view line, long n) {
    if (n == 1) {
      if (line != kManifestHeader) throw_input_error(manifest, 1, std::string("expected header '") + kManifestHeader + "'");
      return;
    }
    if (line.empty()) return;
    const auto f = split(line, ',');
    if (f.size() != 6) throw_input_error(manifest, n, "expected 6 columns, found " + std::to_string(f.size()));
    HapticSequence seq;
    seq.id = std::string(f[0]);
    if (seq.id.empty()) throw_input_error(manifest, n, "empty trial_id");
    if (auto [it, fresh] = seen.emplace(seq.id, n); !fresh) {
      throw_input_error(manifest, n, "trial_id '" + seq.id + "' repeats line " + std::to_string(it->second));
    }
    seq.participant = std::string(f[1]);
    const auto h = parse_arm_height(f[2]);
    if (!h) throw_input_error(manifest, n, "height must be high, middle or low, not '" + std::string(f[2]) + "'");
    seq.height = *h;
    seq.speed = parse_double(f[3], manifest, n, "speed");
    if (!(seq.speed >= kMinSpeed && seq.speed <= kMaxSpeed))
      throw_input_error(manifest, n,
                        "speed " + format_number(seq.speed) + " m/s is outside [" + format_number(kMinSpeed) + ", " +
                            format_number(kMaxSpeed) + "] m/s (speed is in m/s)");
    if (!f[4].empty()) {
      const auto o = parse_outcome(f[4]);
      if (!o) throw_input_error(manifest, n, "label must be good, missed, caught or empty, not '" + std::string(f[4]) + "'");
      seq.label = *o;
    }
    if (f[5].empty()) throw_input_error(manifest, n, "empty file");
    if (auto [it, fresh] = files.emplace(std::string(f[5]), n); !fresh) {
      throw_input_error(manifest, n, "file '" + it->first + "' repeats line " + std::to_string(it->second));
    }
    ds.files.push_back(dir / std::string(f[5]));
    ds.trial_files.push_back(ds.files.back());
    seq.samples = read_trial_csv(ds.files.back());
    if (const size_t k = unrecorded_samples(seq); k > kMaxUnrecordedSamples)
      throw_input_error(manifest, n,
                        "trial '" + seq.id + "' would start " + std::to_string(k) +
                            " samples into its pull (first travel " + format_number(seq.samples.front().travel) +
                            " m at " + format_number(seq.speed) + " m/s), more than " +
                            std::to_string(kMaxUnrecordedSamples) + ": is t in seconds?");
    ds.trials.push_back(std::move(seq));
  });
  return ds;
}

const HapticSequence* find_trial(const Dataset& ds, const std::string& id) {
  for (const auto& t : ds.trials)
    if (t.id == id) return &t;
  return nullptr;
}

Dataset load_datasets(const std::vector<fs::path>& dirs) {
  Dataset all;
  for (const auto& dir : dirs) {
    Dataset one = load_dataset(dir);
    all.trials.insert(all.trials.end(), std::make_move_iterator(one.trials.begin()),
                      std::make_move_iterator(one.trials.end()));
    all.files.insert(all.files.end(), one.files.begin(), one.files.end());
    all.trial_files.insert(all.trial_files.end(), one.trial_files.begin(), one.trial_files.end());
  }
  return all;
}

std::string trial_file_name(const Dataset& ds, const HapticSequence& t) {
  const auto* first = ds.trials.data();
  if (ds.trial_files.size() == ds.trials.size() && &t >= first && &t < first + ds.trials.size())
    return ds.trial_files[static_cast<std::size_t>(&t - first)].string();
  return "trial '" + t.id + "'";
}

std::string trial_id_problem(std::string_view id) {
  if (id.empty()) return "is empty";
  if (id.front() == '.') return "starts with '.'";
  for (const char c : id) {
    if (c == ',' || c == '/' || c == '\\') return std::string("holds '") + c + "'";
    if (is_control(c)) return "holds a control character";
  }
  return {};
}

namespace {

// trial id -> file, for the plain file names (no folder part) the manifest in `dir` names; none
// when it has none or cannot be read: then there is nothing a save could overwrite that a
// manifest still names.
std::map<std::string, std::string> files_named(const fs::path& dir) {
  std::map<std::string, std::string> out;
  std::error_code ec;
  if (!fs::is_regular_file(dir / "manifest.csv", ec)) return out;
  std::string text;
  try {
    text = read_file(dir / "manifest.csv");
  } catch (const InputError&) {
    return out;
  }
  for_each_line(text, [&](std::string_view line, long n) {
    const auto f = split(line, ',');
    if (n > 1 && f.size() == 6 && !f[5].empty() && f[5].find('/') == std::string_view::npos) out.emplace(f[0], f[5]);
  });
  return out;
}

bool holds(const fs::path& file, const std::string& content) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec) || fs::file_size(file, ec) != content.size()) return false;
  try {
    return read_file(file) == content;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace

void save_dataset(const Dataset& ds, const fs::path& dir) {
  const fs::path manifest = dir / "manifest.csv";
  std::set<std::string> ids;
  for (const auto& seq : ds.trials) {
    if (const std::string why = trial_id_problem(seq.id); !why.empty())
      throw_input_error(manifest, 0, "cannot save trial id '" + seq.id + "': it " + why);
    if (!ids.insert(seq.id).second) throw_input_error(manifest, 0, "cannot save trial id '" + seq.id + "' twice");
    for (const char c : seq.participant)
      if (c == ',' || is_control(c))
        throw_input_error(manifest, 0, "cannot save trial '" + seq.id + "': its participant '" + seq.participant +
                                           "' holds a comma or a control character");
  }
  fs::create_directories(dir);
  const std::map<std::string, std::string> named = files_named(dir);
  std::set<std::string> before, after;
  for (const auto& [id, file] : named) before.insert(file);
  std::ostringstream m;
  m << kManifestHeader << '\n';
  for (const auto& seq : ds.trials) {
    const std::string text = format_trial_csv(seq.samples);
    // The file the previous manifest gave this trial if it holds these samples already, else
    // <id>.csv, else the first usable <id>.<k>.csv that is not another trial's own name (ids "a"
    // and "a.1"). Usable: not given by this save already, and not named by the previous
    // manifest unless it holds these very samples.
    const auto usable = [&](const std::string& f) {
      return !after.count(f) && (!before.count(f) || holds(dir / f, text));
    };
    const auto prev = named.find(seq.id);
    std::string file = prev != named.end() && usable(prev->second) ? prev->second : seq.id + ".csv";
    for (int k = 1; !usable(file); ++k) {
      if (!ids.count(seq.id + "." + std::to_string(k))) file = seq.id + "." + std::to_string(k) + ".csv";
    }
    if (!holds(dir / file, text)) write_file_atomic(dir / file, text);
    after.insert(file);
    m << seq.id << ',' << seq.participant << ',' << arm_height_name(seq.height) << ',' << format_number(seq.speed)
      << ',' << (seq.label ? outcome_name(*seq.label) : std::string_view()) << ',' << file << '\n';
  }
  write_file_atomic(manifest, m.str());
  for (const auto& f : before) {
    std::error_code ec;
    if (!after.count(f)) fs::remove(dir / f, ec);  // best effort: the new dataset is already whole
  }
}

std::vector<HapticSample> read_study_trial(const fs::path& path) {
  const std::string text = read_file(path);
  std::vector<HapticSample> out;
  long first_row = 0;
  for_each_line(text, [&](std::string_view line, long n) {
    const auto f = split_ws(line);
    if (f.empty()) return;
    if (f.size() != 5) throw_input_error(path, n, "expected 5 space-separated columns, found " + std::to_string(f.size()));
    static constexpr const char* names[] = {"t", "position", "F_motion", "F_lateral", "F_vertical"};
    append_sample(f, names, path, n, out);
    if (out.size() == 1) first_row = n;
  });
  require_a_sequence(out, path, first_row);
  return out;
}

double estimate_speed(const std::vector<HapticSample>& s) {
  // The rig accelerates at 1 m/s^2, so by 0.2 s it cruises; fit the slope over the middle half.
  if (s.size() < 8) return 0.1;
  const size_t a = s.size() / 4, b = 3 * s.size() / 4;
  const double v = (s[b].travel - s[a].travel) / (s[b].t - s[a].t);
  return std::fabs(v - 0.1) <= std::fabs(v - 0.15) ? 0.1 : 0.15;
}

bool ended_at_force_limit(const std::vector<HapticSample>& s) {
  if (s.empty()) return false;
  return std::abs(s.back().f_motion) >= 9.5 || std::abs(s.back().f_vertical) >= 9.5;
}

double rig_end_of_travel(const std::vector<HapticSample>& s, double full) {
  return s.empty() || ended_at_force_limit(s) ? full : s.back().travel;
}

Dataset import_study(const fs::path& study) {
  struct Folder { const char* name; ArmHeight height; Outcome label; const char* tag; };
  static constexpr Folder folders[] = {
      {"good", ArmHeight::High, Outcome::Good, "good"},
      {"caughtmiss", ArmHeight::Middle, Outcome::Missed, "middlemiss"},
      {"miss", ArmHeight::Low, Outcome::Missed, "miss"},
  };
  if (!fs::is_directory(study)) throw_input_error(study, 0, "not a folder");
  Dataset ds;
  std::map<std::string, fs::path> from;  // trial id -> its file
  for (const auto& folder : folders) {
    const fs::path dir = study / folder.name;
    if (!fs::is_directory(dir)) throw_input_error(dir, 0, "missing: expected the study's good/, miss/ and caughtmiss/ folders");
    std::vector<fs::path> files;
    for (const auto& subj : fs::directory_iterator(dir)) {
      if (!subj.is_directory()) continue;
      for (const auto& f : fs::directory_iterator(subj.path())) {
        if (is_trial_file_name(f.path())) files.push_back(f.path());
      }
    }
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      for (const char c : f.string())
        if (is_control(c)) throw_input_error(f, 0, "the path holds a control character");
      const std::string subj = f.parent_path().filename().string();
      if (subj.rfind("subject", 0) != 0) throw_input_error(f.parent_path(), 0, "expected a folder named subject<N>");
      HapticSequence seq;
      seq.participant = subj.substr(7);
      seq.id = "s" + seq.participant + "-" + folder.tag + "-" + f.stem().string();
      if (const std::string why = trial_id_problem(seq.id); !why.empty())
        throw_input_error(f, 0, "its trial id '" + seq.id + "' " + why);
      if (auto [it, fresh] = from.emplace(seq.id, f); !fresh)
        throw_input_error(f, 0, "its trial id '" + seq.id + "' is also that of " + it->second.string());
      seq.height = folder.height;
      seq.label = folder.label;
      seq.samples = read_study_trial(f);
      seq.speed = estimate_speed(seq.samples);
      ds.trials.push_back(std::move(seq));
    }
  }
  if (ds.trials.empty()) throw_input_error(study, 0, "no trial files (<outcome>/subject<N>/<k>.txt)");
  return ds;
}

fs::path study_dir() {
  const fs::path s = shared_dir();
  if (s.empty()) return {};
  const fs::path d = s / "data" / "kapusta2016-calibration-trials";
  return fs::is_directory(d) ? d : fs::path();
}

}  // namespace dressguard
