#include <charconv>
#include <string>

#include "absl/strings/str_cat.h"
#include "motion/bvh.h"
#include "motion/files.h"

namespace stylus::motion {
namespace {

void AppendNumber(std::string* out, double v) {
  char buf[32];
  if (v == 0) v = 0;  // Writes "-0" as "0".
  const auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v);
  out->append(buf, ec == std::errc() ? end : buf);
}

void AppendVec(std::string* out, const Vec3& v) {
  for (int i = 0; i < 3; ++i) {
    out->push_back(' ');
    AppendNumber(out, v[i]);
  }
}

}  // namespace

std::string FormatBvh(const Motion& motion) {
  const Skeleton& sk = motion.skeleton;
  std::string out = "HIERARCHY\n";
  std::vector<int> open;  // Joints whose braces are still open.
  auto indent = [&](size_t depth) { out.append(2 * depth, ' '); };
  auto close = [&]() {
    const int j = open.back();
    for (const Vec3& e : sk.joint(j).end_sites) {
      indent(open.size());
      out += "End Site\n";
      indent(open.size());
      out += "{\n";
      indent(open.size() + 1);
      out += "OFFSET";
      AppendVec(&out, e);
      out += "\n";
      indent(open.size());
      out += "}\n";
    }
    open.pop_back();
    indent(open.size());
    out += "}\n";
  };
  for (int j = 0; j < sk.num_joints(); ++j) {
    const Joint& joint = sk.joint(j);
    while (!open.empty() && open.back() != joint.parent) close();
    indent(open.size());
    absl::StrAppend(&out, j == 0 ? "ROOT " : "JOINT ", joint.name, "\n");
    indent(open.size());
    out += "{\n";
    indent(open.size() + 1);
    out += "OFFSET";
    AppendVec(&out, joint.offset);
    out += "\n";
    indent(open.size() + 1);
    absl::StrAppend(&out, "CHANNELS ", joint.channels.size());
    for (Channel c : joint.channels) absl::StrAppend(&out, " ", ChannelName(c));
    out += "\n";
    open.push_back(j);
  }
  while (!open.empty()) close();
  absl::StrAppend(&out, "MOTION\nFrames: ", motion.num_frames, "\nFrame Time: ");
  AppendNumber(&out, motion.frame_time);
  out += "\n";
  const int channels = sk.num_channels();
  for (int f = 0; f < motion.num_frames; ++f) {
    const double* row = motion.frame(f);
    for (int c = 0; c < channels; ++c) {
      if (c) out.push_back(' ');
      AppendNumber(&out, row[c]);
    }
    out += "\n";
  }
  return out;
}

absl::Status WriteBvhFile(const Motion& motion, const std::string& path) {
  return WriteFileAtomically(path, FormatBvh(motion));
}

}  // namespace stylus::motion
