#include "train/clip_sources.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "motion/bvh.h"
#include "motion/humanoid.h"
#include "motion/normalization.h"
#include "motion/resample.h"
#include "motion/retarget.h"

namespace stylus::model {
namespace fs = std::filesystem;
namespace {

// The mean local rotation of every joint over `clips` (all on one rig).
std::vector<motion::Quat> MeanRotations(const std::vector<const motion::Motion*>& clips) {
  const int n = clips[0]->skeleton.num_joints();
  std::vector<motion::Quat> sum(n, motion::Quat{0, 0, 0, 0}), first(n);
  bool have_first = false;
  for (const motion::Motion* m : clips) {
    for (int f = 0; f < m->num_frames; ++f) {
      const motion::LocalPose pose = motion::PoseAt(*m, f);
      if (!have_first) first = pose.rotations, have_first = true;
      for (int j = 0; j < n; ++j) {
        const motion::Quat q = motion::SameHemisphere(pose.rotations[j], first[j]);
        sum[j] = {sum[j].w + q.w, sum[j].x + q.x, sum[j].y + q.y, sum[j].z + q.z};
      }
    }
  }
  for (motion::Quat& q : sum) q = motion::Normalized(q);
  return sum;
}

}  // namespace

std::string ClipSources::Report() const {
  int labelled = 0;
  for (const auto& l : labels) labelled += l.has_value();
  std::string out = absl::StrFormat("read %d clips", motions.size());
  std::vector<std::string> notes;
  if (retargeted > 0) {
    notes.push_back(absl::StrFormat("%d retargeted from %d other rig%s", retargeted, other_rigs,
                                    other_rigs == 1 ? "" : "s"));
  }
  if (resampled > 0) {
    notes.push_back(absl::StrFormat("%d resampled to %g Hz", resampled, 1.0 / frame_time));
  }
  notes.push_back(absl::StrFormat("%d labelled", labelled));
  absl::StrAppend(&out, " (", absl::StrJoin(notes, ", "), ")");
  if (left_out > 0) absl::StrAppendFormat(&out, "; left out %d clips of the styles left out", left_out);
  absl::StrAppendFormat(&out, "; skipped %d", skipped.size());
  for (const std::string& s : skipped) absl::StrAppend(&out, "\n  skipped ", s);
  return out;
}

absl::StatusOr<ClipSources> ReadClipSources(const std::vector<std::string>& sources, bool test,
                                            const TrainingDataOptions& options) {
  absl::StatusOr<std::map<std::string, motion::ClipLabel>> csv =
      motion::ReadLabelsCsv(options.labels_csv);
  if (!csv.ok()) return csv.status();
  // Which files, and the labels of those that have one.
  std::vector<std::string> paths;
  std::vector<std::optional<motion::ClipLabel>> labels;
  int left_out = 0;
  auto add = [&](const std::string& path, std::optional<motion::ClipLabel> label) {
    auto it = csv->find(motion::CanonicalPath(path));
    if (it != csv->end()) label = it->second;
    if (label && std::find(options.leave_out_styles.begin(), options.leave_out_styles.end(),
                           label->style) != options.leave_out_styles.end()) {
      ++left_out;
      return;
    }
    paths.push_back(path);
    labels.push_back(label);
  };
  for (const std::string& s : sources) {
    if (absl::EndsWith(absl::AsciiStrToLower(s), ".bvh")) {
      if (!test) add(s, motion::ParseClipName(s));
      continue;
    }
    std::error_code ec;
    if (!fs::is_directory(s, ec)) return absl::NotFoundError(s + ": not a directory or .bvh file");
    absl::StatusOr<motion::DatasetIndex> index = motion::IndexDataset({s});
    std::set<std::string> named;
    if (index.ok()) {
      for (const motion::ClipEntry* c : index->Split(test)) add(c->path, c->label);
      for (const motion::ClipEntry& c : index->clips) named.insert(c.path);
    }
    if (test) continue;
    // Clips without a dataset name: all in the training split.
    std::vector<std::string> others;
    for (auto it = fs::recursive_directory_iterator(s, ec); !ec && it != fs::end(it);
         it.increment(ec)) {
      const std::string p = it->path().string();
      if (it->is_regular_file() && absl::EndsWith(absl::AsciiStrToLower(p), ".bvh") &&
          named.count(p) == 0) {
        others.push_back(p);
      }
    }
    std::sort(others.begin(), others.end());
    for (const std::string& p : others) add(p, std::nullopt);
  }
  ClipSources out;
  out.left_out = left_out;
  if (paths.empty()) {
    return absl::InvalidArgumentError(test ? "no held-out clips" : "no training clips");
  }
  // The package's skeleton and reference pose.
  std::shared_ptr<const motion::ModelRig> rig;
  std::vector<motion::Motion> read(paths.size());
  std::vector<bool> ok(paths.size(), false);
  for (size_t i = 0; i < paths.size(); ++i) {
    absl::StatusOr<motion::Motion> m = motion::ReadBvhFile(paths[i]);
    if (!m.ok()) {
      out.skipped.push_back(std::string(m.status().message()));
      continue;
    }
    if (m->num_frames < 2) {
      out.skipped.push_back(paths[i] + ": fewer than 2 frames");
      continue;
    }
    if (absl::Status s = motion::CheckServedRate(m->frame_time, paths[i]); !s.ok()) {
      out.skipped.push_back(std::string(s.message()));
      continue;
    }
    read[i] = *std::move(m);
    ok[i] = true;
  }
  std::vector<motion::Quat> reference;
  if (!options.skeleton.empty()) {
    const bool package = fs::is_directory(options.skeleton);
    absl::StatusOr<motion::Motion> sk =
        motion::ReadBvhFile(package ? options.skeleton + "/skeleton.bvh" : options.skeleton);
    if (!sk.ok()) return sk.status();
    out.skeleton = sk->skeleton;
    out.frame_time = sk->frame_time;
    if (package) {
      absl::StatusOr<motion::NormStats> norm =
          motion::NormStats::Load(options.skeleton + "/norm.txt");
      absl::StatusOr<motion::HumanoidRoles> roles = motion::FindHumanoidRoles(out.skeleton);
      if (norm.ok() && roles.ok()) {
        reference = motion::MeanFeatureRotations(norm->mean, out.skeleton, roles->pelvis);
      }
    }
  } else {
    const auto first = std::find(ok.begin(), ok.end(), true);
    if (first == ok.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat("no training clip could be read: ", out.skipped.front()));
    }
    out.skeleton = read[first - ok.begin()].skeleton;
    out.frame_time = read[first - ok.begin()].frame_time;
  }
  if (reference.empty()) {
    std::vector<const motion::Motion*> on_rig;
    for (size_t i = 0; i < read.size(); ++i) {
      if (ok[i] && read[i].skeleton.SameTopology(out.skeleton)) on_rig.push_back(&read[i]);
    }
    reference = on_rig.empty() ? std::vector<motion::Quat>(out.skeleton.num_joints())
                               : MeanRotations(on_rig);
  }
  std::set<std::string> rigs_seen;
  for (size_t i = 0; i < read.size(); ++i) {
    if (!ok[i]) continue;
    motion::Motion m = std::move(read[i]);
    if (!m.skeleton.SameTopology(out.skeleton)) {
      if (rig == nullptr) {
        absl::StatusOr<std::shared_ptr<const motion::ModelRig>> r =
            motion::MakeModelRig(out.skeleton, reference);
        if (!r.ok()) {
          return absl::InvalidArgumentError(absl::StrCat(
              "the package's skeleton cannot take other rigs: ", r.status().message()));
        }
        rig = *r;
      }
      absl::StatusOr<std::unique_ptr<motion::Retargeter>> r =
          motion::Retargeter::Create(rig, m.skeleton, m.frame(0));
      if (!r.ok()) {
        out.skipped.push_back(absl::StrCat(paths[i], ": ", r.status().message()));
        continue;
      }
      std::string names;
      for (const motion::Joint& j : m.skeleton.joints()) absl::StrAppend(&names, j.name, "/");
      rigs_seen.insert(names);
      m = (*r)->ToModel(m);
      ++out.retargeted;
    }
    if (!motion::SameRate(m.frame_time, out.frame_time)) {
      m = motion::Resample(m, out.frame_time);
      ++out.resampled;
    }
    m.frame_time = out.frame_time;  // Rates within SameRate's tolerance read as one.
    out.motions.push_back(std::move(m));
    out.paths.push_back(paths[i]);
    out.labels.push_back(labels[i]);
  }
  out.other_rigs = static_cast<int>(rigs_seen.size());
  if (out.motions.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(test ? "no held-out clip" : "no training clip",
                                                   " could be used; ", out.Report()));
  }
  return out;
}

}  // namespace stylus::model
