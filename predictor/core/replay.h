// Replay: the predictor's own code run over a candump log, without a bus (the offline twin of the
// daemon). Timer ticks are simulated between frames at the daemon's tick period, so a silent gap
// in the log causes the same sensor-timeout stop the daemon would make; after the last frame the
// bus is taken to stay silent for one more deadline.
#pragma once

#include <string>
#include <vector>

#include "candump_log.h"
#include "predictor_core.h"

namespace dressguard::predictor {

struct ReplayTrial {
  uint16_t trial = 0;
  bool stopped = false;
  StopReason reason = StopReason::None;
  uint32_t stop_sample = 0;   // index in the trial of the deciding sample (logical time)
  double stop_time = 0;       // [s] stop_sample * sample period: logical time since the first sample
  double travel = 0;          // [m] commanded travel at stop_time (speed from TrialStart)
  double log_time = 0;        // [s] log timestamp of the frame that caused the stop, from the trial start
  double p[3] = {0, 0, 0};    // posteriors at the stop
  double f_motion = 0, f_vertical = 0;
  uint32_t samples = 0;       // last sample index + 1
  double max_p_caught = 0;    // over the trial, for margins
};

struct ReplayResult {
  std::vector<ReplayTrial> trials;
  std::vector<uint32_t> counters;  // by protocol::StatusCounter
  size_t frames = 0;
  int stop_frames = 0;             // stop frames the predictor transmitted (retries included)
};

// `model` null: a model that did not load (every trial is refused). tick_ns: the daemon's timer.
ReplayResult replay_frames(const model::OutcomeModel* model, const PredictorConfig& cfg,
                           const std::vector<protocol::LoggedFrame>& frames, int64_t tick_ns = 1'000'000);

}  // namespace dressguard::predictor
