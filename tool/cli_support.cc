#include "tool/cli_support.h"

#include <cstdio>

#include "absl/strings/str_split.h"

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

std::vector<std::string> DataSources(const Args& args) {
  std::vector<std::string> out;
  for (const std::string& d : args.All("data")) {
    for (absl::string_view part : absl::StrSplit(d, ',', absl::SkipEmpty())) out.emplace_back(part);
  }
  for (const std::string& p : args.positional) out.push_back(p);
  return out;
}

model::TrainingDataOptions DataOptions(const Args& args) {
  model::TrainingDataOptions o;
  o.labels_csv = args.Get("labels");
  o.skeleton = args.Get("skeleton");
  o.leave_out_styles = args.All("leave-out-style");
  return o;
}

}  // namespace stylus::tool
