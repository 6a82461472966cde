// Building the constant model (SceneData, GownModel) and the preallocated state.
#include "model.h"

#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>
#include <string>

namespace dressguard::sim {

RoundCone make_round_cone(V3 a, double ra, V3 b, double rb) {
  RoundCone c;
  c.a = a;
  c.b = b;
  c.ra = ra;
  c.rb = rb;
  const V3 d = b - a;
  c.len = norm(d);
  if (c.len > 1e-12) {
    c.u = (1.0 / c.len) * d;
    // A round cone needs |ra - rb| < L (otherwise one sphere contains the other).
    c.sin_phi = std::clamp((ra - rb) / c.len, -0.999, 0.999);
    c.cos_phi = std::sqrt(1 - c.sin_phi * c.sin_phi);
  } else {
    c.u = {1, 0, 0};
    c.len = 0;
  }
  return c;
}

// In the plane of the axis and p: x along the axis from a, y >= 0 radial. The cone's surface
// line touches sphere a at a + ra (sin phi, cos phi) and sphere b at b + rb (sin phi, cos phi);
// the foot of p on that line is s = x cos phi - y sin phi from a's touching point, so
// s < 0 -> nearest to sphere a, s > L cos phi -> sphere b, else the cone: x sin phi + y cos phi - ra.
double round_cone_distance(const RoundCone& c, V3 p, V3* normal) {
  const V3 q = p - c.a;
  if (c.len == 0) {
    const double l = norm(q);
    *normal = l > 1e-15 ? (1.0 / l) * q : V3{0, 0, 1};
    return l - c.ra;
  }
  const double x = dot(q, c.u);
  const V3 radial = q - x * c.u;
  const double y = norm(radial);
  const V3 rhat = y > 1e-15 ? (1.0 / y) * radial : V3{0, 0, 1};
  const double s = x * c.cos_phi - y * c.sin_phi;
  if (s < 0) {
    const double l = norm(q);
    *normal = l > 1e-15 ? (1.0 / l) * q : rhat;
    return l - c.ra;
  }
  if (s > c.len * c.cos_phi) {
    const V3 qb = p - c.b;
    const double l = norm(qb);
    *normal = l > 1e-15 ? (1.0 / l) * qb : rhat;
    return l - c.rb;
  }
  *normal = c.sin_phi * c.u + c.cos_phi * rhat;
  return x * c.sin_phi + y * c.cos_phi - c.ra;
}

namespace {

double cot(V3 a, V3 b) {
  const double s = norm(cross(a, b));
  return s > 1e-18 ? dot(a, b) / s : 0.0;
}

// Reorders constraints by a greedy graph colouring (no two constraints of one colour share a
// vertex), stable within a colour. This is still one fixed Gauss-Seidel order (deterministic),
// but consecutive constraints no longer wait for each other's writes, so the CPU overlaps them
// (measured: about 2x on the solve), and a group's constraints can be solved 4 at a time (SIMD).
// Returns the groups' starts and the list's end. Colour 63 takes whatever does not fit in 63
// colours and may share vertices; make_model() checks every SIMD block anyway.
template <class C, class VertsOf>
std::vector<int32_t> colour_order(std::vector<C>& cs, int n_vertices, VertsOf verts) {
  std::vector<uint64_t> used(n_vertices, 0);
  std::vector<int> colour(cs.size(), 0);
  for (size_t k = 0; k < cs.size(); ++k) {
    uint64_t mask = 0;
    for (int v : verts(cs[k])) mask |= used[v];
    int c = 0;
    while (c < 63 && (mask >> c) & 1) ++c;
    colour[k] = c;
    for (int v : verts(cs[k])) used[v] |= uint64_t{1} << c;
  }
  std::vector<size_t> idx(cs.size());
  for (size_t k = 0; k < idx.size(); ++k) idx[k] = k;
  std::stable_sort(idx.begin(), idx.end(), [&](size_t a, size_t b) { return colour[a] < colour[b]; });
  std::vector<C> out;
  out.reserve(cs.size());
  std::vector<int32_t> starts;
  for (size_t r = 0; r < idx.size(); ++r) {
    if (r == 0 || colour[idx[r]] != colour[idx[r - 1]]) starts.push_back(static_cast<int32_t>(r));
    out.push_back(cs[idx[r]]);
  }
  starts.push_back(static_cast<int32_t>(cs.size()));
  cs.swap(out);
  return starts;
}

struct HalfEdge {
  int32_t a, b, tri, opp;
};

}  // namespace

// The arm's colliders and their names (ArmPartLoads order), one list so that they cannot drift.
std::vector<RoundCone> arm_colliders(const SceneOptions& opt, double fist_shift, double fist_lateral,
                                     std::vector<std::string>* names) {
  const ArmGeometry& g = opt.arm;
  const V3 gp{opt.grasp_point[0], opt.grasp_point[1], opt.grasp_point[2]};
  const V3 fist0 = gp + V3{g.fist_x, 0, g.z_rel[0]};
  const V3 elbow = fist0 + V3{g.hand, 0, 0} + V3{g.forearm, 0, 0};
  const V3 fist = fist0 + V3{fist_shift, fist_lateral, 0};  // fist0 itself when both are 0
  const V3 wrist = fist + V3{g.hand, 0, 0};
  const V3 shoulder = elbow + V3{0, -g.upper_arm, 0};
  std::vector<RoundCone> arm;
  auto add = [&](const char* name, const RoundCone& c) {
    arm.push_back(c);
    if (names) names->push_back(name);
  };
  add("elbow", make_round_cone(elbow, g.r_elbow, elbow, g.r_elbow));  // [0] elbow (label reference)
  add("fist", make_round_cone(fist, g.r_fist, fist, g.r_fist));
  if (g.hand > 1e-9) add("hand", make_round_cone(fist, g.r_fist, wrist, g.r_wrist));
  add("forearm", make_round_cone(wrist, g.r_wrist, elbow, g.r_elbow));
  add("upper_arm", make_round_cone(elbow, g.r_elbow, shoulder, g.r_shoulder));
  static_assert(kArmParts >= 5, "arm_colliders makes up to five colliders");
  return arm;
}

RoundCone support_collider(const SceneOptions& opt, const ClothParams& p) {
  const V3 gp{opt.grasp_point[0], opt.grasp_point[1], opt.grasp_point[2]};
  const V3 mid = gp + V3{0, p.support_lateral, -p.support_depth};
  return make_round_cone(mid - V3{kSupportBehind, 0, 0}, kSupportRadius, mid + V3{kSupportAhead, 0, 0}, kSupportRadius);
}

const char* friction_scheme_name(FrictionScheme s) {
  switch (s) {
    case FrictionScheme::Stock: return "stock";
    case FrictionScheme::Improved: return "improved";
    case FrictionScheme::Constraint: return "constraint";
  }
  return "?";
}

bool parse_friction_scheme(const std::string& name, FrictionScheme* out) {
  for (FrictionScheme f : {FrictionScheme::Stock, FrictionScheme::Improved, FrictionScheme::Constraint})
    if (name == friction_scheme_name(f)) {
      *out = f;
      return true;
    }
  return false;
}

int Scene::vertex_count() const { return static_cast<int>(d_->rest.size()); }
int Scene::triangle_count() const { return static_cast<int>(d_->mesh.tris.size()); }
double Scene::gown_mass() const { return d_->rest_area * ClothParams{}.areal_density; }
const ClothMesh& Scene::mesh() const { return d_->mesh; }

std::vector<std::string> arm_part_names(const Scene& scene) { return scene.data().arm_names; }

Scene make_scene(const ClothMesh& mesh, const SceneOptions& opt) {
  auto d = std::make_shared<SceneData>();
  d->mesh = mesh;
  d->opt = opt;
  const int n = static_cast<int>(mesh.x.size());
  if (n == 0 || mesh.tris.empty()) throw std::invalid_argument("make_scene: mesh '" + mesh.name + "' is empty");
  if (opt.substeps < 1 || opt.step_hz <= 0) throw std::invalid_argument("make_scene: substeps and step_hz must be positive");
  d->rest.resize(n);
  for (int i = 0; i < n; ++i) d->rest[i] = {mesh.x[i][0], mesh.x[i][1], mesh.x[i][2]};
  d->vertex_area.assign(n, 0.0);
  std::vector<HalfEdge> he;
  he.reserve(mesh.tris.size() * 3);
  for (size_t t = 0; t < mesh.tris.size(); ++t) {
    const auto& tr = mesh.tris[t];
    for (int k = 0; k < 3; ++k)
      if (tr[k] < 0 || tr[k] >= n)
        throw std::invalid_argument("make_scene: triangle " + std::to_string(t) + " has vertex index " +
                                    std::to_string(tr[k]) + " outside 0.." + std::to_string(n - 1));
    const V3 a = d->rest[tr[0]], b = d->rest[tr[1]], c = d->rest[tr[2]];
    const double area = 0.5 * norm(cross(b - a, c - a));
    d->rest_area += area;
    {
      // Rest frame: e1 along the first edge, e2 perpendicular in the plane; Dm = [[l1, p], [0, q]].
      const double l1 = norm(b - a);
      if (l1 > 1e-12 && area > 1e-14) {
        const V3 e1 = (1.0 / l1) * (b - a);
        const double p = dot(c - a, e1);
        const double q = 2 * area / l1;
        ShearTri st{{tr[0], tr[1], tr[2]}, {1.0 / l1, -p / (l1 * q), 0.0, 1.0 / q}, area};
        d->shear.push_back(st);
      }
    }
    for (int k = 0; k < 3; ++k) d->vertex_area[tr[k]] += area / 3;
    for (int k = 0; k < 3; ++k) {
      const int32_t u = tr[k], v = tr[(k + 1) % 3], o = tr[(k + 2) % 3];
      he.push_back({std::min(u, v), std::max(u, v), static_cast<int32_t>(t), o});
    }
  }
  std::sort(he.begin(), he.end(), [](const HalfEdge& p, const HalfEdge& q) {
    return p.a != q.a ? p.a < q.a : p.b != q.b ? p.b < q.b : p.tri < q.tri;
  });
  for (size_t k = 0; k < he.size();) {
    size_t e = k + 1;
    while (e < he.size() && he[e].a == he[k].a && he[e].b == he[k].b) ++e;
    const int32_t i = he[k].a, j = he[k].b;
    d->stretch.push_back({i, j, norm(d->rest[i] - d->rest[j])});
    if (e - k >= 2) {  // interior edge: a bending stencil (first two triangles)
      const int32_t o2 = he[k].opp, o3 = he[k + 1].opp;
      const V3 x0 = d->rest[i], x1 = d->rest[j], x2 = d->rest[o2], x3 = d->rest[o3];
      const V3 e0 = x1 - x0, e1 = x2 - x0, e2 = x3 - x0, e3 = x2 - x1, e4 = x3 - x1;
      const double a0 = 0.5 * norm(cross(e0, e1)), a1 = 0.5 * norm(cross(e0, e2));
      if (a0 > 1e-14 && a1 > 1e-14) {
        const double c01 = cot(e0, e1), c02 = cot(e0, e2), c03 = cot((-1.0) * e0, e3), c04 = cot((-1.0) * e0, e4);
        const double sc = std::sqrt(3.0 / (a0 + a1));
        BendStencil b{{i, j, o2, o3}, {sc * (c03 + c04), sc * (c01 + c02), -sc * (c01 + c03), -sc * (c02 + c04)}};
        d->bend.push_back(b);
      }
    }
    k = e;
  }
  if (opt.colour_order) {
    d->stretch_colours = colour_order(d->stretch, n, [](const DistanceLink& l) { return std::array<int, 2>{l.i, l.j}; });
    d->shear_colours =
        colour_order(d->shear, n, [](const ShearTri& t) { return std::array<int, 3>{t.v[0], t.v[1], t.v[2]}; });
    d->bend_colours = colour_order(
        d->bend, n, [](const BendStencil& b) { return std::array<int, 4>{b.v[0], b.v[1], b.v[2], b.v[3]}; });
  }
  // Grasp: the given vertices, else those inside the jaw box around the grasp point.
  d->grasped.assign(n, 0);
  if (!mesh.grasp.empty()) {
    for (int g : mesh.grasp) {
      if (g < 0 || g >= n) throw std::invalid_argument("make_scene: grasp vertex " + std::to_string(g) + " out of range");
      d->grasped[g] = 1;
    }
  } else if (opt.require_grasp) {
    const V3 c{opt.grasp_point[0] + opt.jaw_centre[0], opt.grasp_point[1] + opt.jaw_centre[1],
               opt.grasp_point[2] + opt.jaw_centre[2]};
    for (int i = 0; i < n; ++i) {
      const V3 q = d->rest[i] - c;
      if (std::abs(q.x) <= opt.jaw_half[0] && std::abs(q.y) <= opt.jaw_half[1] && std::abs(q.z) <= opt.jaw_half[2])
        d->grasped[i] = 1;
    }
  }
  for (int i = 0; i < n; ++i)
    if (d->grasped[i]) d->grasp_list.push_back(i);
  d->grasp_target = d->rest;
  if (opt.jaw_close_steps > 0)
    for (int g : d->grasp_list) d->grasp_target[g].z = opt.grasp_point[2] - opt.jaw_half[2];
  if (d->grasp_list.empty() && opt.require_grasp) throw std::invalid_argument("make_scene: no vertex of '" + mesh.name + "' is inside the jaw box");
  for (int v : mesh.sleeve_opening)
    if (v < 0 || v >= n) throw std::invalid_argument("make_scene: sleeve opening vertex " + std::to_string(v) + " out of range");
  // The label of a trial that the force limit stops is the opening's lower half against the
  // elbow (paper V-A): an arm without an opening labelled every such trial good (d_max 0).
  if (opt.with_arm && mesh.sleeve_opening.empty())
    throw std::invalid_argument("make_scene: '" + mesh.name + "' has no sleeve opening (ClothMesh::sleeve_opening), "
                                "which a scene with the arm needs to label its trials; give one, or build the scene "
                                "without the arm (SceneOptions::with_arm false)");
  d->opening = std::vector<int32_t>(mesh.sleeve_opening.begin(), mesh.sleeve_opening.end());
  d->rim_distance.assign(n, std::numeric_limits<double>::infinity());
  for (int i = 0; i < n; ++i)
    for (int32_t o : d->opening) d->rim_distance[i] = std::min(d->rim_distance[i], norm(d->rest[i] - d->rest[o]));
  for (const auto& pl : opt.planes) {
    const V3 nn{pl[0], pl[1], pl[2]};
    const double l = norm(nn);
    if (l < 1e-12) throw std::invalid_argument("make_scene: a plane has a zero normal");
    d->planes.push_back({(1.0 / l) * nn, pl[3] / l});
  }
  if (opt.with_arm) {
    d->arm = arm_colliders(opt, 0.0, 0.0, &d->arm_names);
    d->elbow = d->arm[0].a;
  }
  return Scene(std::move(d));
}

double compliance_of(double k, double alpha_soft, double alpha_stiff) {
  k = std::clamp(k, kStiffnessLowest, kStiffnessHighest);  // params.cpp refuses a file beyond them
  return std::exp(std::log(alpha_soft) + k * (std::log(alpha_stiff) - std::log(alpha_soft)));
}

double bend_mesh_factor(const SceneData& s) {
  double sum = 0;
  for (const BendStencil& b : s.bend) {
    // Unfold the stencil about its hinge x0-x1: u along the hinge, v across it, x2 and x3 on
    // opposite sides at their rest distances (the dihedral opened flat).
    const V3 e = s.rest[b.v[1]] - s.rest[b.v[0]];
    const double le = norm(e);
    if (le < 1e-12) continue;
    const V3 t = (1.0 / le) * e;
    double u[4] = {0, le, 0, 0}, v[4] = {0, 0, 0, 0};
    for (int k = 2; k < 4; ++k) {
      const V3 d = s.rest[b.v[k]] - s.rest[b.v[0]];
      u[k] = dot(d, t);
      v[k] = std::sqrt(std::max(0.0, dot(d, d) - u[k] * u[k])) * (k == 2 ? 1.0 : -1.0);
    }
    double sa = 0, sb = 0, sc = 0;
    for (int k = 0; k < 4; ++k) sa += b.k[k] * u[k] * u[k], sb += b.k[k] * u[k] * v[k], sc += b.k[k] * v[k] * v[k];
    const double mean = 0.5 * (sa + sc), dev = 0.5 * (sa - sc);
    sum += 0.25 * (mean * mean + 0.5 * dev * dev + 0.5 * sb * sb);  // |K X|^2 / kappa^2, direction-averaged
  }
  return s.rest_area > 0 ? sum / s.rest_area : 0.0;
}

GownModel make_model(const SceneData& s, const ClothParams& p, FrictionScheme scheme, bool self_collision, double arm_dz) {
  GownModel m;
  m.scene = &s;
  m.substeps = s.opt.substeps;
  m.dt = 1.0 / s.opt.step_hz;
  m.h = m.dt / m.substeps;
  const int n = static_cast<int>(s.rest.size());
  m.mass.resize(n);
  m.w.resize(n);
  for (int i = 0; i < n; ++i) {
    m.mass[i] = std::max(s.vertex_area[i] * p.areal_density, 1e-12);
    m.w[i] = s.grasped[i] ? 0.0 : 1.0 / m.mass[i];
  }
  // Ranges documented in trial.h (ClothParams).
  m.alpha_stretch = compliance_of(p.stretch, kStretchComplianceSoft, kStretchComplianceStiff);
  m.alpha_compress = m.alpha_stretch * s.opt.compression_softening;
  m.alpha_shear = compliance_of(p.shear, kShearComplianceSoft, kShearComplianceStiff);
  m.alpha_bend = compliance_of(p.bend, kBendComplianceSoft, kBendComplianceStiff);
  m.friction = std::max(0.0, p.friction);
  m.self_friction = std::max(0.0, p.self_friction);
  m.arm_compliance = std::max(0.0, p.arm_compliance);
  m.fist_shift = p.fist_shift;
  m.arm_lateral = p.arm_lateral;
  m.fist_lateral = p.fist_lateral;
  m.has_support = p.support_depth > 0;
  if (m.has_support) m.support = support_collider(s.opt, p);
  m.hem_width = std::max(0.0, p.hem_width);
  m.hem_bend_ratio = p.hem_bend_ratio > 0 ? p.hem_bend_ratio : 1.0;
  m.damping_factor = std::exp(-std::max(0.0, p.damping) * m.h);
  m.scheme = scheme;
  m.self_collision = self_collision;
  place_arm(m, arm_dz);
  refresh_constraints(m);
  return m;
}

namespace {

// Packs one constraint list into blocks, colour group by colour group (BlockSpan). `fill(block,
// lane, c)` writes constraint c into a lane; `empty(block, lane)` marks a lane unused. A group's
// constraints that touch no grasped vertex fill full "free" blocks in list order; the rest (the
// remainder and the constraints touching a grasped vertex, whose force the gripper reads) follow
// in list order in "careful" blocks. Every block's constraints share no vertex (checked here, not
// assumed: colour 63 may hold dependent ones), so its lanes can be solved at once. Mesh order
// (no colours): one group of careful blocks in list order, for the scalar kernels only (which
// solve a block's lanes one after another, so they may share vertices there).
template <class Block, class C, class VertsOf, class Fill, class Empty>
void pack_blocks(const std::vector<C>& cs, const std::vector<int32_t>& colours, const std::vector<uint8_t>& grasped,
                 VertsOf verts, Fill fill, Empty empty, std::vector<Block>& blocks, std::vector<BlockSpan>& spans) {
  blocks.clear();
  spans.clear();
  const bool mesh_order = colours.empty();
  const std::vector<int32_t> starts = mesh_order ? std::vector<int32_t>{0, static_cast<int32_t>(cs.size())} : colours;
  std::vector<size_t> free_list, rest_list;
  std::vector<int> vs;
  auto distinct = [&](const std::vector<size_t>& list, size_t from, size_t to) {
    vs.clear();
    for (size_t r = from; r < to; ++r)
      for (int v : verts(cs[list[r]])) vs.push_back(v);
    std::sort(vs.begin(), vs.end());
    return std::adjacent_find(vs.begin(), vs.end()) == vs.end();
  };
  auto put = [&](const std::vector<size_t>& list, size_t from, size_t to) {
    Block blk{};
    for (int l = 0; l < 4; ++l) {
      if (from + l < to) {
        fill(blk, l, cs[list[from + l]]);
      } else {
        empty(blk, l);
      }
    }
    blocks.push_back(blk);
  };
  for (size_t g = 0; g + 1 < starts.size(); ++g) {
    free_list.clear();
    rest_list.clear();
    for (int32_t c = starts[g]; c < starts[g + 1]; ++c) {
      bool held = false;
      for (int v : verts(cs[c])) held |= grasped[v] != 0;
      (!mesh_order && !held ? free_list : rest_list).push_back(static_cast<size_t>(c));
    }
    BlockSpan sp{};
    sp.begin = static_cast<int32_t>(blocks.size());
    const size_t full = free_list.size() / 4 * 4;
    for (size_t r = 0; r < full; r += 4) {
      if (distinct(free_list, r, r + 4)) {
        put(free_list, r, r + 4);
      } else {
        for (size_t q = r; q < r + 4; ++q) rest_list.push_back(free_list[q]);
      }
    }
    for (size_t r = full; r < free_list.size(); ++r) rest_list.push_back(free_list[r]);
    sp.simd_end = static_cast<int32_t>(blocks.size());
    std::sort(rest_list.begin(), rest_list.end());  // list order within the careful share
    // Careful blocks: up to 4 consecutive constraints with distinct vertices. In mesh order
    // (scalar kernels only, lane after lane) any 4 consecutive ones.
    for (size_t r = 0; r < rest_list.size();) {
      size_t e = r + 1;
      while (e < rest_list.size() && e - r < 4 && (mesh_order || distinct(rest_list, r, e + 1))) ++e;
      put(rest_list, r, e);
      r = e;
    }
    sp.end = static_cast<int32_t>(blocks.size());
    spans.push_back(sp);
  }
}

}  // namespace

bool cpu_has_avx2() {
#if defined(__x86_64__) || defined(__i386__)
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

void refresh_constraints(GownModel& m) {
  const SceneData& s = *m.scene;
  const double inv_h2 = 1.0 / (m.h * m.h);
  const double* w = m.w.data();
  // Mesh order (the benchmark's baseline) stays scalar. The scalar kernels run the same blocks
  // as the AVX2 ones: the same Gauss-Seidel order on both paths.
  const bool simd = s.opt.simd && s.opt.colour_order && cpu_has_avx2();
  m.path = simd ? KernelPath::Avx2 : KernelPath::Scalar;
  const double at = m.alpha_stretch * inv_h2, ac = m.alpha_compress * inv_h2;
  auto inv_pos = [](double d) { return d > 0 ? 1.0 / d : 0.0; };
  // The cuff (ClothParams::hem_width): a vertex within it, and an edge or hinge with both ends
  // within it. Compression softening stands for single fabric buckling below the mesh's scale; a
  // hem's stitched layers do not, so its edges keep the tension compliance in compression too.
  auto in_hem = [&](int32_t v) { return m.hem_width > 0 && s.rim_distance[v] <= m.hem_width; };
  pack_blocks<StretchBlock>(
      s.stretch, s.stretch_colours, s.grasped, [](const DistanceLink& l) { return std::array<int, 2>{l.i, l.j}; },
      [&](StretchBlock& b, int k, const DistanceLink& l) {
        b.i[k] = l.i;
        b.j[k] = l.j;
        b.rest[k] = l.rest;
        b.wi[k] = w[l.i];
        b.wj[k] = w[l.j];
        b.inv_t[k] = inv_pos(w[l.i] + w[l.j] + at);
        b.inv_c[k] = inv_pos(w[l.i] + w[l.j] + (in_hem(l.i) && in_hem(l.j) ? at : ac));
      },
      [](StretchBlock& b, int k) { b.i[k] = b.j[k] = -1; }, m.stretch_blocks, m.stretch_spans);
  const double as = m.alpha_shear * inv_h2;
  pack_blocks<ShearBlock>(
      s.shear, s.shear_colours, s.grasped,
      [](const ShearTri& t) { return std::array<int, 3>{t.v[0], t.v[1], t.v[2]}; },
      [&](ShearBlock& b, int k, const ShearTri& t) {
        for (int a = 0; a < 3; ++a) b.v[a][k] = t.v[a];
        b.a[k] = t.dm_inv[0];
        b.b[k] = t.dm_inv[1];
        b.c[k] = t.dm_inv[2];
        b.d[k] = t.dm_inv[3];
        b.w0[k] = w[t.v[0]];
        b.w1[k] = w[t.v[1]];
        b.w2[k] = w[t.v[2]];
        b.alpha_t[k] = as / t.area;
      },
      [](ShearBlock& b, int k) { b.v[0][k] = b.v[1][k] = b.v[2][k] = -1; }, m.shear_blocks, m.shear_spans);
  const double ab = m.alpha_bend * inv_h2;
  // A stencil whose hinge lies within the cuff is hem_bend_ratio x stiffer.
  pack_blocks<BendBlock>(
      s.bend, s.bend_colours, s.grasped,
      [](const BendStencil& b) { return std::array<int, 4>{b.v[0], b.v[1], b.v[2], b.v[3]}; },
      [&](BendBlock& b, int k, const BendStencil& st) {
        double denom = in_hem(st.v[0]) && in_hem(st.v[1]) ? ab / m.hem_bend_ratio : ab;
        for (int a = 0; a < 4; ++a) {
          b.v[a][k] = st.v[a];
          b.k[a][k] = st.k[a];
          b.wk[a][k] = w[st.v[a]] * st.k[a];
          denom += b.wk[a][k] * st.k[a];
        }
        b.neg_inv_denom[k] = -1.0 / denom;
      },
      [](BendBlock& b, int k) { b.v[0][k] = b.v[1][k] = b.v[2][k] = b.v[3][k] = -1; }, m.bend_blocks, m.bend_spans);
}

GownState make_state(const GownModel& m) {
  const SceneData& sc = *m.scene;
  const size_t n = sc.rest.size();
  GownState s;
  s.x = sc.rest;
  s.p = sc.rest;
  s.v.assign(n, {});
  s.anchor.assign(n, {});
  s.anchored.assign(n, 0);
  s.cand.assign(n, {});
  s.contact_list.assign(n, 0);
  s.contact_n.assign(n, {});
  s.contact_dn.assign(n, 0.0);
  s.support_cand.assign(n, 0);
  s.contact_acc.assign(n, {});
  s.ext_force.assign(n, {});
  size_t table = 1;
  while (table < 2 * n || table < 64) table <<= 1;  // >= 64: detect_self()'s row_slot()
  s.cell_start.assign(table + 1, 0);
  s.cell_sorted.assign(n, 0);
  s.cell_of.assign(n, 0);
  s.cell_x.assign(n, {});
  s.self_scratch.assign(n + 8, 0);
  const size_t cap = m.self_collision ? 16 * n : 0;
  s.pairs.resize(cap);
  return s;
}

double current_area(const GownModel& m, const GownState& s) {
  double a = 0;
  for (const auto& t : m.scene->mesh.tris) a += 0.5 * norm(cross(s.x[t[1]] - s.x[t[0]], s.x[t[2]] - s.x[t[0]]));
  return a;
}

}  // namespace dressguard::sim
