// CMA-ES, see cmaes.h. Equation numbers: Hansen, arXiv:1604.00772.
#include "cmaes.h"

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>

namespace dressguard::calib {
namespace {

// SplitMix64 (Steele, Lea, Flood 2014): decorrelates the generator seeds of neighbouring
// generations, so that seeding by (seed, restart, generation) gives independent streams.
std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// The generator of one generation's samples: std::mt19937_64 is specified bit-exactly by the
// standard; the normal deviates are our own Box-Muller (std::normal_distribution is not
// specified bit-exactly across standard libraries).
class Normal {
 public:
  explicit Normal(std::uint64_t seed) : gen_(seed) {}
  double uniform() {  // in (0, 1): 53 random bits, never 0
    return (static_cast<double>(gen_() >> 11) + 0.5) * 0x1.0p-53;
  }
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double r = std::sqrt(-2.0 * std::log(uniform()));
    const double phi = 2.0 * M_PI * uniform();
    spare_ = r * std::sin(phi);
    has_spare_ = true;
    return r * std::cos(phi);
  }

 private:
  std::mt19937_64 gen_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

std::uint64_t stream_seed(std::uint64_t seed, int restart, long generation) {
  return splitmix(splitmix(splitmix(seed) ^ static_cast<std::uint64_t>(restart + 1)) ^
                  static_cast<std::uint64_t>(generation + 2));
}

// TolFun's window (Appendix B.3): the best values of the last 10 + ceil(30 n / lambda) generations.
std::size_t tolfun_window(int n, int lambda) {
  return 10 + static_cast<std::size_t>(std::ceil(30.0 * n / lambda));
}

// Stagnation's window (Appendix B.3): the last 20 % of the restart's generations, but at least
// 120 + 30 n / lambda and at most 20 000.
constexpr std::size_t kStagnationMaxWindow = 20000;
std::size_t stagnation_min_window(int n, int lambda) {
  return 120 + static_cast<std::size_t>(std::ceil(30.0 * n / lambda));
}

// How many of the newest generations the best and median histories keep: all that TolFun and
// Stagnation look at, no more (the histories were the whole restart's, without bound).
std::size_t history_capacity(int n, int lambda) {
  return std::max(kStagnationMaxWindow, tolfun_window(n, lambda));
}

double median_of(std::vector<double> v) {
  const std::size_t m = v.size();
  std::nth_element(v.begin(), v.begin() + m / 2, v.end());
  const double upper = v[m / 2];
  if (m % 2) return upper;
  return 0.5 * (*std::max_element(v.begin(), v.begin() + m / 2) + upper);
}

}  // namespace

const char* stop_reason_name(StopReason r) {
  switch (r) {
    case StopReason::None: return "none";
    case StopReason::TargetReached: return "target-reached";
    case StopReason::MaxEvaluations: return "max-evaluations";
    case StopReason::MaxGenerations: return "max-generations";
    case StopReason::TolFun: return "tolfun";
    case StopReason::TolX: return "tolx";
    case StopReason::ConditionCov: return "condition-cov";
    case StopReason::NoEffectAxis: return "no-effect-axis";
    case StopReason::NoEffectCoord: return "no-effect-coord";
    case StopReason::Stagnation: return "stagnation";
    case StopReason::SmallRunBudget: return "small-run-budget";
  }
  return "?";
}

int Cmaes::default_lambda(int n) {
  return 4 + static_cast<int>(std::floor(3.0 * std::log(static_cast<double>(n))));  // eq. 48
}

Cmaes::Cmaes(CmaesSettings settings) : settings_(std::move(settings)) {
  const long n = settings_.x0.size();
  if (n < 1) throw std::invalid_argument("cmaes: x0 must have at least one coordinate");
  if (!(settings_.sigma0 > 0.0)) throw std::invalid_argument("cmaes: sigma0 must be positive");
  if (settings_.lower.has_value() != settings_.upper.has_value())
    throw std::invalid_argument("cmaes: give both lower and upper bounds or neither");
  if (settings_.lower) {
    if (settings_.lower->size() != n || settings_.upper->size() != n)
      throw std::invalid_argument("cmaes: bounds must have the size of x0");
    for (long i = 0; i < n; ++i) {
      if (!((*settings_.lower)[i] < (*settings_.upper)[i]))
        throw std::invalid_argument("cmaes: lower bound must be below upper bound in every coordinate");
      settings_.x0[i] = std::clamp(settings_.x0[i], (*settings_.lower)[i], (*settings_.upper)[i]);
    }
  }
  state_.n = static_cast<int>(n);
  state_.best_x = settings_.x0;
  const int lambda = settings_.lambda > 0 ? settings_.lambda : default_lambda(state_.n);
  if (lambda < 2) throw std::invalid_argument("cmaes: lambda must be at least 2");
  if (lambda > kMaxPopulation)
    throw std::invalid_argument("cmaes: population " + std::to_string(lambda) + " is above the largest, 2^30 = " +
                                std::to_string(kMaxPopulation));
  if (settings_.max_restarts < 0)
    throw std::invalid_argument("cmaes: max_restarts " + std::to_string(settings_.max_restarts) + " is negative");
  if (settings_.restarts != Restarts::None) {
    // The last counted restart runs lambda 2^max_restarts (IPOP: the first run's lambda doubled at
    // each restart; BIPOP: lambda_def 2^k for the k-th large restart, lambda_def = this lambda).
    // Refused rather than saturated: a search that asked for more doublings than an int holds
    // would silently run other restarts than it asked for (session 90's review: lambda * 2 and
    // lambda_def << k overflowed, undefined, beyond about 27 restarts).
    int most = 0;
    while ((static_cast<long>(lambda) << (most + 1)) <= kMaxPopulation) ++most;
    if (settings_.max_restarts > most)
      throw std::invalid_argument("cmaes: max_restarts " + std::to_string(settings_.max_restarts) +
                                  " would double the population " + std::to_string(lambda) + " to " +
                                  std::to_string(lambda) + " x 2^" + std::to_string(settings_.max_restarts) +
                                  ", above the largest population, 2^30 = " + std::to_string(kMaxPopulation) +
                                  "; at most " + std::to_string(most) + " restarts with this population");
  }
  start_restart(lambda, settings_.sigma0, /*reset_mean=*/false);
}

// Weights and learning rates for the current lambda: tutorial Table 1 / Appendix A.
void Cmaes::derive_strategy() {
  const int n = state_.n;
  const int lambda = state_.lambda;
  const double nd = n;
  mu_ = lambda / 2;  // eq. 49: mu = floor(lambda / 2)
  // eq. 49: w'_i = ln((lambda + 1) / 2) - ln i, i = 1..lambda (negative for i > mu).
  Eigen::VectorXd wp(lambda);
  for (int i = 0; i < lambda; ++i) wp[i] = std::log((lambda + 1) / 2.0) - std::log(i + 1.0);
  double sum_pos = 0, sum_pos2 = 0, sum_neg = 0, sum_neg2 = 0;
  for (int i = 0; i < lambda; ++i) {
    if (wp[i] >= 0) {
      sum_pos += wp[i];
      sum_pos2 += wp[i] * wp[i];
    } else {
      sum_neg += -wp[i];
      sum_neg2 += wp[i] * wp[i];
    }
  }
  mu_eff_ = sum_pos * sum_pos / sum_pos2;                         // mu_eff, below eq. 49
  const double mu_eff_neg = sum_neg2 > 0 ? sum_neg * sum_neg / sum_neg2 : 0.0;
  // eq. 57 (alpha_cov = 2): rank-one and rank-mu learning rates.
  const double alpha_cov = 2.0;
  c_1_ = alpha_cov / ((nd + 1.3) * (nd + 1.3) + mu_eff_);
  c_mu_ = std::min(1.0 - c_1_, alpha_cov * (0.25 + mu_eff_ + 1.0 / mu_eff_ - 2.0) /
                                   ((nd + 2.0) * (nd + 2.0) + alpha_cov * mu_eff_ / 2.0));
  // eq. 50-52: the three bounds on the sum of the negative weights.
  const double alpha_mu_neg = 1.0 + c_1_ / c_mu_;
  const double alpha_mueff_neg = 1.0 + 2.0 * mu_eff_neg / (mu_eff_ + 2.0);
  const double alpha_posdef_neg = (1.0 - c_1_ - c_mu_) / (nd * c_mu_);
  const double neg_scale = std::min({alpha_mu_neg, alpha_mueff_neg, alpha_posdef_neg});
  // eq. 53: positive weights sum to one, negative ones to -neg_scale.
  weights_.resize(lambda);
  for (int i = 0; i < lambda; ++i)
    weights_[i] = wp[i] >= 0 ? wp[i] / sum_pos : (sum_neg > 0 ? neg_scale * wp[i] / sum_neg : 0.0);
  // eq. 55: step-size control.
  c_sigma_ = (mu_eff_ + 2.0) / (nd + mu_eff_ + 5.0);
  d_sigma_ = 1.0 + 2.0 * std::max(0.0, std::sqrt((mu_eff_ - 1.0) / (nd + 1.0)) - 1.0) + c_sigma_;
  // eq. 56: cumulation for the rank-one update.
  c_c_ = (4.0 + mu_eff_ / nd) / (nd + 4.0 + 2.0 * mu_eff_ / nd);
  // E||N(0, I)||, the approximation below eq. 44.
  chi_n_ = std::sqrt(nd) * (1.0 - 1.0 / (4.0 * nd) + 1.0 / (21.0 * nd * nd));
}

void Cmaes::start_restart(int lambda, double sigma, bool reset_mean) {
  const int n = state_.n;
  state_.lambda = lambda;
  state_.generation = 0;
  state_.sigma = sigma;
  state_.sigma_this_restart = sigma;
  if (reset_mean && settings_.lower) {
    // A new start drawn uniformly in the box: the restarts explore other basins.
    Normal rng(stream_seed(settings_.seed, state_.restart, -1));
    state_.mean.resize(n);
    for (int i = 0; i < n; ++i)
      state_.mean[i] = (*settings_.lower)[i] + rng.uniform() * ((*settings_.upper)[i] - (*settings_.lower)[i]);
  } else {
    state_.mean = settings_.x0;
  }
  state_.pc = Eigen::VectorXd::Zero(n);
  state_.ps = Eigen::VectorXd::Zero(n);
  state_.C = Eigen::MatrixXd::Identity(n, n);
  state_.best_history.clear();
  state_.median_history.clear();
  derive_strategy();
  update_eigen();
  asked_ = false;
}

void Cmaes::update_eigen() {
  // Enforce symmetry (rounding), then C = B D^2 B^T (tutorial eq. 10-12).
  Eigen::MatrixXd C = 0.5 * (state_.C + state_.C.transpose());
  state_.C = C;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(C);
  B_ = es.eigenvectors();
  D_ = es.eigenvalues().cwiseMax(1e-300).cwiseSqrt();
}

std::vector<Eigen::VectorXd> Cmaes::ask() {
  if (stopped()) throw std::logic_error("cmaes: ask() after the run stopped");
  const int n = state_.n;
  Normal rng(stream_seed(settings_.seed, state_.restart, state_.generation));
  y_.assign(state_.lambda, Eigen::VectorXd(n));
  x_unrepaired_.assign(state_.lambda, Eigen::VectorXd(n));
  x_repaired_.assign(state_.lambda, Eigen::VectorXd(n));
  Eigen::VectorXd z(n);
  for (int k = 0; k < state_.lambda; ++k) {
    for (int i = 0; i < n; ++i) z[i] = rng();
    y_[k] = B_ * D_.cwiseProduct(z);                   // eq. 38-39: y_k ~ N(0, C)
    x_unrepaired_[k] = state_.mean + state_.sigma * y_[k];  // eq. 40: x_k ~ m + sigma N(0, C)
    x_repaired_[k] = x_unrepaired_[k];
    if (settings_.lower)  // repair: projection onto the box (Appendix B.5)
      x_repaired_[k] = x_repaired_[k].cwiseMax(*settings_.lower).cwiseMin(*settings_.upper);
  }
  asked_ = true;
  return x_repaired_;
}

void Cmaes::step(const Objective& f) {
  const std::vector<Eigen::VectorXd> xs = ask();
  std::vector<double> v;
  v.reserve(xs.size());
  for (const auto& x : xs) v.push_back(f(x));
  tell(v);
}

void Cmaes::minimize(const Objective& f) {
  while (!stopped()) step(f);
}

std::vector<double> Cmaes::ranking_values(const std::vector<double>& f) const {
  if (!asked_) throw std::logic_error("cmaes: ranking_values() without a matching ask()");
  const int lambda = state_.lambda;
  if (static_cast<int>(f.size()) != lambda) throw std::invalid_argument("cmaes: ranking_values() needs lambda values");
  // Ranking values: the repaired point's value plus the boundary penalty (cmaes.h, Appendix B.5).
  // The penalty's weight is the spread of the values that were evaluated: the IQR of the finite
  // ones. A failed evaluation has no value; counted as DBL_MAX, a quarter of a generation failing
  // made the weight DBL_MAX and every repaired candidate's rank value infinite, behind the failures,
  // which then took positive weights in eq. 41 (session 84's review, finding 6).
  std::vector<double> rank_f(f);
  std::vector<double> sorted;
  for (int k = 0; k < lambda; ++k) {
    if (std::isfinite(f[k]))
      sorted.push_back(f[k]);
    else
      rank_f[k] = std::numeric_limits<double>::infinity();
  }
  if (settings_.lower) {
    std::sort(sorted.begin(), sorted.end());
    const std::size_t m = sorted.size();
    const double iqr = m == 0 ? 0.0 : sorted[(3 * (m - 1)) / 4] - sorted[(m - 1) / 4];
    const double gamma = std::max(iqr, 1e-12);
    for (int k = 0; k < lambda; ++k) {
      const double d2 = (x_unrepaired_[k] - x_repaired_[k]).squaredNorm();
      if (d2 > 0 && std::isfinite(f[k])) rank_f[k] = f[k] + gamma * d2 / (state_.sigma * state_.sigma);
    }
  }
  return rank_f;
}

void Cmaes::tell(const std::vector<double>& f_in) {
  if (!asked_) throw std::logic_error("cmaes: tell() without a matching ask()");
  const int n = state_.n;
  const int lambda = state_.lambda;
  if (static_cast<int>(f_in.size()) != lambda) throw std::invalid_argument("cmaes: tell() needs lambda values");
  const std::vector<double> rank_f = ranking_values(f_in);
  asked_ = false;
  std::vector<double> f(f_in);
  std::vector<char> failed(static_cast<std::size_t>(lambda), 0);
  for (int k = 0; k < lambda; ++k)
    if (!std::isfinite(f[k])) {
      f[k] = std::numeric_limits<double>::max();  // failures rank last
      failed[k] = 1;
    }
  state_.evaluations += lambda;
  state_.generations_total += 1;
  for (int k = 0; k < lambda; ++k) {
    if (f[k] < state_.best_f) {
      state_.best_f = f[k];
      state_.best_x = x_repaired_[k];
    }
  }
  // Failures last whatever a penalty adds to the others (a rank value may overflow to infinity),
  // in their index order.
  std::vector<int> order(lambda);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return failed[a] != failed[b] ? failed[b] != 0 : rank_f[a] < rank_f[b];
  });

  // eq. 41: <y>_w = sum_{i<=mu} w_i y_{i:lambda}; eq. 42: m <- m + c_m sigma <y>_w (c_m = 1).
  Eigen::VectorXd y_w = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < mu_; ++i) y_w += weights_[i] * y_[order[i]];
  state_.mean += state_.sigma * y_w;

  // C^{-1/2} = B D^{-1} B^T.
  const Eigen::MatrixXd C_invsqrt = B_ * D_.cwiseInverse().asDiagonal() * B_.transpose();
  // eq. 43: cumulation for sigma.
  state_.ps = (1.0 - c_sigma_) * state_.ps + std::sqrt(c_sigma_ * (2.0 - c_sigma_) * mu_eff_) * (C_invsqrt * y_w);
  // h_sigma (Appendix A, below eq. 45): stalls p_c when ||p_sigma|| is large.
  const double g1 = static_cast<double>(state_.generation + 1);
  const double ps_norm = state_.ps.norm();
  const bool h_sigma =
      ps_norm / std::sqrt(1.0 - std::pow(1.0 - c_sigma_, 2.0 * g1)) < (1.4 + 2.0 / (n + 1.0)) * chi_n_;
  // eq. 45: cumulation for the rank-one update.
  state_.pc = (1.0 - c_c_) * state_.pc + (h_sigma ? std::sqrt(c_c_ * (2.0 - c_c_) * mu_eff_) : 0.0) * y_w;
  // eq. 46: w°_i = w_i for w_i >= 0, else w_i n / ||C^{-1/2} y_{i:lambda}||^2.
  // eq. 47: C <- (1 + c_1 delta(h_sigma) - c_1 - c_mu sum w_j) C + c_1 p_c p_c^T + c_mu sum w°_i y y^T.
  const double delta_h = h_sigma ? 0.0 : c_c_ * (2.0 - c_c_);  // delta(h_sigma) = (1 - h_sigma) c_c (2 - c_c)
  Eigen::MatrixXd rank_mu = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < lambda; ++i) {
    const Eigen::VectorXd& y = y_[order[i]];
    double w = weights_[i];
    if (w < 0) {
      const double q = (C_invsqrt * y).squaredNorm();
      w *= q > 0 ? n / q : 0.0;
    }
    rank_mu.noalias() += w * (y * y.transpose());
  }
  const double sum_w = weights_.sum();
  state_.C = (1.0 + c_1_ * delta_h - c_1_ - c_mu_ * sum_w) * state_.C +
             c_1_ * (state_.pc * state_.pc.transpose()) + c_mu_ * rank_mu;
  // eq. 44: step-size update.
  // The exponent is capped at 1 (as purecma does) so one wild generation cannot blow sigma up.
  state_.sigma *= std::exp(std::min(1.0, (c_sigma_ / d_sigma_) * (ps_norm / chi_n_ - 1.0)));
  update_eigen();

  // Histories for TolFun and stagnation, and this generation's range (TolFun).
  std::vector<double> sorted(f);
  std::sort(sorted.begin(), sorted.end());
  const double range = sorted.back() - sorted.front();
  state_.best_history.push_back(sorted.front());
  state_.median_history.push_back(sorted[lambda / 2]);
  const std::size_t capacity = history_capacity(n, lambda);
  for (std::vector<double>* h : {&state_.best_history, &state_.median_history})
    if (h->size() > capacity) h->erase(h->begin(), h->end() - static_cast<long>(capacity));
  state_.generation += 1;

  // Global stops first, then local ones (which may restart).
  if (state_.best_f <= settings_.target_f) {
    state_.stopped = StopReason::TargetReached;
    return;
  }
  if (settings_.max_evaluations > 0 && state_.evaluations >= settings_.max_evaluations) {
    state_.stopped = StopReason::MaxEvaluations;
    return;
  }
  if (settings_.max_generations > 0 && state_.generations_total >= settings_.max_generations) {
    state_.stopped = StopReason::MaxGenerations;
    return;
  }
  // The range of this generation is of the repaired points' values (without the penalty): the
  // values the objective gave, which is what TolFun asks about.
  const StopReason local = local_stop(range);
  if (local != StopReason::None) on_local_stop(local);
}

