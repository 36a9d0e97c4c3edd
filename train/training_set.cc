#include "train/training_set.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/mirror.h"
#include "motion/rig_roles.h"
#include "train/training_run.h"

namespace stylus::model {
namespace {

// Frames [start, start + length) of `clip`, channels first, into `dst`.
void CopyWindow(const motion::FeatureClip& clip, int start, int length, float* dst) {
  for (int t = 0; t < length; ++t) {
    const float* row = clip.row(start + t);
    for (int k = 0; k < clip.dim; ++k) dst[static_cast<size_t>(k) * length + t] = row[k];
  }
}

}  // namespace

void TrainingSet::SampleBatch(int count, int length, std::mt19937_64* rng, std::vector<float>* out,
                              std::vector<int>* clip_of) const {
  if (clip_of) clip_of->clear();
  const int d = dim();
  out->resize(static_cast<size_t>(count) * d * length);
  std::uniform_int_distribution<size_t> pick(0, windows.size() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int b = 0; b < count; ++b) {
    size_t i;
    if (window_cdf.empty()) {
      i = pick(*rng);
    } else {
      const double u = unit(*rng) * window_cdf.back();
      i = std::min<size_t>(
          std::upper_bound(window_cdf.begin(), window_cdf.end(), u) - window_cdf.begin(),
          windows.size() - 1);
    }
    const Window& w = windows[i];
    const motion::FeatureClip& clip = clips[w.clip];
    if (clip_of) clip_of->push_back(w.clip);
    const int start =
        random_starts ? static_cast<int>((*rng)() % static_cast<uint64_t>(clip.frames - length + 1))
                      : w.start;
    CopyWindow(clip, start, length, out->data() + static_cast<size_t>(b) * d * length);
  }
}

std::vector<double> TrainingSet::BalanceWindows(const std::vector<int>& class_of_clip,
                                                double power) {
  int classes = 0;
  for (int c : class_of_clip) classes = std::max(classes, c + 1);
  std::vector<double> count(classes, 0.0), share(classes, 0.0);
  for (const Window& w : windows) count[class_of_clip[w.clip]] += 1;
  window_cdf.clear();
  double total = 0;
  for (const Window& w : windows) {
    const int c = class_of_clip[w.clip];
    const double weight = std::pow(count[c], -power);
    total += weight;
    share[c] += weight;
    window_cdf.push_back(total);
  }
  for (double& s : share) s /= total;
  return share;
}

void TrainingSet::SampleFromClips(const std::vector<int>& clip_ids, int length,
                                  std::mt19937_64* rng, std::vector<float>* out) const {
  const int d = dim();
  out->resize(clip_ids.size() * d * length);
  for (size_t b = 0; b < clip_ids.size(); ++b) {
    const motion::FeatureClip& clip = clips[clip_ids[b]];
    const int start = static_cast<int>((*rng)() % static_cast<uint64_t>(clip.frames - length + 1));
    CopyWindow(clip, start, length, out->data() + b * d * length);
  }
}

absl::StatusOr<TrainingSet> LoadTrainingSet(const std::vector<std::string>& sources,
                                            const motion::WindowSpec& spec,
                                            const std::function<void(int, int)>& progress,
                                            bool test, const motion::NormStats* fixed_norm,
                                            std::vector<motion::Motion>* motions,
                                            const motion::ContactParams& contacts,
                                            const TrainingDataOptions& data_options,
                                            const std::function<void(const ClipSources&)>& report) {
  absl::StatusOr<ClipSources> read = ReadClipSources(sources, test, data_options);
  if (!read.ok()) return read.status();
  if (report) report(*read);
  TrainingSet set;
  set.skeleton = read->skeleton;
  set.frame_time = read->frame_time;
  absl::StatusOr<motion::HumanoidRoles> roles = motion::HumanoidRolesOf(read->motions[0]);
  if (!roles.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(read->paths[0], ": ", roles.status().message()));
  }
  set.roles = *roles;
  std::vector<const motion::FeatureClip*> raw;
  for (size_t i = 0; i < read->motions.size(); ++i) {
    absl::StatusOr<motion::FeatureClip> f =
        motion::ExtractFeatures(read->motions[i], set.roles, contacts);
    if (!f.ok())
      return absl::InvalidArgumentError(absl::StrCat(read->paths[i], ": ", f.status().message()));
    set.clips.push_back(*std::move(f));
    set.paths.push_back(read->paths[i]);
    set.labels.push_back(read->labels[i]);
    if (progress) progress(static_cast<int>(i + 1), static_cast<int>(read->motions.size()));
  }
  if (motions != nullptr) *motions = std::move(read->motions);
  for (const auto& c : set.clips) raw.push_back(&c);
  const motion::FeatureLayout layout(set.skeleton.num_joints());
  if (fixed_norm != nullptr) {
    if (fixed_norm->dim() != layout.dim()) {
      return absl::InvalidArgumentError(
          "normalization statistics do not match the clips' feature width");
    }
    set.norm = *fixed_norm;
  } else {
    absl::StatusOr<motion::NormStats> norm =
        motion::NormStats::Compute(raw, layout.ChannelNames(set.skeleton, set.roles));
    if (!norm.ok()) return norm.status();
    set.norm = *std::move(norm);
  }
  for (size_t i = 0; i < set.clips.size(); ++i) {
    set.norm.Normalize(&set.clips[i]);
    absl::StatusOr<std::vector<int>> starts = motion::WindowStarts(set.clips[i].frames, spec);
    if (!starts.ok()) return starts.status();
    for (int s : *starts) set.windows.push_back({static_cast<int>(i), s});
  }
  if (set.windows.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("no clip is at least ", spec.length, " frames long"));
  }
  return set;
}

