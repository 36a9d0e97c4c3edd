// Movement from examples with the shipped default package on real Bandai
// takes: the style clip of the same action, a style library's take for a
// style shown only by another action, a gesture registered to the content's,
// and the network's movement kept where no example fits; and the same
// through a stream of the shipped live package, frame by frame.
#include "model/movement.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>

#include "gtest/gtest.h"
#include "model/family_registry.h"
#include "model/style_model.h"
#include "motion/bvh.h"
#include "motion/contacts.h"
#include "motion/gait.h"
#include "motion/humanoid.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "tests/test_support.h"

namespace stylus::model {
namespace {

namespace fs = std::filesystem;

class MovementTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    absl::StatusOr<std::unique_ptr<StyleModel>> m = LoadStyleModel(testing::DefaultPackageDir());
    ASSERT_TRUE(m.ok()) << m.status();
    model_ = new std::shared_ptr<StyleModel>(*std::move(m));
  }
  static void TearDownTestSuite() { delete model_; }
  const StyleModel& model() { return **model_; }
  motion::Motion Take(const std::string& data, const std::string& name) {
    absl::StatusOr<motion::Motion> m =
        motion::ReadBvhFile(data + "/dataset-2/dataset-2_" + name + ".bvh");
    EXPECT_TRUE(m.ok()) << m.status();
    return *m;
  }
  TransferResult Transfer(const motion::Motion& content, const motion::Motion& style,
                          const TransferOptions& options = {}) {
    absl::StatusOr<StyleCode> code = model().EncodeStyle(style);
    EXPECT_TRUE(code.ok()) << code.status();
    absl::StatusOr<TransferResult> r = model().Transfer(content, *code, options);
    EXPECT_TRUE(r.ok()) << r.status();
    return *r;
  }
  static std::shared_ptr<StyleModel>* model_;
};
std::shared_ptr<StyleModel>* MovementTest::model_ = nullptr;

TEST_F(MovementTest, TheDefaultPackageTakesItsMovementFromExamples) {
  EXPECT_TRUE(model().moves_from_examples());
}

TEST_F(MovementTest, AnElderlyWalkOnANormalWalksPathTakesMoreShorterSteps) {
  STYLUS_REQUIRE_BANDAI(data);
  const motion::Motion content = Take(data, "walk_normal_004");
  const motion::Motion style = Take(data, "walk_elderly_003");
  const TransferResult r = Transfer(content, style);
  ASSERT_TRUE(r.movement.applied) << r.movement.reason;
  EXPECT_EQ(r.movement.example, "style clip");
  EXPECT_EQ(r.movement.kind, "steps");
  ASSERT_EQ(r.motion.num_frames, content.num_frames);
  ASSERT_TRUE(r.contacts.has_value());
  const motion::HumanoidRoles& roles = model().data().roles;
  const motion::GaitSummary c = motion::MeasureGait(content, roles)->summary;
  const motion::GaitSummary e = motion::MeasureGait(style, roles)->summary;
  const motion::GaitSummary o = motion::MeasureGait(r.motion, roles)->summary;
  ASSERT_TRUE(c.cadence && e.cadence && o.cadence);
  // The content's speed and path; the style's cadence scaled by its walk
  // ratio: sqrt(1.16 / 0.79) faster than the elderly take's own.
  EXPECT_NEAR(o.speed, c.speed, 0.05 * c.speed);
  const double want = e.cadence->period_s / std::sqrt(c.speed / e.speed);
  EXPECT_NEAR(o.cadence->period_s, want, 0.1 * want);
  EXPECT_LT(o.cadence->period_s, 0.9 * c.cadence->period_s);
  EXPECT_LT(o.stride, 0.95 * c.stride);
  // Planted on its own contacts: skating there no worse than real capture's
  // (x1.2), and no foot below the floor.
  const double skating = motion::FootSkatingOnSpans(r.motion, *r.contacts, roles);
  const double real = motion::FootSkating(content, content, roles);
  EXPECT_LT(skating, 1.2 * real) << skating << " vs real " << real;
  auto lowest_foot = [&](const motion::Motion& m) {
    double lowest = 1e300;
    for (const auto& p : motion::GlobalPositions(m)) {
      for (int j : motion::FootJoints(roles)) lowest = std::min(lowest, p[j].y);
    }
    return lowest;
  };
  EXPECT_GE(lowest_foot(r.motion), lowest_foot(content) - 1e-6);
}

