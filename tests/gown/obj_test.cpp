// OBJ reading on small files written here: forms of the face line, fan triangulation, errors
// that name file:line, and the boundary loops of known shapes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <unistd.h>

#include "files.h"
#include "gown.h"

namespace fs = std::filesystem;
using namespace dressguard;
using namespace dressguard::gown;

namespace {

fs::path write_obj(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("dg_gown_test_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p) << text;
  return p;
}

// The InputError message of read_obj on `text` ("" when it does not throw).
std::string error_of(const std::string& name, const std::string& text) {
  const fs::path p = write_obj(name, text);
  std::string msg;
  try {
    read_obj(p, 1.0);
  } catch (const InputError& e) {
    msg = e.what();
  }
  fs::remove(p);
  return msg;
}

// A file read_obj must refuse, and what its error must say after the file's name.
struct ErrorCase {
  const char* name;
  std::string text, want;
};

void expect_errors(const std::vector<ErrorCase>& cases) {
  for (const auto& c : cases) {
    const std::string e = error_of(c.name, c.text);
    EXPECT_NE(e.find(c.name + c.want), std::string::npos) << "want '" << c.want << "', got '" << e << "'";
  }
}

// An n x n grid of unit squares as an OBJ, each square one quad face.
std::string grid_obj(int n, double h) {
  std::string s;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) s += "v " + std::to_string(i * h) + " " + std::to_string(j * h) + " 0\n";
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i + 1;
      s += "f " + std::to_string(a) + " " + std::to_string(a + 1) + " " + std::to_string(a + n + 2) + " " +
           std::to_string(a + n + 1) + "\n";
    }
  return s;
}

}  // namespace

TEST(ReadObj, AcceptsEveryFaceFormAndNegativeIndices) {
  // A 2 x 1 strip of unit squares (vertices 1-3 at y = 0, 4-6 at y = 1), its four triangles
  // four ways: plain, v/vt/vn, v//vn, negative; plus comments, normals, blank lines, a
  // byte-order mark, an indented vertex line and CRLF line ends.
  const std::string text =
      "\xEF\xBB\xBF# strip\r\nv 0 0 0\nv 1 0 0\nv 2 0 0\n\tv 0 1 0\nv 1 1 0\nv 2 1 0\r\nvn 0 0 1\nvt 0 0\n\n"
      "f 1 2 5\nf 1/1/1 5/1/1 4/1/1\nf 2//1 3//1 6//1\nf -5 -1 -2\ng group\ns off\n";
  const fs::path p = write_obj("forms.obj", text);
  const GownMesh m = read_obj(p, 2.0);
  fs::remove(p);
  ASSERT_EQ(m.x.size(), 6u);
  ASSERT_EQ(m.triangles.size(), 4u);
  EXPECT_EQ(m.triangles[1], (std::array<int, 3>{0, 4, 3}));
  EXPECT_EQ(m.triangles[3], (std::array<int, 3>{1, 5, 4}));  // -5 -1 -2 after 6 vertices
  EXPECT_DOUBLE_EQ(m.x[3].y(), 2.0);                         // the indented line; scaled by 2
  EXPECT_DOUBLE_EQ(m.x[4].x(), 2.0);
  EXPECT_NEAR(total_area(m), 8.0, 1e-12);                    // 2 unit squares, times 2^2
}

TEST(ReadObj, FanTriangulatesPolygonsAndKeepsArea) {
  // A regular hexagon as one face: 4 triangles, area 3 sqrt(3)/2 r^2 (exact, a planar fan).
  std::string text;
  for (int k = 0; k < 6; ++k)
    text += "v " + std::to_string(std::cos(k * M_PI / 3)) + " " + std::to_string(std::sin(k * M_PI / 3)) + " 0\n";
  text += "f 1 2 3 4 5 6\n";
  const fs::path p = write_obj("hex.obj", text);
  const GownMesh m = read_obj(p, 1.0);
  fs::remove(p);
  EXPECT_EQ(m.triangles.size(), 4u);
  EXPECT_NEAR(total_area(m), 1.5 * std::sqrt(3.0), 1e-5);  // 1e-5: coordinates printed with 6 digits
  ASSERT_EQ(m.boundary_loops.size(), 1u);
  EXPECT_EQ(m.boundary_loops[0].size(), 6u);
}

