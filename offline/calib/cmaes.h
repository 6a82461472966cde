// CMA-ES (covariance matrix adaptation evolution strategy) with an ask/tell interface.
//
// Follows N. Hansen, "The CMA Evolution Strategy: A Tutorial", arXiv:1604.00772 (2016/2023),
// Table 1 and Appendix A; equation numbers in the comments below are that tutorial's. Written for
// the simulator calibration of the paper's section IV-B.4 (50 generations x 32 samples), where
// one evaluation is a whole cloth simulation: ask() hands out a generation's candidates so that
// the caller can evaluate them on threads or MPI ranks and checkpoint between generations;
// tell() takes their objective values back.
//
// Why our own and not pagmo2's `pagmo::cmaes` (Debian libpagmo-dev, also benchmarked against this
// one in tools/bench/bench_calib_cmaes.cpp): pagmo's algorithm owns the loop (`evolve(pop)`), so a
// generation cannot be spread over MPI ranks or checkpointed mid-run without re-implementing the
// problem as a batch evaluator and serialising its boost archive; it has no restarts, and its
// bounds handling is plain clipping. Here the state is a flat struct that serialises exactly.
//
// Determinism: a generation's normal samples come from a generator seeded by (seed, restart,
// generation), so the same seed gives the same bits, independent of how the caller spreads the
// evaluations, and a run restored from save_state() continues bit-identically.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace dressguard::calib {

// Restart strategy after a local stop (tutorial Appendix B.3 recommends restarts with increasing
// population: IPOP, Auger & Hansen 2005; BIPOP, Hansen 2009). Each restart starts from a mean
// drawn uniformly in the box (without bounds, from x0).
//   IPOP: every restart doubles the population, sigma0 as given.
//   BIPOP (Hansen 2009, section 2): the first run has the default population (settings.lambda,
//   or eq. 48's) and sigma0 and counts to neither regime; each restart then runs the regime that
//   has used fewer evaluations so far, the large one on a tie (so the first restart is a large
//   one). Large regime, k-th restart: lambda_def 2^k, sigma0. Small regime: lambda_s =
//   floor(lambda_def (lambda_large / (2 lambda_def))^(U^2)), lambda_large the latest large run's
//   population, so lambda_def <= lambda_s <= lambda_large / 2; sigma0 10^(-2 U'); at most half
//   the evaluations of the latest large run (U, U' uniform in (0, 1), drawn from the seed).
enum class Restarts { None = 0, Ipop = 1, Bipop = 2 };

// Why the run (or the current restart) stopped. Local reasons trigger a restart when enabled.
enum class StopReason {
  None = 0,
  TargetReached,      // best f <= target_f
  MaxEvaluations,     // evaluation budget used up (across restarts)
  MaxGenerations,     // generation budget of this run used up (across restarts)
  TolFun,             // range of recent best values and of this generation below tol_fun (local)
  TolX,               // sigma * max(sqrt(C_ii), |p_c,i|) below tol_x for every i (local)
  ConditionCov,       // cond(C) above 1e14 (local)
  NoEffectAxis,       // adding 0.1 sigma along a principal axis leaves the mean unchanged (local)
  NoEffectCoord,      // adding 0.2 sigma to a coordinate leaves it unchanged (local)
  Stagnation,         // over the last 20 % of generations (>= 120 + 30 n / lambda, <= 20 000), the
                      // newest 30 % improve on the oldest 30 % neither in best nor in median (local)
  SmallRunBudget,     // a BIPOP small-regime run used its budget, half the last large run's (local)
};
const char* stop_reason_name(StopReason r);

// Constant settings of a run. Defaults are the tutorial's (Table 1) where it has one.
struct CmaesSettings {
  Eigen::VectorXd x0;          // initial mean m (size n >= 1)
  double sigma0 = 0.3;         // initial step size
  int lambda = 0;              // population; 0 = default 4 + floor(3 ln n) (eq. 48); <= kMaxPopulation
  std::uint64_t seed = 1;
  // Box bounds (both or neither, size n). Method: a candidate outside the box is evaluated at its
  // projection onto the box (the "repair"), and its value for ranking is f(repaired) plus
  // gamma * ||x - repaired||^2 / sigma^2, gamma the interquartile range of the generation's
  // values that are finite (at least 1e-12); the update uses the unrepaired x. A non-finite value
  // (a failed evaluation) gets no penalty and ranks behind every finite one. This is the tutorial's
  // "repair and penalise" boundary handling (Appendix B.5) with the penalty weight taken from the
  // spread of the generation's values, as Hansen's cmaes.m does for its boundary weights. Points
  // handed out by ask() are always the repaired ones, so the caller never sees an infeasible x.
  std::optional<Eigen::VectorXd> lower, upper;
  // Stopping criteria (tutorial Appendix B.3, termination criteria).
  double target_f = -1e300;     // stop when best f <= target_f
  long max_evaluations = 0;     // 0 = unlimited
  long max_generations = 0;     // 0 = unlimited (counts all generations of all restarts)
  double tol_fun = 1e-12;
  double tol_x = 1e-12;         // relative to sigma0
  Restarts restarts = Restarts::None;
  // How many restarts with a larger population follow the first run. IPOP: every restart (the
  // last has 2^max_restarts times the first's population). BIPOP: the large regime's restarts
  // (the last has lambda_def 2^max_restarts); the small-regime runs between them are not counted
  // (as pycma's fmin counts its `restarts`), the budget rule bounds them. The search ends with
  // the local stop of the last counted run (with 0, of the first run). Not negative; with
  // restarts, the last counted run's population, lambda 2^max_restarts, must not pass
  // Cmaes::kMaxPopulation (2^30): the constructor refuses a larger one (std::invalid_argument
  // naming both), as the doubling would overflow int past about 27 restarts.
  int max_restarts = 9;
};

