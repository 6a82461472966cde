// libFuzzer target for the offline toolchain's file readers (offline/core, offline/gown): the
// first input byte chooses the reader, the rest is the file's text. Rules (files.h, dataset.h,
// gown.h):
//
//   errors   bad input throws InputError "PATH:LINE: what" (or "PATH: what"), LINE a line of the
//            file; no other exception escapes (a std::stod out_of_range, a bad_alloc, ...);
//   values   what a reader returns is finite: a measured or simulated force, a vertex position.
//
// Readers: 0 a dataset trial CSV (read_trial_csv), 1 a trial of the study's layout
// (read_study_trial), 2 an OBJ mesh (read_obj, scale 1.679 as the measured gown's).
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

#include "dataset.h"
#include "files.h"
#include "gown.h"
#include "traffic.h"

using namespace dressguard;
using fuzz::broken;

namespace {

std::filesystem::path scratch_file() {
  static const std::filesystem::path p =
      std::filesystem::temp_directory_path() / ("dg-fuzz-inputs-" + std::to_string(getpid()) + ".txt");
  return p;
}

bool finite_samples(const std::vector<HapticSample>& v) {
  for (const auto& s : v)
    if (!std::isfinite(s.t) || !std::isfinite(s.travel) || !std::isfinite(s.f_motion) || !std::isfinite(s.f_lateral) ||
        !std::isfinite(s.f_vertical))
      return false;
  return true;
}


}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const int reader = data[0] % 3;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  const std::filesystem::path path = scratch_file();
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f || std::fwrite(text.data(), 1, text.size(), f) != text.size() || std::fclose(f) != 0) {
      std::perror(path.c_str());
      std::abort();
    }
  }
  try {
    switch (reader) {
      case 0:
        if (!finite_samples(read_trial_csv(path))) broken("a trial CSV read with a non-finite value", 0);
        break;
      case 1:
        if (!finite_samples(read_study_trial(path))) broken("a study trial read with a non-finite value", 0);
        break;
      default: {
        const gown::GownMesh m = gown::read_obj(path, 1.679);
        for (const auto& p : m.x)
          if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) broken("an OBJ read with a non-finite vertex", 0);
        for (const auto& t : m.triangles)
          for (int k = 0; k < 3; ++k)
            if (t[k] < 0 || t[k] >= static_cast<int>(m.x.size())) broken("an OBJ read with an index out of range", 0);
        break;
      }
    }
  } catch (const InputError& e) {
    fuzz::check_error_names_line(e.what(), path.string(), text, true);  // or "PATH: what"
  }
  return 0;
}
