#include "motion/features.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "motion/kinematics.h"

namespace stylus::motion {
namespace {

double WrapAngle(double a) { return std::remainder(a, 2 * kPi); }

}  // namespace

// Forward = across x up.
double FacingYaw(const std::vector<Vec3>& p, const HumanoidRoles& r) {
  Vec3 across = (p[r.left_hip] - p[r.right_hip]) + (p[r.left_shoulder] - p[r.right_shoulder]);
  across.y = 0;
  const Vec3 forward = Cross(across, Vec3{0, 1, 0});
  return std::atan2(forward.x, forward.z);
}

namespace {

// Frame pose features into `row` (positions and rotations; the rotation
// signs continue from `prev_q`, or CanonicalSign when `first`); returns
// the global positions, with the root and facing yaw.
std::vector<Vec3> PoseRow(const Skeleton& sk, const HumanoidRoles& roles,
                          const std::vector<bool>& above, const LocalPose& local, bool first,
                          std::vector<Quat>* prev_q, Vec3* root, double* yaw, float* row) {
  const FeatureLayout layout(sk.num_joints());
  const GlobalPose g = ForwardKinematics(sk, local);
  *root = {g.positions[roles.pelvis].x, 0, g.positions[roles.pelvis].z};
  *yaw = FacingYaw(g.positions, roles);
  const Quat inv_yaw = Conjugate(YawRotation(*yaw));
  for (int j = 0; j < sk.num_joints(); ++j) {
    const Vec3 p = above[j] ? local.translations[j] : Rotate(inv_yaw, g.positions[j] - *root);
    Quat q = j == roles.pelvis ? inv_yaw * g.rotations[j] : local.rotations[j];
    q = first ? CanonicalSign(q) : SameHemisphere(q, (*prev_q)[j]);
    (*prev_q)[j] = q;
    for (int c = 0; c < 3; ++c) row[layout.position(j) + c] = static_cast<float>(p[c]);
    const double qv[4] = {q.w, q.x, q.y, q.z};
    for (int c = 0; c < 4; ++c) row[layout.rotation(j) + c] = static_cast<float>(qv[c]);
  }
  return g.positions;
}

// The root trajectory channels of a frame from the frames a and b after it.
void TrajectoryRow(const FeatureLayout& layout, const Vec3& root_a, double yaw_a,
                   const Vec3& root_b, double yaw_b, double pelvis_dy, double fps, float* row) {
  const Vec3 v = Rotate(Conjugate(YawRotation(yaw_a)), root_b - root_a) * fps;
  row[layout.trajectory() + 0] = static_cast<float>(v.x);
  row[layout.trajectory() + 1] = static_cast<float>(v.z);
  row[layout.trajectory() + 2] = static_cast<float>(WrapAngle(yaw_b - yaw_a) * fps);
  row[layout.trajectory() + 3] = static_cast<float>(pelvis_dy * fps);
}

}  // namespace

std::vector<bool> AbovePelvis(const Skeleton& sk, const HumanoidRoles& r) {
  std::vector<bool> above(sk.num_joints(), false);
  for (int j = sk.joint(r.pelvis).parent; j >= 0; j = sk.joint(j).parent) above[j] = true;
  return above;
}

FeatureStream::FeatureStream(const Skeleton& skeleton, const HumanoidRoles& roles,
                             double frame_time, ContactParams contacts)
    : skeleton_(skeleton),
      one_(RestMotion(skeleton, 1, frame_time)),
      roles_(roles),
      fps_(1.0 / frame_time),
      contacts_(contacts),
      layout_(skeleton.num_joints()),
      above_(AbovePelvis(skeleton, roles)),
      prev_q_(skeleton.num_joints()) {
  ground_.fill(1e300);
}

bool FeatureStream::Push(const double* frame, float* out) {
  std::copy(frame, frame + skeleton_.num_channels(), one_.values.begin());
  Frame next;
  next.row.assign(layout_.dim(), 0.f);
  next.positions = PoseRow(skeleton_, roles_, above_, PoseAt(one_, 0), frames_ == 0, &prev_q_,
                           &next.root, &next.yaw, next.row.data());
  const std::array<int, 4> feet = FootJoints(roles_);
  for (int k = 0; k < 4; ++k) {
    const double y = next.positions[feet[k]].y;
    ground_[k] = std::min(ground_[k], y);  // The running floor, always.
    next.low[k] = y - ground_[k] <= contacts_.height * roles_.leg_length;
  }
  ++frames_;
  bool wrote = false;
  if (has_waiting_) {
    Complete(&next, out);
    wrote = true;
    before_ = std::move(waiting_);
    has_before_ = true;
  }
  waiting_ = std::move(next);
  has_waiting_ = true;
  return wrote;
}

bool FeatureStream::Finish(float* out) {
  if (!has_waiting_) return false;
  Complete(nullptr, out);
  has_waiting_ = false;
  return true;
}

void FeatureStream::Complete(const Frame* after, float* out) {
  const Frame& f = waiting_;
  std::copy(f.row.begin(), f.row.end(), out);
  // Velocities: forward difference; the last frame repeats the one before.
  const Frame* a = after != nullptr ? &f : (has_before_ ? &before_ : nullptr);
  const Frame* b = after != nullptr ? after : (has_before_ ? &f : nullptr);
  if (a != nullptr) {
    TrajectoryRow(layout_, a->root, a->yaw, b->root, b->yaw,
                  b->positions[roles_.pelvis].y - a->positions[roles_.pelvis].y, fps_, out);
  }
  // Contacts: low (checked when the frame came) and still (central
  // difference, one-sided at the clip's ends).
  const Frame* s0 = has_before_ ? &before_ : &f;
  const Frame* s1 = after != nullptr ? after : &f;
  const int span = (has_before_ ? 1 : 0) + (after != nullptr ? 1 : 0);
  const std::array<int, 4> feet = FootJoints(roles_);
  for (int k = 0; k < 4; ++k) {
    double speed = 0;
    if (span > 0) {
      const Vec3 d = s1->positions[feet[k]] - s0->positions[feet[k]];
      speed = std::hypot(d.x, d.z) * fps_ / span;
    }
    out[layout_.contacts() + k] =
        f.low[k] && speed <= contacts_.speed * roles_.leg_length ? 1.f : 0.f;
  }
}

std::vector<std::string> FeatureLayout::ChannelNames(const Skeleton& sk,
                                                     const HumanoidRoles& roles) const {
  std::vector<std::string> names;
  for (int j = 0; j < num_joints; ++j) {
    for (const char* c : {".px", ".py", ".pz"}) names.push_back(sk.joint(j).name + c);
  }
  for (int j = 0; j < num_joints; ++j) {
    for (const char* c : {".qw", ".qx", ".qy", ".qz"}) names.push_back(sk.joint(j).name + c);
  }
  for (const char* c : {"root.vx", "root.vz", "root.yaw_rate", "root.vy"}) names.push_back(c);
  for (int j : FootJoints(roles)) names.push_back("contact." + sk.joint(j).name);
  return names;
}

RootStart RootAt(const Motion& motion, const HumanoidRoles& roles, int f) {
  const GlobalPose g = ForwardKinematics(motion.skeleton, PoseAt(motion, f));
  return {g.positions[roles.pelvis].x, g.positions[roles.pelvis].z, FacingYaw(g.positions, roles)};
}

std::vector<Quat> FeatureRotations(const FeatureClip& features, int f) {
  const FeatureLayout layout((features.dim - 8) / 7);
  std::vector<Quat> out(layout.num_joints);
  for (int j = 0; j < layout.num_joints; ++j) {
    const float* q = features.row(f) + layout.rotation(j);
    out[j] = {q[0], q[1], q[2], q[3]};
  }
  return out;
}

absl::StatusOr<FeatureClip> ExtractFeatures(const Motion& motion, const HumanoidRoles& roles,
                                            const ContactParams& contact_params,
                                            const std::vector<Quat>* sign_reference) {
  const Skeleton& sk = motion.skeleton;
  const int n = motion.num_frames, nj = sk.num_joints();
  if (n <= 0) return absl::InvalidArgumentError("cannot extract features from an empty motion");
  const FeatureLayout layout(nj);
  const std::vector<bool> above = AbovePelvis(sk, roles);
  FeatureClip out;
  out.frames = n;
  out.dim = layout.dim();
  out.values.assign(static_cast<size_t>(n) * out.dim, 0.f);

  std::vector<std::vector<Vec3>> positions(n);
  std::vector<Vec3> root(n);
  std::vector<double> yaw(n);
  std::vector<Quat> prev_q(nj);
  const bool referenced =
      sign_reference != nullptr && static_cast<int>(sign_reference->size()) == nj;
  if (referenced) prev_q = *sign_reference;
  for (int f = 0; f < n; ++f) {
    positions[f] = PoseRow(sk, roles, above, PoseAt(motion, f), f == 0 && !referenced, &prev_q,
                           &root[f], &yaw[f], out.row(f));
  }
  const double fps = motion.fps();
  for (int f = 0; f < n; ++f) {
    // Forward difference; the last frame repeats the one before it.
    const int a = (f + 1 < n) ? f : std::max(0, f - 1);
    const int b = std::min(n - 1, a + 1);
    if (b > a) {
      TrajectoryRow(layout, root[a], yaw[a], root[b], yaw[b],
                    positions[b][roles.pelvis].y - positions[a][roles.pelvis].y, fps, out.row(f));
    }
  }
  const auto contacts = DetectFootContacts(positions, roles, fps, contact_params);
  for (int f = 0; f < n; ++f) {
    for (int k = 0; k < 4; ++k) out.row(f)[layout.contacts() + k] = contacts[f][k] ? 1.f : 0.f;
  }
  return out;
}

absl::StatusOr<Motion> MotionFromFeatures(const FeatureClip& features, const Skeleton& sk,
                                          const HumanoidRoles& roles, double frame_time,
                                          const RootStart& start) {
  DecodeState state{start, {}, {}};
  return MotionFromFeatures(features, sk, roles, frame_time, &state);
}

absl::StatusOr<Motion> MotionFromFeatures(const FeatureClip& features, const Skeleton& sk,
                                          const HumanoidRoles& roles, double frame_time,
                                          DecodeState* state) {
  const int nj = sk.num_joints();
  const FeatureLayout layout(nj);
  if (features.dim != layout.dim()) {
    return absl::InvalidArgumentError(absl::StrCat("features have ", features.dim,
                                                   " channels; skeleton with ", nj,
                                                   " joints needs ", layout.dim()));
  }
  if (features.frames <= 0) return absl::InvalidArgumentError("features have no frames");
  if (!(frame_time > 0)) return absl::InvalidArgumentError("frame time must be positive");
  for (size_t i = 0; i < features.values.size(); ++i) {
    if (!std::isfinite(features.values[i])) {
      return absl::InvalidArgumentError(absl::StrCat("feature value at frame ", i / features.dim,
                                                     ", channel ", i % features.dim,
                                                     " is not finite"));
    }
  }
  const std::vector<bool> above = AbovePelvis(sk, roles);
  // Every channel is written below (SetPose).
  Motion m;
  m.skeleton = sk;
  m.frame_time = frame_time;
  m.num_frames = features.frames;
  m.values.assign(static_cast<size_t>(features.frames) * sk.num_channels(), 0.0);
  std::vector<Vec3>& prev_euler = state->prev_euler;
  prev_euler.resize(nj);
  double x = state->root.x, z = state->root.z, yaw = state->root.yaw;
  for (int f = 0; f < features.frames; ++f) {
    const float* row = features.row(f);
    const Quat yaw_q = YawRotation(yaw);
    LocalPose local;
    local.translations.resize(nj);
    local.rotations.resize(nj);
    for (int j = 0; j < nj; ++j) {
      const float* q = row + layout.rotation(j);
      const Quat raw{q[0], q[1], q[2], q[3]};
      const bool vague = std::sqrt(raw.w * raw.w + raw.x * raw.x + raw.y * raw.y + raw.z * raw.z) <
                         kMinRotationNorm;
      local.rotations[j] = vague && static_cast<int>(state->prev_rotations.size()) == nj
                               ? state->prev_rotations[j]
                               : Normalized(raw);
      local.translations[j] = sk.joint(j).offset;
      if (above[j]) {
        const float* p = row + layout.position(j);
        local.translations[j] = {p[0], p[1], p[2]};
      }
    }
    const std::vector<Quat> decoded = local.rotations;  // Before the pelvis is placed.
    // The pelvis is placed in the world, then expressed relative to its parent.
    GlobalPose g = ForwardKinematics(sk, local);
    const float* pp = row + layout.position(roles.pelvis);
    const Vec3 pelvis_world = Vec3{x, 0, z} + Rotate(yaw_q, Vec3{pp[0], pp[1], pp[2]});
    const Quat pelvis_rot = yaw_q * local.rotations[roles.pelvis];
    const int parent = sk.joint(roles.pelvis).parent;
    if (parent < 0) {
      local.translations[roles.pelvis] = pelvis_world;
      local.rotations[roles.pelvis] = pelvis_rot;
    } else {
      const Quat inv = Conjugate(g.rotations[parent]);
      local.translations[roles.pelvis] = Rotate(inv, pelvis_world - g.positions[parent]);
      local.rotations[roles.pelvis] = Normalized(inv * pelvis_rot);
    }
    SetPose(&m, f, local, &prev_euler);
    state->prev_rotations = decoded;
    const float* t = row + layout.trajectory();
    const Vec3 step = Rotate(yaw_q, Vec3{t[0], 0, t[1]}) * frame_time;
    x += step.x;
    z += step.z;
    yaw += t[2] * frame_time;
  }
  state->root = {x, z, yaw};
  return m;
}

}  // namespace stylus::motion
