#include "motion/humanoid.h"

#include <string>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace stylus::motion {
namespace {

enum class Side { kLeft, kRight };

// True when the lower-cased name marks `side`: "foot_l", "l_foot", "leftfoot",
// "foot.l", "lfoot" are all left.
bool HasSide(const std::string& n, Side side) {
  const char c = side == Side::kLeft ? 'l' : 'r';
  const std::string word = side == Side::kLeft ? "left" : "right";
  if (absl::StrContains(n, word)) return true;
  for (const char* sep : {"_", ".", "-", " "}) {
    if (absl::EndsWith(n, absl::StrCat(sep, std::string(1, c)))) return true;
    if (absl::StartsWith(n, absl::StrCat(std::string(1, c), sep))) return true;
  }
  return false;
}

// First joint on `side` whose name contains one of `keys` (in priority order).
int FindJoint(const Skeleton& sk, Side side, const std::vector<std::string>& keys,
              const std::vector<std::string>& exclude = {}) {
  for (const std::string& key : keys) {
    for (int j = 0; j < sk.num_joints(); ++j) {
      const std::string n = absl::AsciiStrToLower(sk.joint(j).name);
      if (!HasSide(n, side) || !absl::StrContains(n, key)) continue;
      bool excluded = false;
      for (const std::string& x : exclude) excluded |= absl::StrContains(n, x);
      if (!excluded) return j;
    }
  }
  return -1;
}

}  // namespace

double ChainLength(const Skeleton& sk, int from, int to) {
  double len = 0;
  for (int j = to; j != from && j >= 0; j = sk.joint(j).parent) len += Norm(sk.joint(j).offset);
  return len;
}

absl::StatusOr<HumanoidRoles> FindHumanoidRoles(const Skeleton& sk) {
  HumanoidRoles r;
  const std::vector<std::string> hip = {"upperleg", "upleg", "thigh", "hip"};
  const std::vector<std::string> ankle = {"foot", "ankle"};
  const std::vector<std::string> toe = {"toe", "ball"};
  const std::vector<std::string> shoulder = {"upperarm", "uparm", "arm", "shoulder"};
  const std::vector<std::string> not_lower_arm = {"fore", "lower"};
  r.left_hip = FindJoint(sk, Side::kLeft, hip);
  r.right_hip = FindJoint(sk, Side::kRight, hip);
  r.left_ankle = FindJoint(sk, Side::kLeft, ankle, {"toe"});
  r.right_ankle = FindJoint(sk, Side::kRight, ankle, {"toe"});
  r.left_toe = FindJoint(sk, Side::kLeft, toe);
  r.right_toe = FindJoint(sk, Side::kRight, toe);
  r.left_shoulder = FindJoint(sk, Side::kLeft, shoulder, not_lower_arm);
  r.right_shoulder = FindJoint(sk, Side::kRight, shoulder, not_lower_arm);
  const std::pair<const char*, int> roles[] = {{"left hip/upper leg", r.left_hip},
                                               {"right hip/upper leg", r.right_hip},
                                               {"left foot/ankle", r.left_ankle},
                                               {"right foot/ankle", r.right_ankle},
                                               {"left toe", r.left_toe},
                                               {"right toe", r.right_toe},
                                               {"left upper arm", r.left_shoulder},
                                               {"right upper arm", r.right_shoulder}};
  for (const auto& [what, j] : roles) {
    if (j < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("skeleton is not a recognizable humanoid: no joint named like a ", what,
                       " (e.g. UpperLeg_L, Foot_R, Toes_L, UpperArm_R)"));
    }
  }
  r.pelvis = sk.joint(r.left_hip).parent;
  if (r.pelvis < 0 || r.pelvis != sk.joint(r.right_hip).parent) {
    return absl::InvalidArgumentError(absl::StrCat("hips '", sk.joint(r.left_hip).name, "' and '",
                                                   sk.joint(r.right_hip).name,
                                                   "' do not share a parent joint (pelvis)"));
  }
  r.leg_length =
      ChainLength(sk, r.left_hip, r.left_ankle) + ChainLength(sk, r.left_ankle, r.left_toe);
  if (r.leg_length <= 0) return absl::InvalidArgumentError("the left leg has zero length");
  return r;
}

std::vector<bool> LegJoints(const Skeleton& skeleton, const HumanoidRoles& roles) {
  std::vector<bool> leg(skeleton.num_joints(), false);
  for (int j = 0; j < skeleton.num_joints(); ++j) {  // Parents come first.
    const int p = skeleton.joint(j).parent;
    leg[j] = j == roles.left_hip || j == roles.right_hip || (p >= 0 && leg[p]);
  }
  return leg;
}

namespace {
int Descendants(const Skeleton& sk, int j) {
  int n = 0;
  for (int c : sk.children(j)) n += 1 + Descendants(sk, c);
  return n;
}
}  // namespace

int MainChild(const Skeleton& skeleton, int joint) {
  int best = -1, best_size = -1;
  for (int c : skeleton.children(joint)) {
    const int size = Descendants(skeleton, c);
    if (size > best_size) best = c, best_size = size;
  }
  return best;
}

}  // namespace stylus::motion