TEST(ReadObj, ErrorsNameFileAndLine) {
  EXPECT_NE(error_of("a.obj", "v 0 0 0\nv 1 0\n").find("a.obj"), std::string::npos);
  EXPECT_NE(error_of("a.obj", "v 0 0 0\nv 1 0\n").find(":2:"), std::string::npos);  // short vertex
  EXPECT_NE(error_of("b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").find(":4:"), std::string::npos);  // range
  EXPECT_NE(error_of("c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n").find(":4:"), std::string::npos);  // 2 vertices
  EXPECT_NE(error_of("d.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n").find(":4:"), std::string::npos);  // not a number
  EXPECT_NE(error_of("e.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n").find(":4:"), std::string::npos);  // index 0
  EXPECT_NE(error_of("f.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").find(":1:"), std::string::npos);
  EXPECT_NE(error_of("g.obj", "v 0 0 0\n").find("no faces"), std::string::npos);
  EXPECT_NE(error_of("h.obj", "v 0 0 0\nv 1 0 0\nf 1 2 1\n").find(":3:"), std::string::npos);  // degenerate
  EXPECT_THROW(read_obj("/nonexistent/gown.obj", 1.0), InputError);
}

// What a cloth mesh cannot be, each named at the face's line: a triangle of zero area, the same
// triangle twice (also a quad folded onto itself), an edge of three faces; an upper-case
// keyword; a vertex a unit slip put kilometres out, or a scale that overflows.
TEST(ReadObj, RejectsWhatTheSimulatorCannotTake) {
  const std::string square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 0.5 0 0\nf 1 2 3\nf 1 3 4\n";
  expect_errors({
      {"area.obj", square + "f 1 6 2\n", ":9: face of area 0"},
      {"twice.obj", square + "f 3 2 1\n", ":9: the same triangle as line 7"},
      {"folded.obj", square + "f 2 5 3 5\n", ":9: the same triangle as line 9"},
      {"fan.obj", square + "f 1 3 5\n", ":9: edge 1-3 is shared by three faces (lines 7, 8 and this one)"},
      {"upper.obj", "v 0 0 0\nV 1 0 0\nv 1 1 0\nf 1 2 3\n", ":2: keyword 'V'"},
      {"far.obj", "v 0 0 0\nv 1000 0 0\nv 0 1 0\nf 1 2 3\n", ":2: vertex 2 lies 1000"},
  });
  const fs::path p = write_obj("scale.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_THROW(read_obj(p, 1e307), InputError);
  EXPECT_THROW(read_obj(p, std::numeric_limits<double>::infinity()), InputError);  // not a finite scale either
  fs::remove(p);
}

// What else a cloth cannot be, each named at the vertex's line: a vertex where two fans of
// triangles meet only at it, and a vertex no face uses. A 3 x 3 grid of unit squares without its
// centre square and its corner square (2, 2) has a hole that touches the outer boundary at vertex
// 11: the boundary walk went through it twice and merged the two loops into one; a bowtie (two
// triangles sharing a vertex) is the same; an unused vertex was a particle without mass that
// counted in the placement's centroid (finding 5 of session 85's gown review).
TEST(ReadObj, RejectsPinchedAndUnusedVertices) {
  // The grid without its centre square, and with `corner` without square (2, 2) and vertex 16.
  auto holed = [](bool corner) {
    std::string s;
    for (int v = 0; v < (corner ? 15 : 16); ++v)
      s += "v " + std::to_string(v % 4) + " " + std::to_string(v / 4) + " 0\n";
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        if ((i == 1 && j == 1) || (corner && i == 2 && j == 2)) continue;
        const std::string a = std::to_string(j * 4 + i + 1), b = std::to_string(j * 4 + i + 2),
                          c = std::to_string(j * 4 + i + 6), d = std::to_string(j * 4 + i + 5);
        s += "f " + a + " " + b + " " + c + "\nf " + a + " " + c + " " + d + "\n";
      }
    return s;
  };
  const std::string square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  expect_errors({
      {"pinch.obj", holed(true), ":11: vertex 11 is pinched: its faces form 2 fans that meet only there"},
      {"bowtie.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv -1 0 0\nv -1 -1 0\nf 1 2 3\nf 1 4 5\n", ":1: vertex 1 is pinched"},
      {"unused.obj", square + "v 5 5 5\nf 1 2 3\nf 1 3 4\n", ":5: vertex 5 is used by no face"},
  });
  // A hole that touches nothing is a cloth: two loops, 12 and 4 vertices.
  const fs::path p = write_obj("annulus.obj", holed(false));
  const GownMesh m = read_obj(p, 1.0);
  fs::remove(p);
  ASSERT_EQ(m.boundary_loops.size(), 2u);
  EXPECT_EQ(m.boundary_loops[0].size(), 12u);
  EXPECT_EQ(m.boundary_loops[1].size(), 4u);
}

