// dg_sim_fit: a coarse grid search of the cloth parameters against measured trials, reporting the
// paper's objective (eq. 3-5, w = 20) per trial and the fidelity checks of issue 5.
//
// Usage: dg_sim_fit [--gown coarse|reduced|full] [--parametric] [--good FILE] [--miss FILE]
//                   [--params FILE] [--friction a,b,..] [--stretch a,b,..] [--bend a,b,..]
//                   [--offsets a,b,..] [--grips a,b,..] [--out DIR]
// Defaults: participant 4 (good/subject4/3.txt, miss/subject4/2.txt, the paper's fidelity
// anchor), friction 0.1,0.3,0.6, stretch 0.5,0.9, bend 0.2, arm offsets 0,-0.02, coarse gown.
// --params: the other cloth parameters (shear, self-friction, ...; params.h), e.g. a calibration's.
// --grips: the jaws' grip depths [m] to try (gown::OpeningGrip; default the gown's own), each its
// own scene.
// Every grid point's result is appended to DIR/grid.csv as soon as it is known; a rerun skips the
// points already there (resumable). At the end the best point (smallest L_good + L_miss) is
// re-simulated and its trials written as DIR/best_good.csv and DIR/best_miss.csv for plotting
// (tools/plot/sim_forces.py), and a summary is printed.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "dataset.h"
#include "gown_scene.h"
#include "files.h"
#include "objective.h"  // offline/calib: the paper's eq. 3-5
#include "params.h"
#include "trial.h"

using namespace dressguard;
using namespace dressguard::sim;

