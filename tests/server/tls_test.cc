// TLS and mutual TLS on a real server, with certificates made for the test
// by tests/server/make_test_certs.sh (Debian's openssl).
#include "server/tls.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include "tests/server/server_test_support.h"

namespace stylus::testing {
namespace {

class TlsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // Per process: ctest runs each test of this suite in its own, at once.
    dir_ = new std::string(::testing::TempDir() + "/tls_test_" + std::to_string(getpid()));
    std::filesystem::create_directories(*dir_);
    const std::string command = SourceDir() + "/tests/server/make_test_certs.sh " + *dir_ + " > " +
                                *dir_ + "/openssl.log 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << "see " << *dir_ << "/openssl.log";
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  static std::string File(const std::string& name) { return *dir_ + "/" + name; }

  static std::unique_ptr<LiveServer> StartTls(bool mutual) {
    server::ServerOptions options;
    options.tls_cert = File("server.pem");
    options.tls_key = File("server.key");
    if (mutual) options.tls_client_ca = File("ca.pem");
    return LiveServer::Start(options);
  }

  // A client of `live` with TLS from these files ("" for none; no CA and no
  // certificate: plain text).
  static Client Connect(const LiveServer& live, const std::string& ca, const std::string& cert = "",
                        const std::string& key = "") {
    ClientOptions options;
    options.address = live.address;
    options.deadline = std::chrono::milliseconds(20000);
    absl::StatusOr<TlsOptions> tls = ReadTlsFiles(
        ca.empty() ? "" : File(ca), cert.empty() ? "" : File(cert), key.empty() ? "" : File(key));
    EXPECT_TRUE(tls.ok()) << tls.status();
    if (tls.ok()) options.tls = *tls;
    return Client(options);
  }

  static std::string* dir_;
};

std::string* TlsTest::dir_ = nullptr;

TEST_F(TlsTest, ServesClientsThatTrustItsCaAndNoOneElse) {
  std::unique_ptr<LiveServer> live = StartTls(/*mutual=*/false);
  ASSERT_NE(live, nullptr);

  Client trusted = Connect(*live, "ca.pem");
  absl::StatusOr<std::vector<v1::ModelInfo>> models = trusted.ListModels();
  ASSERT_TRUE(models.ok()) << models.status();
  const motion::Motion content = Sample("walk_normal.bvh");
  const motion::Motion style = Sample("walk_old.bvh");
  absl::StatusOr<motion::Motion> out = trusted.Transfer(content, Style{&style, ""});
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->num_frames, content.num_frames);
  // A stream over TLS too.
  motion::Motion head = content;
  head.num_frames = 40;
  head.values.resize(static_cast<size_t>(40) * content.skeleton.num_channels());
  absl::StatusOr<StreamResult> streamed = trusted.Stream(head, Style{&style, ""}, 0);
  ASSERT_TRUE(streamed.ok()) << streamed.status();
  EXPECT_EQ(streamed->output.num_frames, 40);

  // Plain text to a TLS port, and TLS that trusts another CA: no call gets in.
  Client plain = Connect(*live, "");
  EXPECT_EQ(plain.ListModels().status().code(), absl::StatusCode::kUnavailable);
  Client wrong_ca = Connect(*live, "other_ca.pem");
  EXPECT_EQ(wrong_ca.ListModels().status().code(), absl::StatusCode::kUnavailable);
  // A name the certificate does not carry is refused as well.
  ClientOptions renamed;
  renamed.address = live->address;
  renamed.tls = *ReadTlsFiles(File("ca.pem"), "", "");
  renamed.tls.server_name = "stylus.example.com";
  EXPECT_EQ(Client(renamed).ListModels().status().code(), absl::StatusCode::kUnavailable);
}

TEST_F(TlsTest, MutualTlsNeedsAClientCertificateItsCaSigned) {
  std::unique_ptr<LiveServer> live = StartTls(/*mutual=*/true);
  ASSERT_NE(live, nullptr);
  Client with_cert = Connect(*live, "ca.pem", "client.pem", "client.key");
  absl::StatusOr<std::vector<v1::ModelInfo>> models = with_cert.ListModels();
  ASSERT_TRUE(models.ok()) << models.status();

  Client no_cert = Connect(*live, "ca.pem");
  EXPECT_EQ(no_cert.ListModels().status().code(), absl::StatusCode::kUnavailable);
  Client untrusted_cert = Connect(*live, "ca.pem", "other_client.pem", "other_client.key");
  EXPECT_EQ(untrusted_cert.ListModels().status().code(), absl::StatusCode::kUnavailable);
}

