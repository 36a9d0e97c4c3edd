// PEM files for TLS, read the same way by the client and the server: a
// missing or unreadable file, or one without the PEM block expected, is an
// error naming the file and the flag it came from (gRPC's own message for a
// bad certificate is a handshake failure much later).
#ifndef STYLUS_WIRE_PEM_H_
#define STYLUS_WIRE_PEM_H_

#include <string>

#include "absl/status/statusor.h"

namespace stylus::wire {

enum class PemKind { kCertificate, kPrivateKey };

// The file's text. NOT_FOUND when it cannot be read; INVALID_ARGUMENT when it
// has no "-----BEGIN ...CERTIFICATE-----" (or "...PRIVATE KEY-----") block.
absl::StatusOr<std::string> ReadPem(const std::string& path, PemKind kind, const std::string& flag);

}  // namespace stylus::wire

#endif  // STYLUS_WIRE_PEM_H_
