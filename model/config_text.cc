#include "model/config_text.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace stylus::model {

absl::Status ConfigEntry::Error(absl::string_view what) const {
  return absl::InvalidArgumentError(absl::StrCat(source, ":", line, ": ", what));
}

absl::Status ConfigEntry::Int(int* out, int lo, int hi) const {
  if (!absl::SimpleAtoi(value, out) || *out < lo || *out > hi) {
    return Error(absl::StrCat(key, " must be a whole number in [", lo, ", ", hi, "]"));
  }
  return absl::OkStatus();
}

absl::Status ConfigEntry::Double(double* out, double lo, double hi) const {
  if (!absl::SimpleAtod(value, out) || !(*out >= lo && *out <= hi)) {
    return Error(absl::StrCat(key, " must be a number in [", lo, ", ", hi, "]"));
  }
  return absl::OkStatus();
}

absl::Status ConfigEntry::Bool(bool* out) const {
  if (value != "0" && value != "1") return Error(key + " must be 0 or 1");
  *out = value == "1";
  return absl::OkStatus();
}

absl::Status ConfigEntry::Uint64(uint64_t* out) const {
  if (!absl::SimpleAtoi(value, out)) return Error(key + " must be a whole number");
  return absl::OkStatus();
}

std::optional<absl::Status> ParseTrainingKey(const ConfigEntry& e, const TrainingKeys& keys) {
  if (e.key == "batch") return e.Int(keys.batch, 1, 1 << 20);
  if (e.key == "lr") return e.Double(keys.lr, 0, 10);
  if (e.key == "iterations") return e.Int(keys.iterations, 0, 1 << 30);
  if (e.key == "trained_iterations") return e.Int(keys.trained_iterations, 0, 1 << 30);
  if (e.key == "seed") return e.Uint64(keys.seed);
  if (e.key == "data") return *keys.data = e.value, absl::OkStatus();
  if (e.key == "commit") return *keys.commit = e.value, absl::OkStatus();
  return std::nullopt;
}

absl::Status ParseConfigText(const std::string& text, const std::string& source,
                             const std::function<absl::Status(const ConfigEntry&)>& handle) {
  ConfigEntry e;
  e.source = source;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++e.line;
    line = absl::StripAsciiWhitespace(line);
    if (line.empty() || line[0] == '#') continue;
    const size_t eq = line.find('=');
    if (eq == absl::string_view::npos) return e.Error("expected 'key = value'");
    e.key = std::string(absl::StripAsciiWhitespace(line.substr(0, eq)));
    e.value = std::string(absl::StripAsciiWhitespace(line.substr(eq + 1)));
    if (absl::Status s = handle(e); !s.ok()) return s;
  }
  return absl::OkStatus();
}

void AppendConfigLine(std::string* out, absl::string_view key, absl::string_view value) {
  absl::StrAppend(out, key, " = ", value, "\n");
}

