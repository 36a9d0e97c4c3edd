// Reading: FBX, glTF and COLLADA through assimp, sampled into a Motion.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "formats/scene_file.h"
#include "formats/scene_graph.h"
#include "motion/bvh.h"

namespace stylus::formats {

using motion::Quat;
using motion::Vec3;

absl::StatusOr<FileFormat> FormatOfPath(absl::string_view path) {
  std::string lower = absl::AsciiStrToLower(path);
  if (absl::EndsWith(lower, ".bvh")) return FileFormat::kBvh;
  if (absl::EndsWith(lower, ".fbx")) return FileFormat::kFbx;
  if (absl::EndsWith(lower, ".gltf")) return FileFormat::kGltf;
  if (absl::EndsWith(lower, ".glb")) return FileFormat::kGlb;
  if (absl::EndsWith(lower, ".dae")) return FileFormat::kCollada;
  return absl::InvalidArgumentError(
      absl::StrCat(path, ": unknown file type; Stylus reads ", ReadableFormats()));
}

bool CanWrite(FileFormat format) {
  return format == FileFormat::kBvh || format == FileFormat::kGltf || format == FileFormat::kGlb;
}

std::string ReadableFormats() { return "a .bvh, .fbx, .gltf, .glb or .dae file"; }
std::string WritableFormats() { return "a .bvh, .gltf or .glb file"; }

namespace {

std::string AnimationName(const aiAnimation* a, unsigned index) {
  std::string name = a->mName.C_Str();
  return name.empty() ? absl::StrCat("#", index) : name;
}

absl::StatusOr<const aiAnimation*> ChooseAnimation(const aiScene& scene, const std::string& wanted,
                                                   const std::string& path) {
  if (scene.mNumAnimations == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        path, ": no animation: the file holds a skeleton or meshes but no keys; export it with its animation"));
  }
  std::vector<std::string> names;
  for (unsigned i = 0; i < scene.mNumAnimations; ++i) names.push_back(AnimationName(scene.mAnimations[i], i));
  if (wanted.empty()) {
    if (scene.mNumAnimations == 1) return scene.mAnimations[0];
    return absl::InvalidArgumentError(absl::StrCat(path, ": has ", names.size(), " animations (",
                                                   absl::StrJoin(names, ", "), "); choose one with --animation NAME"));
  }
  for (unsigned i = 0; i < scene.mNumAnimations; ++i) {
    if (names[i] == wanted) return scene.mAnimations[i];
  }
  return absl::InvalidArgumentError(absl::StrCat(path, ": has no animation '", wanted, "'; it has ",
                                                 absl::StrJoin(names, ", ")));
}

template <typename Key>
int KeyBefore(const Key* keys, unsigned n, double t) {
  // Index of the last key at or before t (0 when t precedes them all).
  int lo = 0, hi = static_cast<int>(n) - 1;
  while (lo < hi) {
    int mid = (lo + hi + 1) / 2;
    if (keys[mid].mTime <= t) lo = mid; else hi = mid - 1;
  }
  return lo;
}

Vec3 SampleVector(const aiVectorKey* keys, unsigned n, double t) {
  int i = KeyBefore(keys, n, t);
  const aiVector3D& a = keys[i].mValue;
  if (i + 1 >= static_cast<int>(n) || t <= keys[i].mTime) return {a.x, a.y, a.z};
  const aiVector3D& b = keys[i + 1].mValue;
  double u = (t - keys[i].mTime) / std::max(1e-12, keys[i + 1].mTime - keys[i].mTime);
  u = std::clamp(u, 0.0, 1.0);
  return {a.x + (b.x - a.x) * u, a.y + (b.y - a.y) * u, a.z + (b.z - a.z) * u};
}

Quat SampleRotation(const aiQuatKey* keys, unsigned n, double t) {
  int i = KeyBefore(keys, n, t);
  const aiQuaternion& a = keys[i].mValue;
  Quat qa = motion::Normalized(Quat{a.w, a.x, a.y, a.z});
  if (i + 1 >= static_cast<int>(n) || t <= keys[i].mTime) return qa;
  const aiQuaternion& b = keys[i + 1].mValue;
  double u = (t - keys[i].mTime) / std::max(1e-12, keys[i + 1].mTime - keys[i].mTime);
  return motion::Slerp(qa, motion::Normalized(Quat{b.w, b.x, b.y, b.z}), std::clamp(u, 0.0, 1.0));
}

