// dressguard gown: load (or generate) the gown, reduce it if asked, place it like the paper's
// simulator, and report what the simulator will get; optionally write the placed mesh and a
// picture of the scene (tools/plot/gown.py).
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>

#include "args.h"
#include "commands.h"
#include "files.h"
#include "gown.h"
#include "grip_option.h"
#include "json.h"
#include "placement.h"

namespace dressguard::cli {
namespace {

namespace fs = std::filesystem;
using gown::GownMesh;

std::string vec_json(const Eigen::Vector3d& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.6f, %.6f, %.6f]", v.x(), v.y(), v.z());
  return buf;
}

std::string ints_json(const std::vector<int>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
  return s + "]";
}

// Everything the picture needs: mesh, grasped vertices, loops, arm and gripper (all in W).
std::string scene_dump(const GownMesh& m, const gown::PaperScene& s, const std::vector<int>& grasp, bool hung) {
  std::string out = "{\n\"frame\": \"W: z up, gravity -z, gripper moves +x\",\n\"state\": \"";
  out += hung ? "after a crude 3 s hang (edges only, no bending, no collisions)" : "placed, before gravity";
  out += "\",\n\"x\": [";
  for (size_t i = 0; i < m.x.size(); ++i) {
    char buf[80];
    std::snprintf(buf, sizeof buf, "%s[%.5f,%.5f,%.5f]", i ? "," : "", m.x[i].x(), m.x[i].y(), m.x[i].z());
    out += buf;
  }
  out += "],\n\"triangles\": [";
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& t = m.triangles[i];
    out += (i ? ",[" : "[") + std::to_string(t[0]) + "," + std::to_string(t[1]) + "," + std::to_string(t[2]) + "]";
  }
  out += "],\n\"boundary_loops\": [";
  for (size_t l = 0; l < m.boundary_loops.size(); ++l) out += (l ? ", " : "") + ints_json(m.boundary_loops[l]);
  out += "],\n\"sleeve_loop\": " + std::to_string(m.sleeve_loop);
  out += ",\n\"sleeve_lower_half\": " + ints_json(m.sleeve_lower_half);
  out += ",\n\"grasp\": " + ints_json(grasp);
  out += ",\n\"grasp_box\": {\"center\": " + vec_json(s.grasp_box_center_W()) +
         ", \"half_extent\": " + vec_json(s.grasp_box_half_extent_W()) + "}";
  out += ",\n\"upper_jaw\": {\"center\": " + vec_json(s.upper_jaw_center_W) + ", \"size\": " + vec_json(s.jaw_size_W) + "}";
  char buf[512];
  std::snprintf(buf, sizeof buf,
                ",\n\"arm\": {\"fist\": %s, \"wrist\": %s, \"elbow\": %s, \"shoulder\": %s, "
                "\"r_fist\": %g, \"r_wrist\": %g, \"r_elbow\": %g, \"r_shoulder\": %g}\n}\n",
                vec_json(s.fist_W()).c_str(), vec_json(s.wrist_W()).c_str(), vec_json(s.elbow_W()).c_str(),
                vec_json(s.shoulder_W()).c_str(), s.r_fist, s.r_wrist, s.r_elbow, s.r_shoulder);
  out += buf;
  return out;
}

// tools/plot/gown.py: from $DRESSGUARD_SOURCE_DIR, else from the folders above the executable
// (build/<preset>/offline/cli/dressguard), else from the working directory.
}  // namespace

