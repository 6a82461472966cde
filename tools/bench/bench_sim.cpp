// bench_sim: how fast the cloth simulator runs on one core (issue 5's speed goals).
//
// For the reduced (~5k triangles) and the full (~20k) gown, with bending, self-collision and
// arm collision on, it reports the CPU time per second of simulated time for the pull alone
// and for the whole trial (grasp, settling, pull at the low arm), the whole trial's CPU and wall
// time over the same span, and the peak memory (each configuration runs in its own child process; its ru_maxrss holds the
// three scenes of the comparison below, so it bounds one simulation's from above). Baselines, measured in the same run on the same scene over the
// same window (0.5 s of settling): the solver with its constraints in mesh order (no colouring,
// scalar: the solver as it was before the colour order), and the colour-ordered solver with the
// scalar kernels (SceneOptions::simd off), so the ratios show what the colour order and the AVX2
// kernels each buy. The trial itself runs the default path (AVX2 where the CPU has it).
// Goals (issue 5): full >= 1x real time, whole trial < 15 s, reduced >= 8x real time, < 100 MB.
//
// Usage: bench_sim [--quick]   (--quick: the reduced gown only and a 0.2 m pull)
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstring>
#include <string>

#include "gown_scene.h"
#include "model.h"
#include "trial.h"

using namespace dressguard;
using namespace dressguard::sim;

