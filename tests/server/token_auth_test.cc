// Bearer tokens (--auth-tokens): the file's rules, and a real server that
// lets in only calls with a valid token while health checks stay open.
#include "server/token_auth.h"

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <fstream>
#include <future>
#include <optional>
#include <sstream>

#include "gtest/gtest.h"
#include "tests/server/server_test_support.h"

namespace stylus::testing {
namespace {

std::string WriteTokens(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(TokenAuthTest, TheFileSaysWhichTokensGetIn) {
  const std::string path = WriteTokens("tokens_a", "# studio A\n  alpha  \n\nbeta-2\n");
  absl::StatusOr<std::unique_ptr<server::TokenAuth>> auth = server::TokenAuth::Load(path);
  ASSERT_TRUE(auth.ok()) << auth.status();
  EXPECT_TRUE((*auth)->Allows("Bearer alpha"));
  EXPECT_TRUE((*auth)->Allows("Bearer beta-2"));
  for (const char* no : {"", "alpha", "Bearer ", "Bearer alph", "Bearer alphaa", "bearer alpha",
                         "Bearer # studio A", "Basic alpha"}) {
    EXPECT_FALSE((*auth)->Allows(no)) << no;
  }
  // Reloaded: the new file's tokens; a file with no valid token revokes all.
  WriteTokens("tokens_a", "gamma\n");
  EXPECT_EQ(*(*auth)->Reload(), 1);
  EXPECT_FALSE((*auth)->Allows("Bearer alpha"));
  EXPECT_TRUE((*auth)->Allows("Bearer gamma"));
  WriteTokens("tokens_a", "# none\n");
  EXPECT_EQ((*auth)->Reload().status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_FALSE((*auth)->Allows("Bearer gamma"));
  WriteTokens("tokens_a", "gamma\nbad token\n");
  EXPECT_EQ((*auth)->Reload().status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_FALSE((*auth)->Allows("Bearer gamma"));
  std::remove(path.c_str());
  EXPECT_EQ((*auth)->Reload().status().code(), absl::StatusCode::kNotFound);
  EXPECT_FALSE((*auth)->Allows("Bearer gamma"));
}

// A changed file is read again without a signal (a mounted Secret); an
// unchanged one is not.
TEST(TokenAuthTest, AChangedFileIsReadAgain) {
  const std::string path = WriteTokens("tokens_watch", "alpha\n");
  absl::StatusOr<std::unique_ptr<server::TokenAuth>> auth = server::TokenAuth::Load(path);
  ASSERT_TRUE(auth.ok()) << auth.status();
  EXPECT_FALSE((*auth)->ReloadIfChanged().has_value());
  WriteTokens("tokens_watch", "beta-longer\n");
  const std::optional<absl::StatusOr<int>> n = (*auth)->ReloadIfChanged();
  ASSERT_TRUE(n.has_value());
  EXPECT_EQ(**n, 1);
  EXPECT_FALSE((*auth)->Allows("Bearer alpha"));
  EXPECT_TRUE((*auth)->Allows("Bearer beta-longer"));
  EXPECT_FALSE((*auth)->ReloadIfChanged().has_value());
}

TEST(TokenAuthTest, BadFilesAreClearErrors) {
  EXPECT_EQ(server::TokenAuth::Load("/nonexistent/tokens").status().code(),
            absl::StatusCode::kNotFound);
  const std::string spaced = WriteTokens("tokens_b", "ok\ntwo words\n");
  const absl::Status s = server::TokenAuth::Load(spaced).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find(spaced + ":2"), std::string::npos) << s;
  EXPECT_EQ(server::TokenAuth::Load(WriteTokens("tokens_c", "\n# c\n")).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// grpc.health.v1.Health/Check without any token: the status byte, or -1.
int HealthStatus(const std::string& address) {
  grpc::GenericStub stub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  grpc::Slice empty("", 0);  // HealthCheckRequest{} is empty.
  grpc::ByteBuffer request(&empty, 1), response;
  std::promise<grpc::Status> done;
  stub.UnaryCall(&ctx, "/grpc.health.v1.Health/Check", {}, &request, &response,
                 [&](grpc::Status s) { done.set_value(s); });
  if (!done.get_future().get().ok()) return -1;
  std::vector<grpc::Slice> slices;
  if (!response.Dump(&slices).ok() || slices.empty() || slices[0].size() < 2) return -1;
  return slices[0].begin()[1];  // HealthCheckResponse{status = N}: bytes 0x08 N.
}

TEST(TokenAuthServerTest, OnlyCallsWithAValidTokenGetIn) {
  server::ServerOptions options;
  options.auth_tokens = WriteTokens("tokens_server", "alpha\nbeta\n");
  options.metrics_listen = "127.0.0.1:0";
  auto s = LiveServer::Start(options);
  ASSERT_NE(s, nullptr);
  const motion::Motion content = Sample("walk_normal.bvh"), style = Sample("walk_old.bvh");
  auto client_with = [&](const std::string& token) {
    ClientOptions o;
    o.address = s->address;
    o.token = token;
    return std::make_unique<Client>(o);
  };
  int rejected = 0;
  for (const std::string token : {"", "alphabet", "gamma"}) {
    auto c = client_with(token);
    EXPECT_EQ(c->ListModels().status().code(), absl::StatusCode::kUnauthenticated) << token;
    EXPECT_EQ(c->Transfer(content, {&style, ""}).status().code(),
              absl::StatusCode::kUnauthenticated);
    EXPECT_EQ(c->Stream(content, {&style, ""}, 0, {"live"}).status().code(),
              absl::StatusCode::kUnauthenticated);
    rejected += 3;
  }
  EXPECT_EQ(HealthStatus(s->address), 1) << "health checks need no token (SERVING = 1)";
  auto alpha = client_with("alpha");
  EXPECT_TRUE(alpha->ListModels().ok());
  EXPECT_TRUE(alpha->Transfer(content, {&style, ""}).ok());
  absl::StatusOr<StreamResult> streamed = alpha->Stream(content, {&style, ""}, 0, {"live"});
  ASSERT_TRUE(streamed.ok()) << streamed.status();
  EXPECT_EQ(streamed->output.num_frames, content.num_frames);
  // Reloaded (as on SIGHUP): alpha is out, gamma in.
  WriteTokens("tokens_server", "gamma\n");
  EXPECT_EQ(*s->server->ReloadTokens(), 1);
  EXPECT_EQ(alpha->ListModels().status().code(), absl::StatusCode::kUnauthenticated);
  ++rejected;
  EXPECT_TRUE(client_with("gamma")->ListModels().ok());
  // Every rejection is counted.
  const std::string text = bench::HttpGet(s->server->metrics_port(), "/metrics");
  double counted = 0;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("grpc_server_handled_total{grpc_code=\"UNAUTHENTICATED\"", 0) == 0) {
      counted += std::stod(line.substr(line.rfind(' ') + 1));
    }
  }
  EXPECT_EQ(counted, rejected) << text;
}

// Loading and unloading models is for admin tokens only; the default model
// stays loaded.
TEST(TokenAuthServerTest, OnlyAdminTokensLoadAndUnloadModels) {
  server::ServerOptions options;
  options.auth_tokens = WriteTokens("tokens_serving", "alpha\n");
  options.admin_tokens = WriteTokens("tokens_admin", "root-1\n");
  auto s = LiveServer::Start(options);
  ASSERT_NE(s, nullptr);
  auto client_with = [&](const std::string& token) {
    ClientOptions o;
    o.address = s->address;
    o.token = token;
    return std::make_unique<Client>(o);
  };
  auto serving = client_with("alpha"), admin = client_with("root-1"), none = client_with("");
  EXPECT_EQ(serving->UnloadModel("cyclic/v1").code(), absl::StatusCode::kPermissionDenied);
  EXPECT_EQ(serving->LoadModel("cyclic/v1").status().code(), absl::StatusCode::kPermissionDenied);
  EXPECT_EQ(none->UnloadModel("cyclic/v1").code(), absl::StatusCode::kUnauthenticated);
  EXPECT_TRUE(admin->ListModels().ok());  // An admin token serves too.
  const absl::Status def = admin->UnloadModel(DefaultPackage());
  EXPECT_EQ(def.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(def.message().find("default"), std::string::npos) << def;
  ASSERT_TRUE(admin->UnloadModel("cyclic/v1").ok());
  ASSERT_TRUE(admin->LoadModel("cyclic/v1").ok());
  // Without --admin-tokens, a server with tokens loads nothing after start-up.
  server::ServerOptions no_admin;
  no_admin.auth_tokens = options.auth_tokens;
  auto t = LiveServer::Start(no_admin);
  ASSERT_NE(t, nullptr);
  ClientOptions o;
  o.address = t->address;
  o.token = "alpha";
  const absl::Status refused = Client(o).UnloadModel("cyclic/v1");
  EXPECT_EQ(refused.code(), absl::StatusCode::kPermissionDenied);
  EXPECT_NE(refused.message().find("--admin-tokens"), std::string::npos) << refused;
}

TEST(TokenAuthServerTest, ReloadWithoutTokensIsRefused) {
  auto s = LiveServer::Start();
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->server->ReloadTokens().status().code(), absl::StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace stylus::testing
