#include "model/contrastive/live_streamer.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "model/movement.h"
#include "motion/resample.h"

namespace stylus::model {
namespace {

// Output frames re-cleaned with each new one: enough for a contact span's
// start (three frames at the model's 30 Hz) and the smoothing of rotations
// over +-2 frames.
constexpr int kCleanHistory = 6;
// Own contacts kept for TakeContacts when nobody takes them.
constexpr size_t kMaxKeptContacts = 256;
// The action gate: the content's action is read every kActionEvery output
// frames from its last kActionRows feature rows (about 4 s at 30 Hz; 2 s
// read a little worse on the validation pairs), once it has kMinActionRows.
constexpr int kActionEvery = 8, kActionRows = 128, kMinActionRows = 16;

// The schedule keeps codes only; the takes chosen hold the style clip's
// reading.
StyleCode WithoutExample(StyleCode code) {
  code.example = nullptr;
  return code;
}

}  // namespace

absl::StatusOr<std::unique_ptr<LiveStreamer>> LiveStreamer::Create(
    std::shared_ptr<const ContrastiveModel> model, const StreamSpec& spec) {
  if (!model) return absl::InvalidArgumentError("no model");
  if (!model->config().live) {
    return absl::FailedPreconditionError(
        absl::StrCat("model ", model->dir(), " is not a live package"));
  }
  absl::StatusOr<std::vector<float>> params = model->LiveStyleParams(spec.style);
  if (!params.ok()) return params.status();
  motion::Motion probe = motion::RestMotion(spec.skeleton, 1, spec.frame_time);
  if (absl::Status s = CheckClipFitsModel(probe, model->data(), "stream"); !s.ok()) return s;
  probe.num_frames = 0;
  probe.values.clear();
  std::shared_ptr<const motion::StreamExamples> examples;
  if (model->moves_from_examples()) {
    absl::StatusOr<motion::StreamExamples> chosen =
        ChooseStreamExamples(*model, spec.style, spec.movement);
    if (!chosen.ok()) return chosen.status();
    examples = std::make_shared<const motion::StreamExamples>(*std::move(chosen));
  }
  return std::unique_ptr<LiveStreamer>(new LiveStreamer(
      std::move(model), probe, spec.style, *std::move(params), spec.post, std::move(examples)));
}

LiveStreamer::LiveStreamer(std::shared_ptr<const ContrastiveModel> model,
                           const motion::Motion& empty, StyleCode style, std::vector<float> params,
                           motion::PostProcessMode post,
                           std::shared_ptr<const motion::StreamExamples> examples)
    : model_(std::move(model)),
      dim_(model_->config().dim),
      shift_(model_->config().lookahead - 1),
      lookahead_(model_->config().lookahead),
      schedule_(WithoutExample(std::move(style)), model_->config().style_strength),
      params_(std::move(params)),
      strength_(model_->config().style_strength),
      features_(empty.skeleton, model_->data().roles, empty.frame_time,
                model_->config().Contacts()),
      carry_(model_->NewLiveCarry()),
      out_(dim_),
      input_(empty),
      empty_(empty),
      cleaner_(model_->data().roles, post, kCleanHistory) {
  generated_.dim = dim_;
  if (examples) {
    const MovementKeys& keys = model_->config();
    follow_.parts.arms = *motion::ParsePartSource(keys.movement_arms);
    follow_.parts.spine = *motion::ParsePartSource(keys.movement_spine);
    follow_.parts.fit_stride = keys.movement_fit_stride;
    follow_.max_cost = keys.movement_max_cost;
    follow_.max_mismatch = keys.movement_max_mismatch;
    follow_.action_gate = keys.movement_action_gate;
    track_.emplace(empty.skeleton, model_->data().roles, empty.frame_time, lookahead_);
    contacts_.reserve(2 * kMaxKeptContacts);
    follower_ = std::make_unique<motion::MovementFollower>(*examples, *track_, follow_);
    step_style_.examples = std::move(examples);
  }
}

absl::Status LiveStreamer::Feed(const motion::Motion& frames, bool end) {
  const int channels = input_.skeleton.num_channels();
  for (size_t i = 0; i < frames.values.size(); ++i) {
    if (!std::isfinite(frames.values[i])) {
      return absl::InvalidArgumentError(absl::StrCat(
          "frame ", received_ + static_cast<int64_t>(i / channels), " has a non-finite value"));
    }
  }
  if (ended_ && frames.num_frames > 0) return absl::FailedPreconditionError("the stream has ended");
  std::vector<float> row(dim_);
  for (int f = 0; f < frames.num_frames; ++f) {
    const double* frame = frames.values.data() + static_cast<size_t>(f) * channels;
    if (received_ == 0) {
      // The output starts where the content does, as in a whole-clip transfer.
      motion::Motion first = input_;
      first.num_frames = 1;
      first.values.assign(frame, frame + channels);
      decode_.root = motion::RootAt(first, model_->data().roles, 0);
    }
    input_.values.insert(input_.values.end(), frame, frame + channels);
    ++input_.num_frames;
    ++received_;
    if (track_) track_->Add(motion::PoseAt(input_, input_.num_frames - 1));
    if (features_.Push(frame, row.data())) {
      model_->data().norm.Normalize(row.data());
      queue_.push_back(row);
      if (follow_.action_gate > 0) {  // Trimmed by Trim(), as the frames held.
        action_rows_.push_back(row);
        ++action_rows_end_;
      }
    }
  }
  if (end && !ended_) {
    if (received_ == 0) return absl::FailedPreconditionError("the stream has no frames");
    ended_ = true;
    if (features_.Finish(row.data())) {
      model_->data().norm.Normalize(row.data());
      // The look-ahead past the last frame: the last frame repeated, as in a
      // whole-clip pass.
      for (int k = 0; k <= shift_; ++k) queue_.push_back(row);
    }
  }
  return absl::OkStatus();
}

bool LiveStreamer::NextStep(LiveStep* step) {
  if (queue_.empty()) return false;
  const int64_t frame = stepped_ - shift_;  // The frame this step generates.
  if (frame >= 0) {
    const StyleSchedule::At at = schedule_.Advance(frame);
    if (at.changed) {
      // Checked when the change was queued: the code fits the model.
      absl::StatusOr<std::vector<float>> p = model_->LiveStyleParams(at.code);
      if (p.ok()) params_ = *std::move(p);
    }
    strength_ = at.strength;
    step_style_.strength = at.strength;
    step_style_.fade = at.fade;
    if (at.generation != step_style_.generation) {
      step_style_.generation = at.generation;
      step_style_.examples = *at.examples;
    }
  }
  *step = {&carry_, queue_.front().data(), params_.data(), out_.data()};
  return true;
}

void LiveStreamer::StepDone() {
  recent_.push_back(std::move(queue_.front()));
  queue_.pop_front();
  while (static_cast<int>(recent_.size()) > shift_ + 1) recent_.pop_front();
  const int64_t frame = stepped_++ - shift_;  // The frame the output is of.
  if (frame < 0) {                            // The content encoder's warm-up: no frame yet.
    carry_.ResetGenerator();
    return;
  }
  if (frame >= received_) return;
  const motion::FeatureLayout layout((dim_ - motion::FeatureLayout::kPathChannels) / 7);
  const std::vector<float>& own = recent_.front();  // Frame `frame`'s features.
  if (model_->config().frame_residual) {
    for (int c = 0; c < dim_; ++c) out_[c] += own[c];
  }
  if (const double k = strength_; k != 1) {
    for (int c = 0; c < layout.trajectory(); ++c)
      out_[c] = static_cast<float>(k * out_[c] + (1 - k) * own[c]);
  }
  if (model_->config().keep_path) {
    std::copy(own.begin() + layout.trajectory(), own.end(), out_.begin() + layout.trajectory());
  }
  model_->data().norm.Denormalize(out_.data());
  generated_.values.insert(generated_.values.end(), out_.begin(), out_.end());
  ++generated_.frames;
  if (track_) frame_styles_.push_back(step_style_);
}

void LiveStreamer::ReadActions() {
  // The rows frame emitted_ may read: up to emitted_ + lookahead_ - 1 (the
  // frames it waited for), whatever arrived since, so that how the stream
  // was chunked does not change the reading.
  const int64_t end = std::min(action_rows_end_, emitted_ + lookahead_);
  const int64_t first = action_rows_end_ - static_cast<int64_t>(action_rows_.size());
  const int64_t begin = std::max(first, end - kActionRows);
  if (end - begin < kMinActionRows) return;
  motion::FeatureClip clip;
  clip.dim = dim_;
  for (int64_t r = begin; r < end; ++r) {
    const std::vector<float>& row = action_rows_[static_cast<size_t>(r - first)];
    clip.values.insert(clip.values.end(), row.begin(), row.end());
    ++clip.frames;
  }
  actions_ = model_->ActionProbabilities(clip);
  if (follower_) follower_->ReadActions(actions_);
  if (fading_) fading_->ReadActions(actions_);
}

void LiveStreamer::Move(motion::Motion* one) {
  if (!track_) return;
  const FrameStyle style = std::move(frame_styles_.front());
  frame_styles_.pop_front();
  if (style.generation != generation_) {  // A change of style: its takes fade in.
    generation_ = style.generation;
    fading_ = std::move(follower_);
    follower_.reset();
    if (style.examples) {
      follower_ = std::make_unique<motion::MovementFollower>(*style.examples, *track_, follow_);
      follower_->ReadActions(actions_);
    }
  }
  // Read while a follower's takes are gated (a change of style may bring
  // gated takes later: the rows are kept all along).
  if (emitted_ % kActionEvery == 0 &&
      ((follower_ && follower_->gated()) || (fading_ && fading_->gated()))) {
    ReadActions();
  }
  const motion::ContentTrack::Reading now = track_->Read(emitted_);
  const motion::LocalPose network = motion::PoseAt(*one, 0);
  std::optional<std::array<bool, 4>> contacts, fading_contacts;
  motion::LocalPose pose =
      follower_ ? follower_->Apply(*track_, now, network, style.strength, &contacts) : network;
  if (fading_ && style.fade < 1) {
    const motion::LocalPose was =
        fading_->Apply(*track_, now, network, style.strength, &fading_contacts);
    pose = motion::BlendPoses(was, pose, style.fade);
    if (style.fade < 0.5) contacts = fading_contacts;
  } else {
    fading_.reset();
  }
  if (moved_euler_.empty()) moved_euler_.assign(one->skeleton.num_joints(), motion::Vec3{});
  motion::SetPose(one, 0, pose, &moved_euler_);
  cleaner_.NoteContacts(emitted_, contacts);
  // Bounded: for a caller that never takes them, the last frames.
  if (contacts_.size() >= 2 * kMaxKeptContacts) {
    contacts_.erase(contacts_.begin(), contacts_.end() - kMaxKeptContacts);
  }
  contacts_.push_back(contacts);
  track_->Forget(emitted_ + 1);
}

absl::StatusOr<motion::Motion> LiveStreamer::Collect() {
  if (generated_.frames == 0) {
    Trim();
    return empty_;
  }
  absl::StatusOr<motion::Motion> decoded = motion::MotionFromFeatures(
      generated_, input_.skeleton, model_->data().roles, input_.frame_time, &decode_);
  if (!decoded.ok()) return decoded.status();
  generated_.frames = 0;
  generated_.values.clear();
  motion::Motion& raw = *decoded;
  // Frame by frame, so that how the input was chunked cannot change the
  // output.
  const int channels = input_.skeleton.num_channels();
  if (raw.num_frames == 1) {
    Move(&raw);
    absl::StatusOr<motion::Motion> clean =
        cleaner_.Clean(std::move(raw), emitted_, input_, base_, emitted_ + lookahead_ + 1);
    if (clean.ok()) ++emitted_;
    Trim();
    return clean;
  }
  motion::Motion out = empty_;
  for (int f = 0; f < raw.num_frames; ++f) {
    motion::Motion one = raw;
    one.num_frames = 1;
    one.values.assign(raw.values.begin() + f * channels, raw.values.begin() + (f + 1) * channels);
    Move(&one);
    absl::StatusOr<motion::Motion> clean =
        cleaner_.Clean(std::move(one), emitted_, input_, base_, emitted_ + lookahead_ + 1);
    if (!clean.ok()) return clean.status();
    out.values.insert(out.values.end(), clean->values.begin(), clean->values.end());
    ++out.num_frames;
    ++emitted_;
  }
  Trim();
  return out;
}

void LiveStreamer::Trim() {
  // Keep what the features, the cleaner and the frames not yet emitted need.
  const int64_t keep = std::min(cleaner_.FirstInputNeeded(emitted_), emitted_);
  if (keep > base_) {
    const int channels = input_.skeleton.num_channels();
    input_.values.erase(input_.values.begin(), input_.values.begin() + (keep - base_) * channels);
    input_.num_frames -= static_cast<int>(keep - base_);
    base_ = keep;
  }
  // The action gate's rows: those the frames not yet moved read (frame f
  // reads up to kActionRows rows ending at f + lookahead_ - 1).
  const int64_t first_read = emitted_ + lookahead_ - kActionRows;
  while (!action_rows_.empty() &&
         action_rows_end_ - static_cast<int64_t>(action_rows_.size()) < first_read) {
    action_rows_.pop_front();
  }
}

absl::StatusOr<motion::Motion> LiveStreamer::Push(const motion::Motion& frames) {
  if (absl::Status s = Feed(frames); !s.ok()) return s;
  if (absl::Status s = RunSteps(); !s.ok()) return s;
  return Collect();
}

absl::StatusOr<motion::Motion> LiveStreamer::Finish() {
  motion::Motion none = input_;
  none.num_frames = 0;
  none.values.clear();
  if (absl::Status s = Feed(none, /*end=*/true); !s.ok()) return s;
  if (absl::Status s = RunSteps(); !s.ok()) return s;
  return Collect();
}

absl::Status LiveStreamer::RunSteps() {
  LiveStep step;
  while (NextStep(&step)) {
    if (absl::Status s = model_->StepLive({step}); !s.ok()) return s;
    StepDone();
  }
  return absl::OkStatus();
}

absl::Status LiveStreamer::ChangeStyle(const StyleChange& change) {
  if (!change.code || !track_) return schedule_.Add(change, std::max<int64_t>(0, stepped_ - shift_));
  // The new style's takes, chosen now (not on the stepping thread).
  absl::StatusOr<motion::StreamExamples> chosen =
      ChooseStreamExamples(*model_, *change.code, change.movement);
  if (!chosen.ok()) return chosen.status();
  StyleChange with = change;
  with.examples = std::make_shared<const motion::StreamExamples>(*std::move(chosen));
  with.code->example = nullptr;  // Held by the takes chosen, not by the schedule.
  return schedule_.Add(std::move(with), std::max<int64_t>(0, stepped_ - shift_));
}

std::vector<std::optional<std::array<bool, 4>>> LiveStreamer::TakeContacts() {
  std::vector<std::optional<std::array<bool, 4>>> taken(contacts_.begin(), contacts_.end());
  contacts_.clear();  // Its room kept: a stream's state stays one size.
  return taken;
}

size_t LiveStreamer::state_bytes() const {
  size_t n = carry_.bytes() + params_.size() * sizeof(float) + schedule_.bytes();
  for (const auto& q : queue_) n += q.size() * sizeof(float);
  for (const auto& r : recent_) n += r.size() * sizeof(float);
  n += input_.values.size() * sizeof(double);
  n += generated_.values.size() * sizeof(float);
  if (track_) n += track_->bytes() + frame_styles_.size() * sizeof(FrameStyle);
  for (const auto& r : action_rows_) n += r.size() * sizeof(float);
  n += contacts_.capacity() * sizeof(contacts_[0]);
  if (follower_) n += follower_->bytes();
  if (fading_) n += fading_->bytes();
  return n + cleaner_.bytes();
}

}  // namespace stylus::model
