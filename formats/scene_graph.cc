#include "formats/scene_graph.h"

#include <assimp/config.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/container/flat_hash_set.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace stylus::formats {

using motion::Mat3;
using motion::Quat;
using motion::Vec3;

Affine operator*(const Affine& a, const Affine& b) {
  return {a.linear * b.linear, a.linear * b.translation + a.translation};
}

Affine Inverse(const Affine& a) {
  const auto& m = a.linear.m;
  double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
               m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  if (std::abs(det) < 1e-300) det = 1e-300;
  Mat3 inv;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      // Cofactor of (c, r) over the determinant: the adjugate's entry.
      int r0 = (c + 1) % 3, r1 = (c + 2) % 3, c0 = (r + 1) % 3, c1 = (r + 2) % 3;
      inv.m[r][c] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
    }
  }
  Vec3 t = inv * a.translation;
  return {inv, Vec3{-t.x, -t.y, -t.z}};
}

Affine FromAssimp(const aiMatrix4x4& m) {
  Affine a;
  const ai_real* row[3] = {m[0], m[1], m[2]};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) a.linear.m[r][c] = row[r][c];
    a.translation[r] = row[r][3];
  }
  return a;
}

aiMatrix4x4 ToAssimp(const Affine& a) {
  aiMatrix4x4 m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[r][c] = static_cast<ai_real>(a.linear.m[r][c]);
    m[r][3] = static_cast<ai_real>(a.translation[r]);
  }
  return m;
}

Affine Compose(const Vec3& t, const Quat& r, const Vec3& s) {
  Affine a{motion::QuatToMat(r), t};
  for (int row = 0; row < 3; ++row) {
    for (int c = 0; c < 3; ++c) a.linear.m[row][c] *= s[c];
  }
  return a;
}

Vec3 ScaleOf(const Affine& a) {
  Vec3 s;
  for (int c = 0; c < 3; ++c) {
    s[c] = std::sqrt(a.linear.m[0][c] * a.linear.m[0][c] + a.linear.m[1][c] * a.linear.m[1][c] +
                     a.linear.m[2][c] * a.linear.m[2][c]);
  }
  return s;
}

Quat RotationOf(const Affine& a) {
  Vec3 s = ScaleOf(a);
  Mat3 r = a.linear;
  for (int row = 0; row < 3; ++row) {
    for (int c = 0; c < 3; ++c) r.m[row][c] /= (s[c] > 1e-300 ? s[c] : 1.0);
  }
  return motion::Normalized(motion::MatToQuat(r));
}

namespace {

std::string NodeName(const aiNode* n) { return std::string(n->mName.C_Str()); }

// World transform of a node's parent (identity above the scene's root).
Affine ParentWorld(const aiNode* node) {
  Affine world;
  std::vector<const aiNode*> chain;
  for (const aiNode* p = node->mParent; p != nullptr; p = p->mParent) chain.push_back(p);
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) world = world * FromAssimp((*it)->mTransformation);
  return world;
}

int Depth(const aiNode* n) {
  int d = 0;
  for (; n->mParent != nullptr; n = n->mParent) ++d;
  return d;
}

const aiNode* CommonAncestor(const aiNode* a, const aiNode* b) {
  int da = Depth(a), db = Depth(b);
  for (; da > db; --da) a = a->mParent;
  for (; db > da; --db) b = b->mParent;
  while (a != b) {
    a = a->mParent;
    b = b->mParent;
  }
  return a;
}

// Appends the nodes of `root`'s subtree that are in `keep` (or lead to one),
// depth-first with an explicit stack (no recursion on file-controlled depth).
void CollectJoints(const aiNode* root, const absl::flat_hash_set<const aiNode*>& leads,
                   SceneSkeleton* out) {
  std::vector<std::pair<const aiNode*, int>> stack = {{root, -1}};
  while (!stack.empty()) {
    auto [node, parent] = stack.back();
    stack.pop_back();
    int index = static_cast<int>(out->nodes.size());
    out->nodes.push_back(node);
    out->parent.push_back(parent);
    for (unsigned c = node->mNumChildren; c-- > 0;) {
      if (leads.contains(node->mChildren[c])) stack.push_back({node->mChildren[c], index});
    }
  }
}

// World transforms at bind time of the bones skinned by the scene's meshes
// (the mesh node's world transform times the inverse of the bone's offset
// matrix): the rest pose, where node transforms may hold a posed frame (as
// Blender's FBX writer leaves them).
absl::flat_hash_map<std::string, Affine> BindPoses(const aiScene& scene) {
  absl::flat_hash_map<std::string, Affine> bind;
  std::vector<const aiNode*> stack = {scene.mRootNode};
  while (!stack.empty()) {
    const aiNode* node = stack.back();
    stack.pop_back();
    for (unsigned c = 0; c < node->mNumChildren; ++c) stack.push_back(node->mChildren[c]);
    if (node->mNumMeshes == 0) continue;
    Affine mesh_world = ParentWorld(node) * FromAssimp(node->mTransformation);
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      if (node->mMeshes[i] >= scene.mNumMeshes) continue;
      const aiMesh* mesh = scene.mMeshes[node->mMeshes[i]];
      for (unsigned b = 0; b < mesh->mNumBones; ++b) {
        bind.emplace(mesh->mBones[b]->mName.C_Str(),
                     mesh_world * Inverse(FromAssimp(mesh->mBones[b]->mOffsetMatrix)));
      }
    }
  }
  return bind;
}

