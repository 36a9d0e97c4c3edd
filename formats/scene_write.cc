// Writing: BVH through motion/bvh.h, glTF 2.0 through assimp's exporter.
#include <assimp/Exporter.hpp>
#include <assimp/scene.h>
#include <stdlib.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "formats/scene_file.h"
#include "formats/scene_graph.h"
#include "motion/bvh.h"
#include "motion/kinematics.h"

namespace stylus::formats {

using motion::Quat;
using motion::Vec3;

namespace {

aiVector3D ToAi(const Vec3& v) {
  return aiVector3D(static_cast<ai_real>(v.x), static_cast<ai_real>(v.y), static_cast<ai_real>(v.z));
}

// One animation channel per joint: each frame's node transform, keyed once
// per frame (time in frames; ticks per second = the motion's rate).
aiAnimation* BuildAnimation(const motion::Motion& m, const SceneSkeleton& s, const std::string& name) {
  const int n = m.skeleton.num_joints();
  auto* anim = new aiAnimation();
  anim->mName = aiString(name);
  anim->mTicksPerSecond = m.fps();
  anim->mDuration = std::max(0, m.num_frames - 1);
  anim->mNumChannels = n;
  anim->mChannels = new aiNodeAnim*[n];
  std::vector<Vec3> rest_scale(n);
  std::vector<Quat> rest_rotation(n);
  for (int j = 0; j < n; ++j) {
    rest_scale[j] = ScaleOf(s.rest_world[j]);
    rest_rotation[j] = RotationOf(s.rest_world[j]);
    auto* ch = new aiNodeAnim();
    ch->mNodeName = s.nodes[j]->mName;
    ch->mNumPositionKeys = ch->mNumRotationKeys = ch->mNumScalingKeys = m.num_frames;
    ch->mPositionKeys = new aiVectorKey[m.num_frames];
    ch->mRotationKeys = new aiQuatKey[m.num_frames];
    ch->mScalingKeys = new aiVectorKey[m.num_frames];
    anim->mChannels[j] = ch;
  }
  std::vector<Affine> world(n);
  for (int f = 0; f < m.num_frames; ++f) {
    motion::GlobalPose g = motion::ForwardKinematics(m.skeleton, motion::PoseAt(m, f));
    for (int j = 0; j < n; ++j) {
      world[j] = Compose(g.positions[j], g.rotations[j] * rest_rotation[j], rest_scale[j]);
      const Affine& up = s.parent[j] < 0 ? s.above_root : world[s.parent[j]];
      Affine local = Inverse(up) * world[j];
      Quat r = RotationOf(local);
      aiNodeAnim* ch = anim->mChannels[j];
      ch->mPositionKeys[f] = aiVectorKey(f, ToAi(local.translation));
      ch->mRotationKeys[f] = aiQuatKey(f, aiQuaternion(static_cast<ai_real>(r.w), static_cast<ai_real>(r.x),
                                                       static_cast<ai_real>(r.y), static_cast<ai_real>(r.z)));
      ch->mScalingKeys[f] = aiVectorKey(f, ToAi(ScaleOf(local)));
    }
  }
  return anim;
}

// A scene holding the motion's skeleton as nodes at rest, and nothing else.
std::unique_ptr<aiScene> SkeletonScene(const motion::Motion& m) {
  const motion::Skeleton& sk = m.skeleton;
  const int n = sk.num_joints();
  auto scene = std::make_unique<aiScene>();
  scene->mRootNode = new aiNode("Stylus");
  std::vector<aiNode*> nodes(n);
  for (int j = 0; j < n; ++j) {
    nodes[j] = new aiNode(sk.joint(j).name);
    nodes[j]->mTransformation = ToAssimp(Affine{motion::Mat3{}, sk.joint(j).offset});
  }
  for (int j = 0; j < n; ++j) {
    std::vector<aiNode*> kids;
    for (int c : sk.children(j)) kids.push_back(nodes[c]);
    if (!kids.empty()) nodes[j]->addChildren(static_cast<unsigned>(kids.size()), kids.data());
  }
  scene->mRootNode->addChildren(1, &nodes[0]);
  return scene;
}

template <typename T>
void Append(T*** array, unsigned* count, T* item) {
  T** grown = new T*[*count + 1];
  std::copy(*array, *array + *count, grown);
  grown[*count] = item;
  delete[] *array;
  *array = grown;
  ++*count;
}

// When no mesh of `scene` is skinned, a stick figure skinned to the
// skeleton's joints: per bone two thin crossed triangles from the parent
// joint to the child, so that viewers draw it moving and importers (Blender's
// among them) build an armature from its skin.
void AddStickFigure(aiScene* scene, const SceneSkeleton& s) {
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    if (scene->mMeshes[i]->mNumBones > 0) return;
  }
  const int n = static_cast<int>(s.nodes.size());
  std::vector<Vec3> world(n);
  for (int j = 0; j < n; ++j) world[j] = s.rest_world[j].translation;
  std::vector<aiVector3D> vertices;
  std::vector<std::vector<aiVertexWeight>> weights(n);
  for (int j = 1; j < n; ++j) {
    const int p = s.parent[j];
    const Vec3 bone = world[j] - world[p];
    const double length = motion::Norm(bone);
    if (length < 1e-9) continue;
    const Vec3 dir = bone * (1.0 / length);
    const Vec3 u =
        motion::Normalized(motion::Cross(dir, std::abs(dir.y) < 0.9 ? Vec3{0, 1, 0} : Vec3{1, 0, 0}));
    const Vec3 v = motion::Cross(dir, u);
    for (const Vec3& side : {u, v}) {
      const unsigned base = static_cast<unsigned>(vertices.size());
      vertices.push_back(ToAi(world[p] + side * (0.06 * length)));
      vertices.push_back(ToAi(world[p] - side * (0.06 * length)));
      vertices.push_back(ToAi(world[j]));
      weights[p].push_back(aiVertexWeight(base, 1.0f));
      weights[p].push_back(aiVertexWeight(base + 1, 1.0f));
      weights[j].push_back(aiVertexWeight(base + 2, 1.0f));
    }
  }
  auto* mesh = new aiMesh();
  mesh->mName = aiString("stick_figure");
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mNumVertices = static_cast<unsigned>(vertices.size());
  mesh->mVertices = new aiVector3D[vertices.size()];
  std::copy(vertices.begin(), vertices.end(), mesh->mVertices);
  mesh->mNumFaces = mesh->mNumVertices / 3;
  mesh->mFaces = new aiFace[mesh->mNumFaces];
  for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
    mesh->mFaces[f].mNumIndices = 3;
    mesh->mFaces[f].mIndices = new unsigned[3]{3 * f, 3 * f + 1, 3 * f + 2};
  }
  mesh->mNumBones = n;
  mesh->mBones = new aiBone*[n];
  for (int j = 0; j < n; ++j) {
    auto* bone = new aiBone();
    bone->mName = s.nodes[j]->mName;
    // The mesh lies in world space (its node undoes the scene root's
    // transform): the bind matrix is the joint's world transform at rest.
    bone->mOffsetMatrix = ToAssimp(Inverse(s.rest_world[j]));
    bone->mNumWeights = static_cast<unsigned>(weights[j].size());
    bone->mWeights = new aiVertexWeight[std::max<size_t>(1, weights[j].size())];
    std::copy(weights[j].begin(), weights[j].end(), bone->mWeights);
    mesh->mBones[j] = bone;
  }
  auto* material = new aiMaterial();
  aiString material_name("stick_figure");
  material->AddProperty(&material_name, AI_MATKEY_NAME);
  mesh->mMaterialIndex = scene->mNumMaterials;
  Append(&scene->mMaterials, &scene->mNumMaterials, material);
  auto* node = new aiNode("stick_figure");
  node->mTransformation = ToAssimp(Inverse(FromAssimp(scene->mRootNode->mTransformation)));
  node->mNumMeshes = 1;
  node->mMeshes = new unsigned[1]{scene->mNumMeshes};
  Append(&scene->mMeshes, &scene->mNumMeshes, mesh);
  scene->mRootNode->addChildren(1, &node);
}