// The mutable state. Everything needed to continue a run bit-identically.
struct CmaesState {
  int n = 0;
  int lambda = 0;         // current population (grows with IPOP/BIPOP restarts)
  int restart = 0;        // restarts done so far
  long generation = 0;    // generation within the current restart
  long generations_total = 0;
  long evaluations = 0;   // over all restarts
  double sigma = 0.0;
  Eigen::VectorXd mean, pc, ps;
  Eigen::MatrixXd C;
  // History for TolFun and stagnation (best and median of each generation of this restart): the
  // newest max(20 000, TolFun's window) generations, all that the two criteria look at.
  std::vector<double> best_history, median_history;
  // Best point seen over the whole run (repaired, i.e. feasible).
  Eigen::VectorXd best_x;
  double best_f = 1e300;
  // BIPOP bookkeeping: evaluations spent in the large- and small-population regimes (the first
  // run in neither), and in the latest large run (a small run's budget is half of it).
  long bipop_large_evals = 0, bipop_small_evals = 0, bipop_last_large_evals = 0;
  int bipop_large_restarts = 0;  // how many large-regime restarts (lambda = 2^k * default)
  bool bipop_small_regime = false;  // the current restart is a small-regime one
  double sigma_this_restart = 0.0;  // sigma0 of the current restart (BIPOP's small regime shrinks it)
  StopReason stopped = StopReason::None;
};

class Cmaes {
 public:
  explicit Cmaes(CmaesSettings settings);

  // Candidates of the next generation (lambda of them, feasible). Call tell() with their values
  // in the same order before the next ask().
  std::vector<Eigen::VectorXd> ask();
  // Objective values of the candidates from the last ask(). NaN or inf counts as worst.
  void tell(const std::vector<double>& f);
  // The values tell(f) ranks the last ask()'s candidates by: f at the repaired point plus the
  // boundary penalty (above), +infinity for a failed evaluation (NaN or inf, ranked last). The
  // mu lowest set the mean (eq. 41), so a caller that knows some f only as lower bounds
  // (calibration's pruning) must know these mu exactly, not the mu lowest f: a repaired
  // candidate's penalty can put a lower f behind a higher one. Between ask() and tell().
  std::vector<double> ranking_values(const std::vector<double>& f) const;

  // The serial driver for a cheap objective on one thread: step() is one ask, f at every
  // candidate in order, tell; minimize() steps until a stopping criterion fires. Calibration
  // uses ask/tell itself, to spread a generation over threads and MPI ranks and checkpoint it.
  using Objective = std::function<double(const Eigen::VectorXd&)>;
  void step(const Objective& f);
  void minimize(const Objective& f);

  bool stopped() const { return state_.stopped != StopReason::None; }
  StopReason stop_reason() const { return state_.stopped; }
  const CmaesState& state() const { return state_; }
  const CmaesSettings& settings() const { return settings_; }
  int mu() const { return mu_; }  // how many of the best candidates get a positive weight (eq. 49)
  const Eigen::VectorXd& best_x() const { return state_.best_x; }
  double best_f() const { return state_.best_f; }

  // Exact text serialisation of the state (hex floats): restore_state(save_state()) continues
  // with identical bits. restore_state takes only a text that save_state can have written: each
  // key exactly once, counters not negative and consistent, sigma finite and above 0, mean, paths
  // and C finite, C with positive variances and symmetric, one history value per generation.
  // Otherwise it throws std::runtime_error naming the key and what is wrong, and the search
  // stays as it was.
  std::string save_state() const;
  void restore_state(const std::string& text);

  // The tutorial's default population for dimension n (eq. 48).
  static int default_lambda(int n);
  // The largest population, 2^30: IPOP's and BIPOP's doublings and eq. 49's lambda + 1 stay in an
  // int, and a generation of 2^30 samples (8n GiB) is beyond any machine this runs on anyway.
  static constexpr int kMaxPopulation = 1 << 30;

 private:
  struct Strategy;  // weights and learning rates for the current lambda (eq. 49-58)
  void start_restart(int lambda, double sigma, bool reset_mean);
  void update_eigen();
  // The local stop that fires after a tell(); `generation_range`: max f - min f of its values.
  StopReason local_stop(double generation_range) const;
  void on_local_stop(StopReason r);

  CmaesSettings settings_;
  CmaesState state_;
  // Derived from state_ (recomputed, never serialised): weights, rates, eigensystem.
  Eigen::VectorXd weights_;  // w_i, i = 1..lambda (positive then negative, eq. 53)
  double mu_eff_ = 0, c_sigma_ = 0, d_sigma_ = 0, c_c_ = 0, c_1_ = 0, c_mu_ = 0, chi_n_ = 0;
  int mu_ = 0;
  Eigen::MatrixXd B_;
  Eigen::VectorXd D_;
  // Last ask(): unrepaired samples y_k = (x_k - m) / sigma and the repaired x_k.
  std::vector<Eigen::VectorXd> y_, x_unrepaired_, x_repaired_;
  bool asked_ = false;
  void derive_strategy();
};

// Benchmark functions (tutorial Appendix, "test functions"): all have minimum 0.
double sphere(const Eigen::VectorXd& x);
double ellipsoid(const Eigen::VectorXd& x);    // sum 1e6^((i-1)/(n-1)) x_i^2
double rosenbrock(const Eigen::VectorXd& x);   // sum 100 (x_i^2 - x_{i+1})^2 + (x_i - 1)^2

}  // namespace dressguard::calib
