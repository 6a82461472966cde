// Runs a calibration and a synthesis with the analytic stand-in simulator and prints a digest of
// the results (exact hex floats, labels, file contents' sizes). tests/calib/mpi_check.cmake runs
// it once as one process and once under `mpirun -n 2` and requires identical digests: the MPI
// spreading of generations and trials must not change a single bit.
//
// `calib_mpi_check --checkpoint-fails WORKDIR`: a calibration whose checkpoint cannot be written
// after its first generation (its folder turns into a file while the generation is simulated).
// Every rank must end with the error, printed as "rank R: ..." with exit 3
// (mpi_root_failure.cmake); rank 0 alone used to, and the others waited for it for good.
//
// `calib_mpi_check --synthesis-fails WORKDIR`: a synthesis whose labels.csv, which rank 0 alone
// writes once every rank's trials are in, cannot be written (a folder holds its place). Every
// rank must end with the error too; rank 0 alone used to, the others waiting at the barrier
// after it (session 90's review).
//
// `calib_mpi_check --ranks-disagree WORKDIR`: a calibration whose ranks compute different
// generations (here each rank gets another seed, as nodes of different CPU kinds could round
// differently): every rank must end after the first generation, saying the states differ.
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <sstream>

#include "calibration.h"
#include "fake_sim.h"
#include "files.h"
#include "synthesis.h"

using namespace dressguard;
using namespace dressguard::calib;

namespace {

// Runs one of the failure modes: each rank prints "rank R: " and the error it ended with (exit 3),
// or that it went on, `unnoticed` (exit 0).
int each_rank_ends(const Comm& comm, const char* unnoticed, const std::function<void()>& run) {
  try {
    run();
  } catch (const std::exception& e) {
    std::printf("rank %d: %s\n", comm.rank(), e.what());
    std::fflush(stdout);
    return 3;
  }
  std::printf("rank %d: %s\n", comm.rank(), unnoticed);
  return 0;
}

// The checkpoint of a calibration on `comm` becomes unwritable during its first generation.
int checkpoint_fails(const std::filesystem::path& dir, const std::vector<HapticSequence>& inputs,
                     const ParameterSpace& space, const Comm& comm) {
  namespace fs = std::filesystem;
  if (comm.is_root()) fs::remove_all(dir / "ck");
  comm.barrier();
  CalibrationOptions o;
  o.generations = 3;
  o.population = 6;
  o.threads = 1;
  o.checkpoint = dir / "ck" / "run.ckpt";
  o.candidate_progress = [&](const CandidateProgress& c) {  // rank 0 only
    if (c.generation != 1 || c.done != 1) return;
    fs::remove_all(dir / "ck");
    write_file_atomic(dir / "ck", "in the checkpoint's folder's place\n");
  };
  return each_rank_ends(comm, "calibrated, the checkpoint's failure unnoticed",
                        [&] { calibrate(inputs, space, testing::fake_simulate, o, comm); });
}

// The last file of a synthesis on `comm`, written by rank 0 alone, cannot be written.
int synthesis_fails(const std::filesystem::path& dir, const Comm& comm) {
  namespace fs = std::filesystem;
  if (comm.is_root()) {
    fs::remove_all(dir / "sf");
    fs::create_directories(dir / "sf" / "labels.csv");
  }
  comm.barrier();
  Calibration cal;
  cal.cloth = ClothValues{0.4, 0.6, 0.3, 1.1, 0.5};
  SynthesisOptions so;
  so.per_height = 2;
  so.threads = 1;
  return each_rank_ends(comm, "synthesized, labels.csv's failure unnoticed",
                        [&] { synthesize(cal, testing::fake_simulate, so, dir / "sf", comm); });
}

// Rank r searches with seed 5 + r: their states part at the first tell().
int ranks_disagree(const std::vector<HapticSequence>& inputs, const ParameterSpace& space, const Comm& comm) {
  CalibrationOptions o;
  o.generations = 3;
  o.population = 6;
  o.threads = 1;
  o.seed = 5 + static_cast<std::uint64_t>(comm.rank());
  return each_rank_ends(comm, "calibrated, the ranks' disagreement unnoticed",
                        [&] { calibrate(inputs, space, testing::fake_simulate, o, comm); });
}

}  // namespace

