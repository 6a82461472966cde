// dressguard import: the study's folder layout -> a dataset (manifest.csv + one CSV per trial).
#include <cstdio>

#include "args.h"
#include "commands.h"
#include "dataset.h"
#include "files.h"
#include "json.h"

namespace dressguard::cli {

int run_import(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json"});
  if (args.has("help")) {
    std::puts(
        "usage: dressguard import [--study DIR] --out DATASET [--json]\n"
        "  Converts the study's <outcome>/subject<N>/<k>.txt layout into a dataset folder.\n"
        "  --study DIR   default: shared/data/kapusta2016-calibration-trials\n"
        "  --out DATASET folder to write manifest.csv and the trial CSVs into\n"
        "  --json        print a machine-readable summary");
    return 0;
  }
  args.allow_only({"help", "json", "study", "out"});
  std::filesystem::path study = args.get("study").value_or(study_dir().string());
  if (study.empty()) throw UsageError("no --study given and shared/data is not present");
  const std::string out = args.require("out");
  const Dataset ds = import_study(study);  // everything is read before anything is written
  save_dataset(ds, out);
  int per[kOutcomeCount] = {};
  for (const auto& t : ds.trials) per[static_cast<int>(*t.label)]++;
  if (args.has("json")) {
    std::printf("{\"trials\": %zu, \"good\": %d, \"missed\": %d, \"caught\": %d, \"out\": %s}\n",
                ds.trials.size(), per[0], per[1], per[2], json_string(out).c_str());
  } else {
    std::printf("imported %zu trials (%d good, %d missed, %d caught) into %s\n", ds.trials.size(), per[0], per[1],
                per[2], out.c_str());
  }
  return 0;
}

}  // namespace dressguard::cli
