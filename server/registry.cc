#include "server/registry.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "model/config_text.h"
#include "model/family_registry.h"
#include "model/package.h"

namespace stylus::server {
namespace {

namespace fs = std::filesystem;

// Whether <dir>/config.txt declares a family this server can host.
bool IsServable(const fs::path& dir) {
  absl::StatusOr<std::string> family = model::ReadConfigFamily(dir.string());
  return family.ok() && model::IsServedFamily(*family);
}

bool ValidId(const std::string& id) {
  const std::vector<std::string> parts = absl::StrSplit(id, '/');
  if (parts.size() != 2) return false;
  for (const std::string& p : parts) {
    if (p.empty() || p == "." || p == ".." || p.find('\\') != std::string::npos) return false;
  }
  return true;
}

// Whether version `a` comes before `b`: "v<number>" versions by their
// number (v2 before v10) and after any other name (e.g. "dev"), which
// sort among themselves in string order.
bool VersionBefore(const std::string& a, const std::string& b) {
  auto number = [](const std::string& v) -> int64_t {
    if (v.size() < 2 || v[0] != 'v' || v.size() > 18) return -1;
    for (size_t i = 1; i < v.size(); ++i)
      if (v[i] < '0' || v[i] > '9') return -1;
    return std::stoll(v.substr(1));
  };
  const int64_t na = number(a), nb = number(b);
  if (na >= 0 && nb >= 0) return na != nb ? na < nb : a < b;
  if ((na >= 0) != (nb >= 0)) return nb >= 0;
  return a < b;
}

}  // namespace

absl::StatusOr<std::unique_ptr<ModelRegistry>> ModelRegistry::Create(
    const std::string& root, const std::string& default_id) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) {
    return absl::NotFoundError(absl::StrCat("model directory ", root, " does not exist"));
  }
  std::unique_ptr<ModelRegistry> r(new ModelRegistry(root));
  std::vector<std::string> ids;
  for (const auto& name : fs::directory_iterator(root, ec)) {
    if (!name.is_directory()) continue;
    for (const auto& version : fs::directory_iterator(name.path(), ec)) {
      if (version.is_directory() && IsServable(version.path())) {
        ids.push_back(name.path().filename().string() + "/" + version.path().filename().string());
      }
    }
  }
  std::sort(ids.begin(), ids.end());
  for (const std::string& id : ids) {
    absl::StatusOr<HostedModel> m = r->Load(id);
    if (!m.ok()) return m.status();
  }
  std::string named = default_id, named_by = "--default-model";
  if (named.empty()) {
    absl::StatusOr<std::string> from_file = model::ReadDefaultPackage(root);
    if (!from_file.ok()) return from_file.status();
    named = *from_file, named_by = (fs::path(root) / model::kDefaultPackageFile).string();
  }
  absl::MutexLock lock(&r->mu_);
  if (!named.empty()) {
    if (!r->models_.count(named)) {
      return absl::NotFoundError(absl::StrCat("default model '", named, "' (", named_by,
                                              ") is not in ", root,
                                              " (found: ", absl::StrJoin(ids, ", "), ")"));
    }
    r->default_id_ = named;
  } else if (!ids.empty()) {
    r->default_id_ = ids.front();
  }
  return r;
}

absl::StatusOr<HostedModel> ModelRegistry::Get(const std::string& id) const {
  absl::MutexLock lock(&mu_);
  std::string key = id.empty() ? default_id_ : id;
  if (!key.empty() && key.find('/') == std::string::npos) {
    // A bare name: its highest version (v10 after v2).
    std::string best;
    for (const auto& [k, v] : models_) {
      if (absl::StartsWith(k, key + "/") &&
          (best.empty() || VersionBefore(best.substr(key.size() + 1), k.substr(key.size() + 1))))
        best = k;
    }
    key = best.empty() ? key : best;
  }
  auto it = models_.find(key);
  if (it == models_.end()) {
    std::vector<std::string> have;
    for (const auto& [k, v] : models_) have.push_back(k);
    return absl::NotFoundError(
        id.empty()
            ? absl::StrCat("no default model is loaded (loaded: ", absl::StrJoin(have, ", "), ")")
            : absl::StrCat("unknown model '", id,
                           "' (loaded: ", have.empty() ? "none" : absl::StrJoin(have, ", "), ")"));
  }
  return HostedModel{it->first, it->second};
}

std::vector<HostedModel> ModelRegistry::List() const {
  absl::MutexLock lock(&mu_);
  std::vector<HostedModel> out;
  for (const auto& [k, v] : models_) out.push_back({k, v});
  return out;
}

std::string ModelRegistry::default_id() const {
  absl::MutexLock lock(&mu_);
  return default_id_;
}

absl::StatusOr<HostedModel> ModelRegistry::Load(const std::string& id) {
  if (!ValidId(id)) {
    return absl::InvalidArgumentError(
        absl::StrCat("model id '", id, "' is not of the form <name>/<version>"));
  }
  {
    absl::MutexLock lock(&mu_);
    if (models_.count(id)) return absl::AlreadyExistsError(absl::StrCat(id, " is already loaded"));
  }
  // Loading reads files and weights: done outside the lock.
  absl::StatusOr<std::unique_ptr<model::StyleModel>> m = model::LoadStyleModel(root_ + "/" + id);
  if (!m.ok()) return m.status();
  std::shared_ptr<const model::StyleModel> shared = std::move(*m);
  absl::MutexLock lock(&mu_);
  if (models_.count(id)) return absl::AlreadyExistsError(absl::StrCat(id, " is already loaded"));
  models_[id] = shared;
  if (default_id_.empty()) default_id_ = id;
  return HostedModel{id, shared};
}

absl::Status ModelRegistry::Unload(const std::string& id) {
  absl::MutexLock lock(&mu_);
  if (!models_.count(id))
    return absl::NotFoundError(absl::StrCat("model '", id, "' is not loaded"));
  if (default_id_ == id) {
    return absl::FailedPreconditionError(
        absl::StrCat(id,
                     " is the default model (--default-model or models/DEFAULT): calls that "
                     "name no model use it, so it stays loaded; restart the server with "
                     "another default to retire it"));
  }
  models_.erase(id);
  return absl::OkStatus();
}

}  // namespace stylus::server
