// The `key = value` text of a package's config.txt, shared by the families'
// configurations: parsing with errors that name the file, line and key.
#ifndef STYLUS_MODEL_CONFIG_TEXT_H_
#define STYLUS_MODEL_CONFIG_TEXT_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace stylus::model {

// One line of a config file; the converters return INVALID_ARGUMENT naming
// "<source>:<line>" and the key when the value is malformed or out of range.
struct ConfigEntry {
  std::string source;
  int line = 0;
  std::string key, value;

  absl::Status Error(absl::string_view what) const;
  absl::Status Int(int* out, int lo, int hi) const;
  absl::Status Double(double* out, double lo, double hi) const;
  absl::Status Bool(bool* out) const;  // "0" or "1".
  absl::Status Uint64(uint64_t* out) const;
};

// The keys every family's config has: optimization and provenance.
struct TrainingKeys {
  int* batch;
  double* lr;
  int* iterations;
  int* trained_iterations;
  uint64_t* seed;
  std::string* data;
  std::string* commit;
};
// When `e` is one of those keys, parses it into `keys` and returns the
// status; nullopt for any other key.
std::optional<absl::Status> ParseTrainingKey(const ConfigEntry& e, const TrainingKeys& keys);

// The content guard's inference keys (model/content_guard.h), which both
// families' configs have. With `content_guard`, the package's content guard
// (guard_K.pt; `stylus-tool train-guard`) reads the action of the content
// clip and of each whole-clip transfer. When they differ, the transfer is
// made again with a weaker style change at each of `guard_strengths` in
// turn (each family says what a strength is), and the first whose action
// the guard reads as the content's is returned (the last one when none is).
// The style is given up where the action would be lost (docs/families.md).
// Streams are not guarded, in either family.
struct GuardKeys {
  bool content_guard = false;
  std::vector<double> guard_strengths = {1, 0.7, 0.4, 0.2};
  // A transfer passes the guard when the guard's likeliest action for it is
  // the content clip's, with at least this probability.
  double guard_min_probability = 0;
};
// When `e` is one of those keys, parses it into `keys` and returns the
// status; nullopt for any other key. guard_strengths: 1 to 8 numbers in
// [0, 1], each below the one before, separated by commas.
std::optional<absl::Status> ParseGuardKey(const ConfigEntry& e, GuardKeys* keys);
// Appends the keys (nothing when the guard is off).
void AppendGuardKeys(const GuardKeys& keys, std::string* out);
// The keys' names (all inference keys).
const std::vector<std::string>& GuardKeyNames();

// Movement from examples (motion/example_motion.h, docs/movement.md), which
// both families' configs have: with `movement = examples`, a transfer's legs
// and pelvis (and, as `movement_arms` and `movement_spine` say, its arms and
// spine) move as a take of the style does, registered to the content clip:
// the style clip itself when it shows the same kind of movement, else the
// best-matching take of a style library. `movement = network` (the default)
// leaves the network's output as it is.
struct MovementKeys {
  bool movement_examples = false;
  std::string movement_arms = "layer", movement_spine = "network";
  // A gesture's registration cost (leg lengths) above which the example is
  // taken not to show the content's movement, and not used.
  double movement_max_cost = 1;
  // Steps: the travel mismatch (speed as a log ratio, turning, direction,
  // flight; model/movement.cc) above which the example is not used.
  double movement_max_mismatch = 1;
  bool movement_fit_stride = true;
  // An example whose action is known (a library take's label, or the
  // package's content guard's reading of it) is used only where its action
  // overlaps the content's as the guard reads it by at least this much
  // (motion::ActionOverlap): a stream's last seconds, a transfer's whole
  // content clip. 0: no gate; above 0 the package needs its content guard.
  double movement_action_gate = 0;
};
std::optional<absl::Status> ParseMovementKey(const ConfigEntry& e, MovementKeys* keys);
// Appends the keys (nothing when movement comes from the network).
void AppendMovementKeys(const MovementKeys& keys, std::string* out);
// The keys' names (all inference keys).
const std::vector<std::string>& MovementKeyNames();

// INVALID_ARGUMENT naming the line when `e` is one of `removed`: keys of
// experiments that no shipped package used and that were taken out
// (docs/config.md lists them and what they gave); nullopt otherwise.
std::optional<absl::Status> RefuseRemovedKey(const ConfigEntry& e,
                                             const std::vector<std::string>& removed);

// Calls `handle` for every non-empty, non-comment line; stops at the first
// error (a line without '=' is one).
absl::Status ParseConfigText(const std::string& text, const std::string& source,
                             const std::function<absl::Status(const ConfigEntry&)>& handle);

// Appends "key = value\n".
void AppendConfigLine(std::string* out, absl::string_view key, absl::string_view value);

// The text of <dir>/config.txt: NOT_FOUND when the directory or file is
// missing.
absl::StatusOr<std::string> ReadConfigText(const std::string& dir);
// <dir>/config.txt parsed by `Config::Parse`, then the lines of `overrides`
// as if they followed it. NOT_FOUND when the directory or file is missing.
template <typename Config>
absl::StatusOr<Config> ReadConfig(const std::string& dir, const std::string& overrides) {
  absl::StatusOr<std::string> text = ReadConfigText(dir);
  if (!text.ok()) return text.status();
  return Config::Parse(*text + "\n" + overrides, dir + "/config.txt");
}

// The `family` its config.txt names (INVALID_ARGUMENT naming the file when
// there is none).
absl::StatusOr<std::string> ReadConfigFamily(const std::string& dir);

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONFIG_TEXT_H_
