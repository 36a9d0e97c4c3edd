#include "server/token_auth.h"

#include <sys/stat.h>

#include <fstream>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace stylus::server {
namespace {

// Equal in time that depends only on the lengths, not on where a and b
// first differ.
bool ConstantTimeEquals(absl::string_view a, absl::string_view b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  const size_t n = std::max(a.size(), b.size());
  for (size_t i = 0; i < n; ++i) {
    const unsigned char x = i < a.size() ? a[i] : 0, y = i < b.size() ? b[i] : 0;
    diff |= x ^ y;
  }
  return diff == 0;
}

}  // namespace

absl::StatusOr<std::vector<std::string>> TokenAuth::Read(const std::string& path) {
  std::ifstream in(path);
  if (!in) return absl::NotFoundError(absl::StrCat("auth tokens: cannot read ", path));
  std::vector<std::string> tokens;
  int line_number = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    const absl::string_view token = absl::StripAsciiWhitespace(line);
    if (token.empty() || token[0] == '#') continue;
    for (const char c : token) {
      if (c <= ' ' || c > '~') {
        return absl::InvalidArgumentError(
            absl::StrCat(path, ":", line_number,
                         ": a token is printable ASCII without spaces (one token per line)"));
      }
    }
    tokens.emplace_back(token);
  }
  if (tokens.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": no token (one token per line)"));
  }
  return tokens;
}

absl::StatusOr<std::unique_ptr<TokenAuth>> TokenAuth::Load(const std::string& path) {
  std::unique_ptr<TokenAuth> auth(new TokenAuth(path));
  absl::StatusOr<int> n = auth->Reload();
  if (!n.ok()) return n.status();
  return auth;
}

std::string TokenAuth::Stamp(const std::string& path) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return "missing";
  return absl::StrCat(st.st_dev, ":", st.st_ino, ":", st.st_size, ":", st.st_mtim.tv_sec, ".",
                      st.st_mtim.tv_nsec, ":", st.st_ctim.tv_sec, ".", st.st_ctim.tv_nsec);
}

absl::StatusOr<int> TokenAuth::Reload() {
  const std::string stamp = Stamp(path_);
  absl::StatusOr<std::vector<std::string>> tokens = Read(path_);
  absl::MutexLock lock(&mu_);
  stamp_ = stamp;
  if (!tokens.ok()) {
    tokens_.clear();
    return tokens.status();
  }
  tokens_ = *std::move(tokens);
  return static_cast<int>(tokens_.size());
}

std::optional<absl::StatusOr<int>> TokenAuth::ReloadIfChanged() {
  {
    absl::MutexLock lock(&mu_);
    if (Stamp(path_) == stamp_) return std::nullopt;
  }
  return Reload();
}

bool TokenAuth::Allows(absl::string_view authorization) const {
  constexpr absl::string_view kScheme = "Bearer ";
  if (!absl::StartsWith(authorization, kScheme)) return false;
  const absl::string_view token = authorization.substr(kScheme.size());
  absl::MutexLock lock(&mu_);
  bool allowed = false;
  for (const std::string& t : tokens_) allowed |= ConstantTimeEquals(token, t);
  return allowed;
}

}  // namespace stylus::server
