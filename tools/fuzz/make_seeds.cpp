// dg_fuzz_seeds DIR: writes the seed corpus of fuzz_dgm at test time: valid models of several
// shapes (1 class x 1 state, 2 x 5, 3 x 10, a general topology), each with mode byte 0 (as is)
// and 1 (size and CRC repaired by the harness), plus a truncated and a bit-flipped file.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "dgm.h"

using namespace dressguard::model;

namespace {
OutcomeModel make(int classes, int states, bool general) {
  OutcomeModel m;
  m.tool_version = "seed";
  m.created = "2026-01-01T00:00:00Z";
  m.source_dataset = "seed";
  m.training_summary = "seed";
  const char* names[] = {"good", "missed", "caught"};
  for (int c = 0; c < classes; ++c) {
    ClassHmm h;
    h.name = names[c];
    h.n_states = states;
    h.initial.assign(states, 0.0);
    h.initial[0] = 1.0;
    h.transition.assign(states * states, 0.0);
    for (int i = 0; i < states; ++i) {
      if (i == states - 1) {
        h.transition[i * states + i] = 1.0;
      } else if (general && i > 0) {
        h.transition[i * states + i - 1] = 0.25, h.transition[i * states + i] = 0.5, h.transition[i * states + i + 1] = 0.25;
      } else {
        h.transition[i * states + i] = 0.75, h.transition[i * states + i + 1] = 0.25;
      }
    }
    for (int j = 0; j < states; ++j) {
      GaussianEmission e;
      e.mean[0] = 0.5 * j - c;
      e.mean[1] = std::sin(j + c);
      e.cov[0][1] = e.cov[1][0] = 0.25;
      h.emission.push_back(e);
    }
    h.log_prior = -std::log(static_cast<double>(classes));
    m.classes.push_back(h);
  }
  double z = 0;
  for (auto& h : m.classes) z += std::exp(h.log_prior);
  for (auto& h : m.classes) h.log_prior -= std::log(z);
  return m;
}

void put(const std::filesystem::path& p, uint8_t mode, const std::vector<uint8_t>& b) {
  std::ofstream o(p, std::ios::binary);
  o.put(static_cast<char>(mode));
  o.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: dg_fuzz_seeds DIR\n");
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  int k = 0;
  for (auto [c, s, g] : {std::tuple{1, 1, false}, std::tuple{2, 5, false}, std::tuple{3, 10, false}, std::tuple{2, 4, true}}) {
    const auto b = encode_model(make(c, s, g));
    put(dir / ("valid" + std::to_string(k) + "_raw"), 0, b);
    put(dir / ("valid" + std::to_string(k) + "_fixed"), 1, b);
    auto t = b;
    t.resize(t.size() / 2);
    put(dir / ("truncated" + std::to_string(k)), 0, t);
    auto f = b;
    f[f.size() / 3] ^= 0x40;
    put(dir / ("flipped" + std::to_string(k)), 1, f);
    ++k;
  }
  std::printf("wrote %d seeds into %s\n", 4 * k, dir.c_str());
  return 0;
}
