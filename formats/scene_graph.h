// Internal to formats/: affine transforms in double precision, and the
// skeleton of an assimp scene (which nodes are joints, their rest transforms).
#ifndef STYLUS_FORMATS_SCENE_GRAPH_H_
#define STYLUS_FORMATS_SCENE_GRAPH_H_

#include <string>
#include <vector>

#include <assimp/Importer.hpp>
#include <assimp/anim.h>
#include <assimp/matrix4x4.h>
#include <assimp/scene.h>

#include "absl/status/statusor.h"
#include "motion/rotation.h"

namespace stylus::formats {

// x' = linear * x + translation.
struct Affine {
  motion::Mat3 linear;
  motion::Vec3 translation;
};

Affine operator*(const Affine& a, const Affine& b);
Affine Inverse(const Affine& a);
Affine FromAssimp(const aiMatrix4x4& m);
aiMatrix4x4 ToAssimp(const Affine& a);
// Translation * rotation * scale, as nodes and animation keys compose them.
Affine Compose(const motion::Vec3& t, const motion::Quat& r, const motion::Vec3& s);
// The scale (column lengths) and rotation (columns normalized) of `a`;
// shear is not kept.
motion::Vec3 ScaleOf(const Affine& a);
motion::Quat RotationOf(const Affine& a);

// The turn and scale from a scene's axes and unit (FBX states both in its
// metadata) to Y up and metres; identity for files without them (glTF is Y-up
// metres; assimp applies COLLADA's unit itself). ImportScene applies it to
// the scene's root node.
Affine MetresYUp(const aiScene& scene);

// A scene's skeleton: joints in depth-first order (parents first).
struct SceneSkeleton {
  std::vector<const aiNode*> nodes;
  std::vector<int> parent;            // -1 for the root.
  Affine above_root;                  // World transform of the root's parent.
  std::vector<Affine> rest_world;     // Each joint's world transform at rest.
  std::vector<Affine> rest_local;     // Each node's own transform.
  // Per joint, its leaf children that are no joints (nothing moves them, no
  // mesh, no children: the "_end" bones Blender's FBX writer adds), at rest
  // in world space: what BVH calls End Sites.
  std::vector<std::vector<motion::Vec3>> end_sites;
};

// The joints of `scene`: the nodes `animation` moves and the bones of its
// meshes, with the nodes between them, under their lowest common ancestor
// (which becomes the root joint when it is itself moved, else when it is not
// the scene's root node). `source` names the file in errors.
absl::StatusOr<SceneSkeleton> FindSkeleton(const aiScene& scene, const aiAnimation* animation,
                                           const std::string& source);

// The joints named `names` (in that order, parents first), found by name.
// INVALID_ARGUMENT names a joint the scene lacks or whose parent differs.
absl::StatusOr<SceneSkeleton> SkeletonByNames(const aiScene& scene,
                                              const std::vector<std::string>& names,
                                              const std::vector<int>& parents,
                                              const std::string& source);

// Assimp's import of `path` with the settings every reader here uses
// (pivots folded into their nodes, no post-processing). `importer` owns the
// scene. Errors name the file.
absl::StatusOr<const aiScene*> ImportScene(Assimp::Importer* importer, const std::string& path);

}  // namespace stylus::formats

#endif  // STYLUS_FORMATS_SCENE_GRAPH_H_
