// Outcome HMMs offline: Baum-Welch training of left-right HMMs with bivariate full-covariance
// Gaussian emissions (paper section V-B), the forward log-likelihood, Viterbi, sampling, and the
// outcome model built from a dataset (one HMM per labelled outcome).
//
// Numerics. Every recursion is scaled (Rabiner 1989, section V-A): at each t the forward vector
// is normalised to sum 1 and the log of the normaliser accumulates, and the emission densities are
// shifted by their maximum m_t over reachable states before exponentiation. Nothing is ever a
// product of T probabilities, so sequences of any length keep finite log-likelihoods. Normalised
// forward probabilities below 1e-300 are set to 0 (no subnormal arithmetic; the online filter does
// the same): a state that improbable is dropped, which can matter only when a later sample is so
// far out that such a state alone explains it.
//
// Training (Rabiner eq. 40, 52-54 for the Gaussian case):
//   initialisation: every sequence of at least n samples (with the samples it did not record,
//     FeatureSequence::unobserved) split into n equal segments, segment j feeding state j's mean
//     and covariance; a shorter sequence cannot give every state a sample and is left out, of
//     the segments and of the mean length. pi = (1, 0, ..., 0); A_ii = 1 - leave with leave =
//     n / mean length held to [1e-6, 0.5] (a stay of at least 1/2 for sequences under 2n
//     samples; never a band transition of 0, which every M-step would keep), the rest of the row
//     spread over the band j = i+1..i+w with weights halving per step (the last state absorbs).
//   E-step: scaled forward-backward per sequence, restricted to the band; the forward pass runs
//     through the online filter's vector update (predictor/filter/emission_update.h), so training
//     and the robot compute the same recursion.
//   M-step: pi_j = mean gamma_1(j); A_ij = sum_t xi_t(i,j) / sum_t gamma_t(i) (zeros stay zero, so
//     the left-right band is kept); mu_j = sum gamma x / sum gamma;
//     Sigma_j = sum gamma (x - mu_j)(x - mu_j)^T / sum gamma, accumulated about the previous mean
//     and corrected exactly (not GHMM's previous-mean covariance), then floored: every eigenvalue of
//     Sigma_j is raised to at least cov_floor (feature units) so no state collapses onto a point.
//   Convergence: stop when the log-likelihood gain per training sample is below `tolerance`, or
//     at `max_iterations`; the result is the best model whose likelihood was evaluated, with that
//     exact likelihood (never the likelihood of the model before the last update).
//
// Determinism. The same data and options train the same bits on one machine, so `train` and
// `build-model` with --created fixed write the same bytes there. On another CPU they may not: the
// E-step runs the filter's best update for the CPU (filter::class_update_best: AVX2+FMA, else
// portable), and the two kernels' exps differ in the last bit. Trained on the study, the default
// 10-state model's parameters differ in their last digits (72 of 300 numbers, at most 7e-15
// relative; session 85's HMM review, finding 3), and so do the model's bytes and SHA-256. A run
// whose last gain per sample lands within rounding of `tolerance` may also stop one iteration
// earlier or later on the other kernel; its parameters then differ by that iteration's change.
// Any two CPUs with AVX2+FMA train the same bits (one build), as do any two without. Why not the
// portable kernel everywhere: it makes `dressguard train` on the study 28 % slower (0.145 s
// against 0.114 s, median of 10 runs), and classification agrees across the kernels to 1e-9
// relative anyway (tests/hmm/filter_test.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "dataset.h"
#include "dgm.h"