// The text (finding 6 of session 85's gown review): any isspace blank separates words (a 'v'
// glued to a vertical tab or form feed was an unknown keyword, its line skipped and every later
// index shifted), '#' starts a comment anywhere on a line (an inline one was read as a vertex
// reference), a subnormal coordinate is a coordinate (strtod's ERANGE refused it), and a lone CR
// ends a line (a classic Mac file read as one line: "no faces").
TEST(ReadObj, BlanksCommentsSubnormalsAndLoneCarriageReturns) {
  struct Case { const char* name; std::string text; };
  const Case cases[] = {
      {"blanks.obj", "v 0 0 0\nv 1 0 0\nv\v0 1 0\nv\f1 1 0\nf 1 2 3\nf 2 4 3\n"},
      {"comments.obj", "v 0 0 0 # origin\nv 1 0 0\nv 0 1 0\nv 1 1 0#\nf 1 2 3 # the first face\nf 2 4 3\n"},
      {"subnormal.obj", "v 0 0 1e-320\nv 1 0 1e-400\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n"},
      {"cr.obj", "v 0 0 0\rv 1 0 0\rv 0 1 0\rv 1 1 0\rf 1 2 3\rf 2 4 3\r"},
  };
  for (const auto& c : cases) {
    const fs::path p = write_obj(c.name, c.text);
    GownMesh m;
    EXPECT_NO_THROW(m = read_obj(p, 1.0)) << c.name;
    fs::remove(p);
    ASSERT_EQ(m.x.size(), 4u) << c.name;
    EXPECT_EQ(m.triangles, (std::vector<std::array<int, 3>>{{0, 1, 2}, {1, 3, 2}})) << c.name;
    EXPECT_EQ(m.x[2], Eigen::Vector3d(0, 1, 0)) << c.name;
    EXPECT_NEAR(total_area(m), 1.0, 1e-12) << c.name;
  }
  const fs::path p = write_obj("subnormal.obj", cases[2].text);
  EXPECT_EQ(read_obj(p, 1.0).x[0].z(), 1e-320);
  fs::remove(p);
  EXPECT_NE(error_of("cr2.obj", "v 0 0 0\rv 1 0\r").find("cr2.obj:2: malformed vertex line"), std::string::npos);
  EXPECT_NE(error_of("huge.obj", "v 1e400 0 0\n").find("huge.obj:1: malformed vertex line"), std::string::npos);
}

