#include "report.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace dressguard::hmm {

namespace {
template <class It, class F>
std::string json_array(It b, It e, F f) {
  std::string o = "[";
  for (It i = b; i != e; ++i) o += (i == b ? "" : ", ") + f(*i);
  return o + "]";
}
}  // namespace

std::string model_json(const model::OutcomeModel& m) {
  std::ostringstream o;
  o << "{\"format_version\": " << model::format_version_of(m) << ", \"tool_version\": " << json_string(m.tool_version)
    << ", \"created\": " << json_string(m.created) << ", \"source_dataset\": " << json_string(m.source_dataset)
    << ", \"training_summary\": " << json_string(m.training_summary) << ", \"features\": [";
  static const char* kAxis[] = {"f_motion", "f_lateral", "f_vertical", "none"};
  for (int k = 0; k < model::kFeatures; ++k)
    o << (k ? ", " : "") << "{\"axis\": " << json_string(kAxis[m.features.axis[k]]) << ", \"sign\": "
      << json_number(m.features.sign[k]) << ", \"offset\": " << json_number(m.features.offset[k])
      << ", \"scale\": " << json_number(m.features.scale[k]) << "}";
  // The training conditions (format version 3): null where the model does not know them.
  const auto known = [](double v) { return v != 0.0 ? json_number(v) : std::string("null"); };
  o << "], \"stop_threshold\": " << json_number(m.stop_threshold) << ", \"stop_consecutive\": " << m.stop_consecutive
    << ", \"sample_period_s\": " << known(m.sample_period_s) << ", \"speed_min_m_s\": " << known(m.speed_min_m_s)
    << ", \"speed_max_m_s\": " << known(m.speed_max_m_s) << ", \"classes\": [";
  auto num = [](double v) { return json_number(v); };
  for (size_t c = 0; c < m.classes.size(); ++c) {
    const auto& h = m.classes[c];
    o << (c ? ", " : "") << "{\"name\": " << json_string(h.name) << ", \"states\": " << h.n_states
      << ", \"prior\": " << json_number(std::exp(h.log_prior)) << ", \"initial\": "
      << json_array(h.initial.begin(), h.initial.end(), num) << ", \"transition\": [";
    for (int i = 0; i < h.n_states; ++i)
      o << (i ? ", " : "")
        << json_array(h.transition.begin() + i * h.n_states, h.transition.begin() + (i + 1) * h.n_states, num);
    o << "], \"emissions\": [";
    for (int j = 0; j < h.n_states; ++j) {
      const auto& e = h.emission[j];
      o << (j ? ", " : "") << "{\"mean\": [" << num(e.mean[0]) << ", " << num(e.mean[1]) << "], \"cov\": [["
        << num(e.cov[0][0]) << ", " << num(e.cov[0][1]) << "], [" << num(e.cov[1][0]) << ", " << num(e.cov[1][1])
        << "]]}";
    }
    o << "]}";
  }
  o << "]}";
  return o.str();
}

std::string confusion_text(const Evaluation& ev) {
  std::ostringstream o;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%-14s", "truth \\ pred");
  o << buf;
  for (const auto& c : ev.classes) {
    std::snprintf(buf, sizeof buf, " %8s", c.c_str());
    o << buf;
  }
  o << "\n";
  for (size_t r = 0; r < ev.classes.size(); ++r) {
    std::snprintf(buf, sizeof buf, "%-14s", ev.classes[r].c_str());
    o << buf;
    for (size_t c = 0; c < ev.classes.size(); ++c) {
      std::snprintf(buf, sizeof buf, " %8d", ev.confusion[r][c]);
      o << buf;
    }
    o << "\n";
  }
  return o.str();
}

std::string accuracy_text(const Evaluation& ev) {
  if (ev.total == 0) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f", ev.accuracy());
  return buf;
}

std::string evaluation_json(const Evaluation& ev) {
  std::ostringstream o;
  o << "{\"classes\": " << json_array(ev.classes.begin(), ev.classes.end(), [](const std::string& s) { return json_string(s); })
    << ", \"confusion\": [";
  for (size_t r = 0; r < ev.confusion.size(); ++r)
    o << (r ? ", " : "")
      << json_array(ev.confusion[r].begin(), ev.confusion[r].end(), [](int v) { return std::to_string(v); });
  o << "], \"correct\": " << ev.correct << ", \"total\": " << ev.total << ", \"skipped\": " << ev.skipped
    << ", \"accuracy\": " << (ev.total > 0 ? json_number(ev.accuracy()) : "null");
  if (ev.total > 0) {  // how sure that accuracy is on this many trials (hmm.h, wilson_interval)
    const AccuracyInterval iv = wilson_interval(ev.correct, ev.total);
    o << ", \"accuracy_interval\": [" << json_number(iv.lower) << ", " << json_number(iv.upper) << "]";
  }
  o << "}";
  return o.str();
}

}  // namespace dressguard::hmm
