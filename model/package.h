// Model packages on disk: models/<name>/<version>/ holding
//   config.txt   family, architecture, inference and training keys
//                (docs/config.md)
//   norm.txt     per-channel feature normalization (motion::NormStats)
//   skeleton.bvh the skeleton trained on (one rest frame; its frame time is the
//                model's frame rate)
//   weights.pt   network weights (LibTorch archive; read by the model itself)
//   loss.csv     the training curve (optional)
#ifndef STYLUS_MODEL_PACKAGE_H_
#define STYLUS_MODEL_PACKAGE_H_

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "motion/humanoid.h"
#include "motion/motion.h"
#include "motion/normalization.h"

namespace stylus::model {

// What every package trained on clips holds (norm.txt, skeleton.bvh): the
// feature statistics and the skeleton (with its frame rate and roles) that
// input clips must match.
struct DataFiles {
  motion::NormStats norm;
  motion::Skeleton skeleton;
  double frame_time = 1.0 / 30;
  motion::HumanoidRoles roles;
};

// NOT_FOUND for a missing file; INVALID_ARGUMENT (naming the file) for a
// malformed one, a non-humanoid skeleton, or statistics of another width.
absl::StatusOr<DataFiles> ReadDataFiles(const std::string& dir);
// Writes norm.txt and skeleton.bvh (one rest frame) into `dir`.
absl::Status WriteDataFiles(const std::string& dir, const motion::NormStats& norm,
                            const motion::Skeleton& skeleton, double frame_time);

// The data files of the package in `dir` (ReadDataFiles), checked against
// the feature width `config_dim` its config.txt states, and that its
// weights.pt exists. NOT_FOUND for a missing file; INVALID_ARGUMENT naming
// the file for a malformed or mismatched one.
absl::StatusOr<DataFiles> ReadPackageData(const std::string& dir, int config_dim);

// INVALID_ARGUMENT unless `clip` can be fed to a model of `package`: same joint
// names, hierarchy and channel layout, the same frame rate (within 1%), finite
// values, at least one frame. `what` names the clip in the message.
absl::Status CheckClipFitsModel(const motion::Motion& clip, const DataFiles& package,
                                const std::string& what);

// The file in a model directory (models/) that names its default package:
// one line "<name>/<version>"; blank lines and "#" comments are skipped.
inline constexpr char kDefaultPackageFile[] = "DEFAULT";

// The id <models_dir>/DEFAULT names, "" when there is no such file;
// INVALID_ARGUMENT naming the file unless it names exactly one id.
absl::StatusOr<std::string> ReadDefaultPackage(const std::string& models_dir);

}  // namespace stylus::model

#endif  // STYLUS_MODEL_PACKAGE_H_
