// bvh-info, bvh-roundtrip, bvh-mirror and features.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "motion/bvh.h"
#include "motion/features.h"
#include "motion/humanoid.h"
#include "motion/kinematics.h"
#include "motion/mirror.h"
#include "motion/splice.h"
#include "tool/cli_support.h"

namespace stylus::tool {

using motion::Motion;

int BvhInfo(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool bvh-info FILE\n\n"
      "Prints the joints (parent, offset, channels), frame count, frame rate and\n"
      "duration of a BVH file. Exits 1 with file:line: reason on malformed input.\n";
  int code = 0;
  auto args = ParseOrExit("bvh-info", argv, {}, kHelp, &code);
  if (!args) return code;
  if (args->positional.size() != 1) {
    std::fprintf(stderr, "stylus-tool bvh-info: expected one FILE\n\n%s", kHelp);
    return 2;
  }
  absl::StatusOr<Motion> m = motion::ReadBvhFile(args->positional[0]);
  if (!m.ok()) return Fail("bvh-info", m.status());
  const motion::Skeleton& sk = m->skeleton;
  absl::PrintF("file: %s\n", args->positional[0]);
  absl::PrintF("joints: %d (root '%s')\n", sk.num_joints(), sk.joint(0).name);
  absl::PrintF("channels: %d per frame\n", sk.num_channels());
  absl::PrintF("frames: %d\n", m->num_frames);
  absl::PrintF("frame_time: %g s (%.3f fps)\n", m->frame_time, m->fps());
  absl::PrintF("duration: %.3f s\n", m->num_frames * m->frame_time);
  absl::PrintF("%-4s %-20s %-20s %-30s %s\n", "#", "joint", "parent", "offset", "channels");
  for (int j = 0; j < sk.num_joints(); ++j) {
    const motion::Joint& joint = sk.joint(j);
    std::string channels;
    for (motion::Channel c : joint.channels)
      absl::StrAppend(&channels, channels.empty() ? "" : " ", motion::ChannelName(c));
    if (sk.has_rotation(j))
      absl::StrAppend(&channels, "  (order ", sk.rotation_order(j).Name(), ")");
    absl::PrintF("%-4d %-20s %-20s %-30s %s\n", j, joint.name,
                 joint.parent < 0 ? "-" : sk.joint(joint.parent).name,
                 absl::StrFormat("%g %g %g", joint.offset.x, joint.offset.y, joint.offset.z),
                 channels);
  }
  return 0;
}

int BvhRoundtrip(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool bvh-roundtrip IN OUT\n\n"
      "Reads IN, writes it to OUT, reads OUT back and compares forward-kinematics\n"
      "joint positions of every frame. The last line is max_fk_error=<value> (in the\n"
      "file's units). Exits 1 when a file cannot be read or written.\n";
  int code = 0;
  auto args = ParseOrExit("bvh-roundtrip", argv, {}, kHelp, &code);
  if (!args) return code;
  if (args->positional.size() != 2) {
    std::fprintf(stderr, "stylus-tool bvh-roundtrip: expected IN and OUT\n\n%s", kHelp);
    return 2;
  }
  absl::StatusOr<Motion> in = motion::ReadBvhFile(args->positional[0]);
  if (!in.ok()) return Fail("bvh-roundtrip", in.status());
  if (absl::Status s = motion::WriteBvhFile(*in, args->positional[1]); !s.ok()) {
    return Fail("bvh-roundtrip", s);
  }
  absl::StatusOr<Motion> back = motion::ReadBvhFile(args->positional[1]);
  if (!back.ok()) return Fail("bvh-roundtrip", back.status());
  if (!in->skeleton.SameTopology(back->skeleton) || in->num_frames != back->num_frames) {
    return Fail("bvh-roundtrip",
                absl::InternalError("re-read file has another skeleton or frame count"));
  }
  absl::PrintF("frames=%d joints=%d\n", in->num_frames, in->skeleton.num_joints());
  absl::PrintF("max_fk_error=%g\n", motion::MaxPositionDifference(*in, *back));
  return 0;
}

int BvhMirror(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool bvh-mirror IN OUT\n\n"
      "Writes IN mirrored left to right on its own skeleton (docs/motion.md,\n"
      "\"Mirroring\"): the world reflected across x = 0, each joint moving as its\n"
      "counterpart (Hand_L <-> Hand_R) did, so a raise of the left hand becomes a\n"
      "raise of the right. Prints the largest distance between a mirrored joint\n"
      "and the mirror image of its counterpart (max_mirror_error=..., in the\n"
      "file's units). Exits 1 when a file cannot be read or written, or when the\n"
      "skeleton has no left-right symmetry (the message names the joint).\n";
  int code = 0;
  auto args = ParseOrExit("bvh-mirror", argv, {}, kHelp, &code);
  if (!args) return code;
  if (args->positional.size() != 2) {
    std::fprintf(stderr, "stylus-tool bvh-mirror: expected IN and OUT\n\n%s", kHelp);
    return 2;
  }
  absl::StatusOr<Motion> in = motion::ReadBvhFile(args->positional[0]);
  if (!in.ok()) return Fail("bvh-mirror", in.status());
  absl::StatusOr<motion::MirrorMap> map = motion::PlanMirror(in->skeleton, {&*in});
  if (!map.ok()) {
    return Fail("bvh-mirror",
                absl::Status(map.status().code(),
                             absl::StrCat(args->positional[0], ": ", map.status().message())));
  }
  const Motion out = motion::MirrorMotion(*in, *map);
  if (absl::Status s = motion::WriteBvhFile(out, args->positional[1]); !s.ok()) {
    return Fail("bvh-mirror", s);
  }
  absl::PrintF("frames=%d joints=%d\n", in->num_frames, in->skeleton.num_joints());
  absl::PrintF("max_mirror_error=%g\n", motion::MaxMirrorError(*in, out, *map));
  return 0;
}

int BvhSplice(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool bvh-splice BASE DONOR --part legs|torso|left-arm|right-arm...\n"
      "         -o OUT.bvh\n\n"
      "Writes BASE with the named body parts taken from DONOR, frame by frame\n"
      "(DONOR's first frames; it needs at least as many as BASE): the legs of one\n"
      "take under the upper body of another. Parts are found by the skeleton's\n"
      "humanoid roles: the legs from the hips down, an arm from its clavicle, the\n"
      "torso from the spine to the head; the pelvis and root stay BASE's, so the\n"
      "path does. Both clips must share a skeleton layout. --part may repeat.\n";
  int code = 0;
  auto args = ParseOrExit("bvh-splice", argv, {{"part", "out"}, {}}, kHelp, &code);
  if (!args) return code;
  if (args->positional.size() != 2 || args->All("part").empty() || args->Get("out").empty()) {
    std::fprintf(stderr, "stylus-tool bvh-splice: expected BASE, DONOR, --part and -o\n\n%s",
                 kHelp);
    return 2;
  }
  const std::string &base_path = args->positional[0], &donor_path = args->positional[1];
  absl::StatusOr<Motion> base = motion::ReadBvhFile(base_path);
  if (!base.ok()) return Fail("bvh-splice", base.status());
  absl::StatusOr<Motion> donor = motion::ReadBvhFile(donor_path);
  if (!donor.ok()) return Fail("bvh-splice", donor.status());
  absl::StatusOr<motion::HumanoidRoles> roles = motion::FindHumanoidRoles(base->skeleton);
  if (!roles.ok()) {
    return Fail("bvh-splice", absl::InvalidArgumentError(
                                  absl::StrCat(base_path, ": ", roles.status().message())));
  }
  std::vector<int> joints;
  for (const std::string& name : args->All("part")) {
    absl::StatusOr<motion::BodyPart> part = motion::ParseBodyPart(name);
    if (!part.ok()) return Fail("bvh-splice", part.status());
    for (int j : motion::BodyPartJoints(base->skeleton, *roles, *part)) joints.push_back(j);
  }
  absl::StatusOr<Motion> out = motion::SpliceJoints(*base, *donor, joints, base_path, donor_path);
  if (!out.ok()) return Fail("bvh-splice", out.status());
  if (absl::Status s = motion::WriteBvhFile(*out, args->Get("out")); !s.ok()) {
    return Fail("bvh-splice", s);
  }
  absl::PrintF("wrote %s: %d frames, %zu joints from %s\n", args->Get("out"), out->num_frames,
               joints.size(), donor_path);
  return 0;
}

int Features(const Argv& argv) {
  static const char kHelp[] =
      "usage: stylus-tool features FILE [-o RECONSTRUCTED.bvh]\n\n"
      "Extracts per-frame features (docs/motion.md) from a humanoid BVH clip and\n"
      "prints a summary: root speed, turning, pelvis height, foot contacts. Then\n"
      "rebuilds the motion from the features alone and reports the largest joint\n"
      "position error against the input (max_reconstruction_error=...). With -o,\n"
      "writes the rebuilt motion as BVH.\n";
  int code = 0;
  auto args = ParseOrExit("features", argv, {{"out"}, {}}, kHelp, &code);
  if (!args) return code;
  if (args->positional.size() != 1) {
    std::fprintf(stderr, "stylus-tool features: expected one FILE\n\n%s", kHelp);
    return 2;
  }
  absl::StatusOr<Motion> m = motion::ReadBvhFile(args->positional[0]);
  if (!m.ok()) return Fail("features", m.status());
  absl::StatusOr<motion::HumanoidRoles> roles = motion::FindHumanoidRoles(m->skeleton);
  if (!roles.ok()) return Fail("features", roles.status());
  absl::StatusOr<motion::FeatureClip> f = motion::ExtractFeatures(*m, *roles);
  if (!f.ok()) return Fail("features", f.status());
  const motion::FeatureLayout layout(m->skeleton.num_joints());
  double speed = 0, turn = 0, height = 0;
  double contact[4] = {0, 0, 0, 0};
  for (int t = 0; t < f->frames; ++t) {
    const float* r = f->row(t);
    speed += std::hypot(r[layout.trajectory()], r[layout.trajectory() + 1]);
    turn += std::fabs(r[layout.trajectory() + 2]);
    height += r[layout.position(roles->pelvis) + 1];
    for (int k = 0; k < 4; ++k) contact[k] += r[layout.contacts() + k];
  }
  const double n = f->frames;
  absl::PrintF(
      "file: %s\nframes: %d  feature channels: %d (7 x %d joints + 4 trajectory + 4 contacts)\n",
      args->positional[0], f->frames, f->dim, m->skeleton.num_joints());
  absl::PrintF("root speed: %.1f units/s   turning: %.1f deg/s   pelvis height: %.1f units\n",
               speed / n, turn / n * motion::kRadToDeg, height / n);
  const auto feet = motion::FootJoints(*roles);
  for (int k = 0; k < 4; ++k) {
    absl::PrintF("contact %-12s %5.1f%% of frames\n", m->skeleton.joint(feet[k]).name,
                 100 * contact[k] / n);
  }
  absl::StatusOr<Motion> rebuilt = motion::MotionFromFeatures(
      *f, m->skeleton, *roles, m->frame_time, motion::RootAt(*m, *roles, 0));
  if (!rebuilt.ok()) return Fail("features", rebuilt.status());
  if (args->Has("out")) {
    if (absl::Status s = motion::WriteBvhFile(*rebuilt, args->Get("out")); !s.ok())
      return Fail("features", s);
    absl::PrintF("wrote %s\n", args->Get("out"));
  }
  absl::PrintF("max_reconstruction_error=%g\n", motion::MaxPositionDifference(*m, *rebuilt));
  return 0;
}

}  // namespace stylus::tool
