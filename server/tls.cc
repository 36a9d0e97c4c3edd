#include "server/tls.h"

#include <arpa/inet.h>
#include <grpcpp/security/server_credentials.h>
#include <grpcpp/security/tls_certificate_provider.h>
#include <grpcpp/security/tls_credentials_options.h>
#include <netinet/in.h>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "wire/pem.h"

namespace stylus::server {

absl::StatusOr<ServerTransport> MakeServerTransport(const TlsFiles& files) {
  if (files.cert.empty() && files.key.empty()) {
    if (!files.client_ca.empty()) {
      return absl::InvalidArgumentError(
          "--tls-client-ca needs --tls-cert and --tls-key (mutual TLS is TLS first)");
    }
    return ServerTransport{grpc::InsecureServerCredentials(),
                           "plain text (no --tls-cert): for localhost or a trusted network only"};
  }
  if (files.cert.empty() || files.key.empty()) {
    return absl::InvalidArgumentError("TLS needs both --tls-cert and --tls-key");
  }
  absl::StatusOr<std::string> cert =
      wire::ReadPem(files.cert, wire::PemKind::kCertificate, "--tls-cert");
  if (!cert.ok()) return cert.status();
  absl::StatusOr<std::string> key =
      wire::ReadPem(files.key, wire::PemKind::kPrivateKey, "--tls-key");
  if (!key.ok()) return key.status();
  std::string description = absl::StrCat("TLS (certificate ", files.cert, ")");
  if (!files.client_ca.empty()) {
    absl::StatusOr<std::string> ca =
        wire::ReadPem(files.client_ca, wire::PemKind::kCertificate, "--tls-client-ca");
    if (!ca.ok()) return ca.status();
    absl::StrAppend(&description, ", client certificates required (CA ", files.client_ca, ")");
  }
  // The files are read again when they change (a renewed certificate, a
  // rotated Secret), checked every kCertRefreshS seconds; new handshakes use
  // the new ones.
  auto provider = std::make_shared<grpc::experimental::FileWatcherCertificateProvider>(
      files.key, files.cert, files.client_ca, kCertRefreshS);
  grpc::experimental::TlsServerCredentialsOptions options(provider);
  options.watch_identity_key_cert_pairs();
  if (!files.client_ca.empty()) {
    options.watch_root_certs();
    options.set_cert_request_type(GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
  } else {
    options.set_cert_request_type(GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE);
  }
  absl::StrAppend(&description, "; files re-read when they change");
  return ServerTransport{grpc::experimental::TlsServerCredentials(options), description};
}

bool IsLoopbackAddress(const std::string& listen) {
  if (absl::StartsWith(listen, "unix:")) return true;
  const size_t colon = listen.rfind(':');
  if (colon == std::string::npos) return false;
  std::string host = listen.substr(0, colon);
  if (host == "localhost") return true;
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
    in6_addr a6{};
    return inet_pton(AF_INET6, host.c_str(), &a6) == 1 && IN6_IS_ADDR_LOOPBACK(&a6);
  }
  in_addr a4{};
  // A dotted-quad IPv4 address in 127.0.0.0/8; "127.foo" names some other host.
  return inet_pton(AF_INET, host.c_str(), &a4) == 1 && (ntohl(a4.s_addr) >> 24) == 127;
}

}  // namespace stylus::server
