#include "motion/motion.h"

namespace stylus::motion {

LocalPose PoseAt(const Motion& motion, int f) {
  const Skeleton& sk = motion.skeleton;
  const int n = sk.num_joints();
  LocalPose pose;
  pose.translations.resize(n);
  pose.rotations.resize(n);
  const double* row = motion.frame(f);
  for (int j = 0; j < n; ++j) {
    const Joint& joint = sk.joint(j);
    Vec3 t = joint.offset;
    Vec3 euler;
    int k = 0;
    const double* v = row + sk.channel_start(j);
    for (size_t c = 0; c < joint.channels.size(); ++c) {
      const Channel ch = joint.channels[c];
      if (IsPosition(ch)) {
        t[ChannelAxis(ch)] = v[c];
      } else {
        euler[k++] = v[c];
      }
    }
    pose.translations[j] = t;
    pose.rotations[j] = sk.has_rotation(j) ? EulerToQuat(euler, sk.rotation_order(j)) : Quat{};
  }
  return pose;
}

void SetPose(Motion* motion, int f, const LocalPose& pose, std::vector<Vec3>* previous_euler) {
  const Skeleton& sk = motion->skeleton;
  double* row = motion->frame(f);
  for (int j = 0; j < sk.num_joints(); ++j) {
    const Joint& joint = sk.joint(j);
    double* v = row + sk.channel_start(j);
    Vec3 euler;
    if (sk.has_rotation(j)) {
      euler = QuatToEulerNear(pose.rotations[j], sk.rotation_order(j), (*previous_euler)[j]);
      (*previous_euler)[j] = euler;
    }
    int k = 0;
    for (size_t c = 0; c < joint.channels.size(); ++c) {
      const Channel ch = joint.channels[c];
      v[c] = IsPosition(ch) ? pose.translations[j][ChannelAxis(ch)] : euler[k++];
    }
  }
}

Motion RestMotion(const Skeleton& skeleton, int num_frames, double frame_time) {
  Motion m;
  m.skeleton = skeleton;
  m.frame_time = frame_time;
  m.num_frames = num_frames;
  m.values.assign(static_cast<size_t>(num_frames) * skeleton.num_channels(), 0.0);
  LocalPose rest;
  for (const Joint& j : skeleton.joints()) {
    rest.translations.push_back(j.offset);
    rest.rotations.push_back(Quat{});
  }
  std::vector<Vec3> prev(skeleton.num_joints());
  for (int f = 0; f < num_frames; ++f) SetPose(&m, f, rest, &prev);
  return m;
}

}  // namespace stylus::motion