// Termination criteria of Appendix B.3 that end one restart.
StopReason Cmaes::local_stop(double generation_range) const {
  const int n = state_.n;
  const auto& bh = state_.best_history;
  // TolFun (Appendix B.3): the range of the best values of the last 10 + ceil(30 n / lambda)
  // generations and the range of this generation's values both below tol_fun. The first alone
  // stops on a plateau whose generation still spreads widely (the best stays put while the
  // samples do not: session 84's review, finding 8).
  const std::size_t window = tolfun_window(n, state_.lambda);
  if (bh.size() >= window && generation_range < settings_.tol_fun) {
    const auto [lo, hi] = std::minmax_element(bh.end() - window, bh.end());
    if (*hi - *lo < settings_.tol_fun) return StopReason::TolFun;
  }
  // TolX: sigma * max(|p_c,i|, sqrt(C_ii)) < tol_x * sigma0 for all i.
  bool all_small = true;
  for (int i = 0; i < n; ++i) {
    const double s = state_.sigma * std::max(std::abs(state_.pc[i]), std::sqrt(state_.C(i, i)));
    if (!(s < settings_.tol_x * settings_.sigma0)) all_small = false;
  }
  if (all_small) return StopReason::TolX;
  // ConditionCov: cond(C) > 1e14.
  const double dmax = D_.maxCoeff(), dmin = D_.minCoeff();
  if (dmax * dmax > 1e14 * dmin * dmin) return StopReason::ConditionCov;
  // NoEffectAxis: m + 0.1 sigma d_i b_i == m for the axis i = g mod n.
  {
    const int i = static_cast<int>(state_.generation % n);
    const Eigen::VectorXd moved = state_.mean + 0.1 * state_.sigma * D_[i] * B_.col(i);
    if (moved == state_.mean) return StopReason::NoEffectAxis;
  }
  // NoEffectCoord: m_i + 0.2 sigma sqrt(C_ii) == m_i for some i.
  for (int i = 0; i < n; ++i)
    if (state_.mean[i] + 0.2 * state_.sigma * std::sqrt(state_.C(i, i)) == state_.mean[i])
      return StopReason::NoEffectCoord;
  // Stagnation (Appendix B.3): the best and the median value of each generation over the last
  // 20 % of this restart's generations, but at least 120 + 30 n / lambda and at most 20 000; the
  // restart stops when, in both histories, the median of the newest 30 % of that window is not
  // better than the median of its oldest 30 %. The window is what makes the rule: the oldest and
  // newest 30 % of the whole restart (as here until session 90) put the early descent into the
  // comparison, and the rule practically never fired (a noisy sphere went on to ConditionCov
  // after 650-1057 generations instead of stopping after 162-312; session 90's review).
  // The calibrations run 50 generations (n = 7-10, lambda = 32): the window's minimum, 127-130
  // generations, is beyond them, so Stagnation cannot stop one.
  const std::size_t generations = static_cast<std::size_t>(state_.generation);
  const std::size_t min_window = stagnation_min_window(n, state_.lambda);
  if (generations >= min_window) {
    // At most 20 000 even where the minimum is larger (30 n / lambda > 19 880): the cap wins.
    const std::size_t window = std::min(std::max(generations / 5, min_window), kStagnationMaxWindow);
    const std::size_t k = window * 3 / 10;
    const auto& mh = state_.median_history;
    // The histories hold min(generations, history_capacity) >= window values.
    const auto oldest = [&](const std::vector<double>& h) {
      return median_of({h.end() - static_cast<long>(window), h.end() - static_cast<long>(window - k)});
    };
    const auto newest = [&](const std::vector<double>& h) {
      return median_of({h.end() - static_cast<long>(k), h.end()});
    };
    if (newest(bh) >= oldest(bh) && newest(mh) >= oldest(mh)) return StopReason::Stagnation;
  }
  // A BIPOP small-regime run: at most half the evaluations of the latest large run (Hansen 2009,
  // section 2, the second regime's budget; see on_local_stop). Its population is at most half the
  // large run's, so the budget is at least that run's generation count, never 0.
  if (settings_.restarts == Restarts::Bipop && state_.bipop_small_regime &&
      state_.generation >= state_.bipop_last_large_evals / 2 / state_.lambda)
    return StopReason::SmallRunBudget;
  return StopReason::None;
}