namespace {

// "DIR/mirrored/NAME" for the mirror of the clip at `path` (see
// AddMirroredClips).
std::string MirroredPath(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash);
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  if (std::optional<motion::ClipLabel> l = motion::ParseClipName(path)) {
    name = absl::StrFormat("%s_%s_%s_%03d.bvh", l->dataset, motion::MirrorLabel(l->content),
                           l->style, l->take);
  }
  return dir + "/mirrored/" + name;
}

// Appends the mirrors of `motions` (the set's clips as read, one each) to
// `set` (see LoadTrainingData).
absl::Status AddMirroredClips(const std::vector<motion::Motion>& motions,
                              const motion::WindowSpec& spec, const motion::ContactParams& contacts,
                              TrainingSet* set) {
  std::vector<const motion::Motion*> samples;
  for (const motion::Motion& m : motions) samples.push_back(&m);
  absl::StatusOr<motion::MirrorMap> map = motion::PlanMirror(set->skeleton, samples);
  if (!map.ok()) return map.status();
  const size_t real = set->clips.size();
  for (size_t i = 0; i < real; ++i) {
    absl::StatusOr<motion::FeatureClip> f =
        motion::ExtractFeatures(motion::MirrorMotion(motions[i], *map), set->roles, contacts);
    if (!f.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat(set->paths[i], " (mirrored): ", f.status().message()));
    }
    set->norm.Normalize(&*f);
    absl::StatusOr<std::vector<int>> starts = motion::WindowStarts(f->frames, spec);
    if (!starts.ok()) return starts.status();
    for (int s : *starts) set->windows.push_back({static_cast<int>(set->clips.size()), s});
    set->clips.push_back(*std::move(f));
    set->paths.push_back(MirroredPath(set->paths[i]));
    std::optional<motion::ClipLabel> label = set->labels[i];
    if (label) label->content = motion::MirrorLabel(label->content);
    set->labels.push_back(label);
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<TrainingSet> LoadTrainingData(const std::vector<std::string>& sources,
                                             const motion::WindowSpec& windows,
                                             const std::function<void(const std::string&)>& log,
                                             bool mirror, const motion::ContactParams& contacts,
                                             const TrainingDataOptions& data_options) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<motion::Motion> motions;
  absl::StatusOr<TrainingSet> loaded = LoadTrainingSet(
      sources, windows, {}, false, nullptr, mirror ? &motions : nullptr, contacts, data_options,
      [&log](const ClipSources& read) { LogLine(log, read.Report()); });
  if (!loaded.ok()) return loaded.status();
  if (mirror) {
    if (absl::Status s = AddMirroredClips(motions, windows, contacts, &*loaded); !s.ok()) return s;
  }
  LogLine(log, absl::StrFormat(
                   "loaded %d clips%s, %d windows of %d frames, %d channels in %.1f s",
                   loaded->clips.size(), mirror ? " (half of them mirrored)" : "",
                   loaded->windows.size(), windows.length, loaded->dim(),
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
  return loaded;
}

}  // namespace stylus::model
