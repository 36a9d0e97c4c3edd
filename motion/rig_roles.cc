#include "motion/rig_roles.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace stylus::motion {
namespace {

constexpr const char* kRoleNames[kRoleCount] = {
    "pelvis",          "spine",          "chest",        "neck",       "head",
    "left_clavicle",   "left_upper_arm", "left_forearm", "left_hand",  "right_clavicle",
    "right_upper_arm", "right_forearm",  "right_hand",   "left_thigh", "left_shin",
    "left_foot",       "left_toe",       "right_thigh",  "right_shin", "right_foot",
    "right_toe"};

enum class Side { kNone, kLeft, kRight };

// The joint's name without a `namespace:` or `path|` prefix.
std::string BaseName(const std::string& name) {
  const size_t cut = name.find_last_of(":|");
  return cut == std::string::npos ? name : name.substr(cut + 1);
}

Side SideOf(const std::string& name) {
  const std::string base = BaseName(name);
  const std::string n = absl::AsciiStrToLower(base);
  if (absl::StrContains(n, "left")) return Side::kLeft;
  if (absl::StrContains(n, "right")) return Side::kRight;
  for (absl::string_view token : absl::StrSplit(n, absl::ByAnyChar("_.- "))) {
    if (token == "l") return Side::kLeft;
    if (token == "r") return Side::kRight;
  }
  // "LHipJoint", "RThigh": a capital L or R before another capital.
  if (base.size() >= 2 && absl::ascii_isupper(base[1])) {
    if (base[0] == 'L') return Side::kLeft;
    if (base[0] == 'R') return Side::kRight;
  }
  return Side::kNone;
}

bool NameHas(const std::string& name, const std::vector<const char*>& keys) {
  const std::string n = absl::AsciiStrToLower(BaseName(name));
  for (const char* k : keys) {
    if (absl::StrContains(n, k)) return true;
  }
  return false;
}

// Joints in the chain of a limb that are no part of it: twist and roll bones.
bool IsTwist(const std::string& name) { return NameHas(name, {"twist", "roll"}); }

class Finder {
 public:
  Finder(const Skeleton& sk, const GlobalPose& pose) : sk_(sk), pose_(pose) {
    size_.assign(sk.num_joints(), 1);
    for (int j = sk.num_joints() - 1; j > 0; --j) size_[sk.joint(j).parent] += size_[j];
  }

  RigRoles& roles() { return r_; }

  void Set(Role role, int joint, const char* how) {
    const int i = static_cast<int>(role);
    if (r_.joint[i] >= 0 || joint < 0 || Used(joint)) return;
    r_.joint[i] = joint;
    r_.how[i] = how;
  }

  absl::Status ApplyJointMap(const JointMap& map) {
    for (const auto& [role, name] : map) {
      const std::optional<int> j = sk_.Find(name);
      if (!j) {
        return absl::InvalidArgumentError(absl::StrCat("joint map: ", RoleName(role), " = '", name,
                                                       "': the skeleton has no such joint"));
      }
      r_.joint[static_cast<int>(role)] = *j;
      r_.how[static_cast<int>(role)] = "joint map";
    }
    return absl::OkStatus();
  }

  // Feet and hands by name; the rest of each limb by the hierarchy.
  void ByName() {
    const std::vector<const char*> not_hand = {"thumb", "index",  "middle", "ring",
                                               "pinky", "finger", "end",    "nub",
                                               "site",  "twist",  "roll"};
    const std::vector<const char*> not_foot = {"toe",  "ball",  "end", "nub",
                                               "heel", "twist", "roll"};
    for (int j = 0; j < sk_.num_joints(); ++j) {
      const std::string& name = sk_.joint(j).name;
      const Side side = SideOf(name);
      if (side == Side::kNone) continue;
      const bool left = side == Side::kLeft;
      if (NameHas(name, {"hand", "wrist"}) && !NameHas(name, not_hand)) {
        Set(left ? Role::kLeftHand : Role::kRightHand, j, "name");
      }
      if (NameHas(name, {"foot", "ankle"}) && !NameHas(name, not_foot)) {
        Set(left ? Role::kLeftFoot : Role::kRightFoot, j, "name");
      }
    }
  }

