#include "files.h"

#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <fcntl.h>
#include <unistd.h>

#ifndef DRESSGUARD_DEFAULT_SHARED_DIR
#define DRESSGUARD_DEFAULT_SHARED_DIR ""
#endif

namespace dressguard {
namespace fs = std::filesystem;

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string format_string(const char* format, ...) {
  std::va_list args, again;
  va_start(args, format);
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string out(n > 0 ? static_cast<std::size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(out.data(), out.size() + 1, format, again);
  va_end(again);
  return out;
}

void throw_input_error(const fs::path& file, long line, std::string_view what) {
  std::ostringstream os;
  os << file.string();
  if (line > 0) os << ':' << line;
  os << ": " << what;
  throw InputError(os.str());
}

std::string read_file(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw_input_error(path, 0, "is a folder, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw_input_error(path, 0, std::string("cannot open: ") + std::strerror(errno));
  std::ostringstream os;
  os << in.rdbuf();
  if (in.bad()) throw_input_error(path, 0, "read error");
  return os.str();
}

bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) {
    const bool same = fs::equivalent(a, b, ec);
    if (!ec) return same;
  }
  const fs::path ca = fs::weakly_canonical(a, ec);
  if (ec) return false;
  const fs::path cb = fs::weakly_canonical(b, ec);
  return !ec && ca == cb;
}

void write_file_atomic(const fs::path& path, std::string_view content) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  // Unique per process so that MPI ranks or parallel runs never share a temporary.
  fs::path tmp = path;
  tmp += ".tmp." + std::to_string(::getpid());
  {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw_input_error(tmp, 0, std::string("cannot create: ") + std::strerror(errno));
    const size_t n = std::fwrite(content.data(), 1, content.size(), f);
    bool ok = n == content.size() && std::fflush(f) == 0 && ::fsync(fileno(f)) == 0;
    int err = errno;
    if (std::fclose(f) != 0 && ok) ok = false, err = errno;
    if (!ok) {
      fs::remove(tmp);
      throw_input_error(tmp, 0, std::string("write failed: ") + std::strerror(err));
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp);
    throw_input_error(path, 0, "cannot rename temporary into place: " + ec.message());
  }
  // The rename is durable once the folder's entry is on disk too (a power cut may otherwise
  // bring back the old file). Best effort: some file systems refuse fsync on a folder.
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

fs::path shared_dir() {
  auto holds_data = [](const fs::path& p) { return !p.empty() && fs::is_directory(p / "data"); };
  if (const char* env = std::getenv("DRESSGUARD_SHARED_DIR"); env && *env)
    return holds_data(env) ? fs::path(env) : fs::path{};  // taken at its word (files.h)
  if (holds_data(DRESSGUARD_DEFAULT_SHARED_DIR)) return fs::path(DRESSGUARD_DEFAULT_SHARED_DIR);
  if (holds_data("../shared")) return fs::path("../shared");
  return {};
}

}  // namespace dressguard
