// dressguard model show: print a model file readably (or as JSON). Loading validates it fully.
#include <cstdio>

#include "args.h"
#include "commands.h"
#include "dgm.h"
#include "files.h"
#include "report.h"

namespace dressguard::cli {

int run_model(int argc, char** argv) {
  Args args(argc - 1, argv + 1, {"help", "json"});
  if (args.has("help")) {
    std::puts(
        "usage: dressguard model show MODEL.dgm [--json]\n"
        "  Validates a model file (magic, version, CRC-32, parameters; see models/FORMAT.md) and\n"
        "  prints its metadata, feature convention, stop defaults, training conditions (sample\n"
        "  period, pull speeds; 'unknown' before format version 3) and every class's HMM.\n"
        "  --json   print the whole model as one JSON object");
    return 0;
  }
  args.allow_only({"help", "json"}, 2);
  const auto& pos = args.positional();
  if (pos.empty()) throw UsageError("missing subcommand (show)");
  if (pos[0] != "show") throw UsageError("unknown subcommand '" + pos[0] + "' (show)");
  if (pos.size() != 2) throw UsageError("model show takes exactly one MODEL.dgm");
  model::OutcomeModel m;
  try {
    m = model::read_model(pos[1]);
  } catch (const model::ModelError& e) {
    throw InputError(e.what());
  }
  if (args.has("json")) {
    std::printf("%s\n", hmm::model_json(m).c_str());
  } else {
    std::printf("%s", model::describe_model(m).c_str());
  }
  return 0;
}

}  // namespace dressguard::cli
