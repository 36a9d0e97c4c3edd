// The stream cleaner keeps its history as poses (and their world poses from
// when they were new) and the input's world positions between calls; its
// frames must be what post-processing each batch with its history from the
// frames as sent gives, the history read as final.
#include "model/stream_cleaner.h"

#include <array>
#include <cmath>
#include <optional>
#include <tuple>
#include <utility>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/contacts.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "motion/postprocess.h"
#include "tests/test_support.h"

namespace stylus::model {
namespace {

using motion::Motion;
using motion::PostProcessMode;

constexpr int kHistory = 6;
constexpr int kLookahead = 2;

// The content with its hips swaying: a sliding foot wherever the content's
// foot is planted, so the feet get locked.
Motion Swaying(const Motion& content, const motion::HumanoidRoles& roles) {
  Motion output = content;
  const int cx = output.skeleton.channel_start(roles.pelvis);
  for (int f = 0; f < output.num_frames; ++f) {
    output.frame(f)[cx + 0] += 6 * std::sin(f * 0.21);
    output.frame(f)[cx + 2] += 4 * std::sin(f * 0.13);
  }
  return output;
}

// Post-processes each batch of `chunk` raw frames with the last kHistory
// frames as sent, read back from their Euler angles, against the input up to
// kLookahead frames ahead, every frame posed afresh; a contact seen before
// keeps its pin; the history frames are final (not smoothed again; their
// world poses those their own batch gave them); no foot ends below the
// lowest the input's feet went up to the look-ahead; the batch's angles
// continue from the last frame sent.
Motion Reference(const Motion& raw, const Motion& input, const motion::HumanoidRoles& roles,
                 PostProcessMode mode, int chunk) {
  Motion sent = raw;
  sent.num_frames = 0;
  sent.values.clear();
  motion::PostProcessParams params;
  params.pin_at_span_start = true;
  std::array<std::optional<std::pair<int, motion::Vec3>>, 4> carried;  // Stream frame, pin.
  std::vector<motion::GlobalPose> posed_all;  // Per stream frame.
  const std::vector<std::vector<motion::Vec3>> input_world = motion::GlobalPositions(input);
  for (int first = 0; first < raw.num_frames; first += chunk) {
    const int last = std::min(raw.num_frames, first + chunk);
    const int from = std::max(0, first - kHistory);
    Motion window = testing::Frames(sent, from, first);
    testing::Append(testing::Frames(raw, first, last), &window);
    const Motion content =
        testing::Frames(input, from, std::min(input.num_frames, last - 1 + kLookahead + 1));
    std::vector<motion::LocalPose> poses;
    for (int f = 0; f < window.num_frames; ++f) poses.push_back(motion::PoseAt(window, f));
    motion::ContactPins pins;
    for (int k = 0; k < 4; ++k) {
      if (carried[k]) pins[k] = motion::ContactPin{carried[k]->first - from, carried[k]->second};
    }
    std::vector<motion::GlobalPose> posed(posed_all.begin() + from, posed_all.end());
    absl::StatusOr<std::vector<motion::LocalPose>> cleaned =
        motion::PostProcessPoses(raw.skeleton, roles, poses, motion::GlobalPositions(content),
                                 raw.fps(), mode, params, first - from, &pins, &posed);
    EXPECT_EQ(posed.size(), poses.size());
    posed_all.resize(from);
    posed_all.insert(posed_all.end(), posed.begin(), posed.end());
    EXPECT_TRUE(cleaned.ok()) << cleaned.status();
    if (!cleaned.ok()) return sent;
    double floor = 1e300;
    const int seen = std::min(input.num_frames, last - 1 + kLookahead + 1);
    for (int f = 0; f < seen; ++f) {
      for (int j : motion::FootJoints(roles)) floor = std::min(floor, input_world[f][j].y);
    }
    for (motion::LocalPose& pose : *cleaned)
      motion::KeepFeetAboveFloor(raw.skeleton, roles, floor, &pose);
    for (int k = 0; k < 4; ++k) {
      carried[k].reset();
      if (pins[k]) carried[k] = std::make_pair(from + pins[k]->frame, pins[k]->pin);
    }
    Motion fresh = testing::Frames(raw, first, last);
    // Continuity from the last frame sent, or from the raw frame's own angles.
    Motion lead = first > 0 ? testing::Frames(sent, first - 1, first) : testing::Frames(raw, 0, 1);
    std::vector<motion::Vec3> prev(raw.skeleton.num_joints());
    for (int j = 0; j < raw.skeleton.num_joints(); ++j) {
      int c = raw.skeleton.channel_start(j), k = 0;
      for (motion::Channel ch : raw.skeleton.joint(j).channels) {
        if (!motion::IsPosition(ch)) prev[j][k++] = lead.values[c];
        ++c;
      }
    }
    for (int f = 0; f < fresh.num_frames; ++f) motion::SetPose(&fresh, f, (*cleaned)[f], &prev);
    testing::Append(fresh, &sent);
  }
  return sent;
}

class StreamCleanerTest : public ::testing::TestWithParam<std::tuple<PostProcessMode, int>> {};

TEST_P(StreamCleanerTest, EqualsPostProcessingEachBatchWithItsHistory) {
  const auto [mode, chunk] = GetParam();
  const Motion input = *motion::ReadBvhFile(testing::SourceDir() + "/samples/walk_normal.bvh");
  const motion::HumanoidRoles roles = *motion::FindHumanoidRoles(input.skeleton);
  const Motion raw = Swaying(input, roles);
  const Motion want = Reference(raw, input, roles, mode, chunk);

  StreamCleaner cleaner(roles, mode, kHistory);
  Motion got = raw;
  got.num_frames = 0;
  got.values.clear();
  for (int first = 0; first < raw.num_frames; first += chunk) {
    const int last = std::min(raw.num_frames, first + chunk);
    // The input held as a streamer holds it: from what the cleaner still
    // needs on, up to the look-ahead.
    const int base = static_cast<int>(cleaner.FirstInputNeeded(first));
    const Motion held = testing::Frames(input, base, std::min(input.num_frames, last + kLookahead));
    absl::StatusOr<Motion> out = cleaner.Clean(testing::Frames(raw, first, last), first, held, base,
                                               last - 1 + kLookahead + 1);
    ASSERT_TRUE(out.ok()) << out.status();
    ASSERT_EQ(out->num_frames, last - first);
    testing::Append(*out, &got);
  }
  ASSERT_EQ(got.num_frames, want.num_frames);
  EXPECT_LT(motion::MaxPositionDifference(got, want), 1e-6);
  double worst_angle = 0;
  for (size_t i = 0; i < got.values.size(); ++i)
    worst_angle = std::max(worst_angle, std::abs(got.values[i] - want.values[i]));
  EXPECT_LT(worst_angle, 1e-6) << "the same Euler branch, frame after frame";
  // And it did clean: the swaying hips' feet are held, through contacts
  // longer than the history window.
  const double before = motion::FootSkating(raw, input, roles);
  const double after = motion::FootSkating(got, input, roles);
  EXPECT_LT(after, 0.25 * before) << before << " -> " << after;
}

INSTANTIATE_TEST_SUITE_P(ModesAndBatches, StreamCleanerTest,
                         ::testing::Combine(::testing::Values(PostProcessMode::kFeet,
                                                              PostProcessMode::kFull),
                                            ::testing::Values(1, 4)));

}  // namespace
}  // namespace stylus::model