  bool HasLimbEnds() const {
    for (Role e : {Role::kLeftHand, Role::kRightHand, Role::kLeftFoot, Role::kRightFoot}) {
      if (!r_.has(e)) return false;
    }
    return true;
  }

  // Hierarchy-and-geometry fallback for the limbs (see the header).
  void ByGeometry() {
    int pelvis = -1;
    for (int j = 0; j < sk_.num_joints() && pelvis < 0; ++j) {
      if (sk_.children(j).size() >= 3) pelvis = j;
    }
    if (pelvis < 0) return;
    std::vector<int> branches = BranchesBySize(pelvis);
    const int spine_root = branches[0];
    int chest = -1;
    for (int j = spine_root; j >= 0 && chest < 0; j = LargestChild(j)) {
      if (sk_.children(j).size() >= 3) chest = j;
    }
    if (chest < 0) return;
    const std::vector<int> arms = BranchesBySize(chest);
    struct Limb {
      int upper = -1, lower = -1, end = -1, extra = -1, before = -1;
    };
    auto limb = [&](int root) {
      std::vector<int> chain;
      for (int j = root; j >= 0; j = LargestChild(j)) chain.push_back(j);
      Limb l;
      double best = -1;
      for (size_t i = 0; i + 2 < chain.size(); ++i) {
        const double len =
            Norm(sk_.joint(chain[i + 1]).offset) + Norm(sk_.joint(chain[i + 2]).offset);
        if (len > best + 1e-9) {
          best = len;
          l.upper = chain[i];
          l.lower = chain[i + 1];
          l.end = chain[i + 2];
          l.extra = i + 3 < chain.size() ? chain[i + 3] : -1;
          l.before = i > 0 ? chain[i - 1] : -1;
        }
      }
      return l;
    };
    Limb leg_a = limb(branches[1]), leg_b = limb(branches[2]);
    Limb arm_a = limb(arms[0]), arm_b = limb(arms[1]);
    if (leg_a.end < 0 || leg_b.end < 0 || arm_a.end < 0 || arm_b.end < 0) return;
    // Sides: the toes point forward; left = up x forward.
    const Vec3 up = UpFrom(chest, leg_a.end, leg_b.end);
    Vec3 forward;
    for (const Limb& leg : {leg_a, leg_b})
      forward = forward + (ToePoint(leg.end, leg.extra) - P(leg.end));
    forward = forward - Dot(forward, up) * up;
    if (Norm(forward) < 1e-9) return;
    const Vec3 left = Cross(up, Normalized(forward));
    if (Dot(P(leg_a.upper) - P(leg_b.upper), left) < 0) std::swap(leg_a, leg_b);
    if (Dot(P(arm_a.upper) - P(arm_b.upper), left) < 0) std::swap(arm_a, arm_b);
    const char* g = "geometry";
    Set(Role::kLeftThigh, leg_a.upper, g);
    Set(Role::kLeftShin, leg_a.lower, g);
    Set(Role::kLeftFoot, leg_a.end, g);
    Set(Role::kLeftToe, leg_a.extra, g);
    Set(Role::kRightThigh, leg_b.upper, g);
    Set(Role::kRightShin, leg_b.lower, g);
    Set(Role::kRightFoot, leg_b.end, g);
    Set(Role::kRightToe, leg_b.extra, g);
    Set(Role::kLeftUpperArm, arm_a.upper, g);
    Set(Role::kLeftForearm, arm_a.lower, g);
    Set(Role::kLeftHand, arm_a.end, g);
    Set(Role::kRightUpperArm, arm_b.upper, g);
    Set(Role::kRightForearm, arm_b.lower, g);
    Set(Role::kRightHand, arm_b.end, g);
    if (arm_a.before != chest) Set(Role::kLeftClavicle, arm_a.before, g);
    if (arm_b.before != chest) Set(Role::kRightClavicle, arm_b.before, g);
    if (branches.size() >= 3 && arms.size() >= 3) {
      int head = arms[2];
      for (int j = head; j >= 0; j = LargestChild(j)) head = j;
      if (NameHas(sk_.joint(head).name, {"end", "top", "nub", "site"}) &&
          sk_.joint(head).parent != chest) {
        head = sk_.joint(head).parent;
      }
      Set(Role::kHead, head, g);
    }
  }

