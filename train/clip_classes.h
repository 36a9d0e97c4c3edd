// The style and content labels of a training set's clips (from their Bandai
// file names), and the reference clips label-guided training draws from them.
#ifndef STYLUS_TRAIN_CLIP_CLASSES_H_
#define STYLUS_TRAIN_CLIP_CLASSES_H_

#include <optional>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "train/training_set.h"

namespace stylus::model {

struct ClipClasses {
  std::vector<std::string> styles, contents;     // Sorted, unique.
  std::vector<int> style_of, content_of;         // Per clip: index into styles / contents.
  std::vector<std::vector<int>> clips_of_style;  // The clips references are drawn from.

  // INVALID_ARGUMENT naming the first path that is not a labelled Bandai
  // name ("dataset-N_{content}_{style}_{take}.bvh"). Clips whose `usable` is
  // false (e.g. shorter than a window) are labelled but never drawn.
  static absl::StatusOr<ClipClasses> FromPaths(const std::vector<std::string>& paths,
                                               const std::vector<bool>& usable);
  // The same from labels given per clip (TrainingSet::labels); `paths` name
  // the clips in errors.
  static absl::StatusOr<ClipClasses> FromLabels(
      const std::vector<std::string>& paths,
      const std::vector<std::optional<motion::ClipLabel>>& labels, const std::vector<bool>& usable);

  // The classes of a training set's clips for windows of `window` frames
  // (shorter clips are never drawn); logs the class counts through `log`.
  static absl::StatusOr<ClipClasses> ForTraining(
      const TrainingSet& data, int window, const std::function<void(const std::string&)>& log);

  // A usable clip of the same style as `clip` doing something else; another
  // clip of that style when all of them do the same; `clip` itself when it is
  // alone.
  int SameStyle(int clip, std::mt19937_64* rng) const;
  // A usable clip of another style (the style uniformly among those with
  // usable clips, then one of its clips, preferring another content); `clip`
  // when there is no other.
  int OtherStyle(int clip, std::mt19937_64* rng) const;
  // A usable clip of style `style` doing `clip`'s action; -1 when there is
  // none.
  int SameContentInStyle(int clip, int style, std::mt19937_64* rng) const;
};

// Reweights `data`'s window draws so that a content class with n windows
// comes up in proportion to n^(1 - power) (TrainingSet::BalanceWindows) and
// returns a log line naming the classes drawn least and most often.
std::string BalanceContents(const ClipClasses& classes, double power, TrainingSet* data);

// The classes of a label-guided run (ClipClasses::ForTraining) for windows
// of `window` frames, with `data`'s draws balanced by `content_balance`
// (BalanceContents, logged) when it is above 0.
absl::StatusOr<ClipClasses> GuidedClasses(TrainingSet* data, int window, double content_balance,
                                          const std::function<void(const std::string&)>& log);

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_CLIP_CLASSES_H_
