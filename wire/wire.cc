#include "wire/wire.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace stylus::wire {
namespace {

using motion::Vec3;

v1::Vec3 ToProto(const Vec3& v) {
  v1::Vec3 out;
  out.set_x(v.x);
  out.set_y(v.y);
  out.set_z(v.z);
  return out;
}

Vec3 FromProto(const v1::Vec3& v) { return {v.x(), v.y(), v.z()}; }

bool Finite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

void SkeletonToProto(const motion::Skeleton& skeleton, v1::Skeleton* out) {
  out->Clear();
  for (const motion::Joint& j : skeleton.joints()) {
    v1::Joint* p = out->add_joints();
    p->set_name(j.name);
    p->set_parent(j.parent);
    *p->mutable_offset() = ToProto(j.offset);
    for (motion::Channel c : j.channels) p->add_channels(std::string(motion::ChannelName(c)));
    for (const Vec3& e : j.end_sites) *p->add_end_sites() = ToProto(e);
  }
}

absl::StatusOr<motion::Skeleton> SkeletonFromProto(const v1::Skeleton& skeleton,
                                                   const std::string& what) {
  if (skeleton.joints().empty()) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": the skeleton has no joints"));
  }
  std::vector<motion::Joint> joints;
  joints.reserve(skeleton.joints_size());
  for (int i = 0; i < skeleton.joints_size(); ++i) {
    const v1::Joint& p = skeleton.joints(i);
    motion::Joint j;
    j.name = p.name();
    j.parent = p.parent();
    j.offset = FromProto(p.offset());
    for (const std::string& c : p.channels()) {
      std::optional<motion::Channel> ch = motion::ParseChannel(c);
      if (!ch) {
        return absl::InvalidArgumentError(absl::StrCat(what, ": joint ", i, " ('", p.name(),
                                                       "') has an unknown channel '", c, "'"));
      }
      j.channels.push_back(*ch);
    }
    for (const v1::Vec3& e : p.end_sites()) j.end_sites.push_back(FromProto(e));
    joints.push_back(std::move(j));
  }
  absl::StatusOr<motion::Skeleton> s = motion::Skeleton::Create(std::move(joints));
  if (!s.ok()) return absl::InvalidArgumentError(absl::StrCat(what, ": ", s.status().message()));
  return s;
}

void FrameToProto(const motion::Motion& motion, int f, int64_t index, v1::Frame* out) {
  out->Clear();
  out->set_index(index);
  out->set_timestamp(f * motion.frame_time);
  const motion::LocalPose pose = motion::PoseAt(motion, f);
  *out->mutable_root_position() = ToProto(pose.translations[0]);
  for (int j = 0; j < motion.skeleton.num_joints(); ++j) {
    const motion::Quat& q = pose.rotations[j];
    v1::Quaternion* r = out->add_rotations();
    r->set_w(q.w);
    r->set_x(q.x);
    r->set_y(q.y);
    r->set_z(q.z);
    if (j > 0 && motion::HasPositionChannel(motion.skeleton.joint(j))) {
      *out->add_translations() = ToProto(pose.translations[j]);
    }
  }
}

void ClipToProto(const motion::Motion& motion, v1::Clip* out) {
  out->Clear();
  SkeletonToProto(motion.skeleton, out->mutable_skeleton());
  out->set_fps(motion.fps());
  for (int f = 0; f < motion.num_frames; ++f) FrameToProto(motion, f, f, out->add_frames());
}

