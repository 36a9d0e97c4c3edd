// End-to-end: a real server on localhost:0 with the shipped default model,
// called through stylus::Client and the raw generated stubs.
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <future>
#include <limits>
#include <thread>

#include "gtest/gtest.h"
#include "model/contrastive/contrastive_model.h"
#include "model/style_model.h"
#include "motion/cadence.h"
#include "motion/kinematics.h"
#include "motion/rig_roles.h"
#include "server/registry.h"
#include "server/status.h"
#include "tests/model/transfer_support.h"
#include "tests/server/server_test_support.h"
#include "wire/wire.h"

namespace stylus {
namespace {

using ::stylus::testing::MotionOf;

using testing::Frames;

using testing::LiveServer;
using testing::Sample;

const std::string kModel = testing::DefaultPackageDir();

motion::Motion BandaiClip(const std::string& dir, const std::string& name) {
  return *motion::ReadBvhFile(dir + "/dataset-1/dataset-1_" + name + ".bvh");
}

// A clip as the server reads it: quaternions on the wire, Euler angles
// again (equal to 1e-9, but a contact threshold can tell 1e-12 apart, and
// in-process comparisons hold the server to 1e-6).
motion::Motion AsServed(const motion::Motion& clip) {
  v1::Clip wire_clip;
  wire::ClipToProto(clip, &wire_clip);
  return *wire::ClipFromProto(wire_clip, "clip");
}

class ServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    live_ = LiveServer::Start();
    ASSERT_NE(live_, nullptr);
  }
  Client& client() { return *live_->client; }
  std::unique_ptr<LiveServer> live_;
};

