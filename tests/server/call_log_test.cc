// The call log: JSON lines, request ids (the client's or made), peers, on a
// real server.
#include "server/call_log.h"

#include <grpcpp/grpcpp.h>

#include <sstream>
#include <thread>

#include "absl/strings/str_split.h"
#include "spdlog/sinks/ostream_sink.h"
#include "tests/server/server_test_support.h"

namespace stylus::testing {
namespace {

using server::JsonEscape;

TEST(JsonEscapeTest, EscapesWhatJsonNeedsAndKeepsUtf8) {
  EXPECT_EQ(JsonEscape("plain"), "plain");
  EXPECT_EQ(JsonEscape("a \"quote\" and a \\"), "a \\\"quote\\\" and a \\\\");
  EXPECT_EQ(JsonEscape("line\nbreak\ttab\x01"), "line\\nbreak\\ttab\\u0001");
  EXPECT_EQ(JsonEscape("caf\xc3\xa9 \xe2\x86\x92"), "caf\xc3\xa9 \xe2\x86\x92");  // Valid UTF-8.
  // Bytes that are not UTF-8 (a lone continuation, a truncated sequence, an
  // overlong form) become U+FFFD.
  EXPECT_EQ(JsonEscape("x\x80y"), "x\\ufffdy");
  EXPECT_EQ(JsonEscape("x\xc3"), "x\\ufffd");
  EXPECT_EQ(JsonEscape("\xc0\xaf"), "\\ufffd\\ufffd");
}

class CallLogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    server::SetUpLogging(server::LogFormat::kJson,
                         std::make_shared<spdlog::sinks::ostream_sink_mt>(log_));
    live_ = LiveServer::Start();
    ASSERT_NE(live_, nullptr);
  }
  void TearDown() override {
    live_.reset();
    server::SetUpLogging(server::LogFormat::kText);
  }

  // GetModel with `request_id` (none when empty); the id the server answered.
  std::string GetModel(const std::string& request_id) {
    auto stub = v1::ModelService::NewStub(
        grpc::CreateChannel(live_->address, grpc::InsecureChannelCredentials()));
    grpc::ClientContext ctx;
    if (!request_id.empty()) ctx.AddMetadata("x-request-id", request_id);
    v1::GetModelRequest request;
    v1::ModelInfo info;
    EXPECT_TRUE(stub->GetModel(&ctx, request, &info).ok());
    const auto& metadata = ctx.GetServerInitialMetadata();
    const auto it = metadata.find("x-request-id");
    return it == metadata.end() ? "" : std::string(it->second.data(), it->second.size());
  }

  std::vector<std::string> Lines() {
    std::vector<std::string> lines = absl::StrSplit(log_.str(), '\n', absl::SkipEmpty());
    return lines;
  }

  std::ostringstream log_;
  std::unique_ptr<LiveServer> live_;
};

TEST_F(CallLogTest, EachCallsLineCarriesItsRequestIdAndPeer) {
  EXPECT_EQ(GetModel("req-42"), "req-42");
  const std::string made = GetModel("");
  EXPECT_EQ(made.size(), 16u) << made;
  const std::string replaced = GetModel("has space");  // Not usable: one is made.
  EXPECT_EQ(replaced.size(), 16u) << replaced;
  const motion::Motion walk = Sample("walk_normal.bvh"), old = Sample("walk_old.bvh");
  motion::Motion head = walk;
  head.num_frames = 20;
  head.values.resize(static_cast<size_t>(20) * walk.skeleton.num_channels());
  ASSERT_TRUE(live_->client->Stream(head, {&old, ""}, 0).ok());
  // A stream's line is written when gRPC is done with it, just after the
  // status, and before the stream is counted out.
  for (int i = 0; i < 500 && live_->server->load().open_streams > 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }

  int calls = 0;
  bool given = false, generated = false, stream = false;
  for (const std::string& line : Lines()) {
    // Every line is one JSON object with a UTC time and a level.
    EXPECT_EQ(line.rfind("{\"time\":\"", 0), 0u) << line;
    EXPECT_EQ(line.back(), '}') << line;
    EXPECT_NE(line.find("Z\",\"level\":\""), std::string::npos) << line;
    if (line.find("\"rpc\":") == std::string::npos) continue;
    ++calls;
    EXPECT_NE(line.find("\"peer\":\"ipv"), std::string::npos) << line;
    given |= line.find("\"rpc\":\"GetModel\"") != std::string::npos &&
             line.find("\"request_id\":\"req-42\"") != std::string::npos;
    generated |= line.find("\"request_id\":\"" + made + "\"") != std::string::npos;
    stream |= line.find("\"rpc\":\"TransferStream\",\"model\":\"" + testing::DefaultPackage() +
                        "\",\"frames\":20") != std::string::npos;
  }
  EXPECT_EQ(calls, 4) << log_.str();
  EXPECT_TRUE(given) << log_.str();
  EXPECT_TRUE(generated) << log_.str();
  EXPECT_TRUE(stream) << log_.str();
}

TEST_F(CallLogTest, AFailedCallsMessageIsEscapedIntoItsLine) {
  const motion::Motion old = Sample("walk_old.bvh");
  CallOptions options;
  options.model = "no \"such\"\nmodel";
  EXPECT_FALSE(live_->client->Transfer(old, {&old, ""}, options).ok());
  bool found = false;
  for (const std::string& line : Lines()) {
    if (line.find("\"rpc\":\"Transfer\"") == std::string::npos) continue;
    found = true;
    EXPECT_NE(line.find("\"level\":\"warning\""), std::string::npos) << line;
    EXPECT_TRUE(line.find("\"status\":\"NOT_FOUND\"") != std::string::npos ||
                line.find("\"status\":\"INVALID_ARGUMENT\"") != std::string::npos)
        << line;
    EXPECT_NE(line.find("no \\\"such\\\"\\nmodel"), std::string::npos) << line;
    EXPECT_EQ(line.find('\n'), std::string::npos);
  }
  EXPECT_TRUE(found) << log_.str();
}

// Text lines too: a client's string cannot start a line of its own, and a
// long one is cut.
TEST(TextEscapeTest, ControlCharactersAreEscapedAndLongFieldsCut) {
  EXPECT_EQ(server::TextEscape("a\nb\r\"c\"\\"), "a\\x0ab\\x0d\\\"c\\\"\\\\");
  EXPECT_EQ(server::TextEscape("ok: /x"), "ok: /x");
  const std::string big(1 << 20, 'x');
  const std::string cut = server::Capped(big);
  EXPECT_LE(cut.size(), server::kMaxLoggedField + 32);
  EXPECT_NE(cut.find("(1048576 bytes)"), std::string::npos);
  EXPECT_EQ(server::Capped("short"), "short");
}

}  // namespace
}  // namespace stylus::testing
