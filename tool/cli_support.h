// Shared plumbing for subcommands: parse arguments or print help and an exit
// code, and report a failed status.
#ifndef STYLUS_TOOL_CLI_SUPPORT_H_
#define STYLUS_TOOL_CLI_SUPPORT_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "cli/args.h"
#include "tool/commands.h"
#include "train/clip_sources.h"

namespace stylus::tool {

using cli::Args;
using cli::ArgSpec;
using cli::ParseArgs;

// Parses argv; on --help prints `help` and sets *exit_code 0; on a usage error
// prints it with the help and sets *exit_code 2. Returns the arguments only when
// the command should run.
std::optional<Args> ParseOrExit(const char* command, const Argv& argv, const ArgSpec& spec,
                                const char* help, int* exit_code);

// Every --data value (each may list several, separated by commas) and the
// positional arguments: the clips or dataset directories to train on.
std::vector<std::string> DataSources(const Args& args);
// A training run's --labels FILE.csv and --skeleton PACKAGE_DIR|FILE.bvh.
model::TrainingDataOptions DataOptions(const Args& args);

// Prints "stylus-tool COMMAND: message" to stderr and returns 1.
int Fail(const char* command, const absl::Status& status);

}  // namespace stylus::tool

#endif  // STYLUS_TOOL_CLI_SUPPORT_H_