TEST_F(TlsTest, BadTlsFilesAreRefusedAtStartNamingTheFlag) {
  server::ServerOptions options;
  options.models_dir = SourceDir() + "/models";
  options.listen = "localhost:0";
  auto start = [&options] { return server::StylusServer::Start(options).status(); };

  options.tls_cert = File("server.pem");  // No key.
  EXPECT_EQ(start().code(), absl::StatusCode::kInvalidArgument);
  options.tls_key = File("missing.key");
  absl::Status s = start();
  EXPECT_EQ(s.code(), absl::StatusCode::kNotFound);
  EXPECT_NE(s.message().find("--tls-key"), std::string::npos) << s;
  options.tls_key = File("server.pem");  // A certificate where the key goes.
  s = start();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("not a PEM private key"), std::string::npos) << s;
  options.tls_key = File("server.key");
  options.tls_client_ca = File("server.key");  // A key where a CA goes.
  s = start();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("--tls-client-ca"), std::string::npos) << s;
  options = {};
  options.tls_client_ca = File("ca.pem");  // Mutual TLS without TLS.
  EXPECT_EQ(start().code(), absl::StatusCode::kInvalidArgument);

  EXPECT_EQ(ReadTlsFiles("", File("client.pem"), "").status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ReadTlsFiles(File("nope.pem"), "", "").status().code(), absl::StatusCode::kNotFound);
  absl::StatusOr<TlsOptions> none = ReadTlsFiles("", "", "");
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->enabled);
}

// A renewed certificate written over the server's files is served to new
// connections without a restart.
TEST_F(TlsTest, ACertificateWrittenOverItsFilesIsServedWithoutARestart) {
  namespace fs = std::filesystem;
  const auto copy = [](const std::string& from, const std::string& to) {
    fs::copy_file(File(from), File(to + ".tmp"), fs::copy_options::overwrite_existing);
    fs::rename(File(to + ".tmp"), File(to));
  };
  copy("server.pem", "live.pem");
  copy("server.key", "live.key");
  server::ServerOptions options;
  options.tls_cert = File("live.pem");
  options.tls_key = File("live.key");
  std::unique_ptr<LiveServer> live = LiveServer::Start(options);
  ASSERT_NE(live, nullptr);
  ASSERT_TRUE(Connect(*live, "ca.pem").ListModels().ok());
  copy("other_server.key", "live.key");
  copy("other_server.pem", "live.pem");
  bool renewed = false;
  for (int i = 0; i < 40 && !renewed; ++i) {  // The files are checked every 2 s.
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    renewed = Connect(*live, "other_ca.pem").ListModels().ok();
  }
  EXPECT_TRUE(renewed);
  EXPECT_FALSE(Connect(*live, "ca.pem").ListModels().ok());
}

TEST(TlsAddressTest, LoopbackAddressesAreTheOnlyOnesPlainTextIsQuietFor) {
  EXPECT_TRUE(server::IsLoopbackAddress("localhost:50051"));
  EXPECT_TRUE(server::IsLoopbackAddress("127.0.0.1:0"));
  EXPECT_TRUE(server::IsLoopbackAddress("[::1]:50051"));
  EXPECT_FALSE(server::IsLoopbackAddress("0.0.0.0:50051"));
  EXPECT_FALSE(server::IsLoopbackAddress("[::]:50051"));
  EXPECT_FALSE(server::IsLoopbackAddress("stylus.example.com:443"));
  EXPECT_TRUE(server::IsLoopbackAddress("127.1.2.3:50051"));
  // Host names that merely start like a loopback address are not one.
  EXPECT_FALSE(server::IsLoopbackAddress("127.foo:50051"));
  EXPECT_FALSE(server::IsLoopbackAddress("127.0.0.1.example.com:50051"));
  EXPECT_FALSE(server::IsLoopbackAddress("localhost.example.com:50051"));
  EXPECT_FALSE(server::IsLoopbackAddress("[::1].example:50051"));
}

}  // namespace
}  // namespace stylus::testing
