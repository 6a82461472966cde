// dressguard calibrate: fit the simulator's cloth parameters and arm offsets to one participant's
// measured sequences with CMA-ES (paper section IV-B). See offline/calib/README.md.
#include <array>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <optional>

#include "args.h"
#include "calibration.h"
#include "commands.h"
#include "dataset.h"
#include "files.h"
#include "json.h"
#ifdef DRESSGUARD_HAVE_SIM
#include "sim_bridge.h"
#endif

namespace dressguard::cli {

using namespace dressguard::calib;

namespace {

#ifdef DRESSGUARD_HAVE_SIM
// Empty when the simulator builds the grasp of some probe of a fitted rim_shift box (grasp_probes),
// else why the first probe's grasp cannot be built.
std::string unbuildable_box(const ClothSimulator& sim, const ParamBound& box) {
  std::string first;
  for (double rim_shift : grasp_probes(box.lower, box.upper)) {
    try {
      sim.build_grasp(rim_shift);
      return "";
    } catch (const UnbuildableCandidate& e) {
      if (first.empty()) first = e.what();
    }
  }
  return first;
}
#endif

[[maybe_unused]] std::string minutes(double s) {
  char buf[32];
  if (s < 120) std::snprintf(buf, sizeof buf, "%.0f s", s);
  else std::snprintf(buf, sizeof buf, "%.1f min", s / 60);
  return buf;
}

// calibrate --rescore: a calibration file's figures again by this build's objective, its values
// unchanged (calibration.h, rescore). Its own inputs, gown and offsets; one batch of simulations.
int rescore_file(const Args& args) {
  args.allow_only({"help", "json", "rescore", "data", "out", "why"});
  const std::string file = args.require("rescore");
  const std::string data = args.require("data");
  const std::string out = args.require_output_file("out");
  Calibration cal;
  try {
    cal = read_calibration(file);
  } catch (const std::exception& e) {
    throw UsageError("--rescore " + file + ": " + e.what());
  }
  std::vector<std::string> ids;
  for (const SequenceFit& f : cal.fits) ids.push_back(f.trial_id);
  std::vector<HapticSequence> inputs;
  try {
    inputs = inputs_by_id(load_dataset(data), cal.participant, ids);
  } catch (const InputError& e) {
    throw UsageError("--rescore " + file + ": its inputs in " + data + "/manifest.csv: " + e.what());
  }
#ifndef DRESSGUARD_HAVE_SIM
  throw UsageError("this dressguard was built without the cloth simulator (offline/sim); --rescore needs it");
#else
  const ClothSimulator sim = make_cloth_simulator(cal.gown);
  const std::vector<SimulatedTrial> curves = simulate_inputs(sim.trials, cal.cloth, cal.offsets, inputs);
  const Calibration before = cal;
  rescore(cal, inputs, curves, args.get("why").value_or("the objective's definition changed"), utc_now());
  write_calibration(out, cal);
  write_file_atomic(out + ".curves.csv", overlay_csv(inputs, curves, "simulated"));
  if (args.has("json")) {
    std::printf("%s\n", calibration_to_json(cal).dump(0).c_str());
  } else {
    std::printf("%s, participant %s: L = %.4f (recorded %.4f)\n", file.c_str(), cal.participant.c_str(), cal.objective,
                before.objective);
    for (std::size_t k = 0; k < cal.fits.size(); ++k)
      std::printf("  %-18s L = %.4f (recorded %.4f)\n", cal.fits[k].trial_id.c_str(), cal.fits[k].objective,
                  before.fits[k].objective);
    std::printf("wrote %s and %s.curves.csv\n", out.c_str(), out.c_str());
  }
  return 0;
#endif
}

}  // namespace

int run_calibrate(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json", "no-arm-offset"});
  if (args.has("help")) {
    std::puts(
        "usage: dressguard calibrate --data DATASET --participant P --out CAL.json [options]\n"
        "  Fits stretch, shear, bend, friction, self-friction and one arm-height offset per height\n"
        "  to one measured sequence per arm height of participant P (caught excluded; paper IV-B)\n"
        "  with CMA-ES, minimising the area between force curves (eq. 3-5).\n"
        "  --profile default|quick   default: 50 generations x 32 (the paper); quick: 6 x 8 (tests)\n"
        "  --generations N --population N   override the profile\n"
        "  --bounds FILE       'name lower upper [initial]' lines (offline/calib/README.md)\n"
        "  --start CAL.json    start where that calibration ended: its values (and each height's\n"
        "                      own offset) become the initial values within the bounds\n"
        "  --sigma0 S          CMA-ES's initial step in the unit box (default 0.3: a global search;\n"
        "                      about 0.1 from initial values known to fit, e.g. another calibration's)\n"
        "  --seed S            input selection and CMA-ES (default 1); same seed, same result\n"
        "  --inputs ID,ID[,ID] fit these trials of P (one per height, good or missed) instead of\n"
        "                      the seed's choice; the seed then drives CMA-ES alone\n"
        "  --objective area|position-weighted   (default area: paper eq. 3-5)\n"
        "  --combine sum|worst|bar|count   how the sequences' L combine: sum (the paper, the\n"
        "                      default), worst (max_k L_k + 0.1 sum_k L_k: the worst-fitted sequence\n"
        "                      first, as issue 4 judges each one), bar (sum_k max(0, L_k - 0.3) +\n"
        "                      0.1 sum_k L_k: each sequence's excess over issue 4's 0.3) or count\n"
        "                      (the number of sequences over 0.3, then bar: those within it stay\n"
        "                      there; offline/calib/calibration.h)\n"
        "  --contrast-weight K   add K times the heights' contrast to the objective: how the high\n"
        "                      sequence's forces differ from the lower one's over the first 0.30 m,\n"
        "                      simulated against measured (offline/calib/objective.h, contrast_error;\n"
        "                      what a classifier learns from cut sequences). Default 0: eq. 3-5 alone\n"
        "  --lateral-weight K  add K times the lateral force's area error to the objective (eq. 3\n"
        "                      on F_lateral, over the travel both cover; offline/calib/calibration.h,\n"
        "                      lateral_term). Default 0: eq. 3-5 alone\n"
        "  --prune KAPPA       stop simulating a candidate once its objective's lower bound (the\n"
        "                      area so far; eq. 3-5's terms are >= 0) passes KAPPA times the last\n"
        "                      generation's median, keeping the mu best exact: a cut one among them\n"
        "                      is simulated on from its cut ('again' in the progress lines;\n"
        "                      offline/calib/calibration.h). Area objective only. Default 0: every\n"
        "                      candidate whole\n"
        "  --no-arm-offset     do not optimise the arm offsets (paper Fig. 9 comparison)\n"
        "  --arm-compliance fit|fixed|C   the person's arm: fit its compliance [m/N] too (one more\n"
        "                      parameter; offline/sim/arm_spring.h), hold it fixed (the paper's, the\n"
        "                      default) or give way by C m per N\n"
        "  --fist-shift fit|fixed|M   the person's fist: fit how far it sits beyond the paper's\n"
        "                      toward the elbow (one more parameter; the elbow stays), hold it at the\n"
        "                      paper's (the default) or at M metres\n"
        "  --rim-shift fit|fixed|M   the robot's grasp: fit how much further ahead of the jaws\n"
        "                      the sleeve opening's rim hangs than the gown's placement puts it\n"
        "                      (4 cm on the measured gown; one more parameter, in [-0.04, 0.04] m by\n"
        "                      default, from -0.01 m on the parametric gown, which holds it 1 cm\n"
        "                      ahead), hold it there (the default) or shift it by M metres\n"
        "  --hem W,R           the gown's cuff: bending R x stiffer within W metres of the sleeve\n"
        "                      opening (held, not fitted; recorded in CAL.json, so synthesis uses\n"
        "                      it too; offline/sim/MEASUREMENTS.md, \"How stiff the gown is\").\n"
        "                      Default none\n"
        "  --density fit|fixed|D   the gown's areal density [kg/m^2]: fit it too (one more parameter,\n"
        "                      in [0.04, 0.25] by default), hold it at the paper's 0.145 (the default)\n"
        "                      or at D; recorded in CAL.json, so synthesis uses it too\n"
        "                      (offline/sim/MEASUREMENTS.md, \"The gown's weight\")\n"
        "  --arm-lateral fit|fixed|M   the person's arm sideways of the gripper's line (+y, away\n"
        "                      from the body): fit it (one more parameter, in [-0.05, 0.05] m by\n"
        "                      default; --lateral-weight lets the lateral force judge it), hold it\n"
        "                      under the jaws (the paper's, the default) or at M metres\n"
        "                      (offline/sim/MEASUREMENTS.md, \"The lateral force\")\n"
        "  --fist-lateral fit|fixed|M   the fist alone sideways, the elbow fixed (the forearm turned\n"
        "                      about the elbow); as --arm-lateral\n"
        "  --support-depth fit|fixed|M   a support under the gown that carries part of its body\n"
        "                      (a 15 cm capsule under the arm; offline/sim/MEASUREMENTS.md,\n"
        "                      \"What holds the gown on the person's side\"): fit how far below\n"
        "                      the grasp its axis is (one more parameter, in [0.6, 1.0] m by\n"
        "                      default), none (the paper's, the default) or at M metres (0: none)\n"
        "  --support-lateral fit|fixed|M   the support sideways (negative: toward the person; in\n"
        "                      [-0.2, 0.05] m by default when fitted); only with a support\n"
        "  --friction improved|constraint|stock   how friction acts in the simulator (offline/sim/\n"
        "                      trial.h, FrictionScheme; default improved, the paper's): held, not\n"
        "                      fitted; recorded in CAL.json, so synthesis and predict use it too\n"
        "                      (the fitted coefficients belong to the scheme they were searched in)\n"
        "  --gown full|reduced|coarse   simulator gown (default reduced)\n"
        "  --threads N         threads per process (default: all cores)\n"
        "  --checkpoint FILE   default CAL.json.ckpt; an existing one is resumed\n"
        "  --stop-after-generations K   stop after K generations in this process (resume later)\n"
        "  --json              machine-readable summary on stdout\n"
        "  On stderr: a line per generation (best L per sequence, elapsed, ETA) and, within a\n"
        "  generation longer than a minute (the full gown's take about 20), a line a minute.\n"
        "  Writes CAL.json and CAL.json.curves.csv (measured and simulated curves; plot them with\n"
        "  tools/plot/calib_overlay.py). Under mpirun every rank runs a share of each generation.\n"
        "\n"
        "       dressguard calibrate --rescore CAL.json --data DATASET --out NEW.json [--why TEXT]\n"
        "  Scores CAL.json again on its own sequences by this build's objective, its values\n"
        "  unchanged (after a change of the objective's definition); the figures it replaces go\n"
        "  into NEW.json's provenance \"rescored\" with TEXT. Writes NEW.json.curves.csv too.");
    return 0;
  }
  if (args.has("rescore")) return rescore_file(args);
  args.allow_only({"help", "json", "no-arm-offset", "data", "participant", "profile", "bounds", "start", "seed", "out",
                   "checkpoint", "objective", "gown", "threads", "generations", "population",
                   "stop-after-generations", "arm-compliance", "fist-shift", "rim-shift", "sigma0", "hem",
                   "density", "contrast-weight", "lateral-weight", "combine", "arm-lateral", "fist-lateral",
                   "support-depth", "support-lateral", "inputs", "friction", "prune"});
  const std::string data = args.require("data");
  const std::string participant = args.require("participant");
  const std::string out = args.require_output_file("out");
  const std::string profile = args.get("profile").value_or("default");
  if (profile != "default" && profile != "quick") throw UsageError("--profile must be default or quick");
  CalibrationOptions o;
  o.generations = profile == "quick" ? 6 : 50;
  o.population = profile == "quick" ? 8 : 32;
  o.generations = static_cast<int>(args.integer("generations", o.generations, 1, 1000000));
  o.population = static_cast<int>(args.integer("population", o.population, 4, 1000000));
  if (o.generations < 1 || o.population < 4) throw UsageError("need --generations >= 1 and --population >= 4");
  if (const auto s0 = args.get("sigma0")) {
    o.sigma0 = args.number("sigma0", o.sigma0);
    if (!(o.sigma0 > 0 && o.sigma0 <= 1)) throw UsageError("--sigma0 must be in (0, 1], not '" + *s0 + "'");
  }
  const long seed = args.integer("seed", 1, 0, LONG_MAX);
  if (seed < 0) throw UsageError("--seed must be non-negative");
  o.seed = static_cast<std::uint64_t>(seed);
  const auto kind = parse_objective(args.get("objective").value_or("area"));
  if (!kind) throw UsageError("--objective must be area or position-weighted");
  o.objective = *kind;
  const auto combine = parse_combine(args.get("combine").value_or("sum"));
  if (!combine) throw UsageError("--combine must be sum, worst, bar or count, not '" + *args.get("combine") + "'");
  o.combine = *combine;
  if (const auto cw = args.get("contrast-weight")) {
    o.contrast_weight = args.number("contrast-weight", 0);
    if (!(o.contrast_weight >= 0 && o.contrast_weight <= 1000))
      throw UsageError("--contrast-weight must be in [0, 1000], not '" + *cw + "'");
  }
  if (const auto lw = args.get("lateral-weight")) {
    o.lateral_weight = args.number("lateral-weight", 0);
    if (!(o.lateral_weight >= 0 && o.lateral_weight <= 1000))
      throw UsageError("--lateral-weight must be in [0, 1000], not '" + *lw + "'");
  }
  if (const auto pr = args.get("prune")) {
    o.prune = args.number("prune", 0);
    if (!(o.prune >= 0 && o.prune <= 100)) throw UsageError("--prune must be in [0, 100], not '" + *pr + "'");
    if (o.prune > 0 && o.objective != ObjectiveKind::Area) throw UsageError("--prune needs --objective area");
  }
  o.threads = static_cast<int>(args.integer("threads", 0, 0, kMaxThreads));
  o.checkpoint = args.get("checkpoint").value_or(out + ".ckpt");
  o.stop_after_generations = static_cast<int>(args.integer("stop-after-generations", 0, 0, 1000000));
  const std::string gown = args.get("gown").value_or("reduced");
  if (gown != "full" && gown != "reduced" && gown != "coarse") throw UsageError("--gown must be full, reduced or coarse");
  o.gown = gown;

  ParameterSpace space;
  // --arm-compliance, --fist-shift, --rim-shift, --density, --arm-lateral, --fist-lateral.
  for (int i = 0; i < kPersonParams; ++i)
    if (const auto v = args.get(kPersonParamInfo[i].flag); v && !set_person_param(space, i, *v))
      throw UsageError(std::string("--") + kPersonParamInfo[i].flag + " must be fit, fixed or a value (" +
                       kPersonParamInfo[i].name + " " + kPersonParamInfo[i].range + "), not '" + *v + "'");
  const ParameterSpace::Person& depth = space.person[kSupportDepth];
  const ParameterSpace::Person& side = space.person[kSupportLateral];
  if ((side.fit || side.value != 0) && !depth.fit && depth.value == 0)
    throw UsageError("--support-lateral needs a support: --support-depth fit or a depth");
  if (const auto hem = args.get("hem")) {
    double w = 0, r = 0;
    char tail = 0;
    if (std::sscanf(hem->c_str(), "%lf,%lf%c", &w, &r, &tail) != 2 || !(w > 0) || !hem_in_range(w, r))
      throw UsageError("--hem must be WIDTH,RATIO with a width in (0, 0.2] m and a ratio in [1, 10000], not '" +
                       *hem + "'");
    space.hem_width = w;
    space.hem_bend_ratio = r;
  }
  if (const auto f = args.get("friction")) {
    if (!friction_scheme_known(*f)) throw UsageError("--friction must be " + friction_scheme_choices() + ", not '" + *f + "'");
    space.friction_scheme = *f;
  }
  space.bounds = args.get("bounds") ? read_bounds(*args.get("bounds")) : default_bounds();
  bool rim_clipped = false;  // the default rim_shift box, clipped to the gown's rim (said below)
#ifdef DRESSGUARD_HAVE_SIM
  // Before --start moves the initial values within the box, and before anything is simulated.
  try {
    rim_clipped = fit_rim_shift_to_gown(space, gown_rim_ahead(), args.get("bounds").value_or(""));
  } catch (const std::invalid_argument& e) {
    throw UsageError("--rim-shift " + args.get("rim-shift").value_or("") + ": " + e.what());
  }
#endif
  std::optional<Calibration> start_cal;
  if (const auto start = args.get("start")) {
    try {
      start_cal = read_calibration(*start);
      start_from(space.bounds, *start_cal);
    } catch (const std::invalid_argument& e) {
      throw UsageError("--start " + *start + ": " + e.what());
    }
  }
  const Dataset ds = load_dataset(data);
  const std::vector<std::string> chosen = split_in_order(args.get("inputs").value_or(""));
  if (args.get("inputs") && chosen.empty()) throw UsageError("--inputs must name one to three trial ids, not '" +
                                                              *args.get("inputs") + "'");
  std::vector<HapticSequence> inputs;
  if (chosen.empty()) {
    inputs = select_inputs(ds, participant, o.seed);
  } else {
    try {
      inputs = inputs_by_id(ds, participant, chosen);
    } catch (const InputError& e) {
      throw UsageError("--inputs: " + std::string(e.what()) + " (" + data + "/manifest.csv)");
    }
  }
  if (!args.has("no-arm-offset"))
    for (const auto& s : inputs) space.offset_heights.push_back(s.height);

#ifndef DRESSGUARD_HAVE_SIM
  throw UsageError("this dressguard was built without the cloth simulator (offline/sim); calibrate needs it");
#else
  const Comm& comm = Comm::world();
  const ClothSimulator sim = make_cloth_simulator(gown);
  // A held rim_shift whose jaws hold none of the gown (the measured gown's from +0.030 m, where
  // they hold no whole triangle of it, gown.h) makes
  // every candidate unbuildable: the whole budget was spent to end with "no candidate could be
  // simulated" (exit 1). Unlike a fitted box's, which the search may leave, it is refused here.
  if (const ParameterSpace::Person& rim = space.person[kRimShift]; !rim.fit) {
    try {
      sim.build_grasp(rim.value);
    } catch (const UnbuildableCandidate& e) {
      throw UsageError("--rim-shift " + args.get("rim-shift").value_or("") + " holds none of the gown: no candidate "
                       "could be simulated (" + e.what() + ")");
    }
  }
  // A fitted box none of whose grasps holds the gown (a bounds file's rim_shift 0.045 0.06 on the
  // measured gown) made every candidate unbuildable too: refused alike, probed at both ends and
  // between (calibration.h, grasp_probes: where no probe builds, no rim_shift of the box does).
  if (const ParamBound& box = space.bounds.person[kRimShift]; space.person[kRimShift].fit)
    if (const std::string why = unbuildable_box(sim, box); !why.empty()) {
      std::string probes;
      for (double r : grasp_probes(box.lower, box.upper)) probes += (probes.empty() ? "" : ", ") + format_number(r);
      throw UsageError("rim_shift's box [" + format_number(box.lower) + ", " + format_number(box.upper) + "] m holds " +
                       "none of the gown at any rim_shift (probed at " + probes + " m: calibration.h, grasp_probes): " +
                       "no candidate could be simulated (" + why + ")");
    }
  // Now, not after the first generation (20 minutes on the full gown), and on every rank.
  try {
    probe_checkpoint(o.checkpoint, comm);
  } catch (const InputError& e) {
    throw UsageError("--checkpoint " + std::string(e.what()));
  }
  if (comm.is_root()) {
    std::string ids;  // the selected sequences, "s4-good-3, s4-miss-2"
    for (const HapticSequence& s : inputs) ids += (ids.empty() ? "" : ", ") + s.id;
    std::fprintf(stderr, "calibrate: participant %s, %zu sequences (%s), %d parameters, %d x %d, %d rank(s) x %d "
                 "thread(s), gown %s%s%s\n", participant.c_str(), inputs.size(), ids.c_str(), space.dimension(),
                 o.generations, o.population, comm.size(), thread_count(o.threads), gown.c_str(),
                 space.friction_scheme == kFrictionSchemes[0] ? "" : ", friction ",
                 space.friction_scheme == kFrictionSchemes[0] ? "" : space.friction_scheme.c_str());
    // Said before the first generation (minutes away at the paper's budget): whether this run
    // starts afresh or continues a stopped one. A checkpoint of another command is refused then.
    if (rim_clipped)
      std::fprintf(stderr, "calibrate: note: rim_shift's box is [%g, %g] m on this gown, whose sleeve opening is "
                   "held %g m ahead of the jaws (the default box is the measured gown's)\n",
                   space.bounds.person[kRimShift].lower, space.bounds.person[kRimShift].upper, gown_rim_ahead());
    std::fprintf(stderr, "calibrate: checkpoint %s (%s)\n", o.checkpoint.c_str(),
                 std::filesystem::exists(o.checkpoint) ? "exists: resumed if it is this run's"
                                                       : "new: written each generation");
    // The seed picks the sequences (IV-B.1: one per height at random) unless --inputs names them.
    // Continuing a calibration of the same person on other trials than the file was fitted to (its
    // offsets included) is legitimate but rarely what was meant: said before the hours of search,
    // with the --inputs value that would fit the file's own trials.
    if (start_cal && start_cal->cloth.friction_scheme != space.friction_scheme)
      std::fprintf(stderr, "calibrate: note: --start %s was searched under the %s friction scheme, this run "
                   "simulates %s (--friction): its values are a start, not a fit, here\n",
                   args.get("start")->c_str(), start_cal->cloth.friction_scheme.c_str(), space.friction_scheme.c_str());
    if (start_cal && start_cal->participant == participant) {
      std::string was;
      std::string flag;  // the same as --inputs' value, "s4-good-3,s4-miss-2"
      for (const SequenceFit& f : start_cal->fits) {
        was += (was.empty() ? "" : ", ") + f.trial_id;
        flag += (flag.empty() ? "" : ",") + f.trial_id;
      }
      if (was != ids && chosen.empty())
        std::fprintf(stderr, "calibrate: note: --start %s was fitted to %s; seed %llu selects %s (--inputs %s "
                     "fits those)\n", args.get("start")->c_str(), was.c_str(),
                     static_cast<unsigned long long>(o.seed), ids.c_str(), flag.c_str());
      if (was != ids && !chosen.empty())
        std::fprintf(stderr, "calibrate: note: --start %s was fitted to %s; --inputs names %s\n",
                     args.get("start")->c_str(), was.c_str(), ids.c_str());
    }
  }
  // Within a generation, a line a minute at most: one of the full gown takes about 20 min on two
  // cores, and a generation's own line says when it ends.
  int line_generation = -1;
  double line_at = 0;  // the generation's elapsed time at its last line
  o.candidate_progress = [&](const CandidateProgress& c) {
    if (c.generation != line_generation) {
      line_generation = c.generation;
      line_at = 0;
    }
    if (c.done == c.total || c.elapsed_s - line_at < 60) return;
    line_at = c.elapsed_s;
    std::fprintf(stderr, "  generation %d/%d: %d of %d %s on this rank in %s\n", c.generation, o.generations,
                 c.done, c.total, c.finishing ? "cut candidates finished" : "candidates", minutes(c.elapsed_s).c_str());
  };
  bool first_line = true;
  const CalibrationResult r = calibrate(inputs, space, sim.trials, o, comm, [&](const GenerationProgress& p) {
    std::string per;  // the best point's L per sequence
    for (std::size_t k = 0; k < p.best_fits.size() && k < inputs.size(); ++k) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s%s %.3f", k ? ", " : "", inputs[k].id.c_str(), p.best_fits[k]);
      per += buf;
    }
    if (o.contrast_weight > 0) {
      char buf[64];
      std::snprintf(buf, sizeof buf, ", contrast %.3f", p.best_contrast);
      per += buf;
    }
    if (o.lateral_weight > 0) {
      char buf[64];
      std::snprintf(buf, sizeof buf, ", lateral %.3f", p.best_lateral);
      per += buf;
    }
    // The first line of a resumed process says where it took over (each line follows one generation).
    char resumed[64] = "";
    if (p.resumed && first_line) std::snprintf(resumed, sizeof resumed, "  (resumed after generation %d)", p.generation - 1);
    first_line = false;
    char pruned[64] = "";
    if (o.prune > 0)
      std::snprintf(pruned, sizeof pruned, "  pruned %d/%d (%d again)", p.pruned, o.population, p.resimulated);
    // The cloth time simulated: the work a generation's wall time follows, without the machine's noise.
    std::fprintf(stderr, "generation %d/%d  best L %.4f (%s)  (this generation %.4f)%s  elapsed %s  ETA %s  "
                 "%.0f s of cloth simulated%s\n",
                 p.generation, p.generations, p.best, per.c_str(), p.generation_best, pruned,
                 minutes(p.elapsed_s).c_str(), minutes(p.eta_s).c_str(), p.simulated_s, resumed);
  });
  if (!r.resume_note.empty() && comm.is_root())
    std::fprintf(stderr, "calibrate: note: %s: %s\n", o.checkpoint.string().c_str(), r.resume_note.c_str());
  if (!r.complete) {
    if (comm.is_root()) {
      if (args.has("json"))
        std::printf("{\"complete\": false, \"generations_done\": %d, \"checkpoint\": %s}\n", r.generations_done,
                    json_string(o.checkpoint.string()).c_str());
      else
        std::printf("stopped after %d generations; run the same command again to resume from %s\n",
                    r.generations_done, o.checkpoint.c_str());
    }
    return 0;
  }
  Calibration cal = calibration_of(participant, r, space, o, inputs);
  Json prov = Json::object();
  prov.set("tool", "dressguard calibrate");
  prov.set("created", utc_now());
  prov.set("dataset", data);
  prov.set("seed", std::to_string(o.seed));
  prov.set("inputs", chosen.empty() ? "chosen by the seed (IV-B.1)" : "named by --inputs");
  prov.set("profile", profile);
  prov.set("generations", r.generations_done);
  prov.set("population", o.population);
  prov.set("evaluations", r.evaluations);
  prov.set("start_objective", r.start_objective);
  prov.set("sigma0", o.sigma0);
  prov.set("simulations", r.evaluations * static_cast<long>(inputs.size()));
  prov.set("ranks", comm.size());
  prov.set("threads_per_rank", thread_count(o.threads));
  prov.set("elapsed_s_last_process", r.elapsed_s);
  prov.set("simulated_s_last_process", r.simulated_s);  // cloth time, the start and this process's generations
  if (o.prune > 0) {  // only when asked (files of unpruned runs keep their fields)
    prov.set("prune", o.prune);
    prov.set("pruned_last_process", r.pruned);
    prov.set("resimulated_last_process", r.resimulated);
  }
  Json names = Json::array();
  for (const auto& n : space.names()) names.push(n);
  prov.set("parameters", names);
  Json boxes = Json::array();  // each searched parameter's [lower, upper], in "parameters" order
  for (const ParamBound& b : space.boxes()) {
    Json box = Json::array();
    box.push(b.lower);
    box.push(b.upper);
    boxes.push(box);
  }
  prov.set("boxes", boxes);
  Json unit = Json::array();
  for (long i = 0; i < r.best_unit.size(); ++i) unit.push(r.best_unit[i]);
  prov.set("best_unit_vector", unit);
  cal.provenance = prov;
  // The best candidate's curves, simulated again (deterministic: the same as during the search).
  std::vector<SimulatedTrial> curves(inputs.size());
  if (comm.is_root()) {
    curves = simulate_inputs(sim.trials, r.cloth, r.offsets, inputs);
    measure_axis_fits(cal.fits, inputs, curves);
    write_calibration(out, cal);
    write_file_atomic(out + ".curves.csv",
                      overlay_csv(inputs, curves, args.has("no-arm-offset") ? "simulated-no-offset" : "simulated"));
    std::filesystem::remove(o.checkpoint);  // done: a rerun starts afresh
    if (args.has("json")) {
      std::printf("%s\n", calibration_to_json(cal).dump(0).c_str());
    } else {
      std::printf("participant %s: L = %.4f after %d generations (%ld evaluations, %s; the start's L %.4f)\n",
                  participant.c_str(), r.objective, r.generations_done, r.evaluations, minutes(r.elapsed_s).c_str(),
                  r.start_objective);
      if (std::string(r.stopped_by) != "max-generations")
        std::printf("  CMA-ES stopped on its own criterion (%s) before the budget of %d generations\n", r.stopped_by,
                    o.generations);
      if (o.prune > 0)
        std::printf("  pruned at %g x the last generation's median: %ld candidates cut, %ld of them finished whole "
                    "from the cut (this process)\n", o.prune, r.pruned, r.resimulated);
      if (o.combine != SequenceCombine::Sum) {
        double sum = 0;
        for (const auto& f : cal.fits) sum += f.objective;
        std::printf("  L combines the sequences as %s (%s + %g x sum); their sum, the paper's L: %.4f\n",
                    std::string(combine_name(o.combine)).c_str(),
                    o.combine == SequenceCombine::Worst ? "max"
                    : o.combine == SequenceCombine::Bar ? "the excesses over 0.3"
                                                        : "the count over 0.3 + the excesses over it",
                    kWorstRho, sum);
      }
      for (const auto& f : cal.fits)
        std::printf("  %-18s %-6s L = %.4f; over the common travel F_motion %.3f (zero force %.3f), F_vertical %.3f "
                    "(zero force %.3f), F_lateral %.3f (zero force %.3f) N m\n", f.trial_id.c_str(),
                    std::string(arm_height_name(f.height)).c_str(), f.objective, f.motion.error, f.motion.zero,
                    f.vertical.error, f.vertical.zero, f.lateral.error, f.lateral.zero);
      if (o.contrast_weight > 0)
        std::printf("  the heights' contrast to %.2f m: %.4f N m, times %g: %.4f of L\n", kLatestCut,
                    r.contrast / o.contrast_weight, o.contrast_weight, r.contrast);
      if (o.lateral_weight > 0)
        std::printf("  the lateral force over the common travel: %.4f N m, times %g: %.4f of L\n",
                    r.lateral / o.lateral_weight, o.lateral_weight, r.lateral);
      for (int i = 0; i < kClothParams; ++i) {
        std::printf("  %-13s %.4f", kClothParamNames[i], cloth_value(r.cloth, i));
        // What bend means as a fabric (light woven fabrics: 1.5-3 cm; offline/sim/MEASUREMENTS.md).
        if (std::string(kClothParamNames[i]) == "bend" && sim.bending_length)
          std::printf("  (bending length %.1f cm on this gown)",
                      100 * sim.bending_length(cloth_value(r.cloth, i), r.cloth.areal_density));
        std::printf("\n");
      }
      for (int i = 0; i < kPersonParams; ++i)
        if (space.person[i].fit || person_value(r.cloth, i) != kPersonParamInfo[i].paper)
          std::printf("  %-14s %.4f%s\n", kPersonParamInfo[i].name, person_value(r.cloth, i), space.person[i].fit ? "" : " (held)");
      if (r.cloth.hem_width > 0)
        std::printf("  hem           %.3f m, bending x %g (held)\n", r.cloth.hem_width, r.cloth.hem_bend_ratio);
      if (r.cloth.friction_scheme != kFrictionSchemes[0])
        std::printf("  friction      the %s scheme (held)\n", r.cloth.friction_scheme.c_str());
      for (ArmHeight h : space.offset_heights)
        std::printf("  arm offset %-6s %+.4f m\n", std::string(arm_height_name(h)).c_str(), r.offsets[static_cast<int>(h)]);
      std::printf("wrote %s and %s.curves.csv\n", out.c_str(), out.c_str());
    }
  }
  return 0;
#endif
}

}  // namespace dressguard::cli
