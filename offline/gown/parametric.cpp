// The project's own gown, for running without shared/data: a hospital gown sewn from a T-shaped
// pattern (body panel with a short sleeve on each side), front and back layers, open at the back.
//
// Pattern frame (metres): X across the body, Y up, layer sigma = +1 front, -1 back.
//   body    X in [0, Wb],            Y in [0, Hb]
//   sleeves X in [-Ls, 0] and [Wb, Wb + Ls], Y in [Hb - Ws, Hb]
// Seams (front and back share the vertex): the body's sides below the armholes, each sleeve's
// underarm and top, the shoulders outside the neck. Not sewn: the hem, the neck, the cuffs and a
// two-cell slit down the middle of the back layer, so the boundary is one long loop (hem, back
// opening, neck) and the two cuffs: three loops, as the measured gown has.
// A square grid of spacing s (two triangles per cell, diagonals alternating) meshes the pattern.
//
// 3-D shape: the layers bulge apart by up to kBulge in the body (zero on the seams); each sleeve
// is a flattened tube hanging from its top seam (as a sleeve held by its top edge hangs), whose
// layers part from the armhole on into a lens of half-thickness kSleeveBulge; the cuff's
// perimeter is then 0.47 m (the measured openings: 0.473 and 0.477 m).
//
// Dimensions (cells of s = 11.75 mm): Wb = 56 (0.658 m), Hb = 93 (1.093 m), Ws = 19 (0.223 m),
// Ls = 17 (0.200 m), neck 22 (0.259 m); area 2 * (Wb Hb + 2 Ls Ws) - slit = 1.60 m^2 (measured
// 1.614), about 23k triangles, mean edge 1.34 cm (measured 1.4 cm).
//
// Placement in W: the right sleeve (pattern X > Wb) is the one the arm enters. Pattern X -> x_W,
// Y -> z_W, Z -> -y_W (a proper rotation), so the body hangs in the x-z plane behind the sleeve
// and the cuff faces +x, toward the fist. The cuff sits 1 cm ahead of the grasp box and the
// sleeve's top seam 3 cm above the lower jaw's starting face, so the closing jaws pick up the
// top of the sleeve (both layers, about 8 cm behind the rim) and lift it to the upper jaw; the
// opening then hangs open below the jaws, spanning the fist at the high setting (checked by a
// crude hang in tests/gown/placement_test.cpp). The measured gown is placed the same way by
// place_at_opening (placement.h); the paper's code grips it near the sleeve's root instead.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "gown.h"
#include "placement.h"