  // Everything else from the hierarchy around the limb ends.
  void ByHierarchy() {
    const char* h = "hierarchy";
    for (bool left : {true, false}) {
      const Role foot = left ? Role::kLeftFoot : Role::kRightFoot;
      const Role shin = left ? Role::kLeftShin : Role::kRightShin;
      const Role thigh = left ? Role::kLeftThigh : Role::kRightThigh;
      const Role toe = left ? Role::kLeftToe : Role::kRightToe;
      const Role hand = left ? Role::kLeftHand : Role::kRightHand;
      const Role fore = left ? Role::kLeftForearm : Role::kRightForearm;
      const Role upper = left ? Role::kLeftUpperArm : Role::kRightUpperArm;
      if (r_.has(foot)) Set(shin, LimbParent(r_[foot]), h);
      if (r_.has(shin)) Set(thigh, LimbParent(r_[shin]), h);
      if (r_.has(hand)) Set(fore, LimbParent(r_[hand]), h);
      if (r_.has(fore)) Set(upper, LimbParent(r_[fore]), h);
      if (r_.has(foot) && !r_.has(toe)) {
        for (int c : sk_.children(r_[foot])) {
          if (!NameHas(sk_.joint(c).name, {"heel"}) && !IsTwist(sk_.joint(c).name)) {
            Set(toe, c, h);
            break;
          }
        }
        if (!r_.has(toe) && !sk_.joint(r_[foot]).end_sites.empty()) {
          r_.toe_is_end_site[left ? 0 : 1] = true;
          r_.how[static_cast<int>(toe)] = "end site";
        }
      }
    }
    if (r_.has(Role::kLeftThigh) && r_.has(Role::kRightThigh)) {
      Set(Role::kPelvis, CommonAncestor(r_[Role::kLeftThigh], r_[Role::kRightThigh]), h);
    }
    if (r_.has(Role::kLeftUpperArm) && r_.has(Role::kRightUpperArm)) {
      Set(Role::kChest, CommonAncestor(r_[Role::kLeftUpperArm], r_[Role::kRightUpperArm]), h);
    }
    if (!r_.has(Role::kChest)) return;
    const int chest = r_[Role::kChest];
    for (Role c : {Role::kLeftClavicle, Role::kRightClavicle}) {
      const Role upper = c == Role::kLeftClavicle ? Role::kLeftUpperArm : Role::kRightUpperArm;
      if (!r_.has(upper)) continue;
      const int p = LimbParent(r_[upper]);
      if (p != chest && IsBelow(p, chest)) Set(c, p, h);
    }
    if (!r_.has(Role::kHead)) {
      for (int j = chest + 1; j < sk_.num_joints(); ++j) {
        const std::string& n = sk_.joint(j).name;
        if (IsBelow(j, chest) && SideOf(n) == Side::kNone && NameHas(n, {"head"}) &&
            !NameHas(n, {"end", "top", "nub", "site", "eye", "jaw"})) {
          Set(Role::kHead, j, "name");
          break;
        }
      }
    }
    if (!r_.has(Role::kHead)) {
      // No joint named like a head: the end of the chest's branch that is
      // no arm (its last joint with a length; "...End" tips excluded).
      for (int c : sk_.children(chest)) {
        bool arm = false;
        for (Role a : {Role::kLeftUpperArm, Role::kRightUpperArm}) {
          arm |= r_.has(a) && (r_[a] == c || IsBelow(r_[a], c));
        }
        if (arm) continue;
        int head = c;
        for (int j = c; j >= 0; j = LargestChild(j)) head = j;
        if (NameHas(sk_.joint(head).name, {"end", "top", "nub", "site"}) &&
            sk_.joint(head).parent != chest) {
          head = sk_.joint(head).parent;
        }
        Set(Role::kHead, head, h);
        break;
      }
    }
    if (r_.has(Role::kPelvis) && IsBelow(chest, r_[Role::kPelvis])) {
      // The spine joint: the one between pelvis and chest nearest halfway.
      std::vector<int> path = Between(r_[Role::kPelvis], chest);
      double total = 0, best = 2;
      for (int j : path) total += Norm(sk_.joint(j).offset);
      total += Norm(sk_.joint(chest).offset);
      double at = 0;
      int pick = -1;
      for (int j : path) {
        at += Norm(sk_.joint(j).offset);
        const double d = std::fabs(at / std::max(total, 1e-9) - 0.5);
        if (d < best) best = d, pick = j;
      }
      Set(Role::kSpine, pick, h);
    }
    if (r_.has(Role::kHead) && IsBelow(r_[Role::kHead], chest)) {
      const std::vector<int> path = Between(chest, r_[Role::kHead]);
      if (!path.empty()) Set(Role::kNeck, path.front(), h);
    }
  }

