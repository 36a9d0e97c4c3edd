#include "motion/kinematics.h"

#include <algorithm>

namespace stylus::motion {

GlobalPose ForwardKinematics(const Skeleton& skeleton, const LocalPose& pose) {
  const int n = skeleton.num_joints();
  GlobalPose g;
  g.positions.resize(n);
  g.rotations.resize(n);
  for (int j = 0; j < n; ++j) {
    const int p = skeleton.joint(j).parent;
    if (p < 0) {
      g.positions[j] = pose.translations[j];
      g.rotations[j] = pose.rotations[j];
    } else {
      g.positions[j] = g.positions[p] + Rotate(g.rotations[p], pose.translations[j]);
      g.rotations[j] = Normalized(g.rotations[p] * pose.rotations[j]);
    }
  }
  return g;
}

std::vector<std::vector<Vec3>> GlobalPositions(const Motion& motion) {
  std::vector<std::vector<Vec3>> out(motion.num_frames);
  for (int f = 0; f < motion.num_frames; ++f) {
    out[f] = ForwardKinematics(motion.skeleton, PoseAt(motion, f)).positions;
  }
  return out;
}

std::vector<std::vector<Vec3>> GlobalPositionsYUp(const Motion& motion, int up_axis) {
  std::vector<std::vector<Vec3>> out = GlobalPositions(motion);
  if (up_axis == 1) return out;
  for (std::vector<Vec3>& frame : out) {
    for (Vec3& p : frame) p = up_axis == 2 ? Vec3{p.x, p.z, -p.y} : Vec3{-p.y, p.x, p.z};
  }
  return out;
}

LocalPose LocalFromGlobal(const Skeleton& skeleton, const GlobalPose& global) {
  const int n = skeleton.num_joints();
  LocalPose l;
  l.translations.resize(n);
  l.rotations.resize(n);
  for (int j = 0; j < n; ++j) {
    const int p = skeleton.joint(j).parent;
    if (p < 0) {
      l.translations[j] = global.positions[j];
      l.rotations[j] = global.rotations[j];
    } else {
      const Quat inv = Conjugate(global.rotations[p]);
      l.translations[j] = Rotate(inv, global.positions[j] - global.positions[p]);
      l.rotations[j] = Normalized(inv * global.rotations[j]);
    }
  }
  return l;
}

double MaxPositionDifference(const Motion& a, const Motion& b) {
  double worst = 0;
  for (int f = 0; f < std::min(a.num_frames, b.num_frames); ++f) {
    const GlobalPose ga = ForwardKinematics(a.skeleton, PoseAt(a, f));
    const GlobalPose gb = ForwardKinematics(b.skeleton, PoseAt(b, f));
    for (size_t j = 0; j < ga.positions.size() && j < gb.positions.size(); ++j) {
      worst = std::max(worst, Norm(ga.positions[j] - gb.positions[j]));
    }
  }
  return worst;
}

}  // namespace stylus::motion
