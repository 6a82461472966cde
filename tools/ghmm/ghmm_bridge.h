// A thin C++ bridge to GHMM's C API (libghmm-dev), the library the paper trained with: our
// ClassHmm <-> ghmm_cmodel with one multinormal component per state, and our sequences <->
// ghmm_cseq. Used by the comparison tool (tools/ghmm) and the training benchmark; nothing in the
// product links it.
//
// GHMM behaviours this bridge accounts for (measured against this Debian build, see README.md):
//  - a 2-D sequence is one interleaved array (x0 y0 x1 y1 ...) and ghmm_cseq::seq_len counts
//    doubles, not samples (so T samples are declared as 2T);
//  - its multinormal covariance re-estimate is about the previous mean, not the new one;
//  - every covariance entry with magnitude below 1e-4 is set to +-1e-4 (GHMM_EPS_U);
//  - Baum-Welch stops at a relative gain of at most 1e-4 and reports the log-likelihood of the
//    model before its last update.
#pragma once

#include <memory>
#include <vector>

#include "dgm.h"
#include "hmm.h"

struct ghmm_cmodel;
struct ghmm_cseq;

namespace dressguard::ghmm_bridge {

class Model {
 public:
  explicit Model(const model::ClassHmm& h);
  ~Model();
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;
  model::ClassHmm to_class_hmm() const;  // the current parameters back in our form
  // log p(seq) by ghmm_cmodel_logp (its length argument counts doubles too: 2T).
  double log_likelihood(const hmm::FeatureSequence& seq) const;
  ghmm_cmodel* raw() const { return m_; }

 private:
  ghmm_cmodel* m_ = nullptr;
};

class Sequences {
 public:
  explicit Sequences(const std::vector<hmm::FeatureSequence>& seqs);
  ~Sequences();
  Sequences(const Sequences&) = delete;
  Sequences& operator=(const Sequences&) = delete;
  ghmm_cseq* raw() const { return s_; }

 private:
  ghmm_cseq* s_ = nullptr;
};

// ghmm_cmodel_baum_welch with the given stop rule; returns GHMM's reported log-likelihood (of
// the model before its last update) and the return code.
struct TrainReport {
  int rc = 0;
  double reported_log_likelihood = 0.0;
};
TrainReport baum_welch(Model& m, const Sequences& s, double eps, int max_iter);

}  // namespace dressguard::ghmm_bridge
