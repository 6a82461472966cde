// The dressguard subcommands. Each lives in its own cmd_<name>.cpp and is listed once in main.cpp.
#pragma once

namespace dressguard::cli {

// Every command: argv[0] is the subcommand name; returns the process exit code. Throws
// UsageError or InputError for bad input (main prints the one-line reason, exits 2).
using CommandFn = int (*)(int argc, char** argv);

struct Command {
  const char* name;
  const char* summary;
  CommandFn run;
};

int run_import(int argc, char** argv);
int run_simulate(int argc, char** argv);
int run_train(int argc, char** argv);
int run_classify(int argc, char** argv);
int run_model(int argc, char** argv);
int run_gown(int argc, char** argv);
int run_replay(int argc, char** argv);
int run_export_candump(int argc, char** argv);
int run_calibrate(int argc, char** argv);
int run_synthesize(int argc, char** argv);
int run_build_model(int argc, char** argv);
int run_predict(int argc, char** argv);

}  // namespace dressguard::cli
