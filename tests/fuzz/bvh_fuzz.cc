// libFuzzer target: the BVH reader on arbitrary bytes. What parses must
// format and parse back to the same shape, and goes through the humanoid
// role finder and, when it is a humanoid, retargeting onto its own first
// pose and back (scripts/fuzz bvh SECONDS).
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "motion/bvh.h"
#include "motion/kinematics.h"
#include "motion/retarget.h"
#include "motion/rig_roles.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using stylus::motion::Motion;
  // Limits small enough that a header cannot ask for gigabytes.
  stylus::motion::BvhLimits limits;
  limits.max_joints = 512;
  limits.max_frames = 100000;
  const absl::string_view text(reinterpret_cast<const char*>(data), size);
  absl::StatusOr<Motion> motion = stylus::motion::ParseBvh(text, "fuzz", limits);
  if (!motion.ok()) return 0;
  absl::StatusOr<Motion> again =
      stylus::motion::ParseBvh(stylus::motion::FormatBvh(*motion), "formatted", limits);
  if (!again.ok() || again->num_frames != motion->num_frames ||
      again->skeleton.num_joints() != motion->skeleton.num_joints() ||
      again->values.size() != motion->values.size()) {
    std::abort();  // A clip the writer cannot round-trip.
  }
  if (motion->num_frames == 0 || motion->skeleton.num_joints() > 128) return 0;
  namespace m = stylus::motion;
  const m::LocalPose first = m::PoseAt(*motion, 0);
  (void)m::FindRigRoles(motion->skeleton, m::ForwardKinematics(motion->skeleton, first));
  (void)m::HumanoidRolesOf(*motion);
  absl::StatusOr<std::shared_ptr<const m::ModelRig>> rig =
      m::MakeModelRig(motion->skeleton, first.rotations);
  if (!rig.ok()) return 0;
  absl::StatusOr<std::unique_ptr<m::Retargeter>> r =
      m::Retargeter::Create(*rig, motion->skeleton, motion->frame(0));
  if (!r.ok()) return 0;
  std::vector<double> on_model(motion->skeleton.num_channels()), back(on_model.size());
  for (int f = 0; f < std::min(motion->num_frames, 4); ++f) {
    (*r)->ToModel(motion->frame(f), on_model.data());
    (*r)->FromModel(on_model.data(), motion->frame(f), back.data());
  }
  return 0;
}
