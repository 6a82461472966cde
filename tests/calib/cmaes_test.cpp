// CMA-ES on the tutorial's test functions against reference evaluation counts, plus the
// properties the calibration relies on: bounds, determinism, exact checkpoint and restarts.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <vector>

#include "cmaes.h"

namespace dressguard::calib {
namespace {

using Fn = Cmaes::Objective;

// Evaluations until the best value is <= 1e-8, counted in whole generations as purecma does;
// -1 when the budget runs out first (counted as a failure, i.e. +infinity in the median).
long evaluations_to_target(const Fn& f, int n, std::uint64_t seed, long budget) {
  CmaesSettings s;
  s.x0 = Eigen::VectorXd::Constant(n, 0.1);  // purecma's example start, 0.1 in every coordinate
  s.sigma0 = 0.5;
  s.seed = seed;
  s.target_f = 1e-8;
  s.max_evaluations = budget;
  Cmaes es(s);
  es.minimize(f);
  return es.stop_reason() == StopReason::TargetReached ? es.state().evaluations : -1;
}

double median_evaluations(const Fn& f, int n) {
  std::vector<double> e;
  for (std::uint64_t seed = 1; seed <= 31; ++seed) {
    const long k = evaluations_to_target(f, n, seed, 100000);
    e.push_back(k < 0 ? 1e12 : static_cast<double>(k));
  }
  std::nth_element(e.begin(), e.begin() + 15, e.end());
  return e[15];  // the 16th of 31: the median
}

// Reference figures from the issue: the larger of Hansen's purecma and a second implementation,
// median of 31 seeds, default population. A correct tutorial CMA-ES lands within the pair; the
// assertion is the upper figure, so a wrong weight, learning rate or step-size rule fails it.
struct Case {
  const char* name;
  Fn f;
  int n;
  double limit;
};

TEST(Cmaes, ReferenceEvaluationCounts) {
  const std::vector<Case> cases = {
      {"sphere", sphere, 8, 1200},        {"sphere", sphere, 10, 1440},
      {"ellipsoid", ellipsoid, 8, 4230},  {"ellipsoid", ellipsoid, 10, 5840},
      {"rosenbrock", rosenbrock, 8, 4320}, {"rosenbrock", rosenbrock, 10, 5945},
  };
  for (const auto& c : cases) {
    const double m = median_evaluations(c.f, c.n);
    std::printf("  %-10s n=%2d median evaluations %6.0f (reference <= %.0f)\n", c.name, c.n, m, c.limit);
    EXPECT_LE(m, c.limit) << c.name << " n=" << c.n;
  }
}

TEST(Cmaes, DefaultPopulationIsTutorialEq48) {
  EXPECT_EQ(Cmaes::default_lambda(8), 10);   // 4 + floor(3 ln 8) = 4 + 6
  EXPECT_EQ(Cmaes::default_lambda(10), 10);  // 4 + floor(6.9)
  EXPECT_EQ(Cmaes::default_lambda(2), 6);
}

TEST(Cmaes, SameSeedSameBitsDifferentSeedDifferentRun) {
  auto run = [](std::uint64_t seed) {
    CmaesSettings s;
    s.x0 = Eigen::VectorXd::Constant(6, 0.5);
    s.seed = seed;
    s.max_generations = 40;
    Cmaes es(s);
    es.minimize(rosenbrock);
    return es.save_state();
  };
  EXPECT_EQ(run(7), run(7));
  EXPECT_NE(run(7), run(8));
}

TEST(Cmaes, CheckpointRestoreContinuesBitIdentically) {
  CmaesSettings s;
  s.x0 = Eigen::VectorXd::Constant(5, 0.3);
  s.seed = 3;
  s.max_generations = 60;
  Cmaes a(s);
  for (int g = 0; g < 25; ++g) a.step(ellipsoid);
  const std::string saved = a.save_state();
  Cmaes b(s);
  b.restore_state(saved);
  a.minimize(ellipsoid);
  b.minimize(ellipsoid);
  EXPECT_EQ(a.save_state(), b.save_state());
  EXPECT_EQ(a.best_f(), b.best_f());
}

TEST(Cmaes, RestoreRejectsTruncatedState) {
  CmaesSettings s;
  s.x0 = Eigen::VectorXd::Zero(3);
  Cmaes a(s);
  std::string text = a.save_state();
  Cmaes b(s);
  EXPECT_THROW(b.restore_state(text.substr(0, text.size() / 2)), std::runtime_error);
  CmaesSettings s4 = s;
  s4.x0 = Eigen::VectorXd::Zero(4);
  Cmaes c(s4);
  EXPECT_THROW(c.restore_state(text), std::runtime_error);
}

// Bounds: the optimum of a shifted sphere lies outside the box [0, 1]^n at x = -1 in the first
// coordinate; the constrained optimum is on the face x_0 = 0. Every asked point is feasible and
// the run converges to the face (tolerance 1e-4: sqrt of the 1e-8 target on the other coordinates).
TEST(Cmaes, BoundsRepairKeepsPointsFeasibleAndFindsFaceOptimum) {
  CmaesSettings s;
  const int n = 4;
  s.x0 = Eigen::VectorXd::Constant(n, 0.5);
  s.sigma0 = 0.3;
  s.lower = Eigen::VectorXd::Zero(n);
  s.upper = Eigen::VectorXd::Ones(n);
  s.max_generations = 400;
  s.tol_fun = 1e-14;
  Eigen::VectorXd target(n);
  target << -1.0, 0.3, 0.6, 0.9;
  Cmaes es(s);
  es.minimize([&](const Eigen::VectorXd& x) {
    EXPECT_TRUE((x.array() >= 0.0).all() && (x.array() <= 1.0).all());
    return (x - target).squaredNorm();
  });
  EXPECT_NEAR(es.best_x()[0], 0.0, 1e-4);
  EXPECT_NEAR(es.best_x()[1], 0.3, 1e-4);
  EXPECT_NEAR(es.best_x()[3], 0.9, 1e-4);
  EXPECT_NEAR(es.best_f(), 1.0, 1e-4);
}

// Rastrigin in 5-D has many local optima; the default population usually ends in one (TolFun).
// IPOP restarts with doubling populations must find a better optimum than a single run with
// the same seed; BIPOP too. The budget is small so the test stays fast.
double rastrigin(const Eigen::VectorXd& x) {
  double f = 10.0 * x.size();
  for (long i = 0; i < x.size(); ++i) f += x[i] * x[i] - 10.0 * std::cos(2 * M_PI * x[i]);
  return f;
}

double run_rastrigin(Restarts r, std::uint64_t seed) {
  CmaesSettings s;
  s.x0 = Eigen::VectorXd::Constant(5, 2.0);
  s.sigma0 = 2.0;
  s.lower = Eigen::VectorXd::Constant(5, -5.0);
  s.upper = Eigen::VectorXd::Constant(5, 5.0);
  s.seed = seed;
  s.restarts = r;
  s.max_evaluations = 30000;
  s.tol_fun = 1e-10;
  s.target_f = 1e-8;
  Cmaes es(s);
  es.minimize(rastrigin);
  return es.best_f();
}

TEST(Cmaes, RestartsEscapeLocalOptima) {
  double none = 0, ipop = 0, bipop = 0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    none += run_rastrigin(Restarts::None, seed);
    ipop += run_rastrigin(Restarts::Ipop, seed);
    bipop += run_rastrigin(Restarts::Bipop, seed);
  }
  std::printf("  rastrigin-5 mean best f: none %.3f ipop %.3f bipop %.3f\n", none / 5, ipop / 5, bipop / 5);
  EXPECT_LT(ipop, none);
  EXPECT_LT(bipop, none);
}

}  // namespace
}  // namespace dressguard::calib
