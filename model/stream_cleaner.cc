#include "model/stream_cleaner.h"

#include <algorithm>
#include <iterator>

#include "motion/contacts.h"
#include "motion/example_motion.h"
#include "motion/kinematics.h"

namespace stylus::model {

StreamCleaner::StreamCleaner(const motion::HumanoidRoles& roles, motion::PostProcessMode post,
                             int history)
    : roles_(roles), post_(post), history_(history) {}

int64_t StreamCleaner::FirstInputNeeded(int64_t first) const {
  return std::max({int64_t{0}, sent_base_, first - history_});
}

absl::StatusOr<motion::Motion> StreamCleaner::Clean(motion::Motion raw, int64_t first,
                                                    const motion::Motion& input, int64_t input_base,
                                                    int64_t input_end) {
  if (post_ == motion::PostProcessMode::kNone || raw.num_frames == 0) return raw;
  const motion::Skeleton& sk = raw.skeleton;
  // Output: the post-processed history, then the new raw frames; content: the
  // held input over the same frames and every later one received.
  const int64_t from = std::max({input_base, sent_base_, first - history_});
  const int64_t end = input_end >= 0 ? std::min(input_end, input_base + input.num_frames)
                                     : input_base + input.num_frames;
  // The input's world positions over [from, end), each frame posed once.
  if (content_.empty() || content_base_ > from ||
      content_base_ + static_cast<int64_t>(content_.size()) < from) {
    content_.clear();
    content_base_ = from;
  }
  content_.erase(content_.begin(), content_.begin() + (from - content_base_));
  content_base_ = from;
  for (int64_t i = content_base_ + static_cast<int64_t>(content_.size()); i < end; ++i) {
    content_.push_back(
        motion::ForwardKinematics(sk, motion::PoseAt(input, static_cast<int>(i - input_base)))
            .positions);
  }
  std::vector<motion::LocalPose> poses;
  poses.reserve(first - from + raw.num_frames);
  poses.insert(poses.end(), sent_.begin() + (from - sent_base_), sent_.end());
  for (int f = 0; f < raw.num_frames; ++f) poses.push_back(motion::PoseAt(raw, f));
  motion::PostProcessParams params;
  params.pin_at_span_start = true;
  // Frames whose contacts are the output's own: those, the input's
  // elsewhere.
  while (!own_.empty() && own_base_ < from) {
    own_.pop_front();
    ++own_base_;
  }
  std::array<std::vector<motion::ContactSpan>, 4> own_spans;
  if (std::any_of(own_.begin(), own_.end(), [](const auto& o) { return o.has_value(); })) {
    const auto content = absl::MakeConstSpan(content_).subspan(0, static_cast<size_t>(end - from));
    const std::array<std::vector<motion::ContactSpan>, 4> found =
        motion::DetectContactSpans(content, roles_, raw.fps(), params.contacts);
    std::array<std::vector<bool>, 4> flags;
    for (int k = 0; k < 4; ++k) {
      flags[k].assign(content.size(), false);
      for (const motion::ContactSpan& span : found[k]) {
        for (int f = span.begin; f < span.end; ++f) flags[k][f] = true;
      }
      for (size_t i = 0; i < own_.size(); ++i) {
        const int64_t f = own_base_ + static_cast<int64_t>(i) - from;
        if (own_[i] && f >= 0 && f < static_cast<int64_t>(content.size())) flags[k][f] = (*own_[i])[k];
      }
    }
    own_spans = motion::SpansFromFlags(flags, 1);
    params.contact_spans = &own_spans;
  }
  // A contact that goes on keeps its pin, though the span began before the
  // history window.
  motion::ContactPins pins;
  for (int k = 0; k < 4; ++k) {
    if (pins_[k])
      pins[k] = motion::ContactPin{static_cast<int>(pins_[k]->first - from), pins_[k]->second};
  }
  // The history's world poses as they were posed when new (posed from the
  // frames as sent if they are not known).
  std::vector<motion::GlobalPose> posed;
  const int history = static_cast<int>(first - from);
  if (posed_.size() == sent_.size() &&
      sent_base_ + static_cast<int64_t>(sent_.size()) - from == history) {
    posed.assign(std::make_move_iterator(posed_.begin() + (from - sent_base_)),
                 std::make_move_iterator(posed_.end()));
  } else {
    for (int f = 0; f < history && f < static_cast<int>(poses.size()); ++f)
      posed.push_back(motion::ForwardKinematics(sk, poses[f]));
  }
  absl::StatusOr<std::vector<motion::LocalPose>> cleaned = motion::PostProcessPoses(
      sk, roles_, std::move(poses),
      absl::MakeConstSpan(content_).subspan(0, static_cast<size_t>(end - from)), raw.fps(), post_,
      params, history, &pins, &posed);
  if (!cleaned.ok()) {
    posed_.clear();  // Moved from: posed afresh by the next call.
    return cleaned.status();
  }
  // No foot below the content's floor: the lowest its feet went so far.
  for (size_t i = 0; i < content_.size() && content_base_ + static_cast<int64_t>(i) < end; ++i) {
    for (int j : motion::FootJoints(roles_)) floor_ = std::min(floor_, content_[i][j].y);
  }
  for (motion::LocalPose& pose : *cleaned) motion::KeepFeetAboveFloor(sk, roles_, floor_, &pose);
  for (int k = 0; k < 4; ++k) {
    pins_[k].reset();
    if (pins[k]) pins_[k] = std::make_pair(from + pins[k]->frame, pins[k]->pin);
  }
  // The new frames' Euler angles continue from the last frame sent (from the
  // first raw frame's own at the stream's start).
  if (sent_.empty() || sent_base_ + static_cast<int64_t>(sent_.size()) != first) {
    last_euler_.assign(sk.num_joints(), motion::Vec3{});
    const double* row = raw.frame(0);
    for (int j = 0; j < sk.num_joints(); ++j) {
      const motion::Joint& joint = sk.joint(j);
      int k = 0;
      for (size_t c = 0; c < joint.channels.size(); ++c) {
        if (!motion::IsPosition(joint.channels[c])) {
          last_euler_[j][k++] = row[sk.channel_start(j) + c];
        }
      }
    }
  }
  const int frames = raw.num_frames;
  motion::Motion fresh = std::move(raw);
  for (int f = 0; f < frames; ++f) motion::SetPose(&fresh, f, (*cleaned)[f], &last_euler_);
  // Keep `history` of the frames as sent, and their world poses.
  sent_.erase(sent_.begin(), sent_.begin() + (from - sent_base_));
  sent_base_ = from;
  std::move(cleaned->begin(), cleaned->end(), std::back_inserter(sent_));
  posed_ = std::move(posed);  // Frames [from, first + frames), as sent_'s now.
  const int64_t keep = std::max(sent_base_, first + frames - history_);
  sent_.erase(sent_.begin(), sent_.begin() + (keep - sent_base_));
  posed_.erase(posed_.begin(), posed_.begin() + (keep - sent_base_));
  sent_base_ = keep;
  return fresh;
}

void StreamCleaner::NoteContacts(int64_t frame, const std::optional<std::array<bool, 4>>& on) {
  if (post_ == motion::PostProcessMode::kNone) return;
  if (own_.empty()) own_base_ = frame;
  while (own_base_ + static_cast<int64_t>(own_.size()) < frame) own_.emplace_back();
  if (own_base_ + static_cast<int64_t>(own_.size()) == frame) own_.push_back(on);
}

size_t StreamCleaner::bytes() const {
  size_t n = last_euler_.size() * sizeof(motion::Vec3);
  for (const motion::LocalPose& p : sent_)
    n += p.translations.size() * sizeof(motion::Vec3) + p.rotations.size() * sizeof(motion::Quat);
  for (const motion::GlobalPose& p : posed_)
    n += p.positions.size() * sizeof(motion::Vec3) + p.rotations.size() * sizeof(motion::Quat);
  for (const std::vector<motion::Vec3>& c : content_) n += c.size() * sizeof(motion::Vec3);
  return n;
}

}  // namespace stylus::model
