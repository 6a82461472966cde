// The AVX2 kernels' lane helpers (offline/sim/lanes_avx2.h): four 32-byte vertices into x, y, z
// lanes and back. Every stretch and shear projection goes through them, so a lane mixed up or a
// pad left dirty would move the wrong vertex (the kernels' same-bits test would then fail too,
// but not say where).
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "lanes_avx2.h"
#include "model.h"

#if defined(__x86_64__)
namespace dressguard::sim {
namespace {

using namespace lanes;

std::vector<V3> numbered(int n) {
  std::vector<V3> x(n);
  for (int i = 0; i < n; ++i) x[i] = V3{10.0 * i + 1, 10.0 * i + 2, 10.0 * i + 3};
  for (int i = 0; i < n; ++i) x[i].pad = -7.0;  // dirty, so that a store's zero shows
  return x;
}

struct LaneValues {
  double x[4], y[4], z[4];
};

DG_AVX2 LaneValues load_lanes(const std::vector<V3>& x, const int32_t idx[4]) {
  const Lanes3 l = load4(x.data(), idx);
  LaneValues out;
  _mm256_storeu_pd(out.x, l.x);
  _mm256_storeu_pd(out.y, l.y);
  _mm256_storeu_pd(out.z, l.z);
  return out;
}

DG_AVX2 void store_lanes(std::vector<V3>& x, const int32_t idx[4], const LaneValues& v, int count) {
  store4(x.data(), idx, Lanes3{_mm256_loadu_pd(v.x), _mm256_loadu_pd(v.y), _mm256_loadu_pd(v.z)}, count);
}

// The helpers are AVX2 instructions: on a CPU without it the solver runs the scalar kernels and
// never calls them, so there is nothing of theirs to check.
class SimLanes : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2: the solver runs the scalar kernels here";
  }
};

TEST_F(SimLanes, Load4PutsEachVertexInItsLane) {
  const std::vector<V3> x = numbered(8);
  const int32_t idx[4] = {5, 2, 7, 0};
  const LaneValues l = load_lanes(x, idx);
  for (int lane = 0; lane < 4; ++lane) {
    EXPECT_EQ(l.x[lane], x[idx[lane]].x) << "lane " << lane;
    EXPECT_EQ(l.y[lane], x[idx[lane]].y) << "lane " << lane;
    EXPECT_EQ(l.z[lane], x[idx[lane]].z) << "lane " << lane;
  }
}

TEST_F(SimLanes, Store4WritesItsLanesOnlyAndZeroesTheirPads) {
  const std::vector<V3> before = numbered(8);
  const int32_t idx[4] = {6, 1, 3, 4};
  const LaneValues v = {{-1, -2, -3, -4}, {-5, -6, -7, -8}, {-9, -10, -11, -12}};
  for (int count = 1; count <= 4; ++count) {
    std::vector<V3> x = before;
    store_lanes(x, idx, v, count);
    for (int lane = 0; lane < 4; ++lane) {
      const V3& got = x[idx[lane]];
      if (lane < count) {
        EXPECT_EQ(got.x, v.x[lane]) << "count " << count << ", lane " << lane;
        EXPECT_EQ(got.y, v.y[lane]) << "count " << count << ", lane " << lane;
        EXPECT_EQ(got.z, v.z[lane]) << "count " << count << ", lane " << lane;
        EXPECT_EQ(got.pad, 0.0) << "count " << count << ", lane " << lane;
      } else {  // a careful block's empty lane: left as it was
        EXPECT_EQ(got.x, before[idx[lane]].x) << "count " << count << ", lane " << lane;
        EXPECT_EQ(got.pad, -7.0) << "count " << count << ", lane " << lane;
      }
    }
    for (int i : {0, 2, 5, 7}) EXPECT_EQ(x[i].x, before[i].x) << "vertex " << i << " is in no lane";
  }
}

}  // namespace
}  // namespace dressguard::sim
#endif  // __x86_64__
