#include "motion/synth.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "motion/kinematics.h"

namespace stylus::motion {
namespace {

const std::vector<Channel> kSixChannels = {Channel::kXposition, Channel::kYposition,
                                           Channel::kZposition, Channel::kZrotation,
                                           Channel::kXrotation, Channel::kYrotation};

Quat Rx(double deg) { return AxisAngle({1, 0, 0}, deg * kDegToRad); }
Quat Ry(double deg) { return AxisAngle({0, 1, 0}, deg * kDegToRad); }
Quat Rz(double deg) { return AxisAngle({0, 0, 1}, deg * kDegToRad); }

// Rotation taking u1 onto t1 and then u2 (as near as possible) onto t2.
Quat TwoVectorAlign(const Vec3& u1, const Vec3& t1, const Vec3& u2, const Vec3& t2) {
  const Quat q1 = RotationBetween(u1, t1);
  const Vec3 axis = Normalized(t1);
  const Vec3 a = Rotate(q1, u2) - axis * Dot(Rotate(q1, u2), axis);
  const Vec3 b = t2 - axis * Dot(t2, axis);
  const double angle = std::atan2(Dot(Cross(a, b), axis), Dot(a, b));
  return AxisAngle(axis, angle) * q1;
}

// The skeleton's joints by name, and A_j: the world rotation of each joint in a
// canonical standing pose (facing +Z, left +X, up +Y, arms down). Animation is
// authored as rotations C_j in that canonical space (see docs/motion.md).
struct Rig {
  Skeleton sk;
  std::map<std::string, int> id;
  std::vector<Quat> rest;  // A_j
  double thigh = 0, shin = 0, foot = 0;
  Vec3 hip_offset[2];  // Canonical pelvis-to-hip vectors, left and right.

