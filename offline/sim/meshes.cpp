#include "meshes.h"

#include <cmath>
#include <numbers>

namespace dressguard::sim {

namespace {

// Quad p q / r s (p, q along u; r, s the next row) as two triangles, split along p-s or q-r by
// `parity`: alternating diagonals keep a grid free of a preferred shear direction.
void add_quad(ClothMesh& m, int p, int q, int r, int s, int parity) {
  if (parity == 0) {
    m.tris.push_back({p, q, s});
    m.tris.push_back({p, s, r});
  } else {
    m.tris.push_back({p, q, r});
    m.tris.push_back({q, s, r});
  }
}

}  // namespace

ClothMesh grid_patch(std::array<double, 3> o, std::array<double, 3> a, std::array<double, 3> b, int nu, int nv) {
  ClothMesh m;
  m.name = "patch";
  for (int iv = 0; iv < nv; ++iv)
    for (int iu = 0; iu < nu; ++iu) {
      const double su = nu > 1 ? double(iu) / (nu - 1) : 0, sv = nv > 1 ? double(iv) / (nv - 1) : 0;
      m.x.push_back({o[0] + su * a[0] + sv * b[0], o[1] + su * a[1] + sv * b[1], o[2] + su * a[2] + sv * b[2]});
    }
  for (int iv = 0; iv + 1 < nv; ++iv)
    for (int iu = 0; iu + 1 < nu; ++iu) {
      const int p = iv * nu + iu;
      add_quad(m, p, p + 1, p + nu, p + nu + 1, (iu + iv) % 2);
    }
  return m;
}

namespace {

// Rings around a centreline: centre(v), tangent frame (ey and e2 = t x ey), radius(v).
template <class F>
ClothMesh ring_mesh(int nu, int nv, F&& ring) {
  ClothMesh m;
  for (int iv = 0; iv < nv; ++iv)
    for (int iu = 0; iu < nu; ++iu) m.x.push_back(ring(iv, iu));
  for (int iv = 0; iv + 1 < nv; ++iv)
    for (int iu = 0; iu < nu; ++iu) {
      const int p = iv * nu + iu, q = iv * nu + (iu + 1) % nu;
      add_quad(m, p, q, p + nu, q + nu, (iu + iv) % 2);
    }
  return m;
}

}  // namespace

ClothMesh tube(double r, double x0, double x1, int nu, int nv) {
  ClothMesh m = ring_mesh(nu, nv, [&](int iv, int iu) {
    const double th = 2 * std::numbers::pi * iu / nu;
    const double x = x0 + (x1 - x0) * iv / (nv - 1);
    return std::array<double, 3>{x, r * std::cos(th), r * std::sin(th)};
  });
  m.name = "tube";
  return m;
}

ClothMesh sleeve_gown(int nu, int nv) {
  const double pi = std::numbers::pi;
  const double r_cuff = 0.075, r_body = 0.22, sleeve = 0.45, bend_r = 0.15, body = 0.6;
  const double bend_len = 0.5 * pi * bend_r;
  const double total = sleeve + bend_len + body;
  ClothMesh m = ring_mesh(nu, nv, [&](int iv, int iu) {
    const double s = total * iv / (nv - 1);
    // Centreline from the cuff centre (0, 0, -r_cuff): along -x, a quarter bend down, then -z.
    double cx, cz, tx, tz, r;
    if (s <= sleeve) {
      cx = -s; cz = -r_cuff; tx = -1; tz = 0; r = r_cuff;
    } else if (s <= sleeve + bend_len) {
      const double a = (s - sleeve) / bend_r;  // 0 .. pi/2
      cx = -sleeve - bend_r * std::sin(a);
      cz = -r_cuff - bend_r * (1 - std::cos(a));
      tx = -std::cos(a); tz = -std::sin(a);
      r = r_cuff + (r_body - r_cuff) * 0.3 * (a / (0.5 * pi));
    } else {
      const double b = (s - sleeve - bend_len) / body;
      cx = -sleeve - bend_r; cz = -r_cuff - bend_r - (s - sleeve - bend_len);
      tx = 0; tz = -1;
      r = r_cuff + (r_body - r_cuff) * (0.3 + 0.7 * b);
    }
    // Ring frame: e1 = +y, e2 = t x e1 (in the x-z plane); angle 0 at the top of the cuff.
    const double e2x = -tz, e2z = tx;  // t x ey = (tx,0,tz) x (0,1,0) = (-tz, 0, tx)
    const double th = 2 * pi * iu / nu;
    const double c = std::cos(th), sn = std::sin(th);
    // top of the ring (th = 0) along +z at the cuff: e2 = (0,0,-1) there, so use -e2 for "up".
    return std::array<double, 3>{cx - r * c * e2x, r * sn, cz - r * c * e2z};
  });
  m.name = "sleeve-gown";
  for (int iu = 0; iu < nu; ++iu) m.sleeve_opening.push_back(iu);
  return m;
}

}  // namespace dressguard::sim