namespace dressguard::hmm {

using model::ClassHmm;
using model::kFeatures;

// One sequence of feature vectors (x_t in feature units), row-major: x[t*kFeatures + k].
//
// A sequence that starts late. The HMMs are trained on pulls recorded from their start, so their
// chain's time is the pull's time. A recording that begins `unobserved` samples into its pull
// (core/haptic.h, unrecorded_samples; one study trial begins 64 samples in) is scored from the
// state distribution the chain has reached by then with nothing observed, pi A^k: the forward
// recursion over k samples whose emission densities are all 1, i.e. the missing start
// marginalised out. Scored from pi instead, the late recording's first forces (a pull 0.1 m in)
// meet the states of a pull's first centimetres. Everything here reads `unobserved`: the forward,
// Viterbi, classify, and training (the equal segments are of the whole pull, and Baum-Welch's
// E-step runs the k unobserved steps with emission density 1, so their transitions count in A
// and their first state in pi, exactly; hmm.cpp, unobserved_statistics). The robot's filter
// does not: it hears every pull from its start.
struct FeatureSequence {
  std::vector<double> x;
  size_t unobserved = 0;  // samples of the pull before x_1 (0: recorded from the start)
  size_t size() const { return x.size() / kFeatures; }
  const double* at(size_t t) const { return x.data() + t * kFeatures; }
};

// The smallest covariance floor training takes, in scaled feature units squared. The emission
// normaliser needs the 2x2 determinant a d - b^2 = l1 l2, which rounding gets wrong by ~eps l1^2:
// relative error eps l1 / l2. A state spans at most the features' spread (l1 ~ 1 to 100, the
// features having unit variance), so l2 >= 1e-9 keeps that error below 2e-5 (a log density
// off by < 1e-4 nats). Floors below 1e-30 let a state fitted to a constant segment (the
// zero forces before contact) keep a rank-1 covariance of rounding, whose determinant rounds to
// 0: log-likelihood -inf (session 85's HMM review, finding 2). 1e-9 is also a standard deviation
// of 3e-5 of a feature's spread (~0.01 mN on the study's forces), far below any force sensor's
// resolution, so no real floor is refused.
inline constexpr double kMinCovFloor = 1e-9;

struct TrainOptions {
  int n_states = 10;           // the paper's 10; the study's code used 5
  int band = 1;                // left-right width: A_ij > 0 only for i <= j <= i + band
  // Minimum covariance eigenvalue, feature units squared (features are scaled to unit variance).
  // 0.05 (a standard deviation of 0.22 of the feature's spread): a floor near the sensor noise
  // lets Baum-Welch shrink states until the online posterior is certain within ~5 samples, and
  // the predictor then stops good trials at once (measured on the replay logs); 0.05 keeps the
  // posteriors calibrated enough for the StopPolicy and costs no accuracy on the study.
  // At least kMinCovFloor.
  double cov_floor = 0.05;
  int max_iterations = 100;
  double tolerance = 1e-6;     // stop when the log-likelihood gain per sample is below this [nats]
};

struct TrainResult {
  ClassHmm hmm;                   // name and log_prior left for the caller
  int iterations = 0;             // E-steps run
  bool converged = false;         // tolerance reached (false: max_iterations)
  double log_likelihood = 0.0;    // total over the training sequences, of `hmm` exactly
  std::vector<double> history;    // log-likelihood of each evaluated model, in order
};

// Equal-segment initialisation (above). Throws std::invalid_argument when the sequences are too
// short to give every state a sample or the options are out of range.
ClassHmm initial_left_right(const std::vector<FeatureSequence>& seqs, const TrainOptions& opt);

// One Baum-Welch iteration: returns log p(seqs | in) and writes the re-estimated model to `out`.
// `cov_floor` <= 0 disables the floor (for comparisons with other libraries).
double baum_welch_step(const ClassHmm& in, const std::vector<FeatureSequence>& seqs, double cov_floor, ClassHmm& out);

// Trains from `start` (usually initial_left_right) until convergence. Throws std::invalid_argument
// naming the iteration when a log-likelihood is not finite (a sample that is not, or one so far
// from every state that its squared distance overflows): -inf and NaN compare false with every
// likelihood, so training would otherwise stop "converged" on one or return no model at all.
TrainResult train(const ClassHmm& start, const std::vector<FeatureSequence>& seqs, const TrainOptions& opt);
TrainResult train(const std::vector<FeatureSequence>& seqs, const TrainOptions& opt);

// log p(x_1..T | hmm), general full-matrix scaled forward (any topology). 0 for an empty sequence.
double forward_log_likelihood(const ClassHmm& hmm, const FeatureSequence& seq);
// log p(x_1..t | hmm) for every t = 1..T (one forward pass).
std::vector<double> forward_prefix_log_likelihoods(const ClassHmm& hmm, const FeatureSequence& seq);

// The most probable state path and its joint log-probability log p(x, path), in log space.
// When no path can produce the sequence (log_probability -inf) the path is arbitrary, but every
// entry is a valid state index.
struct ViterbiResult {
  std::vector<int> path;
  double log_probability = -std::numeric_limits<double>::infinity();
};
ViterbiResult viterbi(const ClassHmm& hmm, const FeatureSequence& seq);

// log N(x; mean, cov) of one emission (Cholesky of the 2x2 covariance).
double emission_log_density(const model::GaussianEmission& e, const double x[kFeatures]);

// Draws a sequence of T samples (and its states) from the HMM. Deterministic for a given rng state.
FeatureSequence sample(const ClassHmm& hmm, size_t T, std::mt19937_64& rng, std::vector<int>* states = nullptr);

// ---- outcome models from datasets ----------------------------------------------------------

// The feature vectors of one trial, cut after the last sample with travel <= truncate_at, with
// `unobserved` = unrecorded_samples(trial).
FeatureSequence features_of(const HapticSequence& trial, const model::FeatureConvention& fc,
                            double truncate_at = std::numeric_limits<double>::infinity());

// The axes and signs of `axes` (default F_motion and F_vertical, sign +1), offset/scale = mean/
// standard deviation over every sample of the trials. A constant feature gets scale 1: one whose
// samples are all the same value (offset that value, so the feature is 0; a feature with axis
// model::kAxisNone gets offset 0), or whose standard deviation is at most 1e-9 max(1, |mean|),
// rounding's size. Scaled by a spread of rounding, a test trial off such a constant by a
// millinewton would sit 10^4 feature units from every state.
model::FeatureConvention fit_feature_scaling(const std::vector<const HapticSequence*>& trials,
                                             const model::FeatureConvention& axes = {});

struct ModelOptions {
  TrainOptions hmm;
  model::FeatureConvention features;  // the axes and signs to model; offset and scale are fitted
  bool uniform_priors = false;  // log_prior = -log(classes) instead of the training counts
  std::string source_dataset;   // written into the model's metadata
  // Names a training trial in an error (its file, where the caller knows it); empty: its id.
  std::function<std::string(const HapticSequence&)> trial_name;
};

// The training conditions of m (format version 3) from the labelled `trials`: the sample period,
// from each trial's mean interval, which every trial must share within kRecordingPeriodTolerance
// (else std::invalid_argument naming the trial by `trial_name`, or its id, and both periods),
// their mean to the whole microsecond (nominal_sample_period); and the slowest and fastest pull
// speed. A trial of fewer than 2 samples says no period.
void set_training_conditions(model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials,
                             const std::function<std::string(const HapticSequence&)>& trial_name = {});

// The classes' log priors of m: equal (`uniform`, the paper's "highest likelihood"), or each
// class's share of the labelled `trials` (the Bayes decision for data drawn like the training
// set: a synthesized set has the study's three arm heights in equal numbers, so its shares are
// the protocol's, not the measured trials'). Throws std::invalid_argument when a class has no
// trial and `uniform` is false.
void set_log_priors(model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials, bool uniform);

// One HMM per outcome label present in `trials` (in Outcome order: good, missed, caught), trained
// on the labelled trials; unlabelled trials are ignored. `progress` (may be empty) is told each
// class's result. Throws std::invalid_argument when no trial is labelled, or when a class cannot
// be trained: train()'s reason after the class's name, its trial count and its longest trial.
model::OutcomeModel train_outcome_model(const std::vector<const HapticSequence*>& trials, const ModelOptions& opt,
                                        const std::function<void(const std::string&)>& progress = {});

// The classification of one sequence: per-class log-likelihoods, posteriors (with log priors)
// and the MAP class (the paper's "highest likelihood" when the priors are equal).
struct Classification {
  int predicted = -1;
  std::vector<double> log_likelihood, posterior;
};
//
// `among` (by name; empty: all of the model's classes) limits the decision to some classes: the
// others keep their log-likelihood but get posterior 0 and are never predicted. Why: the study's
// recordings hold good and missed trials only, so a classifier trained on them (the issue's
// 1-nearest-neighbour baseline) can answer only "good or missed?"; asking an STC the same
// question compares the two on one footing. The robot asks all three (a caught arm is the one
// it must stop for), and so does every evaluation by default.
using ClassChoice = std::vector<std::string>;
Classification classify(const model::OutcomeModel& m, const FeatureSequence& seq, const ClassChoice& among = {});

// Truth-by-prediction counts: confusion[truth][predicted] over `classes`, the model's classes
// and then every label of a scored trial that the model has no class for (its column stays 0:
// the model never predicts it; its row holds that label's trials, all wrong).
struct Evaluation {
  std::vector<std::string> classes;
  std::vector<std::vector<int>> confusion;
  int correct = 0, total = 0, skipped = 0;  // skipped: unlabelled, or no sample before the cut
  double accuracy() const { return total ? static_cast<double>(correct) / total : 0.0; }
};

// One trial's result in an evaluation.
struct TrialResult {
  const HapticSequence* trial = nullptr;
  int truth = -1;            // model class index of the label; -1 when skipped or when the
                             // model has no class for the label (then scored, and wrong)
  size_t samples = 0;        // after truncation
  Classification result;     // empty when skipped
};

// Classifies every trial (cut at truncate_at travel, deciding `among` some classes as classify())
// and counts the confusion matrix over every labelled trial with a sample before the cut. A
// label the model has no class for counts as wrong (a model trained without any caught trial
// can never be right about one; skipping such trials once scored a model of "missed" alone
// 14/14 on the study's 22 trials), as calib::count_correct counts it.
Evaluation evaluate(const model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials,
                    double truncate_at = std::numeric_limits<double>::infinity(),
                    std::vector<TrialResult>* per_trial = nullptr, const ClassChoice& among = {});

// ---- a committee of outcome models -----------------------------------------------------------

// The vote of several outcome models on one trial: a committee of simulation-trained classifiers,
// one per person's simulator (offline/calib/MEASUREMENTS.md, session 22). Each model classifies the
// trial, cut at `truncate_at`, in its own features (classify()); the class that most models pick
// wins, a tie goes to the larger sum of the models' posteriors for the tied classes, and then to
// the class named first. Classes are matched by name; `classes` is their union in the order the
// models first name them, so a model that never saw a class (a simulator that never catches)
// simply gives it no vote.
// Why votes, not one HMM of everyone's trials or a mixture of the likelihoods: a trial that one
// simulator explains far better than the others decides a mixture alone, and a pooled HMM learns
// the average of cues that some simulators have reversed; a vote counts each simulator once.
struct Vote {
  std::vector<std::string> classes;
  std::vector<int> votes;             // per class: how many models predict it
  std::vector<double> posterior_sum;  // per class: the sum of the models' posteriors
  std::vector<int> answers;           // per model, in order: index into classes of its answer
                                      // (empty when the cut leaves no sample)
  size_t samples = 0;                 // after the cut
  int predicted = -1;                 // index into classes; -1 when the cut leaves no sample
};
// With `among`, each model decides among those classes only (classify()); with `weights` (one
// per model), the weighted sums decide (weighted_choice(), below) instead of the counts.
Vote vote(const std::vector<const model::OutcomeModel*>& models, const HapticSequence& trial,
          double truncate_at = std::numeric_limits<double>::infinity(), const ClassChoice& among = {},
          const std::vector<double>& weights = {});

// The committee's decision with a weight per member (`weights`, in the order of the vote's
// models): per class the sum of the weights of the members that answer it wins, a tie goes to the
// larger posterior sum and then to the class named first, as vote() decides with every weight 1.
// -1 when the cut left no sample. Why weights: a plain vote counts a member that is right one
// time in four as much as one right three times in four (offline/calib/MEASUREMENTS.md, session
// 72: at 0.15 m the committee's figure is a balance of the members' leanings). Throws
// std::invalid_argument unless there is one finite weight >= 0 per member.
int weighted_choice(const Vote& v, const std::vector<double>& weights);

// The weight of a committee member that is right `right` of `n` times on trials of a K-class
// question: the log-odds of its accuracy a = right / n above chance,
//
//   w = max(0, ln(a / (1 - a)) + ln(K - 1)),
//
// SAMME's member weight (Zhu, Zou, Rosset and Hastie 2009, multi-class AdaBoost). For K = 2 it is
// ln(a / (1 - a)), the weight under which a vote of independent members is the most likely class
// (Nitzan and Paroush 1982); a member at or below chance (a <= 1 / K) gets none. a is held inside
// [1 / (2n), 1 - 1 / (2n)], so that a member right every time has a finite weight that grows with
// the evidence. Throws std::invalid_argument unless 0 <= right <= n, n > 0 and classes >= 2.
double member_weight(int right, int n, int classes);

// How often a model names the label of `trials` cut at `truncate_at`, deciding `among` some
// classes (classify()): `scored` counts every labelled trial with a sample before the cut, also
// one whose label the model does not know (a simulator that never catches, facing a caught
// trial: in a vote such a member is wrong there, so its weight must count it wrong, as
// evaluate() does), `right` those whose MAP class is the label.
struct LabelScore {
  int right = 0, scored = 0;
};
LabelScore score_labels(const model::OutcomeModel& m, const std::vector<const HapticSequence*>& trials,
                        double truncate_at = std::numeric_limits<double>::infinity(), const ClassChoice& among = {});
// The same score of counts[truth][answer] (answer_counts(), below): right the diagonal, scored
// every count.
LabelScore label_score(const std::vector<std::vector<int>>& counts);

// The members' weights learnt from simulation alone (rule S; offline/calib/MEASUREMENTS.md,
// session 73): member i is scored (score_labels) on every set but its own, `sets[j]` being the
// synthesized trials that member j was trained on, at the cut and question it will vote at,
// and weighted by member_weight() with K = the classes decided among (`among`, else the union of
// the models' classes). With `among`, a trial whose label is not among them is not scored. Why
// the other members' sets: a member whose simulator agrees with the others' on what a good and
// a missed trial look like at that cut is more likely to be right on a person none of them was
// fitted to than one whose simulator stands alone (session 73 measured it: over seven people's
// simulators, the two accuracies rank the members alike at every cut, Spearman median 0.82); its
// own set would only say how well it learnt itself. Give one set per person: two simulators of one person would score each other
// as if they were another person's. Throws std::invalid_argument unless there is one set per
// model; a member with no scored trial gets weight 0.
std::vector<double> simulation_weights(const std::vector<const model::OutcomeModel*>& models,
                                       const std::vector<std::vector<const HapticSequence*>>& sets,
                                       double truncate_at = std::numeric_limits<double>::infinity(),
                                       const ClassChoice& among = {});

// What one member's answer says about the truth: ln P(answer | truth) over `classes` (rows the
// truth, columns the answer), learnt from how often it gave each answer on trials of each label.
// Why more than rule S's one weight per member: a member that calls most trials good is right on
// the good ones and wrong on the missed ones, so its "good" says little and its "missed" much;
// one accuracy cannot tell the two answers apart (offline/calib/MEASUREMENTS.md, session 72: at
// 0.15 m three of seven members call most missed trials good).
struct AnswerModel {
  std::vector<std::string> classes;
  std::vector<std::vector<double>> log_p;  // log_p[truth][answer]
};

// The answer model of counts[truth][answer] (over `classes`): each row's counts plus 1/2 per cell
// (Jeffreys' prior, so that an answer never seen for a truth is unlikely, not impossible),
//
//   P(a | t) = (n_ta + 1/2) / (n_t + K/2),   K = classes.size(),
//
// and a row without counts 1/K for every answer (it tells nothing). Throws std::invalid_argument
// unless counts is K x K with counts >= 0 and K >= 2.
AnswerModel answer_model(const std::vector<std::string>& classes, const std::vector<std::vector<int>>& counts);

// How often model `m` gave each answer on `trials` of each label, cut at `truncate_at` and
// deciding `among` some classes (classify()), as counts[truth][answer] over `classes`: trials
// whose label is not in `classes` (or not among) are not counted, nor those with no sample before
// the cut; an answer not in `classes` throws std::invalid_argument. The confusion matrix of
// evaluate(), but over classes the model may not know (a simulator that never catches, facing
// caught trials: every answer it gives them counts).
std::vector<std::vector<int>> answer_counts(const model::OutcomeModel& m,
                                            const std::vector<const HapticSequence*>& trials,
                                            const std::vector<std::string>& classes,
                                            double truncate_at = std::numeric_limits<double>::infinity(),
                                            const ClassChoice& among = {});

// The committee's decision by its members' answer models (rule C; Kuncheva 2004, "Combining
// Pattern Classifiers", the naive Bayes combination; Dawid and Skene 1979): if the members err
// independently given the truth, the most likely truth t given their answers a_m is
//
//   argmax_t  sum_m ln P_m(a_m | t)          (equal priors, as classify() with its defaults),
//
// over `among` (empty: the vote's classes); a tie goes to the larger posterior sum and then to
// the class named first, as vote(). Each model gives its classes by name; a class the vote holds
// and a member's model does not is a truth that member says nothing about. For two classes and a
// member whose two kinds of error are equally likely, its term is rule S's weight ln(a/(1-a))
// for its answer, without member_weight()'s floor at 0: a member under chance counts against its
// own answer. -1 when the cut left no sample. Throws std::invalid_argument unless there is one
// model per member.
int answer_model_choice(const Vote& v, const std::vector<AnswerModel>& models, const ClassChoice& among = {});

// The members' answer models learnt from simulation alone (rule C), where simulation_weights()
// learns rule S's weights: member i's answer_counts() summed over every set but its own, over
// the union of the models' classes (`among`: those only), then answer_model(). The same
// arguments and the same caveat: one set per person.
std::vector<AnswerModel> simulation_answer_models(const std::vector<const model::OutcomeModel*>& models,
                                                  const std::vector<std::vector<const HapticSequence*>>& sets,
                                                  double truncate_at = std::numeric_limits<double>::infinity(),
                                                  const ClassChoice& among = {});

// evaluate() for a committee: the confusion matrix over the union of the models' classes (then
// the labels no model has a class for, as evaluate()), every labelled trial with a sample before
// the cut; a label no model knows counts as wrong. `per_trial` (may be null) gets every trial's
// vote, skipped trials included (predicted -1). `weights` as vote()'s.
Evaluation evaluate_vote(const std::vector<const model::OutcomeModel*>& models,
                         const std::vector<const HapticSequence*>& trials,
                         double truncate_at = std::numeric_limits<double>::infinity(),
                         std::vector<Vote>* per_trial = nullptr, const ClassChoice& among = {},
                         const std::vector<double>& weights = {});

// ---- two classifiers on the same trials ------------------------------------------------------

// Whether one classifier got one trial right: 1 when it names the trial's label, 0 when it names
// another class (also when it has no class for the label), -1 when the trial is not scored
// (unlabelled, or nothing left after the cut), the rules by which evaluate() and evaluate_vote()
// count.
// Pairing two classifiers trial by trial (mcnemar_exact_p, below) starts here.
int right_or_not(const TrialResult& r);
int right_or_not(const Vote& v, const HapticSequence& trial);

// How sure a measured accuracy is: the Wilson score interval (Wilson 1927) of k = `right` out of
// `n` trials at the normal quantile z (1.96: 95 %),
//
//   centre = (k + z^2 / 2) / (n + z^2),   half = z sqrt(k (n - k) / n + z^2 / 4) / (n + z^2),
//
// which stays inside [0, 1] and keeps its coverage near 0 % and 100 %, where the textbook
// p +- z sqrt(p (1 - p) / n) does not (Brown, Cai and DasGupta 2001). The study's 22 trials give
// 16 of 22 (73 %) an interval of [52, 87] %: a few trials either way are inside it.
struct AccuracyInterval {
  double lower = 0, upper = 1;
};
// Throws std::invalid_argument unless 0 <= right <= n and n > 0.
AccuracyInterval wilson_interval(int right, int n, double z = 1.959963984540054);

// Whether two classifiers scored on the same trials differ: McNemar's test in its exact form
// (McNemar 1947; Dietterich 1998 for classifiers). Only the trials on which exactly one of them
// is right count: `only_first` of them the first got right, `only_second` the second. If both
// were equally good, each such trial would go either way with probability 1/2, so with
// b = only_first, c = only_second, n = b + c discordant trials and m = min(b, c) the two-sided
// p-value is
//
//   p = min(1, 2 sum_{i=0}^{m} C(n, i) / 2^n),
//
// and 1 when n = 0. Why not two accuracies side by side: the trials both classifiers get right
// or both get wrong say nothing about which is better, and on 22 trials a difference of two
// trials is as likely as not (b = 2, c = 4: p = 0.69). Throws std::invalid_argument on a
// negative count.
double mcnemar_exact_p(int only_first, int only_second);

}  // namespace dressguard::hmm