int main(int argc, char** argv) {
  const bool fails = argc == 3 && std::strcmp(argv[1], "--checkpoint-fails") == 0;
  const bool synthesis = argc == 3 && std::strcmp(argv[1], "--synthesis-fails") == 0;
  const bool disagree = argc == 3 && std::strcmp(argv[1], "--ranks-disagree") == 0;
  if (argc != 2 && !fails && !synthesis && !disagree) {
    std::fprintf(stderr, "usage: calib_mpi_check [--checkpoint-fails | --synthesis-fails | --ranks-disagree] WORKDIR\n");
    return 2;
  }
  const std::filesystem::path dir = argv[argc - 1];
  const Comm& comm = Comm::world();
  if (synthesis) return synthesis_fails(dir, comm);
  std::vector<HapticSequence> inputs;
  for (ArmHeight h : {ArmHeight::High, ArmHeight::Middle, ArmHeight::Low}) {
    HapticSequence s;
    s.id = std::string("m-") + std::string(arm_height_name(h));
    s.height = h;
    TrialRequest r;
    r.height = h;
    r.arm_offset = h == ArmHeight::High ? 0.01 : -0.02;
    s.samples = testing::fake_simulate(ClothValues{0.4, 0.6, 0.3, 1.1, 0.5}, r).samples;
    inputs.push_back(s);
  }
  ParameterSpace space;
  space.bounds = default_bounds();
  for (const auto& s : inputs) space.offset_heights.push_back(s.height);
  if (fails) return checkpoint_fails(dir, inputs, space, comm);
  if (disagree) return ranks_disagree(inputs, space, comm);
  CalibrationOptions o;
  o.generations = 10;
  o.population = 12;
  o.seed = 5;
  o.threads = 2;
  const CalibrationResult r = calibrate(inputs, space, testing::fake_simulate, o, comm);
  // Pruned (calibrate --prune): a cut candidate known whole goes on from its cut trials
  // (SimulatedTrial::rest), which only the rank that simulated it holds.
  CalibrationOptions op = o;
  op.prune = 1.0;
  const CalibrationResult rp = calibrate(inputs, space, testing::fake_simulate, op, comm);
  if (rp.resimulated == 0) {
    std::fprintf(stderr, "calib_mpi_check: the pruned calibration had no cut candidate to know whole (%ld cut): "
                 "it checks nothing of SimulatedTrial::rest\n", rp.pruned);
    return 1;
  }
  Calibration cal;
  cal.cloth = r.cloth;
  cal.offsets = r.offsets;
  SynthesisOptions so;
  so.per_height = 8;
  so.threads = 2;
  const SynthesisSummary s = synthesize(cal, testing::fake_simulate, so, dir / "synth", comm);
  if (comm.is_root()) {
    std::printf("ranks %d\n", comm.size());  // not part of the compared digest (first line)
    std::printf("objective %a evaluations %ld\n", r.objective, r.evaluations);
    for (long i = 0; i < r.best_unit.size(); ++i) std::printf("x%ld %a\n", i, r.best_unit[i]);
    std::printf("pruned objective %a cut %ld known whole %ld\n", rp.objective, rp.pruned, rp.resimulated);
    for (long i = 0; i < rp.best_unit.size(); ++i) std::printf("pruned x%ld %a\n", i, rp.best_unit[i]);
    std::printf("labels %d %d %d\n", s.per_label[0], s.per_label[1], s.per_label[2]);
    const Dataset ds = load_dataset(dir / "synth");
    std::size_t bytes = 0;
    for (const auto& t : ds.trials) bytes += read_file(dir / "synth" / (t.id + ".csv")).size();
    std::printf("trials %zu bytes %zu manifest %zu\n", ds.trials.size(), bytes, read_file(dir / "synth" / "manifest.csv").size());
  }
  return 0;
}
