// A server with a style library: a transfer whose style clip shows another
// kind of movement takes it from the library's take of the style, and says
// so in its response; a library that cannot be read stops the start.
#include <grpcpp/grpcpp.h>

#include <filesystem>

#include "gtest/gtest.h"
#include "stylus/v1/stylus.grpc.pb.h"
#include "tests/server/server_test_support.h"
#include "wire/wire.h"

namespace stylus {
namespace {

namespace fs = std::filesystem;

TEST(MovementServerTest, AStyleLibraryGivesAWalkTheStylesStepsAndTheResponseSaysWhich) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::string lib = ::testing::TempDir() + "/server_style_library";
  fs::remove_all(lib);
  fs::create_directories(lib);
  for (const char* name : {"walk_elderly_003", "walk_youthful_002"}) {
    const std::string file = std::string("dataset-2_") + name + ".bvh";
    fs::create_symlink(fs::absolute(data + "/dataset-2/" + file), lib + "/" + file);
  }
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
