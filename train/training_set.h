// Normalized feature windows for training, loaded from BVH clips.
#ifndef STYLUS_TRAIN_TRAINING_SET_H_
#define STYLUS_TRAIN_TRAINING_SET_H_

#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_join.h"
#include "motion/features.h"
#include "motion/humanoid.h"
#include "motion/normalization.h"
#include "motion/windowing.h"
#include "train/clip_sources.h"

namespace stylus::model {

struct TrainingSet {
  motion::Skeleton skeleton;  // Of the first clip; all clips share its topology.
  double frame_time = 1.0 / 30;
  motion::HumanoidRoles roles;
  motion::NormStats norm;                  // Computed over these clips.
  std::vector<motion::FeatureClip> clips;  // Normalized.
  std::vector<std::string> paths;
  // Each clip's labels (from its name or a labels CSV), when it has any.
  std::vector<std::optional<motion::ClipLabel>> labels;
  struct Window {
    int clip, start;
  };
  std::vector<Window> windows;
  // Cumulative sampling weights of `windows` (empty: uniform); see BalanceWindows.
  std::vector<double> window_cdf;
  // With `random_starts`, SampleBatch keeps its draw of a window's clip but
  // starts the window anywhere in that clip. The hop grid alone never shows
  // a clip's last frames when its length is off the grid (a 78-frame raise
  // of a hand: windows at 0 and 24, so the hand is never seen coming down).
  bool random_starts = false;
  int dim() const { return norm.dim(); }

  // Reweights SampleBatch so that a class with n windows (class_of_clip[c]
  // per clip) is drawn in proportion to n^(1 - power): 0 keeps the uniform
  // draw over windows, 1 draws every class alike (windows of a class stay
  // equally likely among themselves). Returns each class's share of draws.
  std::vector<double> BalanceWindows(const std::vector<int>& class_of_clip, double power);

  // Copies `count` windows of `length` frames, chosen by `rng` (uniformly
  // unless BalanceWindows reweighted them; see also random_starts), into
  // `out` as (count, dim, length), channels first; `clips` (if not null) gets
  // the clip index of each.
  void SampleBatch(int count, int length, std::mt19937_64* rng, std::vector<float>* out,
                   std::vector<int>* clips = nullptr) const;
  // For each of `clips`, a window of `length` frames starting anywhere in that
  // clip, chosen by `rng`, in the layout of SampleBatch.
  void SampleFromClips(const std::vector<int>& clips, int length, std::mt19937_64* rng,
                       std::vector<float>* out) const;
};

// Loads the training split of `sources` (train/clip_sources.h: folders and
// .bvh files on any humanoid rig, retargeted onto one skeleton and resampled
// to one rate; clips that cannot be used are skipped and reported), or with
// `test` the held-out split of the labelled folders. Normalizes with `norm`
// when given, else with statistics computed over the loaded clips.
// `progress` (may be empty) is told how many clips are loaded; `report`
// (may be empty) gets what was read and skipped.
// `motions` (if not null) gets the loaded clips as read.
absl::StatusOr<TrainingSet> LoadTrainingSet(
    const std::vector<std::string>& sources, const motion::WindowSpec& windows,
    const std::function<void(int, int)>& progress = {}, bool test = false,
    const motion::NormStats* norm = nullptr, std::vector<motion::Motion>* motions = nullptr,
    const motion::ContactParams& contacts = {}, const TrainingDataOptions& data_options = {},
    const std::function<void(const ClipSources&)>& report = {});

// LoadTrainingSet of the training split for a trainer: logs "loaded N clips,
// W windows of T frames, D channels in S s" through `log` (stderr when
// empty). With `mirror`, left-right mirrored copies of the clips
// (motion/mirror.h) follow them, normalized with the real clips' statistics
// (so a package trained without mirroring can be fine-tuned with it). A
// mirrored clip's path is "DIR/mirrored/NAME", where NAME is its clip's file
// name with the content label's sides swapped ("raise-up-left-hand" ->
// "raise-up-right-hand"): it names no file, only the labels.
// INVALID_ARGUMENT when the skeleton cannot be mirrored.
absl::StatusOr<TrainingSet> LoadTrainingData(const std::vector<std::string>& sources,
                                             const motion::WindowSpec& windows,
                                             const std::function<void(const std::string&)>& log,
                                             bool mirror = false,
                                             const motion::ContactParams& contacts = {},
                                             const TrainingDataOptions& data_options = {});

// A trainer's data: LoadTrainingData of `options.data` in `config`'s windows
// (mirrored with config->mirror, random starts with config->random_starts,
// foot contacts as config->Contacts() says),
// and the provenance it fills into `config` (dim, data, commit).
template <typename Options, typename Config>
absl::StatusOr<TrainingSet> LoadRunData(const Options& options, Config* config) {
  absl::StatusOr<TrainingSet> data =
      LoadTrainingData(options.data, {config->window, config->hop}, options.log, config->mirror,
                       config->Contacts(), options.data_options);
  if (!data.ok()) return data.status();
  data->random_starts = config->random_starts;
  config->dim = data->dim();
  config->data = absl::StrJoin(options.data, ";");
  config->commit = options.commit;
  return data;
}

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_TRAINING_SET_H_