TEST_F(MovementTest, ARaiseIsRegisteredToTheContentsRaise) {
  STYLUS_REQUIRE_BANDAI(data);
  const motion::Motion content = Take(data, "raise-up-right-hand_normal_003");
  const motion::Motion style = Take(data, "raise-up-right-hand_exhausted_002");
  const TransferResult r = Transfer(content, style);
  ASSERT_TRUE(r.movement.applied) << r.movement.reason;
  EXPECT_EQ(r.movement.kind, "gesture");
  // The hand is highest when the content's is (within a fifth of a second).
  const motion::HumanoidRoles& roles = model().data().roles;
  auto peak = [&](const motion::Motion& m) {
    const auto pos = motion::GlobalPositions(m);
    int best = 0;
    // The right hand: two joints below the right upper arm.
    int hand = roles.right_shoulder;
    for (int k = 0; k < 2; ++k) hand = motion::MainChild(m.skeleton, hand);
    for (size_t f = 0; f < pos.size(); ++f)
      if (pos[f][hand].y > pos[best][hand].y) best = static_cast<int>(f);
    return best;
  };
  EXPECT_NEAR(peak(r.motion), peak(content), 0.2 / content.frame_time);
}

TEST_F(MovementTest, WithoutAnExampleOfTheContentsMovementTheNetworksIsKept) {
  STYLUS_REQUIRE_BANDAI(data);
  const motion::Motion content = Take(data, "walk_normal_004");
  const motion::Motion style = Take(data, "raise-up-left-hand_elderly_004");
  const TransferResult r = Transfer(content, style);
  EXPECT_FALSE(r.movement.applied);
  // Refused for its action (the default package gates takes by action) or,
  // ungated, because a raise does not step as a walk does.
  EXPECT_TRUE(r.movement.reason.find("another action") != std::string::npos ||
              r.movement.reason.find("steps") != std::string::npos)
      << r.movement.reason;
  TransferOptions network_only;
  network_only.movement_from_examples = false;
  const TransferResult n = Transfer(content, style, network_only);
  EXPECT_EQ(r.motion.values, n.motion.values);
  EXPECT_FALSE(r.contacts.has_value());
}

TEST_F(MovementTest, AStyleShownOnlyByAGestureWalksInItsStyleFromALibrary) {
  STYLUS_REQUIRE_BANDAI(data);
  // A library folder of links to three takes (the data stays where it is).
  const std::string lib = testing::LinkLibrary(
      data, "movement_library",
      {"walk_elderly_003", "walk_youthful_002", "raise-up-left-hand_elderly_004"});
  std::ofstream(lib + "/notes.bvh") << "not a labelled take";  // Skipped, not fatal.
  absl::StatusOr<std::unique_ptr<StyleLibrary>> library = StyleLibrary::Load(lib);
  ASSERT_TRUE(library.ok()) << library.status();
  EXPECT_EQ((*library)->takes().size(), 3u);
  ASSERT_EQ((*library)->skipped().size(), 1u);
  EXPECT_EQ((*library)->Styles(), (std::vector<std::string>{"elderly", "youthful"}));

  const motion::Motion content = Take(data, "walk_normal_004");
  const motion::Motion style = Take(data, "raise-up-right-hand_elderly_009");
  TransferOptions options;
  options.movement.library = library->get();
  options.movement.style_label = "elderly";
  const TransferResult r = Transfer(content, style, options);
  ASSERT_TRUE(r.movement.applied) << r.movement.reason;
  EXPECT_EQ(r.movement.example, "dataset-2_walk_elderly_003.bvh");
  EXPECT_EQ(r.movement.kind, "steps");
  options.movement.style_label = "youthful";
  EXPECT_EQ(Transfer(content, style, options).movement.example, "dataset-2_walk_youthful_002.bvh");
  // A style the library lacks: the network's movement, and the note says why.
  options.movement.style_label = "masculine";
  const TransferResult none = Transfer(content, style, options);
  EXPECT_FALSE(none.movement.applied);
  EXPECT_NE(none.movement.reason.find("no take of 'masculine'"), std::string::npos)
      << none.movement.reason;
}