void FillEndSites(SceneSkeleton* s) {
  absl::flat_hash_set<const aiNode*> joints(s->nodes.begin(), s->nodes.end());
  s->end_sites.assign(s->nodes.size(), {});
  for (size_t j = 0; j < s->nodes.size(); ++j) {
    const aiNode* node = s->nodes[j];
    for (unsigned c = 0; c < node->mNumChildren; ++c) {
      const aiNode* child = node->mChildren[c];
      if (joints.contains(child) || child->mNumChildren > 0 || child->mNumMeshes > 0) continue;
      s->end_sites[j].push_back((s->rest_world[j] * FromAssimp(child->mTransformation)).translation);
    }
  }
}

void FillRest(const aiScene& scene, SceneSkeleton* s) {
  s->above_root = ParentWorld(s->nodes[0]);
  absl::flat_hash_map<std::string, Affine> bind = BindPoses(scene);
  for (size_t j = 0; j < s->nodes.size(); ++j) {
    const Affine up = s->parent[j] < 0 ? s->above_root : s->rest_world[s->parent[j]];
    auto it = bind.find(s->nodes[j]->mName.C_Str());
    Affine world = it != bind.end() ? it->second : up * FromAssimp(s->nodes[j]->mTransformation);
    s->rest_world.push_back(world);
    s->rest_local.push_back(Inverse(up) * world);
  }
  FillEndSites(s);
}

// True when `channel` holds its node still at the node's own transform (an
// armature object baked with constant keys).
bool StillAtRest(const aiNode* node, const aiNodeAnim* channel) {
  Affine rest = FromAssimp(node->mTransformation);
  Vec3 t = rest.translation, s = ScaleOf(rest);
  Quat r = RotationOf(rest);
  double size = std::max({1e-9, motion::Norm(t), std::abs(s.x)});
  for (unsigned k = 0; k < channel->mNumPositionKeys; ++k) {
    const aiVector3D& v = channel->mPositionKeys[k].mValue;
    if (motion::Norm(Vec3{v.x, v.y, v.z} - t) > 1e-5 * size) return false;
  }
  for (unsigned k = 0; k < channel->mNumRotationKeys; ++k) {
    const aiQuaternion& q = channel->mRotationKeys[k].mValue;
    if (motion::AngleBetween(motion::Normalized(Quat{q.w, q.x, q.y, q.z}), r) > 1e-5) return false;
  }
  for (unsigned k = 0; k < channel->mNumScalingKeys; ++k) {
    const aiVector3D& v = channel->mScalingKeys[k].mValue;
    if (motion::Norm(Vec3{v.x, v.y, v.z} - s) > 1e-5 * std::abs(s.x) + 1e-9) return false;
  }
  return true;
}

int MetaInt(const aiScene& scene, const char* key, int fallback) {
  int32_t v = 0;
  return scene.mMetaData != nullptr && scene.mMetaData->Get(key, v) ? v : fallback;
}

}  // namespace

