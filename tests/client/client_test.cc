// client/client: what the client checks before it sends, and how a call
// fails when no server answers. (Calls against a real server are in
// tests/server/server_test.cc.)
#include "client/client.h"

#include <chrono>
#include <cmath>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "tests/test_support.h"

namespace stylus {
namespace {

motion::Motion Sample(const std::string& name) {
  return *motion::ReadBvhFile(testing::SourceDir() + "/samples/" + name);
}

// Port 1 on localhost: nothing listens there.
Client Unreachable(std::chrono::milliseconds deadline = std::chrono::seconds(5)) {
  ClientOptions o;
  o.address = "localhost:1";
  o.deadline = deadline;
  return Client(o);
}

TEST(ClientTest, BadStylesAreRefusedBeforeAnythingIsSent) {
  Client client = Unreachable();
  const motion::Motion walk = Sample("walk_normal.bvh");
  // No style at all: INVALID_ARGUMENT, not the UNAVAILABLE a send would give.
  EXPECT_EQ(client.Transfer(walk, {nullptr, ""}).status().code(),
            absl::StatusCode::kInvalidArgument);
  motion::Motion nan = Sample("walk_old.bvh");
  nan.values[7] = std::nanf("");
  const absl::Status s = client.Transfer(walk, {&nan, ""}).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
  EXPECT_NE(s.message().find("style clip"), absl::string_view::npos) << s;
  EXPECT_EQ(client.Interpolate(walk, {{&nan, ""}, {&walk, ""}}, {0.5, 0.5}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(client.Stream(walk, {nullptr, ""}, 0).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(ClientTest, NoServerIsUnavailableWithinTheDeadline) {
  Client client = Unreachable(std::chrono::seconds(2));
  const auto t0 = std::chrono::steady_clock::now();
  const absl::StatusOr<std::vector<v1::ModelInfo>> models = client.ListModels();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_FALSE(models.ok());
  EXPECT_TRUE(models.status().code() == absl::StatusCode::kUnavailable ||
              models.status().code() == absl::StatusCode::kDeadlineExceeded)
      << models.status();
  EXPECT_LT(seconds, 30.0);  // Bounded by the deadline, not hanging.
}

}  // namespace
}  // namespace stylus
