// What a live stream carries from one frame to the next through a live
// `contrastive` package's networks (model/contrastive/live_net.h): each
// causal convolution's last inputs, as plain floats, so the state of one
// stream is a fixed number of bytes whatever its length, and the streams on
// one model can be stepped together in one batch.
#ifndef STYLUS_MODEL_CONTRASTIVE_LIVE_CARRY_H_
#define STYLUS_MODEL_CONTRASTIVE_LIVE_CARRY_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace stylus::model {

struct LiveCarry {
  // One buffer per causal convolution, (channels, (kernel - 1) x dilation)
  // channel major: each channel's last inputs, oldest first.
  std::vector<std::vector<float>> buffers;
  // buffers[0, content) are the content encoder's, the rest the generator's.
  size_t content = 0;

  // The generator's state back to a clip's start: while the content
  // encoder warms up on its look-ahead, the generator's outputs stand for no
  // frame and must not enter its history.
  void ResetGenerator() {
    for (size_t i = content; i < buffers.size(); ++i)
      std::fill(buffers[i].begin(), buffers[i].end(), 0.f);
  }

  size_t bytes() const {
    size_t n = 0;
    for (const auto& b : buffers) n += b.size() * sizeof(float);
    return n;
  }
};

// One stream's next frame through a live package (ContrastiveModel::StepLive).
struct LiveStep {
  LiveCarry* carry = nullptr;
  const float* features = nullptr;  // The frame's normalized features (dim).
  const float* params = nullptr;    // Its style's LiveStyleParams.
  float* out = nullptr;             // The generated frame (dim), normalized.
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONTRASTIVE_LIVE_CARRY_H_