Affine MetresYUp(const aiScene& scene) {
  Affine a;
  if (scene.mMetaData == nullptr) return a;
  // FBX: UnitScaleFactor is centimetres per file unit (Blender and Maya
  // write 1); the axes are named by index and sign.
  double unit_cm = 0;
  float unit_f = 0;
  if (scene.mMetaData->Get("UnitScaleFactor", unit_cm) || scene.mMetaData->Get("UnitScaleFactor", unit_f)) {
    if (unit_cm == 0) unit_cm = unit_f;
  }
  const double scale = unit_cm > 0 ? unit_cm / 100.0 : 1.0;
  const int up = MetaInt(scene, "UpAxis", 1), front = MetaInt(scene, "FrontAxis", 2),
            coord = MetaInt(scene, "CoordAxis", 0);
  const int up_sign = MetaInt(scene, "UpAxisSign", 1), front_sign = MetaInt(scene, "FrontAxisSign", 1),
            coord_sign = MetaInt(scene, "CoordAxisSign", 1);
  Mat3 m;
  m.m = {{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
  if (up < 0 || up > 2 || front < 0 || front > 2 || coord < 0 || coord > 2 || up == front || up == coord ||
      front == coord) {
    m = Mat3{};
  } else {
    m.m[0][coord] = coord_sign < 0 ? -1 : 1;
    m.m[1][up] = up_sign < 0 ? -1 : 1;
    m.m[2][front] = front_sign < 0 ? -1 : 1;
    double det = m.m[0][0] * (m.m[1][1] * m.m[2][2] - m.m[1][2] * m.m[2][1]) -
                 m.m[0][1] * (m.m[1][0] * m.m[2][2] - m.m[1][2] * m.m[2][0]) +
                 m.m[0][2] * (m.m[1][0] * m.m[2][1] - m.m[1][1] * m.m[2][0]);
    if (det < 0) m.m[2][front] = -m.m[2][front];  // A left-handed file: keep a rotation.
  }
  for (auto& row : m.m) {
    for (double& v : row) v *= scale;
  }
  a.linear = m;
  return a;
}

absl::StatusOr<SceneSkeleton> FindSkeleton(const aiScene& scene, const aiAnimation* animation,
                                           const std::string& source) {
  std::vector<const aiNode*> moved;
  auto add = [&](const aiString& name) {
    const aiNode* n = scene.mRootNode->FindNode(name);
    if (n != nullptr) moved.push_back(n);
  };
  if (animation != nullptr) {
    for (unsigned c = 0; c < animation->mNumChannels; ++c) add(animation->mChannels[c]->mNodeName);
  }
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    for (unsigned b = 0; b < scene.mMeshes[m]->mNumBones; ++b) add(scene.mMeshes[m]->mBones[b]->mName);
  }
  if (moved.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(source, ": no skeleton: the animation moves no node of the scene and no mesh is skinned"));
  }
  const aiNode* root = moved[0];
  for (const aiNode* n : moved) root = CommonAncestor(root, n);
  absl::flat_hash_set<const aiNode*> leads;
  for (const aiNode* n : moved) {
    for (const aiNode* p = n; p != nullptr && !leads.contains(p); p = p->mParent) leads.insert(p);
  }
  // An FBX null above the skeleton keyed to stand still (Blender bakes the
  // armature object with the bones) is the scene's, not a joint.
  for (;;) {
    const aiNodeAnim* channel = nullptr;
    for (unsigned c = 0; animation != nullptr && c < animation->mNumChannels; ++c) {
      if (animation->mChannels[c]->mNodeName == root->mName) channel = animation->mChannels[c];
    }
    std::vector<const aiNode*> down;
    for (unsigned c = 0; c < root->mNumChildren; ++c) {
      if (leads.contains(root->mChildren[c])) down.push_back(root->mChildren[c]);
    }
    bool null_node = false;
    if (root->mMetaData != nullptr) root->mMetaData->Get("IsNull", null_node);
    if (channel == nullptr || down.size() != 1 || !null_node || !StillAtRest(root, channel)) break;
    root = down[0];
  }
  bool root_moved = false;
  for (const aiNode* n : moved) root_moved |= (n == root);
  if (!root_moved && root == scene.mRootNode) {
    std::vector<std::string> tops;
    for (unsigned c = 0; c < root->mNumChildren; ++c) {
      if (leads.contains(root->mChildren[c])) tops.push_back(NodeName(root->mChildren[c]));
    }
    if (tops.size() > 1) {
      return absl::InvalidArgumentError(absl::StrCat(
          source, ": several skeletons: the animation moves nodes under ", absl::StrJoin(tops, ", "),
          "; export one character per file (or one animation per character, chosen with --animation)"));
    }
  }
  SceneSkeleton s;
  CollectJoints(root, leads, &s);
  FillRest(scene, &s);
  return s;
}

absl::StatusOr<SceneSkeleton> SkeletonByNames(const aiScene& scene, const std::vector<std::string>& names,
                                              const std::vector<int>& parents, const std::string& source) {
  SceneSkeleton s;
  for (size_t j = 0; j < names.size(); ++j) {
    const aiNode* n = scene.mRootNode->FindNode(names[j].c_str());
    if (n == nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ": has no node '", names[j], "'; write to a file like the one the motion was read from"));
    }
    if (parents[j] >= 0 && n->mParent != s.nodes[parents[j]]) {
      return absl::InvalidArgumentError(absl::StrCat(source, ": node '", names[j], "' is not a child of '",
                                                     names[parents[j]], "' there"));
    }
    s.nodes.push_back(n);
    s.parent.push_back(parents[j]);
  }
  if (s.nodes.empty()) return absl::InvalidArgumentError("a motion without joints");
  FillRest(scene, &s);
  return s;
}

absl::StatusOr<const aiScene*> ImportScene(Assimp::Importer* importer, const std::string& path) {
  if (!std::ifstream(path).good()) return absl::NotFoundError(absl::StrCat(path, ": cannot open"));
  importer->SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
  // COLLADA: nodes by their names (the bones'), not their document ids.
  importer->SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_USE_COLLADA_NAMES, true);
  const aiScene* scene = importer->ReadFile(path, 0);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": not a readable scene (", importer->GetErrorString(), ")"));
  }
  // The scene belongs to `importer`, which lets its caller change it.
  const_cast<aiNode*>(scene->mRootNode)->mTransformation =
      ToAssimp(MetresYUp(*scene)) * scene->mRootNode->mTransformation;
  return scene;
}

}  // namespace stylus::formats
