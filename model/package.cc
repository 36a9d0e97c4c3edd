#include "model/package.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "motion/bvh.h"
#include "motion/features.h"
#include "motion/files.h"

namespace stylus::model {

namespace fs = std::filesystem;
using motion::WriteFileAtomically;

absl::StatusOr<DataFiles> ReadDataFiles(const std::string& dir) {
  DataFiles d;
  absl::StatusOr<motion::NormStats> norm = motion::NormStats::Load(dir + "/norm.txt");
  if (!norm.ok()) return norm.status();
  d.norm = *std::move(norm);
  absl::StatusOr<motion::Motion> rest = motion::ReadBvhFile(dir + "/skeleton.bvh");
  if (!rest.ok()) return rest.status();
  d.skeleton = rest->skeleton;
  d.frame_time = rest->frame_time;
  absl::StatusOr<motion::HumanoidRoles> roles = motion::FindHumanoidRoles(d.skeleton);
  if (!roles.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(dir, "/skeleton.bvh: ", roles.status().message()));
  }
  d.roles = *roles;
  const int dim = motion::FeatureLayout(d.skeleton.num_joints()).dim();
  if (d.norm.dim() != dim) {
    return absl::InvalidArgumentError(
        absl::StrCat(dir, "/norm.txt has ", d.norm.dim(), " channels; skeleton.bvh implies ", dim));
  }
  return d;
}

absl::Status WriteDataFiles(const std::string& dir, const motion::NormStats& norm,
                            const motion::Skeleton& skeleton, double frame_time) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return absl::PermissionDeniedError(absl::StrCat(dir, ": cannot create: ", ec.message()));
  if (absl::Status s = norm.Save(dir + "/norm.txt"); !s.ok()) return s;
  return motion::WriteBvhFile(motion::RestMotion(skeleton, 1, frame_time), dir + "/skeleton.bvh");
}

absl::StatusOr<DataFiles> ReadPackageData(const std::string& dir, int config_dim) {
  absl::StatusOr<DataFiles> data = ReadDataFiles(dir);
  if (!data.ok()) return data.status();
  if (config_dim != data->norm.dim()) {
    return absl::InvalidArgumentError(absl::StrCat(dir, ": config.txt says ", config_dim,
                                                   " feature channels, norm.txt has ",
                                                   data->norm.dim()));
  }
  const std::string weights = dir + "/weights.pt";
  std::error_code ec;
  if (!fs::is_regular_file(weights, ec)) return absl::NotFoundError(weights + ": missing");
  return data;
}

absl::Status CheckClipFitsModel(const motion::Motion& clip, const DataFiles& package,
                                const std::string& what) {
  if (clip.num_frames <= 0) return absl::InvalidArgumentError(what + " has no frames");
  const std::string mismatch = clip.skeleton.DescribeMismatch(package.skeleton);
  if (!mismatch.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " is on another skeleton than the model's: ", mismatch));
  }
  const double fps = clip.fps(), model_fps = 1.0 / package.frame_time;
  if (!(std::fabs(fps - model_fps) <= 0.01 * model_fps)) {
    return absl::InvalidArgumentError(absl::StrCat(what, " is at ", fps, " fps; the model expects ",
                                                   model_fps, " fps (resample the clip first)"));
  }
  for (size_t i = 0; i < clip.values.size(); ++i) {
    if (!std::isfinite(clip.values[i])) {
      const int channels = clip.skeleton.num_channels();
      return absl::InvalidArgumentError(absl::StrCat(what, ": frame ", i / channels, ", channel ",
                                                     i % channels, " is not a finite number"));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::string> ReadDefaultPackage(const std::string& models_dir) {
  const fs::path path = fs::path(models_dir) / kDefaultPackageFile;
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::string();
  std::ifstream in(path);
  if (!in) return absl::InvalidArgumentError(absl::StrCat("cannot read ", path.string()));
  std::vector<std::string> ids;
  std::string line;
  while (std::getline(in, line)) {
    const std::string id(absl::StripAsciiWhitespace(line));
    if (!id.empty() && id[0] != '#') ids.push_back(id);
  }
  if (ids.size() != 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        path.string(), ": expected one model id (\"<name>/<version>\"), found ", ids.size()));
  }
  return ids.front();
}

}  // namespace stylus::model