TEST_F(ServerTest, ListsGetsUnloadsAndLoadsModels) {
  auto models = client().ListModels();
  ASSERT_TRUE(models.ok()) << models.status();
  ASSERT_EQ(models->size(), 4u);  // models/judges is not a servable family.
  EXPECT_EQ((*models)[0].id(), testing::DefaultPackage());
  EXPECT_EQ((*models)[1].id(), "cyclic/v1");
  EXPECT_EQ((*models)[2].id(), "cyclic/v2");
  EXPECT_EQ((*models)[3].id(), "live/v3");
  EXPECT_EQ((*models)[3].family(), "contrastive");
  EXPECT_EQ((*models)[1].family(), "cyclic");
  EXPECT_EQ((*models)[2].family(), "cyclic");
  EXPECT_FALSE((*models)[1].is_default());
  EXPECT_FALSE((*models)[2].is_default());
  EXPECT_TRUE((*models)[0].is_default());
  EXPECT_EQ((*models)[0].skeleton().joints_size(), 22);
  EXPECT_EQ((*models)[0].window(), 32);
  EXPECT_NEAR((*models)[0].fps(), 30, 1e-3);
  EXPECT_EQ(client().GetModel("contrastive")->id(), testing::DefaultPackage());
  EXPECT_EQ(client().GetModel("cyclic")->id(), "cyclic/v2");  // A bare name: its highest version.
  EXPECT_EQ(client().GetModel("")->id(), testing::DefaultPackage());
  EXPECT_EQ(client().GetModel("nope/v9").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(client().LoadModel(testing::DefaultPackage()).status().code(),
            absl::StatusCode::kAlreadyExists);
  EXPECT_EQ(client().LoadModel("../etc").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(client().LoadModel(testing::DefaultPackage() + "04").status().code(),
            absl::StatusCode::kNotFound);
  // The default stays loaded: calls that name no model use it.
  EXPECT_EQ(client().UnloadModel(testing::DefaultPackage()).code(),
            absl::StatusCode::kFailedPrecondition);
  ASSERT_TRUE(client().UnloadModel("cyclic/v1").ok());
  ASSERT_TRUE(client().UnloadModel("cyclic/v2").ok());
  ASSERT_TRUE(client().UnloadModel("live/v3").ok());
  EXPECT_EQ(client().UnloadModel("cyclic/v2").code(), absl::StatusCode::kNotFound);
  const motion::Motion clip = Sample("walk_normal.bvh");
  CallOptions cyclic;
  cyclic.model = "cyclic";
  EXPECT_EQ(client().Transfer(clip, {&clip, ""}, cyclic).status().code(),
            absl::StatusCode::kNotFound);
  EXPECT_TRUE(client().Transfer(clip, {&clip, ""}).ok());
  auto loaded = client().LoadModel("cyclic/v2");
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  EXPECT_FALSE(loaded->is_default());
  EXPECT_TRUE(client().Transfer(clip, {&clip, ""}, cyclic).ok());
}

TEST_F(ServerTest, BothFamiliesServeSideBySide) {
  STYLUS_REQUIRE_BANDAI(dir);
  const motion::Motion content = BandaiClip(dir, "walk_normal_001");
  const motion::Motion style = BandaiClip(dir, "walk_old_001");
  CallOptions cyclic;
  cyclic.model = "cyclic";
  auto info = client().GetModel("cyclic");
  ASSERT_TRUE(info.ok()) << info.status();
  EXPECT_EQ(info->family(), "cyclic");
  EXPECT_EQ(info->window(), 60);
  auto by_cyclic = client().Transfer(content, {&style, ""}, cyclic);
  ASSERT_TRUE(by_cyclic.ok()) << by_cyclic.status();
  auto by_contrastive = client().Transfer(content, {&style, ""});
  ASSERT_TRUE(by_contrastive.ok()) << by_contrastive.status();
  ASSERT_EQ(by_cyclic->num_frames, content.num_frames);
  EXPECT_GT(motion::MaxPositionDifference(*by_cyclic, *by_contrastive), 1.0);
  // The server's cyclic output is the model's (the bare name's highest
  // version, v2), in process.
  auto local_model = model::LoadStyleModel(testing::SourceDir() + "/models/cyclic/v2");
  ASSERT_TRUE(local_model.ok()) << local_model.status();
  const absl::StatusOr<model::StyleCode> local_code = (*local_model)->EncodeStyle(style);
  ASSERT_TRUE(local_code.ok()) << local_code.status();
  const motion::Motion local = (*local_model)->Transfer(content, *local_code)->motion;
  EXPECT_LT(motion::MaxPositionDifference(*by_cyclic, local), 1e-3);
  // Style codes are per model: v2's style network gives its own code size.
  auto code = client().EncodeStyle(style, "old-cyclic", cyclic);
  ASSERT_TRUE(code.ok()) << code.status();
  EXPECT_EQ(code->size(), local_code->values.size());
  EXPECT_NE(code->size(), 144u);  // Not the contrastive model's.
  auto named = client().Transfer(content, {nullptr, "old-cyclic"}, cyclic);
  ASSERT_TRUE(named.ok()) << named.status();
  EXPECT_LT(motion::MaxPositionDifference(*named, *by_cyclic), 1e-3);
  EXPECT_EQ(client().Transfer(content, {nullptr, "old-cyclic"}).status().code(),
            absl::StatusCode::kNotFound);  // Saved for cyclic/v2 only.
  // Streaming a cyclic model goes in chunks through its transfer in the
  // configured form (streams are not guarded): every frame comes back, in
  // order, close to the unguarded whole-clip output and without root jumps.
  const motion::Motion part = Frames(content, 0, 100);
  auto streamed = client().Stream(part, {&style, ""}, 0, cyclic);
  ASSERT_TRUE(streamed.ok()) << streamed.status();
  ASSERT_EQ(streamed->output.num_frames, 100);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(streamed->indices[i], i);
  model::TransferOptions unguarded;
  unguarded.content_guard = false;
  auto unary = (*local_model)->Transfer(part, *local_code, unguarded);
  ASSERT_TRUE(unary.ok()) << unary.status();
  const double gap = motion::MaxPositionDifference(streamed->output, unary->motion);
  std::printf("cyclic stream vs unary: max joint gap %.2f units\n", gap);
  EXPECT_LT(gap, 15.0);  // Units of the Bandai rig (cm): chunk seams, not a different motion.
}

TEST_F(ServerTest, TransferOfARealClipEqualsTheModelInProcess) {
  STYLUS_REQUIRE_BANDAI(dir);
  const motion::Motion content = BandaiClip(dir, "walk_normal_001");
  const motion::Motion style = BandaiClip(dir, "walk_old_001");
  auto out = client().Transfer(content, {&style, ""});
  ASSERT_TRUE(out.ok()) << out.status();
  auto model = model::ContrastiveModel::Load(kModel);
  ASSERT_TRUE(model.ok());
  const motion::Motion local =
      (*model)->Transfer(AsServed(content), *(*model)->EncodeStyle(AsServed(style)))->motion;
  ASSERT_EQ(out->num_frames, content.num_frames);
  EXPECT_LT(motion::MaxPositionDifference(*out, local), 1e-6);
  EXPECT_GT(motion::MaxPositionDifference(*out, content), 1.0);
}

TEST_F(ServerTest, SavedStyleNamesWorkLikeTheirClips) {
  const motion::Motion content = Sample("walk_normal.bvh"), style = Sample("walk_old.bvh");
  auto code = client().EncodeStyle(style, "old");
  ASSERT_TRUE(code.ok()) << code.status();
  EXPECT_EQ(code->size(), 144u);
  auto by_clip = client().Transfer(content, {&style, ""});
  auto by_name = client().Transfer(content, {nullptr, "old"});
  ASSERT_TRUE(by_clip.ok() && by_name.ok());
  // A saved style keeps the code and cadence, not the clip (the bank holds a
  // few values per name): its movement is the network's, or a library's.
  // By its clip the old walk's own steps play.
  auto model = model::ContrastiveModel::Load(kModel);
  ASSERT_TRUE(model.ok());
  absl::StatusOr<model::StyleCode> saved = (*model)->EncodeStyle(AsServed(style));
  ASSERT_TRUE(saved.ok());
  saved->example = nullptr;
  const motion::Motion local = (*model)->Transfer(AsServed(content), *saved)->motion;
  EXPECT_LT(motion::MaxPositionDifference(*by_name, local), 1e-6);
  EXPECT_GT(motion::MaxPositionDifference(*by_clip, *by_name), 1.0);
  auto missing = client().Transfer(content, {nullptr, "young"});
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("young"), std::string::npos);
}

// A package whose movement is the network's (here cyclic/v2): TIMING_STYLE
// warps the output to the style clip's cadence. (With movement from
// examples it is a pace: MovementServerTest.)
TEST_F(ServerTest, StyleTimingWarpsTheOutputToTheStyleCadence) {
  STYLUS_REQUIRE_BANDAI(dir);
  const motion::Motion content = BandaiClip(dir, "walk_normal_001");
  const motion::Motion style = BandaiClip(dir, "walk_tired_001");
  const motion::HumanoidRoles roles = *motion::HumanoidRolesOf(content);
  const motion::Cadence content_cadence = *motion::FindCadence(content, roles);
  const double ratio = *motion::TempoRatio(content_cadence, *motion::FindCadence(style, roles));
  const double content_period = content_cadence.period_s, style_period = content_period * ratio;
  ASSERT_GT(std::abs(style_period / content_period - 1), 0.05);  // A warp worth seeing.

  CallOptions content_timed;
  content_timed.model = "cyclic/v2";
  auto plain = client().Transfer(content, {&style, ""}, content_timed);
  ASSERT_TRUE(plain.ok()) << plain.status();
  v1::TimeWarp warp;
  CallOptions options;
  options.model = "cyclic/v2";
  options.timing = v1::TIMING_STYLE;
  options.time_warp = &warp;
  auto warped = client().Transfer(content, {&style, ""}, options);
  ASSERT_TRUE(warped.ok()) << warped.status();
  ASSERT_TRUE(warp.applied()) << warp.reason();
  EXPECT_NEAR(warp.content_period_s(), content_period, 1e-9);
  EXPECT_NEAR(warp.style_period_s(), style_period, 1e-9);
  EXPECT_NEAR(warp.ratio(), style_period / content_period, 1e-9);
  ASSERT_EQ(warped->num_frames, std::lround((content.num_frames - 1) * warp.ratio()) + 1);
  EXPECT_DOUBLE_EQ(warped->frame_time, content.frame_time);
  // The content-timed transfer, played slower: the same poses at the warped
  // times (up to interpolation), the same last frame, feet still planted.
  EXPECT_LT(motion::MaxPositionDifference(motion::TimeWarp(*plain, warp.ratio()), *warped), 1e-6);
  // Its motion repeats that much more slowly.
  EXPECT_NEAR(*motion::TempoRatio(*motion::FindCadence(*plain, roles),
                                  *motion::FindCadence(*warped, roles)),
              warp.ratio(), 0.06 * warp.ratio());

  // A saved style keeps its cadence.
  ASSERT_TRUE(client().EncodeStyle(style, "tired", content_timed).ok());
  v1::TimeWarp by_name;
  options.time_warp = &by_name;
  auto named = client().Transfer(content, {nullptr, "tired"}, options);
  ASSERT_TRUE(named.ok()) << named.status();
  EXPECT_NEAR(by_name.ratio(), warp.ratio(), 1e-9);
  EXPECT_EQ(named->num_frames, warped->num_frames);

  // A content whose motion does not repeat keeps its timing, and says why.
  const motion::Motion bow = BandaiClip(dir, "bow_normal_001");
  v1::TimeWarp none;
  options.time_warp = &none;
  auto kept = client().Transfer(bow, {&style, ""}, options);
  ASSERT_TRUE(kept.ok()) << kept.status();
  EXPECT_FALSE(none.applied());
  EXPECT_NE(none.reason().find("content clip has no cadence"), std::string::npos) << none.reason();
  EXPECT_EQ(kept->num_frames, bow.num_frames);
}

TEST_F(ServerTest, InterpolationEndpointsEqualTransfersAndSchedulesWork) {
  const motion::Motion content = Sample("walk_normal.bvh");
  const motion::Motion a = Sample("walk_old.bvh"), b = Sample("run.bvh");
  auto to_a = client().Transfer(content, {&a, ""});
  auto to_b = client().Transfer(content, {&b, ""});
  auto w0 = client().Interpolate(content, {{&a, ""}, {&b, ""}}, {1, 0});
  auto w1 = client().Interpolate(content, {{&a, ""}, {&b, ""}}, {0, 1});
  ASSERT_TRUE(to_a.ok() && to_b.ok() && w0.ok() && w1.ok());
  EXPECT_LT(motion::MaxPositionDifference(*w0, *to_a), 1e-6);
  EXPECT_LT(motion::MaxPositionDifference(*w1, *to_b), 1e-6);
  std::vector<std::vector<double>> schedule;
  for (int f = 0; f < content.num_frames; ++f) {
    const double t = static_cast<double>(f) / (content.num_frames - 1);
    schedule.push_back({1 - t, t});
  }
  auto ramp = client().Interpolate(content, {{&a, ""}, {&b, ""}}, {}, schedule);
  ASSERT_TRUE(ramp.ok()) << ramp.status();
  EXPECT_EQ(ramp->num_frames, content.num_frames);
  EXPECT_EQ(client().Interpolate(content, {{&a, ""}}, {1}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(client().Interpolate(content, {{&a, ""}, {&b, ""}}, {1, 0, 0}).status().code(),
            absl::StatusCode::kInvalidArgument);
  schedule.pop_back();
  EXPECT_EQ(client().Interpolate(content, {{&a, ""}, {&b, ""}}, {}, schedule).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST_F(ServerTest, StreamOfARealClipMatchesUnaryTransfer) {
  STYLUS_REQUIRE_BANDAI(dir);
  const motion::Motion content = BandaiClip(dir, "walk_normal_002");
  const motion::Motion style = BandaiClip(dir, "walk_proud_001");
  CallOptions raw;
  raw.postprocess = v1::POSTPROCESS_NONE;
  auto streamed = client().Stream(content, {&style, ""}, /*rate=*/0, raw);
  ASSERT_TRUE(streamed.ok()) << streamed.status();
  ASSERT_EQ(streamed->output.num_frames, content.num_frames);
  for (int f = 0; f < content.num_frames; ++f) ASSERT_EQ(streamed->indices[f], f);
  // The unary transfer of the configured form (the default package's guard
  // backs off on this pair: its configured transfer reads as a wave).
  auto model = model::ContrastiveModel::Load(testing::CopyPackage(
      kModel, "unguarded_v8", {"content_guard", "guard_strengths", "movement_action_gate"}));
  ASSERT_TRUE(model.ok()) << model.status();
  auto unary = MotionOf(
      (*model)->Transfer(content, *(*model)->EncodeStyle(style), motion::PostProcessMode::kNone));
  ASSERT_TRUE(unary.ok()) << unary.status();
  // Stated tolerance (docs/service.md): 0.5 mm on any joint of any frame.
  EXPECT_LT(motion::MaxPositionDifference(streamed->output, *unary), 0.05);
  EXPECT_EQ(streamed->latency_s.size(), static_cast<size_t>(content.num_frames));
}

TEST_F(ServerTest, TransferSaysWhatTheContentGuardDid) {
  STYLUS_REQUIRE_BANDAI(dir);
  // The default package's guard backs this pair off (see the test above) and
  // keeps the configured transfer of an old walk onto a normal one.
  v1::ContentGuardNote guard;
  CallOptions options;
  options.content_guard = &guard;
  const motion::Motion content = BandaiClip(dir, "walk_normal_002");
  const motion::Motion style = BandaiClip(dir, "walk_proud_001");
  ASSERT_TRUE(client().Transfer(content, {&style, ""}, options).ok());
  EXPECT_TRUE(guard.backed_off());
  const std::vector<double> strengths = {1, 0.9, 0.8, 0.7, 0.55, 0.4, 0.2};
  EXPECT_NE(std::find(strengths.begin(), strengths.end(), guard.residual_strength()),
            strengths.end())
      << guard.residual_strength();
  const motion::Motion walk = BandaiClip(dir, "walk_normal_001");
  const motion::Motion old = BandaiClip(dir, "walk_old_001");
  ASSERT_TRUE(client().Transfer(walk, {&old, ""}, options).ok());
  EXPECT_FALSE(guard.backed_off());
  EXPECT_EQ(guard.residual_strength(), 1);
}

TEST_F(ServerTest, MetricsOfAClipAgainstItsContent) {
  const motion::Motion content = Sample("walk_normal.bvh"), style = Sample("walk_old.bvh");
  auto m = client().ComputeMetrics(content, &content, &style);
  ASSERT_TRUE(m.ok()) << m.status();
  for (const char* k : {"foot_skating", "foot_height_error", "bone_length_error", "jitter",
                        "trajectory_error", "max_euler_step_deg", "content_jitter", "style_jitter"})
    EXPECT_TRUE(m->count(k)) << k;
  EXPECT_NEAR(m->at("trajectory_error"), 0, 1e-9);
  EXPECT_NEAR(m->at("jitter"), m->at("content_jitter"), 1e-9);
  const motion::Motion other =
      *motion::ReadBvhFile(testing::FixturePath("bvh/good/three_joint.bvh"));
  EXPECT_EQ(client().ComputeMetrics(content, &other, nullptr).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST_F(ServerTest, BadClipsGetInvalidArgumentNamingTheProblem) {
  const motion::Motion content = Sample("walk_normal.bvh"), style = Sample("walk_old.bvh");
  const motion::Motion other =
      *motion::ReadBvhFile(testing::FixturePath("bvh/good/three_joint.bvh"));
  auto wrong = client().Transfer(other, {&style, ""});
  EXPECT_EQ(wrong.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(wrong.status().message().find("not a humanoid rig"), std::string::npos)
      << wrong.status();

  motion::Motion nan = content;
  nan.frame(7)[5] = std::numeric_limits<double>::quiet_NaN();
  auto bad = client().Transfer(nan, {&style, ""});
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("frame 7"), std::string::npos) << bad.status();

  auto empty = client().Transfer(Frames(content, 0, 0), {&style, ""});
  EXPECT_EQ(empty.status().code(), absl::StatusCode::kInvalidArgument) << empty.status();
  // Shorter than a window: padded, and the output keeps the length.
  auto short_clip = client().Transfer(Frames(content, 0, 5), {&style, ""});
  ASSERT_TRUE(short_clip.ok()) << short_clip.status();
  EXPECT_EQ(short_clip->num_frames, 5);
  EXPECT_EQ(client().Transfer(content, {nullptr, ""}).status().code(),
            absl::StatusCode::kInvalidArgument);
  CallOptions unknown;
  unknown.model = "cyclic/v7";
  EXPECT_EQ(client().Transfer(content, {&style, ""}, unknown).status().code(),
            absl::StatusCode::kNotFound);

  // Hand-made wire messages: wrong rotation count, zero quaternion, bad fps.
  auto stub = v1::StyleService::NewStub(
      grpc::CreateChannel(live_->address, grpc::InsecureChannelCredentials()));
  v1::TransferRequest request;
  wire::ClipToProto(content, request.mutable_content());
  wire::ClipToProto(style, request.mutable_style()->mutable_clip());
  v1::TransferResponse response;
  {
    v1::TransferRequest r = request;
    r.mutable_content()->mutable_frames(3)->mutable_rotations()->RemoveLast();
    grpc::ClientContext ctx;
    const grpc::Status s = stub->Transfer(&ctx, r, &response);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(s.error_message().find("frame 3"), std::string::npos) << s.error_message();
  }
  {
    v1::TransferRequest r = request;
    *r.mutable_content()->mutable_frames(2)->mutable_rotations(4) = v1::Quaternion();
    grpc::ClientContext ctx;
    const grpc::Status s = stub->Transfer(&ctx, r, &response);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(s.error_message().find("zero quaternion"), std::string::npos) << s.error_message();
  }
  {
    v1::TransferRequest r = request;
    r.mutable_content()->set_fps(-3);
    grpc::ClientContext ctx;
    EXPECT_EQ(stub->Transfer(&ctx, r, &response).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  }
  // The server is still fine.
  EXPECT_TRUE(client().Transfer(content, {&style, ""}).ok());
}

// Sends `requests` on one TransferStream and returns the final status.
grpc::Status RawStream(const std::string& address, const std::vector<v1::StreamRequest>& requests,
                       int* received = nullptr) {
  auto stub =
      v1::StyleService::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  auto stream = stub->TransferStream(&ctx);
  for (const auto& r : requests) {
    if (!stream->Write(r)) break;
  }
  stream->WritesDone();
  v1::StreamResponse response;
  int n = 0;
  while (stream->Read(&response)) ++n;
  if (received) *received = n;
  return stream->Finish();
}

std::vector<v1::StreamRequest> StreamRequests(const motion::Motion& content,
                                              const motion::Motion& style,
                                              const std::vector<int64_t>& indices) {
  std::vector<v1::StreamRequest> out(1);
  v1::StreamConfig* c = out[0].mutable_config();
  c->set_fps(content.fps());
  wire::SkeletonToProto(content.skeleton, c->mutable_skeleton());
  wire::ClipToProto(style, c->mutable_style()->mutable_clip());
  for (size_t i = 0; i < indices.size(); ++i) {
    v1::StreamRequest r;
    wire::FrameToProto(content, static_cast<int>(i), indices[i], r.mutable_frame());
    out.push_back(r);
  }
  return out;
}

TEST_F(ServerTest, StreamProtocolErrorsGetClearStatuses) {
  const motion::Motion content = Sample("walk_normal.bvh"), style = Sample("walk_old.bvh");
  std::vector<int64_t> good(60);
  for (int i = 0; i < 60; ++i) good[i] = 1000 + i;
  int received = 0;
  grpc::Status s = RawStream(live_->address, StreamRequests(content, style, good), &received);
  EXPECT_TRUE(s.ok()) << s.error_message();
  EXPECT_EQ(received, 60);

  std::vector<int64_t> swapped = good;
  std::swap(swapped[40], swapped[41]);
  s = RawStream(live_->address, StreamRequests(content, style, swapped));
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("frame index 1041"), std::string::npos) << s.error_message();

  std::vector<int64_t> duplicate = good;
  duplicate[10] = duplicate[9];
  s = RawStream(live_->address, StreamRequests(content, style, duplicate));
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  auto no_config = StreamRequests(content, style, good);
  no_config.erase(no_config.begin());
  s = RawStream(live_->address, no_config);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("config"), std::string::npos);

  auto unknown_model = StreamRequests(content, style, good);
  unknown_model[0].mutable_config()->set_model("nope/v1");
  EXPECT_EQ(RawStream(live_->address, unknown_model).error_code(), grpc::StatusCode::NOT_FOUND);

  const motion::Motion other =
      *motion::ReadBvhFile(testing::FixturePath("bvh/good/three_joint.bvh"));
  auto wrong_skeleton = StreamRequests(content, style, good);
  wire::SkeletonToProto(other.skeleton, wrong_skeleton[0].mutable_config()->mutable_skeleton());
  EXPECT_EQ(RawStream(live_->address, wrong_skeleton).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);

  auto nan = StreamRequests(content, style, good);
  nan[20].mutable_frame()->mutable_root_position()->set_x(std::nan(""));
  s = RawStream(live_->address, nan);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("frame 1019"), std::string::npos) << s.error_message();
}

TEST_F(ServerTest, CancelledStreamsLeaveTheServerHealthy) {
  const motion::Motion content = Sample("walk_normal.bvh"), style = Sample("walk_old.bvh");
  std::vector<int64_t> idx(100);
  for (int i = 0; i < 100; ++i) idx[i] = i;
  const auto requests = StreamRequests(content, style, idx);
  for (int round = 0; round < 5; ++round) {
    auto stub = v1::StyleService::NewStub(
        grpc::CreateChannel(live_->address, grpc::InsecureChannelCredentials()));
    auto ctx = std::make_unique<grpc::ClientContext>();
    auto stream = stub->TransferStream(ctx.get());
    for (int i = 0; i < 80; ++i) stream->Write(requests[i]);  // Enough for output.
    if (round % 2 == 1) {
      // Also wait for some output first, so that writes are in flight.
      v1::StreamResponse r;
      stream->Read(&r);
    }
    ctx->TryCancel();  // Cancels mid-stream.
    EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::CANCELLED);
  }
  auto out = client().Stream(content, {&style, ""}, 0);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->output.num_frames, content.num_frames);
}

TEST_F(ServerTest, ExpiredDeadlineIsReported) {
  const motion::Motion content = Sample("walk_normal.bvh"), style = Sample("walk_old.bvh");
  ClientOptions o;
  o.address = live_->address;
  o.deadline = std::chrono::milliseconds(1);
  Client hurried(o);
  auto out = hurried.Transfer(content, {&style, ""});
  EXPECT_EQ(out.status().code(), absl::StatusCode::kDeadlineExceeded) << out.status();
  EXPECT_TRUE(client().Transfer(content, {&style, ""}).ok());
}

TEST(ServerLimitsTest, OversizeMessagesAndTooManyStreamsAreResourceExhausted) {
  server::ServerOptions options;
  options.max_message_mb = 1;
  options.max_streams = 1;
  auto live = LiveServer::Start(options);
  ASSERT_NE(live, nullptr);
  const motion::Motion style = Sample("walk_old.bvh");
  motion::Motion big = Sample("walk_normal.bvh");
  while (big.num_frames < 4000) {
    big.values.insert(big.values.end(), big.values.begin(), big.values.end());
    big.num_frames *= 2;
  }
  auto out = live->client->Transfer(big, {&style, ""});
  EXPECT_EQ(out.status().code(), absl::StatusCode::kResourceExhausted) << out.status();

  // One stream open; a second is refused.
  auto stub = v1::StyleService::NewStub(
      grpc::CreateChannel(live->address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  auto open = stub->TransferStream(&ctx);
  std::vector<int64_t> idx = {0};
  const auto requests = StreamRequests(style, style, idx);
  ASSERT_TRUE(open->Write(requests[0]));
  ASSERT_TRUE(open->Write(requests[1]));
  ASSERT_TRUE(testing::WaitFor([&] { return live->server->load().open_streams == 1; }));
  const grpc::Status second = RawStream(live->address, requests);
  EXPECT_EQ(second.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << second.error_message();
  open->WritesDone();
  v1::StreamResponse r;
  while (open->Read(&r)) {
  }
  EXPECT_TRUE(open->Finish().ok());
}

TEST(ServerShutdownTest, InFlightCallsFinishBeforeTheServerStops) {
  STYLUS_REQUIRE_BANDAI(dir);
  auto live = LiveServer::Start();
  ASSERT_NE(live, nullptr);
  motion::Motion content = BandaiClip(dir, "walk_normal_001");
  for (int i = 0; i < 4; ++i) {  // ~3000 frames: long enough to be in flight.
    content.values.insert(content.values.end(), content.values.begin(), content.values.end());
    content.num_frames *= 2;
  }
  const motion::Motion style = BandaiClip(dir, "walk_old_001");
  // Connect first: on a loaded machine the channel's first connection can
  // take longer than the wait below, and the call would then arrive after the
  // shutdown (refused, as it should be, but not what this test is about).
  ASSERT_TRUE(live->client->ListModels().ok());
  // ListModels' executor task may still be winding down after its reply:
  // only the transfer's task may count below.
  ASSERT_TRUE(testing::WaitFor([&] { return live->server->load().running_tasks == 0; }));
  auto pending = std::async(std::launch::async, [&] {
    return live->client->Transfer(content, {&style, ""});
  });
  ASSERT_TRUE(testing::WaitFor([&] { return live->server->load().running_tasks > 0; }));
  live->server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(30));
  auto out = pending.get();
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->num_frames, content.num_frames);
  // After shutdown, new calls are refused.
  auto late = live->client->ListModels();
  EXPECT_EQ(late.status().code(), absl::StatusCode::kUnavailable) << late.status();
}

}  // namespace
}  // namespace stylus
