// Saving and loading a trainer's tensors (networks, optimizers) as files of
// one directory (internal to train/: LibTorch).
#ifndef STYLUS_TRAIN_TORCH_FILES_H_
#define STYLUS_TRAIN_TORCH_FILES_H_

#include <torch/torch.h>

#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "model/package.h"
#include "motion/files.h"
#include "train/training_run.h"
#include "train/training_set.h"

namespace stylus::model {

// One file: its name in the directory and how to save it to / load it from
// a path (both given, so one list serves both directions).
struct TorchFile {
  std::string name;
  std::function<void(const std::string&)> save, load;
};

// A TorchFile for anything torch::save and torch::load take (a module
// holder or an optimizer).
template <typename T>
TorchFile Tensors(std::string name, T* object) {
  return {std::move(name), [object](const std::string& p) { torch::save(*object, p); },
          [object](const std::string& p) { torch::load(*object, p); }};
}

// INTERNAL (save) or DATA_LOSS (load) naming the directory and LibTorch's
// reason when a file fails.
inline absl::Status SaveTorchFiles(const std::vector<TorchFile>& files, const std::string& dir) {
  try {
    for (const TorchFile& f : files) f.save(dir + "/" + f.name);
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("saving ", dir, ": ", e.what()));
  }
  return absl::OkStatus();
}

inline absl::Status LoadTorchFiles(const std::vector<TorchFile>& files, const std::string& dir) {
  try {
    for (const TorchFile& f : files) f.load(dir + "/" + f.name);
  } catch (const std::exception& e) {
    return absl::DataLossError(absl::StrCat("loading ", dir, ": ", e.what()));
  }
  return absl::OkStatus();
}

// Saves `file` into `dir` through a temporary name and a rename, so a reader
// (a server loading the package) never sees half a file.
inline absl::Status SaveTorchFileAtomically(const TorchFile& file, const std::string& dir) {
  const std::string path = dir + "/" + file.name, tmp = path + ".tmp";
  try {
    file.save(tmp);
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("saving ", path, ": ", e.what()));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return absl::InternalError(absl::StrCat(path, ": ", ec.message()));
  return absl::OkStatus();
}

// Makes `spec` checkpoint `files` (its save_tensors and load_tensors).
inline void CheckpointTorchFiles(std::vector<TorchFile> files, TrainingRun::Spec* spec) {
  spec->save_tensors = [files](const std::string& dir) { return SaveTorchFiles(files, dir); };
  spec->load_tensors = [files](const std::string& dir) { return LoadTorchFiles(files, dir); };
}

// Writes a trained package into `dir`: config.txt (`config_text`), norm.txt
// and skeleton.bvh of `data`, the weights (`weights`, renamed into place)
// and loss.csv (`csv`).
inline absl::Status WriteTrainedPackage(const std::string& dir, const std::string& config_text,
                                        const TrainingSet& data, const TorchFile& weights,
                                        const std::string& csv) {
  if (absl::Status s = WriteDataFiles(dir, data.norm, data.skeleton, data.frame_time); !s.ok()) {
    return s;
  }
  if (absl::Status s = motion::WriteFileAtomically(dir + "/config.txt", config_text); !s.ok()) {
    return s;
  }
  if (absl::Status s = SaveTorchFileAtomically(weights, dir); !s.ok()) return s;
  return motion::WriteFileAtomically(dir + "/loss.csv", csv);
}

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_TORCH_FILES_H_
