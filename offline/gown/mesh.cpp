// Mesh queries: boundary loops, lumped masses, areas, edge lengths.
#include <algorithm>
#include <cstdint>
#include <map>
#include <stdexcept>

#include <Eigen/Geometry>

#include "gown.h"

namespace dressguard::gown {
namespace {

double triangle_area(const GownMesh& m, const std::array<int, 3>& t) {
  return 0.5 * (m.x[t[1]] - m.x[t[0]]).cross(m.x[t[2]] - m.x[t[0]]).norm();
}

uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(a) << 32) | static_cast<uint32_t>(b);
}

}  // namespace

std::vector<std::vector<int>> find_boundary_loops(const std::vector<std::array<int, 3>>& tris, int n_vertices) {
  // Every directed edge a->b as it appears in a triangle; an undirected edge used once is on the
  // boundary. Walking it in its triangle's direction orients every loop like the triangles.
  struct HalfEdge {
    uint64_t key;
    int a, b;
  };
  std::vector<HalfEdge> he;
  he.reserve(tris.size() * 3);
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (a < 0 || b < 0 || a >= n_vertices || b >= n_vertices)
        throw std::invalid_argument("find_boundary_loops: vertex index out of range");
      he.push_back({edge_key(a, b), a, b});
    }
  std::sort(he.begin(), he.end(), [](const HalfEdge& l, const HalfEdge& r) {
    return l.key != r.key ? l.key < r.key : (l.a != r.a ? l.a < r.a : l.b < r.b);
  });
  // Boundary edges per vertex, undirected (so a mesh whose triangles are not consistently
  // oriented still closes its loops); `forward` marks the direction a triangle walks the edge.
  struct Link {
    int to;
    bool forward;
    bool used;
  };
  std::vector<std::vector<Link>> links(n_vertices);
  for (size_t i = 0; i < he.size();) {
    size_t j = i;
    while (j < he.size() && he[j].key == he[i].key) ++j;
    if (j - i == 1) {
      links[he[i].a].push_back({he[i].b, true, false});
      links[he[i].b].push_back({he[i].a, false, false});
    }
    i = j;
  }
  auto take = [&](int from, int to) {  // marks edge {from, to} used in both lists
    for (auto& l : links[from])
      if (l.to == to && !l.used) {
        l.used = true;
        break;
      }
    for (auto& l : links[to])
      if (l.to == from && !l.used) {
        l.used = true;
        break;
      }
  };
  // The next unused boundary edge at v: the forward one (walk like the triangles) if any.
  auto next_from = [&](int v) {
    int pick = -1;
    for (const auto& l : links[v])
      if (!l.used) {
        if (l.forward) return l.to;
        if (pick < 0) pick = l.to;
      }
    return pick;
  };
  std::vector<std::vector<int>> loops;
  for (int start = 0; start < n_vertices; ++start) {
    for (int first = next_from(start); first >= 0; first = next_from(start)) {
      std::vector<int> loop{start};
      take(start, first);
      int cur = first;
      while (cur != start) {
        loop.push_back(cur);
        const int nxt = next_from(cur);
        if (nxt < 0) break;  // an open chain: cannot happen on a boundary of a surface
        take(cur, nxt);
        cur = nxt;
      }
      if (loop.size() >= 3) loops.push_back(std::move(loop));
    }
  }
  std::stable_sort(loops.begin(), loops.end(),
                   [](const std::vector<int>& l, const std::vector<int>& r) { return l.size() > r.size(); });
  return loops;
}

std::vector<double> vertex_masses(const GownMesh& mesh) {
  std::vector<double> m(mesh.x.size(), 0.0);
  for (const auto& t : mesh.triangles) {
    const double share = triangle_area(mesh, t) * mesh.areal_density / 3.0;
    for (int v : t) m[v] += share;
  }
  return m;
}

std::vector<int> vertices_in_box(const GownMesh& mesh, const Eigen::Vector3d& center_W,
                                 const Eigen::Vector3d& half_extent) {
  std::vector<int> out;
  for (int i = 0; i < static_cast<int>(mesh.x.size()); ++i)
    if (((mesh.x[i] - center_W).cwiseAbs() - half_extent).maxCoeff() <= 0) out.push_back(i);
  return out;
}

double total_area(const GownMesh& mesh) {
  double a = 0;
  for (const auto& t : mesh.triangles) a += triangle_area(mesh, t);
  return a;
}

double loop_perimeter(const GownMesh& mesh, int loop) {
  const auto& L = mesh.boundary_loops.at(loop);
  double p = 0;
  for (size_t i = 0; i < L.size(); ++i) p += (mesh.x[L[(i + 1) % L.size()]] - mesh.x[L[i]]).norm();
  return p;
}

Eigen::Vector3d loop_centroid(const GownMesh& mesh, int loop) {
  const auto& L = mesh.boundary_loops.at(loop);
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int v : L) c += mesh.x[v];
  return L.empty() ? c : c / static_cast<double>(L.size());
}

double mean_edge_length(const GownMesh& mesh) {
  std::vector<uint64_t> keys;
  keys.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) keys.push_back(edge_key(t[k], t[(k + 1) % 3]));
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  double sum = 0;
  for (uint64_t k : keys) sum += (mesh.x[k >> 32] - mesh.x[k & 0xffffffffu]).norm();
  return keys.empty() ? 0 : sum / static_cast<double>(keys.size());
}

}  // namespace dressguard::gown