void ReplaceAnimations(aiScene* scene, aiAnimation* animation) {
  for (unsigned i = 0; i < scene->mNumAnimations; ++i) delete scene->mAnimations[i];
  delete[] scene->mAnimations;
  scene->mNumAnimations = 1;
  scene->mAnimations = new aiAnimation*[1]{animation};
}

std::string Dir(const std::string& path) {
  size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}
std::string Base(const std::string& path) {
  size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// Exports into a fresh folder beside `path`, then renames each file written
// (the .bin before the .gltf that names it) into place.
absl::Status Export(const aiScene& scene, FileFormat format, const std::string& path) {
  std::string pattern = Dir(path) + "/.stylus-export-XXXXXX";
  if (mkdtemp(pattern.data()) == nullptr) {
    return absl::PermissionDeniedError(absl::StrCat(path, ": cannot write in its folder"));
  }
  std::string base = Base(path);
  std::string tmp = pattern + "/" + base;
  Assimp::Exporter exporter;
  const char* id = format == FileFormat::kGlb ? "glb2" : "gltf2";
  aiReturn r = exporter.Export(&scene, id, tmp);
  absl::Status status;
  if (r != aiReturn_SUCCESS) {
    status = absl::InternalError(absl::StrCat(path, ": the glTF writer failed: ", exporter.GetErrorString()));
  }
  std::string stem = base.substr(0, base.find_last_of('.'));
  std::string bin = stem + ".bin";
  if (status.ok() && format == FileFormat::kGltf && access((pattern + "/" + bin).c_str(), F_OK) == 0 &&
      std::rename((pattern + "/" + bin).c_str(), (Dir(path) + "/" + bin).c_str()) != 0) {
    status = absl::InternalError(absl::StrCat(path, ": cannot move ", bin, " into place"));
  }
  if (status.ok() && std::rename(tmp.c_str(), path.c_str()) != 0) {
    status = absl::InternalError(absl::StrCat(path, ": cannot move the written file into place"));
  }
  std::remove((pattern + "/" + bin).c_str());
  std::remove(tmp.c_str());
  rmdir(pattern.c_str());
  return status;
}

}  // namespace

