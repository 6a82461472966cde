// Simulator calibration (paper section IV-B): CMA-ES over the cloth parameters and one arm-height
// deviation per arm height used, minimising the area objective (eq. 3-5) between simulated and
// measured force sequences of one participant.
//
// The simulator enters through `TrialSimulator` (a function), so that this module builds and is
// tested without the cloth simulator (unit tests use a cheap analytic stand-in), and
// sim_bridge.h binds it to dg_sim's simulate_trial() when that library is built.
#pragma once

#include <array>
#include <cmath>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "dataset.h"
#include "files.h"
#include "haptic.h"
#include "json.h"
#include "objective.h"
#include "person_limits.h"
#include "runner.h"

namespace dressguard::calib {

// ---- what calibration needs from a simulator ---------------------------------------------------

// The simulator's friction schemes by name (sim::friction_scheme_name; sim_bridge.cpp checks the
// two lists agree): the first is the paper's and every calibration's without one in its file.
inline constexpr std::array<const char*, 3> kFrictionSchemes = {"improved", "constraint", "stock"};
bool friction_scheme_known(const std::string& name);
// The names above as an error message lists them: "improved, constraint or stock".
std::string friction_scheme_choices();

// The five cloth parameters of paper IV-B.2, in the simulator's units.
struct ClothValues {
  double stretch = 0.8;        // isotropic stretch stiffness (vertical = horizontal)
  double shear = 0.5;
  double bend = 0.7;
  double friction = 0.5;       // cloth-arm
  double self_friction = 0.2;  // cloth-cloth
  // The person's arm (kPersonParams below; 0 is the paper's), fitted only when ParameterSpace
  // asks for it: [m/N] how far it gives per newton of the cloth's pull (sim/arm_spring.h), and
  // [m] how far its fist sits beyond the paper's toward the elbow (sim/trial.h, ClothParams).
  double arm_compliance = 0.0;
  double fist_shift = 0.0;
  // The gown's cuff (sim/trial.h ClothParams::hem_width, hem_bend_ratio): bending hem_bend_ratio x
  // stiffer within hem_width [m] of the sleeve opening. Held, never fitted (ParameterSpace::hem);
  // 0 and 1 are the paper's uniform cloth.
  double hem_width = 0.0;
  double hem_bend_ratio = 1.0;
  // How the robot holds the gown (kRimShift below; 0 is the gown's placement): [m] how much
  // further ahead of the jaws the sleeve opening's rim is than offline/gown/placement.h puts it
  // (kOpeningRimAhead, 4 cm on the measured gown). The study did not measure it.
  double rim_shift = 0.0;
  // The gown's areal density [kg/m^2] (sim/trial.h ClothParams::areal_density; kArealDensity
  // below). The paper's simulator, and every calibration without one in its file, used
  // kPaperArealDensity. The study did not weigh its gown.
  double areal_density = 0.145;
  // [m] the person's arm sideways of the gripper's line, and the fist alone sideways of the
  // elbow (sim/trial.h ClothParams::arm_lateral, fist_lateral; kArmLateral, kFistLateral below).
  // Only the lateral force tells where they are (calibrate --lateral-weight).
  double arm_lateral = 0.0;
  double fist_lateral = 0.0;
  // [m] the support under the gown (sim/trial.h ClothParams::support_depth, support_lateral;
  // kSupportDepth, kSupportLateral below): its axis below the grasp (0: none) and sideways.
  double support_depth = 0.0;
  double support_lateral = 0.0;
  // How friction acts (sim/trial.h FrictionScheme, by its name; kFrictionSchemes above): the
  // paper's improved scheme unless a calibration chose another. Held, never fitted
  // (ParameterSpace::friction_scheme): fitted friction coefficients belong to the scheme they were
  // searched under (offline/calib/MEASUREMENTS.md, session 49), so the file carries it.
  std::string friction_scheme = kFrictionSchemes[0];
};
inline constexpr double kPaperArealDensity = 0.145;
// [m] the largest arm offset a calibration file holds (read_calibration refuses more, so does
// `simulate --arm-offset`); a bounds file's arm_offset box must lie within it.
inline constexpr double kMaxArmOffset = 0.5;
inline constexpr int kClothParams = 5;
// A cuff's limits (sim/params.cpp checks the same): width in [0, 0.2] m, ratio in [1, 1e4].
inline constexpr double kMaxHemWidth = 0.2, kMaxHemBendRatio = 1e4;
inline bool hem_in_range(double width, double ratio) {
  return width >= 0 && width <= kMaxHemWidth && ratio >= 1 && ratio <= kMaxHemBendRatio;
}
inline constexpr std::array<const char*, kClothParams> kClothParamNames = {"stretch", "shear", "bend", "friction",
                                                                           "self_friction"};
// The simulator's limits of each cloth value (sim/trial.h and sim/params.cpp check the same): the
// stiffnesses are positions on their compliance scales, which the simulator clamps to [0, 1], so a
// box beyond would search a flat objective; a friction coefficient is not negative. read_bounds
// refuses a box past them.
struct ClothParamLimits {
  double lowest, highest;
  const char* range;
};
inline constexpr ClothParamLimits kStiffnessLimits = {
    0.0, 1.0, "must be within [0, 1] (a position on its compliance scale; the simulator clamps beyond)"};
inline constexpr ClothParamLimits kFrictionLimits = {0.0, std::numeric_limits<double>::infinity(),
                                                     "cannot be negative"};
inline constexpr std::array<ClothParamLimits, kClothParams> kClothParamLimits = {
    kStiffnessLimits, kStiffnessLimits, kStiffnessLimits, kFrictionLimits, kFrictionLimits};
double cloth_value(const ClothValues& c, int i);
void set_cloth_value(ClothValues& c, int i, double v);

// Parameters beyond the paper's five cloth values: the person's arm, the robot's grasp and the
// gown's weight. Each is fitted within its bounds or held at a value (ParameterSpace::person);
// held, each defaults to `paper`, the value of the paper's simulator (its arm, the gown's own
// placement, its density).
// `lowest`/`highest` bound every box and held value (the simulator's own limits); `range` says so
// in an error message.
struct PersonParamInfo {
  const char* name;
  const char* flag;  // the command-line option, without its "--" (dressguard calibrate)
  double lowest, highest;
  double paper;
  const char* range;
};
inline constexpr int kPersonParams = 8;
inline constexpr int kArmCompliance = 0;  // [m/N] sim/arm_spring.h
inline constexpr int kFistShift = 1;      // [m] sim/trial.h ClothParams::fist_shift
inline constexpr int kRimShift = 2;       // [m] ClothValues::rim_shift (the grasp, sim_bridge.h)
inline constexpr int kArealDensity = 3;   // [kg/m^2] sim/trial.h ClothParams::areal_density
inline constexpr int kArmLateral = 4;     // [m] sim/trial.h ClothParams::arm_lateral
inline constexpr int kFistLateral = 5;    // [m] sim/trial.h ClothParams::fist_lateral
inline constexpr int kSupportDepth = 6;    // [m] sim/trial.h ClothParams::support_depth
inline constexpr int kSupportLateral = 7;  // [m] sim/trial.h ClothParams::support_lateral
inline constexpr std::array<PersonParamInfo, kPersonParams> kPersonParamInfo = {{
    {"arm_compliance", "arm-compliance", 0.0, kMaxArmCompliance, 0.0, kArmComplianceRange},
    {"fist_shift", "fist-shift", -0.2, 0.2, 0.0, "must be within +-0.2 m (the forearm is 0.31 m)"},
    {"rim_shift", "rim-shift", -0.04, 0.06, 0.0, "must be within -0.04 and +0.06 m (the rim 0 to 10 cm ahead of the jaws)"},
    {"areal_density", "density", kMinArealDensity, kMaxArealDensity, kPaperArealDensity, kArealDensityRange},
    {"arm_lateral", "arm-lateral", -0.1, 0.1, 0.0, "must be within +-0.1 m (beyond it the fist is beside the opening)"},
    {"fist_lateral", "fist-lateral", -0.1, 0.1, 0.0, "must be within +-0.1 m (beyond it the fist is beside the opening)"},
    {"support_depth", "support-depth", 0.0, 1.5, 0.0, "must be within 0 (no support) and 1.5 m below the grasp"},
    {"support_lateral", "support-lateral", -0.3, 0.3, 0.0, "must be within +-0.3 m"},
}};
double person_value(const ClothValues& c, int i);
void set_person_value(ClothValues& c, int i, double v);

// One simulated trial's conditions.
struct TrialRequest {
  ArmHeight height = ArmHeight::High;
  double arm_offset = 0.0;   // [m] added to the height's nominal arm height
  double speed = 0.1;        // [m/s]
  std::uint64_t seed = 0;    // the gown perturbation's random stream
  bool gown_noise = false;   // paper V-A perturbation (x and lateral each up to 6 N, 0.5 s) on or off
  double max_travel = 0.85;  // [m] end of the rig's travel (the paper's 0.85 m; see request_for)
  // Optional (calibrate --prune): asked after each simulated sample with the samples so far and
  // whether the trial has ended; `true` stops a trial that has not (SimulatedTrial::cut). A
  // simulator that cannot stop early may ignore it (its trials are then never cut).
  std::function<bool(const std::vector<HapticSample>& so_far, bool ended)> watch;
};

struct SimulatedTrial {
  std::vector<HapticSample> samples;
  // The automatic label of paper V-A; none when the simulation blew up (sim::TrialResult::outcome).
  std::optional<Outcome> outcome = Outcome::Missed;
  bool finite = true;                 // false: the simulation blew up (ranked worst)
  // false: the gown was still moving when its settling gave up (sim::TrialResult::settled,
  // sim::TrialSpec::settle_max_steps) and the pull began from it; the paper's robot waits.
  bool settled = true;
  // The label's evidence (sim::TrialResult): how far the lower half of the sleeve opening ended
  // behind the elbow centre (forearm side) and past it [m], 0 for a missed trial; NaN when the
  // simulator does not say (a test's stand-in).
  double d_behind = std::numeric_limits<double>::quiet_NaN();
  double d_ahead = std::numeric_limits<double>::quiet_NaN();
  bool cut = false;  // TrialRequest::watch stopped it: `samples` end there, the label is not a trial's
  // A cut trial's rest, when the simulator kept its state at the cut: the whole trial, the same
  // bits as simulating the request again without its watch, for the cost of the part after the
  // cut (the cloth simulator: sim::resume_trial). Empty when the simulator keeps no state (the
  // caller simulates the request again). Callable on the process that made it, from any thread.
  std::function<SimulatedTrial()> rest;
  // [s] the cloth time this result cost on its own, the work a calibration's wall time follows:
  // its settling unless it started from another trial's, and its pull after the part pulled as
  // one with another trial (sim::simulate_trials); for a rest, the pull after the cut. A batch's
  // results sum to what it simulated. 0: the simulator does not say.
  double simulated_s = 0;
};

// Must be deterministic and callable from several threads at once.
using TrialSimulator = std::function<SimulatedTrial(const ClothValues&, const TrialRequest&)>;
// One cloth's trials at once, results in the requests' order, each the same as the one-trial
// simulator's: a simulator may share work between them (the cloth simulator settles the gown
// once for all arm heights, sim::simulate_trials). The same rules as TrialSimulator.
using TrialBatchSimulator =
    std::function<std::vector<SimulatedTrial>(const ClothValues&, const std::vector<TrialRequest>&)>;
// The batch form of a one-trial simulator: its trials one after another.
TrialBatchSimulator one_by_one(TrialSimulator sim);

// What a simulator throws for values whose scene it cannot build: the cloth simulator's when the
// gripper's jaws hold no whole triangle of the gown at the values' rim_shift (sim_bridge.h;
// gown::NothingGrasped: on the measured gown from rim_shift +0.030 m, the rim 7.0 cm ahead of
// the jaws; no vertex at all from +0.0431 m, 8.31 cm). An InputError,
// so a command that simulates a calibration file's values refuses them (exit 2); calibrate ranks
// such a candidate last, as a simulation that blew up (calibrate's "Failures"), and the command
// refuses a held rim_shift that builds none before its search (ClothSimulator::build_grasp).
class UnbuildableCandidate : public InputError {
 public:
  using InputError::InputError;
};

// ---- parameter space and bounds ------------------------------------------------------------------

// A box per parameter. Read from a bounds file (read_bounds) or the documented defaults.
struct ParamBound {
  double lower = 0, upper = 1, initial = 0.5;
  long line = 0;  // the bounds file's line that gave this box (read_bounds); 0: a default
};
struct Bounds {
  std::array<ParamBound, kClothParams> cloth;
  ParamBound arm_offset;                           // [m], shared by the offsets of every height
  std::array<ParamBound, kPersonParams> person;  // kPersonParamInfo order, when fitted
  // Per height (ArmHeight order), a start for that height's offset instead of arm_offset.initial:
  // another calibration's own offsets (start_from, below).
  std::array<std::optional<double>, 3> offset_initial{};
};
// Defaults (the simulator's box, sim/trial.h ClothParams): stretch, shear, bend in [0, 1] (start
// 0.2, 0.5, 0.7); friction and self_friction in [0, 2] (start 0.35, 0.2): the plausibility grid's
// best point against participant 4, see calibration.cpp; arm offset in
// [-0.06, 0.06] m (start 0): the study's middle noise spans 6 cm (paper V-A), and the paper's
// calibrated offset for participant 4 was -0.02 m; arm compliance in [0, 0.01] m/N (start
// 0.004): a stiffness of 100 N/m and up, the hand's postural stiffness being about 300-800 N/m
// (sim/arm_spring.h) and a held-out forearm softer; fist shift in [-0.05, 0.15] m (start 0, the
// paper's arm): a fist-to-elbow length of 0.16-0.36 m; rim shift in [-0.04, 0.04] m (start 0):
// the measured gown's rim held 0 to 8 cm ahead of the jaws (beyond 8 cm the jaws' 8 cm run off
// the reduced gown's sleeve top); areal density in [0.04, 0.25] kg/m^2 (start 0.145, the
// paper's): from a spunbond disposable gown to a heavy woven cotton one; arm lateral and fist
// lateral each in [-0.05, 0.05] m (start 0, the paper's arm under the jaws): the fist's 5 cm
// radius, so that it stays in front of the opening (about 16 cm wide) at either end of the box;
// support depth in [0.6, 1.0] m (start 0.85) and support lateral in [-0.2, 0.05] m (start -0.1):
// around the support that brought participant 4's middle arm nearest the people with his
// calibrated cloth and kept his high arm good (sim README, "What holds the gown on the person's
// side"), its top 0.45-0.85 m below the grasp (at 0.6-0.75 m that cloth's high arm
// catches); the person's side favoured.
Bounds default_bounds();
// Bounds file: one "name lower upper [initial]" per line, '#' starts a comment, names as in
// kClothParamNames plus "arm_offset" and kPersonParamInfo's; unnamed parameters keep their
// defaults. InputError names the file and line of a malformed row (unknown name, a bound or
// initial value that is not a finite number, lower >= upper, initial outside the box, a person
// parameter's box outside its range, a name given a second time).
Bounds read_bounds(const std::filesystem::path& path);

// The search vector: the five cloth parameters, one offset per used height (high, middle, low
// order), then each fitted person parameter (kPersonParamInfo order), each normalised to [0, 1] over its box
// (CMA-ES works in the unit box, as the paper's public code did, so sigma means the same for
// every coordinate).
struct ParameterSpace {
  Bounds bounds;
  std::vector<ArmHeight> offset_heights;  // heights with an optimised offset; empty: --no-arm-offset
  // Each person parameter: fitted within bounds.person[i], or held at `value` (default
  // kPersonParamInfo[i].paper).
  struct Person {
    bool fit = false;
    double value = 0.0;
  };
  static std::array<Person, kPersonParams> paper_person() {
    std::array<Person, kPersonParams> p{};
    for (int i = 0; i < kPersonParams; ++i) p[i] = {false, kPersonParamInfo[i].paper};
    return p;
  }
  std::array<Person, kPersonParams> person = paper_person();
  // The gown's cuff every candidate is simulated with (ClothValues::hem_width, hem_bend_ratio).
  double hem_width = 0.0, hem_bend_ratio = 1.0;
  // The friction scheme every candidate is simulated with (ClothValues::friction_scheme).
  std::string friction_scheme = kFrictionSchemes[0];
  int fitted_person_params() const {
    int n = 0;
    for (const Person& p : person) n += p.fit ? 1 : 0;
    return n;
  }
  int dimension() const { return kClothParams + static_cast<int>(offset_heights.size()) + fitted_person_params(); }
  Eigen::VectorXd initial_unit() const;
  ClothValues cloth(const Eigen::VectorXd& unit) const;
  std::array<double, 3> offsets(const Eigen::VectorXd& unit) const;  // [m] by ArmHeight, 0 if not optimised
  std::vector<std::string> names() const;  // "stretch", ..., "arm_offset_high", ..., "arm_compliance", ...
  // The box of each parameter of names(), in that order: the unit box's ends in metres, N/m... A
  // calibration file records them (provenance "boxes"), so that a later tool knows the search's
  // box when a bounds file set it.
  std::vector<ParamBound> boxes() const;
};

// One parameter of a search by its ParameterSpace::names() spelling: where it lives in a
// calibration's (cloth, offsets) and which box of a Bounds is its own. What a tool that reads
// a calibration file's provenance needs to move a searched parameter (bench_calib_landscape).
struct ParamRef {
  enum class Kind { Cloth, Person, Offset } kind;
  int index;  // into kClothParamNames, kPersonParamInfo, or ArmHeight
};
std::optional<ParamRef> find_param(std::string_view name);  // nullopt: not a parameter's name
double param_value(const ParamRef& p, const ClothValues& c, const std::array<double, 3>& offsets);
void set_param_value(const ParamRef& p, ClothValues& c, std::array<double, 3>& offsets, double v);
const ParamBound& box_of(const Bounds& b, const ParamRef& p);
ParamBound& box_of(Bounds& b, const ParamRef& p);  // read_bounds fills a box through it

// The rim_shift a gown can take: its sleeve opening's rim is held `rim_ahead` [m] ahead of the
// jaws (sim_bridge.h, gown_rim_ahead: 4 cm on the measured gown, 1 cm on the parametric one),
// and a shift below -rim_ahead puts the rim behind them, a grasp the simulator cannot build
// (grasp_of throws). A search would stop at its first such candidate, after the start and part
// of a generation were simulated (session 84's review, finding 2), so before it: a value held
// below -rim_ahead throws std::invalid_argument (the caller names --rim-shift); a fitted box that
// a bounds file gave (ParamBound::line) reaching below it throws InputError naming `bounds_file`
// and the line; the default box, made for the measured gown, is clipped to start at -rim_ahead,
// and then the function returns true (the caller says so). The box's initial value must then
// still lie within it (std::invalid_argument otherwise).
bool fit_rim_shift_to_gown(ParameterSpace& space, double rim_ahead, const std::filesystem::path& bounds_file);

// The rim_shifts across [lower, upper] at which calibrate builds a fitted rim_shift box's grasp
// before its search, to refuse a box none of whose grasps the simulator can build (every
// candidate unbuildable: the whole budget spent, then "no candidate could be simulated"): both
// ends and evenly spaced points between, at most kGraspProbeStep apart. The grasp at a rim_shift
// is the gown's placement moved rigidly along x by it (placement.h, OpeningGrip), so a vertex is
// in the jaws over an interval of rim_shifts as long as the jaws (8 cm), and a whole triangle
// (what a grasp must hold, gown.h) over one shorter by the triangle's length along x (the full
// measured gown's edges are about 1.4 cm): probes 4 cm apart meet every such interval that
// reaches into the box, so when none of them builds, no rim_shift in the box does. Cheap: a
// grasp is built in about 0.3 s on the reduced gown, and probing stops at the first that builds.
inline constexpr double kGraspProbeStep = 0.04;  // [m] half the jaws' length along x
std::vector<double> grasp_probes(double lower, double upper);

// Person parameter i of `space` from a command line's word: "fit" (search bounds.person[i]),
// "fixed" (kPersonParamInfo[i].paper), or a value held during the search. False when the word is
// none of these (or a non-finite number or one outside kPersonParamInfo[i]'s range).
bool set_person_param(ParameterSpace& space, int i, const std::string& word);

// ---- input selection (paper IV-B.1) -------------------------------------------------------------

// [s] The simulator's sample period: one haptic sample per 3 output steps at 300 Hz (sim/trial.h).
inline constexpr double kSimulatedSamplePeriod = 0.01;
// Eq. 3-5 pairs a simulated and a measured curve sample by sample, so a measured sequence can be
// scored against the simulator only when it was recorded at the simulator's rate: a repeat of a
// study trial kept at 50 Hz scores L = 12.9 against itself at 100 Hz, where two real repeats
// differ by 0.22 (session 90's review). Throws InputError naming the trial's file (dataset.h,
// trial_file_name) and both periods when `t`'s mean period is not kSimulatedSamplePeriod within
// kRecordingPeriodTolerance (relative, a recording's jitter); a trial of fewer than two samples
// has no period to compare (a dataset's readers refuse it). What select_inputs, inputs_by_id,
// prediction_targets and calibration_inputs return has passed it.
void require_simulated_rate(const Dataset& ds, const HapticSequence& t);

// One measured sequence per arm height of `participant`, chosen at random (by `seed`) among its
// labelled non-caught trials; heights with only caught trials are left out (2 sequences).
// Throws InputError when the participant has none.
std::vector<HapticSequence> select_inputs(const Dataset& ds, const std::string& participant, std::uint64_t seed);

// The measured sequences named by `ids` instead (`calibrate --inputs`): what a user gives to
// fit chosen trials, e.g. to continue a calibration on the trials it was fitted to under another
// CMA-ES seed. The same rules as the seeded choice: each a labelled good or missed trial of
// `participant`, at most one per arm height; returned in the seeded choice's order (high, middle,
// low). Throws InputError naming the trial and the rule it breaks.
std::vector<HapticSequence> inputs_by_id(const Dataset& ds, const std::string& participant,
                                         const std::vector<std::string>& ids);

// ---- the driver ---------------------------------------------------------------------------------

// How the input sequences' objectives combine into the one number CMA-ES minimises.
//
//   Sum    the paper (eq. 5 summed over the selected sequences):   L = sum_k L_k
//   Worst  augmented Chebyshev scalarisation (Steuer and Choo 1983):
//                                                 L = max_k L_k + kWorstRho * sum_k L_k
//
// The weighted contrast and lateral terms are added to either. Why Worst: issue 4 judges each
// sequence on its own (L_k <= 0.3), and the sum trades one sequence against another. Participant
// 1's paper-budget run had 0.282 / 0.298 in generation 43 and kept 0.268 / 0.305 from generation
// 50, whose sum was lower (offline/calib/MEASUREMENTS.md, session 34). The max alone would rank
// a generation by one sequence and leave CMA-ES blind to how the others move; with the rho term
// every minimiser is Pareto-optimal, and the worst sequence decides unless another one moves
// more than (1 + rho) / rho = 11 times as much.
//
//   Bar    each sequence's excess over issue 4's bar, plus the same rho term:
//                                     L = sum_k max(0, L_k - kSequenceBar) + kWorstRho * sum_k L_k
//
// Why Bar: Worst lowers the max and pays for it with sequences already within the bar. Session
// 65 measured it twice: participant 2's worst fell from 0.464 to 0.391 while his good and missed
// sequences left the bar (0.282 / 0.292 to 0.363 / 0.391); participant 0's from 0.588 to 0.540
// while his good one did (0.231 to 0.483). Under Bar a sequence within 0.3 costs rho per unit
// until it crosses, and 1 + rho beyond, so the search lowers the ones above the bar. It does not
// keep the others there: a sequence at the bar is priced at its excess like any other, and is
// traded as soon as another gains more (session 66: participant 2's good sequence 0.282 -> 0.330
// for his middle one 0.464 -> 0.417; participant 7's missed one 0.302 -> 0.331 for his good one).
//
//   Count  the number of sequences over the bar first, then Bar:
//                                     L = #{k : L_k > kSequenceBar} + Bar
//
// Why Count: issue 4 counts sequences within 0.3, and only a step in L keeps a sequence there
// against a trade. While the Bar term stays below 1 (three sequences each under about 0.57, as
// 3.3 L - 0.9 < 1) the order is lexicographic: fewer sequences over the bar always wins, and among
// equals Bar decides. Session 66: from participant 2's support file at sigma0 0.003 it lowered
// all three (0.282 / 0.464 / 0.292 to 0.262 / 0.443 / 0.279) where Bar, from the same first
// draws, let the missed one cross (0.300).
//
// All four never decrease when one L_k grows, so a cut candidate's lower bounds still bound it
// (`--prune`). CMA-ES uses only the candidates' ranks, so the kinks and the steps do no harm.
enum class SequenceCombine { Sum, Worst, Bar, Count };
inline constexpr double kWorstRho = 0.1;
inline constexpr double kSequenceBar = 0.3;  // issue 4: own sequences at L <= 0.3 (the repeat floor)
std::string_view combine_name(SequenceCombine c);           // "sum", "worst", "bar", "count"
std::optional<SequenceCombine> parse_combine(std::string_view s);

// The number the search minimises for one candidate: `terms` holds its K sequences' L_k, then
// T - K weighted extra terms (contrast, lateral), which are added as they are. Any non-finite
// term gives infinity. Sums in index order (the same bits on every rank and thread count).
double combined_objective(const double* terms, int K, int T, SequenceCombine c);

// One sequence's term: the chosen objective of a simulated trial against its measured input;
// infinity when the simulation blew up or gave nothing (so no combination can prefer it). For a
// trial that was cut (SimulatedTrial::cut), the area objective's lower bound so far
// (area_objective_so_far); a cut trial under another objective throws std::logic_error.
double sequence_term(ObjectiveKind kind, const SimulatedTrial& st, const HapticSequence& measured);

// One candidate's simulations finished within a generation, on the root rank (under mpirun each
// rank simulates every size-th candidate: `total` is the root's share). A generation on the full
// gown takes about 20 minutes on two cores; this is what says in between that the run moves.
struct CandidateProgress {
  int generation = 0;     // the generation being evaluated, 1-based; 0: the start (evaluated once)
  int done = 0;           // of this rank's candidates in it, in the order they finish
  int total = 0;
  double elapsed_s = 0;   // since this generation's evaluation began (its finishing pass too)
  // calibrate --prune: a report of the pass that finishes the generation's cut candidates that
  // must be known whole; `done` and `total` then count those of the pass on this rank (a
  // generation takes one pass or more, calibration.cpp).
  bool finishing = false;
};

struct CalibrationOptions {
  int generations = 50;            // paper IV-B.4: 50 iterations ...
  int population = 32;             // ... of 32 samples
  double sigma0 = 0.3;             // in the unit box
  std::uint64_t seed = 1;
  ObjectiveKind objective = ObjectiveKind::Area;
  // > 0: add this times the heights' contrast (objective.h, contrast_error) of the high input
  // against each lower one, over the first kLatestCut metres, to the objective; 0: the paper's.
  double contrast_weight = 0;
  // > 0: add this times the lateral force's area error (lateral_term) to the objective; 0: the
  // paper's, which scores F_motion and F_vertical only.
  double lateral_weight = 0;
  SequenceCombine combine = SequenceCombine::Sum;
  // The scene the simulator runs (Calibration::gown): not seen by the search, but a checkpoint
  // of a run on one gown must not continue a run on another (the fingerprint carries it).
  std::string gown = "reduced";
  int threads = 0;                 // 0 = all cores
  std::filesystem::path checkpoint;  // empty = none
  int stop_after_generations = 0;  // > 0: stop (as if killed) after this many generations in this process
  // > 0 (calibrate --prune, area objective only): stop simulating a candidate once the lower bound
  // of its objective (its sequences' area_objective_so_far, its extra terms taken as 0, combined)
  // passes `prune` times the previous generation's median objective. See calibrate() below.
  double prune = 0;
  // Optional: called on the root rank as each of its candidates finishes, one call at a time
  // (under a lock; the simulations of other candidates go on meanwhile). Changes no result.
  std::function<void(const CandidateProgress&)> candidate_progress;
};

struct GenerationProgress {
  int generation = 0;       // 1-based, generations done
  int generations = 0;      // total planned
  double best = 0;          // best objective so far
  std::vector<double> best_fits;  // its objective per input sequence, in the inputs' order (with
                                  // the terms below, they combine to best: combined_objective)
  double best_contrast = 0;       // its weighted contrast term (0 without one)
  double best_lateral = 0;        // its weighted lateral term (0 without one)
  double generation_best = 0;
  int pruned = 0;           // this generation's candidates cut short (options.prune) ...
  int resimulated = 0;      // ... and of those, the ones simulated in whole after all (on from the cut, or again)
  double prune_bound = std::numeric_limits<double>::infinity();  // the bound they were cut at
  double simulated_s = 0;   // [s] cloth time this generation simulated, all ranks (SimulatedTrial::simulated_s)
  double elapsed_s = 0;     // this process
  double eta_s = 0;         // estimated remaining, from this process's pace
  bool resumed = false;     // this process continued from a checkpoint
};

// How well the calibrated simulator predicts one force axis of one input: eq. 3 with w = 0 (the
// area between the simulated and the measured curve over the travel both cover, N m) next to the
// same for a zero force (the area under the measured curve there). Where the simulation is
// further from the measurement than zero is, its sequences carry no information about that axis
// into a classifier trained on them (stc.h: choose_stc_axes). NaN: not measured (older files).
struct AxisFit {
  double error = std::numeric_limits<double>::quiet_NaN();
  double zero = std::numeric_limits<double>::quiet_NaN();
  bool measured() const { return std::isfinite(error) && std::isfinite(zero); }
};

struct SequenceFit {
  std::string trial_id;
  ArmHeight height = ArmHeight::High;
  double speed = 0.1;
  double objective = 0;      // this sequence's share of L
  AxisFit motion, vertical;  // filled by measure_axis_fits()
  AxisFit lateral;           // likewise (not in files written before 2026-11-25: NaN)
};

// Fills fits[k].motion, .vertical and .lateral from inputs[k] and the calibrated simulator's curve of it.
void measure_axis_fits(std::vector<SequenceFit>& fits, const std::vector<HapticSequence>& inputs,
                       const std::vector<SimulatedTrial>& curves);

struct CalibrationResult {
  bool complete = false;          // false: stopped by stop_after_generations (resume later)
  const char* stopped_by = "";    // complete: CMA-ES's stop criterion (cmaes.h), "max-generations"
                                  // when the budget ran out
  int generations_done = 0;
  long evaluations = 0;           // candidate evaluations (each = one simulation per sequence), the start's included
  long pruned = 0, resimulated = 0;  // in this process: candidates cut short, and finished whole after all (options.prune)
  double simulated_s = 0;            // [s] cloth time simulated in this process's generations and its start, all ranks
  double objective = 0;           // L of the best candidate (the start, when no sample beat it)
  double start_objective = 0;     // L of the start (the bounds' initial values)
  Eigen::VectorXd best_unit;      // in the unit box
  ClothValues cloth;
  std::array<double, 3> offsets{};  // [m] by ArmHeight
  std::vector<SequenceFit> fits;  // per selected sequence, for the best candidate
  double contrast = 0;            // its weighted contrast term: objective = combined_objective of
                                  // the fits, contrast and lateral (with Sum: their sum)
  double lateral = 0;             // its weighted lateral term
  double elapsed_s = 0;
  // Non-empty when the run resumed a checkpoint written before its fingerprint recorded all it
  // does now: what that checkpoint could not confirm (e.g. the inputs' heights and speeds).
  std::string resume_note;
};

// The weighted contrast term of options.contrast_weight for one candidate's simulated inputs
// (0 when the weight is 0 or the inputs hold no high sequence or no lower one). Issue 4's
// latest cut bounds the travel (objective.h, kLatestCut).
double contrast_term(const std::vector<HapticSequence>& inputs, const std::vector<SimulatedTrial>& simulated,
                     double weight);

// The weighted lateral term of options.lateral_weight (an extension of eq. 5 by a third axis):
//
//   l = weight x sum_k e_0(S_k^lat, R_k^lat)
//
// with e_0 eq. 3 on F_lateral and w = 0, the area between the simulated and the measured lateral
// force over the travel both cover [N m]. w = 0 because eq. 4's length penalty is already
// charged on the other two axes. The paper leaves F_lateral out (its rig's pull and its arm lie
// in one vertical plane), but the study's people did not: every good trial pulls the gripper
// sideways by 0.05-0.15 N from 0.1 m on and every missed one does not (offline/sim/MEASUREMENTS.md,
// "The lateral force"), and only this term lets a search place the arm sideways
// (kArmLateral). 0 when the weight is 0; a simulation that did not finish scores infinity.
double lateral_term(const std::vector<HapticSequence>& inputs, const std::vector<SimulatedTrial>& simulated,
                    double weight);

// Runs (or resumes from options.checkpoint) the calibration. The start (the bounds' initial
// values) is evaluated first, and is the result when no candidate of the search beats it. Every
// rank of `comm` must call it with the same arguments; they evaluate shares of each generation
// and end with identical results; only rank 0 writes the checkpoint and calls `progress`. A
// generation's tasks are its candidates, each simulating all input sequences with one batch
// call; a one-trial simulator runs them one after another (one_by_one). Without pruning the
// result does not depend on which is given; with it, it may: the cloth simulator's batch pulls a
// settling group's later trials before the first (sim::simulate_trials), so each trial's watch
// sees other partial sums and cuts at other samples (each way deterministic).
//
// Pruning (options.prune = kappa > 0). Every term of eq. 3-5 is >= 0, so a candidate's objective
// summed over the samples simulated so far bounds its whole objective from below. From the second
// generation of a search on, a candidate is stopped once that bound passes B = kappa x the
// previous generation's median objective (CmaesState::median_history, so a resume has the same B),
// and enters the ranking with the bound. A search with a wrong guess needs them all: a sleeve
// that misses where the measured one caught runs the rig's whole travel, charged at w = 20 from
// where the measurement stopped. Afterwards, while fewer than mu of the fully simulated candidates
// score at or below the lowest bound among the cut ones, the `mu minus that count` cut candidates
// with the lowest bounds are simulated in whole, and the same by Cmaes::ranking_values (f plus the
// boundary penalty, what sets the mean; cut_candidates_to_finish: until session 90 it went by f
// alone, and a repaired candidate's penalty could put a cut one among the mu that set it): each cut
// trial goes on from where it was cut when the simulator kept its state (SimulatedTrial::rest: the
// cloth simulator does), else the candidate is simulated again; both give the same bits. So the mu
// candidates that set the mean and the positive weights (tutorial eq. 41-47), and the generation's
// best, are always known exactly. What the bound leaves approximate is the order among the rest:
// the negative weights of active CMA (eq. 53) go by it, and the boundary penalty's scale (the
// values' inter-quartile range) uses it, so a pruned search is not the unpruned one to the bit. It
// is deterministic, the same on any thread or rank count, and resumes to the same bits.
//
// Failures. options.checkpoint is probed before the start is simulated (probe_checkpoint), and a
// checkpoint that cannot be written after a generation ends every rank with std::runtime_error
// (rank 0 alone would leave the others waiting for it in the next generation). A simulation that
// blows up or gives no samples scores infinity and ranks last (cmaes.h), and so does a candidate
// whose scene the simulator cannot build (UnbuildableCandidate: the jaws hold nothing of the gown
// at its rim_shift, which depends on the mesh's shape and cannot be told from the box before the
// search; it ended the whole run, session 85's gown review); when the start and every candidate
// of a finished search did, there is no calibration, and std::runtime_error says so. A simulator
// that throws anything else ends the run (under MPI through MPI_Abort, runner.h): it is not taken
// as a failed simulation, because it is a box the search should not have been given, which is
// checked before the search (a rim behind the jaws: fit_rim_shift_to_gown), or a defect that
// ranking it last would hide.
CalibrationResult calibrate(const std::vector<HapticSequence>& inputs, const ParameterSpace& space,
                            const TrialSimulator& sim, const CalibrationOptions& options, const Comm& comm,
                            const std::function<void(const GenerationProgress&)>& progress = {});
CalibrationResult calibrate(const std::vector<HapticSequence>& inputs, const ParameterSpace& space,
                            const TrialBatchSimulator& sim, const CalibrationOptions& options, const Comm& comm,
                            const std::function<void(const GenerationProgress&)>& progress = {});

// Pruning's rule (above), for a generation whose candidates c with cut[c] are known only by the
// lower bound f[c]: the cut candidates to simulate in whole so that the mu candidates of lowest
// ranking value (es.ranking_values(f): those that set the mean, eq. 41) and the mu of lowest f
// (the generation's best point and its L, which the result reports) are all whole ones, lowest
// first; none when that already holds. Finishing a candidate raises its f and
// can change the penalty's weight, so the caller asks again until none are left. Between
// es.ask() and es.tell().
class Cmaes;
std::vector<int> cut_candidates_to_finish(const Cmaes& es, const std::vector<double>& f, const std::vector<char>& cut);

// Whether a checkpoint can be written at `path`, asked before a search, which writes its first
// only after a generation (20 minutes into a run on the full gown): rank 0 makes its folder and
// writes and removes a file beside it. Collective (every rank of `comm` calls it): every rank
// throws InputError naming the path and the reason when rank 0 could not.
void probe_checkpoint(const std::filesystem::path& path, const Comm& comm);

// The request that reproduces a measured input sequence with candidate offsets (no gown noise,
// fixed seed: calibration compares deterministic simulations). The travel limit is the measured
// trial's own when it was not stopped by force: the study's missed trials end at 0.71-0.76 m, not
// at the 0.85 m the paper states (shared/data: 13 of 14 missed trials), and simulating them to
// 0.85 m would charge w = 20 on ~0.1 m of travel that the rig never made.
TrialRequest request_for(const HapticSequence& input, const std::array<double, 3>& offsets);

// The calibration's inputs simulated with one cloth and its offsets (request_for each, one batch:
// the search's evaluation of a candidate and the curves `calibrate` writes are this call), in the
// inputs' order. `watches`: empty, or one TrialRequest::watch per input. Throws
// std::logic_error when the simulator returns another count.
using TrialWatch = std::function<bool(const std::vector<HapticSample>& so_far, bool ended)>;
std::vector<SimulatedTrial> simulate_inputs(const TrialBatchSimulator& sim, const ClothValues& cloth,
                                            const std::array<double, 3>& offsets,
                                            const std::vector<HapticSequence>& inputs,
                                            const std::vector<TrialWatch>& watches = {});

// True when a measured trial ended at the force threshold (|F| >= 9.5 N on motion or vertical at
// its last sample; the rig's limit is 10 N, the last sample may sit just under it).
bool stopped_by_force(const HapticSequence& s);

// The rig's end of travel for a participant: the longest travel among its inputs that were not
// stopped by force; 0.85 m (the paper) when every input was.
double rig_travel_of(const std::vector<HapticSequence>& inputs);

// ---- the calibration file ------------------------------------------------------------------------

// Everything synthesis needs, plus provenance. JSON, written atomically.
struct Calibration {
  std::string participant;
  ClothValues cloth;
  std::array<double, 3> offsets{};            // [m] by ArmHeight
  std::array<bool, 3> offset_calibrated{};    // which offsets were optimised
  double objective = 0;                       // what the search minimised (combined_objective)
  std::vector<SequenceFit> fits;
  double contrast_weight = 0;                 // calibrate --contrast-weight (0: the paper's objective)
  double contrast = 0;                        // its weighted term (contrast_term)
  double lateral_weight = 0;                  // calibrate --lateral-weight (0: the paper's objective)
  double lateral = 0;                         // its weighted term (lateral_term)
  std::string objective_kind = "area";
  std::string combine = "sum";                // calibrate --combine (combine_name)
  std::string gown = "reduced";               // which scene the simulator used
  double rig_travel = 0.85;                   // [m] end of travel for synthesis (rig_travel_of)
  Json provenance = Json::object();           // dataset, seed, budget, evaluations, timing, tool
};
// The calibration file of a finished search `r` on `inputs` (calibrate's arguments `space` and
// `o`): its values, the heights whose offsets it calibrated, its objective with how it was made
// (kind, combination, the extra terms' weights), the scene (`o.gown`) and the rig's end of travel.
// The axis fits (measure_axis_fits) and the provenance are the caller's to add.
Calibration calibration_of(const std::string& participant, const CalibrationResult& r,
                           const ParameterSpace& space, const CalibrationOptions& o,
                           const std::vector<HapticSequence>& inputs);

// Scores calibration `c` again on its own inputs (in its fits' order) by this build's objective,
// its values unchanged (`calibrate --rescore`): each sequence's L, the extra terms, the combined
// objective and the axis fits, from `simulated` = simulate_inputs() of c's values. For a change of
// the objective's definition (session 45: objective.h, "Where the pairs begin"), so that a file's
// figures are what this build computes from it. The figures it replaces go into provenance
// "rescored" (a list: when, why, before). Throws std::invalid_argument when the inputs are not
// the file's sequences, and std::runtime_error, `c` unchanged, when a simulation did not stay
// finite.
void rescore(Calibration& c, const std::vector<HapticSequence>& inputs, const std::vector<SimulatedTrial>& simulated,
             const std::string& why, const std::string& when);

// Starts a search where calibration `c` ended (`calibrate --start`): every initial value of `b`
// becomes c's (the five cloth values, the person parameters, each calibrated height's own
// offset), so that a longer or wider search continues from a fit instead of from a bounds file
// written by hand. Throws std::invalid_argument naming the first value outside its box in `b`.
void start_from(Bounds& b, const Calibration& c);

Json calibration_to_json(const Calibration& c);
Calibration calibration_from_json(const Json& j, const std::filesystem::path& source);
void write_calibration(const std::filesystem::path& path, const Calibration& c);
Calibration read_calibration(const std::filesystem::path& path);

// Measured and simulated curves of each input (for the overlay plots, paper Fig. 7-9): CSV with
// columns trial_id,height,source,travel,f_motion,f_vertical,f_lateral; source "measured" or
// `label` (f_lateral since 2026-11-25).
std::string overlay_csv(const std::vector<HapticSequence>& inputs, const std::vector<SimulatedTrial>& simulated,
                        const std::string& label);

}  // namespace dressguard::calib
