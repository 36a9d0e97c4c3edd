#include "server/tls.h"

#include <grpcpp/security/server_credentials.h>

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
  grpc::SslServerCredentialsOptions options;
  options.pem_key_cert_pairs.push_back({*key, *cert});
  std::string description = absl::StrCat("TLS (certificate ", files.cert, ")");
  if (!files.client_ca.empty()) {
    absl::StatusOr<std::string> ca =
        wire::ReadPem(files.client_ca, wire::PemKind::kCertificate, "--tls-client-ca");
    if (!ca.ok()) return ca.status();
    options.pem_root_certs = *ca;
    options.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
    absl::StrAppend(&description, ", client certificates required (CA ", files.client_ca, ")");
  }
  return ServerTransport{grpc::SslServerCredentials(options), description};
}

bool IsLoopbackAddress(const std::string& listen) {
  return absl::StartsWith(listen, "localhost:") || absl::StartsWith(listen, "127.") ||
         absl::StartsWith(listen, "[::1]:") || absl::StartsWith(listen, "unix:");
}

}  // namespace stylus::server
