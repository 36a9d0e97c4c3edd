// Command-line parsing for both CLIs (stylus-tool, stylus): "--name value" options,
// "--flag" switches, "-o" as a short form of "--out", and positional arguments.
#ifndef STYLUS_CLI_ARGS_H_
#define STYLUS_CLI_ARGS_H_

#include <map>
#include <set>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace stylus::cli {

struct ArgSpec {
  std::set<std::string> options;   // Take a value; may repeat.
  std::set<std::string> switches;  // Take no value.
};

struct Args {
  std::vector<std::string> positional;
  std::map<std::string, std::vector<std::string>> options;
  std::set<std::string> switches;
  bool help = false;

  bool Has(const std::string& name) const { return options.count(name) > 0; }
  // The last value given for `name`, or `fallback`.
  std::string Get(const std::string& name, const std::string& fallback = "") const;
  const std::vector<std::string>& All(const std::string& name) const;
  absl::StatusOr<int> GetInt(const std::string& name, int fallback) const;
  absl::StatusOr<double> GetDouble(const std::string& name, double fallback) const;
};

// INVALID_ARGUMENT for an unknown option or a missing value.
absl::StatusOr<Args> ParseArgs(const std::vector<std::string>& argv, const ArgSpec& spec);

}  // namespace stylus::cli

#endif  // STYLUS_CLI_ARGS_H_