  Vec3 P(int j) const { return pose_.positions[j]; }

  // The first frame's up: from the feet to the chest, snapped to an axis.
  Vec3 UpFrom(int chest, int foot_a, int foot_b) const {
    const Vec3 v = P(chest) - 0.5 * (P(foot_a) + P(foot_b));
    int axis = 0;
    for (int a = 1; a < 3; ++a) {
      if (std::fabs(v[a]) > std::fabs(v[axis])) axis = a;
    }
    Vec3 up;
    up[axis] = v[axis] >= 0 ? 1 : -1;
    return up;
  }

  // Where the toe is: its joint, else the foot's first End Site.
  Vec3 ToePoint(int foot, int toe) const {
    if (toe >= 0) return P(toe);
    const Joint& f = sk_.joint(foot);
    if (f.end_sites.empty()) return P(foot);
    return P(foot) + Rotate(pose_.rotations[foot], f.end_sites[0]);
  }

 private:
  bool Used(int joint) const {
    return std::find(r_.joint.begin(), r_.joint.end(), joint) != r_.joint.end();
  }
  int LargestChild(int j) const {
    int best = -1;
    for (int c : sk_.children(j)) {
      if (best < 0 || size_[c] > size_[best]) best = c;
    }
    return best;
  }
  std::vector<int> BranchesBySize(int j) const {
    std::vector<int> b = sk_.children(j);
    std::stable_sort(b.begin(), b.end(), [&](int x, int y) { return size_[x] > size_[y]; });
    return b;
  }
  int LimbParent(int j) const {
    int p = sk_.joint(j).parent;
    while (p >= 0 && IsTwist(sk_.joint(p).name)) p = sk_.joint(p).parent;
    return p;
  }
  bool IsBelow(int j, int ancestor) const {
    for (int p = sk_.joint(j).parent; p >= 0; p = sk_.joint(p).parent) {
      if (p == ancestor) return true;
    }
    return false;
  }
  int CommonAncestor(int a, int b) const {
    for (int p = sk_.joint(a).parent; p >= 0; p = sk_.joint(p).parent) {
      if (IsBelow(b, p)) return p;
    }
    return -1;
  }
  // Joints strictly between `ancestor` and `j`, top down.
  std::vector<int> Between(int ancestor, int j) const {
    std::vector<int> path;
    for (int p = sk_.joint(j).parent; p >= 0 && p != ancestor; p = sk_.joint(p).parent) {
      path.push_back(p);
    }
    std::reverse(path.begin(), path.end());
    return path;
  }

  const Skeleton& sk_;
  const GlobalPose& pose_;
  std::vector<int> size_;
  RigRoles r_;
};

}  // namespace

absl::string_view RoleName(Role role) { return kRoleNames[static_cast<int>(role)]; }

