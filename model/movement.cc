#include "model/movement.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

#include "absl/strings/str_cat.h"
#include "model/config_text.h"
#include "model/style_model.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/resample.h"
#include "motion/retarget.h"

namespace stylus::model {
namespace fs = std::filesystem;

absl::StatusOr<std::unique_ptr<StyleLibrary>> StyleLibrary::Load(
    const std::string& dir, const std::string& labels_csv,
    const std::vector<std::string>& exclude) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    return absl::NotFoundError(absl::StrCat("style library ", dir, ": not a folder"));
  }
  absl::StatusOr<std::map<std::string, motion::ClipLabel>> csv = motion::ReadLabelsCsv(labels_csv);
  if (!csv.ok()) return csv.status();
  const std::set<std::string> left_out(exclude.begin(), exclude.end());
  std::vector<std::string> files;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    if (it->is_regular_file() && it->path().extension() == ".bvh") {
      files.push_back(it->path().string());
    }
  }
  if (ec) return absl::NotFoundError(absl::StrCat("style library ", dir, ": ", ec.message()));
  std::sort(files.begin(), files.end());
  auto lib = std::unique_ptr<StyleLibrary>(new StyleLibrary);
  lib->dir_ = dir;
  for (const std::string& path : files) {
    if (left_out.count(fs::path(path).filename().string())) continue;
    std::optional<motion::ClipLabel> label;
    if (auto it = csv->find(motion::CanonicalPath(path)); it != csv->end()) {
      label = it->second;
    } else {
      label = motion::ParseClipName(path);
    }
    if (!label) {
      lib->skipped_.push_back(path +
                              ": no style label (name it dataset-N_{action}_{style}_{take}"
                              ".bvh or list it in a labels CSV)");
      continue;
    }
    absl::StatusOr<motion::Motion> clip = motion::ReadBvhFile(path);
    if (!clip.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("style library take ", path, ": ", clip.status().message()));
    }
    lib->takes_.push_back({path, label->style, label->content});
    lib->clips_.push_back(*std::move(clip));
  }
  if (lib->takes_.empty()) {
    return absl::NotFoundError(
        absl::StrCat("style library ", dir, ": no labelled .bvh take in it"));
  }
  return lib;
}

std::vector<std::string> StyleLibrary::Styles() const {
  std::set<std::string> s;
  for (const LibraryTake& t : takes_) s.insert(t.style);
  return {s.begin(), s.end()};
}

absl::StatusOr<std::shared_ptr<const StyleLibrary::Converted>> StyleLibrary::For(
    const StyleModel& model) const {
  std::lock_guard<std::mutex> lock(mu_);
  if (auto it = converted_.find(model.dir()); it != converted_.end()) return it->second;
  auto out = std::make_shared<Converted>();
  std::map<std::string, int> count;
  for (size_t i = 0; i < takes_.size(); ++i) {
    motion::Motion clip = clips_[i];
    if (!clip.skeleton.SameTopology(model.data().skeleton)) {
      absl::StatusOr<std::unique_ptr<motion::Retargeter>> r =
          model.RetargeterFor(clip, {}, absl::StrCat("style library take ", takes_[i].path));
      if (!r.ok()) return r.status();
      clip = (*r)->ToModel(clip);
    }
    if (!motion::SameRate(clip.frame_time, model.data().frame_time)) {
      clip = motion::Resample(clip, model.data().frame_time);
    }
    absl::StatusOr<motion::MovementClip> read = motion::AnalyzeMovement(clip, model.data().roles);
    if (!read.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("style library take ", takes_[i].path, ": ", read.status().message()));
    }
    out->clips.push_back(std::make_shared<const motion::MovementClip>(*std::move(read)));
    absl::StatusOr<StyleCode> code = model.EncodeStyle(clip);
    if (!code.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("style library take ", takes_[i].path, ": ", code.status().message()));
    }
    std::vector<double> labelled = model.LabelledAction(takes_[i].content);
    out->action.push_back(!labelled.empty() ? std::move(labelled) : code->example_actions);
    std::vector<float>& mean = out->mean_code[takes_[i].style];
    mean.resize(code->values.size(), 0.f);
    for (size_t c = 0; c < mean.size(); ++c) mean[c] += code->values[c];
    ++count[takes_[i].style];
  }
  for (auto& [style, mean] : out->mean_code) {
    for (float& v : mean) v /= count[style];
  }
  converted_[model.dir()] = out;
  return std::shared_ptr<const Converted>(out);
}