// A word that begins with v or f but is no OBJ keyword is refused at its line, as upper case
// always was: skipped, "v0.5 1 0" shifted every later index and "fo" (an old spelling of f) lost
// its faces. A polygon whose fan from its first corner folds (a concave one whose first corner
// does not see the others) is refused at its line: it gave overlapping triangles, one flipped.
TEST(ReadObj, RejectsSlippedKeywordsAndFoldedFans) {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  // A square with a notch: corner 4 is reflex. Fanned from corner 1 triangle 1 3 4 is flipped;
  // fanned from corner 4, which sees them all, it is the polygon's area, 4 - 1.8.
  const std::string notched = "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 1 0.2 0\nv 0 2 0\n";
  expect_errors({
      {"glued.obj", tri + "v0.5 1 0\nf 1 2 3\n", ":4: keyword 'v0.5' is none of OBJ's v, vt, vn, vp and f"},
      {"fo.obj", tri + "fo 1 2 3\n", ":4: keyword 'fo'"},
      {"mixed.obj", tri + "vT 0 0\nf 1 2 3\n", ":4: keyword 'vT'"},
      {"upper.obj", tri + "F 1 2 3\n", ":4: keyword 'F'"},
      {"concave.obj", notched + "f 1 2 3 4 5\n",
       ":6: polygon of 5 corners is not convex: fanned from its first corner, triangles 1 2 3 and 1 3 4 face "
       "opposite ways"},
  });
  const fs::path p = write_obj("seen.obj", notched + "f 4 5 1 2 3\n");
  const GownMesh m = read_obj(p, 1.0);
  fs::remove(p);
  EXPECT_EQ(m.triangles.size(), 3u);
  EXPECT_NEAR(total_area(m), 2.2, 1e-12);
}

TEST(BoundaryLoops, GridHasOneOrderedLoopOfItsPerimeter) {
  const fs::path p = write_obj("grid.obj", grid_obj(5, 0.1));
  const GownMesh m = read_obj(p, 1.0);
  fs::remove(p);
  ASSERT_EQ(m.boundary_loops.size(), 1u);
  EXPECT_EQ(m.boundary_loops[0].size(), 20u);  // 4 sides x 5 edges
  // Ordered: consecutive loop vertices are one grid step apart (0.1), so the perimeter is 2.0.
  EXPECT_NEAR(loop_perimeter(m, 0), 2.0, 1e-9);
  EXPECT_NEAR(total_area(m), 0.25, 1e-9);
}

TEST(BoundaryLoops, AnnulusHasTwoLoopsLongestFirst) {
  // A 4x4 grid with the middle 2x2 squares removed: outer loop 16 edges, inner 8 edges.
  std::vector<std::array<int, 3>> tris;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      if (i >= 1 && i <= 2 && j >= 1 && j <= 2) continue;
      const int a = j * 5 + i;
      tris.push_back({a, a + 1, a + 6});
      tris.push_back({a, a + 6, a + 5});
    }
  const auto loops = find_boundary_loops(tris, 25);
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_EQ(loops[0].size(), 16u);
  EXPECT_EQ(loops[1].size(), 8u);
}

TEST(BoundaryLoops, InconsistentOrientationStillClosesTheLoop) {
  // A unit square as two triangles, the second one flipped: one loop of 4 all the same.
  const auto loops = find_boundary_loops({{0, 1, 2}, {0, 3, 2}}, 4);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0].size(), 4u);
}

TEST(Masses, LumpedMassesSumToAreaTimesDensity) {
  const fs::path p = write_obj("grid.obj", grid_obj(4, 0.25));
  GownMesh m = read_obj(p, 1.0);
  fs::remove(p);
  m.areal_density = 0.145;
  const auto mass = vertex_masses(m);
  double sum = 0;
  for (double v : mass) sum += v;
  EXPECT_NEAR(sum, 0.145 * 1.0, 1e-12);  // exact up to rounding
  // A corner vertex touches one or two of the 32 triangles (area 1/32 each): 1/3 or 2/3 of one.
  EXPECT_GT(mass[0], 0.0);
  EXPECT_LE(mass[0], 2.0 / 3.0 * 0.145 / 32 + 1e-15);
}

