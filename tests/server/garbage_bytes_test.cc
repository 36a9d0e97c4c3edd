// Bytes that are not a request: every method of a real server answers them
// INVALID_ARGUMENT (never UNIMPLEMENTED, which would say the method does not
// exist), and the server goes on serving.
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <random>
#include <string>
#include <vector>

#include "server/raw_message.h"
#include "tests/server/server_test_support.h"
#include "wire/wire.h"

namespace stylus::testing {
namespace {

struct Method {
  std::string path;
  bool stream = false;
};

const std::vector<Method>& Methods() {
  static const std::vector<Method> methods = {
      {"/stylus.v1.ModelService/ListModels"},
      {"/stylus.v1.ModelService/GetModel"},
      {"/stylus.v1.ModelService/LoadModel"},
      {"/stylus.v1.ModelService/UnloadModel"},
      {"/stylus.v1.StyleService/Transfer"},
      {"/stylus.v1.StyleService/EncodeStyle"},
      {"/stylus.v1.StyleService/Interpolate"},
      {"/stylus.v1.StyleService/ComputeMetrics"},
      {"/stylus.v1.StyleService/TransferStream", true},
  };
  return methods;
}

grpc::ByteBuffer Bytes(const std::string& s) {
  grpc::Slice slice(s);
  return grpc::ByteBuffer(&slice, 1);
}

class GarbageBytesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    live_ = LiveServer::Start();
    ASSERT_NE(live_, nullptr);
    channel_ = grpc::CreateChannel(live_->address, grpc::InsecureChannelCredentials());
    stub_ = std::make_unique<grpc::GenericStub>(channel_);
  }

  // Sends `bytes` as the one message of `method` (a stream then half-closes)
  // and returns the call's status.
  grpc::Status Call(const Method& method, const std::string& bytes) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    if (!method.stream) {
      grpc::CompletionQueue cq;
      grpc::ByteBuffer response;
      grpc::Status status;
      std::unique_ptr<grpc::GenericClientAsyncResponseReader> call =
          stub_->PrepareUnaryCall(&ctx, method.path, Bytes(bytes), &cq);
      call->StartCall();
      call->Finish(&response, &status, reinterpret_cast<void*>(1));
      void* tag = nullptr;
      bool ok = false;
      EXPECT_TRUE(cq.Next(&tag, &ok));
      return status;
    }
    grpc::CompletionQueue cq;
    std::unique_ptr<grpc::GenericClientAsyncReaderWriter> call =
        stub_->PrepareCall(&ctx, method.path, &cq);
    auto step = [&cq] {
      void* tag = nullptr;
      bool ok = false;
      EXPECT_TRUE(cq.Next(&tag, &ok));
      return ok;
    };
    call->StartCall(reinterpret_cast<void*>(1));
    step();
    call->Write(Bytes(bytes), reinterpret_cast<void*>(2));
    step();
    call->WritesDone(reinterpret_cast<void*>(3));
    step();
    grpc::ByteBuffer response;
    do {
      call->Read(&response, reinterpret_cast<void*>(4));
    } while (step());
    grpc::Status status;
    call->Finish(&status, reinterpret_cast<void*>(5));
    step();
    return status;
  }

  std::unique_ptr<LiveServer> live_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<grpc::GenericStub> stub_;
};

TEST_F(GarbageBytesTest, TruncatedBytesAreInvalidArgumentOnEveryMethod) {
  // A real Transfer request cut short, and a field whose length runs past
  // the end: neither parses as any message.
  v1::TransferRequest request;
  wire::ClipToProto(Sample("walk_normal.bvh"), request.mutable_content());
  wire::ClipToProto(Sample("walk_old.bvh"), request.mutable_style()->mutable_clip());
  const std::string whole = request.SerializeAsString();
  for (const std::string& bytes : {whole.substr(0, whole.size() / 2), std::string("\x0a\x05"
                                                                                  "ab")}) {
    for (const Method& m : Methods()) {
      const grpc::Status s = Call(m, bytes);
      EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
          << m.path << " (" << bytes.size() << " bytes): " << s.error_message();
      EXPECT_NE(s.error_message().find("do not parse as stylus.v1."), std::string::npos)
          << m.path << ": " << s.error_message();
    }
  }
}