// The shipped live package, streamed frame by frame as a stage sends it.
class LiveMovementTest : public MovementTest {
 protected:
  static void SetUpTestSuite() {
    absl::StatusOr<std::unique_ptr<StyleModel>> m =
        LoadStyleModel(testing::SourceDir() + "/models/live/v3");
    ASSERT_TRUE(m.ok()) << m.status();
    live_ = new std::shared_ptr<StyleModel>(*std::move(m));
  }
  static void TearDownTestSuite() { delete live_; }
  const StyleModel& live() { return **live_; }
  static std::shared_ptr<StyleModel>* live_;
};
std::shared_ptr<StyleModel>* LiveMovementTest::live_ = nullptr;

TEST_F(LiveMovementTest, AnElderlyWalkStreamedTakesMoreShorterStepsOnItsOwnContacts) {
  STYLUS_REQUIRE_BANDAI(data);
  EXPECT_TRUE(live().moves_from_examples());
  const motion::Motion content = Take(data, "walk_normal_004");
  const motion::Motion style = Take(data, "walk_elderly_003");
  std::optional<std::array<std::vector<motion::ContactSpan>, 4>> contacts;
  absl::StatusOr<motion::Motion> out = StreamClip(live(), content, *live().EncodeStyle(style),
                                                  motion::PostProcessMode::kFull, {}, &contacts);
  ASSERT_TRUE(out.ok()) << out.status();
  ASSERT_EQ(out->num_frames, content.num_frames);
  ASSERT_TRUE(contacts.has_value()) << "the stream's steps are the take's";
  const motion::HumanoidRoles& roles = live().data().roles;
  const motion::GaitSummary c = motion::MeasureGait(content, roles)->summary;
  const motion::GaitSummary o = motion::MeasureGait(*out, roles)->summary;
  ASSERT_TRUE(c.cadence && o.cadence);
  std::printf("streamed: period %.3f s (content %.3f), stride %.3f (content %.3f)\n",
              o.cadence->period_s, c.cadence->period_s, o.stride, c.stride);
  EXPECT_NEAR(o.speed, c.speed, 0.1 * c.speed);
  EXPECT_LT(o.cadence->period_s, 0.9 * c.cadence->period_s);
  EXPECT_LT(o.stride, 0.95 * c.stride);
  const double skating = motion::FootSkatingOnSpans(*out, *contacts, roles);
  const double real = motion::FootSkating(content, content, roles);
  EXPECT_LT(skating, 1.2 * real) << skating << " vs real " << real;
  double lowest_out = 1e300, lowest_content = 1e300;
  for (const auto& p : motion::GlobalPositions(*out))
    for (int j : motion::FootJoints(roles)) lowest_out = std::min(lowest_out, p[j].y);
  for (const auto& p : motion::GlobalPositions(content))
    for (int j : motion::FootJoints(roles)) lowest_content = std::min(lowest_content, p[j].y);
  EXPECT_GE(lowest_out, lowest_content - 1e-6);
}

TEST_F(LiveMovementTest, HowTheFramesArriveDoesNotChangeTheMovement) {
  STYLUS_REQUIRE_BANDAI(data);
  const motion::Motion content = Take(data, "walk_normal_004");
  const StyleCode code = *live().EncodeStyle(Take(data, "walk_elderly_003"));
  const motion::Motion one_by_one =
      *StreamClip(live(), content, code, motion::PostProcessMode::kFull);
  absl::StatusOr<std::unique_ptr<FrameStreamer>> s = live().OpenStream(
      {code, content.skeleton, content.frame_time, motion::PostProcessMode::kFull});
  ASSERT_TRUE(s.ok()) << s.status();
  motion::Motion chunked = motion::RestMotion(content.skeleton, 0, content.frame_time);
  std::mt19937_64 rng(7);
  const size_t channels = content.skeleton.num_channels();
  auto append = [&](const motion::Motion& m) {
    chunked.values.insert(chunked.values.end(), m.values.begin(), m.values.end());
    chunked.num_frames += m.num_frames;
  };
  for (int f = 0; f < content.num_frames;) {
    const int n = std::min<int>(content.num_frames - f, 1 + rng() % 9);
    motion::Motion part = motion::RestMotion(content.skeleton, n, content.frame_time);
    std::copy_n(content.values.begin() + f * channels, n * channels, part.values.begin());
    absl::StatusOr<motion::Motion> got = (*s)->Push(part);
    ASSERT_TRUE(got.ok()) << got.status();
    append(*got);
    f += n;
  }
  append(*(*s)->Finish());
  ASSERT_EQ(chunked.num_frames, one_by_one.num_frames);
  EXPECT_LT(motion::MaxPositionDifference(chunked, one_by_one), 1e-6);
}

