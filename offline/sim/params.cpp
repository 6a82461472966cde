#include "params.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include "files.h"
#include "model.h"
#include "person_limits.h"

namespace dressguard::sim {
namespace {

double* field(ClothParams& p, const std::string& name) {
  if (name == "stretch") return &p.stretch;
  if (name == "shear") return &p.shear;
  if (name == "bend") return &p.bend;
  if (name == "friction") return &p.friction;
  if (name == "self_friction") return &p.self_friction;
  if (name == "damping") return &p.damping;
  if (name == "areal_density") return &p.areal_density;
  if (name == "arm_compliance") return &p.arm_compliance;
  if (name == "fist_shift") return &p.fist_shift;
  if (name == "arm_lateral") return &p.arm_lateral;
  if (name == "fist_lateral") return &p.fist_lateral;
  if (name == "hem_width") return &p.hem_width;
  if (name == "hem_bend_ratio") return &p.hem_bend_ratio;
  if (name == "support_depth") return &p.support_depth;
  if (name == "support_lateral") return &p.support_lateral;
  return nullptr;
}

// `text` as a whole finite number, with an optional leading '+' (from_chars takes none, and
// '+0.3' is how a signed value is often written); false for anything else.
bool parse_number(const std::string& text, double* out) {
  const char* b = text.data();
  const char* e = b + text.size();
  if (b != e && *b == '+' && b + 1 != e && b[1] != '-' && b[1] != '+') ++b;
  auto [ptr, ec] = std::from_chars(b, e, *out);
  return ec == std::errc() && ptr == e && std::isfinite(*out);
}

}  // namespace

ClothParams parse_params(const std::string& text, const std::filesystem::path& file) {
  ClothParams p;
  // Turn JSON punctuation into spaces and split records at newlines and commas.
  // A UTF-8 byte-order mark (an editor's, on Windows) is no part of the first name.
  std::string t = text.rfind("\xEF\xBB\xBF", 0) == 0 ? text.substr(3) : text;
  for (char& c : t)
    if (c == '{' || c == '}' || c == '"' || c == ':' || c == '=' || c == '\t' || c == '\r') c = ' ';
  std::istringstream in(t);
  std::string line;
  long lineno = 0;
  // The line each parameter was given on: a second one would silently replace the first, and a
  // value out of range is named at its line.
  std::map<std::string, long> line_of;
  while (std::getline(in, line)) {
    ++lineno;
    if (auto h = line.find('#'); h != std::string::npos) line.resize(h);
    std::istringstream recs(line);
    std::string rec;
    std::string before;  // the value of the record before this one on the line, if any
    while (std::getline(recs, rec, ',')) {
      std::istringstream ws(rec);
      std::string name, value, extra;
      if (!(ws >> name)) continue;
      if (!(ws >> value)) {
        // 'friction 0,3' is two records, 'friction 0' and '3': a decimal comma.
        double ignored = 0;
        if (parse_number(name, &ignored) && !before.empty())
          throw_input_error(file, lineno,
                            "'" + before + "," + name + "': a comma separates parameters; use '.' for decimals (" +
                                before + "." + name + ")");
        if (parse_number(name, &ignored))
          throw_input_error(file, lineno, "'" + name + "' is a number where a parameter's name goes");
        throw_input_error(file, lineno, "parameter '" + name + "' has no value");
      }
      if (ws >> extra) throw_input_error(file, lineno, "unexpected '" + extra + "' after " + name);
      double* f = field(p, name);
      if (f && line_of.count(name))
        throw_input_error(file, lineno, "parameter '" + name + "' given again (first on line " +
                                            std::to_string(line_of[name]) + "); give it once");
      if (!f) throw_input_error(file, lineno, "unknown parameter '" + name + "' (stretch, shear, bend, friction, self_friction, damping, areal_density, arm_compliance, fist_shift, arm_lateral, fist_lateral, hem_width, hem_bend_ratio, support_depth, support_lateral)");
      double v = 0;
      if (!parse_number(value, &v))
        throw_input_error(file, lineno, "parameter '" + name + "': '" + value + "' is not a number");
      *f = v;
      line_of[name] = lineno;
      before = value;
    }
  }
  // The line of a value out of range (0: a default's, which none is).
  auto at = [&line_of](const std::string& name) {
    const auto it = line_of.find(name);
    return it == line_of.end() ? 0L : it->second;
  };
  for (const auto& [name, k] : {std::pair{"stretch", p.stretch}, {"shear", p.shear}, {"bend", p.bend}})
    if (!(k >= kStiffnessLowest && k <= kStiffnessHighest))
      throw_input_error(file, at(name),
                        std::string(name) + " must be within [0, 1] (a position on its compliance scale, sim/trial.h)");
  if (p.friction < 0) throw_input_error(file, at("friction"), "friction must not be negative");
  if (p.self_friction < 0) throw_input_error(file, at("self_friction"), "self_friction must not be negative");
  // A decay rate [1/s]: the model would take a negative one as 0 (model.cpp) while the summary
  // reported the value given.
  if (p.damping < 0) throw_input_error(file, at("damping"), "damping must not be negative (0: no damping)");
  // The calibration reader's limits (core/person_limits.h): a params file written from a
  // calibration reads back, and neither takes a value the other refuses.
  if (!(p.areal_density >= kMinArealDensity && p.areal_density <= kMaxArealDensity))
    throw_input_error(file, at("areal_density"), std::string("areal_density ") + kArealDensityRange);
  if (!(p.arm_compliance >= 0 && p.arm_compliance <= kMaxArmCompliance))
    throw_input_error(file, at("arm_compliance"), std::string("arm_compliance ") + kArmComplianceRange);
  const std::string arm_range = " must be within +-" + std::to_string(kMaxArmLateral) + " m";
  if (!(std::abs(p.fist_shift) <= kMaxFistShift))
    throw_input_error(file, at("fist_shift"), "fist_shift must be within +-" + std::to_string(kMaxFistShift) + " m");
  if (!(std::abs(p.arm_lateral) <= kMaxArmLateral))
    throw_input_error(file, at("arm_lateral"), "arm_lateral" + arm_range);
  if (!(std::abs(p.fist_lateral) <= kMaxArmLateral))
    throw_input_error(file, at("fist_lateral"), "fist_lateral" + arm_range);
  if (!(p.hem_width >= 0 && p.hem_width <= kMaxHemWidth))
    throw_input_error(file, at("hem_width"), "hem_width must be within [0, 0.2] m");
  if (!(p.hem_bend_ratio >= 1 && p.hem_bend_ratio <= kMaxHemBendRatio))
    throw_input_error(file, at("hem_bend_ratio"),
                      "hem_bend_ratio must be within [1, 10000] (a hem is stiffer than the fabric)");
  if (!(p.support_depth >= 0 && p.support_depth <= kMaxSupportDepth))
    throw_input_error(file, at("support_depth"),
                      "support_depth must be within [0, 1.5] m below the grasp (0: no support)");
  if (!(std::abs(p.support_lateral) <= kMaxSupportLateral))
    throw_input_error(file, at("support_lateral"), "support_lateral must be within +-0.3 m");
  return p;
}

ClothParams read_params(const std::filesystem::path& file) { return parse_params(read_file(file), file); }

std::string format_params(const ClothParams& p) {
  char b[768];
  std::snprintf(b, sizeof b,
                "stretch %.17g\nshear %.17g\nbend %.17g\nfriction %.17g\nself_friction %.17g\ndamping %.17g\n"
                "areal_density %.17g\narm_compliance %.17g\nfist_shift %.17g\narm_lateral %.17g\n"
                "fist_lateral %.17g\nhem_width %.17g\nhem_bend_ratio %.17g\nsupport_depth %.17g\nsupport_lateral %.17g\n",
                p.stretch, p.shear, p.bend, p.friction, p.self_friction, p.damping, p.areal_density, p.arm_compliance,
                p.fist_shift, p.arm_lateral, p.fist_lateral, p.hem_width, p.hem_bend_ratio, p.support_depth,
                p.support_lateral);
  return b;
}

std::string params_json(const ClothParams& p) {
  char b[768];
  std::snprintf(b, sizeof b,
                "{\"stretch\": %.17g, \"shear\": %.17g, \"bend\": %.17g, \"friction\": %.17g, \"self_friction\": %.17g, "
                "\"damping\": %.17g, \"areal_density\": %.17g, \"arm_compliance\": %.17g, \"fist_shift\": %.17g, "
                "\"arm_lateral\": %.17g, \"fist_lateral\": %.17g, \"hem_width\": %.17g, \"hem_bend_ratio\": %.17g, "
                "\"support_depth\": %.17g, \"support_lateral\": %.17g}",
                p.stretch, p.shear, p.bend, p.friction, p.self_friction, p.damping, p.areal_density, p.arm_compliance,
                p.fist_shift, p.arm_lateral, p.fist_lateral, p.hem_width, p.hem_bend_ratio, p.support_depth,
                p.support_lateral);
  return b;
}

std::string scene_json(const Scene& scene, const ClothParams& params, const TrialSpec& spec, const TrialResult& r) {
  const SceneData& sc = scene.data();
  // The trial's own arm: the fist where params.fist_shift and fist_lateral put it (the scene's
  // arm has it at 0).
  const std::vector<RoundCone> arm = arm_colliders(sc.opt, params.fist_shift, params.fist_lateral);
  const double dz = sc.opt.arm.z_rel[static_cast<int>(spec.height)] - sc.opt.arm.z_rel[0] + r.arm_offset;
  const double dy = params.arm_lateral;  // place_arm moves the whole arm by it
  std::ostringstream o;
  o.precision(6);
  o << "{\"tris\": [";
  for (size_t t = 0; t < sc.mesh.tris.size(); ++t)
    o << (t ? "," : "") << '[' << sc.mesh.tris[t][0] << ',' << sc.mesh.tris[t][1] << ',' << sc.mesh.tris[t][2] << ']';
  o << "],\n\"arm\": [";
  auto cone = [&o](const RoundCone& c, double dy, double dz) {
    o << "{\"a\": [" << c.a.x << ',' << c.a.y + dy << ',' << c.a.z + dz << "], \"ra\": " << c.ra << ", \"b\": ["
      << c.b.x << ',' << c.b.y + dy << ',' << c.b.z + dz << "], \"rb\": " << c.rb << '}';
  };
  for (size_t k = 0; k < arm.size(); ++k) {
    o << (k ? "," : "");
    cone(arm[k], dy, dz);
  }
  // Each height's nominal arm axis (the scene's arm is at the high one), for the view from the fist.
  o << "],\n\"arm_axis_z\": [";
  for (int k = 0; k < 3; ++k) o << (k ? "," : "") << arm[0].a.z + sc.opt.arm.z_rel[k] - sc.opt.arm.z_rel[0];
  o << "],\n\"support\": ";
  if (params.support_depth > 0) {
    cone(support_collider(sc.opt, params), 0, 0);  // fixed in the world
  } else {
    o << "null";
  }
  o << ",\n\"grip\": [" << sc.opt.grasp_point[0] << ',' << sc.opt.grasp_point[1] << ',' << sc.opt.grasp_point[2] << "],";
  o << "\"jaw_half\": [" << sc.opt.jaw_half[0] << ',' << sc.opt.jaw_half[1] << ',' << sc.opt.jaw_half[2] << "],";
  o << "\"grasped\": [";
  for (size_t k = 0; k < sc.grasp_list.size(); ++k) o << (k ? "," : "") << sc.grasp_list[k];
  o << "], \"opening\": [";
  for (size_t k = 0; k < sc.opening.size(); ++k) o << (k ? "," : "") << sc.opening[k];
  o << "],\n\"label\": \"" << label_name(r) << "\", \"travel\": " << r.travel << ", \"d_max\": " << r.d_max << ", \"contact_travel\": " << r.contact_travel
    << ", \"height\": \"" << arm_height_name(spec.height) << "\", \"arm_offset\": " << r.arm_offset << ",\n\"frames\": [";
  for (size_t f = 0; f < r.frames.size(); ++f) {
    const Frame& fr = r.frames[f];
    o << (f ? ",\n" : "") << "{\"t\": " << fr.t << ", \"travel\": " << fr.travel << ", \"x\": [";
    for (size_t k = 0; k < fr.xyz.size(); ++k) o << (k ? "," : "") << fr.xyz[k];
    o << "]}";
  }
  o << "],\n\"samples\": [";
  for (size_t k = 0; k < r.seq.samples.size(); ++k) {
    const HapticSample& s = r.seq.samples[k];
    o << (k ? "," : "") << '[' << s.t << ',' << s.travel << ',' << s.f_motion << ',' << s.f_lateral << ',' << s.f_vertical << ']';
  }
  // Paper eq. 2: the cloth's force on the arm per vertex over the last sample, [vertex, fx, fy, fz].
  o << "],\n\"contacts\": [";
  for (size_t k = 0; k < r.contacts.size(); ++k) {
    const ContactForce& c = r.contacts[k];
    o << (k ? "," : "") << '[' << c.vertex << ',' << c.force[0] << ',' << c.force[1] << ',' << c.force[2] << ']';
  }
  o << "]}\n";
  return o.str();
}

}  // namespace dressguard::sim