  int operator[](const std::string& name) const { return id.at(name); }
  const Vec3& off(const std::string& name) const { return sk.joint(id.at(name)).offset; }
};

Rig BuildRig() {
  Rig r;
  r.sk = BandaiSkeleton();
  for (int j = 0; j < r.sk.num_joints(); ++j) r.id[r.sk.joint(j).name] = j;
  const Vec3 up{0, 1, 0}, down{0, -1, 0}, left{1, 0, 0}, right{-1, 0, 0};
  const Vec3 foot_dir = Normalized(Vec3{0, -0.45, 0.89});
  r.rest.assign(r.sk.num_joints(), Quat{});
  auto aim = [&](const std::string& j, const std::string& child, const Vec3& target) {
    r.rest[r[j]] = RotationBetween(r.off(child), target);
  };
  r.rest[r["Hips"]] =
      TwoVectorAlign(r.off("Spine"), up, r.off("UpperLeg_L") - r.off("UpperLeg_R"), left);
  aim("Spine", "Chest", up);
  r.rest[r["Chest"]] =
      TwoVectorAlign(r.off("Neck"), up, r.off("Shoulder_L") - r.off("Shoulder_R"), left);
  aim("Neck", "Head", up);
  r.rest[r["Head"]] = r.rest[r["Neck"]];
  for (const char* s : {"_L", "_R"}) {
    const std::string side = s;
    aim("Shoulder" + side, "UpperArm" + side, side == "_L" ? left : right);
    aim("UpperArm" + side, "LowerArm" + side, down);
    aim("LowerArm" + side, "Hand" + side, down);
    r.rest[r["Hand" + side]] = r.rest[r["LowerArm" + side]];
    aim("UpperLeg" + side, "LowerLeg" + side, down);
    aim("LowerLeg" + side, "Foot" + side, down);
    aim("Foot" + side, "Toes" + side, foot_dir);
    r.rest[r["Toes" + side]] = r.rest[r["Foot" + side]];
  }
  r.thigh = Norm(r.off("LowerLeg_L"));
  r.shin = Norm(r.off("Foot_L"));
  r.foot = Norm(r.off("Toes_L"));
  r.hip_offset[0] = Rotate(r.rest[r["Hips"]], r.off("UpperLeg_L"));
  r.hip_offset[1] = Rotate(r.rest[r["Hips"]], r.off("UpperLeg_R"));
  return r;
}

// Point at arc length s along a path that starts at the origin facing +Z and
// turns at a constant rate of `curvature` radians per cm.
Vec3 PathPoint(double s, double curvature) {
  if (std::fabs(curvature) < 1e-9) return {0, 0, s};
  return {(1 - std::cos(curvature * s)) / curvature, 0, std::sin(curvature * s) / curvature};
}
Vec3 LeftOf(double heading) { return {std::cos(heading), 0, -std::sin(heading)}; }

// Where one foot's ankle is, along the path: arc length, height and toe-down
// pitch. Stance keeps the foot flat, then rolls it over the planted toe
// (heel-off); swing carries the ankle to the next footstep.
struct FootState {
  double arc = 0;
  double height = 0;
  double pitch = 0;  // Degrees, toes down.
  bool stance = true;
};

struct FootGeometry {
  double length = 0;        // Ankle to toe.
  double ankle_height = 0;  // With the foot flat.
  // Ankle relative to the toe, along the path and up, at a toe-down pitch.
  double ArcFromToe(double pitch) const {
    const double a = pitch * kDegToRad;
    return -length * (-0.45 * std::sin(a) + 0.89 * std::cos(a));
  }
  double HeightAboveToe(double pitch) const {
    const double a = pitch * kDegToRad;
    return length * (0.45 * std::cos(a) + 0.89 * std::sin(a));
  }
};

constexpr double kHeelOffStart = 0.6;  // Fraction of stance.

FootState Foot(const SynthStyle& st, const FootGeometry& g, double t, double phase0,
               double stance_fraction) {
  const double cycle = st.stride / st.speed;
  const double max_pitch = st.run ? 25 : 35;
  const double u = t / cycle + phase0;
  const double c = std::floor(u), phi = u - c;
  const double plant = st.stride * (c - phase0) + st.stride * stance_fraction / 2;
  const double toe_arc = plant - g.ArcFromToe(0);
  const double toe_height = g.ankle_height - g.HeightAboveToe(0);
  FootState f;
  if (phi < stance_fraction) {
    const double p = phi / stance_fraction;
    f.pitch = p < kHeelOffStart ? 0 : max_pitch * (p - kHeelOffStart) / (1 - kHeelOffStart);
    f.arc = toe_arc + g.ArcFromToe(f.pitch);
    f.height = toe_height + g.HeightAboveToe(f.pitch);
    return f;
  }
  const double s = (phi - stance_fraction) / (1 - stance_fraction);
  const double ease = (1 - std::cos(kPi * s)) / 2;
  const double start_arc = toe_arc + g.ArcFromToe(max_pitch);
  const double start_height = toe_height + g.HeightAboveToe(max_pitch);
  f.stance = false;
  f.arc = start_arc + (plant + st.stride - start_arc) * ease;
  f.height =
      start_height + (g.ankle_height - start_height) * ease + st.foot_lift * std::sin(kPi * s);
  f.pitch = max_pitch * (1 - ease);
  return f;
}

// Two-bone IK in the pelvis frame: abduction (about Z), then hip and knee
// flexion in the leg's plane (degrees) that put the ankle at `d` from the hip.
struct LegAngles {
  double abduct = 0, hip = 0, knee = 0;
};

LegAngles LegIk(const Rig& r, const Vec3& d) {
  LegAngles out;
  const double l1 = r.thigh, l2 = r.shin;
  out.abduct = std::atan2(d.x, -d.y) * kRadToDeg;
  const double down = std::hypot(d.x, d.y);  // Distance along the leg plane's "down".
  const double dist = std::clamp(std::hypot(down, d.z), std::fabs(l1 - l2) + 1e-3, l1 + l2 - 1e-4);
  const double alpha = std::atan2(d.z, down);
  const double gamma =
      std::acos(std::clamp((l1 * l1 + l2 * l2 - dist * dist) / (2 * l1 * l2), -1.0, 1.0));
  const double beta =
      std::acos(std::clamp((l1 * l1 + dist * dist - l2 * l2) / (2 * l1 * dist), -1.0, 1.0));
  out.hip = (alpha + beta) * kRadToDeg;
  out.knee = (kPi - gamma) * kRadToDeg;
  return out;
}

}  // namespace

Skeleton BandaiSkeleton() {
  struct Spec {
    const char* name;
    const char* parent;
    Vec3 offset;
    bool end_site;
  };
  // Offsets (cm) as declared by the Bandai dataset's BVH hierarchy.
  const Spec specs[] = {
      {"joint_Root", "", {0, 0, 0}, false},
      {"Hips", "joint_Root", {0, 93.984, 0}, false},
      {"Spine", "Hips", {15.7357, 0, 0}, false},
      {"Chest", "Spine", {8.98455, -0.406207, 0}, false},
      {"Neck", "Chest", {16.3773, 0, 0}, false},
      {"Head", "Neck", {6.45672, 0, 0}, true},
      {"Shoulder_L", "Chest", {12.9942, -0.242716, 4.98039}, false},
      {"UpperArm_L", "Shoulder_L", {5.34809, 0, 0}, false},
      {"LowerArm_L", "UpperArm_L", {24.3286, 0, 0}, false},
      {"Hand_L", "LowerArm_L", {22.2916, 0, 0}, true},
      {"Shoulder_R", "Chest", {12.9945, -0.242716, -4.98039}, false},
      {"UpperArm_R", "Shoulder_R", {-5.34813, 0, 0}, false},
      {"LowerArm_R", "UpperArm_R", {-24.3289, 0, 0}, false},
      {"Hand_R", "LowerArm_R", {-22.2915, 0, 0}, true},
      {"UpperLeg_L", "Hips", {-2.19248, -6.46944, 0}, false},
      {"LowerLeg_L", "UpperLeg_L", {39.0811, 0, 0}, false},
      {"Foot_L", "LowerLeg_L", {40.9854, 0, 0}, false},
      {"Toes_L", "Foot_L", {11.7543, 0, 0}, true},
      {"UpperLeg_R", "Hips", {-2.19251, 6.46944, 0}, false},
      {"LowerLeg_R", "UpperLeg_R", {-39.0811, 0, 0}, false},
      {"Foot_R", "LowerLeg_R", {-40.9854, 0, 0}, false},
      {"Toes_R", "Foot_R", {-11.7543, 0, 0}, true},
  };
  std::vector<Joint> joints;
  std::map<std::string, int> index;
  for (const Spec& s : specs) {
    Joint j;
    j.name = s.name;
    j.parent = s.parent[0] ? index.at(s.parent) : -1;
    j.offset = s.offset;
    j.channels = kSixChannels;
    if (s.end_site) j.end_sites.push_back({0, 0, 0});
    index[j.name] = static_cast<int>(joints.size());
    joints.push_back(std::move(j));
  }
  return *Skeleton::Create(std::move(joints));
}

absl::StatusOr<SynthStyle> ParseSynthStyle(const std::string& spec) {
  SynthStyle s;
  std::vector<std::string> items = absl::StrSplit(spec, ',', absl::SkipEmpty());
  if (!items.empty() && items[0].find('=') == std::string::npos) {
    const std::string preset = items[0];
    items.erase(items.begin());
    if (preset == "old") {
      s.speed = 70, s.stride = 90, s.lean = 16, s.head_drop = 10, s.arm_swing = 6, s.elbow = 25;
      s.bounce = 1, s.foot_lift = 5, s.crouch = 0.07, s.sway = 3;
    } else if (preset == "tired") {
      s.speed = 85, s.stride = 105, s.lean = 10, s.head_drop = 18, s.arm_swing = 5, s.elbow = 5;
      s.foot_lift = 6, s.crouch = 0.05, s.sway = 4;
    } else if (preset == "proud") {
      s.speed = 125, s.stride = 145, s.lean = -6, s.head_drop = -8, s.arm_swing = 28,
      s.arm_out = 12;
      s.elbow = 10;
    } else if (preset == "happy") {
      s.speed = 150, s.stride = 140, s.lean = 2, s.arm_swing = 38, s.elbow = 35, s.bounce = 5;
      s.foot_lift = 14;
    } else if (preset == "sneaky") {
      s.speed = 60, s.stride = 110, s.lean = 20, s.arm_swing = 10, s.elbow = 70, s.crouch = 0.12;
      s.bounce = 0.5, s.foot_lift = 8, s.arm_out = 15;
    } else if (preset == "run") {
      s.run = true, s.speed = 330, s.stride = 250, s.lean = 10, s.arm_swing = 35, s.elbow = 85;
      s.bounce = 5, s.foot_lift = 25, s.crouch = 0.06, s.sway = 1;
    } else if (preset != "normal") {
      return absl::InvalidArgumentError(absl::StrCat(
          "unknown style preset '", preset, "' (normal, old, tired, proud, happy, sneaky, run)"));
    }
  }
  std::map<std::string, double*> knobs = {{"speed", &s.speed},
                                          {"stride", &s.stride},
                                          {"lean", &s.lean},
                                          {"head_drop", &s.head_drop},
                                          {"arm_swing", &s.arm_swing},
                                          {"elbow", &s.elbow},
                                          {"arm_out", &s.arm_out},
                                          {"bounce", &s.bounce},
                                          {"foot_lift", &s.foot_lift},
                                          {"crouch", &s.crouch},
                                          {"sway", &s.sway},
                                          {"turn", &s.turn},
                                          {"fps", &s.fps}};
  for (const std::string& item : items) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) {
      return absl::InvalidArgumentError(absl::StrCat("expected key=value, got '", item, "'"));
    }
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "gait") {
      if (value != "walk" && value != "run") {
        return absl::InvalidArgumentError(
            absl::StrCat("gait must be walk or run, got '", value, "'"));
      }
      s.run = value == "run";
      continue;
    }
    double v = 0;
    if (!absl::SimpleAtod(value, &v) || !std::isfinite(v)) {
      return absl::InvalidArgumentError(
          absl::StrCat("'", key, "' needs a number, got '", value, "'"));
    }
    if (key == "frames") {
      s.frames = static_cast<int>(v);
    } else if (auto it = knobs.find(key); it != knobs.end()) {
      *it->second = v;
    } else {
      return absl::InvalidArgumentError(absl::StrCat("unknown style knob '", key, "'"));
    }
  }
  return s;
}