std::string NearestLibraryStyle(const StyleLibrary::Converted& converted, const StyleCode& code) {
  std::string best;
  double best_cos = -2;
  for (const auto& [style, mean] : converted.mean_code) {
    double dot = 0, a = 0, b = 0;
    for (size_t c = 0; c < mean.size() && c < code.values.size(); ++c) {
      dot += mean[c] * code.values[c];
      a += mean[c] * mean[c];
      b += code.values[c] * code.values[c];
    }
    const double cosine = dot / std::max(1e-12, std::sqrt(a * b));
    if (cosine > best_cos) best_cos = cosine, best = style;
  }
  return best;
}

namespace {

// Stepping examples are matched on how they travel: the direction in the
// facing frame (a walk back is not a walk forward), the speed (as a log
// ratio), the turning (rad/s) and the share of frames in flight (a run is
// not a walk). nullopt when the directions differ by more
// than kMaxTravelAngle: the example does not show the content's stepping.
constexpr double kMaxTravelAngle = M_PI / 4;
std::optional<double> StepMismatch(const motion::MovementClip& a, const motion::MovementClip& b) {
  const double cosine = std::clamp(motion::Dot(a.travel, b.travel), -1.0, 1.0);
  if (std::acos(cosine) > kMaxTravelAngle) return std::nullopt;
  return std::abs(std::log(std::max(a.step_speed, 1e-3) / std::max(b.step_speed, 1e-3))) +
         2 * std::abs(a.turn_rate - b.turn_rate) + 2 * (1 - cosine) +
         4 * std::abs(a.flight - b.flight);
}

// How well `example` shows `content`'s movement (lower is better), with its
// registration; nullopt and the reason when it does not show it at all.
std::optional<std::pair<double, motion::Registration>> Fit(const motion::MovementClip& content,
                                                           const motion::MovementClip& example,
                                                           const MovementKeys& keys,
                                                           std::string* why) {
  absl::StatusOr<motion::Registration> r = motion::RegisterMovement(content, example);
  if (!r.ok()) {
    *why = std::string(r.status().message());
    return std::nullopt;
  }
  if (r->kind == motion::Registration::Kind::kSteps) {
    const std::optional<double> score = StepMismatch(content, example);
    if (!score) {
      *why = "it steps in another direction than the content (forward, back, sideways)";
      return std::nullopt;
    }
    if (*score > keys.movement_max_mismatch) {
      *why = absl::StrCat("its steps travel unlike the content's (mismatch ", *score,
                          " > movement_max_mismatch ", keys.movement_max_mismatch, ")");
      return std::nullopt;
    }
    return std::make_pair(*score, *std::move(r));
  }
  if (std::string arms; !motion::SameArmAction(content, example, &arms)) {
    *why = absl::StrCat("its arms do another thing: ", arms);
    return std::nullopt;
  }
  if (r->cost > keys.movement_max_cost) {
    *why = absl::StrCat("its gesture does not register to the content's (cost ", r->cost,
                        " > movement_max_cost ", keys.movement_max_cost, ")");
    return std::nullopt;
  }
  return std::make_pair(r->cost, *std::move(r));
}

}  // namespace

