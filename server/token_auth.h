// Bearer-token access control (`stylus-server --auth-tokens FILE`): a call is
// let in when its `authorization` metadata is "Bearer TOKEN" for a token in
// the file. The file holds one token per line (blank lines and lines
// starting with '#' are skipped; a token is printable ASCII without spaces);
// Reload() reads it again (the server does on SIGHUP) and keeps the tokens it
// had when the new file is unreadable or has none. Tokens are compared in
// time that does not depend on where they differ, and never logged.
// grpc.health.v1 and reflection are not behind it, so probes work.
//
// Thread-safety: all methods may be called from any thread.
#ifndef STYLUS_SERVER_TOKEN_AUTH_H_
#define STYLUS_SERVER_TOKEN_AUTH_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/synchronization/mutex.h"

namespace stylus::server {

class TokenAuth {
 public:
  // NOT_FOUND when the file cannot be read; INVALID_ARGUMENT (naming the
  // file and line) for a malformed line or a file without tokens.
  static absl::StatusOr<std::unique_ptr<TokenAuth>> Load(const std::string& path);

  // The file read again; on error the tokens stay as they were. Returns the
  // number of tokens now in force.
  absl::StatusOr<int> Reload();

  // `authorization` is the call's metadata value (empty when absent).
  bool Allows(absl::string_view authorization) const;

 private:
  explicit TokenAuth(std::string path) : path_(std::move(path)) {}
  static absl::StatusOr<std::vector<std::string>> Read(const std::string& path);

  const std::string path_;
  mutable absl::Mutex mu_;
  std::vector<std::string> tokens_ ABSL_GUARDED_BY(mu_);
};

}  // namespace stylus::server

#endif  // STYLUS_SERVER_TOKEN_AUTH_H_
