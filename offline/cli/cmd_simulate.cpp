// dressguard simulate: one simulated sleeve-pulling trial (offline/sim) -> trial CSV + summary.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "args.h"
#include "calibration.h"
#include "commands.h"
#include "dataset.h"
#include "files.h"
#include "gown.h"
#include "gown_scene.h"
#include "grip_option.h"
#include "json.h"
#include "model.h"
#include "params.h"
#include "sim_bridge.h"
#include "trial.h"

namespace dressguard::cli {
namespace {

// --frames: at most this many times (the default keeps 55); each frame costs the scene file a copy
// of the gown's positions (about 75 kB on the reduced gown: 500 frames made 38 MB).
constexpr std::size_t kMaxFrames = 100;
// [m] the largest arm-height offset simulated: --arm-offset plus a calibration's.
constexpr double kMaxArmOffset = 0.5;

// --frames: times [s] since the start of the pull, each once, from `earliest` (the longest
// settling before the pull) to `latest` (the pull's time limit): a time outside kept no frame,
// or far out overflowed the count of settling's snapshots; a repeat kept the same frame again.
std::vector<double> parse_times(const std::string& s, double earliest, double latest) {
  std::vector<double> out;
  std::istringstream in(s);
  std::string tok;
  while (std::getline(in, tok, ',')) {
    char* end = nullptr;
    const double v = std::strtod(tok.c_str(), &end);
    if (tok.empty() || *end != '\0' || !std::isfinite(v)) throw UsageError("--frames: '" + tok + "' is not a time in seconds");
    if (!(v >= earliest && v <= latest))
      throw UsageError("--frames: " + tok + " s is outside " + format_number(earliest) + " (the longest settling) to " +
                       format_number(latest) + " s (the pull's time limit)");
    if (std::find(out.begin(), out.end(), v) != out.end()) throw UsageError("--frames: " + tok + " s given twice");
    out.push_back(v);
  }
  if (out.size() > kMaxFrames)
    throw UsageError("--frames: " + std::to_string(out.size()) + " times; at most " + std::to_string(kMaxFrames));
  return out;
}

// The files simulate writes beside its CSV: the summary, the scene for pictures and the arm's load.
struct SideFiles {
  std::filesystem::path meta, scene, arm;
};
SideFiles side_files_of(const std::filesystem::path& out) {
  SideFiles f{out, out, out};
  f.meta.replace_extension(".json");
  f.scene.replace_extension(".scene.json");
  f.arm.replace_extension(".arm.csv");
  // --out X.json (or X.scene.json) would be written as the CSV and then replaced by a side file.
  for (const auto& side : {f.meta, f.scene, f.arm})
    if (side == out)
      throw UsageError("option --out: '" + out.string() + "' is the name of a file written beside the CSV (" +
                       f.meta.filename().string() + ", " + f.scene.filename().string() + ", " +
                       f.arm.filename().string() + "); give FILE.csv");
  return f;
}

// The default scene, with the jaws where --grip-depth / --rim-ahead put them. A grip that leaves
// the jaws off the sleeve's top (the rim too far ahead of them, say) grasps nothing
// (gown::NothingGrasped); that is the options' fault, so it is reported as a usage error that
// names them, as a grip out of its range is.
sim::Scene scene_with_grip(sim::GownResolution res, bool parametric, const std::optional<gown::OpeningGrip>& grip) {
  if (!grip) return sim::make_default_scene(res, parametric);
  auto named = [&](const std::exception& e) {
    return UsageError(format_string("--grip-depth %g --rim-ahead %g: %s", grip->depth, grip->rim_ahead, e.what()));
  };
  try {
    return sim::make_default_scene(res, parametric, *grip);
  } catch (const std::invalid_argument& e) {
    throw named(e);
  } catch (const gown::NothingGrasped& e) {
    throw named(e);
  }
}

// Per sample: t, travel, and the cloth's force on each arm part (sim::ArmPartLoads).
std::string arm_parts_csv(const sim::Scene& scene, const sim::TrialResult& r) {
  const std::vector<std::string> names = sim::arm_part_names(scene);
  std::string o = "t,travel";
  for (const auto& n : names) o += "," + n + "_fx," + n + "_fy," + n + "_fz";
  o += "\n";
  char buf[64];
  for (std::size_t i = 0; i < r.arm_parts.size() && i < r.seq.samples.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%.2f,%.6f", r.seq.samples[i].t, r.seq.samples[i].travel);
    o += buf;
    for (std::size_t k = 0; k < names.size(); ++k)
      for (double v : r.arm_parts[i].f[k]) {
        std::snprintf(buf, sizeof buf, ",%.6g", v + 0.0);  // + 0.0: no "-0"
        o += buf;
      }
    o += "\n";
  }
  return o;
}

}  // namespace

int run_simulate(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json", "noise", "arm-noise", "no-self-collision", "parametric"});
  if (args.has("help")) {
    std::printf(
        "usage: dressguard simulate --height high|middle|low --out FILE.csv [options]\n"
        "  Simulates one sleeve-pulling trial (XPBD cloth, 300 Hz x 20 substeps) and writes its\n"
        "  100 Hz haptic samples as a trial CSV (t,travel,f_motion,f_lateral,f_vertical; the rig's\n"
        "  signs; then label,height,speed,arm_offset,seed, the same on every row, which readers of\n"
        "  trial CSVs skip), a summary FILE.json (label, travel, d_max, final forces, parameters)\n"
        "  and, for pictures, FILE.scene.json (mesh, arm, frames, contact forces on the arm at the\n"
        "  end) read by tools/plot/sim_scene.py, and FILE.arm.csv: per sample, the cloth's force on\n"
        "  each part of the arm (elbow, fist, [hand,] forearm, upper arm; x y z, N) for\n"
        "  tools/plot/arm_parts.py.\n"
        "  --arm-offset M    [m] added to the height's arm height (default 0); within +-%g m,\n"
        "                    --calibration's offset for the height included\n"
        "  --speed V         [m/s] pull speed within %g-%g: the study's are 0.1 and 0.15 (default 0.1)\n"
        "  --params FILE     cloth parameters ('name value' lines or flat JSON; see offline/sim/params.h)\n"
        "  --calibration CAL a calibration file instead (dressguard calibrate): its cloth and person\n"
        "                    parameters, its offset for this height added to --arm-offset, its gown,\n"
        "                    its end of travel and its grasp (rim_shift) as the defaults of --gown,\n"
        "                    --max-travel and --rim-ahead\n"
        "  --seed S          seed of the noise models, 0 to 2^64 - 1 (default 0)\n"
        "  --max-travel M    [m] where the rig stops if the force limit does not stop it first\n"
        "                    (default 0.85; a measured trial's own end: rig_end_of_travel); more than\n"
        "                    the travel of the pull's first sample (0.05 mm), so that the trial has\n"
        "                    at least two samples (a dataset's reader refuses one)\n"
        "  --noise           the paper's gown perturbation (random force up to 6 N for 0.5 s)\n"
        "  --arm-noise       the paper's arm-height noise (+-1.5 cm high/low, -6..0 cm middle)\n"
        "  --gown G          full | reduced | coarse (default reduced): the measured gown at ~20k, 5k,\n"
        "                    1.5k triangles (the gown module's parametric gown without shared/data)\n"
        "  --parametric      the gown module's parametric gown even when the measured one is present\n"
        "  --friction F      stock | improved | constraint (default improved, or the --calibration\n"
        "                    file's)\n"
        "%s"
        "  --no-self-collision\n"
        "  --frames T1,T2,.. [s] since the start of the pull (negative: settling) to keep the gown\n"
        "                    positions at, each once, at most %zu, from -%g s (the longest settling)\n"
        "                    to the pull's time limit (%g s at 0.1 m/s); default every 0.25 s from -1.6 s\n"
        "  --json            print the summary as JSON\n",
        kMaxArmOffset, sim::kMinPullSpeed, sim::kMaxPullSpeed, kGripHelp, kMaxFrames, sim::max_settle_time_of({}),
        sim::max_time_of({}));
    return 0;
  }
  args.allow_only({"help", "json", "noise", "arm-noise", "no-self-collision", "height", "arm-offset", "max-travel", "speed", "params", "calibration", "seed",
                   "gown", "friction", "out", "frames", "parametric", "grip-depth", "rim-ahead"});
  sim::TrialSpec spec;
  const std::string hs = args.require("height");
  const auto h = parse_arm_height(hs);
  if (!h) throw UsageError("--height must be high, middle or low, not '" + hs + "'");
  spec.height = *h;
  const double given_offset = args.number("arm-offset", 0.0);
  spec.arm_offset = given_offset;
  spec.speed = args.number("speed", 0.1);
  // The pull's time limit grows as 1 / speed (sim/trial.h): a speed near 0 would run for days.
  if (!(spec.speed >= sim::kMinPullSpeed && spec.speed <= sim::kMaxPullSpeed))
    throw UsageError("--speed must be within " + format_number(sim::kMinPullSpeed) + " and " +
                     format_number(sim::kMaxPullSpeed) + " m/s (the study pulls at 0.1 and 0.15), not " +
                     format_number(spec.speed));
  spec.seed = args.unsigned64("seed", 0);  // the noise models' stream takes any uint64_t
  if (args.has("params") && args.has("calibration")) throw UsageError("give at most one of --params and --calibration");
  std::optional<calib::Calibration> cal;
  if (auto cf = args.get("calibration")) {
    cal = calib::read_calibration(*cf);
    spec.arm_offset += cal->offsets[static_cast<int>(spec.height)];
  }
  // The limit holds for the offset simulated, the calibration's included (checked before it was
  // added, --arm-offset 0.5 with a calibration's +0.1 simulated 0.6 m).
  if (!(std::abs(spec.arm_offset) <= kMaxArmOffset)) {
    if (cal)
      throw UsageError(format_string("--arm-offset %g plus the calibration's %g m for the %s arm is %g m; the sum must "
                                     "be within +-%g m",
                                     given_offset, cal->offsets[static_cast<int>(spec.height)], hs.c_str(),
                                     spec.arm_offset, kMaxArmOffset));
    throw UsageError(format_string("--arm-offset must be within +-%g m", kMaxArmOffset));
  }
  spec.max_travel = args.number("max-travel", cal ? cal->rig_travel : 0.85);
  if (!(spec.max_travel > 0.0 && spec.max_travel <= 0.85))
    throw UsageError("--max-travel must be in (0, 0.85] m (the rig's travel)");
  // A pull stopped at its first sample writes a trial file of one sample, which every reader of
  // a dataset refuses (core/dataset.h): refused here, before the run, with the least that gives two.
  if (const double least = sim::least_max_travel_of(spec); !(spec.max_travel > least))
    throw UsageError(format_string("--max-travel %g m ends the pull at its first sample, %g m into the rig's ramp: "
                                   "a trial needs at least 2 samples (a dataset's reader refuses one), so more than that",
                                   spec.max_travel, least - sim::kTravelEndTolerance));
  spec.gown_noise = args.has("noise");
  spec.arm_noise = args.has("arm-noise");
  spec.self_collision = !args.has("no-self-collision");
  // A calibration's scheme unless --friction says otherwise: its coefficients were fitted under it.
  const std::string fr = args.get("friction").value_or(cal ? cal->cloth.friction_scheme : calib::kFrictionSchemes[0]);
  if (!sim::parse_friction_scheme(fr, &spec.friction_scheme))
    throw UsageError("--friction must be " + calib::friction_scheme_choices() + ", not '" + fr + "'");
  const std::string gs = args.get("gown").value_or(cal ? cal->gown : "reduced");
  sim::GownResolution res;
  if (gs == "full") res = sim::GownResolution::Full;
  else if (gs == "reduced") res = sim::GownResolution::Reduced;
  else if (gs == "coarse") res = sim::GownResolution::Coarse;
  else throw UsageError("--gown must be full, reduced or coarse, not '" + gs + "'");
  sim::ClothParams params;
  if (auto pf = args.get("params")) params = sim::read_params(*pf);
  if (cal) params = calib::cloth_params_of(cal->cloth);
  const std::filesystem::path out = args.require_output_file("out");  // a folder: refused before the run
  const SideFiles side = side_files_of(out);
  spec.keep_frames = true;
  spec.record_arm_parts = true;
  if (auto f = args.get("frames")) {
    spec.frame_times = parse_times(*f, -sim::max_settle_time_of(spec), sim::max_time_of(spec));
  } else {
    for (double t = -1.6; t < 12.0; t += 0.25) spec.frame_times.push_back(t);
  }

  const bool parametric = args.has("parametric") || gown::measured_gown_path().empty();
  // A calibration's grasp (its rim_shift) is the default that --grip-depth / --rim-ahead change.
  const auto grip = grip_option(args, parametric, cal ? calib::grasp_of(cal->cloth.rim_shift, parametric) : std::nullopt);
  const gown::OpeningGrip held = grip ? *grip : gown::own_grip(parametric);
  const sim::Scene scene = scene_with_grip(res, parametric, grip);
  const sim::TrialResult r = sim::simulate_trial(scene, params, spec);
  if (!r.finite) throw std::runtime_error("the simulation diverged (non-finite positions)");

  const HapticSample last = r.seq.samples.empty() ? HapticSample{} : r.seq.samples.back();
  // What `bend` means as a material on this mesh (model.h): B [N m] and Peirce's bending length.
  const double rigidity = sim::bending_rigidity(params.bend, sim::bend_mesh_factor(scene.data()));
  // The path as a JSON string (escaped), the rest as long as it needs to be.
  const std::string b = format_string(
                "{\"label\": \"%s\", \"height\": \"%s\", \"arm_offset\": %.6g, \"speed\": %.6g, \"seed\": %llu, "
                "\"noise\": %s, \"gown\": \"%s\", \"friction\": \"%s\", \"travel\": %.6f, \"d_max\": %.6f, "
                "\"d_behind\": %.6f, \"d_ahead\": %.6f, \"stopped_by_force\": %s, \"contact_travel\": %.6f, \"samples\": %zu, \"f_motion\": %.6f, "
                "\"f_lateral\": %.6f, \"f_vertical\": %.6f, \"weight\": %.6f, \"support_load\": %.6f, \"area_ratio\": %.6f, "
                "\"settle_s\": %.4f, \"settle_speed\": %.6f, \"settled\": %s, "
                "\"bending_rigidity\": %.6g, \"bending_length\": %.6g, "
                "\"opening\": {\"depth\": %.4f, \"height\": %.4f, \"width\": %.4f, \"centre_y\": %.4f, "
                "\"perimeter_ratio\": %.4f, \"rim_low_above_fist\": %.4f}, "
                "\"grip\": {\"depth\": %.6g, \"rim_ahead\": %.6g}, \"out\": ",
                std::string(sim::label_name(r)).c_str(), hs.c_str(), r.arm_offset, spec.speed,
                static_cast<unsigned long long>(spec.seed), spec.gown_noise ? "true" : "false", gs.c_str(), fr.c_str(),
                r.travel, r.d_max, r.d_behind, r.d_ahead, r.stopped_by_force ? "true" : "false", r.contact_travel, r.seq.samples.size(),
                last.f_motion, last.f_lateral, last.f_vertical, r.weight, r.support_load, r.area_ratio, r.settle_time,
                r.settle_speed, r.settled ? "true" : "false", rigidity, sim::bending_length(rigidity, params.areal_density),
                r.opening.depth, r.opening.height, r.opening.width, r.opening.centre_y, r.opening.perimeter_ratio,
                r.opening.rim_low_above_fist, held.depth, held.rim_ahead) +
                        json_string(out.string()) + ", \"params\": " + sim::params_json(params) + "}";
  write_file_atomic(side.meta, b + "\n");
  write_file_atomic(side.scene, sim::scene_json(scene, params, spec, r));
  write_file_atomic(side.arm, arm_parts_csv(scene, r));
  // The CSV last: it is the commit point. A run that stops before it leaves the old CSV (or none),
  // never a new CSV beside old side files; new side files beside an old CSV are rewritten by the
  // next run of the same --out.
  // The label and the trial's conditions on every row, so that the CSV alone says what it is
  // (issue 5); readers of trial CSVs skip columns after the five (core/dataset.h).
  const std::vector<ConstantColumn> about = {
      {"label", std::string(sim::label_name(r))},
      {"height", std::string(arm_height_name(spec.height))},
      {"speed", format_string("%.9g", spec.speed)},
      {"arm_offset", format_string("%.9g", r.arm_offset)},
      {"seed", std::to_string(spec.seed)}};
  write_file_atomic(out, format_trial_csv(r.seq.samples, about));
  if (args.has("json")) {
    std::printf("%s\n", b.c_str());
  } else {
    std::printf("%s at %s arm (offset %+.3f m): travel %.3f m, d_max %.3f m, final F motion %.2f N vertical %.2f N -> %s\n",
                std::string(sim::label_name(r)).c_str(), hs.c_str(), r.arm_offset, r.travel, r.d_max,
                last.f_motion, last.f_vertical, out.c_str());
    std::printf("  opening at the start of the pull: %.1f cm below the jaws, %.1f cm tall, %.1f cm wide, centre y %+.1f cm,"
                " rim %.0f %% of its rest length; its lowest point %+.1f cm from the fist's centre\n",
                100 * r.opening.depth, 100 * r.opening.height, 100 * r.opening.width, 100 * r.opening.centre_y,
                100 * r.opening.perimeter_ratio, 100 * r.opening.rim_low_above_fist);
  }
  return 0;
}

}  // namespace dressguard::cli
