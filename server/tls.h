// Transport security for stylus-server: TLS with the server's certificate
// and key, and optionally mutual TLS (clients must present a certificate
// signed by a given CA). Without a certificate the server speaks plain text,
// which is meant for localhost and trusted networks only.
#ifndef STYLUS_SERVER_TLS_H_
#define STYLUS_SERVER_TLS_H_

#include <grpcpp/security/server_credentials.h>

#include <memory>
#include <string>

#include "absl/status/statusor.h"

namespace stylus::server {

struct TlsFiles {
  std::string cert;       // PEM certificate chain; empty: plain text.
  std::string key;        // PEM private key of the certificate.
  std::string client_ca;  // PEM CA bundle; when set, clients need a cert it signed.
};

struct ServerTransport {
  std::shared_ptr<grpc::ServerCredentials> credentials;
  std::string description;  // For the start-up line.
};

// Reads the files and builds the credentials. INVALID_ARGUMENT when a key is
// given without a certificate (or the other way round), when a CA is given
// without either, or when a file is not PEM of the kind expected; NOT_FOUND
// for a file that cannot be read. Each message names the file and flag.
absl::StatusOr<ServerTransport> MakeServerTransport(const TlsFiles& files);

// How often the TLS files are checked for changes.
inline constexpr unsigned kCertRefreshS = 2;

// True for an address only this machine can reach: localhost, an IPv4
// address in 127.0.0.0/8, [::1], a unix socket.
bool IsLoopbackAddress(const std::string& listen);

}  // namespace stylus::server

#endif  // STYLUS_SERVER_TLS_H_