namespace {

std::vector<double> list(const std::string& s) {
  std::vector<double> v;
  std::istringstream in(s);
  std::string t;
  while (std::getline(in, t, ',')) v.push_back(std::strtod(t.c_str(), nullptr));
  return v;
}

struct Point {
  double friction, stretch, bend, offset, grip;  // grip < 0: the gown's own
  std::string key() const {
    char b[160];
    std::snprintf(b, sizeof b, "%.4f,%.4f,%.4f,%.4f,%.4f", friction, stretch, bend, offset, grip);
    return b;
  }
};

constexpr const char* kGridHeader =
    "friction,stretch,bend,offset,grip,L_good,L_miss,good_label,good_travel,miss_label,miss_travel,miss_final_drag";

// The measured trial's conditions; the simulation stops where the rig stopped it (as calibration
// does, calib::request_for), so that the objective compares the same stretch of travel.
TrialSpec spec_for(ArmHeight h, const std::vector<HapticSample>& measured, double offset) {
  TrialSpec s;
  s.height = h;
  s.speed = estimate_speed(measured);
  s.arm_offset = offset;
  s.max_travel = rig_end_of_travel(measured, s.max_travel);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  std::map<std::string, std::string> a;
  for (int i = 1; i < argc; ++i) {
    std::string k = argv[i];
    if (k == "--parametric") {
      a["parametric"] = "1";
    } else if (k.rfind("--", 0) == 0 && i + 1 < argc) {
      a[k.substr(2)] = argv[++i];
    } else {
      std::fprintf(stderr, "dg_sim_fit: unexpected argument '%s' (see the header of offline/sim/fit_tool.cpp)\n", k.c_str());
      return 2;
    }
  }
  const auto study = study_dir();
  const std::string good_file = a.count("good") ? a["good"] : (study / "good/subject4/3.txt").string();
  const std::string miss_file = a.count("miss") ? a["miss"] : (study / "miss/subject4/2.txt").string();
  if (!a.count("good") && study.empty()) {
    std::fprintf(stderr, "dg_sim_fit: shared/data is not present; give --good and --miss\n");
    return 2;
  }
  const auto good = read_study_trial(good_file);
  const auto miss = read_study_trial(miss_file);
  const std::string gs = a.count("gown") ? a["gown"] : "coarse";
  const GownResolution res = gs == "full" ? GownResolution::Full : gs == "reduced" ? GownResolution::Reduced : GownResolution::Coarse;
  const bool parametric = a.count("parametric") > 0;
  std::map<double, Scene> scenes;  // one per grip depth
  auto scene_for = [&](double grip) -> const Scene& {
    auto it = scenes.find(grip);
    if (it == scenes.end()) {
      if (grip < 0) {
        it = scenes.emplace(grip, make_default_scene(res, parametric)).first;
      } else {
        gown::OpeningGrip g = gown::own_grip(parametric);
        g.depth = grip;
        it = scenes.emplace(grip, make_default_scene(res, parametric, g)).first;
      }
    }
    return it->second;
  };
  const ClothParams base = a.count("params") ? read_params(a["params"]) : ClothParams{};
  const std::filesystem::path out = a.count("out") ? a["out"] : "out/sim-fit";
  std::filesystem::create_directories(out);
  const auto fr = list(a.count("friction") ? a["friction"] : "0.1,0.3,0.6");
  const auto st = list(a.count("stretch") ? a["stretch"] : "0.5,0.9");
  const auto be = list(a.count("bend") ? a["bend"] : "0.2");
  const auto of = list(a.count("offsets") ? a["offsets"] : "0,-0.02");
  const auto gr = a.count("grips") ? list(a["grips"]) : std::vector<double>{-1.0};

  // Resume: the points already in grid.csv.
  std::map<std::string, std::string> done;
  const auto grid_file = out / "grid.csv";
  {
    std::ifstream in(grid_file);
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      if (n == 1) {
        if (line != kGridHeader) {
          std::fprintf(stderr, "dg_sim_fit: %s:1: not this tool's grid header (an older grid?); use another --out\n",
                       grid_file.c_str());
          return 2;
        }
        continue;
      }
      if (line.empty()) continue;
      std::istringstream ls(line);
      std::string f[5];
      for (auto& x : f) std::getline(ls, x, ',');
      done[f[0] + "," + f[1] + "," + f[2] + "," + f[3] + "," + f[4]] = line;
    }
  }
  std::string csv = std::string(kGridHeader) + "\n";
  for (auto& [k, v] : done) csv += v + "\n";
  std::printf("grid on the %s gown (%d triangles): measured good ends at %.3f m, miss at %.3f m with F_motion %.2f N\n",
              gs.c_str(), scene_for(gr.front()).triangle_count(), good.back().travel, miss.back().travel,
              miss.back().f_motion);
  std::printf("%8s %8s %6s %7s %6s | %7s %7s | %-7s %6s | %-7s %6s %7s\n", "friction", "stretch", "bend", "offset", "grip",
              "L_good", "L_miss", "good", "travel", "miss", "travel", "drag");
  double best = 1e300;
  Point best_p{};
  const size_t total = fr.size() * st.size() * be.size() * of.size() * gr.size();
  size_t count = 0;
  for (double g : gr)
  for (double f : fr)
    for (double s : st)
      for (double b : be)
        for (double o : of) {
          const Point p{f, s, b, o, g};
          const Scene& scene = scene_for(g);
          ++count;
          std::string line;
          if (done.count(p.key())) {
            line = done[p.key()];
          } else {
            ClothParams cp = base;
            cp.friction = f;
            cp.stretch = s;
            cp.bend = b;
            const TrialResult rg = simulate_trial(scene, cp, spec_for(ArmHeight::High, good, o));
            const TrialResult rm = simulate_trial(scene, cp, spec_for(ArmHeight::Low, miss, o));
            char buf[256];
            std::snprintf(buf, sizeof buf, "%s,%.5f,%.5f,%s,%.4f,%s,%.4f,%.4f", p.key().c_str(),
                          calib::area_objective(rg.seq.samples, good), calib::area_objective(rm.seq.samples, miss),
                          std::string(sim::label_name(rg)).c_str(), rg.travel,
                          std::string(sim::label_name(rm)).c_str(), rm.travel,
                          rm.seq.samples.empty() ? 0.0 : rm.seq.samples.back().f_motion);
            line = buf;
            csv += line + "\n";
            write_file_atomic(grid_file, csv);
          }
          std::istringstream ls(line);
          std::vector<std::string> c;
          std::string x;
          while (std::getline(ls, x, ',')) c.push_back(x);
          const double lg = std::atof(c[5].c_str()), lm = std::atof(c[6].c_str());
          std::printf("%8.3f %8.3f %6.3f %7.3f %6.3f | %7.3f %7.3f | %-7s %6s | %-7s %6s %7s   [%zu/%zu]\n", f, s, b, o, g,
                      lg, lm, c[7].c_str(), c[8].c_str(), c[9].c_str(), c[10].c_str(), c[11].c_str(), count, total);
          std::fflush(stdout);
          if (lg + lm < best) best = lg + lm, best_p = p;
        }
  ClothParams cp = base;
  cp.friction = best_p.friction;
  cp.stretch = best_p.stretch;
  cp.bend = best_p.bend;
  const Scene& scene = scene_for(best_p.grip);
  const TrialResult rg = simulate_trial(scene, cp, spec_for(ArmHeight::High, good, best_p.offset));
  const TrialResult rm = simulate_trial(scene, cp, spec_for(ArmHeight::Low, miss, best_p.offset));
  write_file_atomic(out / "best_good.csv", format_trial_csv(rg.seq.samples));
  write_file_atomic(out / "best_miss.csv", format_trial_csv(rm.seq.samples));
  write_file_atomic(out / "best_params.txt", format_params(cp));
  std::printf("best: friction %.3f stretch %.3f bend %.3f offset %.3f grip %.3f: L_good %.3f (%s, travel %.3f vs measured %.3f), "
              "L_miss %.3f (%s, final drag %.2f vs measured %.2f N)\n",
              best_p.friction, best_p.stretch, best_p.bend, best_p.offset, best_p.grip, calib::area_objective(rg.seq.samples, good),
              std::string(sim::label_name(rg)).c_str(), rg.travel, good.back().travel,
              calib::area_objective(rm.seq.samples, miss), std::string(sim::label_name(rm)).c_str(),
              rm.seq.samples.empty() ? 0.0 : rm.seq.samples.back().f_motion, miss.back().f_motion);
  return 0;
}
