// Threads and MPI ranks for batches of simulations, see runner.h.
#include "runner.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#ifdef DRESSGUARD_HAVE_MPI
#include <mpi.h>
#endif

namespace dressguard::calib {

bool Comm::built_with_mpi() {
#ifdef DRESSGUARD_HAVE_MPI
  return true;
#else
  return false;
#endif
}

Comm& Comm::world() {
  static Comm comm = [] {
    Comm c;
#ifdef DRESSGUARD_HAVE_MPI
    const bool launched = std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK");
    if (launched) {
      int initialised = 0;
      MPI_Initialized(&initialised);
      if (!initialised) {
        // Funneled: run_batch's threads simulate, and only the thread that called it talks MPI
        // (the collectives come after its workers have joined); MPI_Init would promise one
        // thread in the whole process (MPI_THREAD_SINGLE).
        int provided = MPI_THREAD_SINGLE;
        MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
        if (provided < MPI_THREAD_FUNNELED)
          std::fprintf(stderr, "dressguard: warning: this MPI library gives no MPI_THREAD_FUNNELED (level %d); "
                               "run with --threads 1 under mpirun\n", provided);
        std::atexit([] {
          int finalised = 0;
          MPI_Finalized(&finalised);
          if (!finalised) MPI_Finalize();
        });
      }
      MPI_Comm_rank(MPI_COMM_WORLD, &c.rank_);
      MPI_Comm_size(MPI_COMM_WORLD, &c.size_);
    }
#endif
    return c;
  }();
  return comm;
}

void Comm::allreduce_sum(std::vector<double>& v) const {
  if (size_ == 1) return;
#ifdef DRESSGUARD_HAVE_MPI
  MPI_Allreduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
#endif
}

void Comm::barrier() const {
  if (size_ == 1) return;
#ifdef DRESSGUARD_HAVE_MPI
  MPI_Barrier(MPI_COMM_WORLD);
#endif
}

void Comm::broadcast(std::string& s) const {
  if (size_ == 1) return;
#ifdef DRESSGUARD_HAVE_MPI
  long n = static_cast<long>(s.size());
  MPI_Bcast(&n, 1, MPI_LONG, 0, MPI_COMM_WORLD);
  s.resize(static_cast<std::size_t>(n));
  MPI_Bcast(s.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD);
#endif
}

void Comm::on_root(const std::function<void()>& work) const {
  if (size_ == 1) {
    work();
    return;
  }
  std::exception_ptr error;
  std::string failed;  // empty: rank 0's work is done
  if (is_root()) {
    try {
      work();
    } catch (const std::exception& e) {
      error = std::current_exception();
      failed = *e.what() ? e.what() : "unknown error";
    } catch (...) {
      error = std::current_exception();
      failed = "unknown error";
    }
  }
  broadcast(failed);
  if (error) std::rethrow_exception(error);
  if (!failed.empty()) throw std::runtime_error("rank 0: " + failed);
}

std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t key) {
  auto splitmix = [](std::uint64_t x) {  // Steele, Lea, Flood 2014
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  };
  return splitmix(splitmix(seed) ^ (key * 0xD1B54A32D192ED03ull + 1));
}

int thread_count(int requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? static_cast<int>(hw) : 1;
}

std::vector<double> run_batch(int n, int block, int threads, const Comm& comm,
                              const std::function<void(int, double*)>& task) {
  std::vector<double> out(static_cast<std::size_t>(n) * block, 0.0);
  // This rank's share: indices r, r + R, r + 2R, ...
  std::vector<int> mine;
  for (int i = comm.rank(); i < n; i += comm.size()) mine.push_back(i);
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto worker = [&] {
    for (;;) {
      const std::size_t k = next.fetch_add(1);
      if (k >= mine.size()) return;
      {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (error) return;
      }
      try {
        task(mine[k], out.data() + static_cast<std::size_t>(mine[k]) * block);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  const int t = std::max(1, std::min<int>(threads, static_cast<int>(mine.size())));
  if (t == 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    for (int k = 0; k < t; ++k) pool.emplace_back(worker);
    for (auto& th : pool) th.join();
  }
  if (error) {
#ifdef DRESSGUARD_HAVE_MPI
    if (comm.size() > 1) {
      try {
        std::rethrow_exception(error);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "dressguard: rank %d: %s\n", comm.rank(), e.what());
      }
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
#endif
    std::rethrow_exception(error);
  }
  comm.allreduce_sum(out);
  return out;
}

}  // namespace dressguard::calib
