// libFuzzer target: request bytes as the server sees them. The bytes are
// parsed as a TransferRequest and a StreamRequest; what parses goes through
// the wire conversions the server runs (clips, skeletons, frames).
#include <cstdint>
#include <string>
#include <vector>

#include "stylus/v1/stylus.pb.h"
#include "wire/wire.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace stylus;
  v1::TransferRequest transfer;
  if (transfer.ParseFromArray(data, static_cast<int>(size))) {
    (void)wire::ClipFromProto(transfer.content(), "content clip");
    if (transfer.style().has_clip()) (void)wire::ClipFromProto(transfer.style().clip(), "style");
  }
  v1::StreamRequest stream;
  if (stream.ParseFromArray(data, static_cast<int>(size))) {
    if (stream.has_config()) {
      absl::StatusOr<motion::Skeleton> skeleton =
          wire::SkeletonFromProto(stream.config().skeleton(), "config");
      if (skeleton.ok() && stream.has_frame()) {
        motion::Motion chunk = motion::RestMotion(*skeleton, 0, 1.0 / 30);
        std::vector<motion::Vec3> prev(skeleton->num_joints());
        (void)wire::AppendFrame(stream.frame(), "frame", &prev, &chunk);
      }
    }
  }
  return 0;
}