absl::StatusOr<std::string> ReadConfigText(const std::string& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    return absl::NotFoundError(absl::StrCat(dir, ": no such model directory"));
  const std::string path = dir + "/config.txt";
  std::ifstream f(path);
  if (!f) return absl::NotFoundError(absl::StrCat(path, ": missing"));
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

absl::StatusOr<std::string> ReadConfigFamily(const std::string& dir) {
  absl::StatusOr<std::string> text = ReadConfigText(dir);
  if (!text.ok()) return text.status();
  std::string family;
  absl::Status s = ParseConfigText(*text, dir + "/config.txt", [&](const ConfigEntry& e) {
    if (e.key == "family") family = e.value;
    return absl::OkStatus();
  });
  if (!s.ok()) return s;
  if (family.empty()) return absl::InvalidArgumentError(dir + "/config.txt: no 'family' line");
  return family;
}

namespace {

absl::Status ParseGuardStrengths(const ConfigEntry& e, std::vector<double>* out) {
  std::vector<double> values;
  for (absl::string_view part : absl::StrSplit(e.value, ',')) {
    double v;
    if (!absl::SimpleAtod(absl::StripAsciiWhitespace(part), &v) || !(v >= 0 && v <= 1)) {
      return e.Error("guard_strengths must be numbers in [0, 1] separated by commas");
    }
    if (!values.empty() && v >= values.back()) {
      return e.Error("guard_strengths must fall from one to the next");
    }
    values.push_back(v);
  }
  if (values.empty() || values.size() > 8) return e.Error("guard_strengths takes 1 to 8 values");
  *out = std::move(values);
  return absl::OkStatus();
}

}  // namespace

std::optional<absl::Status> ParseGuardKey(const ConfigEntry& e, GuardKeys* keys) {
  if (e.key == "content_guard") return e.Bool(&keys->content_guard);
  if (e.key == "guard_strengths") return ParseGuardStrengths(e, &keys->guard_strengths);
  if (e.key == "guard_min_probability") return e.Double(&keys->guard_min_probability, 0, 1);
  return std::nullopt;
}

void AppendGuardKeys(const GuardKeys& keys, std::string* out) {
  if (!keys.content_guard) return;
  AppendConfigLine(out, "content_guard", "1");
  AppendConfigLine(out, "guard_strengths", absl::StrJoin(keys.guard_strengths, ","));
  if (keys.guard_min_probability > 0) {
    AppendConfigLine(out, "guard_min_probability", absl::StrCat(keys.guard_min_probability));
  }
}

std::optional<absl::Status> ParseMovementKey(const ConfigEntry& e, MovementKeys* keys) {
  if (e.key == "movement") {
    if (e.value != "network" && e.value != "examples") {
      return e.Error("movement is 'network' or 'examples'");
    }
    keys->movement_examples = e.value == "examples";
    return absl::OkStatus();
  }
  if (e.key == "movement_arms" || e.key == "movement_spine") {
    if (e.value != "network" && e.value != "example" && e.value != "layer") {
      return e.Error(absl::StrCat(e.key, " is 'network', 'example' or 'layer'"));
    }
    (e.key == "movement_arms" ? keys->movement_arms : keys->movement_spine) = e.value;
    return absl::OkStatus();
  }
  if (e.key == "movement_max_cost") return e.Double(&keys->movement_max_cost, 0, 100);
  if (e.key == "movement_max_mismatch") return e.Double(&keys->movement_max_mismatch, 0, 100);
  if (e.key == "movement_fit_stride") return e.Bool(&keys->movement_fit_stride);
  if (e.key == "movement_action_gate") return e.Double(&keys->movement_action_gate, 0, 1);
  return std::nullopt;
}

const std::vector<std::string>& GuardKeyNames() {
  static const std::vector<std::string>* names =
      new std::vector<std::string>{"content_guard", "guard_strengths", "guard_min_probability"};
  return *names;
}

const std::vector<std::string>& MovementKeyNames() {
  static const std::vector<std::string>* names =
      new std::vector<std::string>{"movement",
                                   "movement_arms",
                                   "movement_spine",
                                   "movement_max_cost",
                                   "movement_max_mismatch",
                                   "movement_fit_stride",
                                   "movement_action_gate"};
  return *names;
}

void AppendMovementKeys(const MovementKeys& keys, std::string* out) {
  if (!keys.movement_examples) return;
  AppendConfigLine(out, "movement", "examples");
  AppendConfigLine(out, "movement_arms", keys.movement_arms);
  AppendConfigLine(out, "movement_spine", keys.movement_spine);
  AppendConfigLine(out, "movement_max_cost", absl::StrCat(keys.movement_max_cost));
  AppendConfigLine(out, "movement_max_mismatch", absl::StrCat(keys.movement_max_mismatch));
  if (!keys.movement_fit_stride) AppendConfigLine(out, "movement_fit_stride", "0");
  if (keys.movement_action_gate > 0) {
    AppendConfigLine(out, "movement_action_gate", absl::StrCat(keys.movement_action_gate));
  }
}

std::optional<absl::Status> RefuseRemovedKey(const ConfigEntry& e,
                                             const std::vector<std::string>& removed) {
  for (const std::string& key : removed) {
    if (e.key == key) {
      return e.Error(absl::StrCat("'", key,
                                  "' was an experiment this version no longer has (docs/config.md, "
                                  "removed keys); delete the line"));
    }
  }
  return std::nullopt;
}

}  // namespace stylus::model