// The key spacing most channels use, in ticks, and the first and last key time.
struct Timing {
  double step = 1, first = 0, last = 0;
};

Timing KeyTiming(const aiAnimation& a) {
  std::map<long long, int> spacing;  // Rounded to 1e-4 tick.
  Timing t{1, 1e300, -1e300};
  auto visit = [&](double time, double previous, bool has_previous) {
    t.first = std::min(t.first, time);
    t.last = std::max(t.last, time);
    if (has_previous && time > previous) ++spacing[std::llround((time - previous) * 1e4)];
  };
  for (unsigned c = 0; c < a.mNumChannels; ++c) {
    const aiNodeAnim* ch = a.mChannels[c];
    for (unsigned k = 0; k < ch->mNumRotationKeys; ++k)
      visit(ch->mRotationKeys[k].mTime, k ? ch->mRotationKeys[k - 1].mTime : 0, k > 0);
    for (unsigned k = 0; k < ch->mNumPositionKeys; ++k)
      visit(ch->mPositionKeys[k].mTime, k ? ch->mPositionKeys[k - 1].mTime : 0, k > 0);
  }
  if (t.first > t.last) t.first = t.last = 0;
  int best = 0;
  for (const auto& [ticks, count] : spacing) {
    if (count > best) {
      best = count;
      t.step = ticks * 1e-4;
    }
  }
  if (t.step <= 0) t.step = 1;
  return t;
}

// A rate within 0.05% of a whole number of frames per second is that number
// (glTF stores times as 32-bit floats: 1/30 s reads back as 0.0333333).
double CleanFrameTime(double seconds) {
  double fps = 1.0 / seconds;
  double whole = std::round(fps);
  if (whole >= 1 && std::abs(fps - whole) < 5e-4 * whole) return 1.0 / whole;
  return seconds;
}

}  // namespace

