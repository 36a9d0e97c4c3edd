// Prometheus metrics of a real server (--metrics-listen), scraped over HTTP
// after real calls.
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "gtest/gtest.h"
#include "tests/server/server_test_support.h"

namespace stylus::testing {
namespace {

// The value of the sample `series` (name and labels as exposed), or -1.
double SeriesValue(const std::string& text, const std::string& series) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(series + " ", 0) == 0) return std::stod(line.substr(series.size() + 1));
  }
  return -1;
}

TEST(MetricsTest, AScrapeAfterRealCallsCountsThem) {
  server::ServerOptions options;
  options.metrics_listen = "127.0.0.1:0";
  auto s = LiveServer::Start(options);
  ASSERT_NE(s, nullptr);
  ASSERT_GT(s->server->metrics_port(), 0);
  const motion::Motion content = Sample("walk_normal.bvh"), style = Sample("walk_old.bvh");
  ASSERT_TRUE(s->client->Transfer(content, {&style, ""}).ok());
  EXPECT_EQ(s->client->Transfer(content, {&style, ""}, {"no-such-model"}).status().code(),
            absl::StatusCode::kNotFound);
  absl::StatusOr<StreamResult> streamed = s->client->Stream(content, {&style, ""}, 0, {"live"});
  ASSERT_TRUE(streamed.ok()) << streamed.status();
  ASSERT_EQ(streamed->output.num_frames, content.num_frames);
  // The client has the stream's status before the server has counted the
  // stream out (its reactor's OnDone).
  ASSERT_TRUE(testing::WaitFor([&] { return s->server->load().open_streams == 0; }));

  const std::string text = bench::HttpGet(s->server->metrics_port(), "/metrics");
  ASSERT_FALSE(text.empty());
  const std::string transfer =
      R"(grpc_method="Transfer",grpc_service="stylus.v1.StyleService",grpc_type="unary")";
  const std::string stream =
      R"(grpc_method="TransferStream",grpc_service="stylus.v1.StyleService",grpc_type="bidi_stream")";
  EXPECT_EQ(SeriesValue(text, "grpc_server_started_total{" + transfer + "}"), 2) << text;
  EXPECT_EQ(SeriesValue(text, R"(grpc_server_handled_total{grpc_code="OK",)" + transfer + "}"), 1);
  EXPECT_EQ(
      SeriesValue(text, R"(grpc_server_handled_total{grpc_code="NOT_FOUND",)" + transfer + "}"), 1);
  EXPECT_EQ(SeriesValue(text, "grpc_server_handling_seconds_count{" + transfer + "}"), 2);
  EXPECT_EQ(SeriesValue(text, "grpc_server_msg_sent_total{" + transfer + "}"), 1);
  EXPECT_EQ(SeriesValue(text, R"(stylus_frames_total{kind="unary",model=")" +
                                  testing::DefaultPackage() + R"("})"),
            content.num_frames);
  // The stream: a config and every frame in, every frame out.
  EXPECT_EQ(SeriesValue(text, "grpc_server_started_total{" + stream + "}"), 1);
  EXPECT_EQ(SeriesValue(text, R"(grpc_server_handled_total{grpc_code="OK",)" + stream + "}"), 1);
  EXPECT_EQ(SeriesValue(text, "grpc_server_msg_received_total{" + stream + "}"),
            content.num_frames + 1);
  EXPECT_EQ(SeriesValue(text, "grpc_server_msg_sent_total{" + stream + "}"), content.num_frames);
  EXPECT_EQ(SeriesValue(text, R"(stylus_frames_total{kind="stream",model="live/v3"})"),
            content.num_frames);
  EXPECT_EQ(SeriesValue(text, "stylus_stream_frame_seconds_count"), content.num_frames);
  EXPECT_GT(SeriesValue(text, "stylus_step_batch_streams_count"), 0);
  EXPECT_EQ(SeriesValue(text, R"(stylus_model_seconds_count{model=")" + testing::DefaultPackage() +
                                  R"("})"),
            1);
  EXPECT_EQ(SeriesValue(text, R"(stylus_model_seconds_count{model="live/v3"})"),
            SeriesValue(text, "stylus_step_batch_streams_count"));
  // States read at the scrape.
  EXPECT_EQ(SeriesValue(text, "stylus_loaded_models"), 4);
  EXPECT_EQ(SeriesValue(text, "stylus_open_streams"), 0);
  EXPECT_GT(SeriesValue(text, "process_resident_memory_bytes"), 50e6);
}

TEST(MetricsTest, OffByDefaultAndABadAddressFailsTheStart) {
  auto s = LiveServer::Start();
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->server->metrics_port(), 0);
  server::ServerOptions with_metrics;
  with_metrics.metrics_listen = "127.0.0.1:0";
  auto first = LiveServer::Start(with_metrics);
  ASSERT_NE(first, nullptr);
  server::ServerOptions options;
  options.models_dir = SourceDir() + "/models";
  options.listen = "localhost:0";
  for (const auto& [listen, code] : std::vector<std::pair<std::string, absl::StatusCode>>{
           {"256.1.1.1:1", absl::StatusCode::kInvalidArgument},
           {"localhost", absl::StatusCode::kInvalidArgument},
           {"127.0.0.1:" + std::to_string(first->server->metrics_port()),
            absl::StatusCode::kUnavailable}}) {
    options.metrics_listen = listen;
    absl::StatusOr<std::unique_ptr<server::StylusServer>> bad =
        server::StylusServer::Start(options);
    EXPECT_EQ(bad.status().code(), code) << listen << ": " << bad.status();
  }
  // Only GET of /metrics.
  EXPECT_NE(bench::HttpGet(first->server->metrics_port(), "/other").find("metrics are at /metrics"),
            std::string::npos);
}

}  // namespace
}  // namespace stylus::testing
