// A small command-line reader shared by the dressguard subcommands.
//
// Every subcommand takes "--name value" options and "--flag" switches, answers --help, and on
// bad input exits non-zero with one line naming what was wrong (UsageError, caught in main).
#pragma once

#include <climits>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "dataset.h"

namespace dressguard::cli {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "a,b,,c" -> {"a", "b", "c"}: the comma-separated lists of options like --participant 1,4.
std::set<std::string> split_list(const std::string& s);
// "a,b,,c" -> {"a", "b", "c"} in the order given: lists whose order matters, like the datasets of
// a pooled training set (--data A,B), whose order is the order of the trials HMM training sums.
std::vector<std::string> split_in_order(const std::string& s);

// The datasets that option --`option` pools ("A,B,...", split_in_order), in the order given.
// UsageError when it names none, or one folder twice (same_file: study and ./study are one),
// saying `why_once`. By default why a pooled folder counts once: pooled twice, its trials would
// count twice in training, their weight doubled and the model's trial counts wrong, without a word
// (train --data study,study once did).
std::vector<std::filesystem::path> dataset_list(const std::string& option, const std::string& list,
                                                const std::string& why_once = "its trials would count twice");
// The files that option --`option` lists ("A,B,...", split_in_order), in the order given, each
// once: UsageError when one file is named twice (same_file, as dataset_list), naming both
// arguments, calling it a `noun` and saying `why_once`. An empty list is the caller's to refuse.
std::vector<std::string> distinct_files(const std::string& option, const std::string& list, const std::string& noun,
                                        const std::string& why_once);

// UsageError naming every name of `given` (option --`option`'s list) that is no participant of
// `ds` (the dataset `data`), and the participants it has: a name that matches nobody would
// select or leave out nothing without a word (train --exclude-participant p4 once trained on
// participant "4" while its model said it excluded p4).
void require_known_participants(const std::string& option, const std::set<std::string>& given, const Dataset& ds,
                                const std::string& data);

// tools/plot/<name> of the sources this binary was built from: under $DRESSGUARD_SOURCE_DIR, else
// in a folder above the binary, else under the working directory; empty when absent.
std::filesystem::path plot_script(const std::string& name);

// Runs `/usr/bin/python3 SCRIPT ARGS...` through the shell, every word quoted (a path may hold a
// quote or a blank); its exit status, 0 when it succeeded.
int run_plot_script(const std::filesystem::path& script, const std::vector<std::string>& args);

// --threads N: 0 is every core; more than this is no machine's.
inline constexpr long kMaxThreads = 1024;

class Args {
 public:
  // `flags`: names that take no value (e.g. "json", "help"); every other "--name" takes one.
  Args(int argc, char** argv, std::set<std::string> flags);

  bool has(const std::string& name) const;
  // The option's value. An option given twice is a UsageError naming it: the second value would
  // otherwise replace the first without a word. Options meant to repeat are read with all().
  std::optional<std::string> get(const std::string& name) const;
  // Every value of a repeatable option, in the order given (e.g. replay's --set KEY=VALUE).
  std::vector<std::string> all(const std::string& name) const;
  std::string require(const std::string& name) const;  // UsageError when absent
  // require() for a file to be written: a UsageError now, too, when it names a folder (the
  // write would fail only after the whole run).
  std::string require_output_file(const std::string& name) const;
  double number(const std::string& name, double fallback) const;  // UsageError when not a number
  // UsageError when not a whole number in [lo, hi] (the default range: what an int holds).
  long integer(const std::string& name, long fallback, long lo = -2147483647L - 1, long hi = 2147483647L) const;
  // UsageError when not a whole number in [0, 2^64 - 1]; a negative one is said to be negative
  // (a seed is a uint64_t: read as a long, the upper half of its values were "not an integer").
  std::uint64_t unsigned64(const std::string& name, std::uint64_t fallback) const;
  const std::vector<std::string>& positional() const { return positional_; }
  // UsageError naming the first option that is not in `known` (catches typos like --sped), or
  // the first word that is no option when the command takes fewer than `max_positional` of them
  // ("-generations 2", with one dash, once ran the paper's budget of hours).
  void allow_only(const std::set<std::string>& known, std::size_t max_positional = 0) const;

 private:
  std::map<std::string, std::vector<std::string>> values_;
  std::set<std::string> flags_set_;
  std::vector<std::string> positional_;
};

// The current time, UTC, ISO-8601 to the second ("2026-11-23T16:20:00Z"), for files' provenance.
std::string utc_now();

}  // namespace dressguard::cli
