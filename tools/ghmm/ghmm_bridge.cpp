#include "ghmm_bridge.h"

#include <cmath>
#include <stdexcept>
#include <string>

extern "C" {
#include <ghmm/ghmm.h>
#include <ghmm/sequence.h>
#include <ghmm/sfoba.h>
#include <ghmm/smodel.h>
#include <ghmm/sreestimate.h>
}

namespace dressguard::ghmm_bridge {

namespace {
// Fills the derived fields GHMM keeps beside each covariance: inverse, determinant, Cholesky.
void set_emission(ghmm_c_emission& e, const model::GaussianEmission& g) {
  e.type = multinormal;
  e.dimension = 2;
  e.mean.vec[0] = g.mean[0];
  e.mean.vec[1] = g.mean[1];
  const double a = g.cov[0][0], b = g.cov[0][1], d = g.cov[1][1];
  e.variance.mat[0] = a;
  e.variance.mat[1] = b;
  e.variance.mat[2] = b;
  e.variance.mat[3] = d;
  e.det = a * d - b * b;
  e.sigmainv[0] = d / e.det;
  e.sigmainv[1] = -b / e.det;
  e.sigmainv[2] = -b / e.det;
  e.sigmainv[3] = a / e.det;
  const double l00 = std::sqrt(a), l10 = b / l00, l11 = std::sqrt(d - l10 * l10);
  e.sigmacd[0] = l00;
  e.sigmacd[1] = 0.0;
  e.sigmacd[2] = l10;
  e.sigmacd[3] = l11;
  e.fixed = 0;
}
}  // namespace

Model::Model(const model::ClassHmm& h) {
  const int n = h.n_states;
  m_ = ghmm_cmodel_calloc(n, GHMM_kContinuousHMM | GHMM_kMultivariate);
  if (!m_) throw std::runtime_error("ghmm_cmodel_calloc failed");
  m_->M = 1;
  m_->dim = 2;
  m_->cos = 1;
  m_->prior = -1;
  for (int i = 0; i < n; ++i) {
    int outs = 0, ins = 0;
    for (int j = 0; j < n; ++j) {
      outs += h.transition[i * n + j] > 0.0;
      ins += h.transition[j * n + i] > 0.0;
    }
    ghmm_cstate& s = m_->s[i];
    if (ghmm_cstate_alloc(&s, 1, ins, outs, 1)) throw std::runtime_error("ghmm_cstate_alloc failed");
    s.pi = h.initial[i];
    s.M = 1;
    s.c[0] = 1.0;
    s.fix = 0;
    int k = 0;
    for (int j = 0; j < n; ++j)
      if (h.transition[i * n + j] > 0.0) s.out_id[k] = j, s.out_a[0][k] = h.transition[i * n + j], ++k;
    k = 0;
    for (int j = 0; j < n; ++j)
      if (h.transition[j * n + i] > 0.0) s.in_id[k] = j, s.in_a[0][k] = h.transition[j * n + i], ++k;
    s.out_states = outs;
    s.in_states = ins;
    if (ghmm_c_emission_alloc(&s.e[0], 2)) throw std::runtime_error("ghmm_c_emission_alloc failed");
    // This GHMM build leaves the mean vector to the caller (ghmm_c_emission_free frees it).
    if (!s.e[0].mean.vec) s.e[0].mean.vec = static_cast<double*>(calloc(2, sizeof(double)));
    if (!s.e[0].variance.mat) s.e[0].variance.mat = static_cast<double*>(calloc(4, sizeof(double)));
    if (!s.e[0].sigmainv) s.e[0].sigmainv = static_cast<double*>(calloc(4, sizeof(double)));
    if (!s.e[0].sigmacd) s.e[0].sigmacd = static_cast<double*>(calloc(4, sizeof(double)));
    set_emission(s.e[0], h.emission[i]);
  }
  if (ghmm_cmodel_check(m_)) throw std::runtime_error("ghmm_cmodel_check refused the model");
}

Model::~Model() {
  if (m_) ghmm_cmodel_free(&m_);
}

model::ClassHmm Model::to_class_hmm() const {
  model::ClassHmm h;
  const int n = m_->N;
  h.n_states = n;
  h.initial.resize(n);
  h.transition.assign(n * n, 0.0);
  h.emission.resize(n);
  for (int i = 0; i < n; ++i) {
    const ghmm_cstate& s = m_->s[i];
    h.initial[i] = s.pi;
    for (int k = 0; k < s.out_states; ++k) h.transition[i * n + s.out_id[k]] = s.out_a[0][k];
    const ghmm_c_emission& e = s.e[0];
    h.emission[i].mean[0] = e.mean.vec[0];
    h.emission[i].mean[1] = e.mean.vec[1];
    h.emission[i].cov[0][0] = e.variance.mat[0];
    h.emission[i].cov[0][1] = e.variance.mat[1];
    h.emission[i].cov[1][0] = e.variance.mat[2];
    h.emission[i].cov[1][1] = e.variance.mat[3];
  }
  return h;
}

double Model::log_likelihood(const hmm::FeatureSequence& seq) const {
  double lp = 0.0;
  std::vector<double> o(seq.x);
  // The length argument counts doubles (2 per sample), as ghmm_cseq::seq_len does.
  if (ghmm_cmodel_logp(m_, o.data(), static_cast<int>(seq.x.size()), &lp) != 0)
    return -std::numeric_limits<double>::infinity();
  return lp;
}

Sequences::Sequences(const std::vector<hmm::FeatureSequence>& seqs) {
  s_ = ghmm_cseq_calloc(static_cast<long>(seqs.size()));
  if (!s_) throw std::runtime_error("ghmm_cseq_calloc failed");
  s_->dim = 2;
  for (size_t i = 0; i < seqs.size(); ++i) {
    const size_t nd = seqs[i].x.size();
    s_->seq[i] = static_cast<double*>(malloc(sizeof(double) * (nd ? nd : 1)));
    for (size_t k = 0; k < nd; ++k) s_->seq[i][k] = seqs[i].x[k];
    s_->seq_len[i] = static_cast<int>(nd);  // doubles, not samples (GHMM's convention)
    s_->seq_id[i] = static_cast<double>(i);
    s_->seq_w[i] = 1.0;
  }
  s_->total_w = static_cast<double>(seqs.size());
}

Sequences::~Sequences() {
  if (s_) ghmm_cseq_free(&s_);
}

TrainReport baum_welch(Model& m, const Sequences& s, double eps, int max_iter) {
  TrainReport r;
  ghmm_cmodel_baum_welch_context ctx;
  ctx.smo = m.raw();
  ctx.sqd = s.raw();
  ctx.logp = &r.reported_log_likelihood;
  ctx.eps = eps;
  ctx.max_iter = max_iter;
  r.rc = ghmm_cmodel_baum_welch(&ctx);
  return r;
}

}  // namespace dressguard::ghmm_bridge