absl::StatusOr<std::optional<ChosenExample>> ChooseExample(
    const StyleModel& model, const motion::Motion& content, const std::vector<StyleCode>& styles,
    const std::vector<double>& shares, const MovementKeys& keys, const MovementRequest& request,
    MovementNote* note) {
  *note = MovementNote{};
  size_t main = 0;
  for (size_t k = 1; k < styles.size() && k < shares.size(); ++k) {
    if (shares[k] > shares[main]) main = k;
  }
  absl::StatusOr<motion::MovementClip> read = motion::AnalyzeMovement(content, model.data().roles);
  if (!read.ok()) return read.status();
  ChosenExample chosen;
  chosen.content = std::make_shared<const motion::MovementClip>(*std::move(read));
  const motion::MovementClip& mine = *chosen.content;

  // Every example of the style competes: the style clip and the library's
  // takes of the style; the one that shows the content's movement best wins.
  // With an action gate, only examples of the content's action compete.
  const std::vector<double> content_action =
      keys.movement_action_gate > 0 ? model.ReadAction(content) : std::vector<double>{};
  double best = std::numeric_limits<double>::infinity();
  std::string why;
  auto consider = [&](const std::shared_ptr<const motion::MovementClip>& e, const std::string& name,
                      const std::vector<double>& action) {
    if (const double overlap = motion::ActionOverlap(action, content_action);
        overlap < keys.movement_action_gate) {
      if (why.empty()) {
        why = absl::StrCat(name, ": it shows another action than the content (overlap ", overlap,
                           " < movement_action_gate ", keys.movement_action_gate, ")");
      }
      return;
    }
    std::string reason;
    std::optional<std::pair<double, motion::Registration>> fit = Fit(mine, *e, keys, &reason);
    if (!fit) {
      if (why.empty()) why = absl::StrCat(name, ": ", reason);
      return;
    }
    if (fit->first < best) {
      best = fit->first;
      chosen.example = e;
      chosen.registration = std::move(fit->second);
      note->example = name;
    }
  };
  if (styles[main].example) {
    consider(styles[main].example, "style clip", styles[main].example_actions);
  }
  if (request.library != nullptr) {
    absl::StatusOr<std::shared_ptr<const StyleLibrary::Converted>> lib =
        request.library->For(model);
    if (!lib.ok()) return lib.status();
    const std::string label = !request.style_label.empty()
                                  ? request.style_label
                                  : NearestLibraryStyle(**lib, styles[main]);
    const std::vector<LibraryTake>& takes = request.library->takes();
    int of_style = 0;
    for (size_t i = 0; i < takes.size(); ++i) {
      if (takes[i].style != label) continue;
      ++of_style;
      consider((*lib)->clips[i], fs::path(takes[i].path).filename().string(), (*lib)->action[i]);
    }
    if (of_style == 0) {
      why = absl::StrCat(why.empty() ? "" : why + "; ", "the library has no take of '", label, "'");
    }
  }
  if (chosen.example == nullptr) {
    note->reason = why.empty() ? "no example of the style (no style clip, no library)" : why;
    return std::optional<ChosenExample>();
  }
  note->kind = chosen.registration.kind == motion::Registration::Kind::kSteps ? "steps" : "gesture";
  note->cost = best;
  note->rate = chosen.registration.rate;
  return std::optional<ChosenExample>(std::move(chosen));
}

absl::StatusOr<motion::StreamExamples> ChooseStreamExamples(const StyleModel& model,
                                                            const StyleCode& code,
                                                            const MovementRequest& request,
                                                            std::string* why) {
  motion::StreamExamples out;
  auto take = [&](const std::shared_ptr<const motion::MovementClip>& e, const std::string& name,
                  const std::vector<double>& action) {
    if (e->steps && out.steps.size() < motion::StreamExamples::kMaxTakes) {
      out.steps.push_back(e);
      out.step_names.push_back(name);
      out.step_actions.push_back(action);
    } else if (!e->steps && out.gestures.size() < motion::StreamExamples::kMaxTakes) {
      out.gestures.push_back(e);
      out.gesture_names.push_back(name);
      out.gesture_actions.push_back(action);
    }
  };
  if (code.example) take(code.example, "style clip", code.example_actions);
  std::string label;
  if (request.library != nullptr) {
    absl::StatusOr<std::shared_ptr<const StyleLibrary::Converted>> lib =
        request.library->For(model);
    if (!lib.ok()) return lib.status();
    label = !request.style_label.empty() ? request.style_label : NearestLibraryStyle(**lib, code);
    const std::vector<LibraryTake>& takes = request.library->takes();
    for (size_t i = 0; i < takes.size(); ++i) {
      if (takes[i].style == label) {
        take((*lib)->clips[i], fs::path(takes[i].path).filename().string(), (*lib)->action[i]);
      }
    }
  }
  if (why != nullptr && out.steps.empty() && out.gestures.empty()) {
    *why = request.library == nullptr
               ? "no example of the style (no style clip read, no style library)"
               : absl::StrCat("no take of '", label,
                              "' in the style library steps or "
                              "stands, and the style clip shows neither");
  }
  return out;
}

double StylePace(const ChosenExample& chosen) {
  if (chosen.registration.kind == motion::Registration::Kind::kSteps) {
    return std::max(chosen.content->step_speed, 1e-3) / std::max(chosen.example->step_speed, 1e-3);
  }
  return chosen.registration.rate;
}

absl::StatusOr<motion::MovementResult> ApplyExample(const motion::Motion& network,
                                                    const ChosenExample& chosen,
                                                    const MovementKeys& keys) {
  motion::MovementOptions options;
  options.arms = *motion::ParsePartSource(keys.movement_arms);
  options.spine = *motion::ParsePartSource(keys.movement_spine);
  options.fit_stride = keys.movement_fit_stride;
  return motion::ApplyMovement(network, *chosen.content, *chosen.example, chosen.registration,
                               options);
}

}  // namespace stylus::model