TEST(Box, VerticesInBoxIsInclusiveAndAxisAligned) {
  const fs::path p = write_obj("grid.obj", grid_obj(4, 0.25));
  const GownMesh m = read_obj(p, 1.0);
  fs::remove(p);
  // Centre (0.5, 0.5), half 0.25: the 3 x 3 grid points 0.25..0.75.
  EXPECT_EQ(vertices_in_box(m, {0.5, 0.5, 0}, {0.25, 0.25, 0.01}).size(), 9u);
  EXPECT_EQ(vertices_in_box(m, {0.5, 0.5, 1}, {0.25, 0.25, 0.01}).size(), 0u);
}

TEST(ToObj, RoundTripsThroughReadObj) {
  const fs::path p = write_obj("grid.obj", grid_obj(3, 0.2));
  const GownMesh m = read_obj(p, 1.0);
  const fs::path q = write_obj("grid2.obj", to_obj(m));
  const GownMesh n = read_obj(q, 1.0);
  fs::remove(p);
  fs::remove(q);
  ASSERT_EQ(n.x.size(), m.x.size());
  ASSERT_EQ(n.triangles, m.triangles);
  for (size_t i = 0; i < m.x.size(); ++i) EXPECT_NEAR((n.x[i] - m.x[i]).norm(), 0, 1e-6);  // 6 printed digits
}

// A file to_obj wrote says on its first line that it is in metres: read_obj takes it at scale 1
// unless told, and refuses any other scale at that line. `gown --obj OUT` read the placed gown
// back with the measured gown's 1.679 and went on with a 4.55 m^2 gown (session 85's gown review).
// Any other file keeps the measured gown's default scale, and so does one whose first line is not
// the header, word for word.
TEST(ToObj, AFileInMetresIsReadAtScaleOneAndRefusesAnother) {
  const fs::path p = write_obj("grid.obj", grid_obj(3, 0.2));
  const GownMesh m = read_obj(p, 1.0);
  const std::string text = to_obj(m);
  ASSERT_EQ(text.rfind(std::string(kObjMetresHeader) + "\n", 0), 0u);
  const std::string body = text.substr(kObjMetresHeader.size() + 1);
  const std::string crlf_header = std::string(kObjMetresHeader) + " \r\n";
  for (const std::string& in_metres : {text, "\xEF\xBB\xBF" + text, crlf_header + body}) {
    const fs::path q = write_obj("metres.obj", in_metres);
    const GownMesh n = read_obj(q);
    ASSERT_EQ(n.x.size(), m.x.size());
    for (size_t i = 0; i < m.x.size(); ++i) EXPECT_NEAR((n.x[i] - m.x[i]).norm(), 0, 1e-6);
    EXPECT_EQ(read_obj(q, 1.0).x, n.x);
    for (const double scale : {kMeasuredGownScale, 2.0, 0.999}) {
      try {
        read_obj(q, scale);
        ADD_FAILURE() << "a file in metres read at scale " << scale;
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(q.string() + ":1: the file says it is in metres"), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("not " + format_number(scale)), std::string::npos) << e.what();
      }
    }
    fs::remove(q);
  }
  // Not the header: the measured gown's scale by default, and any scale asked for.
  const std::string first_line_off = std::string(kObjMetresHeader).substr(0, kObjMetresHeader.size() - 1) + "\n";
  for (const std::string& other : {body, "# a comment\n" + text, first_line_off + body}) {
    const fs::path q = write_obj("units.obj", other);
    const GownMesh n = read_obj(q);
    ASSERT_EQ(n.x.size(), m.x.size());
    EXPECT_EQ(n.x, read_obj(q, kMeasuredGownScale).x);
    EXPECT_NEAR(n.x[1].x(), kMeasuredGownScale * m.x[1].x(), 1e-6);
    EXPECT_NEAR(read_obj(q, 2.0).x[1].x(), 2 * m.x[1].x(), 1e-6);
    fs::remove(q);
  }
  fs::remove(p);
}