TEST_F(LiveMovementTest, AStreamWhoseStyleShowsOnlyAGestureWalksInItsStyleFromALibrary) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::string lib = testing::LinkLibrary(
      data, "live_movement_library", {"walk_elderly_003", "raise-up-left-hand_elderly_004"});
  absl::StatusOr<std::unique_ptr<StyleLibrary>> library = StyleLibrary::Load(lib);
  ASSERT_TRUE(library.ok()) << library.status();
  const motion::Motion content = Take(data, "walk_normal_004");
  const StyleCode code = *live().EncodeStyle(Take(data, "raise-up-right-hand_elderly_009"));
  MovementRequest request;
  request.library = library->get();
  request.style_label = "elderly";
  std::optional<std::array<std::vector<motion::ContactSpan>, 4>> with_contacts;
  const motion::Motion with = *StreamClip(live(), content, code, motion::PostProcessMode::kFull,
                                          request, &with_contacts);
  const motion::Motion without = *StreamClip(live(), content, code, motion::PostProcessMode::kFull);
  EXPECT_TRUE(with_contacts.has_value());
  const motion::HumanoidRoles& roles = live().data().roles;
  const double content_period = motion::MeasureGait(content, roles)->summary.cadence->period_s;
  const auto period = motion::MeasureGait(with, roles)->summary.cadence;
  const auto alone = motion::MeasureGait(without, roles)->summary.cadence;
  ASSERT_TRUE(period.has_value() && alone.has_value());
  std::printf("step period: content %.3f s, with the library %.3f, the raise alone %.3f\n",
              content_period, period->period_s, alone->period_s);
  // The elderly take's many short steps; the raise alone shows none.
  EXPECT_LT(period->period_s, 0.9 * content_period);
  EXPECT_GT(alone->period_s, 1.1 * period->period_s);
}

TEST_F(LiveMovementTest, AStreamDoesNotPlayATakeOfAnotherActionThanTheContents) {
  STYLUS_REQUIRE_BANDAI(data);
  // The package's action gate: the style clip, a wave of both hands, reads
  // to its content guard as another action than the content's raise.
  const motion::Motion content = Take(data, "raise-up-right-hand_normal_001");
  const motion::Motion style = Take(data, "wave-both-hands_elderly_001");
  auto stream = [&](const ConfigOverrides& overrides) {
    absl::StatusOr<std::unique_ptr<StyleModel>> loaded =
        LoadStyleModel(testing::SourceDir() + "/models/live/v3", overrides);
    EXPECT_TRUE(loaded.ok()) << loaded.status();
    const std::shared_ptr<StyleModel> m = *std::move(loaded);  // Streams need shared ownership.
    absl::StatusOr<motion::Motion> out =
        StreamClip(*m, content, *m->EncodeStyle(style), motion::PostProcessMode::kNone);
    EXPECT_TRUE(out.ok()) << out.status();
    return *out;
  };
  const motion::Motion gated = stream({});
  const motion::Motion open = stream({{"movement_action_gate", "0"}});
  const motion::Motion network = stream({{"movement", "network"}});
  const size_t channels = content.skeleton.num_channels();
  auto differs = [&](const motion::Motion& a, int f) {
    double d = 0;
    for (size_t c = 3; c < channels; ++c) {
      d = std::max(d, std::abs(a.values[f * channels + c] - network.values[f * channels + c]));
    }
    return d;
  };
  // Until the content's action is first read (16 frames), the take may
  // play; from the first reading and a fade (8 frames) on, the network's
  // movement alone. Without the gate the wave plays on.
  int open_moved = 0;
  for (int f = 16 + 8 + 1; f < content.num_frames; ++f) {
    ASSERT_LT(differs(gated, f), 1e-9) << "frame " << f;
    open_moved += differs(open, f) > 1;  // Degrees.
  }
  EXPECT_GT(open_moved, (content.num_frames - 25) / 2);
}

TEST(StyleLibraryTest, AFolderWithoutLabelledTakesIsRefusedByName) {
  const std::string dir = ::testing::TempDir() + "/empty_library";
  fs::remove_all(dir);
  fs::create_directories(dir);
  absl::StatusOr<std::unique_ptr<StyleLibrary>> lib = StyleLibrary::Load(dir);
  EXPECT_EQ(lib.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(lib.status().message().find(dir), std::string::npos) << lib.status();
  EXPECT_EQ(StyleLibrary::Load(dir + "/missing").status().code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace stylus::model
