#include "motion/postprocess.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "absl/strings/str_cat.h"
#include "motion/contacts.h"
#include "motion/ik.h"
#include "motion/kinematics.h"

namespace stylus::motion {
namespace {

struct Leg {
  int hip, knee, ankle, toe;
  int ankle_k, toe_k;  // Indices in FootJoints order.
};

absl::StatusOr<std::array<Leg, 2>> Legs(const Skeleton& sk, const HumanoidRoles& roles) {
  std::array<Leg, 2> legs;
  const int hips[2] = {roles.left_hip, roles.right_hip};
  const int ankles[2] = {roles.left_ankle, roles.right_ankle};
  const int toes[2] = {roles.left_toe, roles.right_toe};
  for (int s = 0; s < 2; ++s) {
    const int knee = sk.joint(ankles[s]).parent;
    if (knee < 0 || sk.joint(knee).parent != hips[s] || sk.joint(toes[s]).parent != ankles[s]) {
      return absl::InvalidArgumentError(
          absl::StrCat("leg of '", sk.joint(ankles[s]).name,
                       "' is not a hip -> knee -> ankle -> toe chain; foot locking needs one"));
    }
    legs[s] = {hips[s], knee, ankles[s], toes[s], 2 * s, 2 * s + 1};
  }
  return legs;
}

Vec3 Lerp(const Vec3& a, const Vec3& b, double t) { return a + (b - a) * t; }

// Joints strictly below the pelvis: their translations are bones.
std::vector<bool> BelowPelvis(const Skeleton& sk, const HumanoidRoles& roles) {
  std::vector<bool> below(sk.num_joints(), false);
  for (int j = 0; j < sk.num_joints(); ++j) {
    const int p = sk.joint(j).parent;
    below[j] = p >= 0 && (p == roles.pelvis || below[p]);
  }
  return below;
}

// The Euler angles frame `f` holds, one triple per joint in its axis order.
std::vector<Vec3> EulerAt(const Motion& motion, int f) {
  const Skeleton& sk = motion.skeleton;
  std::vector<Vec3> out(sk.num_joints());
  for (int j = 0; j < sk.num_joints(); ++j) {
    const Joint& joint = sk.joint(j);
    int k = 0;
    for (size_t c = 0; c < joint.channels.size(); ++c) {
      if (!IsPosition(joint.channels[c])) out[j][k++] = motion.frame(f)[sk.channel_start(j) + c];
    }
  }
  return out;
}

}  // namespace

absl::StatusOr<PostProcessMode> ParsePostProcessMode(absl::string_view name) {
  if (name == "none") return PostProcessMode::kNone;
  if (name == "feet") return PostProcessMode::kFeet;
  if (name == "full") return PostProcessMode::kFull;
  return absl::InvalidArgumentError(
      absl::StrCat("post-processing '", name, "' is not one of none, feet, full"));
}

const char* PostProcessModeName(PostProcessMode mode) {
  switch (mode) {
    case PostProcessMode::kNone:
      return "none";
    case PostProcessMode::kFeet:
      return "feet";
    case PostProcessMode::kFull:
      return "full";
  }
  return "?";
}

std::array<std::vector<ContactSpan>, 4> DetectContactSpans(absl::Span<const std::vector<Vec3>> pos,
                                                           const HumanoidRoles& roles, double fps,
                                                           const ContactSpanParams& params) {
  std::array<std::vector<ContactSpan>, 4> spans;
  const int n = static_cast<int>(pos.size());
  const std::array<int, 4> feet = FootJoints(roles);
  const double leg = roles.leg_length;
  const int min_span = std::max(2, static_cast<int>(std::lround(params.min_span_s * fps)));
  for (int k = 0; k < 4; ++k) {
    const int j = feet[k];
    double floor = 1e300;
    for (int f = 0; f < n; ++f) floor = std::min(floor, pos[f][j].y);
    bool in = false;
    int begin = 0;
    for (int f = 0; f <= n; ++f) {
      bool low_on = false, low_off = false;
      if (f < n) {
        const int a = std::max(0, f - 1), b = std::min(n - 1, f + 1);
        double speed = 0;
        if (b > a) {
          const Vec3 d = pos[b][j] - pos[a][j];
          speed = std::hypot(d.x, d.z) * fps / (b - a);
        }
        const double h = pos[f][j].y - floor;
        low_on = h <= params.height_on * leg && speed <= params.speed_on * leg;
        low_off = h <= params.height_off * leg && speed <= params.speed_off * leg;
      }
      if (!in && low_on) {
        in = true;
        begin = f;
      } else if (in && !low_off) {
        in = false;
        if (f - begin >= min_span) spans[k].push_back({begin, f});
      }
    }
  }
  return spans;
}

void RestoreBoneLengths(Motion* motion, const HumanoidRoles& roles) {
  const Skeleton& sk = motion->skeleton;
  const std::vector<bool> below = BelowPelvis(sk, roles);
  for (int f = 0; f < motion->num_frames; ++f) {
    for (int j = 0; j < sk.num_joints(); ++j) {
      if (!below[j]) continue;
      const Joint& joint = sk.joint(j);
      for (size_t c = 0; c < joint.channels.size(); ++c) {
        if (IsPosition(joint.channels[c])) {
          motion->frame(f)[sk.channel_start(j) + c] = joint.offset[ChannelAxis(joint.channels[c])];
        }
      }
    }
  }
}

void SmoothPoses(const Skeleton& sk, std::vector<LocalPose>* poses_in, int radius, int first) {
  std::vector<LocalPose>& poses = *poses_in;
  const int n = static_cast<int>(poses.size());
  if (radius <= 0 || n < 2) return;
  std::vector<Quat> q(n), smoothed_rotations(n);
  for (int j = 1; j < sk.num_joints(); ++j) {
    // The root's rotation is kept as it is (it carries the path's facing).
    // Its children are smoothed in the root's parent frame (the world): a
    // generated root may wobble while its child turns the other way, and
    // smoothing only the child would put the root's wobble into the body.
    const bool under_root = sk.joint(j).parent == 0;
    auto rotation = [&](int f) {
      return under_root ? poses[f].rotations[0] * poses[f].rotations[j] : poses[f].rotations[j];
    };
    for (int f = 0; f < n; ++f) {
      q[f] = f == 0 ? rotation(f) : SameHemisphere(rotation(f), q[f - 1]);
    }
    for (int f = std::max(0, first); f < n; ++f) {
      Quat sum{0, 0, 0, 0};
      for (int d = -radius; d <= radius; ++d) {
        const int i = std::clamp(f + d, 0, n - 1);
        const double w = radius + 1 - std::abs(d);
        const Quat a = SameHemisphere(q[i], q[f]);
        sum = {sum.w + w * a.w, sum.x + w * a.x, sum.y + w * a.y, sum.z + w * a.z};
      }
      const Quat smoothed = Normalized(sum);
      smoothed_rotations[f] =
          under_root ? Normalized(Conjugate(poses[f].rotations[0]) * smoothed) : smoothed;
    }
    for (int f = std::max(0, first); f < n; ++f) poses[f].rotations[j] = smoothed_rotations[f];
  }
}

void SmoothRotations(Motion* motion, int radius) {
  const int n = motion->num_frames;
  if (radius <= 0 || n < 2) return;
  std::vector<LocalPose> poses(n);
  for (int f = 0; f < n; ++f) poses[f] = PoseAt(*motion, f);
  SmoothPoses(motion->skeleton, &poses, radius);
  std::vector<Vec3> prev = EulerAt(*motion, 0);
  for (int f = 0; f < n; ++f) SetPose(motion, f, poses[f], &prev);
}

void MakeEulerContinuous(Motion* motion) {
  if (motion->num_frames == 0) return;
  // The first frame's angles stay as they are: continuity starts there.
  std::vector<Vec3> prev = EulerAt(*motion, 0);
  for (int f = 1; f < motion->num_frames; ++f) SetPose(motion, f, PoseAt(*motion, f), &prev);
}

absl::StatusOr<std::vector<LocalPose>> PostProcessPoses(
    const Skeleton& sk, const HumanoidRoles& roles, std::vector<LocalPose> source,
    absl::Span<const std::vector<Vec3>> content_pos, double fps, PostProcessMode mode,
    const PostProcessParams& params, int first_kept, ContactPins* pins,
    std::vector<GlobalPose>* posed) {
  const int n = static_cast<int>(source.size());
  first_kept = std::clamp(first_kept, 0, n);
  if (posed != nullptr && static_cast<int>(posed->size()) != first_kept) {
    return absl::InvalidArgumentError(
        absl::StrCat("post-processing: ", posed->size(), " posed history frames for ",
                     first_kept, " frames before the first kept"));
  }
  if (mode == PostProcessMode::kNone || n == 0) {
    if (pins != nullptr) pins->fill(std::nullopt);
    source.erase(source.begin(), source.begin() + first_kept);
    return source;
  }
  absl::StatusOr<std::array<Leg, 2>> legs = Legs(sk, roles);
  if (!legs.ok()) return legs.status();
  const std::array<std::vector<ContactSpan>, 4> spans =
      params.contact_spans != nullptr
          ? *params.contact_spans
          : DetectContactSpans(content_pos, roles, fps, params.contacts);
  const int known = posed != nullptr ? first_kept : 0;  // Final frames, posed before.
  if (mode == PostProcessMode::kFull) SmoothPoses(sk, &source, params.smooth_radius, known);
  // The output's world pose per frame: the pins and the knees' hinges read it.
  std::vector<GlobalPose> out_pose(n);
  for (int f = 0; f < n; ++f) {
    out_pose[f] = f < known ? std::move((*posed)[f]) : ForwardKinematics(sk, source[f]);
  }
  const std::array<int, 4> feet = FootJoints(roles);
  const int blend = std::max(1, static_cast<int>(std::lround(params.blend_s * fps)));

  // Per foot joint and frame: lock weight and pinned position.
  std::array<std::vector<double>, 4> weight;
  std::array<std::vector<Vec3>, 4> target;
  for (int k = 0; k < 4; ++k) {
    weight[k].assign(n, 0.0);
    target[k].assign(n, Vec3{});
    const int j = feet[k];
    std::optional<ContactPin> latest;
    for (const ContactSpan& s : spans[k]) {
      if (s.begin >= n) continue;
      const int last = std::min(s.end, n);
      Vec3 pin;
      const std::optional<ContactPin>& known = pins != nullptr ? (*pins)[k] : std::nullopt;
      if (known && s.begin <= known->frame && known->frame < s.end) {
        pin = known->pin;  // A contact seen before: its pin stays.
      } else if (params.pin_at_span_start) {
        pin = out_pose[s.begin].positions[j];
      } else {
        for (int f = s.begin; f < last; ++f) pin = pin + out_pose[f].positions[j];
        pin = pin * (1.0 / (last - s.begin));
      }
      for (int f = std::max(0, s.begin - blend); f < std::min(n, s.end + blend); ++f) {
        const int dist = f < s.begin ? s.begin - f : (f >= s.end ? f - s.end + 1 : 0);
        // Smoothstep ramp: no corner where the lock starts or ends, so the
        // blend adds no jerk spike.
        const double t = 1.0 - static_cast<double>(dist) / (blend + 1);
        const double w = t * t * (3 - 2 * t);
        if (w > weight[k][f]) {
          weight[k][f] = w;
          // Held in place over the floor, at the height the content's foot
          // has at that moment: a planted foot still rolls (heel down, heel
          // off), and pressing it flat would make the knee take up the roll.
          target[k][f] = {pin.x, content_pos[f][j].y, pin.z};
        }
      }
      latest = ContactPin{last - 1, pin};
    }
    if (pins != nullptr) (*pins)[k] = latest;
  }

  // Each knee's hinge in its thigh's frame, the same for the whole clip (a
  // per-frame hinge from positions is noise when the leg is nearly
  // straight): the mean over frames of the bend plane's normal, which
  // weighs each frame by how bent its knee is.
  std::array<std::optional<Vec3>, 2> hinge;
  std::array<double, 2> leg_length{};
  std::array<Vec3, 2> bend_sum;
  for (const GlobalPose& g : out_pose) {
    for (int side = 0; side < 2; ++side) {
      const Leg& leg = (*legs)[side];
      const Vec3 hip = g.positions[leg.hip], knee = g.positions[leg.knee],
                 ankle = g.positions[leg.ankle];
      bend_sum[side] =
          bend_sum[side] + Rotate(Conjugate(g.rotations[leg.hip]), Cross(knee - hip, ankle - knee));
      leg_length[side] += (Norm(knee - hip) + Norm(ankle - knee)) / n;
    }
  }
  for (int side = 0; side < 2; ++side) {
    // A leg straight in every frame has none: each frame's own is used.
    if (Norm(bend_sum[side]) > 1e-9) hinge[side] = Normalized(bend_sum[side], {1, 0, 0});
  }

  std::vector<LocalPose> result;
  result.reserve(n - first_kept);
  const std::vector<bool> below = BelowPelvis(sk, roles);
  for (int f = first_kept; f < n; ++f) {
    LocalPose local = std::move(source[f]);
    if (mode == PostProcessMode::kFull) {
      for (int j = 0; j < sk.num_joints(); ++j) {
        if (below[j] && HasPositionChannel(sk.joint(j))) local.translations[j] = sk.joint(j).offset;
      }
    }
    GlobalPose g = ForwardKinematics(sk, local);
    for (int side = 0; side < 2; ++side) {
      const Leg& leg = (*legs)[side];
      const double wa = weight[leg.ankle_k][f], wt = weight[leg.toe_k][f];
      if (wa <= 0 && wt <= 0) continue;
      Vec3 ankle = g.positions[leg.ankle];
      const Vec3 toe_offset = g.positions[leg.toe] - ankle;
      if (wa > 0) {
        const Vec3 want = Lerp(ankle, target[leg.ankle_k][f], wa);
        TwoBoneParams ik_params;
        if (hinge[side]) {
          ik_params.hinge = Rotate(g.rotations[leg.hip], *hinge[side]);
        } else {  // A straight leg bends towards the character's facing.
          ik_params.pole_hint = Normalized(
              Cross(g.positions[roles.left_hip] - g.positions[roles.right_hip], Vec3{0, 1, 0}),
              {0, 0, 1});
        }
        ik_params.soft = params.soft_reach * leg_length[side];
        const TwoBoneResult ik =
            SolveTwoBone(g.positions[leg.hip], g.positions[leg.knee], ankle, want, ik_params);
        g.rotations[leg.hip] = Normalized(ik.hip_delta * g.rotations[leg.hip]);
        g.rotations[leg.knee] = Normalized(ik.knee_delta * g.rotations[leg.knee]);
        ankle = ik.ankle;
      }
      if (wt > 0) {
        // Toes pinned too (heel-off): turn the ankle so the toe reaches its pin.
        const Vec3 toe = ankle + toe_offset;
        const Vec3 want = Lerp(toe, target[leg.toe_k][f], wt);
        // At most a small turn: a toe pin far from where the foot points is
        // the network's foot, not a reason to spin the ankle.
        Quat turn = RotationBetween(toe - ankle, want - ankle);
        const double angle = AngleBetween(Quat{}, turn), limit = 25 * M_PI / 180;
        if (angle > limit) turn = Slerp(Quat{}, turn, limit / angle);
        g.rotations[leg.ankle] = Normalized(turn * g.rotations[leg.ankle]);
      }
      const int hip_parent = sk.joint(leg.hip).parent;
      local.rotations[leg.hip] =
          Normalized(Conjugate(g.rotations[hip_parent]) * g.rotations[leg.hip]);
      local.rotations[leg.knee] =
          Normalized(Conjugate(g.rotations[leg.hip]) * g.rotations[leg.knee]);
      local.rotations[leg.ankle] =
          Normalized(Conjugate(g.rotations[leg.knee]) * g.rotations[leg.ankle]);
    }
    result.push_back(std::move(local));
  }
  if (posed != nullptr) *posed = std::move(out_pose);
  return result;
}

void PlaceAnkle(const Skeleton& sk, const GlobalPose& g, int ankle, const Vec3& target,
                LocalPose* pose) {
  const int knee = sk.joint(ankle).parent, hip = sk.joint(knee).parent;
  const TwoBoneResult ik =
      SolveTwoBone(g.positions[hip], g.positions[knee], g.positions[ankle], target);
  const Quat hip_world = Normalized(ik.hip_delta * g.rotations[hip]);
  const Quat knee_world = Normalized(ik.knee_delta * g.rotations[knee]);
  pose->rotations[hip] = Normalized(Conjugate(g.rotations[sk.joint(hip).parent]) * hip_world);
  pose->rotations[knee] = Normalized(Conjugate(hip_world) * knee_world);
  pose->rotations[ankle] = Normalized(Conjugate(knee_world) * g.rotations[ankle]);
}

void KeepFeetAboveFloor(const Skeleton& sk, const HumanoidRoles& roles, double floor,
                        LocalPose* pose) {
  GlobalPose g = ForwardKinematics(sk, *pose);
  for (int side = 0; side < 2; ++side) {
    const int ankle = side == 0 ? roles.left_ankle : roles.right_ankle;
    const int toe = side == 0 ? roles.left_toe : roles.right_toe;
    const double depth = floor - std::min(g.positions[ankle].y, g.positions[toe].y);
    if (depth <= 1e-9) continue;
    PlaceAnkle(sk, g, ankle, g.positions[ankle] + Vec3{0, depth, 0}, pose);
    g = ForwardKinematics(sk, *pose);
  }
}

absl::StatusOr<Motion> PostProcess(const Motion& output, const Motion& content,
                                   const HumanoidRoles& roles, PostProcessMode mode,
                                   const PostProcessParams& params) {
  if (mode == PostProcessMode::kNone) return output;
  const Skeleton& sk = output.skeleton;
  if (!sk.SameTopology(content.skeleton)) {
    return absl::InvalidArgumentError(
        absl::StrCat("post-processing: the content clip is on another skeleton: ",
                     sk.DescribeMismatch(content.skeleton)));
  }
  const int n = output.num_frames;
  std::vector<LocalPose> poses(n);
  for (int f = 0; f < n; ++f) poses[f] = PoseAt(output, f);
  const std::vector<std::vector<Vec3>> content_pos = GlobalPositions(content);
  absl::StatusOr<std::vector<LocalPose>> cleaned =
      PostProcessPoses(sk, roles, std::move(poses), content_pos, output.fps(), mode, params);
  if (!cleaned.ok()) return cleaned.status();
  double floor = 1e300;
  for (const std::vector<Vec3>& p : content_pos) {
    for (int j : FootJoints(roles)) floor = std::min(floor, p[j].y);
  }
  for (LocalPose& pose : *cleaned) KeepFeetAboveFloor(sk, roles, floor, &pose);
  if (n == 0) return output;
  Motion result = output;
  // Continuity starts from the output's own first frame (in a stream, the
  // last frame already sent).
  std::vector<Vec3> prev_euler = EulerAt(output, 0);
  for (int f = 0; f < n; ++f) SetPose(&result, f, (*cleaned)[f], &prev_euler);
  return result;
}

}  // namespace stylus::motion
