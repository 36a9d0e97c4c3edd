// Test helpers around StyleModel transfers.
#ifndef STYLUS_TESTS_MODEL_TRANSFER_SUPPORT_H_
#define STYLUS_TESTS_MODEL_TRANSFER_SUPPORT_H_

#include "absl/status/statusor.h"
#include "model/style_model.h"
#include "motion/motion.h"

namespace stylus::testing {

// The motion of a transfer, or its error.
inline absl::StatusOr<motion::Motion> MotionOf(absl::StatusOr<model::TransferResult> result) {
  if (!result.ok()) return result.status();
  return std::move(result->motion);
}

}  // namespace stylus::testing

#endif  // STYLUS_TESTS_MODEL_TRANSFER_SUPPORT_H_