absl::Status WriteMotionFile(const motion::Motion& m, const std::string& path, const WriteOptions& options) {
  absl::StatusOr<FileFormat> format = FormatOfPath(path);
  if (!format.ok()) return format.status();
  if (!CanWrite(*format)) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": Stylus writes ", WritableFormats(),
                                                   "; write a .glb and convert it in your DCC"));
  }
  if (*format == FileFormat::kBvh) return motion::WriteBvhFile(m, path);
  if (m.num_frames < 1) return absl::InvalidArgumentError(absl::StrCat(path, ": the motion has no frames"));

  bool like_scene = false;
  if (!options.like.empty()) {
    absl::StatusOr<FileFormat> like = FormatOfPath(options.like);
    if (!like.ok()) return like.status();
    like_scene = *like != FileFormat::kBvh;
  }
  std::vector<std::string> names;
  std::vector<int> parents;
  for (const motion::Joint& j : m.skeleton.joints()) {
    names.push_back(j.name);
    parents.push_back(j.parent);
  }
  std::unique_ptr<aiScene> scene;
  Assimp::Importer importer;
  if (like_scene) {
    absl::StatusOr<const aiScene*> imported = ImportScene(&importer, options.like);
    if (!imported.ok()) return imported.status();
    scene.reset(importer.GetOrphanedScene());
  } else {
    scene = SkeletonScene(m);
  }
  absl::StatusOr<SceneSkeleton> sk =
      SkeletonByNames(*scene, names, parents, like_scene ? options.like : path);
  if (!sk.ok()) return sk.status();
  ReplaceAnimations(scene.get(), BuildAnimation(m, *sk, options.animation_name));
  AddStickFigure(scene.get(), *sk);
  return Export(*scene, *format, path);
}

}  // namespace stylus::formats
