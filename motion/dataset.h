// The labelled Bandai motion dataset: an index of its clips (content and style
// labels from the file names) and a deterministic train/test split by take.
#ifndef STYLUS_MOTION_DATASET_H_
#define STYLUS_MOTION_DATASET_H_

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace stylus::motion {

struct ClipLabel {
  std::string dataset;  // "dataset-1"
  std::string content;  // "walk"
  std::string style;    // "old"
  int take = 0;         // 1
};

// Parses "dataset-N_{content}_{style}_{take}.bvh" (a directory part is ignored);
// nullopt for other names.
std::optional<ClipLabel> ParseClipName(absl::string_view path);

struct ClipEntry {
  std::string path;
  ClipLabel label;
  bool test = false;  // In the held-out split.
};

struct SplitOptions {
  double test_fraction = 0.1;
  uint64_t seed = 0;
};

struct DatasetIndex {
  std::vector<ClipEntry> clips;      // Sorted by path.
  std::vector<std::string> skipped;  // "path: reason" for .bvh files without a label.

  std::vector<std::string> Contents() const;  // Sorted, unique.
  std::vector<std::string> Styles() const;
  std::vector<const ClipEntry*> Split(bool test) const;
};

// Indexes every .bvh under `dirs` (recursively) and splits it by take, holding
// out round(fraction x n) clips of each group (at least one of two or more):
//  * a (dataset, content, style) with 5 or more takes: takes chosen by a hash of
//    the file name and `seed`;
//  * a content whose styles have fewer takes: the clips of the styles held out
//    least so far (contents in name order, ties by file-name hash), so every
//    style of the dataset is held out about equally often.
// The split never depends on the order files are found. NOT_FOUND when a
// directory is missing or no clip is found.
absl::StatusOr<DatasetIndex> IndexDataset(const std::vector<std::string>& dirs,
                                          const SplitOptions& options = {});

// Labels from a CSV of clip,content,style rows (clip paths relative to the
// CSV's folder; a header line and '#' comments allowed), keyed by each clip's
// canonical path (CanonicalPath). Empty for an empty `csv`; NOT_FOUND when
// it cannot be opened; INVALID_ARGUMENT naming the line of a malformed row.
absl::StatusOr<std::map<std::string, ClipLabel>> ReadLabelsCsv(const std::string& csv);
// `path` made absolute with symbolic links and dots resolved (as it is when
// it does not exist).
std::string CanonicalPath(const std::string& path);

// The Bandai data for tests and tools: $STYLUS_DATA if set, else
// `<project_root>/../shared/data/bandai`; nullopt when that is not a directory.
std::optional<std::string> FindBandaiData(const std::string& project_root);

// 64-bit FNV-1a: a hash that is the same on every platform and run.
uint64_t StableHash(absl::string_view s, uint64_t seed = 0);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_DATASET_H_
