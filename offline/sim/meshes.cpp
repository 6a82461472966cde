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

}  // namespace dressguard::sim
