// libFuzzer target for the offline toolchain's file readers (offline/core, offline/gown): the
// first input byte chooses the reader, the rest is the file's text. Rules (files.h, dataset.h,
// gown.h):
//
//   errors   bad input throws InputError "PATH:LINE: what" (or "PATH: what"), LINE a line of the
//            file; no other exception escapes (a std::stod out_of_range, a bad_alloc, ...);
//   values   what a reader returns is within dataset.h's bounds (finite; travel in [kMinTravel,
//            kMaxTravel], never back by more than kTravelJitter; forces within kMaxForce; t
//            increasing), and a mesh is one gown.h's read_obj promises (vertices within
//            kMaxObjCoordinate, indices in range, triangles of at least kMinObjFaceArea, none
//            twice, no edge of three, every vertex used, around each vertex one fan of triangles
//            joined by their edges).
//
// Readers: 0 a dataset trial CSV (read_trial_csv), 1 a trial of the study's layout
// (read_study_trial), 2 an OBJ mesh (read_obj at the file's own scale: 1 when its first line says
// it is in metres, as `gown --out` writes it, else 1.679 as the measured gown's).
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
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

bool plausible_samples(const std::vector<HapticSample>& v) {
  for (size_t i = 0; i < v.size(); ++i) {
    const HapticSample& s = v[i];
    if (!std::isfinite(s.t) || !(s.travel >= kMinTravel && s.travel <= kMaxTravel)) return false;
    for (const double f : {s.f_motion, s.f_lateral, s.f_vertical})
      if (!(std::fabs(f) <= kMaxForce)) return false;
    if (i > 0 && !(s.t > v[i - 1].t && s.travel >= v[i - 1].travel - kTravelJitter)) return false;
  }
  return !v.empty();
}

void check_mesh(const gown::GownMesh& m) {
  for (const auto& p : m.x)
    if (!p.allFinite() || p.cwiseAbs().maxCoeff() > gown::kMaxObjCoordinate) broken("an OBJ read with a vertex out of bounds", 0);
  std::set<std::array<int, 3>> faces;
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k)
      if (t[k] < 0 || t[k] >= static_cast<int>(m.x.size())) broken("an OBJ read with an index out of range", 0);
    if (!(0.5 * (m.x[t[1]] - m.x[t[0]]).cross(m.x[t[2]] - m.x[t[0]]).norm() >= gown::kMinObjFaceArea))
      broken("an OBJ read with a face of (near) zero area", 0);
    auto key = t;
    std::sort(key.begin(), key.end());
    if (!faces.insert(key).second) broken("an OBJ read with a triangle twice", 0);
    for (int k = 0; k < 3; ++k)
      if (++edges[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}] > 2)
        broken("an OBJ read with an edge of three faces", 0);
  }
  // Each vertex's triangles, spread from the first across the edges through the vertex that two
  // of them share: all reached, or two fans meet only at the vertex.
  std::vector<std::vector<int>> around(m.x.size());
  for (int f = 0; f < static_cast<int>(m.triangles.size()); ++f)
    for (int v : m.triangles[f]) around[v].push_back(f);
  for (int v = 0; v < static_cast<int>(around.size()); ++v) {
    const std::vector<int>& fs = around[v];
    if (fs.empty()) broken("an OBJ read with a vertex no face uses", 0);
    std::vector<char> reached(fs.size(), 0);
    reached[0] = 1;
    for (bool grew = true; grew;) {
      grew = false;
      for (size_t a = 0; a < fs.size(); ++a)
        for (size_t b = 0; b < fs.size(); ++b)
          if (reached[a] && !reached[b]) {
            int shared = 0;  // vertices the two triangles share: v and one more is an edge through v
            const auto& tb = m.triangles[fs[b]];
            for (int p : m.triangles[fs[a]]) shared += static_cast<int>(std::count(tb.begin(), tb.end(), p));
            if (shared == 2) reached[b] = 1, grew = true;
          }
    }
    if (std::count(reached.begin(), reached.end(), 0) > 0) broken("an OBJ read with a pinched vertex", 0);
  }
}

// read_obj's lines end at LF, CRLF or a lone CR: its text with each lone CR an LF, so that the
// error rule counts the lines it names.
std::string obj_lines(std::string_view text) {
  std::string s(text);
  for (size_t i = 0; i < s.size(); ++i)
    if (s[i] == '\r' && (i + 1 == s.size() || s[i + 1] != '\n')) s[i] = '\n';
  return s;
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
        if (!plausible_samples(read_trial_csv(path))) broken("a trial CSV read with a value out of bounds", 0);
        break;
      case 1:
        if (!plausible_samples(read_study_trial(path))) broken("a study trial read with a value out of bounds", 0);
        break;
      default:
        check_mesh(gown::read_obj(path));
        break;
    }
  } catch (const InputError& e) {
    fuzz::check_error_names_line(e.what(), path.string(), reader == 2 ? obj_lines(text) : std::string(text),
                                 true);  // or "PATH: what"
  }
  return 0;
}