absl::Status AppendFrame(const v1::Frame& frame, const std::string& what,
                         std::vector<Vec3>* prev_euler, motion::Motion* motion) {
  const motion::Skeleton& sk = motion->skeleton;
  const int nj = sk.num_joints();
  const std::string where = absl::StrCat(what, ": frame ", frame.index());
  if (frame.rotations_size() != nj) {
    return absl::InvalidArgumentError(absl::StrCat(where, " has ", frame.rotations_size(),
                                                   " rotations; the skeleton has ", nj, " joints"));
  }
  motion::LocalPose pose;
  pose.translations.resize(nj);
  pose.rotations.resize(nj);
  int next_translation = 0;
  for (int j = 0; j < nj; ++j) {
    const motion::Joint& joint = sk.joint(j);
    const v1::Quaternion& r = frame.rotations(j);
    const double norm = std::sqrt(r.w() * r.w() + r.x() * r.x() + r.y() * r.y() + r.z() * r.z());
    if (!std::isfinite(norm)) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, ", joint '", joint.name, "': rotation is not finite"));
    }
    if (norm < 1e-9) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, ", joint '", joint.name, "': rotation is a zero quaternion"));
    }
    pose.rotations[j] = {r.w() / norm, r.x() / norm, r.y() / norm, r.z() / norm};
    pose.translations[j] = joint.offset;
    if (j == 0) {
      pose.translations[j] = FromProto(frame.root_position());
    } else if (motion::HasPositionChannel(joint)) {
      if (next_translation >= frame.translations_size()) {
        return absl::InvalidArgumentError(absl::StrCat(
            where, ": no translation for joint '", joint.name, "', which has position channels"));
      }
      pose.translations[j] = FromProto(frame.translations(next_translation++));
    }
    if (!Finite(pose.translations[j])) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, ", joint '", joint.name, "': position is not finite"));
    }
  }
  if (next_translation != frame.translations_size()) {
    return absl::InvalidArgumentError(absl::StrCat(where, " has ", frame.translations_size(),
                                                   " translations; the skeleton needs ",
                                                   next_translation));
  }
  motion->values.resize(motion->values.size() + sk.num_channels());
  ++motion->num_frames;
  motion::SetPose(motion, motion->num_frames - 1, pose, prev_euler);
  return absl::OkStatus();
}

absl::Status CheckFinite(const motion::Motion& motion, const std::string& what) {
  const motion::Skeleton& sk = motion.skeleton;
  for (int f = 0; f < motion.num_frames; ++f) {
    for (int j = 0; j < sk.num_joints(); ++j) {
      const motion::Joint& joint = sk.joint(j);
      for (size_t c = 0; c < joint.channels.size(); ++c) {
        if (!std::isfinite(motion.frame(f)[sk.channel_start(j) + c])) {
          return absl::InvalidArgumentError(
              absl::StrCat(what, ": frame ", f, ", joint '", joint.name, "', channel ",
                           motion::ChannelName(joint.channels[c]), ": value is not finite"));
        }
      }
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<motion::Motion> ClipFromProto(const v1::Clip& clip, const std::string& what) {
  if (!(std::isfinite(clip.fps()) && clip.fps() > 0 && clip.fps() <= 10000)) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": fps must be a positive number, got ", clip.fps()));
  }
  absl::StatusOr<motion::Skeleton> sk = SkeletonFromProto(clip.skeleton(), what);
  if (!sk.ok()) return sk.status();
  motion::Motion m;
  m.skeleton = *std::move(sk);
  m.frame_time = 1.0 / clip.fps();
  // Counts before memory: the room for every frame is taken only once each
  // frame is known to hold a rotation per joint.
  for (const v1::Frame& f : clip.frames()) {
    if (f.rotations_size() != m.skeleton.num_joints()) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, ": frame ", f.index(), " has ", f.rotations_size(),
                       " rotations; the skeleton has ", m.skeleton.num_joints(), " joints"));
    }
  }
  m.values.reserve(static_cast<size_t>(clip.frames_size()) * m.skeleton.num_channels());
  std::vector<Vec3> prev(m.skeleton.num_joints());
  for (const v1::Frame& f : clip.frames()) {
    if (absl::Status s = AppendFrame(f, what, &prev, &m); !s.ok()) return s;
  }
  return m;
}

absl::StatusOr<motion::JointMap> JointMapFromProto(const v1::Skeleton& skeleton,
                                                   const std::string& what) {
  motion::JointMap map;
  for (const auto& [role_name, joint] : skeleton.joint_map()) {
    motion::Role role;
    if (!motion::ParseRole(role_name, &role)) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, ": joint_map: unknown role '", role_name,
                       "' (roles: pelvis, spine, chest, neck, head, left_/right_ clavicle, "
                       "upper_arm, forearm, hand, thigh, shin, foot, toe)"));
    }
    if (joint.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, ": joint_map: no joint name for role '", role_name, "'"));
    }
    map.emplace_back(role, joint);
  }
  return map;
}

void JointMapToProto(const motion::JointMap& map, v1::Skeleton* out) {
  for (const auto& [role, joint] : map) {
    (*out->mutable_joint_map())[std::string(motion::RoleName(role))] = joint;
  }
}

}  // namespace stylus::wire
