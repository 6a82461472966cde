// bench_sim_kernels: what sets the pace of the cloth solver's AVX2 kernels?
//
// offline/sim/README.md ("What the goals would take") counts vertex writes per substep and puts
// the speed goals at one write per cycle. This measures, per kernel and gown, the two things that
// could be the limit, each against the tree's kernel over its whole constraint stream in the
// same run (the baseline):
//
// 1. Memory. A substep streams 1.4 MB (reduced gown) to 5.8 MB (full) of constraint blocks
//    (model.h: 192, 320 and 352 bytes per block of 4), more than a core's L2. If that stream
//    set the pace, a block would cost less when the same work runs over a slice of the stream
//    small enough to stay in L1 (16 KB) or L2 (256 KB), repeated. Printed: ns per block over the
//    whole stream and over each slice, and their ratio.
// 2. Moving vertices into lanes and back. Stretch and shear transpose 2 and 3 vertices per lane
//    (lanes_avx2.h: load4, store4) around their arithmetic. The same loads and stores with one
//    add each and no constraint arithmetic give the floor that the AoS layout (32-byte vertices)
//    sets, however fast the arithmetic were. Bending needs no transposes (one register per
//    vertex); its floor is its 16 vertices' loads and stores alone.
//
// Then the floor of a whole substep (every kernel moving its vertices only),
// per simulated second at 300 Hz x 20 substeps, against the goals' budgets for everything:
// 0.125 s per simulated s for the reduced gown (8x real time) and 1 s for the full one (1x).
//
// The cloth and start positions are sim_kernel_setup.h's. Each timing is the best of --reps
// rounds of 600 substeps' worth of blocks, a kernel's four timings alternating. Free blocks only
// (model.h, BlockSpan): the careful ones are 0.3-1.6 % of a stream. Run it pinned to one core:
// taskset -c 1 bench_sim_kernels.
//
// Usage: bench_sim_kernels [--reps N]   (default 5; about 25 s)
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <utility>
#include <vector>

#include "kernels.h"
#include "lanes_avx2.h"
#include "model.h"
#include "sim_kernel_setup.h"
#include "trial.h"

using namespace dressguard::sim;

#if defined(__x86_64__)
namespace {

using namespace dressguard::sim::lanes;

// The stretch kernel's loads and stores (lanes_avx2.h) with one add per vertex in place of the
// constraint: what moving 2 x 4 vertices through the lanes costs.
DG_AVX2 void stretch_move(const StretchBlock* b, const StretchBlock* e, V3* x) {
  for (const StretchBlock* p = b; p < e; ++p) {
    Lanes3 xi = load4(x, p->i), xj = load4(x, p->j);
    const __m256d r = _mm256_load_pd(p->rest);  // a block field, so the block is read too
    xi.x = add(xi.x, r);
    xj.x = sub(xj.x, r);
    store4(x, p->i, xi, 4);
    store4(x, p->j, xj, 4);
  }
}
// The same for shear's 3 x 4 vertices.
DG_AVX2 void shear_move(const ShearBlock* b, const ShearBlock* e, V3* x) {
  for (const ShearBlock* p = b; p < e; ++p) {
    Lanes3 x0 = load4(x, p->v[0]), x1 = load4(x, p->v[1]), x2 = load4(x, p->v[2]);
    const __m256d r = _mm256_load_pd(p->a);
    x0.x = add(x0.x, r);
    x1.x = sub(x1.x, r);
    x2.x = add(x2.x, r);
    store4(x, p->v[0], x0, 4);
    store4(x, p->v[1], x1, 4);
    store4(x, p->v[2], x2, 4);
  }
}

// Bending's 4 x 4 vertices, one register each, in bend_free_avx2's order: a stencil's 4 loads,
// then its 4 stores.
DG_AVX2 void bend_move(const BendBlock* b, const BendBlock* e, V3* x) {
  for (const BendBlock* p = b; p < e; ++p)
    for (int l = 0; l < 4; ++l) {
      V3 &v0 = x[p->v[0][l]], &v1 = x[p->v[1][l]], &v2 = x[p->v[2][l]], &v3 = x[p->v[3][l]];
      const __m256d x0 = _mm256_load_pd(&v0.x), x1 = _mm256_load_pd(&v1.x);
      const __m256d x2 = _mm256_load_pd(&v2.x), x3 = _mm256_load_pd(&v3.x);
      const __m256d r = _mm256_broadcast_sd(&p->neg_inv_denom[l]);
      _mm256_store_pd(&v0.x, add(x0, r));
      _mm256_store_pd(&v1.x, sub(x1, r));
      _mm256_store_pd(&v2.x, add(x2, r));
      _mm256_store_pd(&v3.x, sub(x3, r));
    }
}

// The free block ranges of each colour group, cut to the first `budget` bytes of blocks (0: all).
template <class Block>
std::vector<std::pair<const Block*, const Block*>> ranges(const std::vector<Block>& blocks,
                                                        const std::vector<BlockSpan>& spans, std::size_t budget) {
  std::vector<std::pair<const Block*, const Block*>> out;
  std::size_t left = budget == 0 ? blocks.size() : budget / sizeof(Block);
  for (const BlockSpan& sp : spans) {
    const std::size_t n = std::min<std::size_t>(sp.simd_end - sp.begin, left);
    if (n == 0) break;
    out.push_back({blocks.data() + sp.begin, blocks.data() + sp.begin + n});
    left -= n;
  }
  return out;
}

// One timing, ns per block: the ranges run in order, repeated until they have done as many
// blocks as 600 substeps over the whole stream (`per_substep` blocks).
template <class Block, class Kernel>
double ns_per_block(const std::vector<std::pair<const Block*, const Block*>>& r, long per_substep,
                    const std::vector<V3>& start, Kernel kernel) {
  long per_pass = 0;
  for (const auto& q : r) per_pass += q.second - q.first;
  const long passes = std::max(1L, 600 * per_substep / per_pass);
  std::vector<V3> x = start;
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < passes; ++k)
    for (const auto& q : r) kernel(q.first, q.second, x.data());
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s / static_cast<double>(passes * per_pass) * 1e9;
}