TEST_F(GarbageBytesTest, RandomBytesNeverLookLikeAMissingMethod) {
  std::mt19937 rng(7);
  int parse_refusals = 0;
  for (int round = 0; round < 12; ++round) {
    std::string bytes(1 + rng() % 200, '\0');
    for (char& c : bytes) c = static_cast<char>(rng());
    for (const Method& m : Methods()) {
      const grpc::Status s = Call(m, bytes);
      // Bytes that happen to parse are a (strange) request: answered OK
      // (ListModels) or refused for what they say; never as a missing
      // method or a server fault.
      EXPECT_NE(s.error_code(), grpc::StatusCode::UNIMPLEMENTED) << m.path;
      EXPECT_NE(s.error_code(), grpc::StatusCode::INTERNAL) << m.path << ": " << s.error_message();
      EXPECT_NE(s.error_code(), grpc::StatusCode::UNKNOWN) << m.path << ": " << s.error_message();
      if (s.error_message().find("do not parse") != std::string::npos) ++parse_refusals;
    }
  }
  EXPECT_GT(parse_refusals, 0);
  // Still serving, with its models.
  absl::StatusOr<std::vector<v1::ModelInfo>> models = live_->client->ListModels();
  ASSERT_TRUE(models.ok()) << models.status();
  EXPECT_FALSE(models->empty());
}

// A stream's requests parse one after another on one arena: each is read
// whole, whatever the one before held, and a bad one is named by its index.
TEST(RawMessageTest, StreamRequestsParseInTurnOnOneArena) {
  server::StreamRequests<v1::StreamRequest> requests;
  v1::StreamRequest frame, change;
  for (int j = 0; j < 40; ++j) {
    v1::Quaternion* q = frame.mutable_frame()->add_rotations();
    q->set_w(1);
    q->set_x(0.01 * j);
  }
  frame.mutable_frame()->set_index(7);
  change.mutable_change()->set_from_frame(9);
  change.mutable_change()->set_strength(0.5);
  grpc::ByteBuffer frame_bytes, change_bytes;
  ASSERT_TRUE(server::SerializeMessage(frame, &frame_bytes).ok());
  ASSERT_TRUE(server::SerializeMessage(change, &change_bytes).ok());
  for (int round = 0; round < 3; ++round) {
    absl::StatusOr<const v1::StreamRequest*> a = requests.Parse(frame_bytes, 2 * round, "message");
    ASSERT_TRUE(a.ok()) << a.status();
    EXPECT_EQ((*a)->frame().index(), 7);
    ASSERT_EQ((*a)->frame().rotations_size(), 40);
    EXPECT_DOUBLE_EQ((*a)->frame().rotations(39).x(), 0.39);
    absl::StatusOr<const v1::StreamRequest*> b =
        requests.Parse(change_bytes, 2 * round + 1, "message");
    ASSERT_TRUE(b.ok()) << b.status();
    EXPECT_FALSE((*b)->has_frame());
    EXPECT_EQ((*b)->change().from_frame(), 9);
  }
  const absl::StatusOr<const v1::StreamRequest*> bad = requests.Parse(Bytes("\x0a\x09"
                                                                            "short"),
                                                                      12, "stream message");
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(bad.status().message(),
            "stream message 12: its 7 bytes do not parse as stylus.v1.StreamRequest (truncated, or "
            "not this message)");
}

TEST(RawMessageTest, ParsesWhatSerializes) {
  v1::GetModelRequest request;
  request.set_model("contrastive/v1");
  grpc::ByteBuffer bytes;
  ASSERT_TRUE(server::SerializeMessage(request, &bytes).ok());
  v1::GetModelRequest parsed;
  parsed.set_model("left over");
  ASSERT_TRUE(server::ParseMessage(bytes, "the request", &parsed).ok());
  EXPECT_EQ(parsed.model(), "contrastive/v1");
  // The bytes can be parsed again (the parse does not consume them).
  ASSERT_TRUE(server::ParseMessage(bytes, "the request", &parsed).ok());
  const absl::Status bad = server::ParseMessage(Bytes("\x0a\x09"
                                                      "short"),
                                                "message 3", &parsed);
  EXPECT_EQ(bad.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(bad.message(),
            "message 3: its 7 bytes do not parse as stylus.v1.GetModelRequest (truncated, or not "
            "this message)");
  EXPECT_EQ(parsed.model(), "");  // Left empty, not half filled.
}

}  // namespace
}  // namespace stylus::testing
