// Datasets: round trip, errors that name the file and line, atomic writes, the study import;
// where the study's data is looked for (shared_dir).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <unistd.h>
#include <fstream>

#include "dataset.h"
#include "files.h"

namespace fs = std::filesystem;
using namespace dressguard;

namespace {

// A temporary folder removed when the test ends.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() / ("dg_core_test_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

void write_text(const fs::path& p, const std::string& s) { std::ofstream(p) << s; }

}  // namespace

TEST(Dataset, RoundTripKeepsEverySampleAndLabel) {
  Dataset ds;
  for (int k = 0; k < 3; ++k) {
    HapticSequence s;
    s.id = "t" + std::to_string(k);
    s.participant = "4";
    s.height = static_cast<ArmHeight>(k);
    s.speed = k == 2 ? 0.15 : 0.1;
    if (k != 1) s.label = static_cast<Outcome>(k);
    for (int i = 0; i < 50; ++i) s.samples.push_back({0.01 * i, 0.001 * i * i, -0.123456 * i, 1e-7 * i, 0.5 - i});
    ds.trials.push_back(s);
  }
  const TempDir tmp("roundtrip");
  const fs::path& dir = tmp.path;
  save_dataset(ds, dir);
  const Dataset back = load_dataset(dir);
  ASSERT_EQ(back.trials.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    const auto& a = ds.trials[k];
    const auto& b = back.trials[k];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.label, b.label);
    EXPECT_DOUBLE_EQ(a.speed, b.speed);
    ASSERT_EQ(a.samples.size(), b.samples.size());
    for (size_t i = 0; i < a.samples.size(); ++i) {
      // %.9g: 9 significant digits, so a relative error below 1e-8.
      EXPECT_NEAR(a.samples[i].f_motion, b.samples[i].f_motion, 1e-8 * (1 + std::fabs(a.samples[i].f_motion)));
      EXPECT_NEAR(a.samples[i].travel, b.samples[i].travel, 1e-9);
    }
  }
}

TEST(Dataset, MalformedRowNamesFileAndLine) {
  const TempDir tmp("malformed");
  const fs::path& dir = tmp.path;
  write_text(dir / "manifest.csv", "trial_id,participant,height,speed,label,file\na,1,high,0.1,good,a.csv\n");
  write_text(dir / "a.csv", "t,travel,f_motion,f_lateral,f_vertical\n0,0,0,0,0\n0.01,0.001,abc,0,0\n");
  try {
    load_dataset(dir);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("a.csv:3"), std::string::npos) << msg;
    EXPECT_NE(msg.find("f_motion"), std::string::npos) << msg;
  }
  write_text(dir / "manifest.csv", "trial_id,participant,height,speed,label,file\na,1,sideways,0.1,good,a.csv\n");
  try {
    load_dataset(dir);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("manifest.csv:2"), std::string::npos) << e.what();
  }
}

TEST(Files, AtomicWriteReplacesWholeOrNothing) {
  const TempDir tmp("atomic");
  const fs::path& dir = tmp.path;
  const fs::path p = dir / "x.txt";
  write_file_atomic(p, "first");
  EXPECT_EQ(read_file(p), "first");
  write_file_atomic(p, "second, longer");
  EXPECT_EQ(read_file(p), "second, longer");
  // A write into a folder that cannot be created fails and leaves no temporary behind.
  write_text(dir / "blocker", "a file, not a folder");
  EXPECT_ANY_THROW(write_file_atomic(dir / "blocker" / "y.txt", "z"));
  size_t n = 0;
  for ([[maybe_unused]] auto& e : fs::directory_iterator(dir)) ++n;
  EXPECT_EQ(n, 2u);  // x.txt and blocker only
}

TEST(Study, ImportsAllTwentyTwoTrialsWithLabelsAndSpeeds) {
  const fs::path study = study_dir();
  if (study.empty()) GTEST_SKIP() << "shared/data not present: the study import is checked in CI, where it is";
  const Dataset ds = import_study(study);
  ASSERT_EQ(ds.trials.size(), 22u);
  int good = 0, low_miss = 0, middle_miss = 0, fast = 0;
  for (const auto& t : ds.trials) {
    if (t.label == Outcome::Good) { ++good; EXPECT_EQ(t.height, ArmHeight::High); }
    if (t.height == ArmHeight::Low) ++low_miss;
    if (t.height == ArmHeight::Middle) ++middle_miss;
    if (t.speed > 0.12) ++fast;
    // The README: good trials end at the 10 N stop at 0.62 +- 0.03 m (a few 2-sigma outliers).
    if (t.label == Outcome::Good) {
      EXPECT_NEAR(t.samples.back().travel, 0.62, 0.06) << t.id;
      EXPECT_LT(t.samples.back().f_motion, -9.0) << t.id;
    }
  }
  EXPECT_EQ(good, 8);
  EXPECT_EQ(low_miss, 8);
  EXPECT_EQ(middle_miss, 6);
  EXPECT_EQ(fast, 1);  // the README: one trial at about 0.15 m/s
}