struct KindFigures {
  long blocks = 0;             // free blocks per substep
  double whole = 0;            // ns per block, the whole stream (baseline)
  double l1 = 0, l2 = 0;       // ns per block over a 16 KB and a 256 KB slice
  double move = 0;             // ns per block, vertex movement alone
};

template <class Block, class Kernel, class Move>
KindFigures measure(const char* name, const std::vector<Block>& blocks, const std::vector<BlockSpan>& spans,
                    const std::vector<V3>& start, Kernel kernel, Move move, int reps) {
  KindFigures f;
  const auto all = ranges(blocks, spans, 0);
  for (const auto& q : all) f.blocks += q.second - q.first;
  const auto l1 = ranges(blocks, spans, 16 << 10), l2 = ranges(blocks, spans, 256 << 10);
  // The four timings alternate, best of `reps` rounds each, so that a change of the machine's
  // pace during the run (a VM's neighbours, its clock) falls on all four alike.
  f.whole = f.l1 = f.l2 = f.move = 1e30;
  for (int rep = 0; rep < reps; ++rep) {
    f.whole = std::min(f.whole, ns_per_block(all, f.blocks, start, kernel));
    f.l1 = std::min(f.l1, ns_per_block(l1, f.blocks, start, kernel));
    f.l2 = std::min(f.l2, ns_per_block(l2, f.blocks, start, kernel));
    f.move = std::min(f.move, ns_per_block(all, f.blocks, start, move));
  }
  std::printf("  %-8s %6ld blocks x %3zu B = %7.1f KB | ns per block: whole %6.2f, 16 KB slice %6.2f (%.2fx), "
              "256 KB slice %6.2f (%.2fx)",
              name, f.blocks, sizeof(Block), f.blocks * sizeof(Block) / 1024.0, f.whole, f.l1, f.whole / f.l1, f.l2,
              f.whole / f.l2);
  std::printf(" | vertex movement alone %6.2f (%.0f %% of the kernel)", f.move, 100 * f.move / f.whole);
  std::printf("\n");
  return f;
}

}  // namespace
#endif

int main(int argc, char** argv) {
  const int reps = dressguard::bench::parse_reps(argc, argv, "bench_sim_kernels");
  if (reps == 0) return 2;
#if defined(__x86_64__)
  if (!cpu_has_avx2()) {
    std::fprintf(stderr, "bench_sim_kernels: this CPU has no AVX2; the kernels measured here do not run on it\n");
    return 1;
  }
  constexpr double kSubstepsPerSimSecond = 300.0 * 20.0;
  for (const GownResolution res : {GownResolution::Reduced, GownResolution::Full}) {
    const bool reduced = res == GownResolution::Reduced;
    const dressguard::bench::KernelSetup k = dressguard::bench::kernel_setup(res);
    const GownModel& m = k.model;
    const std::vector<V3>& start = k.start;

    std::printf("%s gown (%zu vertices):\n", reduced ? "reduced" : "full", start.size());
    const KindFigures st = measure("stretch", m.stretch_blocks, m.stretch_spans, start, stretch_free_avx2,
                                   stretch_move, reps);
    const KindFigures sh = measure("shear", m.shear_blocks, m.shear_spans, start, shear_free_avx2, shear_move, reps);
    const KindFigures be = measure("bend", m.bend_blocks, m.bend_spans, start, bend_free_avx2, bend_move, reps);
    const double kernels_us = (st.blocks * st.whole + sh.blocks * sh.whole + be.blocks * be.whole) * 1e-3;
    const double floor_us = (st.blocks * st.move + sh.blocks * sh.move + be.blocks * be.move) * 1e-3;
    const double budget = reduced ? 0.125 : 1.0;
    std::printf("  per substep: the three kernels %.1f us = %.3f s per simulated s; every kernel moving its "
                "vertices only: %.1f us = %.3f s per simulated s (%.2fx the %s goal's %.3f s "
                "for everything)\n",
                kernels_us, kernels_us * 1e-6 * kSubstepsPerSimSecond, floor_us,
                floor_us * 1e-6 * kSubstepsPerSimSecond, floor_us * 1e-6 * kSubstepsPerSimSecond / budget,
                reduced ? "8x" : "1x", budget);
  }
  return 0;
#else
  std::fprintf(stderr, "bench_sim_kernels: x86-64 only (the AVX2 kernels)\n");
  return 1;
#endif
}
