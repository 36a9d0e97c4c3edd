#include "model/stream_cleaner.h"

#include <algorithm>

namespace stylus::model {

StreamCleaner::StreamCleaner(const motion::Motion& empty, const motion::HumanoidRoles& roles,
                             motion::PostProcessMode post, int history)
    : roles_(roles),
      post_(post),
      history_(history),
      done_(empty),
      output_(empty),
      content_(empty) {}

int64_t StreamCleaner::FirstInputNeeded(int64_t first) const {
  return std::max({int64_t{0}, done_base_, first - history_});
}

absl::StatusOr<motion::Motion> StreamCleaner::Clean(const motion::Motion& raw, int64_t first,
                                                    const motion::Motion& input, int64_t input_base,
                                                    int64_t input_end) {
  if (post_ == motion::PostProcessMode::kNone || raw.num_frames == 0) return raw;
  const int channels = raw.skeleton.num_channels();
  // Output: the post-processed history, then the new raw frames; content: the
  // held input over the same frames and every later one received.
  const int64_t from = std::max({input_base, done_base_, first - history_});
  motion::Motion& output = output_;
  output.num_frames = static_cast<int>(first - from);
  output.values.assign(done_.values.begin() + (from - done_base_) * channels, done_.values.end());
  output.values.insert(output.values.end(), raw.values.begin(), raw.values.end());
  output.num_frames += raw.num_frames;
  motion::Motion& content = content_;
  const int64_t end = input_end >= 0 ? std::min(input_end, input_base + input.num_frames)
                                     : input_base + input.num_frames;
  content.num_frames = static_cast<int>(end - from);
  content.values.assign(input.values.begin() + (from - input_base) * channels,
                        input.values.begin() + (end - input_base) * channels);
  motion::PostProcessParams params;
  params.pin_at_span_start = true;
  absl::StatusOr<motion::Motion> cleaned =
      motion::PostProcess(output, content, roles_, post_, params);
  if (!cleaned.ok()) return cleaned.status();
  // The new frames' Euler angles continue from the last frame sent (the
  // history was re-solved above and may sit on another Euler branch).
  motion::Motion fresh = raw;
  const int64_t lead = first > from ? 1 : 0;
  fresh.values.assign(done_.values.end() - lead * channels, done_.values.end());
  fresh.values.insert(fresh.values.end(), cleaned->values.begin() + (first - from) * channels,
                      cleaned->values.end());
  fresh.num_frames = raw.num_frames + static_cast<int>(lead);
  motion::MakeEulerContinuous(&fresh);
  fresh.values.erase(fresh.values.begin(), fresh.values.begin() + lead * channels);
  fresh.num_frames = raw.num_frames;
  // Keep `history` of the frames as sent.
  done_.values.erase(done_.values.begin(), done_.values.begin() + (from - done_base_) * channels);
  done_.values.insert(done_.values.end(), fresh.values.begin(), fresh.values.end());
  done_.num_frames = static_cast<int>(done_.values.size() / channels);
  done_base_ = from;
  const int64_t keep = std::max(done_base_, first + raw.num_frames - history_);
  done_.values.erase(done_.values.begin(), done_.values.begin() + (keep - done_base_) * channels);
  done_.num_frames -= static_cast<int>(keep - done_base_);
  done_base_ = keep;
  return fresh;
}

}  // namespace stylus::model
