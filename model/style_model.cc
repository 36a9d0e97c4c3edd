#include "model/style_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "absl/strings/str_cat.h"
#include "model/chunked_streamer.h"
#include "model/content_guard.h"
#include "model/resampling_streamer.h"
#include "model/retargeting_streamer.h"
#include "motion/cadence.h"
#include "motion/features.h"
#include "motion/kinematics.h"
#include "motion/postprocess.h"
#include "motion/resample.h"
#include "motion/rig_roles.h"

namespace stylus::model {

absl::Status CheckStyleMix(const std::vector<StyleCode>& styles, const StyleWeights& weights,
                           int frames, int code_size) {
  if (styles.empty()) return absl::InvalidArgumentError("no style given");
  for (const StyleCode& s : styles) {
    if (static_cast<int>(s.values.size()) != code_size) {
      return absl::InvalidArgumentError(absl::StrCat("style code has ", s.values.size(),
                                                     " values; this model's have ", code_size));
    }
  }
  const bool per_frame = !weights.per_frame.empty();
  if (per_frame && static_cast<int>(weights.per_frame.size()) != frames) {
    return absl::InvalidArgumentError(absl::StrCat("weight schedule has ", weights.per_frame.size(),
                                                   " rows; the content clip has ", frames,
                                                   " frames"));
  }
  for (const auto& row :
       per_frame ? weights.per_frame : std::vector<std::vector<double>>{weights.fixed}) {
    if (row.size() != styles.size()) {
      return absl::InvalidArgumentError(
          absl::StrCat("got ", row.size(), " weights for ", styles.size(), " styles"));
    }
    for (double w : row) {
      if (!std::isfinite(w)) return absl::InvalidArgumentError("style weights must be finite");
    }
  }
  return absl::OkStatus();
}

StyleCode MixStyles(const std::vector<StyleCode>& styles, const std::vector<double>& mix) {
  StyleCode out;
  out.values.assign(styles[0].values.size(), 0.f);
  for (size_t c = 0; c < out.values.size(); ++c) {
    double v = 0;
    for (size_t k = 0; k < styles.size(); ++k) v += mix[k] * styles[k].values[c];
    out.values[c] = static_cast<float>(v);
  }
  return out;
}

StyleModel::~StyleModel() = default;

absl::StatusOr<TransferResult> StyleModel::Transfer(const motion::Motion& content,
                                                    const StyleCode& style,
                                                    const TransferOptions& options) const {
  return Interpolate(content, {style}, StyleWeights{{1.0}, {}}, options);
}

namespace {

// Each style's share: its fixed weight, or its mean weight over the frames.
std::vector<double> StyleShares(const std::vector<StyleCode>& styles, const StyleWeights& weights) {
  std::vector<double> share(styles.size(), 0);
  for (size_t k = 0; k < styles.size(); ++k) {
    if (weights.per_frame.empty()) {
      share[k] = k < weights.fixed.size() ? weights.fixed[k] : 0;
    } else {
      for (const std::vector<double>& row : weights.per_frame) share[k] += row[k];
      share[k] /= weights.per_frame.size();
    }
  }
  return share;
}

// The warp that gives `content` the cadence of the blend of `styles`.
TimeWarpNote StyleTiming(const motion::Motion& content, const std::vector<StyleCode>& styles,
                         const StyleWeights& weights) {
  TimeWarpNote note;
  const std::vector<double> share = StyleShares(styles, weights);
  absl::StatusOr<motion::HumanoidRoles> roles = motion::HumanoidRolesOf(content);
  if (!roles.ok()) {
    note.reason = absl::StrCat("the content clip's roles: ", roles.status().message());
    return note;
  }
  absl::StatusOr<motion::Cadence> cadence = motion::FindCadence(content, *roles);
  if (!cadence.ok()) {
    note.reason = absl::StrCat("the content clip has no cadence: ", cadence.status().message());
    return note;
  }
  note.content_period_s = cadence->period_s;
  // Each style's tempo against the content's, mixed by the styles' shares.
  double ratio = 0, total = 0;
  for (size_t k = 0; k < styles.size(); ++k) {
    if (share[k] <= 0) continue;
    const std::string which = styles.size() == 1 ? "the style clip" : absl::StrCat("style ", k + 1);
    if (!styles[k].cadence) {
      note.reason = absl::StrCat(which, " has no cadence (it neither steps nor repeats)");
      return note;
    }
    absl::StatusOr<double> r = motion::TempoRatio(*cadence, *styles[k].cadence);
    if (!r.ok()) {
      note.reason = std::string(r.status().message());
      return note;
    }
    ratio += share[k] * *r;
    total += share[k];
  }
  if (total <= 0) {
    note.reason = "no style has a weight above 0";
    return note;
  }
  note.style_period_s = note.content_period_s * ratio / total;
  note.ratio = std::clamp(ratio / total, kMinTimeWarp, kMaxTimeWarp);
  note.applied = true;
  return note;
}

}  // namespace

absl::StatusOr<motion::Motion> StyleModel::OnModel(const motion::Motion& clip,
                                                   const motion::JointMap& joint_map) const {
  motion::Motion m = clip;
  if (clip.num_frames > 0 && !clip.skeleton.SameTopology(data().skeleton)) {
    absl::StatusOr<std::unique_ptr<motion::Retargeter>> r =
        RetargeterFor(clip, joint_map, "content clip");
    if (!r.ok()) return r.status();
    m = (*r)->ToModel(clip);
  }
  if (!motion::SameRate(m.frame_time, data().frame_time) && m.num_frames > 0) {
    if (absl::Status s = motion::CheckServedRate(m.frame_time, "content clip"); !s.ok()) return s;
    m = motion::Resample(m, data().frame_time);
  }
  return m;
}

namespace {

// `weights` for `content` played `ratio` times as long: each output
// frame's row the nearest content frame's.
StyleWeights WarpWeights(const StyleWeights& weights, int content_frames, int frames,
                         double ratio) {
  StyleWeights out{weights.fixed, {}};
  for (int k = 0; k < frames && !weights.per_frame.empty(); ++k) {
    const int f = std::clamp(static_cast<int>(std::lround(k / ratio)), 0, content_frames - 1);
    out.per_frame.push_back(weights.per_frame[f]);
  }
  return out;
}

void FillContentTimes(double frame_time, int frames, TimeWarpNote* note) {
  note->content_time_s.resize(frames);
  for (int k = 0; k < frames; ++k) note->content_time_s[k] = k * frame_time / note->ratio;
}

}  // namespace

absl::StatusOr<TransferResult> StyleModel::Interpolate(const motion::Motion& content,
                                                       const std::vector<StyleCode>& styles,
                                                       const StyleWeights& weights,
                                                       const TransferOptions& options) const {
  const int n = content.num_frames;
  std::optional<double> fit_ratio;
  if (options.fit_frames > 0) {
    const double r = n > 1 ? static_cast<double>(options.fit_frames - 1) / (n - 1) : 0;
    if (n < 2 || r < kMinTimeWarp - 1e-9 || r > kMaxTimeWarp + 1e-9) {
      return absl::InvalidArgumentError(
          absl::StrCat("fit_frames ", options.fit_frames, " is not within ", kMinTimeWarp, "-",
                       kMaxTimeWarp, "x the content clip's ", n, " frames"));
    }
    fit_ratio = r;
  }
  if (options.timing == Timing::kContent && !fit_ratio) {
    return InterpolateInContentTime(content, styles, weights, options);
  }
  if (absl::Status s = CheckStyleMix(styles, weights, n, code_size()); !s.ok()) return s;
  if (options.movement_from_examples && moves_from_examples()) {
    // A pace: the content played at the example's pace (or to fit_frames)
    // before the transfer, so the example's steps are played as they were.
    TimeWarpNote note;
    if (fit_ratio) {
      note.ratio = *fit_ratio;
    } else {
      absl::StatusOr<motion::Motion> on_model = OnModel(content, options.joint_map);
      if (!on_model.ok()) return on_model.status();
      MovementNote why;
      absl::StatusOr<std::optional<ChosenExample>> chosen =
          ChooseExample(*this, *on_model, styles, StyleShares(styles, weights), movement_keys(),
                        options.movement, &why);
      if (!chosen.ok()) return chosen.status();
      if (!chosen->has_value()) {
        absl::StatusOr<TransferResult> result =
            InterpolateInContentTime(content, styles, weights, options);
        if (result.ok()) result->warp.reason = absl::StrCat("no example to pace by: ", why.reason);
        return result;
      }
      note.ratio = std::clamp(StylePace(**chosen), kMinTimeWarp, kMaxTimeWarp);
    }
    note.applied = true;
    const motion::Motion warped = motion::TimeWarp(content, note.ratio);
    absl::StatusOr<TransferResult> result = InterpolateInContentTime(
        warped, styles, WarpWeights(weights, n, warped.num_frames, note.ratio), options);
    if (!result.ok()) return result;
    FillContentTimes(content.frame_time, result->motion.num_frames, &note);
    result->warp = std::move(note);
    return result;
  }
  absl::StatusOr<TransferResult> result =
      InterpolateInContentTime(content, styles, weights, options);
  if (!result.ok()) return result;
  if (fit_ratio) {
    result->warp.applied = true;
    result->warp.ratio = *fit_ratio;
  } else {
    result->warp = StyleTiming(content, styles, weights);
  }
  if (result->warp.applied) {
    result->motion = motion::TimeWarp(result->motion, result->warp.ratio);
    FillContentTimes(content.frame_time, result->motion.num_frames, &result->warp);
    if (result->contacts) {
      for (auto& spans : *result->contacts) {
        for (motion::ContactSpan& s : spans) {
          s.begin = std::min(result->motion.num_frames,
                             static_cast<int>(std::lround(s.begin * result->warp.ratio)));
          s.end = std::clamp(static_cast<int>(std::lround(s.end * result->warp.ratio)), s.begin,
                             result->motion.num_frames);
        }
      }
    }
  }
  return result;
}

absl::StatusOr<TransferResult> StyleModel::InterpolateInContentTime(
    const motion::Motion& content, const std::vector<StyleCode>& styles,
    const StyleWeights& weights, const TransferOptions& options) const {
  if (absl::Status s = CheckStyleMix(styles, weights, content.num_frames, code_size()); !s.ok()) {
    return s;
  }
  if (content.num_frames > 0 && !content.skeleton.SameTopology(data().skeleton)) {
    absl::StatusOr<std::unique_ptr<motion::Retargeter>> r =
        RetargeterFor(content, options.joint_map, "content clip");
    if (!r.ok()) return r.status();
    const motion::Motion on_model = (*r)->ToModel(content);
    absl::StatusOr<TransferResult> result =
        InterpolateInContentTime(on_model, styles, weights, options);
    if (!result.ok()) return result.status();
    absl::StatusOr<motion::Motion> back = (*r)->FromModel(result->motion, content);
    if (!back.ok()) return back.status();
    result->motion = *std::move(back);
    return result;
  }
  if (motion::SameRate(content.frame_time, data().frame_time) || content.num_frames == 0) {
    return InterpolateAtModelRate(content, content, styles, weights, options);
  }
  if (absl::Status s = motion::CheckServedRate(content.frame_time, "content clip"); !s.ok()) {
    return s;
  }
  // At the model's rate, each frame's weights those of the content frame
  // nearest it; the output back at the content's rate before
  // post-processing, which reads the contacts of the content as it came.
  const motion::Motion at_model = motion::Resample(content, data().frame_time);
  StyleWeights model_weights{weights.fixed, {}};
  for (int k = 0; k < at_model.num_frames && !weights.per_frame.empty(); ++k) {
    const int f =
        std::min(content.num_frames - 1,
                 static_cast<int>(std::lround(k * at_model.frame_time / content.frame_time)));
    model_weights.per_frame.push_back(weights.per_frame[f]);
  }
  return InterpolateAtModelRate(at_model, content, styles, model_weights, options);
}

absl::StatusOr<TransferResult> StyleModel::InterpolateAtModelRate(
    const motion::Motion& content, const motion::Motion& original,
    const std::vector<StyleCode>& styles, const StyleWeights& weights,
    const TransferOptions& options) const {
  absl::StatusOr<std::unique_ptr<Forms>> forms =
      PrepareTransfer(content, styles, weights, options.batcher);
  if (!forms.ok()) return forms.status();
  TransferResult result;
  const ContentGuard* guard = options.content_guard ? content_guard() : nullptr;
  absl::StatusOr<motion::Motion> out;
  auto normalized = [this](const motion::Motion& clip) -> absl::StatusOr<motion::FeatureClip> {
    absl::StatusOr<motion::FeatureClip> f = motion::ExtractFeatures(clip, data().roles);
    if (f.ok()) data().norm.Normalize(&*f);
    return f;
  };
  int action = -1;  // The content's, as the guard reads it.
  if (guard == nullptr) {
    out = (*forms)->Final(0, nullptr);
  } else {
    // The first form whose action reads as the content's, judged before
    // refinement and post-processing (as `eval` judges raw transfers), so
    // only the chosen form is refined and post-processed.
    absl::StatusOr<motion::FeatureClip> read = normalized(content);
    if (!read.ok()) return read.status();
    action = guard->Classify(*read);
    const GuardKeys& keys = guard_keys();
    const std::vector<double>& strengths = keys.guard_strengths;
    for (size_t step = 0; step <= strengths.size(); ++step) {
      absl::StatusOr<motion::Motion> draft = (*forms)->Draft(step);
      if (!draft.ok()) return draft.status();
      read = normalized(*draft);
      if (!read.ok()) return read.status();
      if (guard->Keeps(*read, action, keys.guard_min_probability) || step == strengths.size()) {
        result.note = TransferNote::Guarded(step, strengths);
        out = (*forms)->Final(step, &*draft);
        break;
      }
    }
  }
  if (!out.ok()) return out.status();
  // Movement from examples: the output's steps are its own, and the feet
  // are planted on its own contacts. The guard reads the moved output too:
  // where the example's movement would change the action, the network's is
  // kept.
  std::optional<std::array<std::vector<motion::ContactSpan>, 4>> own_contacts;
  if (options.movement_from_examples && moves_from_examples()) {
    absl::StatusOr<std::optional<ChosenExample>> chosen =
        ChooseExample(*this, content, styles, StyleShares(styles, weights), movement_keys(),
                      options.movement, &result.movement);
    if (!chosen.ok()) return chosen.status();
    // A paced transfer (the content played at the example's pace) is the
    // example's steps by request: the guard, trained on clips at their own
    // pace, reads slowed content as other actions too often to judge it.
    const bool paced = options.timing == Timing::kStyle || options.fit_frames > 0;
    // The configured parts first; when the guard reads another action in
    // them, the legs and pelvis alone (the arms and spine the network's).
    MovementKeys keys = movement_keys();
    for (int attempt = 0; chosen->has_value() && attempt < 2; ++attempt) {
      absl::StatusOr<motion::MovementResult> moved = ApplyExample(*out, **chosen, keys);
      if (!moved.ok()) return moved.status();
      bool keep = true;
      if (guard != nullptr && !paced) {
        absl::StatusOr<motion::FeatureClip> read = normalized(moved->motion);
        if (!read.ok()) return read.status();
        keep = guard->Keeps(*read, action, guard_keys().guard_min_probability);
      }
      if (keep) {
        result.movement.applied = true;
        if (attempt > 0) result.movement.example += " (legs and pelvis only)";
        *out = std::move(moved->motion);
        own_contacts = std::move(moved->contacts);
        break;
      }
      if (keys.movement_arms == "network" && keys.movement_spine == "network") break;
      keys.movement_arms = keys.movement_spine = "network";
    }
    if (chosen->has_value() && !result.movement.applied) {
      result.movement = MovementNote{};
      result.movement.reason = "the content guard read another action with the example's movement";
    }
  }
  if (&original != &content) {
    *out = motion::Resample(*out, original.frame_time, original.num_frames);
    if (own_contacts) {  // The spans at the original's rate.
      const double scale = content.frame_time / original.frame_time;
      for (auto& spans : *own_contacts) {
        for (motion::ContactSpan& s : spans) {
          s.begin =
              std::clamp(static_cast<int>(std::lround(s.begin * scale)), 0, original.num_frames);
          s.end = std::clamp(static_cast<int>(std::lround(s.end * scale)), s.begin,
                             original.num_frames);
        }
      }
    }
  }
  if (options.post == motion::PostProcessMode::kNone) {
    result.motion = *std::move(out);
  } else {
    motion::PostProcessParams params;
    if (own_contacts) params.contact_spans = &*own_contacts;
    absl::StatusOr<motion::Motion> clean = motion::PostProcess(*out, own_contacts ? *out : original,
                                                               data().roles, options.post, params);
    if (!clean.ok()) return clean.status();
    result.motion = *std::move(clean);
  }
  result.contacts = std::move(own_contacts);
  return result;
}

absl::StatusOr<StyleCode> StyleModel::EncodeStyle(const motion::Motion& clip,
                                                  const motion::JointMap& joint_map) const {
  absl::StatusOr<StyleCode> code = EncodeAnyRigStyle(clip, joint_map);
  if (!code.ok()) return code;
  // The cadence is the rig's own: any rig, any rate.
  if (absl::StatusOr<motion::HumanoidRoles> roles = motion::HumanoidRolesOf(clip); roles.ok()) {
    if (absl::StatusOr<motion::Cadence> c = motion::FindCadence(clip, *roles); c.ok()) {
      code->cadence = *std::move(c);
    }
  }
  return code;
}

std::vector<double> StyleModel::ReadAction(const motion::Motion& clip) const {
  if (content_guard() == nullptr) return {};
  absl::StatusOr<motion::FeatureClip> f = motion::ExtractFeatures(clip, data().roles);
  if (!f.ok()) return {};
  data().norm.Normalize(&*f);
  return ActionProbabilities(*f);
}

std::vector<double> StyleModel::ActionProbabilities(const motion::FeatureClip& normalized) const {
  const ContentGuard* guard = content_guard();
  if (guard == nullptr) return {};
  return guard->Probabilities(normalized);
}

std::vector<double> StyleModel::LabelledAction(const std::string& label) const {
  const ContentGuard* guard = content_guard();
  if (guard == nullptr) return {};
  const std::vector<std::string>& names = guard->contents();
  const auto it = std::find(names.begin(), names.end(), label);
  if (it == names.end()) return {};
  std::vector<double> p(names.size(), 0.0);
  p[it - names.begin()] = 1;
  return p;
}

absl::StatusOr<StyleCode> StyleModel::EncodeAnyRigStyle(const motion::Motion& clip,
                                                        const motion::JointMap& joint_map) const {
  if (clip.num_frames > 0 && !clip.skeleton.SameTopology(data().skeleton)) {
    absl::StatusOr<std::unique_ptr<motion::Retargeter>> r =
        RetargeterFor(clip, joint_map, "style clip");
    if (!r.ok()) return r.status();
    return EncodeAnyRigStyle((*r)->ToModel(clip), {});
  }
  const bool same_rate =
      motion::SameRate(clip.frame_time, data().frame_time) || clip.num_frames == 0;
  if (!same_rate) {
    if (absl::Status s = motion::CheckServedRate(clip.frame_time, "style clip"); !s.ok()) return s;
  }
  const motion::Motion resampled =
      same_rate ? motion::Motion{} : motion::Resample(clip, data().frame_time);
  const motion::Motion& at_model = same_rate ? clip : resampled;
  absl::StatusOr<StyleCode> code = EncodeModelRateStyle(at_model);
  if (!code.ok()) return code;
  // The clip itself, for movement from examples (a clip it cannot read,
  // too short say, gives none: the network's movement is used).
  if (movement_keys().movement_examples) {
    if (absl::StatusOr<motion::MovementClip> read = motion::AnalyzeMovement(at_model, data().roles);
        read.ok()) {
      code->example = std::make_shared<const motion::MovementClip>(*std::move(read));
      if (movement_keys().movement_action_gate > 0) code->example_actions = ReadAction(at_model);
    }
  }
  return code;
}

absl::StatusOr<motion::Motion> StreamClip(
    const StyleModel& model, const motion::Motion& content, const StyleCode& code,
    motion::PostProcessMode post, const MovementRequest& movement,
    std::optional<std::array<std::vector<motion::ContactSpan>, 4>>* contacts) {
  StreamSpec spec;
  spec.style = code;
  spec.skeleton = content.skeleton;
  spec.frame_time = content.frame_time;
  spec.post = post;
  spec.movement = movement;
  absl::StatusOr<std::unique_ptr<FrameStreamer>> stream = model.OpenStream(spec);
  if (!stream.ok()) return stream.status();
  motion::Motion out = motion::RestMotion(content.skeleton, 0, content.frame_time);
  std::vector<std::optional<std::array<bool, 4>>> own;
  auto append = [&](const motion::Motion& m) {
    out.values.insert(out.values.end(), m.values.begin(), m.values.end());
    out.num_frames += m.num_frames;
    for (auto& c : (*stream)->TakeContacts()) own.push_back(c);
  };
  const size_t channels = content.skeleton.num_channels();
  motion::Motion one = motion::RestMotion(content.skeleton, 1, content.frame_time);
  for (int f = 0; f < content.num_frames; ++f) {
    std::copy_n(content.values.begin() + f * channels, channels, one.values.begin());
    absl::StatusOr<motion::Motion> got = (*stream)->Push(one);
    if (!got.ok()) return got.status();
    append(*got);
  }
  absl::StatusOr<motion::Motion> rest = (*stream)->Finish();
  if (!rest.ok()) return rest.status();
  append(*rest);
  if (contacts == nullptr) return out;
  contacts->reset();
  if (own.size() != static_cast<size_t>(content.num_frames) ||
      std::none_of(own.begin(), own.end(), [](const auto& c) { return c.has_value(); })) {
    return out;
  }
  absl::StatusOr<motion::HumanoidRoles> roles = motion::HumanoidRolesOf(content);
  if (!roles.ok()) return roles.status();
  const std::array<std::vector<motion::ContactSpan>, 4> found =
      motion::DetectContactSpans(motion::GlobalPositions(content), *roles, content.fps());
  std::array<std::vector<bool>, 4> flags;
  for (int k = 0; k < 4; ++k) {
    flags[k].assign(content.num_frames, false);
    for (const motion::ContactSpan& span : found[k]) {
      for (int f = span.begin; f < span.end; ++f) flags[k][f] = true;
    }
    for (int f = 0; f < content.num_frames; ++f) {
      if (own[f]) flags[k][f] = (*own[f])[k];
    }
  }
  *contacts = motion::SpansFromFlags(flags, 1);
  return out;
}

absl::StatusOr<std::unique_ptr<FrameStreamer>> StyleModel::OpenStream(
    const StreamSpec& spec) const {
  if (weak_from_this().expired()) {
    return absl::FailedPreconditionError(
        absl::StrCat("model ", dir(), ": streams need a model owned by a std::shared_ptr"));
  }
  if (!spec.skeleton.SameTopology(data().skeleton)) {
    // Checked on the rig's rest pose now; the roles are found again on the
    // stream's first frame.
    absl::StatusOr<std::shared_ptr<const motion::ModelRig>> rig = model_rig();
    if (!rig.ok()) return rig.status();
    const motion::Motion rest = motion::RestMotion(spec.skeleton, 1, spec.frame_time);
    if (absl::StatusOr<std::unique_ptr<motion::Retargeter>> r =
            RetargeterFor(rest, spec.joint_map, "stream");
        !r.ok()) {
      return r.status();
    }
    StreamSpec inner = spec;
    inner.skeleton = data().skeleton;
    absl::StatusOr<std::unique_ptr<FrameStreamer>> s = OpenStream(inner);
    if (!s.ok()) return s.status();
    return std::unique_ptr<FrameStreamer>(new RetargetingStreamer(
        *std::move(s), *rig, spec.skeleton, spec.frame_time, spec.joint_map));
  }
  if (motion::SameRate(spec.frame_time, data().frame_time)) return OpenModelRateStream(spec);
  if (absl::Status s = motion::CheckServedRate(spec.frame_time, "stream"); !s.ok()) return s;
  StreamSpec inner = spec;
  inner.frame_time = data().frame_time;
  absl::StatusOr<std::unique_ptr<FrameStreamer>> s = OpenModelRateStream(inner);
  if (!s.ok()) return s.status();
  motion::Motion empty = motion::RestMotion(spec.skeleton, 0, spec.frame_time);
  return std::unique_ptr<FrameStreamer>(
      new ResamplingStreamer(*std::move(s), empty, data().frame_time));
}

absl::StatusOr<std::shared_ptr<const motion::ModelRig>> StyleModel::model_rig() const {
  std::call_once(rig_once_, [this] {
    rig_ = motion::MakeModelRig(
        data().skeleton,
        motion::MeanFeatureRotations(data().norm.mean, data().skeleton, data().roles.pelvis));
  });
  return rig_;
}

absl::StatusOr<std::unique_ptr<motion::Retargeter>> StyleModel::RetargeterFor(
    const motion::Motion& clip, const motion::JointMap& joint_map, const std::string& what) const {
  absl::StatusOr<std::shared_ptr<const motion::ModelRig>> rig = model_rig();
  if (!rig.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " is on another skeleton than the model's, which cannot retarget: ",
                     rig.status().message()));
  }
  absl::StatusOr<std::unique_ptr<motion::Retargeter>> r =
      motion::Retargeter::Create(*rig, clip.skeleton, clip.frame(0), joint_map);
  if (!r.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " is on another rig than the model's: ", r.status().message()));
  }
  return r;
}

absl::StatusOr<std::unique_ptr<FrameStreamer>> StyleModel::OpenModelRateStream(
    const StreamSpec& spec) const {
  absl::StatusOr<std::unique_ptr<ChunkedStreamer>> s =
      ChunkedStreamer::Create(weak_from_this().lock(), spec);
  if (!s.ok()) return s.status();
  return std::unique_ptr<FrameStreamer>(*std::move(s));
}

}  // namespace stylus::model
