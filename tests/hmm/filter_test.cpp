// The online ForwardFilter against the offline forward recursion: same log-likelihoods on every
// prefix of every test sequence, the band it exploits, posteriors, and its handling of bad samples.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>

#include "fixtures.h"
#include "forward_filter.h"
#include "hmm.h"

using namespace dressguard;

namespace {

// |a - b| <= 1e-9 max(|b|, 1): 1e-9 relative, as issue 2 requires, and 1e-9 nats absolute for
// the first samples whose log-likelihood may pass near 0 (relative error is meaningless there).
// Both sides sum the same terms in a different order (band vs full matrix, inverse vs Cholesky
// density), so they differ by rounding only: ~1e-15 per term, ~1e-12 relative over 10^3 terms.
::testing::AssertionResult close(double a, double b) {
  if (std::fabs(a - b) <= 1e-9 * std::max(std::fabs(b), 1.0)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " vs " << b << " (diff " << a - b << ")";
}

// Feeds every trial sample by sample and checks each class's log-likelihood on every prefix.
void expect_prefix_agreement(const model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials) {
  filter::ForwardFilter f(m);
  long checked = 0;
  for (const auto* t : trials) {
    // The filter hears a pull from wherever its recording begins, as the robot's filter hears
    // every pull from its start; so the offline side is asked the same (no unobserved start).
    auto seq = hmm::features_of(*t, m.features);
    seq.unobserved = 0;
    std::vector<std::vector<double>> pre;
    for (const auto& h : m.classes) pre.push_back(hmm::forward_prefix_log_likelihoods(h, seq));
    f.reset();
    for (size_t i = 0; i < t->samples.size(); ++i) {
      const auto& s = t->samples[i];
      f.step(s.f_motion, s.f_lateral, s.f_vertical);
      for (int c = 0; c < f.classes(); ++c) {
        ASSERT_TRUE(close(f.log_likelihood(c), pre[c][i])) << t->id << " sample " << i << " class " << c;
        ++checked;
      }
    }
    ASSERT_EQ(f.samples(), static_cast<long>(t->samples.size()));
    // At the end the posterior is the offline classification's.
    const auto cl = hmm::classify(m, seq);
    for (int c = 0; c < f.classes(); ++c) EXPECT_NEAR(f.posterior(c), cl.posterior[c], 1e-9);
    EXPECT_EQ(f.best(), cl.predicted);
  }
  EXPECT_GT(checked, 0);
}

model::OutcomeModel synthetic_model(int states, int band, const Dataset& train) {
  hmm::ModelOptions opt;
  opt.hmm.n_states = states;
  opt.hmm.band = band;
  return hmm::train_outcome_model(fx::pointers(train), opt);
}

}  // namespace

TEST(ForwardFilter, AgreesWithOfflineOnEveryPrefixTenStates) {
  const Dataset train = fx::synthetic_dataset(15, 600, 900, 31, 10);
  const Dataset test = fx::synthetic_dataset(5, 600, 900, 32, 10);
  const auto m = synthetic_model(10, 1, train);
  filter::ForwardFilter f(m);
  for (int c = 0; c < f.classes(); ++c) EXPECT_EQ(f.band(c), 1);
  expect_prefix_agreement(m, fx::pointers(test));
}

TEST(ForwardFilter, AgreesWithOfflineOnEveryPrefixFiveStatesBandTwo) {
  const Dataset train = fx::synthetic_dataset(15, 300, 600, 33, 5);
  const Dataset test = fx::synthetic_dataset(5, 300, 600, 34, 5);
  const auto m = synthetic_model(5, 2, train);
  filter::ForwardFilter f(m);
  for (int c = 0; c < f.classes(); ++c) EXPECT_EQ(f.band(c), 2);
  expect_prefix_agreement(m, fx::pointers(test));
}

// A model of F_motion alone (feature 1 none, format version 2), read back from its file as the
// predictor reads it: the online filter agrees with the offline forward pass on every prefix.
TEST(ForwardFilter, MotionOnlyModelFromItsFileAgrees) {
  const Dataset train = fx::synthetic_dataset(15, 300, 600, 35, 5);
  const Dataset test = fx::synthetic_dataset(5, 300, 600, 36, 5);
  hmm::ModelOptions opt;
  opt.hmm.n_states = 5;
  opt.features.axis[1] = model::kAxisNone;
  const auto bytes = model::encode_model(hmm::train_outcome_model(fx::pointers(train), opt));
  const auto m = model::decode_model(bytes.data(), bytes.size(), "motion-only");
  EXPECT_EQ(m.features.axis[1], model::kAxisNone);
  expect_prefix_agreement(m, fx::pointers(test));
}

// Any topology: an ergodic model (A_10 > 0) takes the general path and still agrees.
TEST(ForwardFilter, GeneralTopologyAgrees) {
  const Dataset train = fx::synthetic_dataset(10, 300, 400, 35, 4);
  auto m = synthetic_model(4, 1, train);
  for (auto& h : m.classes) {
    const int n = h.n_states;
    for (int i = 1; i < n; ++i) {  // move 5% of each row to the state before
      for (int j = 0; j < n; ++j) h.transition[i * n + j] *= 0.95;
      h.transition[i * n + i - 1] += 0.05;
    }
    h.initial.assign(n, 1.0 / n);
  }
  filter::ForwardFilter f(m);
  for (int c = 0; c < f.classes(); ++c) EXPECT_EQ(f.band(c), -1);
  expect_prefix_agreement(m, fx::pointers(fx::synthetic_dataset(3, 300, 400, 36, 4)));
}

// The measured study: good vs missed models trained on all of it, every prefix of every trial.
TEST(ForwardFilter, AgreesWithOfflineOnTheStudy) {
  const auto dir = study_dir();
  if (dir.empty()) GTEST_SKIP() << "shared/data (the study) is not present";
  const Dataset ds = import_study(dir);
  hmm::ModelOptions opt;
  opt.hmm.n_states = 5;
  const auto m = hmm::train_outcome_model(fx::pointers(ds), opt);
  expect_prefix_agreement(m, fx::pointers(ds));
}

// Before any sample the posterior is the prior; a non-finite sample is skipped and counted, not
// allowed to poison the state; reset() starts over exactly.
TEST(ForwardFilter, PriorNonFiniteSamplesAndReset) {
  const Dataset train = fx::synthetic_dataset(10, 200, 300, 37, 5);
  const auto m = synthetic_model(5, 1, train);
  filter::ForwardFilter f(m);
  for (int c = 0; c < f.classes(); ++c) EXPECT_DOUBLE_EQ(f.posterior(c), std::exp(m.classes[c].log_prior));
  const auto& tr = train.trials[3].samples;
  for (int i = 0; i < 50; ++i) f.step(tr[i].f_motion, tr[i].f_lateral, tr[i].f_vertical);
  const double before = f.log_likelihood(0);
  f.step(NAN, 0.0, 1.0);
  f.step(1.0, 0.0, INFINITY);
  EXPECT_EQ(f.log_likelihood(0), before);
  EXPECT_EQ(f.samples(), 50);
  EXPECT_EQ(f.rejected(), 2);
  f.reset();
  EXPECT_EQ(f.samples(), 0);
  for (int i = 0; i < 50; ++i) f.step(tr[i].f_motion, tr[i].f_lateral, tr[i].f_vertical);
  EXPECT_EQ(f.log_likelihood(0), before);  // same bits
  double sum = 0.0;
  for (int c = 0; c < f.classes(); ++c) sum += f.posterior(c);
  EXPECT_NEAR(sum, 1.0, 1e-12);
  // State probabilities are normalised.
  double ps = 0.0;
  for (int j = 0; j < f.n_states(0); ++j) ps += f.state_probabilities(0)[j];
  EXPECT_NEAR(ps, 1.0, 1e-12);
}

namespace {
// Two classes of two states, A = [[0.9 0.1][0 1]], unit covariances; state 1 of class "caught"
// sits `far` standard deviations out on feature 0 and starts with probability pi1.
model::OutcomeModel tiny_start_model(double pi1, double far) {
  model::OutcomeModel m;
  for (const char* name : {"good", "caught"}) {
    model::ClassHmm h;
    h.name = name;
    h.n_states = 2;
    h.initial = {1.0 - pi1, pi1};
    h.transition = {0.9, 0.1, 0.0, 1.0};
    h.emission.resize(2);
    h.emission[1].mean[0] = far;
    h.log_prior = std::log(0.5);
    m.classes.push_back(h);
  }
  m.classes[0].initial = {1.0, 0.0};
  m.classes[0].emission[1].mean[0] = -far;
  return m;
}
}  // namespace

// A state whose prediction is tiny but which alone explains the sample (every other state 40
// standard deviations away: log density -800). Closed form of the first sample's log-likelihood
// of "caught": log(pi0 N(x; 0, I) + pi1 N(x; mu1, I)) with x = mu1 = (40, 0), which is
// log N(0; 0, I) + log(pi1 + e^-800) = -log 2pi + log pi1 for pi1 = 1e-290. Below kFlushBelow
// (pi1 = 1e-310, a subnormal the model file accepts) the state counts as unreachable, as in the
// offline forward, and the likelihood is state 0's alone: -log 2pi - 800. Before predictions
// were flushed, the normaliser c was subnormal there, 1/c overflowed and the posteriors went NaN
// (posterior > threshold is false for NaN: no caught stop could fire).
TEST(ForwardFilter, ATinyPredictionThatAloneExplainsTheSampleStaysFinite) {
  const double log2pi = std::log(2 * M_PI);
  for (const double pi1 : {1e-290, 1e-310}) {
    const auto m = tiny_start_model(pi1, 40.0);
    filter::ForwardFilter f(m);
    hmm::FeatureSequence seq;
    seq.x = {40, 0, 40, 0, 40, 0};
    const auto pre = hmm::forward_prefix_log_likelihoods(m.classes[1], seq);
    const double want = pi1 > filter::kFlushBelow ? -log2pi + std::log(pi1) : -log2pi - 800.0;
    EXPECT_NEAR(pre[0], want, 1e-9 * std::fabs(want)) << "pi1 " << pi1;
    for (size_t t = 0; t < seq.size(); ++t) {
      f.step_features(seq.at(t));
      ASSERT_FALSE(f.failed()) << "pi1 " << pi1 << " sample " << t;
      ASSERT_TRUE(std::isfinite(f.log_likelihood(1))) << "pi1 " << pi1 << " sample " << t;
      EXPECT_TRUE(close(f.log_likelihood(1), pre[t])) << "pi1 " << pi1 << " sample " << t;
      EXPECT_NEAR(f.posterior(0) + f.posterior(1), 1.0, 1e-12);
    }
    // Class "good" (state 1 at -40) rates each sample at -log 2pi - 800; "caught" from the
    // second sample at about -log 2pi: caught wins in both cases.
    EXPECT_EQ(f.best(), 1) << "pi1 " << pi1;
  }
}

// Both kernels flush predictions below kFlushBelow (pred given, as at a trial's first sample):
// the normaliser stays >= kFlushBelow and the two agree.
TEST(ForwardFilter, BothKernelsFlushTinyPredictions) {
  const int np = 4;
  const double zero[np] = {0, 0, 0, 0}, lc[np] = {0, 0, 0, 0}, one[np] = {1, 1, 1, 1};
  const double m0[np] = {0, 40, 0, 0};
  filter::ClassBlock b;
  b.n_padded = np;
  b.band = 0;
  b.diag[0] = one;
  b.m0 = m0, b.m1 = zero, b.ip = one, b.iq = zero, b.ir = one, b.lc = lc;
  std::vector<filter::ClassUpdateFn> kernels{filter::class_update_portable};
  if (auto avx = filter::class_update_avx2()) kernels.push_back(avx);
  for (const auto update : kernels) {
    std::vector<double> alpha(filter::kBandPad + np, 0.0), logb(np);
    double pred[np] = {1.0, 1e-310, 0.0, 0.0}, m = 0.0;
    const double c = update(b, true, 40.0, 0.0, alpha.data() + filter::kBandPad, pred, logb.data(), &m, nullptr);
    EXPECT_EQ(pred[1], 0.0) << "the subnormal prediction is flushed";
    EXPECT_GE(c, filter::kFlushBelow);
    EXPECT_EQ(m, -800.0) << "only state 0 is reachable";
    EXPECT_EQ(alpha[filter::kBandPad], 1.0);
    EXPECT_EQ(alpha[filter::kBandPad + 1], 0.0);
  }
}

// A sample that every state of every class rates at log density -inf (here a feature scale of
// 1e-200 turns 2 N into 2e200: its square overflows) leaves posteriors that mean nothing: the
// filter says so, from that sample until reset.
TEST(ForwardFilter, SaysWhenItsPosteriorsFail) {
  auto m = tiny_start_model(0.0, 3.0);
  filter::ForwardFilter ok(m);
  ok.step(-2.0, 0.0, 0.0);
  EXPECT_FALSE(ok.failed());
  m.features.scale[0] = 1e-200;
  filter::ForwardFilter f(m);
  f.step(0.0, 0.0, 0.0);
  EXPECT_FALSE(f.failed());
  f.step(-2.0, 0.0, 0.0);
  EXPECT_TRUE(f.failed());
  f.step(0.0, 0.0, 0.0);
  EXPECT_TRUE(f.failed()) << "sticky until reset";
  f.reset();
  EXPECT_FALSE(f.failed());
}

// An invalid model is refused at construction, never at step time.
TEST(ForwardFilter, RefusesInvalidModel) {
  model::OutcomeModel m;
  EXPECT_THROW(filter::ForwardFilter{m}, model::ModelError);
}

// The AVX2 update and the portable one compute the same step: on random states, samples and
// parameters they give the same alpha and increment to 1e-14 relative (their exps differ by
// < 3e-16; the rest is the same arithmetic in another order). Skipped on CPUs without AVX2+FMA.
TEST(ForwardFilter, VectorAndPortableUpdatesAgree) {
  const auto avx = filter::class_update_avx2();
  if (!avx) GTEST_SKIP() << "this CPU has no AVX2+FMA";
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int np = 4 * (1 + trial % 3), w = trial % 5;  // every band width the vector path takes
    std::vector<double> diag((w + 1) * np), m0(np), m1(np), ip(np), iq(np), ir(np), lc(np);
    for (auto& v : diag) v = u(rng);
    for (int j = 0; j < np; ++j) {
      m0[j] = 4 * u(rng) - 2, m1[j] = 4 * u(rng) - 2;
      const double a = 0.2 + u(rng), d = 0.2 + u(rng), b = 0.3 * (u(rng) - 0.5) * std::sqrt(a * d);
      const double det = a * d - b * b;
      ip[j] = d / det, iq[j] = -b / det, ir[j] = a / det, lc[j] = -std::log(2 * M_PI) - 0.5 * std::log(det);
    }
    filter::ClassBlock b;
    b.n_padded = np;
    b.band = w;
    for (int d = 0; d <= w; ++d) b.diag[d] = diag.data() + d * np;
    b.m0 = m0.data(), b.m1 = m1.data(), b.ip = ip.data(), b.iq = iq.data(), b.ir = ir.data(), b.lc = lc.data();
    std::vector<double> alpha1(filter::kBandPad + np, 0.0);
    for (int j = 0; j < np; ++j) alpha1[filter::kBandPad + j] = trial % 5 == 0 && j % 2 ? 0.0 : u(rng);
    auto alpha2 = alpha1;
    std::vector<double> pred1(np), pred2(np), lb1(np), lb2(np);
    const double x0 = 6 * u(rng) - 3, x1 = 6 * u(rng) - 3;
    double ma = 0, mb = 0;
    const double r1 = filter::class_update_portable(b, false, x0, x1, alpha1.data() + filter::kBandPad, pred1.data(),
                                                    lb1.data(), &ma, nullptr);
    const double r2 = avx(b, false, x0, x1, alpha2.data() + filter::kBandPad, pred2.data(), lb2.data(), &mb, nullptr);
    ASSERT_NEAR(ma, mb, 1e-14 * std::max(1.0, std::fabs(ma))) << "trial " << trial;  // FMA vs mul+add
    ASSERT_NEAR(r1, r2, 1e-14 * r1) << "trial " << trial;
    for (int j = 0; j < np; ++j)
      ASSERT_NEAR(alpha1[filter::kBandPad + j], alpha2[filter::kBandPad + j], 1e-14) << "trial " << trial << " state " << j;
  }
}

