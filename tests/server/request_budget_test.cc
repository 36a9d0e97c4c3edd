// The request budget on real and crafted requests: what a parse would
// allocate, repeated fields over their caps, long strings, and bytes that
// are not the message.
#include "server/request_budget.h"

#include <google/protobuf/arena.h>

#include <cstdio>
#include <string>

#include "gtest/gtest.h"
#include "tests/server/server_test_support.h"
#include "wire/wire.h"

namespace stylus::testing {
namespace {

grpc::ByteBuffer Bytes(const std::string& s) {
  grpc::Slice slice(s);
  return grpc::ByteBuffer(&slice, 1);
}

server::RequestBudget Budget() {
  server::RequestBudget::Options o;
  o.entries = {{"stylus.v1.Clip.frames", 1000, "--max-clip-frames"},
               {"stylus.v1.InterpolateRequest.styles", 4, "--max-styles"}};
  EXPECT_TRUE(server::RequestBudget::Validate(o).ok());
  return server::RequestBudget(o);
}

TEST(RequestBudgetTest, RealRequestsPassWellWithinTheRatio) {
  const server::RequestBudget budget = Budget();
  v1::TransferRequest r;
  wire::ClipToProto(Sample("walk_normal.bvh"), r.mutable_content());
  wire::ClipToProto(Sample("walk_old.bvh"), r.mutable_style()->mutable_clip());
  r.set_model("contrastive");
  const std::string bytes = r.SerializeAsString();
  EXPECT_TRUE(budget.Check(Bytes(bytes), v1::TransferRequest::descriptor(), "req").ok());
  const int64_t estimate = budget.EstimateParse(Bytes(bytes), v1::TransferRequest::descriptor());
  // What the parse really takes on an arena, as the server parses, against
  // the estimate.
  google::protobuf::Arena arena;
  auto* parsed = google::protobuf::Arena::CreateMessage<v1::TransferRequest>(&arena);
  ASSERT_TRUE(parsed->ParseFromString(bytes));
  const double actual = static_cast<double>(arena.SpaceUsed());
  EXPECT_GE(static_cast<double>(estimate), actual);
  EXPECT_LE(static_cast<double>(estimate), 1.5 * actual);
  EXPECT_LE(static_cast<double>(estimate), 3.0 * bytes.size())
      << "a real clip's parse: " << estimate << " bytes for " << bytes.size() << " on the wire";
  std::printf("real clips: %zu bytes on the wire, parsed into %.0f (estimated %lld)\n",
              bytes.size(), actual, static_cast<long long>(estimate));
}

TEST(RequestBudgetTest, RepeatedFieldsOverTheirCapAreRefusedByPath) {
  const server::RequestBudget budget = Budget();
  v1::TransferRequest r;
  const motion::Motion walk = Sample("walk_normal.bvh");
  v1::Clip* clip = r.mutable_style()->mutable_clip();
  wire::ClipToProto(walk, clip);
  while (clip->frames_size() <= 1000) *clip->add_frames() = clip->frames(0);
  const absl::Status s =
      budget.Check(Bytes(r.SerializeAsString()), v1::TransferRequest::descriptor(), "the request");
  EXPECT_EQ(s.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(s.message().find("the request: style.clip.frames: more than 1000"), std::string::npos)
      << s;
  EXPECT_NE(s.message().find("--max-clip-frames"), std::string::npos) << s;

  v1::InterpolateRequest many;
  for (int i = 0; i < 5; ++i) many.add_styles()->set_name("a");
  EXPECT_EQ(budget.Check(Bytes(many.SerializeAsString()), v1::InterpolateRequest::descriptor(), "x")
                .code(),
            absl::StatusCode::kResourceExhausted);
}

TEST(RequestBudgetTest, LongStringsEmptyEntriesAndBadBytesAreRefused) {
  const server::RequestBudget budget = Budget();
  v1::GetModelRequest id;
  id.set_model(std::string(2000, 'x'));
  absl::Status s =
      budget.Check(Bytes(id.SerializeAsString()), v1::GetModelRequest::descriptor(), "r");
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("model: 2000 bytes"), std::string::npos) << s;

  // 900 frames of 100 empty rotations: tiny on the wire, large once parsed.
  v1::TransferRequest empty;
  for (int f = 0; f < 900; ++f) {
    v1::Frame* frame = empty.mutable_content()->add_frames();
    for (int j = 0; j < 100; ++j) frame->add_rotations();
  }
  const std::string bytes = empty.SerializeAsString();
  s = budget.Check(Bytes(bytes), v1::TransferRequest::descriptor(), "r");
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("empty"), std::string::npos) << s;
  EXPECT_GT(budget.EstimateParse(Bytes(bytes), v1::TransferRequest::descriptor()),
            static_cast<int64_t>(4 * bytes.size()));

  s = budget.Check(Bytes("\x12\xff\xff\x01"), v1::TransferRequest::descriptor(), "r");
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("do not parse"), std::string::npos) << s;

  server::RequestBudget::Options bad;
  bad.entries = {{"stylus.v1.Clip.no_such_field", 1, "--x"}};
  EXPECT_FALSE(server::RequestBudget::Validate(bad).ok());
}

TEST(MemoryPoolTest, HoldsTakeAndGiveBack) {
  server::MemoryPool pool(100);
  {
    server::MemoryHold a(&pool, 60);
    EXPECT_TRUE(a.ok());
    server::MemoryHold b(&pool, 60);
    EXPECT_FALSE(b.ok());
    EXPECT_EQ(pool.in_use(), 60);
    server::MemoryHold c = std::move(a);
    EXPECT_EQ(pool.in_use(), 60);
  }
  EXPECT_EQ(pool.in_use(), 0);
  EXPECT_TRUE(server::MemoryHold(nullptr, 1 << 30).ok());
}

}  // namespace
}  // namespace stylus::testing
