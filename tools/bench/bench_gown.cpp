// Gown benchmark: reading the measured gown (or generating the parametric one) is the baseline;
// the reduction 20k -> 5k triangles is measured against it in the same run, on one thread.
// Goal (issue 5): the reduction under 2 s on one core. Prints the shape error of the result.
//
// usage: bench_gown [repetitions (default 3)]
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "gown.h"

using namespace dressguard::gown;

namespace {

template <class F>
double best_seconds(int reps, F&& f) {
  double best = 1e30;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

void run(const char* name, const GownMesh& full, double baseline, int reps) {
  GownMesh red;
  const double t = best_seconds(reps, [&] { red = reduce_gown(full, 5000); });
  std::printf("%-11s %6zu -> %5zu triangles: reduce %.3f s (%.1fx the baseline), goal < 2 s: %s\n", name,
              full.triangles.size(), red.triangles.size(), t, t / baseline, t < 2.0 ? "met" : "MISSED");
  std::printf("            area %.4f -> %.4f m^2, max distance reduced->full %.2f mm, full->reduced %.2f mm, "
              "smallest angle %.1f -> %.1f deg\n",
              total_area(full), total_area(red), 1000 * max_distance_to_surface(red, full),
              1000 * max_distance_to_surface(full, red), min_triangle_angle(full) * 180 / M_PI,
              min_triangle_angle(red) * 180 / M_PI);
}

}  // namespace

int main(int argc, char** argv) {
  const int reps = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  std::printf("bench_gown: best of %d, one thread\n", reps);
  if (!measured_gown_path().empty()) {
    GownMesh full;
    const double t_read = best_seconds(reps, [&] { full = load_gown({}); });
    std::printf("baseline: read + place the measured gown %.3f s\n", t_read);
    run("measured", full, t_read, reps);
  } else {
    std::printf("measured gown absent (shared/data): parametric only\n");
  }
  GownMesh par;
  const double t_gen = best_seconds(reps, [&] { par = make_parametric_gown(); });
  std::printf("baseline: generate the parametric gown %.3f s\n", t_gen);
  run("parametric", par, t_gen, reps);
  return 0;
}