absl::StatusOr<motion::Motion> ReadMotionFile(const std::string& path, const ReadOptions& options) {
  absl::StatusOr<FileFormat> format = FormatOfPath(path);
  if (!format.ok()) return format.status();
  if (*format == FileFormat::kBvh) {
    motion::BvhLimits limits;
    limits.max_frames = options.max_frames;
    limits.max_file_bytes = options.max_file_bytes;
    return motion::ReadBvhFile(path, limits);
  }
  {
    std::ifstream f(path, std::ios::binary | std::ios::ate);
    if (f && static_cast<int64_t>(f.tellg()) > options.max_file_bytes) {
      return absl::InvalidArgumentError(absl::StrCat(path, ": larger than ", options.max_file_bytes, " bytes"));
    }
  }
  Assimp::Importer importer;
  absl::StatusOr<const aiScene*> scene = ImportScene(&importer, path);
  if (!scene.ok()) return scene.status();
  absl::StatusOr<const aiAnimation*> animation = ChooseAnimation(**scene, options.animation, path);
  if (!animation.ok()) return animation.status();
  absl::StatusOr<SceneSkeleton> skeleton = FindSkeleton(**scene, *animation, path);
  if (!skeleton.ok()) return skeleton.status();
  const SceneSkeleton& s = *skeleton;
  const int n = static_cast<int>(s.nodes.size());

  // Each joint's keys, and whether its translation moves.
  std::vector<const aiNodeAnim*> channel(n, nullptr);
  for (unsigned c = 0; c < (*animation)->mNumChannels; ++c) {
    const aiNodeAnim* ch = (*animation)->mChannels[c];
    for (int j = 0; j < n; ++j) {
      if (s.nodes[j]->mName == ch->mNodeName) channel[j] = ch;
    }
  }
  double size = 0;
  for (int j = 1; j < n; ++j) size = std::max(size, motion::Norm(s.rest_world[j].translation - s.rest_world[s.parent[j]].translation));
  std::vector<bool> moves_position(n, false);
  moves_position[0] = true;
  for (int j = 1; j < n; ++j) {
    const aiNodeAnim* ch = channel[j];
    if (ch == nullptr) continue;
    Vec3 rest = s.rest_local[j].translation;
    for (unsigned k = 0; k < ch->mNumPositionKeys && !moves_position[j]; ++k) {
      const aiVector3D& v = ch->mPositionKeys[k].mValue;
      moves_position[j] = motion::Norm(Vec3{v.x, v.y, v.z} - rest) > 1e-4 * std::max(size, 1e-9);
    }
  }

  // The skeleton, world-aligned at rest.
  std::vector<motion::Joint> joints(n);
  for (int j = 0; j < n; ++j) {
    motion::Joint& joint = joints[j];
    joint.name = s.nodes[j]->mName.C_Str();
    if (joint.name.empty()) joint.name = absl::StrCat("joint", j);
    joint.parent = s.parent[j];
    joint.offset = j == 0 ? s.rest_world[0].translation
                          : s.rest_world[j].translation - s.rest_world[s.parent[j]].translation;
    using motion::Channel;
    if (moves_position[j]) joint.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition};
    joint.channels.insert(joint.channels.end(), {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation});
    for (const Vec3& site : s.end_sites[j]) joint.end_sites.push_back(site - s.rest_world[j].translation);
  }
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if (joints[i].name == joints[j].name) {
        return absl::InvalidArgumentError(absl::StrCat(path, ": two joints are called '", joints[i].name,
                                                       "'; rename one in the source file"));
      }
    }
  }
  absl::StatusOr<motion::Skeleton> skel = motion::Skeleton::Create(std::move(joints));
  if (!skel.ok()) return absl::InvalidArgumentError(absl::StrCat(path, ": ", skel.status().message()));

  Timing timing = KeyTiming(**animation);
  double ticks_per_second = (*animation)->mTicksPerSecond > 0 ? (*animation)->mTicksPerSecond : 25.0;
  double frames_span = (timing.last - timing.first) / timing.step;
  if (frames_span + 1 > static_cast<double>(options.max_frames)) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": the animation spans more than ", options.max_frames, " frames"));
  }
  motion::Motion m;
  m.skeleton = *skel;
  m.frame_time = CleanFrameTime(timing.step / ticks_per_second);
  m.num_frames = static_cast<int>(std::llround(frames_span)) + 1;
  m.values.assign(static_cast<size_t>(m.num_frames) * m.skeleton.num_channels(), 0.0);

  std::vector<Quat> rest_rotation(n);
  for (int j = 0; j < n; ++j) rest_rotation[j] = RotationOf(s.rest_world[j]);
  std::vector<Vec3> previous_euler(n);
  std::vector<Affine> world(n);
  motion::LocalPose pose;
  pose.translations.resize(n);
  pose.rotations.resize(n);
  std::vector<Quat> aligned(n);
  for (int f = 0; f < m.num_frames; ++f) {
    double t = timing.first + f * timing.step;
    for (int j = 0; j < n; ++j) {
      const Affine& rest = s.rest_local[j];
      Vec3 tr = rest.translation;
      Quat rot = RotationOf(rest);
      Vec3 sc = ScaleOf(rest);
      if (const aiNodeAnim* ch = channel[j]) {
        if (ch->mNumPositionKeys) tr = SampleVector(ch->mPositionKeys, ch->mNumPositionKeys, t);
        if (ch->mNumRotationKeys) rot = SampleRotation(ch->mRotationKeys, ch->mNumRotationKeys, t);
        if (ch->mNumScalingKeys) sc = SampleVector(ch->mScalingKeys, ch->mNumScalingKeys, t);
      }
      world[j] = (s.parent[j] < 0 ? s.above_root : world[s.parent[j]]) * Compose(tr, rot, sc);
      aligned[j] = motion::Normalized(RotationOf(world[j]) * motion::Conjugate(rest_rotation[j]));
      if (s.parent[j] < 0) {
        pose.rotations[j] = aligned[j];
        pose.translations[j] = world[j].translation;
      } else {
        const Quat& up = aligned[s.parent[j]];
        pose.rotations[j] = motion::Normalized(motion::Conjugate(up) * aligned[j]);
        pose.translations[j] =
            motion::Rotate(motion::Conjugate(up), world[j].translation - world[s.parent[j]].translation);
      }
    }
    motion::SetPose(&m, f, pose, &previous_euler);
  }
  return m;
}

}  // namespace stylus::formats
