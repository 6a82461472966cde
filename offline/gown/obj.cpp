// OBJ reading and writing: only what a cloth mesh needs (v and f lines).
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <map>
#include <cstdlib>
#include <numeric>
#include <string>
#include <string_view>

#include "files.h"
#include "gown.h"

namespace dressguard::gown {
namespace {

// Every blank isspace knows: a vertical tab or form feed read as part of a word made "v\v0 1 0"
// one unknown keyword, a skipped line, and every later vertex index shifted.
bool is_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

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
  // ERANGE is also an underflow: a subnormal (1e-320) or a value rounded to 0 is a coordinate
  // like 0. An overflow (+-HUGE_VAL) stays refused.
  const bool in_range = errno == 0 || (errno == ERANGE && std::abs(v) <= DBL_MIN);
  return end == tmp.c_str() + tmp.size() && in_range && !tmp.empty();
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

// The mesh must be a cloth the simulator can take: no triangle of (near) zero area (its bending
// and stretching constraints divide by it), none twice, no edge shared by more than two
// triangles, and around every vertex one fan of triangles (a cloth sheet is a 2-manifold; its
// boundary loops are only defined then: where two fans meet at a vertex, a hole touching the hem
// or a bowtie, the boundary walk runs through it twice and two loops come out as one). Every
// vertex is used by some face: one that is not is a particle without mass (vertex_masses gives
// it 0) that still counts in the placement's centroid and, in the jaws, as grasped.
void check_cloth_topology(const GownMesh& mesh, const std::vector<long>& face_line,
                          const std::vector<long>& vertex_line, const std::filesystem::path& path) {
  std::map<std::array<int, 3>, size_t> faces;
  std::map<std::pair<int, int>, std::vector<size_t>> edges;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& tri = mesh.triangles[f];
    const double area =
        0.5 * (mesh.x[tri[1]] - mesh.x[tri[0]]).cross(mesh.x[tri[2]] - mesh.x[tri[0]]).norm();
    if (!(area >= kMinObjFaceArea))
      throw_input_error(path, face_line[f],
                        "face of area " + format_number(area) + " m^2 (its vertices are collinear)");
    std::array<int, 3> key = tri;
    std::sort(key.begin(), key.end());
    if (auto [it, fresh] = faces.emplace(key, f); !fresh)
      throw_input_error(path, face_line[f], "the same triangle as line " + std::to_string(face_line[it->second]));
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      auto& users = edges[{std::min(a, b), std::max(a, b)}];
      users.push_back(f);
      if (users.size() > 2)
        throw_input_error(path, face_line[f], "edge " + std::to_string(std::min(a, b) + 1) + "-" +
                                                  std::to_string(std::max(a, b) + 1) + " is shared by three faces (lines " +
                                                  std::to_string(face_line[users[0]]) + ", " +
                                                  std::to_string(face_line[users[1]]) + " and this one)");
    }
  }
  // The fans: the corners (face, vertex) around a vertex joined across each edge two faces share;
  // a 2-manifold's vertex ends with one group.
  std::vector<size_t> root(3 * mesh.triangles.size());
  std::iota(root.begin(), root.end(), size_t{0});
  auto find = [&](size_t c) {
    while (root[c] != c) c = root[c] = root[root[c]];
    return c;
  };
  auto corner = [&](size_t f, int v) {
    const auto& t = mesh.triangles[f];
    return 3 * f + static_cast<size_t>(t[0] == v ? 0 : t[1] == v ? 1 : 2);
  };
  for (const auto& [e, users] : edges)
    if (users.size() == 2)
      for (int v : {e.first, e.second}) root[find(corner(users[0], v))] = find(corner(users[1], v));
  std::vector<std::vector<size_t>> fans(mesh.x.size());
  for (size_t c = 0; c < root.size(); ++c) fans[static_cast<size_t>(mesh.triangles[c / 3][c % 3])].push_back(find(c));
  for (size_t v = 0; v < fans.size(); ++v) {
    auto& f = fans[v];
    std::sort(f.begin(), f.end());
    f.erase(std::unique(f.begin(), f.end()), f.end());
    if (f.empty())
      throw_input_error(path, vertex_line[v], "vertex " + std::to_string(v + 1) +
                                                  " is used by no face (a particle without mass); remove it");
    if (f.size() > 1)
      throw_input_error(path, vertex_line[v], "vertex " + std::to_string(v + 1) + " is pinched: its faces form " +
                                                  std::to_string(f.size()) +
                                                  " fans that meet only there (the cloth touches itself at a "
                                                  "point; a cloth's vertex has one fan)");
  }
}

// Fan triangulation from the polygon's first corner holds for a convex polygon (and a concave one
// whose first corner sees all the others); otherwise some fan triangles face the other way and
// overlap the rest, a fold the file does not have. Refused, naming the first such pair. A polygon
// that repeats a corner is left to its triangles' checks (a repeated vertex, a triangle twice).
void check_fan(const GownMesh& mesh, const std::vector<int>& idx, const std::filesystem::path& path, long line_no) {
  std::vector<int> corners = idx;
  std::sort(corners.begin(), corners.end());
  if (std::adjacent_find(corners.begin(), corners.end()) != corners.end()) return;
  std::vector<Eigen::Vector3d> n;
  for (size_t i = 1; i + 1 < idx.size(); ++i)
    n.push_back((mesh.x[idx[i]] - mesh.x[idx[0]]).cross(mesh.x[idx[i + 1]] - mesh.x[idx[0]]));
  for (size_t i = 0; i < n.size(); ++i)
    for (size_t j = i + 1; j < n.size(); ++j)
      if (n[i].dot(n[j]) < 0)
        throw_input_error(path, line_no, "polygon of " + std::to_string(idx.size()) +
                                             " corners is not convex: fanned from its first corner, triangles 1 " +
                                             std::to_string(i + 2) + " " + std::to_string(i + 3) + " and 1 " +
                                             std::to_string(j + 2) + " " + std::to_string(j + 3) +
                                             " face opposite ways; split it into triangles");
}

