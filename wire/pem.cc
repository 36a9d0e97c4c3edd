#include "wire/pem.h"

#include <fstream>
#include <sstream>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace stylus::wire {

absl::StatusOr<std::string> ReadPem(const std::string& path, PemKind kind,
                                    const std::string& flag) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat(flag, ": cannot read ", path));
  std::ostringstream text;
  text << in.rdbuf();
  const std::string pem = text.str();
  const bool cert = kind == PemKind::kCertificate;
  // "BEGIN CERTIFICATE"; keys come as "BEGIN PRIVATE KEY", "BEGIN RSA
  // PRIVATE KEY", "BEGIN EC PRIVATE KEY".
  const bool found = cert ? absl::StrContains(pem, "-----BEGIN CERTIFICATE-----")
                          : absl::StrContains(pem, "PRIVATE KEY-----");
  if (!found) {
    return absl::InvalidArgumentError(
        absl::StrCat(flag, ": ", path, " is not a PEM ", cert ? "certificate" : "private key",
                     " (no '-----BEGIN ", cert ? "CERTIFICATE" : "PRIVATE KEY", "-----' block)"));
  }
  return pem;
}

}  // namespace stylus::wire
