#include "motion/contacts.h"

#include <algorithm>
#include <cmath>

namespace stylus::motion {

std::array<int, 4> FootJoints(const HumanoidRoles& r) {
  return {r.left_ankle, r.left_toe, r.right_ankle, r.right_toe};
}

std::vector<std::array<bool, 4>> DetectFootContacts(const std::vector<std::vector<Vec3>>& pos,
                                                    const HumanoidRoles& roles, double fps,
                                                    const ContactParams& params) {
  const int n = static_cast<int>(pos.size());
  std::vector<std::array<bool, 4>> out(n, {false, false, false, false});
  const std::array<int, 4> feet = FootJoints(roles);
  const double max_height = params.height * roles.leg_length;
  const double max_speed = params.speed * roles.leg_length;
  for (int k = 0; k < 4; ++k) {
    const int j = feet[k];
    double ground = 1e300;
    if (!params.running_floor) {
      for (int f = 0; f < n; ++f) ground = std::min(ground, pos[f][j].y);
    }
    for (int f = 0; f < n; ++f) {
      if (params.running_floor) ground = std::min(ground, pos[f][j].y);
      // Central difference inside the clip, one-sided at its ends.
      const int a = std::max(0, f - 1), b = std::min(n - 1, f + 1);
      double speed = 0;
      if (b > a) {
        const Vec3 d = pos[b][j] - pos[a][j];
        speed = std::hypot(d.x, d.z) * fps / (b - a);
      }
      out[f][k] = pos[f][j].y - ground <= max_height && speed <= max_speed;
    }
  }
  return out;
}

}  // namespace stylus::motion