void Cmaes::on_local_stop(StopReason r) {
  if (settings_.restarts == Restarts::None) {
    state_.stopped = r;
    return;
  }
  const int lambda_default = settings_.lambda > 0 ? settings_.lambda : default_lambda(state_.n);
  if (settings_.restarts == Restarts::Ipop) {
    // IPOP: double the population, same sigma0 (Auger & Hansen 2005). The constructor bounds
    // the doublings; the second test only keeps a hand-made state within the largest population.
    if (state_.restart >= settings_.max_restarts || state_.lambda > kMaxPopulation / 2) {
      state_.stopped = r;
      return;
    }
    state_.restart += 1;
    start_restart(state_.lambda * 2, settings_.sigma0, /*reset_mean=*/true);
    return;
  }
  // BIPOP (Hansen 2009, section 2): after the first run with the default population, two regimes
  // of restarts, each time the one that has used fewer evaluations; cmaes.h, Restarts, has the
  // rules. Where the sources differ, the choices made here:
  // - The first run counts to neither regime (Hansen 2009 runs it before the two regimes begin;
  //   so does DEAP's port of the paper; pycma counts it to the small regime), and a tie goes to
  //   the large regime, so the first restart is a large one. Counted to the large regime (as
  //   here until session 90), it made the first restarts small ones with lambda_large =
  //   lambda_def, which the formula below turns into floor(lambda_def 0.5^(U^2)), under the
  //   default (n = 8: 7 and 8 against 10; session 90's review).
  // - lambda_large in lambda_s = floor(lambda_def (lambda_large / (2 lambda_def))^(U^2)) is the
  //   latest large run's population, so lambda_def <= lambda_s <= lambda_large / 2 (the paper's
  //   range); pycma's fmin draws up to the latest large population itself.
  // - A small run's budget is half the evaluations of the latest large run (Hansen 2009 limits
  //   the second regime's runs to half the budget of the first regime's last run; so does DEAP's
  //   port); pycma allows half of all the large regime's evaluations. local_stop() applies it.
  const long spent = static_cast<long>(state_.lambda) * state_.generation;
  if (state_.bipop_small_regime) {
    state_.bipop_small_evals += spent;
  } else if (state_.restart > 0) {
    state_.bipop_large_evals += spent;
    state_.bipop_last_large_evals = spent;
  }
  const bool small_next = state_.bipop_small_evals < state_.bipop_large_evals;
  // max_restarts counts the large regime's restarts: the search ends when the last of them (or
  // the first run) stops. A small run begins only while the large regime has a restart left, so
  // after one the large regime may still run; the `!small_next` half only keeps a hand-made state
  // from going past max_restarts.
  if ((!state_.bipop_small_regime || !small_next) && state_.bipop_large_restarts >= settings_.max_restarts) {
    state_.stopped = r;
    return;
  }
  state_.restart += 1;
  Normal rng(stream_seed(settings_.seed, state_.restart, -2));
  if (small_next) {
    const double u_lambda = rng.uniform(), u_sigma = rng.uniform();
    const double lambda_large = std::ldexp(static_cast<double>(lambda_default), state_.bipop_large_restarts);
    const int lambda_s = static_cast<int>(
        std::floor(lambda_default * std::pow(0.5 * lambda_large / lambda_default, u_lambda * u_lambda)));
    start_restart(lambda_s, settings_.sigma0 * std::pow(10.0, -2.0 * u_sigma), /*reset_mean=*/true);
    state_.bipop_small_regime = true;
  } else {
    state_.bipop_large_restarts += 1;
    state_.bipop_small_regime = false;
    start_restart(lambda_default << state_.bipop_large_restarts, settings_.sigma0, /*reset_mean=*/true);
  }
}