namespace dressguard::gown {
namespace {

constexpr double kCell = 0.01175;  // s [m]
constexpr int kWb = 56, kHb = 93, kWs = 19, kLs = 17, kNeck = 22, kSlit = 2;
constexpr double kBulge = 0.03;      // half the front-back separation in the body [m]
constexpr double kSleeveBulge = 0.0326;  // half-thickness of the sleeve's lens cross-section [m]
constexpr double kBlend = 0.08;      // sleeve length over which the flat start opens up [m]

double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

bool in_pattern_cell(int i, int j) {  // cell (i, j) spans grid points i..i+1, j..j+1
  if (j < 0 || j >= kHb) return false;
  if (i >= 0 && i < kWb) return true;
  const bool sleeve_rows = j >= kHb - kWs;
  return sleeve_rows && ((i >= -kLs && i < 0) || (i >= kWb && i < kWb + kLs));
}

bool back_cell(int i, int j) {  // the back layer misses the slit's cells
  const int slit_lo = kWb / 2 - kSlit / 2;
  return in_pattern_cell(i, j) && !(i >= slit_lo && i < slit_lo + kSlit);
}

bool seam_point(int i, int j) {
  const bool in_sleeve_x = (i >= -kLs && i <= 0) || (i >= kWb && i <= kWb + kLs);
  if ((i == 0 || i == kWb) && j >= 0 && j <= kHb - kWs) return true;         // body sides
  if (in_sleeve_x && (j == kHb - kWs || j == kHb)) return true;               // underarm, sleeve top
  const int neck_lo = (kWb - kNeck) / 2, neck_hi = neck_lo + kNeck;
  if (j == kHb && ((i >= 0 && i <= neck_lo) || (i >= neck_hi && i <= kWb))) return true;  // shoulders
  return false;
}

// Pattern point -> 3-D point in the pattern frame (X, Y, Z = front/back).
Eigen::Vector3d shape(int i, int j, int sigma) {
  const double x = i * kCell, y = j * kCell;
  const double Wb = kWb * kCell, Hb = kHb * kCell, Ws = kWs * kCell;
  // Body bulge: zero on the sides (sin) and toward the shoulders; the neck stays open.
  const int neck_lo = (kWb - kNeck) / 2, neck_hi = neck_lo + kNeck;
  const double into_neck = std::max(0.0, std::min(i - neck_lo, neck_hi - i) * kCell);
  const double shoulder = 1.0 - smoothstep(into_neck / 0.05);  // 1 on the shoulders, 0 inside the neck
  const double top = 1.0 - shoulder * (1.0 - smoothstep((Hb - y) / 0.15));
  const double xb = std::clamp(x, 0.0, Wb);
  const double z_flat = sigma * kBulge * std::sin(M_PI * xb / Wb) * top;
  if (x >= 0 && x <= Wb) return {x, y, z_flat};
  // Sleeve: a flattened tube hanging from its top seam, like a sleeve held up by its top edge:
  // the layers part as a lens of half-thickness kSleeveBulge (reached kBlend from the armhole).
  const double from_armhole = x < 0 ? -x : x - Wb;
  const double beta = smoothstep(from_armhole / kBlend);
  const double u = (y - (Hb - Ws)) / Ws;  // 0 underarm .. 1 top seam
  return {x, y, sigma * kSleeveBulge * beta * std::sin(M_PI * u)};
}

}  // namespace

GownMesh make_parametric_gown(const OpeningGrip& grip) {
  check_grip(grip);
  GownMesh mesh;
  std::map<std::array<int, 3>, int> index;  // (i, j, layer) -> vertex; seam points share layer 0
  auto vertex = [&](int i, int j, int sigma) {
    const std::array<int, 3> key{i, j, seam_point(i, j) ? 0 : sigma};
    const auto it = index.find(key);
    if (it != index.end()) return it->second;
    const int v = static_cast<int>(mesh.x.size());
    index.emplace(key, v);
    mesh.x.push_back(shape(i, j, seam_point(i, j) ? 1 : sigma));
    return v;
  };
  for (int sigma : {1, -1})
    for (int j = 0; j < kHb; ++j)
      for (int i = -kLs; i < kWb + kLs; ++i) {
        if (!(sigma > 0 ? in_pattern_cell(i, j) : back_cell(i, j))) continue;
        const int a = vertex(i, j, sigma), b = vertex(i + 1, j, sigma);
        const int c = vertex(i + 1, j + 1, sigma), d = vertex(i, j + 1, sigma);
        // Front faces point +Z, back faces -Z: the two layers make one oriented surface.
        auto add = [&](int p, int q, int w) {
          if (sigma > 0) mesh.triangles.push_back({p, q, w});
          else mesh.triangles.push_back({p, w, q});
        };
        if ((i + j) % 2 == 0) {
          add(a, b, c);
          add(a, c, d);
        } else {
          add(a, b, d);
          add(b, c, d);
        }
      }
  // Pattern -> W: X -> x, Y -> z, Z -> -y; the right cuff and the sleeve's top seam where the
  // jaws of the paper's scene find them.
  const PaperScene scene;
  const double cuff_x = (kWb + kLs) * kCell, top_y = kHb * kCell;
  // Where the sleeve sits relative to the jaws: the rule the measured gown's Opening placement
  // follows too (placement.h), with the grip's depth and the cuff's lead.
  const double cuff_W = opening_rim_x_W(scene, grip.rim_ahead), top_W = sleeve_top_z_W(scene, grip.depth);
  for (auto& p : mesh.x) p = Eigen::Vector3d(p.x() - cuff_x + cuff_W, -p.z(), p.y() - top_y + top_W);
  mesh.boundary_loops = find_boundary_loops(mesh.triangles, static_cast<int>(mesh.x.size()));
  label_sleeve(mesh);
  return mesh;
}

}  // namespace dressguard::gown