namespace {

struct Figures {
  int vertices = 0, triangles = 0;
  double load_s = 0;
  double settle_wall = 0, settle_sim = 0, pull_wall = 0, pull_sim = 0;
  double base_wall = 0, scalar_wall = 0, fast_wall = 0, window_sim = 0;  // mesh order, scalar, default path
  bool avx2 = false;
  double trial_cpu = 0;   // CPU seconds of the whole trial
  double trial_wall = 0;  // wall seconds of the same span as trial_cpu (one thread: wall >= CPU)
  char label[16] = {};
  double travel = 0;
};

double cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// 0.5 s of settling of a scene, CPU seconds.
double settle_window(const Scene& scene) {
  const GownModel m = make_model(scene.data(), ClothParams{}, FrictionScheme::Improved, true, 0);
  GownState s = make_state(m);
  const double c0 = cpu_now();
  for (int k = 0; k < 150; ++k) step(m, s, {}, {}, {});
  return cpu_now() - c0;
}

Figures run(GownResolution res, double max_travel) {
  Figures f;
  const auto t0 = std::chrono::steady_clock::now();
  gown::GownOptions go;
  go.target_triangles = target_triangles(res);
  const gown::GownMesh mesh = gown::load_gown(go);
  SceneOptions opt;
  opt.self_distance = res == GownResolution::Full ? 0.008 : 0.012;
  const Scene scene = make_scene(mesh, gown::PaperScene{}, opt);
  SceneOptions naive = opt;
  naive.colour_order = false;
  const Scene baseline = make_scene(mesh, gown::PaperScene{}, naive);
  SceneOptions scalar_opt = opt;
  scalar_opt.simd = false;
  const Scene scalar = make_scene(mesh, gown::PaperScene{}, scalar_opt);
  f.load_s = seconds_since(t0);
  f.vertices = scene.vertex_count();
  f.triangles = scene.triangle_count();
  f.avx2 = make_model(scene.data(), ClothParams{}, FrictionScheme::Improved, true, 0).path == KernelPath::Avx2;
  f.base_wall = settle_window(baseline);
  f.scalar_wall = settle_window(scalar);
  f.fast_wall = settle_window(scene);
  f.window_sim = 0.5;
  // The low arm: the hand misses the sleeve and the pull runs its full travel.
  TrialSpec spec;
  spec.height = ArmHeight::Low;
  spec.max_travel = max_travel;
  TrialSpec settle_only = spec;
  settle_only.max_travel = 1e-6;
  double c0 = cpu_now();
  const TrialResult settled = simulate_trial(scene, ClothParams{}, settle_only);
  const double settle_cpu = cpu_now() - c0;
  // CPU and wall time over the same span: simulate_trial whole, its make_model and make_state
  // included (TrialResult's wall_settle + wall_pull leave them and the pull's end out, so that
  // sum could fall below the CPU time on a free core).
  c0 = cpu_now();
  const auto w0 = std::chrono::steady_clock::now();
  const TrialResult r = simulate_trial(scene, ClothParams{}, spec);
  f.trial_cpu = cpu_now() - c0;
  f.trial_wall = seconds_since(w0);
  // CPU seconds: the machine is shared, so wall time measures the other jobs as much as ours;
  // on a free core the two agree.
  f.settle_wall = settle_cpu;
  f.settle_sim = settled.settle_time;  // until the gown is at rest (TrialSpec::settle_speed)
  f.pull_wall = f.trial_cpu - settle_cpu;
  f.pull_sim = r.seq.samples.empty() ? 0 : r.seq.samples.back().t;
  std::snprintf(f.label, sizeof f.label, "%s", std::string(label_name(r)).c_str());
  f.travel = r.travel;
  return f;
}

// Runs one configuration in a child process; returns its figures and its peak RSS [MB].
bool run_child(GownResolution res, double max_travel, Figures* f, double* peak_mb) {
  int fd[2];
  if (pipe(fd) != 0) return false;
  const pid_t pid = fork();
  if (pid < 0) return false;
  if (pid == 0) {
    close(fd[0]);
    const Figures r = run(res, max_travel);
    const ssize_t n = write(fd[1], &r, sizeof r);
    _exit(n == static_cast<ssize_t>(sizeof r) ? 0 : 1);
  }
  close(fd[1]);
  const ssize_t n = read(fd[0], f, sizeof *f);
  close(fd[0]);
  int status = 0;
  struct rusage ru {};
  wait4(pid, &status, 0, &ru);
  *peak_mb = ru.ru_maxrss / 1024.0;
  return n == static_cast<ssize_t>(sizeof *f) && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && !std::strcmp(argv[1], "--quick");
  std::printf("bench_sim: one core, 300 Hz x %d substeps, bending + self-collision + arm collision on\n",
              SceneOptions{}.substeps);
  std::printf("times are CPU seconds of this process (one core); the trial's wall time is shown too\n");
  std::printf("window: CPU s per simulated s over 0.5 s of settling, for the mesh-order scalar solver, the\n"
              "colour-ordered scalar kernels and the default path, and the default path's speedup over each\n");
  std::printf("%-8s %6s %6s | %-24s | %-24s | %-18s | %-41s | %9s | %s\n", "gown", "verts", "tris", "pull: s per sim s (x RT)",
              "trial: s per sim s (x RT)", "trial CPU (wall) s", "window: mesh / scalar / default, speedups",
              "MB, 3 scn", "outcome");
  for (GownResolution res : {GownResolution::Reduced, GownResolution::Full}) {
    if (quick && res == GownResolution::Full) continue;
    Figures f;
    double mb = 0;
    if (!run_child(res, quick ? 0.2 : 0.85, &f, &mb)) {
      std::fprintf(stderr, "bench_sim: the child simulation failed\n");
      return 1;
    }
    const double pull = f.pull_wall / f.pull_sim, trial = (f.settle_wall + f.pull_wall) / (f.settle_sim + f.pull_sim);
    std::printf("%-8s %6d %6d | %8.3f (%6.2fx RT)      | %8.3f (%6.2fx RT)      | %7.1f (%7.1f)  | %6.3f / %6.3f / %6.3f %-6s %5.2fx %5.2fx | %9.1f | %s at %.3f m (load %.1f s)\n",
                res == GownResolution::Full ? "full" : "reduced", f.vertices, f.triangles, pull, 1 / pull, trial, 1 / trial,
                f.trial_cpu, f.trial_wall, f.base_wall / f.window_sim, f.scalar_wall / f.window_sim,
                f.fast_wall / f.window_sim, f.avx2 ? "(avx2)" : "(scal)", f.base_wall / f.fast_wall,
                f.scalar_wall / f.fast_wall, mb, f.label, f.travel, f.load_s);
    std::fflush(stdout);
  }
  return 0;
}
