// What a training run reads: BVH clips from folders and files on any
// humanoid rig, brought onto one skeleton and frame rate, with their labels
// when there are any, and a report of what was read and skipped.
#ifndef STYLUS_TRAIN_CLIP_SOURCES_H_
#define STYLUS_TRAIN_CLIP_SOURCES_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/dataset.h"
#include "motion/motion.h"

namespace stylus::model {

struct TrainingDataOptions {
  // A CSV of clip,content,style rows (clip paths relative to the CSV's
  // folder; a header line is allowed): labels for clips whose names carry
  // none (the Bandai names dataset-N_{content}_{style}_{take}.bvh do).
  std::string labels_csv;
  // The package's skeleton: a package directory (its skeleton.bvh, and its
  // norm.txt for the reference pose) or a BVH file. Empty: the first clip's.
  std::string skeleton;
  // Styles whose labelled clips are left out entirely (to test how a model
  // does on a style it has never seen).
  std::vector<std::string> leave_out_styles;
};

struct ClipSources {
  motion::Skeleton skeleton;     // Every clip is on it...
  double frame_time = 1.0 / 30;  // ...at this rate.
  std::vector<motion::Motion> motions;
  std::vector<std::string> paths;
  std::vector<std::optional<motion::ClipLabel>> labels;  // From the name or the CSV.
  std::vector<std::string> skipped;                      // "path: reason".
  int retargeted = 0, resampled = 0, other_rigs = 0;
  int left_out = 0;  // Clips of TrainingDataOptions::leave_out_styles.
  // "read 12 clips (4 retargeted from 2 other rigs, 3 resampled to 30 Hz; 9
  // labelled); skipped 2" and one line per skipped clip.
  std::string Report() const;
};

// Reads `sources` (folders: every .bvh below them, the labelled ones split
// as motion::IndexDataset does, the others all in the training split; .bvh
// paths whole). With `test`, only the held-out split of labelled folders.
// A clip that cannot be read, is on a rig that cannot be mapped, or whose
// rate is outside 24-240 Hz is skipped, not fatal. INVALID_ARGUMENT when no
// clip is left, or the CSV or the skeleton is malformed.
absl::StatusOr<ClipSources> ReadClipSources(const std::vector<std::string>& sources, bool test,
                                            const TrainingDataOptions& options);

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_CLIP_SOURCES_H_
