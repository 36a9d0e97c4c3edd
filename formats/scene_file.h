// Animation files other than BVH: FBX, glTF 2.0 and COLLADA in, glTF 2.0 out,
// through the Open Asset Import Library (Debian's libassimp). This is where
// files become motions; the wire and the server never see a file format.
//
// A scene file's skeleton is the set of nodes its chosen animation moves (and
// the bones its meshes are skinned to), rooted at the highest of them; what
// lies above that root (an armature object, the file's axis and unit
// conversion) is folded into the root, so positions are in the scene's world
// frame. Rotations are expressed as BVH writers from DCC tools do: each
// joint's frame is world-aligned at rest, so a motion whose rotations are all
// zero stands in the file's rest pose, and offsets are rest-pose bone vectors.
// Reading a BVH exported from the same rig by Blender gives the same joint
// positions.
#ifndef STYLUS_FORMATS_SCENE_FILE_H_
#define STYLUS_FORMATS_SCENE_FILE_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "motion/motion.h"

namespace stylus::formats {

enum class FileFormat { kBvh, kFbx, kGltf, kGlb, kCollada };

// The format a path names by its extension (case-insensitive): .bvh, .fbx,
// .gltf, .glb, .dae. INVALID_ARGUMENT names the path and the formats known.
absl::StatusOr<FileFormat> FormatOfPath(absl::string_view path);
// True for the formats WriteMotionFile writes (.bvh, .gltf, .glb).
bool CanWrite(FileFormat format);
// "a .bvh, .fbx, .gltf, .glb or .dae file", for messages and --help.
std::string ReadableFormats();
std::string WritableFormats();

struct ReadOptions {
  // The animation to read, by name; empty reads the file's only one (a file
  // with several is an error that lists their names).
  std::string animation;
  int64_t max_frames = 10'000'000;
  int64_t max_file_bytes = int64_t{2} << 30;
};

// Reads any readable format (BVH through motion/bvh.h). Errors name the file
// and what is missing: NOT_FOUND (cannot be opened), INVALID_ARGUMENT (not a
// format assimp reads, no animation, an animation name not in the file,
// several skeletons, joints with one name, more frames than allowed).
absl::StatusOr<motion::Motion> ReadMotionFile(const std::string& path,
                                              const ReadOptions& options = {});

struct WriteOptions {
  // A scene file (FBX, glTF or COLLADA) the motion's skeleton was read from:
  // a glTF output keeps its nodes, meshes, skins and materials and replaces
  // only the animations with this motion. Empty (or a .bvh): the output holds
  // the skeleton alone, with a thin stick figure skinned to it so that any
  // glTF viewer shows it moving and Blender imports it as an armature.
  std::string like;
  std::string animation_name = "stylus";
};

// Writes a .bvh, .gltf (with its .bin beside it) or .glb file, each through a
// temporary file renamed into place. INVALID_ARGUMENT for an extension it
// does not write or a `like` file whose nodes do not hold the motion's joints.
absl::Status WriteMotionFile(const motion::Motion& motion, const std::string& path,
                             const WriteOptions& options = {});

}  // namespace stylus::formats

#endif  // STYLUS_FORMATS_SCENE_FILE_H_
