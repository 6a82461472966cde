// --states, --band, --cov-floor, --max-iter and --tolerance: Baum-Welch's settings, shared by
// `dressguard train` and `dressguard build-model` (offline/hmm/hmm.h, TrainOptions).
#pragma once

#include <string>

#include "args.h"
#include "dgm.h"
#include "files.h"
#include "hmm.h"

namespace dressguard::cli {

inline constexpr const char* kHmmOptionNames[] = {"states", "band", "cov-floor", "max-iter", "tolerance"};

inline constexpr const char* kHmmHelp =
    "  --states N              states per HMM (default 10, the paper; the study's code used 5)\n"
    "  --band W                left-right width: state i may go to i..i+W (default 1)\n"
    "  --cov-floor V           minimum covariance eigenvalue in scaled feature units squared,\n"
    "                          at least 1e-9: below it a 2x2 determinant is lost to rounding\n"
    "                          (default 0.05)\n"
    "  --max-iter N            Baum-Welch iterations at most (default 100)\n"
    "  --tolerance T           stop when the gain per sample is below T nats (default 1e-6)\n";

// The options given, over TrainOptions' defaults; a UsageError names the one out of range.
inline hmm::TrainOptions hmm_options(const Args& args) {
  hmm::TrainOptions o;
  const long states = args.integer("states", o.n_states), band = args.integer("band", o.band);
  const long max_iter = args.integer("max-iter", o.max_iterations);
  if (states < 1 || states > model::kMaxStates)
    throw UsageError("--states must be 1.." + std::to_string(model::kMaxStates));
  if (band < 1 || band > model::kMaxStates) throw UsageError("--band must be 1.." + std::to_string(model::kMaxStates));
  if (max_iter < 1 || max_iter > 1000000) throw UsageError("--max-iter must be 1..1000000");
  o.n_states = static_cast<int>(states);
  o.band = static_cast<int>(band);
  o.max_iterations = static_cast<int>(max_iter);
  o.cov_floor = args.number("cov-floor", o.cov_floor);
  o.tolerance = args.number("tolerance", o.tolerance);
  if (!(o.cov_floor >= hmm::kMinCovFloor))
    throw UsageError("--cov-floor must be at least 1e-9 (scaled feature units squared): below it a state's "
                     "covariance determinant is lost to rounding and its log-likelihood is -inf");
  if (!(o.tolerance >= 0)) throw UsageError("--tolerance must be >= 0");
  return o;
}

}  // namespace dressguard::cli
