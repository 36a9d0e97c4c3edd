// Bearer-token access control (`stylus-server --auth-tokens FILE`): a call is
// let in when its `authorization` metadata is "Bearer TOKEN" for a token in
// the file. The file holds one token per line (blank lines and lines
// starting with '#' are skipped; a token is printable ASCII without spaces);
// Reload() reads it again (the server does on SIGHUP, and when the file
// changes: ReloadIfChanged). A file that cannot be read, has a malformed
// line or holds no token revokes every token: a revocation that empties the
// file must not leave the old tokens valid. Tokens are compared in time that
// does not depend on where they differ, and never logged. grpc.health.v1 is
// not behind it, so probes work.
//
// Thread-safety: all methods may be called from any thread.
#ifndef STYLUS_SERVER_TOKEN_AUTH_H_
#define STYLUS_SERVER_TOKEN_AUTH_H_

#include <memory>
#include <optional>
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

  // The file read again: the number of tokens now in force, or the error,
  // and then no token is in force.
  absl::StatusOr<int> Reload();
  // Reload() when the file's identity, size or time of change differs from
  // the last read's; nullopt when it has not changed.
  std::optional<absl::StatusOr<int>> ReloadIfChanged();
  const std::string& path() const { return path_; }

  // `authorization` is the call's metadata value (empty when absent).
  bool Allows(absl::string_view authorization) const;

 private:
  explicit TokenAuth(std::string path) : path_(std::move(path)) {}
  static absl::StatusOr<std::vector<std::string>> Read(const std::string& path);
  static std::string Stamp(const std::string& path);

  const std::string path_;
  mutable absl::Mutex mu_;
  std::vector<std::string> tokens_ ABSL_GUARDED_BY(mu_);
  std::string stamp_ ABSL_GUARDED_BY(mu_);  // The file's stat at the last read.
};

}  // namespace stylus::server

#endif  // STYLUS_SERVER_TOKEN_AUTH_H_
