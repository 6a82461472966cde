// Spreading independent simulations over threads and MPI ranks with results that do not depend
// on how they are spread.
//
// A batch is N tasks with indices 0..N-1, each producing a fixed-size block of doubles from its
// index alone (the simulator is deterministic and thread-safe). Rank r of R runs the tasks with
// index % R == r on `threads` threads (a shared atomic counter hands out indices); each result
// lands in its own slot, so the order in which threads finish changes nothing. Over MPI the
// blocks are combined with one MPI_Allreduce(SUM) of a zero-initialised buffer: every slot has
// exactly one non-zero contributor, x + 0 = x exactly, so every rank ends with the same bits as a
// single process, whatever R and the thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace dressguard::calib {

// The process group. Without MPI (or when not started by mpirun) a single process.
class Comm {
 public:
  // Initialises MPI once if the binary was built with it and launched by mpirun/srun (detected
  // from the launcher's environment: OMPI_COMM_WORLD_SIZE, PMI_SIZE, PMIX_RANK); else size 1.
  static Comm& world();
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }
  // Element-wise sum over all ranks, result on every rank (no-op for one process).
  void allreduce_sum(std::vector<double>& v) const;
  void barrier() const;
  // Rank 0's string on every rank.
  void broadcast(std::string& s) const;
  // Runs `work` on rank 0 alone (a file only it writes or reads) and tells every rank how it
  // went. A rank 0 that ended on its own would leave the others waiting in their next
  // collective (barrier, allreduce, broadcast) until the job's time limit; so an exception on
  // rank 0 is rethrown there as it was, and on every other rank as std::runtime_error("rank 0:
  // " + its message), and every rank ends. One process: work() alone. A collective itself.
  void on_root(const std::function<void()>& work) const;
  // True when compiled with MPI support (DRESSGUARD_WITH_MPI).
  static bool built_with_mpi();

 private:
  Comm() = default;
  int rank_ = 0, size_ = 1;
};

// A seed for the stream identified by (seed, key): SplitMix64 of both, so that neighbouring keys
// (trial indices, heights) get unrelated streams. Used for every per-trial random choice, which
// is what makes results independent of the thread and rank count.
std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t key);

// Number of threads to use: `requested` if > 0, else the hardware's concurrency (at least 1).
int thread_count(int requested);

// Runs tasks [0, n) as described above; task(i, out) writes `block` doubles to out[0..block).
// Returns the n*block results, identical on every rank. An exception in a task is rethrown
// (the first one, on the rank that hit it; with MPI the other ranks then abort via MPI).
std::vector<double> run_batch(int n, int block, int threads, const Comm& comm,
                              const std::function<void(int, double*)>& task);

}  // namespace dressguard::calib
