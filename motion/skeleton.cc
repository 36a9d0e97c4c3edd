#include "motion/skeleton.h"

#include <cmath>

#include "absl/container/flat_hash_set.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace stylus::motion {

bool HasPositionChannel(const Joint& joint) {
  for (Channel c : joint.channels) {
    if (IsPosition(c)) return true;
  }
  return false;
}

absl::string_view ChannelName(Channel c) {
  switch (c) {
    case Channel::kXposition:
      return "Xposition";
    case Channel::kYposition:
      return "Yposition";
    case Channel::kZposition:
      return "Zposition";
    case Channel::kXrotation:
      return "Xrotation";
    case Channel::kYrotation:
      return "Yrotation";
    case Channel::kZrotation:
      return "Zrotation";
  }
  return "?";
}

std::optional<Channel> ParseChannel(absl::string_view name) {
  for (Channel c : {Channel::kXposition, Channel::kYposition, Channel::kZposition,
                    Channel::kXrotation, Channel::kYrotation, Channel::kZrotation}) {
    if (absl::EqualsIgnoreCase(name, ChannelName(c))) return c;
  }
  return std::nullopt;
}

Skeleton::Skeleton() {
  static const std::shared_ptr<const Data>* empty = new std::shared_ptr<const Data>(new Data);
  d_ = *empty;
}

absl::StatusOr<Skeleton> Skeleton::Create(std::vector<Joint> joints) {
  if (joints.empty()) return absl::InvalidArgumentError("skeleton has no joints");
  auto d = std::make_shared<Data>();
  Data& s = *d;
  const int n = static_cast<int>(joints.size());
  s.children.resize(n);
  s.channel_start.resize(n);
  s.rotation_order.resize(n);
  s.has_rotation.resize(n);
  absl::flat_hash_set<std::string> names;
  for (int i = 0; i < n; ++i) {
    const Joint& j = joints[i];
    const std::string who = absl::StrCat("joint ", i, " '", j.name, "'");
    if (j.name.empty())
      return absl::InvalidArgumentError(absl::StrCat("joint ", i, " has no name"));
    if (!names.insert(j.name).second) {
      return absl::InvalidArgumentError(absl::StrCat("duplicate joint name '", j.name, "'"));
    }
    if (i == 0 && j.parent != -1)
      return absl::InvalidArgumentError(who + " is first but not a root");
    if (i > 0 && (j.parent < 0 || j.parent >= i)) {
      return absl::InvalidArgumentError(
          absl::StrCat(who, " has parent ", j.parent, "; parents must come before children"));
    }
    if (i > 0) {
      // Depth-first order: the parent is the previous joint or one of its ancestors.
      int a = i - 1;
      while (a >= 0 && a != j.parent) a = joints[a].parent;
      if (a != j.parent) {
        return absl::InvalidArgumentError(who + " breaks depth-first joint order");
      }
      s.children[j.parent].push_back(i);
    }
    auto finite = [](const Vec3& v) {
      return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    };
    if (!finite(j.offset)) return absl::InvalidArgumentError(who + " has a non-finite OFFSET");
    for (const Vec3& e : j.end_sites) {
      if (!finite(e)) return absl::InvalidArgumentError(who + " has a non-finite End Site OFFSET");
    }
    if (j.channels.size() > 6) {
      return absl::InvalidArgumentError(
          absl::StrCat(who, " has ", j.channels.size(), " channels; at most 6 are allowed"));
    }
    int seen = 0;
    std::vector<int> rot_axes;
    for (Channel c : j.channels) {
      const int bit = 1 << static_cast<int>(c);
      if (seen & bit) {
        return absl::InvalidArgumentError(
            absl::StrCat(who, " lists channel ", ChannelName(c), " twice"));
      }
      seen |= bit;
      if (!IsPosition(c)) rot_axes.push_back(ChannelAxis(c));
    }
    if (!rot_axes.empty() && rot_axes.size() != 3) {
      return absl::InvalidArgumentError(
          absl::StrCat(who, " has ", rot_axes.size(), " rotation channels; 0 or 3 are supported"));
    }
    s.has_rotation[i] = !rot_axes.empty();
    if (s.has_rotation[i]) {
      s.rotation_order[i].axes = {rot_axes[0], rot_axes[1], rot_axes[2]};
    }
    s.channel_start[i] = s.num_channels;
    s.num_channels += static_cast<int>(j.channels.size());
  }
  s.joints = std::move(joints);
  Skeleton skeleton;
  skeleton.d_ = std::move(d);
  return skeleton;
}

std::optional<int> Skeleton::Find(absl::string_view name) const {
  for (int i = 0; i < num_joints(); ++i) {
    if (d_->joints[i].name == name) return i;
  }
  return std::nullopt;
}

bool Skeleton::SameTopology(const Skeleton& other) const { return DescribeMismatch(other).empty(); }

std::string Skeleton::DescribeMismatch(const Skeleton& other) const {
  if (d_ == other.d_) return "";  // Copies of one skeleton.
  if (num_joints() != other.num_joints()) {
    return absl::StrCat("it has ", num_joints(), " joints but the other has ", other.num_joints());
  }
  for (int i = 0; i < num_joints(); ++i) {
    const Joint& a = d_->joints[i];
    const Joint& b = other.d_->joints[i];
    if (a.name != b.name) {
      return absl::StrCat("joint ", i, " is '", a.name, "' here but '", b.name, "' in the other");
    }
    if (a.parent != b.parent) return absl::StrCat("joint '", a.name, "' has another parent");
    if (a.channels != b.channels) {
      return absl::StrCat("joint '", a.name, "' has another channel layout");
    }
  }
  return "";
}

}  // namespace stylus::motion