// A copy (and a move) of a filter is independent of the original: destroying the original and
// stepping the copy gives the same bits as an untouched filter.
TEST(ForwardFilter, CopiesAndMovesStayValid) {
  const Dataset train = fx::synthetic_dataset(8, 200, 300, 38, 5);
  hmm::ModelOptions opt;
  opt.hmm.n_states = 5;
  const auto m = hmm::train_outcome_model(fx::pointers(train), opt);
  filter::ForwardFilter reference(m);
  auto original = std::make_unique<filter::ForwardFilter>(m);
  const auto& tr = train.trials[1].samples;
  for (int i = 0; i < 20; ++i) {
    original->step(tr[i].f_motion, tr[i].f_lateral, tr[i].f_vertical);
    reference.step(tr[i].f_motion, tr[i].f_lateral, tr[i].f_vertical);
  }
  filter::ForwardFilter copy(*original);
  original.reset();
  std::optional<filter::ForwardFilter> moved;
  moved.emplace(std::move(copy));
  for (size_t i = 20; i < tr.size(); ++i) {
    moved->step(tr[i].f_motion, tr[i].f_lateral, tr[i].f_vertical);
    reference.step(tr[i].f_motion, tr[i].f_lateral, tr[i].f_vertical);
  }
  for (int c = 0; c < reference.classes(); ++c) EXPECT_EQ(moved->log_likelihood(c), reference.log_likelihood(c));
}