// Where the rig stopped a measured trial: at the force limit (|F| >= 9.5 N at the last sample,
// either axis) the simulation may run the rig's full travel; otherwise it ends at the trial's
// last travel. Every good trial of the study ends at the force limit and every missed one does
// not, where the study is present.
TEST(Study, RigEndOfTravel) {
  std::vector<HapticSample> s = {{0.01, 0.001, 0, 0, 0}, {0.02, 0.72, -3.99, 0.1, -0.5}};
  EXPECT_FALSE(ended_at_force_limit(s));
  EXPECT_DOUBLE_EQ(rig_end_of_travel(s), 0.72);
  s.back().f_vertical = 9.6;
  EXPECT_TRUE(ended_at_force_limit(s));
  EXPECT_DOUBLE_EQ(rig_end_of_travel(s), 0.85);
  s.back().f_vertical = 0;
  s.back().f_motion = -9.5;
  EXPECT_DOUBLE_EQ(rig_end_of_travel(s, 0.9), 0.9);
  EXPECT_DOUBLE_EQ(rig_end_of_travel({}), 0.85);
  const fs::path study = study_dir();
  if (study.empty()) GTEST_SKIP() << "shared/data not present: the study's trials are checked in CI, where it is";
  for (const auto& t : import_study(study).trials) {
    EXPECT_EQ(ended_at_force_limit(t.samples), t.label == Outcome::Good) << t.id;
    if (t.label != Outcome::Good) {
      EXPECT_LE(rig_end_of_travel(t.samples), 0.85 + 1e-9) << t.id;
    }
  }
}

// The rig's pull (haptic.h): on the ramp x = a t^2 / 2, after it x = v (t - v / 2a); the two
// meet at x = v^2 / 2a, t = v / a. A recording counts its unrecorded start in its own periods.
TEST(Pull, TimeAtTravelAndUnrecordedStart) {
  EXPECT_NEAR(pull_time_at(0.005, 0.15), 0.1, 1e-15);                 // sqrt(2 * 0.005 / 1)
  EXPECT_NEAR(pull_time_at(0.01125, 0.15), 0.15, 1e-15);              // the ramp's end, both forms
  EXPECT_NEAR(pull_time_at(0.0958, 0.15), 0.0958 / 0.15 + 0.075, 1e-15);
  EXPECT_NEAR(pull_time_at(0.5, 0.1, 2.0), 0.5 / 0.1 + 0.025, 1e-15);
  EXPECT_EQ(pull_time_at(0.0, 0.1), 0.0);

  HapticSequence s;
  s.speed = 0.1;
  for (int i = 0; i < 50; ++i) s.samples.push_back({0.01 * i, 0.004 + 0.001 * i, 0, 0, 0});
  EXPECT_EQ(unrecorded_samples(s), 0u) << "4 mm in is within kLateStart: recorded from the start";
  for (auto& smp : s.samples) smp.travel += 0.1;  // 0.104 m in: 0.104 / 0.1 + 0.05 = 1.09 s
  EXPECT_EQ(unrecorded_samples(s), 109u);
  for (auto& smp : s.samples) smp.t *= 3.0;       // the same start at a 30 ms period
  EXPECT_EQ(unrecorded_samples(s), 36u);          // 1.09 / 0.03 = 36.3
  EXPECT_EQ(unrecorded_samples(HapticSequence{}), 0u);
}

// Where the study's data is looked for: an explicit $DRESSGUARD_SHARED_DIR with data/ in it is
// used; one without data/ means "absent" even when the build's default holds the data, which is
// how tests run the project as on a machine without ../shared. Unset, the build's default (or
// ../shared) is used, so that result does not depend on this test's own environment.
TEST(SharedDir, AnExplicitFolderIsTakenAtItsWord) {
  // Puts the variable back as it was however the test ends (an ASSERT returns early), so that
  // the tests after it in the same process see the environment ctest gave them.
  struct RestoreSharedDir {
    const char* before = std::getenv("DRESSGUARD_SHARED_DIR");
    const std::string saved = before ? before : "";
    ~RestoreSharedDir() {
      if (before) ::setenv("DRESSGUARD_SHARED_DIR", saved.c_str(), 1);
      else ::unsetenv("DRESSGUARD_SHARED_DIR");
    }
  } restore;
  TempDir with("shared_with"), without("shared_without");
  fs::create_directories(with.path / "data");

  ASSERT_EQ(::setenv("DRESSGUARD_SHARED_DIR", with.path.c_str(), 1), 0);
  EXPECT_EQ(shared_dir(), with.path);
  ASSERT_EQ(::setenv("DRESSGUARD_SHARED_DIR", without.path.c_str(), 1), 0);
  EXPECT_TRUE(shared_dir().empty()) << shared_dir();
  ASSERT_EQ(::setenv("DRESSGUARD_SHARED_DIR", (without.path / "nonexistent").c_str(), 1), 0);
  EXPECT_TRUE(shared_dir().empty()) << shared_dir();
  // Set but empty is as if unset: whatever the build's default or ../shared gives.
  ASSERT_EQ(::unsetenv("DRESSGUARD_SHARED_DIR"), 0);
  const fs::path unset = shared_dir();
  ASSERT_EQ(::setenv("DRESSGUARD_SHARED_DIR", "", 1), 0);
  EXPECT_EQ(shared_dir(), unset);
}
