#include "train/clip_classes.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "motion/dataset.h"
#include "train/training_run.h"

namespace stylus::model {
namespace {

int IndexOf(const std::vector<std::string>& names, const std::string& name) {
  return static_cast<int>(std::lower_bound(names.begin(), names.end(), name) - names.begin());
}

// A uniformly chosen element of `items` that passes `keep`, else of `items`.
template <typename Keep>
int PickPreferring(const std::vector<int>& items, Keep keep, std::mt19937_64* rng) {
  std::vector<int> kept;
  for (int i : items)
    if (keep(i)) kept.push_back(i);
  const std::vector<int>& from = kept.empty() ? items : kept;
  return from[(*rng)() % from.size()];
}

}  // namespace

absl::StatusOr<ClipClasses> ClipClasses::FromPaths(const std::vector<std::string>& paths,
                                                   const std::vector<bool>& usable) {
  std::vector<std::optional<motion::ClipLabel>> labels;
  for (const std::string& p : paths) labels.push_back(motion::ParseClipName(p));
  return FromLabels(paths, labels, usable);
}

absl::StatusOr<ClipClasses> ClipClasses::FromLabels(
    const std::vector<std::string>& paths,
    const std::vector<std::optional<motion::ClipLabel>>& clip_labels,
    const std::vector<bool>& usable) {
  ClipClasses c;
  std::vector<motion::ClipLabel> labels;
  for (size_t i = 0; i < paths.size(); ++i) {
    const std::optional<motion::ClipLabel>& label =
        i < clip_labels.size() ? clip_labels[i] : std::nullopt;
    if (!label) {
      return absl::InvalidArgumentError(
          paths[i] +
          ": this clip has no labels: name it dataset-N_{content}_{style}_{take}.bvh "
          "(stylus-tool train also reads them from --labels FILE.csv)");
    }
    labels.push_back(*label);
    c.styles.push_back(label->style);
    c.contents.push_back(label->content);
  }
  for (std::vector<std::string>* names : {&c.styles, &c.contents}) {
    std::sort(names->begin(), names->end());
    names->erase(std::unique(names->begin(), names->end()), names->end());
  }
  c.clips_of_style.resize(c.styles.size());
  for (size_t i = 0; i < labels.size(); ++i) {
    c.style_of.push_back(IndexOf(c.styles, labels[i].style));
    c.content_of.push_back(IndexOf(c.contents, labels[i].content));
    if (i < usable.size() && usable[i])
      c.clips_of_style[c.style_of.back()].push_back(static_cast<int>(i));
  }
  return c;
}

absl::StatusOr<ClipClasses> ClipClasses::ForTraining(
    const TrainingSet& data, int window, const std::function<void(const std::string&)>& log) {
  std::vector<bool> usable;
  for (const motion::FeatureClip& clip : data.clips) usable.push_back(clip.frames >= window);
  absl::StatusOr<ClipClasses> c = FromLabels(data.paths, data.labels, usable);
  if (c.ok()) {
    LogLine(log, absl::StrCat("label-guided: ", c->styles.size(), " styles, ", c->contents.size(),
                              " contents"));
  }
  return c;
}

int ClipClasses::SameStyle(int clip, std::mt19937_64* rng) const {
  std::vector<int> others;
  for (int i : clips_of_style[style_of[clip]])
    if (i != clip) others.push_back(i);
  if (others.empty()) return clip;
  return PickPreferring(
      others, [&](int i) { return content_of[i] != content_of[clip]; }, rng);
}

int ClipClasses::OtherStyle(int clip, std::mt19937_64* rng) const {
  std::vector<int> others;
  for (size_t s = 0; s < styles.size(); ++s)
    if (static_cast<int>(s) != style_of[clip] && !clips_of_style[s].empty())
      others.push_back(static_cast<int>(s));
  if (others.empty()) return clip;
  const int style = others[(*rng)() % others.size()];
  return PickPreferring(
      clips_of_style[style], [&](int i) { return content_of[i] != content_of[clip]; }, rng);
}

int ClipClasses::SameContentInStyle(int clip, int style, std::mt19937_64* rng) const {
  std::vector<int> found;
  for (int i : clips_of_style[style]) {
    if (content_of[i] == content_of[clip]) found.push_back(i);
  }
  return found.empty() ? -1 : found[(*rng)() % found.size()];
}

std::string BalanceContents(const ClipClasses& classes, double power, TrainingSet* data) {
  const std::vector<double> share = data->BalanceWindows(classes.content_of, power);
  const auto [lo, hi] = std::minmax_element(share.begin(), share.end());
  return absl::StrFormat("content balance %g: %s drawn %.1f%% of the time, %s %.1f%%", power,
                         classes.contents[lo - share.begin()], 100 * *lo,
                         classes.contents[hi - share.begin()], 100 * *hi);
}

absl::StatusOr<ClipClasses> GuidedClasses(TrainingSet* data, int window, double content_balance,
                                          const std::function<void(const std::string&)>& log) {
  absl::StatusOr<ClipClasses> classes = ClipClasses::ForTraining(*data, window, log);
  if (!classes.ok()) return classes.status();
  if (content_balance > 0) LogLine(log, BalanceContents(*classes, content_balance, data));
  return classes;
}

}  // namespace stylus::model
