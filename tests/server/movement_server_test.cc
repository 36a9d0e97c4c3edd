// A server with a style library: a transfer whose style clip shows another
// kind of movement takes it from the library's take of the style, and says
// so in its response; a live stream moves from the style clip's and the
// library's takes; a library that cannot be read stops the start.
#include <grpcpp/grpcpp.h>

#include <set>

#include "gtest/gtest.h"
#include "motion/gait.h"
#include "motion/rig_roles.h"
#include "stylus/v1/stylus.grpc.pb.h"
#include "tests/server/server_test_support.h"
#include "wire/wire.h"

namespace stylus {
namespace {

TEST(MovementServerTest, AStyleLibraryGivesAWalkTheStylesStepsAndTheResponseSaysWhich) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::string lib =
      testing::LinkLibrary(data, "server_style_library", {"walk_elderly_003", "walk_youthful_002"});
  server::ServerOptions options;
  options.style_library = lib;
  std::unique_ptr<testing::LiveServer> live = testing::LiveServer::Start(options);
  ASSERT_NE(live, nullptr);
  auto stub = v1::StyleService::NewStub(
      grpc::CreateChannel(live->address, grpc::InsecureChannelCredentials()));
  v1::TransferRequest request;
  wire::ClipToProto(*motion::ReadBvhFile(data + "/dataset-2/dataset-2_walk_normal_004.bvh"),
                    request.mutable_content());
  // The style shown by a raise only: the library's elderly walk moves the legs
  // (the library's style nearest the clip's code; two styles to choose from).
  wire::ClipToProto(
      *motion::ReadBvhFile(data + "/dataset-2/dataset-2_raise-up-right-hand_elderly_009.bvh"),
      request.mutable_style()->mutable_clip());
  v1::TransferResponse response;
  grpc::ClientContext ctx;
  const grpc::Status s = stub->Transfer(&ctx, request, &response);
  ASSERT_TRUE(s.ok()) << s.error_message();
  ASSERT_TRUE(response.has_movement());
  EXPECT_TRUE(response.movement().applied()) << response.movement().reason();
  EXPECT_EQ(response.movement().kind(), "steps");
  EXPECT_TRUE(response.movement().example() == "dataset-2_walk_elderly_003.bvh" ||
              response.movement().example() == "dataset-2_walk_youthful_002.bvh")
      << response.movement().example();
  EXPECT_EQ(response.output().frames_size(), request.content().frames_size());
  // The output's own contacts, within its frames, for all four foot joints.
  std::set<std::string> joints;
  for (const v1::FootContact& c : response.contacts()) {
    joints.insert(c.joint());
    EXPECT_TRUE(0 <= c.begin() && c.begin() < c.end() && c.end() <= response.output().frames_size())
        << c.ShortDebugString();
  }
  EXPECT_EQ(joints, (std::set<std::string>{"left_ankle", "left_toe", "right_ankle", "right_toe"}));

  // A pace: the content's path at the example's speed, with a time map.
  {
    v1::TransferRequest paced = request;
    paced.set_timing(v1::TIMING_STYLE);
    v1::TransferResponse r;
    grpc::ClientContext c;
    ASSERT_TRUE(stub->Transfer(&c, paced, &r).ok());
    ASSERT_TRUE(r.time_warp().applied()) << r.time_warp().reason();
    EXPECT_NE(r.output().frames_size(), request.content().frames_size());
    ASSERT_EQ(r.time_warp().content_time_s_size(), r.output().frames_size());
    const double last = r.time_warp().content_time_s(r.output().frames_size() - 1);
    EXPECT_NEAR(last, (request.content().frames_size() - 1) / request.content().fps(), 0.02);
  }
  // An exact length, and one too far from the content's refused.
  for (int fit : {request.content().frames_size() + 45, request.content().frames_size() * 3}) {
    v1::TransferRequest fitted = request;
    fitted.set_fit_frames(fit);
    v1::TransferResponse r;
    grpc::ClientContext c;
    const grpc::Status st = stub->Transfer(&c, fitted, &r);
    if (fit < 2 * request.content().frames_size()) {
      ASSERT_TRUE(st.ok()) << st.error_message();
      EXPECT_EQ(r.output().frames_size(), fit);
    } else {
      EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
      EXPECT_NE(st.error_message().find("fit_frames"), std::string::npos) << st.error_message();
    }
  }
}

// The step period of `clip`, in seconds.
double StepPeriod(const motion::Motion& clip) {
  const motion::HumanoidRoles roles = *motion::HumanoidRolesOf(clip);
  const absl::StatusOr<motion::Gait> gait = motion::MeasureGait(clip, roles);
  EXPECT_TRUE(gait.ok() && gait->summary.cadence) << clip.num_frames;
  return gait.ok() && gait->summary.cadence ? gait->summary.cadence->period_s : 0;
}

TEST(MovementServerTest, ALiveStreamStepsAsTheStyleClipAndTheLibraryShow) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::string lib = testing::LinkLibrary(data, "server_stream_library", {"walk_elderly_003"});
  const motion::Motion content =
      *motion::ReadBvhFile(data + "/dataset-2/dataset-2_walk_normal_004.bvh");
  CallOptions on_live;
  on_live.model = "live";
  const double own = StepPeriod(content);
  // The style clip walks: its steps, at the content's speed, shorter (a
  // server without a library).
  std::unique_ptr<testing::LiveServer> plain = testing::LiveServer::Start();
  ASSERT_NE(plain, nullptr);
  const motion::Motion walk =
      *motion::ReadBvhFile(data + "/dataset-2/dataset-2_walk_elderly_005.bvh");
  absl::StatusOr<StreamResult> by_clip = plain->client->Stream(content, {&walk, ""}, 0, on_live);
  ASSERT_TRUE(by_clip.ok()) << by_clip.status();
  ASSERT_EQ(by_clip->output.num_frames, content.num_frames);
  // The style clip only raises a hand: the library's elderly walk steps.
  server::ServerOptions options;
  options.style_library = lib;
  std::unique_ptr<testing::LiveServer> live = testing::LiveServer::Start(options);
  ASSERT_NE(live, nullptr);
  const motion::Motion raise =
      *motion::ReadBvhFile(data + "/dataset-2/dataset-2_raise-up-right-hand_elderly_009.bvh");
  absl::StatusOr<StreamResult> by_library = live->client->Stream(content, {&raise, ""}, 0, on_live);
  ASSERT_TRUE(by_library.ok()) << by_library.status();
  ASSERT_EQ(by_library->output.num_frames, content.num_frames);
  const double clip_period = StepPeriod(by_clip->output);
  const double library_period = StepPeriod(by_library->output);
  std::printf("step period: content %.3f s, by the style clip %.3f, by the library %.3f\n", own,
              clip_period, library_period);
  EXPECT_LT(clip_period, 0.9 * own);
  EXPECT_LT(library_period, 0.9 * own);
}

TEST(MovementServerTest, AStyleLibraryThatCannotBeReadStopsTheStart) {
  server::ServerOptions options;
  options.models_dir = testing::SourceDir() + "/models";
  options.listen = "localhost:0";
  options.style_library = ::testing::TempDir() + "/no_such_library";
  absl::StatusOr<std::unique_ptr<server::StylusServer>> s = server::StylusServer::Start(options);
  EXPECT_EQ(s.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(s.status().message().find("no_such_library"), std::string::npos) << s.status();
}

}  // namespace
}  // namespace stylus