// ---- exact serialisation ----------------------------------------------------------------------

namespace {
void put(std::ostringstream& o, const char* key, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  o << key << ' ' << buf << '\n';
}
void put_vec(std::ostringstream& o, const char* key, const Eigen::VectorXd& v) {
  o << key << ' ' << v.size();
  char buf[64];
  for (long i = 0; i < v.size(); ++i) {
    std::snprintf(buf, sizeof buf, " %a", v[i]);
    o << buf;
  }
  o << '\n';
}
void put_list(std::ostringstream& o, const char* key, const std::vector<double>& v) {
  put_vec(o, key, Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<long>(v.size())));
}
}  // namespace

std::string Cmaes::save_state() const {
  std::ostringstream o;
  // Version 2 (session 90) adds bipop_last_large_evals; restore_state reads version 1 too.
  o << "cmaes-state 2\n";
  o << "n " << state_.n << "\nlambda " << state_.lambda << "\nrestart " << state_.restart
    << "\ngeneration " << state_.generation << "\ngenerations_total " << state_.generations_total
    << "\nevaluations " << state_.evaluations << "\nbipop_large_evals " << state_.bipop_large_evals
    << "\nbipop_small_evals " << state_.bipop_small_evals << "\nbipop_last_large_evals "
    << state_.bipop_last_large_evals << "\nbipop_large_restarts " << state_.bipop_large_restarts
    << "\nbipop_small_regime " << state_.bipop_small_regime << "\nstopped " << static_cast<int>(state_.stopped)
    << '\n';
  put(o, "sigma", state_.sigma);
  put(o, "sigma_this_restart", state_.sigma_this_restart);
  put(o, "best_f", state_.best_f);
  put_vec(o, "mean", state_.mean);
  put_vec(o, "pc", state_.pc);
  put_vec(o, "ps", state_.ps);
  put_vec(o, "best_x", state_.best_x);
  put_vec(o, "C", Eigen::Map<const Eigen::VectorXd>(state_.C.data(), state_.C.size()));
  put_list(o, "best_history", state_.best_history);
  put_list(o, "median_history", state_.median_history);
  o << "end\n";
  return o.str();
}

