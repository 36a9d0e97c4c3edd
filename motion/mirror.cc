#include "motion/mirror.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "motion/kinematics.h"

namespace stylus::motion {
namespace {

// The world reflection: x -> -x.
const Vec3 kWorldFlip{-1, 1, 1};

// The reflections a joint frame may need: one axis flipped, or all three.
const Vec3 kCandidates[] = {{-1, 1, 1}, {1, -1, 1}, {1, 1, -1}, {-1, -1, -1}};

// How far offsets may miss their mirror image, relative to their length.
constexpr double kOffsetTolerance = 0.05;

Vec3 Scale(const Vec3& s, const Vec3& v) { return {s.x * v.x, s.y * v.y, s.z * v.z}; }

// diag(a) * R(q) * diag(b), a proper rotation when both are reflections.
Quat Reflect(const Vec3& a, const Quat& q, const Vec3& b) {
  Mat3 m = QuatToMat(q);
  const double sa[3] = {a.x, a.y, a.z}, sb[3] = {b.x, b.y, b.z};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m.m[r][c] *= sa[r] * sb[c];
  return MatToQuat(m);
}

bool SameSigns(const Vec3& a, const Vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

// `name` with its side marker swapped (Left <-> Right, _L <-> _R, l_ <-> r_,
// .L <-> .R, ...), or nullopt when it has none.
std::optional<std::string> SwapSide(const std::string& name) {
  for (const auto& [a, b] : {std::pair<const char*, const char*>{"Left", "Right"},
                             {"left", "right"},
                             {"LEFT", "RIGHT"}}) {
    for (const auto& [from, to] : {std::pair{a, b}, std::pair{b, a}}) {
      if (name.find(from) != std::string::npos)
        return absl::StrReplaceAll(name, {{from, to}});
    }
  }
  for (const char* sep : {"_", ".", "-", " "}) {
    for (const auto& [l, r] : {std::pair<char, char>{'L', 'R'}, {'l', 'r'}}) {
      for (const auto& [from, to] : {std::pair{l, r}, std::pair{r, l}}) {
        const std::string suffix = absl::StrCat(sep, std::string(1, from));
        if (name.size() > suffix.size() &&
            name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
          return name.substr(0, name.size() - 1) + to;
        const std::string prefix = absl::StrCat(std::string(1, from), sep);
        if (name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0)
          return std::string(1, to) + name.substr(1);
      }
    }
  }
  return std::nullopt;
}

// Local poses of every 4th frame of the samples.
std::vector<LocalPose> SamplePoses(const std::vector<const Motion*>& samples) {
  std::vector<LocalPose> out;
  for (const Motion* m : samples)
    for (int f = 0; f < m->num_frames; f += 4) out.push_back(PoseAt(*m, f));
  return out;
}

// Whether joint `j`'s translation moves off its offset (by more than `tol`)
// in any sampled pose: then the offset says nothing about the bone (a root's
// child placed in the world, say) and does not constrain the mirror.
bool Animated(const std::vector<LocalPose>& poses, const Skeleton& skeleton, int j, double tol) {
  for (const LocalPose& p : poses)
    if (Norm(p.translations[j] - skeleton.joint(j).offset) > tol) return true;
  return false;
}

// The sign-aligned mean of `map` of joint `j`'s rotations, normalized.
Quat MeanRotation(const std::vector<LocalPose>& poses, int j,
                  const std::function<Quat(const Quat&)>& map) {
  Quat sum{0, 0, 0, 0};
  std::optional<Quat> first;
  for (const LocalPose& pose : poses) {
    Quat q = map(pose.rotations[j]);
    if (!first) first = q;
    if (Dot(q, *first) < 0) q = {-q.w, -q.x, -q.y, -q.z};
    sum = {sum.w + q.w, sum.x + q.x, sum.y + q.y, sum.z + q.z};
  }
  if (!first) return Quat{};
  return Normalized(sum);
}

}  // namespace

absl::StatusOr<MirrorMap> PlanMirror(const Skeleton& skeleton,
                                     const std::vector<const Motion*>& samples) {
  const int n = skeleton.num_joints();
  MirrorMap map;
  map.counterpart.assign(n, -1);
  for (int j = 0; j < n; ++j) {
    const std::string& name = skeleton.joint(j).name;
    const std::optional<std::string> other = SwapSide(name);
    if (!other) {
      map.counterpart[j] = j;
      continue;
    }
    const std::optional<int> k = skeleton.Find(*other);
    if (!k) {
      return absl::InvalidArgumentError(absl::StrCat("cannot mirror the skeleton: joint '", name,
                                                     "' has no counterpart '", *other, "'"));
    }
    map.counterpart[j] = *k;
  }
  double scale = 0;
  for (int j = 0; j < n; ++j) scale = std::max(scale, Norm(skeleton.joint(j).offset));
  for (const Motion* m : samples) {
    if (!m->skeleton.SameTopology(skeleton))
      return absl::InvalidArgumentError("cannot mirror: a sample motion is on another skeleton");
  }

  const std::vector<LocalPose> poses = SamplePoses(samples);
  map.flip.assign(n, Vec3{0, 0, 0});
  for (int j = 0; j < n; ++j) {
    if (map.flip[j].x != 0) continue;  // Planned with its counterpart.
    const int k = map.counterpart[j];
    const Joint& joint = skeleton.joint(j);
    const Joint& twin = skeleton.joint(k);
    const int p = joint.parent;
    if ((p < 0) != (twin.parent < 0) || (p >= 0 && map.counterpart[p] != twin.parent) ||
        skeleton.children(j).size() != skeleton.children(k).size() ||
        joint.end_sites.size() != twin.end_sites.size()) {
      return absl::InvalidArgumentError(absl::StrCat("cannot mirror the skeleton: joints '",
                                                     joint.name, "' and '", twin.name,
                                                     "' do not sit alike in the hierarchy"));
    }
    const Vec3 parent_flip = p < 0 ? kWorldFlip : map.flip[p];
    // B(j) must carry each of k's child offsets onto j's matching child's
    // (children placed by their position channels aside).
    std::vector<std::pair<Vec3, Vec3>> pairs;  // (own offset, counterpart's offset)
    for (int c : skeleton.children(j)) {
      const int twin_child = map.counterpart[c];
      const Vec3& own = skeleton.joint(c).offset;
      const Vec3& theirs = skeleton.joint(twin_child).offset;
      const double tol = kOffsetTolerance * std::max(Norm(own), Norm(theirs)) + 1e-6 * scale;
      if (Animated(poses, skeleton, c, tol) || Animated(poses, skeleton, twin_child, tol)) continue;
      pairs.push_back({own, theirs});
    }
    for (size_t e = 0; e < joint.end_sites.size(); ++e)
      pairs.push_back({joint.end_sites[e], twin.end_sites[e]});
    std::vector<Vec3> feasible;
    for (const Vec3& b : kCandidates) {
      bool ok = true;
      for (const auto& [own, theirs] : pairs) {
        const double tol = kOffsetTolerance * std::max(Norm(own), Norm(theirs)) + 1e-6 * scale;
        ok = ok && Norm(Scale(b, theirs) - own) <= tol;
      }
      if (ok) feasible.push_back(b);
    }
    if (feasible.empty()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "cannot mirror the skeleton: it is not left-right symmetric at joint '", joint.name,
          "' (the offsets below '", twin.name, "' do not mirror onto its own)"));
    }
    // Several fit: the parent's reflection if it is one of them (then a
    // local rotation is mirrored by conjugation, B R B, and a joint at rest
    // stays at rest); else the one whose mirrored rotations look most like
    // the counterpart's own on the samples; else the first.
    Vec3 best = feasible[0];
    const bool parents = std::any_of(feasible.begin(), feasible.end(),
                                     [&](const Vec3& b) { return SameSigns(b, parent_flip); });
    if (parents) {
      best = parent_flip;
    } else if (feasible.size() > 1 && !poses.empty() && skeleton.has_rotation(j)) {
      double best_cost = 1e9;
      auto same = [](const Quat& q) { return q; };
      const Quat own_mean = MeanRotation(poses, j, same);
      const Quat twin_mean = MeanRotation(poses, k, same);
      for (const Vec3& b : feasible) {
        auto mirrored = [&](const Quat& q) { return Reflect(parent_flip, q, b); };
        double cost = AngleBetween(MeanRotation(poses, j, mirrored), twin_mean);
        if (k != j) cost += AngleBetween(MeanRotation(poses, k, mirrored), own_mean);
        if (cost < best_cost - 1e-9) best_cost = cost, best = b;
      }
    }
    map.flip[j] = map.flip[k] = best;
  }
  return map;
}

Motion MirrorMotion(const Motion& motion, const MirrorMap& map) {
  Motion out = motion;
  const int n = motion.skeleton.num_joints();
  std::vector<Vec3> previous_euler(n, Vec3{0, 0, 0});
  for (int f = 0; f < motion.num_frames; ++f) {
    const LocalPose pose = PoseAt(motion, f);
    LocalPose mirrored = pose;
    for (int j = 0; j < n; ++j) {
      const int p = motion.skeleton.joint(j).parent;
      const Vec3 parent_flip = p < 0 ? kWorldFlip : map.flip[p];
      const int k = map.counterpart[j];
      mirrored.rotations[k] = Reflect(parent_flip, pose.rotations[j], map.flip[j]);
      mirrored.translations[k] = Scale(parent_flip, pose.translations[j]);
    }
    SetPose(&out, f, mirrored, &previous_euler);
  }
  return out;
}

double MaxMirrorError(const Motion& original, const Motion& mirrored, const MirrorMap& map) {
  const auto before = GlobalPositions(original), after = GlobalPositions(mirrored);
  double worst = 0;
  for (size_t f = 0; f < before.size() && f < after.size(); ++f)
    for (size_t j = 0; j < before[f].size(); ++j)
      worst = std::max(worst, Norm(Scale(kWorldFlip, before[f][j]) - after[f][map.counterpart[j]]));
  return worst;
}

std::string MirrorLabel(const std::string& label) {
  return absl::StrReplaceAll(label, {{"left", "right"}, {"right", "left"}});
}

}  // namespace stylus::motion
