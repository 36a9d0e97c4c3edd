#include "tool/cli_support.h"

#include <cstdio>

namespace stylus::tool {

std::optional<Args> ParseOrExit(const char* command, const Argv& argv, const ArgSpec& spec,
                                const char* help, int* exit_code) {
  absl::StatusOr<Args> args = ParseArgs(argv, spec);
  if (!args.ok()) {
    std::fprintf(stderr, "stylus-tool %s: %s\n\n%s", command,
                 std::string(args.status().message()).c_str(), help);
    *exit_code = 2;
    return std::nullopt;
  }
  if (args->help) {
    std::fputs(help, stdout);
    *exit_code = 0;
    return std::nullopt;
  }
  return *std::move(args);
}

int Fail(const char* command, const absl::Status& status) {
  std::fprintf(stderr, "stylus-tool %s: %s\n", command, std::string(status.message()).c_str());
  return 1;
}

}  // namespace stylus::tool