// A state is read as a whole and checked before it replaces the current one: every key exactly
// once, every value one that save_state() can have written. A missing `sigma` line used to leave
// sigma at 0, and every candidate of the resumed search was the mean (session 90's review).
// The messages name the key; the calibration adds the checkpoint's file.
void Cmaes::restore_state(const std::string& text) {
  std::istringstream in(text);
  std::string key;  // the key being read, for the messages
  CmaesState s;
  auto fail = [](const std::string& what) { throw std::runtime_error("cmaes state: " + what); };
  auto number = [](double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return std::string(buf);
  };
  auto read_token = [&]() {
    std::string tok;
    if (!(in >> tok)) fail("'" + key + "': truncated");
    return tok;
  };
  auto read_double = [&](double& v) {
    const std::string tok = read_token();
    char* end = nullptr;
    v = std::strtod(tok.c_str(), &end);
    if (end == tok.c_str() || *end) fail("'" + key + "': bad number '" + tok + "'");
  };
  auto read_long = [&](long& v) {
    const std::string tok = read_token();
    char* end = nullptr;
    errno = 0;
    v = std::strtol(tok.c_str(), &end, 10);
    if (end == tok.c_str() || *end || errno == ERANGE) fail("'" + key + "': bad whole number '" + tok + "'");
  };
  auto read_int = [&](int& v) {
    long l = 0;
    read_long(l);
    if (l < std::numeric_limits<int>::min() || l > std::numeric_limits<int>::max())
      fail("'" + key + "': " + std::to_string(l) + " is out of range");
    v = static_cast<int>(l);
  };
  auto read_vec = [&](Eigen::VectorXd& v) {
    long size = 0;
    read_long(size);
    if (size < 0 || size > 1000000) fail("'" + key + "': bad vector size " + std::to_string(size));
    v.resize(size);
    for (long i = 0; i < size; ++i) read_double(v[i]);
  };
  auto read_list = [&](std::vector<double>& v) {
    Eigen::VectorXd e;
    read_vec(e);
    v.assign(e.data(), e.data() + e.size());
  };
  int version = 0;
  if (!(in >> key >> version) || key != "cmaes-state" || (version != 1 && version != 2))
    fail("not a cmaes state (version 1 or 2)");
  // The keys save_state() writes, each exactly once; version 1 (before session 90) has no
  // bipop_last_large_evals.
  static const char* const kKeys[] = {
      "n", "lambda", "restart", "generation", "generations_total", "evaluations", "bipop_large_evals",
      "bipop_small_evals", "bipop_last_large_evals", "bipop_large_restarts", "bipop_small_regime", "stopped",
      "sigma", "sigma_this_restart", "best_f", "mean", "pc", "ps", "best_x", "C", "best_history",
      "median_history"};
  const auto version_has = [&](const std::string& k) { return version >= 2 || k != "bipop_last_large_evals"; };
  std::vector<std::string> seen;
  bool ended = false;
  Eigen::VectorXd cflat;
  int small_regime = 0, stopped = 0;
  while (in >> key) {
    if (key == "end") {
      ended = true;
      break;
    }
    if (std::find(std::begin(kKeys), std::end(kKeys), key) == std::end(kKeys) || !version_has(key))
      fail("unknown key '" + key + "'" + (version_has(key) ? "" : " in a version 1 state"));
    if (std::find(seen.begin(), seen.end(), key) != seen.end()) fail("key '" + key + "' given twice");
    seen.push_back(key);
    if (key == "n") read_int(s.n);
    else if (key == "lambda") read_int(s.lambda);
    else if (key == "restart") read_int(s.restart);
    else if (key == "generation") read_long(s.generation);
    else if (key == "generations_total") read_long(s.generations_total);
    else if (key == "evaluations") read_long(s.evaluations);
    else if (key == "bipop_large_evals") read_long(s.bipop_large_evals);
    else if (key == "bipop_small_evals") read_long(s.bipop_small_evals);
    else if (key == "bipop_last_large_evals") read_long(s.bipop_last_large_evals);
    else if (key == "bipop_large_restarts") read_int(s.bipop_large_restarts);
    else if (key == "bipop_small_regime") read_int(small_regime);
    else if (key == "stopped") read_int(stopped);
    else if (key == "sigma") read_double(s.sigma);
    else if (key == "sigma_this_restart") read_double(s.sigma_this_restart);
    else if (key == "best_f") read_double(s.best_f);
    else if (key == "mean") read_vec(s.mean);
    else if (key == "pc") read_vec(s.pc);
    else if (key == "ps") read_vec(s.ps);
    else if (key == "best_x") read_vec(s.best_x);
    else if (key == "C") read_vec(cflat);
    else if (key == "best_history") read_list(s.best_history);
    else if (key == "median_history") read_list(s.median_history);
  }
  if (!ended) fail("missing 'end' (truncated state)");
  if (in >> key) fail("text after 'end': '" + key + "'");
  for (const char* k : kKeys)
    if (version_has(k) && std::find(seen.begin(), seen.end(), k) == seen.end())
      fail(std::string("missing key '") + k + "'");
  // A version 1 state's small run (there were no BIPOP calibrations) gets pycma's budget: half
  // of all the large regime's evaluations.
  if (version == 1) s.bipop_last_large_evals = s.bipop_large_evals;

  // Values. Counters first: they size and bound the rest.
  if (s.n != state_.n) fail("dimension " + std::to_string(s.n) + " does not match " + std::to_string(state_.n));
  if (s.lambda < 2) fail("'lambda' " + std::to_string(s.lambda) + " is below 2");
  if (s.lambda > kMaxPopulation)
    fail("'lambda' " + std::to_string(s.lambda) + " is above the largest population, 2^30 = " +
         std::to_string(kMaxPopulation));
  for (const auto& [name, v] : {std::pair<const char*, long>{"restart", s.restart},
                                {"generation", s.generation},
                                {"generations_total", s.generations_total},
                                {"evaluations", s.evaluations},
                                {"bipop_large_evals", s.bipop_large_evals},
                                {"bipop_small_evals", s.bipop_small_evals},
                                {"bipop_last_large_evals", s.bipop_last_large_evals},
                                {"bipop_large_restarts", s.bipop_large_restarts}})
    if (v < 0) fail(std::string("'") + name + "' " + std::to_string(v) + " is negative");
  if (s.generations_total < s.generation)
    fail("'generations_total' " + std::to_string(s.generations_total) + " is below 'generation' " +
         std::to_string(s.generation));
  // This restart's generations alone took lambda evaluations each.
  if (s.evaluations / s.lambda < s.generation)
    fail("'evaluations' " + std::to_string(s.evaluations) + " is below lambda x generation (" +
         std::to_string(s.lambda) + " x " + std::to_string(s.generation) + ")");
  if (s.bipop_last_large_evals > s.bipop_large_evals)
    fail("'bipop_last_large_evals' " + std::to_string(s.bipop_last_large_evals) + " is above 'bipop_large_evals' " +
         std::to_string(s.bipop_large_evals));
  if (s.bipop_large_restarts > s.restart)
    fail("'bipop_large_restarts' " + std::to_string(s.bipop_large_restarts) + " is above 'restart' " +
         std::to_string(s.restart));
  // The large regime's population lambda_def 2^k must stay within the constructor's bound.
  if (settings_.restarts == Restarts::Bipop && s.bipop_large_restarts > settings_.max_restarts)
    fail("'bipop_large_restarts' " + std::to_string(s.bipop_large_restarts) + " is above max_restarts " +
         std::to_string(settings_.max_restarts));
  if (small_regime != 0 && small_regime != 1)
    fail("'bipop_small_regime' is " + std::to_string(small_regime) + ", not 0 or 1");
  s.bipop_small_regime = small_regime != 0;
  if (stopped < 0 || stopped > static_cast<int>(StopReason::SmallRunBudget))
    fail("'stopped' " + std::to_string(stopped) + " is no stop reason");
  s.stopped = static_cast<StopReason>(stopped);
  // Step sizes: sigma 0 samples every candidate at the mean; sigma0 of the restart scales nothing
  // yet but is a step size too.
  for (const auto& [name, v] : {std::pair<const char*, double>{"sigma", s.sigma},
                                {"sigma_this_restart", s.sigma_this_restart}})
    if (!(std::isfinite(v) && v > 0)) fail(std::string("'") + name + "' must be finite and above 0, not " + number(v));
  // best_f is a value that tell() kept: a failure's is DBL_MAX, never NaN or infinite.
  if (!std::isfinite(s.best_f)) fail("'best_f' must be finite, not " + number(s.best_f));
  for (const auto& [name, v] : {std::pair<const char*, const Eigen::VectorXd*>{"mean", &s.mean},
                                {"pc", &s.pc},
                                {"ps", &s.ps},
                                {"best_x", &s.best_x}}) {
    if (v->size() != s.n)
      fail(std::string("'") + name + "' has " + std::to_string(v->size()) + " values, not n = " + std::to_string(s.n));
    if (!v->allFinite()) fail(std::string("'") + name + "' must be finite");
  }
  if (cflat.size() != static_cast<long>(s.n) * s.n)
    fail("'C' has " + std::to_string(cflat.size()) + " values, not n^2 = " + std::to_string(s.n * s.n));
  if (!cflat.allFinite()) fail("'C' must be finite");
  s.C = Eigen::Map<Eigen::MatrixXd>(cflat.data(), s.n, s.n);
  // A covariance matrix: positive variances and symmetric. save_state() writes C as update_eigen()
  // left it, (C + C^T) / 2, which is symmetric to the bit (a + b == b + a, and halving is exact),
  // so a written state passes with equality; the tolerance is for a hand-made one. Each pair is
  // measured against sqrt(C_ii C_jj), the bound on |C_ij| of any covariance (Cauchy-Schwarz), so
  // the test is as tight for a badly conditioned C as for the identity; 1e-12 of it admits
  // decimal text of 13 or more significant digits and no asymmetry that could move the search
  // (restore symmetrises C as update_eigen does). Positive definiteness is not asked: near
  // ConditionCov's 1e14 the rounding of an eigen decomposition may call a valid C indefinite,
  // and update_eigen() keeps the eigenvalues at 1e-300 or above.
  for (int i = 0; i < s.n; ++i)
    if (!(s.C(i, i) > 0)) fail("'C' has the variance " + number(s.C(i, i)) + " at (" + std::to_string(i) + ", " +
                               std::to_string(i) + "); a variance must be above 0");
  for (int i = 0; i < s.n; ++i)
    for (int j = i + 1; j < s.n; ++j)
      if (!(std::abs(s.C(i, j) - s.C(j, i)) <= 1e-12 * std::sqrt(s.C(i, i) * s.C(j, j))))
        fail("'C' is not symmetric: " + number(s.C(i, j)) + " at (" + std::to_string(i) + ", " + std::to_string(j) +
             "), " + number(s.C(j, i)) + " at (" + std::to_string(j) + ", " + std::to_string(i) + ")");
  // One value per generation of this restart, the newest history_capacity() of them (a longer
  // history of a state written before the cap is cut to it).
  const std::size_t capacity = history_capacity(s.n, s.lambda);
  const std::size_t generations = static_cast<std::size_t>(s.generation);
  for (const auto& [name, h] : {std::pair<const char*, std::vector<double>*>{"best_history", &s.best_history},
                                {"median_history", &s.median_history}}) {
    if (h->size() != std::min(generations, capacity) && h->size() != generations)
      fail(std::string("'") + name + "' has " + std::to_string(h->size()) + " values for " +
           std::to_string(generations) + " generations (one each, the newest " + std::to_string(capacity) + ")");
    if (!std::all_of(h->begin(), h->end(), [](double v) { return std::isfinite(v); }))
      fail(std::string("'") + name + "' must be finite");
    if (h->size() > capacity) h->erase(h->begin(), h->end() - static_cast<long>(capacity));
  }
  state_ = std::move(s);
  derive_strategy();
  update_eigen();
  asked_ = false;
}

// ---- benchmark functions ------------------------------------------------------------------------

double sphere(const Eigen::VectorXd& x) { return x.squaredNorm(); }

double ellipsoid(const Eigen::VectorXd& x) {
  const long n = x.size();
  double f = 0;
  for (long i = 0; i < n; ++i) f += std::pow(1e6, n > 1 ? static_cast<double>(i) / (n - 1) : 0.0) * x[i] * x[i];
  return f;
}

double rosenbrock(const Eigen::VectorXd& x) {
  double f = 0;
  for (long i = 0; i + 1 < x.size(); ++i) {
    const double a = x[i] * x[i] - x[i + 1], b = x[i] - 1.0;
    f += 100.0 * a * a + b * b;
  }
  return f;
}

}  // namespace dressguard::calib
