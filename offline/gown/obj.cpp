// OBJ reading and writing: only what a cloth mesh needs (v and f lines).
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "files.h"
#include "gown.h"

namespace dressguard::gown {
namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// Splits a line into whitespace-separated tokens (views into the line).
std::vector<std::string_view> tokens(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    size_t j = i;
    while (j < line.size() && !is_space(line[j])) ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

bool parse_double(std::string_view s, double& v) {
  const std::string tmp(s);
  char* end = nullptr;
  errno = 0;
  v = std::strtod(tmp.c_str(), &end);
  return end == tmp.c_str() + tmp.size() && errno == 0 && !tmp.empty();
}

// "a", "a/b", "a//c" or "a/b/c": the vertex index a (1-based, or negative counting back from the
// last vertex read so far), as a 0-based index; -1 when malformed or out of range.
int parse_vertex_ref(std::string_view s, int n_vertices_so_far) {
  const std::string_view a = s.substr(0, s.find('/'));
  if (a.empty()) return -1;
  const std::string tmp(a);
  char* end = nullptr;
  const long k = std::strtol(tmp.c_str(), &end, 10);
  if (end != tmp.c_str() + tmp.size()) return -1;
  long idx = k > 0 ? k - 1 : (k < 0 ? n_vertices_so_far + k : -1);
  return (idx >= 0 && idx < n_vertices_so_far) ? static_cast<int>(idx) : -1;
}

}  // namespace

GownMesh read_obj(const std::filesystem::path& path, double scale) {
  if (!(scale > 0)) throw_input_error(path, 0, "scale must be positive, got " + std::to_string(scale));
  const std::string text = read_file(path);
  GownMesh mesh;
  long line_no = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) eol = text.size();
    const std::string_view line(text.data() + pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    if (line.size() < 2 || line[0] == '#') continue;
    if (line[0] == 'v' && is_space(line[1])) {
      const auto t = tokens(line);
      Eigen::Vector3d p;
      if (t.size() < 4 || !parse_double(t[1], p.x()) || !parse_double(t[2], p.y()) || !parse_double(t[3], p.z()))
        throw_input_error(path, line_no, "malformed vertex line (want 'v x y z'): '" + std::string(line) + "'");
      if (!p.allFinite()) throw_input_error(path, line_no, "vertex coordinate is not finite");
      mesh.x.push_back(scale * p);
    } else if (line[0] == 'f' && is_space(line[1])) {
      const auto t = tokens(line);
      if (t.size() < 4) throw_input_error(path, line_no, "face with fewer than 3 vertices");
      std::vector<int> idx;
      for (size_t i = 1; i < t.size(); ++i) {
        const int k = parse_vertex_ref(t[i], static_cast<int>(mesh.x.size()));
        if (k < 0)
          throw_input_error(path, line_no,
                            "bad vertex reference '" + std::string(t[i]) + "' (" + std::to_string(mesh.x.size()) +
                                " vertices defined so far)");
        idx.push_back(k);
      }
      // Fan triangulation of a (convex, planar enough) polygon.
      for (size_t i = 1; i + 1 < idx.size(); ++i) {
        const std::array<int, 3> tri{idx[0], idx[i], idx[i + 1]};
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
          throw_input_error(path, line_no, "degenerate face (a vertex repeated)");
        mesh.triangles.push_back(tri);
      }
    }
  }
  if (mesh.triangles.empty()) throw_input_error(path, 0, "no faces");
  mesh.boundary_loops = find_boundary_loops(mesh.triangles, static_cast<int>(mesh.x.size()));
  return mesh;
}

std::string to_obj(const GownMesh& mesh) {
  std::string out = "# dressguard gown mesh, world frame W (z up, gripper moves along +x), metres\n";
  out.reserve(mesh.x.size() * 40 + mesh.triangles.size() * 24);
  char buf[96];
  for (const auto& p : mesh.x) {
    std::snprintf(buf, sizeof buf, "v %.6f %.6f %.6f\n", p.x(), p.y(), p.z());
    out += buf;
  }
  for (const auto& t : mesh.triangles) {
    std::snprintf(buf, sizeof buf, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
    out += buf;
  }
  return out;
}

}  // namespace dressguard::gown