bool ParseRole(absl::string_view name, Role* role) {
  std::string n = absl::AsciiStrToLower(absl::StripAsciiWhitespace(name));
  std::replace(n.begin(), n.end(), '-', '_');
  std::replace(n.begin(), n.end(), ' ', '_');
  for (int i = 0; i < kRoleCount; ++i) {
    if (n == kRoleNames[i]) {
      *role = static_cast<Role>(i);
      return true;
    }
  }
  return false;
}

bool RoleRequired(Role role) {
  switch (role) {
    case Role::kSpine:
    case Role::kNeck:
    case Role::kLeftClavicle:
    case Role::kRightClavicle:
    case Role::kLeftToe:
    case Role::kRightToe:
      return false;
    default:
      return true;
  }
}

absl::StatusOr<JointMap> ParseJointMap(absl::string_view text, absl::string_view source) {
  JointMap map;
  int line_no = 0;
  for (absl::string_view line : absl::StrSplit(text, absl::ByAnyChar("\r\n"))) {
    ++line_no;
    const size_t hash = line.find('#');
    if (hash != absl::string_view::npos) line = line.substr(0, hash);
    line = absl::StripAsciiWhitespace(line);
    if (line.empty()) continue;
    const size_t eq = line.find('=');
    if (eq == absl::string_view::npos) {
      return absl::InvalidArgumentError(absl::StrCat(
          source, ":", line_no, ": expected 'role = joint name' (e.g. left_foot = LeftFoot)"));
    }
    const absl::string_view key = absl::StripAsciiWhitespace(line.substr(0, eq));
    const absl::string_view value = absl::StripAsciiWhitespace(line.substr(eq + 1));
    Role role;
    if (!ParseRole(key, &role)) {
      std::vector<std::string> names(kRoleNames, kRoleNames + kRoleCount);
      return absl::InvalidArgumentError(absl::StrCat(source, ":", line_no, ": unknown role '", key,
                                                     "'; roles: ", absl::StrJoin(names, ", ")));
    }
    if (value.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ":", line_no, ": no joint name after '", key, " ='"));
    }
    for (const auto& [r, n] : map) {
      if (r == role) {
        return absl::InvalidArgumentError(
            absl::StrCat(source, ":", line_no, ": role '", RoleName(role), "' given twice"));
      }
    }
    map.emplace_back(role, std::string(value));
  }
  return map;
}

absl::StatusOr<JointMap> ReadJointMapFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open the joint map"));
  std::stringstream text;
  text << in.rdbuf();
  return ParseJointMap(text.str(), path);
}

absl::StatusOr<RigRoles> FindRigRoles(const Skeleton& skeleton, const GlobalPose& sample,
                                      const JointMap& joint_map) {
  Finder finder(skeleton, sample);
  if (absl::Status s = finder.ApplyJointMap(joint_map); !s.ok()) return s;
  finder.ByName();
  if (!finder.HasLimbEnds()) finder.ByGeometry();
  finder.ByHierarchy();
  RigRoles& r = finder.roles();
  std::vector<std::string> missing;
  for (int i = 0; i < kRoleCount; ++i) {
    if (r.joint[i] < 0 && RoleRequired(static_cast<Role>(i))) missing.push_back(kRoleNames[i]);
  }
  if (!missing.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "not a humanoid rig that can be mapped: found no joint for ", absl::StrJoin(missing, ", "),
        " (name them in a joint map: --joint-map FILE with lines like 'left_foot = MyFootL')"));
  }
  auto below = [&](int j, int ancestor) {
    for (int p = skeleton.joint(j).parent; p >= 0; p = skeleton.joint(p).parent) {
      if (p == ancestor) return true;
    }
    return false;
  };
  const std::pair<Role, Role> chains[] = {{Role::kPelvis, Role::kChest},
                                          {Role::kChest, Role::kHead},
                                          {Role::kPelvis, Role::kLeftThigh},
                                          {Role::kLeftThigh, Role::kLeftShin},
                                          {Role::kLeftShin, Role::kLeftFoot},
                                          {Role::kPelvis, Role::kRightThigh},
                                          {Role::kRightThigh, Role::kRightShin},
                                          {Role::kRightShin, Role::kRightFoot},
                                          {Role::kChest, Role::kLeftUpperArm},
                                          {Role::kLeftUpperArm, Role::kLeftForearm},
                                          {Role::kLeftForearm, Role::kLeftHand},
                                          {Role::kChest, Role::kRightUpperArm},
                                          {Role::kRightUpperArm, Role::kRightForearm},
                                          {Role::kRightForearm, Role::kRightHand}};
  for (const auto& [top, low] : chains) {
    if (!below(r[low], r[top])) {
      return absl::InvalidArgumentError(
          absl::StrCat("not a humanoid rig that can be mapped: ", RoleName(low), " '",
                       skeleton.joint(r[low]).name, "' is not below ", RoleName(top), " '",
                       skeleton.joint(r[top]).name, "' (fix the roles with --joint-map FILE)"));
    }
  }
  r.up = finder.UpFrom(r[Role::kChest], r[Role::kLeftFoot], r[Role::kRightFoot]);
  return r;
}

