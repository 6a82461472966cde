// File handling shared by every offline command: errors that name the file and line, and
// writes that never leave a half-written file behind.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace dressguard {

// Bad input: the message names the file (and line, where there is one) and what was wrong.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "path:line: what" (line 0 omits the line).
[[noreturn]] void throw_input_error(const std::filesystem::path& file, long line, std::string_view what);

// A number as people read it in messages and CSV: six significant digits ("%.6g").
std::string format_number(double v);

// printf into a string as long as it needs (a fixed buffer cut long paths off mid-JSON).
std::string format_string(const char* format, ...) __attribute__((format(printf, 1, 2)));

// Reads a whole file; throws InputError naming the file if it cannot.
std::string read_file(const std::filesystem::path& path);

// Writes `content` to `path` through a temporary file in the same folder and a rename, so a
// reader sees either the old file or the whole new one, never a torn one. Creates parent folders.
void write_file_atomic(const std::filesystem::path& path, std::string_view content);

// Whether two paths name one file: the same file (std::filesystem::equivalent) when both exist,
// else the same path once made absolute and normal (weakly_canonical, through symlinks as far as
// they exist). What a command checks before writing an output over one of its inputs.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

// The study's shared/ folder: $DRESSGUARD_SHARED_DIR, else the build-time default, else
// ../shared relative to the working directory. Empty when none of them holds data/.
// A non-empty $DRESSGUARD_SHARED_DIR is taken at its word: one without data/ means the data is
// absent, not "look elsewhere", so that a run (or a test) can be made as on a machine without
// ../shared, e.g. DRESSGUARD_SHARED_DIR=/nonexistent.
std::filesystem::path shared_dir();

}  // namespace dressguard