absl::StatusOr<Motion> Synthesize(const SynthStyle& st) {
  if (!(st.speed > 0) || !(st.stride > 0) || !(st.fps > 0) || st.frames <= 0 ||
      st.frames > 1000000) {
    return absl::InvalidArgumentError("speed, stride, fps and frames (<= 1e6) must be positive");
  }
  if (st.crouch < 0 || st.crouch > 0.5 || st.foot_lift < 0) {
    return absl::InvalidArgumentError("crouch must be in [0, 0.5] and foot_lift >= 0");
  }
  static const Rig* const rig = new Rig(BuildRig());
  const Rig& r = *rig;
  const Skeleton& sk = r.sk;
  const int nj = sk.num_joints();
  const double stance = st.run ? 0.35 : 0.6;
  const double reach = 0.995 * (r.thigh + r.shin);
  FootGeometry foot_geometry;
  foot_geometry.length = r.foot;
  foot_geometry.ankle_height = 0.45 * r.foot + 2.0;
  const double ankle_height = foot_geometry.ankle_height;
  const double curvature = st.turn * kDegToRad / st.speed;
  const double cycle = st.stride / st.speed;
  const double stand_height =
      ankle_height - r.hip_offset[0].y + (r.thigh + r.shin) * (1 - st.crouch);

  Motion m = RestMotion(sk, st.frames, 1.0 / st.fps);
  std::vector<Vec3> prev_euler(nj);
  for (int f = 0; f < st.frames; ++f) {
    const double t = f / st.fps;
    const double body_arc = st.speed * t;
    const double heading = curvature * body_arc;
    const double phi_l = std::fmod(t / cycle, 1.0);
    const double phi_r = std::fmod(t / cycle + 0.5, 1.0);
    const FootState feet[2] = {Foot(st, foot_geometry, t, 0.0, stance),
                               Foot(st, foot_geometry, t, 0.5, stance)};

    // Pelvis: bob (highest at mid-stance when walking, lowest when running),
    // sway over the stance leg, and twist with the forward leg.
    const double wave = std::cos(4 * kPi * (phi_l - stance / 2));
    double height = st.run ? stand_height - st.bounce * (1 + wave) / 2
                           : stand_height - st.bounce * (1 - wave) / 2;
    const double sway = st.sway * std::cos(2 * kPi * (phi_l - stance / 2));
    const double twist = -4 * std::cos(2 * kPi * phi_l);
    const Quat pelvis_rot = YawRotation(heading) * Ry(twist);
    Vec3 pelvis = PathPoint(body_arc, curvature) + LeftOf(heading) * sway;

    Vec3 targets[2];
    for (int k = 0; k < 2; ++k) {
      const double lateral = r.hip_offset[k].x;
      targets[k] = PathPoint(feet[k].arc, curvature) + LeftOf(curvature * feet[k].arc) * lateral;
      targets[k].y = feet[k].height;
      if (!feet[k].stance) continue;
      // Lower the pelvis when a planted foot would otherwise be out of reach.
      const Vec3 hip = pelvis + Rotate(pelvis_rot, r.hip_offset[k]);
      const double horiz = std::hypot(targets[k].x - hip.x, targets[k].z - hip.z);
      if (horiz < reach) {
        height = std::min(
            height, targets[k].y - r.hip_offset[k].y + std::sqrt(reach * reach - horiz * horiz));
      }
    }
    pelvis.y = height;

    std::vector<Quat> c(nj);  // Canonical-space rotations C_j.
    const double arm_comp = -st.lean;
    c[r["Spine"]] = Rx(st.lean / 2) * Ry(-twist / 2);
    c[r["Chest"]] = Rx(st.lean / 2) * Ry(-twist / 2);
    c[r["Neck"]] = Rx(-st.lean * 0.6 + st.head_drop);
    const char* sides[2] = {"_L", "_R"};
    for (int k = 0; k < 2; ++k) {
      const std::string side = sides[k];
      const double out = k == 0 ? st.arm_out : -st.arm_out;
      const double swing = st.arm_swing * std::cos(2 * kPi * (k == 0 ? phi_r : phi_l));
      c[r["UpperArm" + side]] = Rz(out) * Rx(arm_comp - swing);
      c[r["LowerArm" + side]] = Rx(-st.elbow);
      const Vec3 hip = pelvis + Rotate(pelvis_rot, r.hip_offset[k]);
      const Vec3 d = Rotate(Conjugate(pelvis_rot), targets[k] - hip);
      const LegAngles leg = LegIk(r, d);
      const Quat upper = Rz(leg.abduct) * Rx(-leg.hip);
      c[r["UpperLeg" + side]] = upper;
      c[r["LowerLeg" + side]] = Rx(leg.knee);
      // The foot faces along the path where it is planted, pitched toes-down.
      const Quat foot_world = YawRotation(curvature * feet[k].arc) * Rx(feet[k].pitch);
      c[r["Foot" + side]] = Normalized(Conjugate(pelvis_rot * upper * Rx(leg.knee)) * foot_world);
    }

    // World rotations W_j = W_parent C_j; joint rotations G_j = W_j A_j.
    GlobalPose g;
    g.positions.resize(nj);
    g.rotations.resize(nj);
    std::vector<Quat> w(nj);
    for (int j = 0; j < nj; ++j) {
      const int p = sk.joint(j).parent;
      if (p < 0) {
        w[j] = Quat{};
      } else if (j == r["Hips"]) {
        w[j] = pelvis_rot;
      } else {
        w[j] = w[p] * c[j];
      }
      g.rotations[j] = Normalized(w[j] * r.rest[j]);
      g.positions[j] = p < 0 ? Vec3{} : g.positions[p] + Rotate(g.rotations[p], sk.joint(j).offset);
      if (j == r["Hips"]) g.positions[j] = pelvis;
    }
    SetPose(&m, f, LocalFromGlobal(sk, g), &prev_euler);
  }
  return m;
}

}  // namespace stylus::motion