int run_gown(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json", "parametric", "hang", "in-world"});
  if (args.has("help")) {
    std::printf(
        "usage: dressguard gown [--obj FILE [--scale S] [--in-world] [--placement P] | --parametric] [--reduced N]\n"
        "                       [--hang] [--out MESH.obj] [--dump SCENE.json] [--picture GOWN.png] [--json]\n"
        "  Loads the gown the simulator runs on, placed in the world frame W (z up, gripper moves +x)\n"
        "  with the paper's gripper and arm, and prints its statistics.\n"
        "  --obj FILE      mesh to load (default: shared/data/gown/fullgown.obj when present,\n"
        "                  else the project's parametric gown)\n"
        "  --scale S       file units -> metres (default 1.679, the paper's; 1 for a file --out wrote,\n"
        "                  whose first line says it is in metres, and refused there unless 1)\n"
        "  --in-world      the OBJ is already placed in W (as --out writes it); refused when the jaws\n"
        "                  hold none of it or its cloth starts inside the arm at any height\n"
        "  --placement P   opening (default: the jaws hold the sleeve's top from 4 cm behind its rim,\n"
        "                  the opening facing the fist) or paper (the paper's code's transform, as\n"
        "                  read); a placement whose jaws hold no whole triangle of the gown is\n"
        "                  refused (exit 2)\n"
        "  --parametric    use the parametric gown even when the measured one is present (not with\n"
        "                  --obj, --scale or --in-world, which read an OBJ)\n"
        "  --reduced N     reduce to about N triangles (quadric edge collapse), e.g. 5000\n"
        "%s"
        "  --hang          let the gown hang 3 s from the jaws in a crude check (edges only, no\n"
        "                  bending, no collisions; not the simulator) before reporting where its\n"
        "                  loops are and drawing it (area, mass, edges and --out stay as placed)\n"
        "  --out MESH.obj  write the placed mesh (atomically; before any --hang; never over --obj)\n"
        "  --dump FILE     write the scene (mesh, grasp, loops, arm, gripper) as JSON for plotting\n"
        "  --picture PNG   draw the placed gown with grasp, sleeve opening and arm (needs python3 +\n"
        "                  matplotlib; tools/plot/gown.py)\n"
        "  --json          print a machine-readable summary\n",
        kGripHelp);
    return 0;
  }
  args.allow_only({"help", "json", "parametric", "hang", "in-world", "obj", "scale", "reduced", "out", "dump", "picture",
                  "placement", "grip-depth", "rim-ahead"});
  // --scale and --in-world read an OBJ: the parametric gown would silently ignore them.
  for (const char* o : {"obj", "scale", "in-world"})
    if (args.has("parametric") && args.has(o))
      throw UsageError(std::string("--parametric and --") + o + " exclude each other");
  gown::GownOptions opt;
  // Unset, the file's own (gown.h, read_obj): a file --out wrote is in metres.
  if (args.has("scale")) {
    opt.scale = args.number("scale", 0);
    if (!(*opt.scale > 0)) throw UsageError("--scale must be positive");
  }
  const long reduced = args.integer("reduced", 0);
  if (reduced < 0 || (reduced > 0 && reduced < 100)) throw UsageError("--reduced wants 0 (full) or at least 100 triangles");
  opt.target_triangles = static_cast<int>(reduced);
  if (auto obj = args.get("obj")) opt.obj = *obj;
  if (auto p = args.get("placement")) {
    if (*p == "opening")
      opt.placement = gown::GownPlacement::Opening;
    else if (*p == "paper")
      opt.placement = gown::GownPlacement::Paper;
    else
      throw UsageError("--placement wants opening or paper, not '" + *p + "'");
  }

  // An output over the --obj it reads would replace the user's mesh: --out by the placed one, in
  // metres, which the default --scale then scales a second time when it is read back.
  for (const char* o : {"out", "dump", "picture"})
    if (const auto path = args.get(o); path && !opt.obj.empty() && same_file(*path, opt.obj))
      throw UsageError(std::string("--") + o + " " + *path + " would write over the input --obj " + opt.obj.string() +
                       ": choose another file");

  const auto t0 = std::chrono::steady_clock::now();
  opt.parametric = args.has("parametric");
  opt.already_in_W = args.has("in-world");
  const fs::path measured = gown::measured_gown_path();
  opt.grip = grip_option(args, opt.parametric || (opt.obj.empty() && measured.empty()));
  if (opt.grip && (opt.already_in_W || opt.placement == gown::GownPlacement::Paper))
    throw UsageError("--grip-depth and --rim-ahead place the sleeve at the jaws: not with --in-world or --placement paper");
  const std::string source =
      opt.parametric || (opt.obj.empty() && measured.empty()) ? "parametric" : (opt.obj.empty() ? measured : opt.obj).string();
  GownMesh mesh = gown::load_gown(opt);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // The cloth as placed: what the simulator starts from, so what --out writes and what the mesh's
  // statistics describe (a crude hang stretches edges, which is no change of area or mass).
  const auto masses = gown::vertex_masses(mesh);
  double mass = 0;
  for (double m : masses) mass += m;
  const double area = gown::total_area(mesh), mean_edge = gown::mean_edge_length(mesh);
  const double min_angle_deg = gown::min_triangle_angle(mesh) * 180 / M_PI;
  const auto grasp = gown::grasp_vertices(mesh, opt.scene);
  if (auto out = args.get("out")) write_file_atomic(*out, gown::to_obj(mesh));
  // --hang moves the positions the rest reports and draws: the loops, the sleeve, the picture.
  if (args.has("hang")) mesh.x = gown::crude_hang(mesh, opt.scene);
  const Eigen::Vector3d sleeve_c = gown::loop_centroid(mesh, mesh.sleeve_loop);

  const auto dump = args.get("dump");
  const auto picture = args.get("picture");
  if (dump || picture) {
    const fs::path dump_path =
        dump ? fs::path(*dump) : fs::temp_directory_path() / ("dressguard-gown-" + std::to_string(::getpid()) + ".json");
    write_file_atomic(dump_path, scene_dump(mesh, opt.scene, grasp, args.has("hang")));
    if (picture) {
      const fs::path script = plot_script("gown.py");
      if (script.empty()) throw std::runtime_error("tools/plot/gown.py not found (set DRESSGUARD_SOURCE_DIR)");
      const int rc = run_plot_script(script, {dump_path.string(), *picture});
      if (!dump) fs::remove(dump_path);
      if (rc != 0) throw std::runtime_error("the picture script failed: " + script.string() + " " + *picture);
    }
  }

  if (args.has("json")) {
    std::printf("{\"source\": %s, \"vertices\": %zu, \"triangles\": %zu, \"area_m2\": %.5f, \"mass_kg\": %.5f, "
                "\"mean_edge_m\": %.5f, \"min_angle_deg\": %.2f, \"seconds\": %.3f, \"hung\": %s, \"loops\": [",
                json_string(source).c_str(), mesh.x.size(), mesh.triangles.size(), area, mass, mean_edge,
                min_angle_deg, seconds, args.has("hang") ? "true" : "false");
    for (size_t l = 0; l < mesh.boundary_loops.size(); ++l)
      std::printf("%s{\"vertices\": %zu, \"perimeter_m\": %.5f, \"centroid\": %s}", l ? ", " : "",
                  mesh.boundary_loops[l].size(), gown::loop_perimeter(mesh, static_cast<int>(l)),
                  vec_json(gown::loop_centroid(mesh, static_cast<int>(l))).c_str());
    std::printf("], \"sleeve_loop\": %d, \"sleeve_center\": %s, \"sleeve_lower_half\": %zu, \"grasped\": %zu}\n",
                mesh.sleeve_loop, vec_json(sleeve_c).c_str(), mesh.sleeve_lower_half.size(), grasp.size());
  } else {
    std::printf("gown: %s%s\n", source.c_str(), args.has("hang") ? " (after a crude 3 s hang from the jaws)" : "");
    std::printf("  as placed: %zu vertices, %zu triangles, area %.4f m^2, mass %.4f kg (%.3f kg/m^2)\n",
                mesh.x.size(), mesh.triangles.size(), area, mass, mesh.areal_density);
    std::printf("  mean edge %.2f cm, smallest angle %.1f deg, built in %.3f s\n", mean_edge * 100, min_angle_deg,
                seconds);
    for (size_t l = 0; l < mesh.boundary_loops.size(); ++l) {
      const auto c = gown::loop_centroid(mesh, static_cast<int>(l));
      std::printf("  loop %zu: %zu vertices, perimeter %.3f m, centre (%.3f, %.3f, %.3f)%s\n", l,
                  mesh.boundary_loops[l].size(), gown::loop_perimeter(mesh, static_cast<int>(l)), c.x(), c.y(), c.z(),
                  static_cast<int>(l) == mesh.sleeve_loop ? "  <- sleeve opening the arm enters" : "");
    }
    std::printf("  grasped vertices: %zu; sleeve lower half: %zu vertices\n", grasp.size(),
                mesh.sleeve_lower_half.size());
  }
  return 0;
}

}  // namespace dressguard::cli
