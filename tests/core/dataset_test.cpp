// Datasets: round trip, errors that name the file and line, atomic writes, the study import;
// where the study's data is looked for (shared_dir).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>
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
    for (int i = 0; i < 50; ++i) s.samples.push_back({0.01 * i, 0.0002 * i * i, -0.123456 * i, 1e-7 * i, 0.5 - i});
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
    EXPECT_EQ(a.participant, b.participant);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.label, b.label);
    EXPECT_DOUBLE_EQ(a.speed, b.speed);
    ASSERT_EQ(a.samples.size(), b.samples.size());
    for (size_t i = 0; i < a.samples.size(); ++i) {
      // %.9g: 9 significant digits, so a relative error below 1e-8. Every column: past the first
      // sample the five differ from one another, so a column dropped or two swapped shows.
      const auto near = [](double x, double y) { return std::fabs(x - y) <= 1e-8 * (1 + std::fabs(x)); };
      EXPECT_TRUE(near(a.samples[i].t, b.samples[i].t)) << i;
      EXPECT_TRUE(near(a.samples[i].f_motion, b.samples[i].f_motion)) << i;
      EXPECT_TRUE(near(a.samples[i].f_lateral, b.samples[i].f_lateral)) << i;
      EXPECT_TRUE(near(a.samples[i].f_vertical, b.samples[i].f_vertical)) << i;
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

namespace {

constexpr const char* kManifestHead = "trial_id,participant,height,speed,label,file\n";
constexpr const char* kTrialHead = "t,travel,f_motion,f_lateral,f_vertical\n";

// The InputError message of f(), or "" when it throws none.
template <typename F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Success when the error message `msg` holds `want`.
::testing::AssertionResult names(const std::string& msg, const std::string& want) {
  if (msg.find(want) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "want '" << want << "', got '" << msg << "'";
}

// A one-trial dataset whose trial file holds `rows` (after the header) and whose manifest row
// carries `speed`; load_dataset's error message, or "" when it loads.
std::string load_error(const fs::path& dir, const std::string& rows, const std::string& speed = "0.1") {
  write_text(dir / "manifest.csv", std::string(kManifestHead) + "a,1,high," + speed + ",good,a.csv\n");
  write_text(dir / "a.csv", kTrialHead + rows);
  try {
    load_dataset(dir);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

HapticSequence ramp_trial(const std::string& id, double f_scale) {
  HapticSequence s;
  s.id = id;
  s.participant = "2";
  for (int i = 0; i < 20; ++i) s.samples.push_back({0.01 * i, 0.001 * i, -f_scale * i, 0.0, 0.1 * i});
  return s;
}

}  // namespace

// Each bound of dataset.h: a unit slip or a glitch is named with its file, line and column, not
// trained on (a speed of 1e-300 m/s once asked the HMMs for 10^300 unrecorded samples and
// crashed `train`).
TEST(DatasetRejects, ImplausibleValuesNameFileLineAndColumn) {
  const TempDir tmp("bounds");
  const fs::path& dir = tmp.path;
  const std::string ok = "0,0,0,0,0\n0.01,0.001,-0.1,0,0.05\n0.02,0.002,-0.2,0,0.1\n";
  EXPECT_EQ(load_error(dir, ok), "");
  struct Case { std::string rows, speed, want; };
  const Case cases[] = {
      {"0,0,0,0,0\n0.01,1.5,-0.1,0,0\n0.02,850,-0.2,0,0\n", "0.1", "a.csv:4: column travel: 850 m is outside"},
      {"0,0,0,0,0\n0.01,0.001,-1e20,0,0\n", "0.1", "a.csv:3: column f_motion: -1e+20 N is beyond"},
      {"0,0,0,0,0\n0.01,0.001,0,0,2000\n", "0.1", "a.csv:3: column f_vertical: 2000 N"},
      {"0,0,0,0,0\n0.01,0.3,0,0,0\n0.02,0.1,0,0,0\n", "0.1", "a.csv:4: column travel goes back 0.2 m"},
      {"0,0,0,0,0\n0.01,1e-400,0,0,0\n", "0.1", "a.csv:3: column travel: beyond the range of a double"},
      {ok, "1e-300", "manifest.csv:2: speed 1e-300 m/s is outside"},
      {ok, "100", "manifest.csv:2: speed 100 m/s is outside"},
      // Late start, t in kiloseconds: 0.5 m into a pull at 0.1 m/s is 5.05 s, 5e5 periods of 1e-5.
      {"0,0.5,0,0,0\n0.00001,0.5,0,0,0\n0.00002,0.5,0,0,0\n", "0.1", "samples into its pull"},
  };
  for (const auto& c : cases) EXPECT_TRUE(names(load_error(dir, c.rows, c.speed), c.want));
  // A travel jitter under a millimetre is a sensor's, not a glitch.
  EXPECT_EQ(load_error(dir, "0,0,0,0,0\n0.01,0.0105,0,0,0\n0.02,0.0100,0,0,0\n"), "");
}

// A trial of one sample is no force sequence: it has no sampling period and classify scored its
// one force as a whole pull (and counted it in the accuracy). Refused at its only row, in a
// dataset's trial and in a study trial (after a blank line: the row's own number); two load.
TEST(DatasetRejects, ATrialOfOneSample) {
  const TempDir tmp("one_sample");
  const fs::path& dir = tmp.path;
  EXPECT_TRUE(names(load_error(dir, "\n0,0.02,-0.1,0,0.05\n"),
                    "a.csv:3: the only sample: a trial is a pull's force sequence, at least 2 samples"));
  EXPECT_EQ(load_error(dir, "0,0.02,-0.1,0,0.05\n0.01,0.021,-0.1,0,0.05\n"), "");
  write_text(dir / "1.txt", "0 0 0 0 0\n");
  EXPECT_TRUE(names(input_error_of([&] { read_study_trial(dir / "1.txt"); }), "1.txt:1: the only sample"));
  write_text(dir / "1.txt", "0 0 0 0 0\n0.01 0.001 -0.1 0 0\n");
  EXPECT_EQ(read_study_trial(dir / "1.txt").size(), 2u);
}

TEST(DatasetRejects, EmptyManifestRepeatedFileAndFolders) {
  const TempDir tmp("manifest");
  const fs::path& dir = tmp.path;
  write_text(dir / "manifest.csv", "");
  EXPECT_TRUE(names(input_error_of([&] { load_dataset(dir); }), "manifest.csv: empty file"));
  write_text(dir / "a.csv", std::string(kTrialHead) + "0,0,0,0,0\n0.01,0.001,0,0,0\n");
  write_text(dir / "manifest.csv", std::string(kManifestHead) + "a,1,high,0.1,good,a.csv\nb,1,high,0.1,good,a.csv\n");
  EXPECT_TRUE(names(input_error_of([&] { load_dataset(dir); }), "manifest.csv:3: file 'a.csv' repeats line 2"));
  fs::create_directories(dir / "sub");
  write_text(dir / "manifest.csv", std::string(kManifestHead) + "a,1,high,0.1,good,sub\n");
  EXPECT_TRUE(names(input_error_of([&] { load_dataset(dir); }), "sub: is a folder, not a file"));
}

// Named columns after the five (dressguard simulate's label and metadata) are written with one
// value on every row and skipped by the reader, so that simulate's CSV alone says what it is and
// every reader of trial CSVs still reads it (export-candump --trial refused the extra columns). A
// row must still have as many fields as the header has names, and the header must begin with
// the five.
TEST(Dataset, NamedColumnsAfterTheFiveAreSkipped) {
  const TempDir tmp("extra");
  const fs::path csv = tmp.path / "t.csv";
  const std::vector<HapticSample> samples = {{0.01, 0.00005, -0.1, 0.02, 0.3}, {0.02, 0.0002, -0.2, 0.01, 0.4}};
  const std::string text = format_trial_csv(samples, {{"label", "missed"}, {"height", "low"}, {"seed", "7"}});
  EXPECT_EQ(text,
            "t,travel,f_motion,f_lateral,f_vertical,label,height,seed\n"
            "0.01,5e-05,-0.1,0.02,0.3,missed,low,7\n0.02,0.0002,-0.2,0.01,0.4,missed,low,7\n");
  EXPECT_EQ(format_trial_csv(samples), format_trial_csv(samples, {}));  // the dataset's own: five columns
  EXPECT_EQ(format_trial_csv(samples).substr(0, 39), "t,travel,f_motion,f_lateral,f_vertical\n");
  write_text(csv, text);
  const std::vector<HapticSample> back = read_trial_csv(csv);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].f_vertical, 0.4);
  EXPECT_EQ(back[0].travel, 0.00005);
  write_text(csv, "t,travel,f_motion,f_lateral,f_vertical,label\n0,0,0,0,0,good\n0.01,0.001,0,0,0\n");
  EXPECT_TRUE(names(input_error_of([&] { read_trial_csv(csv); }), "t.csv:3: expected 6 columns, found 5"));
  write_text(csv, std::string(kTrialHead) + "0,0,0,0,0,good\n0.01,0.001,0,0,0\n");
  EXPECT_TRUE(names(input_error_of([&] { read_trial_csv(csv); }), "t.csv:2: expected 5 columns, found 6"));
  write_text(csv, "t,travel,f_motion,f_lateral,f_vertical_N\n0,0,0,0,0\n0.01,0.001,0,0,0\n");
  EXPECT_TRUE(names(input_error_of([&] { read_trial_csv(csv); }), "t.csv:1: expected header"));
  write_text(csv, "t,travel,f_motion,f_lateral,f_vertical,,seed\n0,0,0,0,0,,1\n0.01,0.001,0,0,0,,1\n");
  EXPECT_TRUE(names(input_error_of([&] { read_trial_csv(csv); }), "t.csv:1: a column without a name"));
  EXPECT_THROW(format_trial_csv(samples, {{"label", "a,b"}}), std::invalid_argument);
}

// A byte-order mark (Excel's "CSV UTF-8") is skipped, in the manifest and in a trial file.
TEST(Dataset, AByteOrderMarkIsSkipped) {
  const TempDir tmp("bom");
  const fs::path& dir = tmp.path;
  write_text(dir / "manifest.csv", std::string("\xEF\xBB\xBF") + kManifestHead + "a,1,high,0.1,good,a.csv\n");
  write_text(dir / "a.csv", std::string("\xEF\xBB\xBF") + kTrialHead + "0,0,-1,0,0\r\n0.01,0.001,-2,0,0\r\n");
  const Dataset ds = load_dataset(dir);
  ASSERT_EQ(ds.trials.size(), 1u);
  EXPECT_EQ(ds.trials[0].samples.size(), 2u);
  EXPECT_EQ(ds.trials[0].samples[1].f_motion, -2.0);
}

// The manifest is the commit point: a save that fails part-way leaves the previous dataset whole
// (it once overwrote trial files in place before it failed); a save that succeeds leaves no file
// of the previous one behind and rewrites nothing that did not change.
TEST(Dataset, AFailedSaveLeavesThePreviousDatasetWhole) {
  const TempDir tmp("commit");
  const fs::path& dir = tmp.path;
  Dataset first;
  for (const char* id : {"a", "b", "c"}) first.trials.push_back(ramp_trial(id, 0.1));
  save_dataset(first, dir);
  const std::string a_before = read_file(dir / "a.csv"), manifest_before = read_file(dir / "manifest.csv");

  // The second save's third trial cannot be written (folders are in the way of both names c's
  // file could take): it fails after a and b have new content.
  Dataset second;
  for (const char* id : {"a", "b", "c"}) second.trials.push_back(ramp_trial(id, 0.2));
  fs::remove(dir / "c.csv");
  fs::create_directories(dir / "c.csv" / "x");
  fs::create_directories(dir / "c.1.csv" / "x");
  EXPECT_THROW(save_dataset(second, dir), InputError);
  EXPECT_EQ(read_file(dir / "manifest.csv"), manifest_before);
  EXPECT_EQ(read_file(dir / "a.csv"), a_before) << "a trial the manifest names was overwritten";
  fs::remove_all(dir / "c.csv");
  fs::remove_all(dir / "c.1.csv");

  // Without the obstacle the save goes through under other names; the old files are removed.
  first.trials.pop_back();
  save_dataset(first, dir);  // the manifest names a.csv, b.csv again
  save_dataset(second, dir);
  const Dataset back = load_dataset(dir);
  ASSERT_EQ(back.trials.size(), 3u);
  EXPECT_NEAR(back.trials[0].samples[5].f_motion, -1.0, 1e-12);
  EXPECT_TRUE(fs::exists(dir / "a.1.csv"));
  EXPECT_FALSE(fs::exists(dir / "a.csv")) << "the previous manifest's file was left behind";
  EXPECT_TRUE(fs::exists(dir / "c.csv")) << "c was not named by the previous manifest: its own name";
  // Saving the same dataset again changes no file.
  const auto stamp = fs::last_write_time(dir / "a.1.csv");
  save_dataset(second, dir);
  EXPECT_EQ(fs::last_write_time(dir / "a.1.csv"), stamp);
  EXPECT_EQ(load_dataset(dir).trials.size(), 3u);
}

TEST(DatasetRejects, IdsTheManifestCouldNotReadBack) {
  const TempDir tmp("ids");
  const fs::path& dir = tmp.path;
  for (const std::string& id : {std::string(), std::string("a,b"), std::string("a/b"), std::string(".hidden"), std::string("a\nb")}) {
    Dataset ds;
    ds.trials.push_back(ramp_trial(id, 0.1));
    EXPECT_THROW(save_dataset(ds, dir / "out"), InputError) << "id '" << id << "'";
  }
  Dataset twice;
  twice.trials = {ramp_trial("a", 0.1), ramp_trial("a", 0.2)};
  EXPECT_THROW(save_dataset(twice, dir / "out"), InputError);
  Dataset comma;
  comma.trials.push_back(ramp_trial("a", 0.1));
  comma.trials[0].participant = "1,2";
  EXPECT_THROW(save_dataset(comma, dir / "out"), InputError);
  EXPECT_FALSE(fs::exists(dir / "out")) << "a refused save wrote something";
  // Ids "a" and "a.1": the alternate name of a's file never takes a.1's.
  Dataset pair;
  pair.trials = {ramp_trial("a", 0.1), ramp_trial("a.1", 0.1)};
  save_dataset(pair, dir / "pair");
  pair.trials[0] = ramp_trial("a", 0.3);
  save_dataset(pair, dir / "pair");
  const Dataset back = load_dataset(dir / "pair");
  EXPECT_NEAR(back.trials[0].samples[1].f_motion, -0.3, 1e-12);
  EXPECT_NEAR(back.trials[1].samples[1].f_motion, -0.1, 1e-12);
}

// The study import names the file whose id cannot be saved or repeats another's, and refuses a
// study folder without trials.
TEST(StudyRejects, UnsavableOrRepeatedIdsAndNoTrials) {
  const TempDir tmp("study");
  const fs::path& dir = tmp.path;
  const std::string rows = "0 0 0 0 0\n0.01 0.001 -0.1 0 0\n";
  for (const char* f : {"good", "miss", "caughtmiss"}) fs::create_directories(dir / f);
  EXPECT_TRUE(names(input_error_of([&] { import_study(dir); }), "no trial files"));
  fs::create_directories(dir / "good" / "subject0");
  write_text(dir / "good" / "subject0" / "0,1.txt", rows);
  EXPECT_TRUE(names(input_error_of([&] { import_study(dir); }), "0,1.txt: its trial id 's0-good-0,1' holds ','"));
  fs::remove(dir / "good" / "subject0" / "0,1.txt");
  // subject1-good-2/3.txt and subject1/2-good-3.txt would both be s1-good-2-good-3.
  fs::create_directories(dir / "good" / "subject1-good-2");
  fs::create_directories(dir / "good" / "subject1");
  write_text(dir / "good" / "subject1-good-2" / "3.txt", rows);
  write_text(dir / "good" / "subject1" / "2-good-3.txt", rows);
  EXPECT_TRUE(names(input_error_of([&] { import_study(dir); }), "is also that of"));
}

// A trial file's extension in any case is a trial (a copy through a FAT volume says 1.TXT); a
// note beside the trials is not.
TEST(Study, ImportsTrialFilesWhateverTheExtensionsCase) {
  const TempDir tmp("study_case");
  const fs::path& dir = tmp.path;
  for (const char* f : {"good", "miss", "caughtmiss"}) fs::create_directories(dir / f / "subject2");
  const std::string rows = "0 0 0 0 0\n0.01 0.001 -0.1 0 0\n";
  write_text(dir / "good" / "subject2" / "1.TXT", rows);
  write_text(dir / "miss" / "subject2" / "4.txt", rows);
  write_text(dir / "miss" / "subject2" / "notes.md", "not a trial\n");
  const Dataset ds = import_study(dir);
  ASSERT_EQ(ds.trials.size(), 2u);
  EXPECT_EQ(ds.trials[0].id, "s2-good-1");
  EXPECT_EQ(ds.trials[1].id, "s2-miss-4");
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
    if (t.height != ArmHeight::High) {
      EXPECT_EQ(t.label, Outcome::Missed) << t.id;  // the README: no caught trial
    }
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
      EXPECT_EQ(rig_end_of_travel(t.samples), t.samples.back().travel) << t.id;  // where the rig stopped
      EXPECT_LE(rig_end_of_travel(t.samples), 0.85 + 1e-9) << t.id;
    }
  }
}

// The rig's pull (haptic.h): on the ramp x = a t^2 / 2, after it x = v (t - v / 2a); the two
// meet at x = v^2 / 2a, t = v / a. A recording counts its unrecorded start in its own periods,
// the time read from its stamp, a constant-speed profile (haptic.h): x / v, not pull_time_at.
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
  for (auto& smp : s.samples) smp.travel += 0.1;  // 0.104 m in by the stamp: 0.104 / 0.1 = 1.04 s
  EXPECT_EQ(unrecorded_samples(s), 104u) << "the ramped reading, 1.09 s, would be 109";
  for (auto& smp : s.samples) smp.t *= 3.0;       // the same start at a 30 ms period
  EXPECT_EQ(unrecorded_samples(s), 35u);          // 1.04 / 0.03 = 34.7
  s.speed = 0.0;                                  // no speed to read the stamp's time by
  EXPECT_EQ(unrecorded_samples(s), 0u);
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
