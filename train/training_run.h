// The bookkeeping every trainer shares: progress lines (iteration, each loss,
// it/s, ETA), the loss curve as CSV, checkpoints swapped in atomically under
// <out>/checkpoint, and resuming from them (iteration, RNG state, curve; the
// trainer loads its own tensors). Torch-free; the trainer supplies callbacks.
#ifndef STYLUS_TRAIN_TRAINING_RUN_H_
#define STYLUS_TRAIN_TRAINING_RUN_H_

#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"

namespace stylus::model {

// Loss values by name (TrainingRun::Spec::loss_names).
using Losses = std::map<std::string, double>;

// Mean losses over the iterations since the previous row.
struct LossRow {
  int iteration = 0;
  Losses values;  // Every name of TrainingRun::Spec::loss_names.
  // The value of loss `name` (0 when the run has no such loss).
  double Get(const std::string& name) const {
    const auto it = values.find(name);
    return it == values.end() ? 0 : it->second;
  }
};

// Writes a progress line to `log`, or to stderr when `log` is empty.
void LogLine(const std::function<void(const std::string&)>& log, const std::string& line);

class TrainingRun {
 public:
  struct Spec {
    std::string out;  // Package directory; the checkpoint goes to out/checkpoint.
    std::vector<std::string> loss_names;  // The losses a step reports; loss.csv's columns.
    std::string config_text;              // Saved with the checkpoint; compared on resume.
    int iterations = 0;
    int log_every = 50, checkpoint_every = 500;
    std::function<void(const std::string&)> log;    // Default: stderr.
    std::function<void(const LossRow&)> on_record;  // May be empty.
    // Writes the trainer's tensors (network, optimizer) into a directory.
    std::function<absl::Status(const std::string& dir)> save_tensors;
    // Reads them back from a checkpoint directory.
    std::function<absl::Status(const std::string& dir)> load_tensors;
    // Writes the package (config with `iterations` trained, weights) into out
    // with `csv` as loss.csv.
    std::function<absl::Status(int iterations, const std::string& csv)> write_package;
  };

  explicit TrainingRun(Spec spec) : spec_(std::move(spec)) {}

  // Continues from out/checkpoint when it exists (FAILED_PRECONDITION when it
  // was made with another configuration text, `comparable` applied to both;
  // DATA_LOSS when unreadable); logs and starts from scratch otherwise.
  absl::Status Resume(const std::function<std::string(const std::string&)>& comparable);

  // Runs `step` (returning a value for every loss name, and no other) up to
  // `iterations`, logging, checkpointing and writing the package at the end.
  // INTERNAL when a loss becomes non-finite or a step reports other losses.
  absl::Status Run(const std::function<Losses(int iteration)>& step);

  std::mt19937_64& rng() { return rng_; }
  int iteration() const { return iteration_; }
  void Log(const std::string& line) const { LogLine(spec_.log, line); }

 private:
  absl::Status SaveCheckpoint();
  std::string Csv() const;

  Spec spec_;
  std::mt19937_64 rng_;
  int iteration_ = 0;
  std::vector<LossRow> curve_;
};

// INVALID_ARGUMENT when averaging from iteration `from` would start after
// the run's last (`iterations`).
inline absl::Status CheckAveraging(int from, int iterations) {
  if (from <= iterations) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat("weight averaging from iteration ", from,
                                                 " would start after the last iteration (",
                                                 iterations, ")"));
}

// The checks every trainer makes of its options and `config` (a family's
// config) before it starts: INVALID_ARGUMENT for no output directory, no
// data, non-positive batch or intervals, weight averaging past the last
// iteration, or label-guided keys without `guided`.
template <typename Options, typename Config>
absl::Status CheckTrainingOptions(const Options& options, const Config& config) {
  if (options.out.empty()) return absl::InvalidArgumentError("no output directory (--out)");
  if (options.data.empty()) return absl::InvalidArgumentError("no training data (--data)");
  if (config.batch <= 0 || options.log_every <= 0 || options.checkpoint_every <= 0) {
    return absl::InvalidArgumentError("batch, log and checkpoint intervals must be positive");
  }
  if (absl::Status s = CheckAveraging(config.average_from, config.iterations); !s.ok()) return s;
  if (config.pair_gan && !config.guided) {
    return absl::InvalidArgumentError("the label-conditional discriminator needs --guided");
  }
  if (config.content_balance > 0 && !config.guided) {
    return absl::InvalidArgumentError("content balance needs label-guided training (--guided)");
  }
  return absl::OkStatus();
}

// What TrainingRun::Resume compares a checkpoint's configuration by: the
// text of `Config` (a family's config) with the iteration counts cleared, so
// a resumed run may go longer.
template <typename Config>
std::string ComparableConfigText(const std::string& text) {
  absl::StatusOr<Config> c = Config::Parse(text, "checkpoint");
  if (!c.ok()) return "unreadable: " + std::string(c.status().message());
  c->iterations = c->trained_iterations = 0;
  return c->Serialize();
}

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_TRAINING_RUN_H_
