#include "model/style_schedule.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace stylus::model {

StyleSchedule::StyleSchedule(StyleCode code, double strength)
    : now_code_(code),
      from_code_(code),
      to_code_(std::move(code)),
      now_strength_(strength),
      from_strength_(strength),
      to_strength_(strength) {}

absl::Status StyleSchedule::Add(StyleChange change, int64_t earliest) {
  if (!change.code && !change.strength) {
    return absl::InvalidArgumentError("a style change needs a style or a strength");
  }
  if (change.code && change.code->values.size() != now_code_.values.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("style change: the code has ", change.code->values.size(),
                     " values; this model's have ", now_code_.values.size()));
  }
  if (change.strength && !(*change.strength >= 0 && *change.strength <= 1)) {
    return absl::InvalidArgumentError(
        absl::StrCat("style change: strength must be in [0, 1], got ", *change.strength));
  }
  if (change.fade_frames < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("style change: fade_frames must be >= 0, got ", change.fade_frames));
  }
  change.from_frame = std::max(change.from_frame, earliest);
  if (!queued_.empty() && change.from_frame < queued_.back().from_frame) {
    return absl::InvalidArgumentError(absl::StrCat("style change from frame ", change.from_frame,
                                                   " comes before one already queued from frame ",
                                                   queued_.back().from_frame,
                                                   ": send changes in frame order"));
  }
  if (static_cast<int>(queued_.size()) >= kMaxQueuedChanges) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "style change: ", kMaxQueuedChanges,
        " changes already wait for later frames; send a change closer to when it is due"));
  }
  queued_.push_back(std::move(change));
  return absl::OkStatus();
}

StyleSchedule::At StyleSchedule::Advance(int64_t t) {
  bool changed = false;
  while (!queued_.empty() && queued_.front().from_frame <= t) {
    StyleChange& c = queued_.front();
    // The new fade starts from wherever the style is now (mid-fade too).
    from_code_ = now_code_;
    from_strength_ = now_strength_;
    if (c.code) {
      to_code_ = *std::move(c.code);
      examples_ = std::move(c.examples);
      ++generation_;
    }
    if (c.strength) to_strength_ = *c.strength;
    fade_start_ = c.from_frame;
    fade_len_ = std::max(1, c.fade_frames);
    fading_ = true;
    queued_.pop_front();
  }
  if (fading_) {
    const double a = std::clamp(static_cast<double>(t - fade_start_ + 1) / fade_len_, 0.0, 1.0);
    for (size_t i = 0; i < now_code_.values.size(); ++i) {
      now_code_.values[i] =
          static_cast<float>((1 - a) * from_code_.values[i] + a * to_code_.values[i]);
    }
    now_strength_ = (1 - a) * from_strength_ + a * to_strength_;
    changed = true;
    fade_ = a;
    if (a >= 1) fading_ = false;
  }
  return {now_code_, now_strength_, changed, fade_, generation_, &examples_};
}

size_t StyleSchedule::bytes() const {
  size_t n = 3 * now_code_.values.size() * sizeof(float);
  for (const StyleChange& c : queued_) n += c.code ? c.code->values.size() * sizeof(float) : 0;
  return n;
}

}  // namespace stylus::model