// Whether the text's first line (after a byte-order mark, up to trailing blanks) is the one
// to_obj writes: the file is in metres.
bool says_metres(std::string_view text, size_t start) {
  std::string_view first = text.substr(start, text.find_first_of("\r\n", start) - start);
  while (!first.empty() && is_space(first.back())) first.remove_suffix(1);
  return first == kObjMetresHeader;
}

// The scale of a file whose first line says whether it is in metres: 1 for one that does, when
// unset or asked for; a file in metres scaled by anything else was `gown --out`'s placed gown
// read back with the measured gown's default 1.679, a 4.55 m^2 gown and no word said.
double file_scale(const std::filesystem::path& path, bool in_metres, std::optional<double> scale) {
  if (!in_metres) return scale.value_or(kMeasuredGownScale);
  if (scale && *scale != 1.0)
    throw_input_error(path, 1, "the file says it is in metres (as `dressguard gown --out` writes it): its scale is 1, "
                               "not " + format_number(*scale) + " (delete this line to scale it)");
  return 1.0;
}

}  // namespace

GownMesh read_obj(const std::filesystem::path& path, std::optional<double> asked_scale) {
  if (asked_scale && !(*asked_scale > 0))
    throw_input_error(path, 0, "scale must be positive, got " + format_number(*asked_scale));
  const std::string text = read_file(path);
  GownMesh mesh;
  std::vector<long> face_line;    // the line of each triangle, for the topology's messages
  std::vector<long> vertex_line;  // the line of each vertex
  long line_no = 0;
  size_t pos = text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;  // a UTF-8 byte-order mark
  const double scale = file_scale(path, says_metres(text, pos), asked_scale);
  while (pos < text.size()) {
    // A line ends at "\n", "\r\n" or a lone "\r" (old Mac files: read as one line, "no faces").
    size_t eol = text.find_first_of("\r\n", pos);
    if (eol == std::string::npos) eol = text.size();
    std::string_view line(text.data() + pos, eol - pos);
    pos = eol + (text.compare(eol, 2, "\r\n") == 0 ? 2 : 1);
    ++line_no;
    line = line.substr(0, line.find('#'));  // a comment, the whole line or after the data
    const auto t = tokens(line);            // leading blanks are no reason to skip a line
    if (t.empty()) continue;
    // OBJ's keywords that begin with v or f are v, vt, vn, vp and f (and fo, an old spelling of
    // f, refused rather than skipped: its faces would be missing). Any other word that does
    // ("V", "F", "VT", "v0.5") is a slip for one of them, and skipped it would shift every later
    // vertex index or drop faces without a word.
    const char first = t[0][0];
    if ((first == 'v' || first == 'V' || first == 'f' || first == 'F') && t[0] != "v" && t[0] != "vt" &&
        t[0] != "vn" && t[0] != "vp" && t[0] != "f")
      throw_input_error(path, line_no, "keyword '" + std::string(t[0]) +
                                           "' is none of OBJ's v, vt, vn, vp and f (keywords are lower case)");
    if (t[0] == "v") {
      Eigen::Vector3d p;
      if (t.size() < 4 || !parse_double(t[1], p.x()) || !parse_double(t[2], p.y()) || !parse_double(t[3], p.z()))
        throw_input_error(path, line_no, "malformed vertex line (want 'v x y z'): '" + std::string(line) + "'");
      p *= scale;
      if (!p.allFinite()) throw_input_error(path, line_no, "vertex coordinate is not finite (after the scale)");
      if (p.cwiseAbs().maxCoeff() > kMaxObjCoordinate)
        throw_input_error(path, line_no,
                          "vertex " + std::to_string(mesh.x.size() + 1) + " lies " +
                              format_number(p.cwiseAbs().maxCoeff()) + " m out (after the scale " +
                              format_number(scale) + "): a gown spans about a metre");
      mesh.x.push_back(p);
      vertex_line.push_back(line_no);
    } else if (t[0] == "f") {
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
      check_fan(mesh, idx, path, line_no);
      for (size_t i = 1; i + 1 < idx.size(); ++i) {
        const std::array<int, 3> tri{idx[0], idx[i], idx[i + 1]};
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
          throw_input_error(path, line_no, "degenerate face (a vertex repeated)");
        mesh.triangles.push_back(tri);
        face_line.push_back(line_no);
      }
    }
  }
  if (mesh.triangles.empty()) throw_input_error(path, 0, "no faces");
  check_cloth_topology(mesh, face_line, vertex_line, path);
  mesh.boundary_loops = find_boundary_loops(mesh.triangles, static_cast<int>(mesh.x.size()));
  return mesh;
}

std::string to_obj(const GownMesh& mesh) {
  std::string out = std::string(kObjMetresHeader) + "\n";  // read_obj then takes it at scale 1
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
