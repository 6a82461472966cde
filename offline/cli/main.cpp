// dressguard: the offline toolchain. `dressguard <command> --help` for each command.
#include <cstdio>
#include <cstring>
#include <exception>

#include "args.h"
#include "commands.h"
#include "files.h"

namespace dressguard::cli {
namespace {

// One row per subcommand, in the order a user meets them.
constexpr Command kCommands[] = {
    {"import", "convert the study's measured trials into a dataset", run_import},
    {"simulate", "simulate one sleeve-pulling trial: haptic CSV, summary, scene for pictures", run_simulate},
    {"train", "train the outcome HMMs of a labelled dataset into a model file", run_train},
    {"classify", "classify a dataset's trials with a model: accuracy, confusion, sweeps", run_classify},
    {"model", "show a model file (model show MODEL.dgm)", run_model},
    {"gown", "load, reduce and place the gown mesh; stats, OBJ and a picture", run_gown},
    {"export-candump", "write trials as candump logs of the CAN protocol (with optional faults)", run_export_candump},
    {"replay", "run the predictor daemon's code on a candump log: would it stop, when, why", run_replay},
    {"calibrate", "fit the simulator to one participant's sequences (CMA-ES)", run_calibrate},
    {"synthesize", "simulate labelled trials with a calibrated simulator", run_synthesize},
    {"build-model", "train the simulation-trained classifier (STC) into a model file", run_build_model},
    {"predict", "a calibrated simulator against the other participants' measured trials", run_predict},
};

void print_usage() {
  std::puts("usage: dressguard <command> [options]   (dressguard <command> --help)\n\ncommands:");
  for (const auto& c : kCommands) std::printf("  %-16s %s\n", c.name, c.summary);
}

}  // namespace
}  // namespace dressguard::cli

int main(int argc, char** argv) {
  using namespace dressguard::cli;
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "help")) {
    print_usage();
    return argc < 2 ? 2 : 0;
  }
  for (const auto& c : kCommands) {
    if (std::strcmp(argv[1], c.name) != 0) continue;
    try {
      return c.run(argc - 1, argv + 1);
    } catch (const UsageError& e) {
      std::fprintf(stderr, "dressguard %s: %s (see --help)\n", c.name, e.what());
      return 2;
    } catch (const dressguard::InputError& e) {
      std::fprintf(stderr, "dressguard %s: %s\n", c.name, e.what());
      return 2;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "dressguard %s: error: %s\n", c.name, e.what());
      return 1;
    }
  }
  std::fprintf(stderr, "dressguard: unknown command '%s' (see dressguard --help)\n", argv[1]);
  return 2;
}