absl::StatusOr<HumanoidRoles> HumanoidRolesOf(const Motion& clip) {
  absl::StatusOr<HumanoidRoles> by_name = FindHumanoidRoles(clip.skeleton);
  if (clip.num_frames == 0) return by_name;
  const Skeleton& sk = clip.skeleton;
  absl::StatusOr<RigRoles> r = FindRigRoles(sk, ForwardKinematics(sk, PoseAt(clip, 0)));
  if (by_name.ok()) {
    if (r.ok()) by_name->up_axis = r->up.x != 0 ? 0 : (r->up.y != 0 ? 1 : 2);
    return by_name;
  }
  if (!r.ok()) return r.status();
  HumanoidRoles h;
  h.pelvis = (*r)[Role::kPelvis];
  h.left_hip = (*r)[Role::kLeftThigh];
  h.right_hip = (*r)[Role::kRightThigh];
  h.left_shoulder = (*r)[Role::kLeftUpperArm];
  h.right_shoulder = (*r)[Role::kRightUpperArm];
  h.left_ankle = (*r)[Role::kLeftFoot];
  h.right_ankle = (*r)[Role::kRightFoot];
  h.left_toe = r->has(Role::kLeftToe) ? (*r)[Role::kLeftToe] : h.left_ankle;
  h.right_toe = r->has(Role::kRightToe) ? (*r)[Role::kRightToe] : h.right_ankle;
  h.leg_length = ChainLength(sk, h.left_hip, h.left_toe);
  h.up_axis = r->up.x != 0 ? 0 : (r->up.y != 0 ? 1 : 2);
  return h;
}

double LegLength(const Skeleton& skeleton, const RigRoles& r) {
  return 0.5 * (ChainLength(skeleton, r[Role::kLeftThigh], r[Role::kLeftFoot]) +
                ChainLength(skeleton, r[Role::kRightThigh], r[Role::kRightFoot]));
}

std::string DescribeRigRoles(const Skeleton& skeleton, const RigRoles& roles) {
  std::string out;
  for (int i = 0; i < kRoleCount; ++i) {
    const int j = roles.joint[i];
    std::string joint = j >= 0 ? skeleton.joint(j).name : "-";
    if (j < 0 && !roles.how[i].empty()) {
      const int foot = roles.joint[static_cast<int>(
          i == static_cast<int>(Role::kLeftToe) ? Role::kLeftFoot : Role::kRightFoot)];
      joint = absl::StrCat("(End Site of ", skeleton.joint(foot).name, ")");
    }
    absl::StrAppend(&out, absl::StrFormat("%-16s %-32s %s\n", kRoleNames[i], joint,
                                          roles.how[i].empty() ? "not found" : roles.how[i]));
  }
  const char axis = roles.up.x != 0 ? 'X' : (roles.up.y != 0 ? 'Y' : 'Z');
  const bool negative = roles.up.x + roles.up.y + roles.up.z < 0;
  absl::StrAppend(&out, "up axis: ", negative ? "-" : "+", std::string(1, axis), "\n");
  return out;
}

}  // namespace stylus::motion
