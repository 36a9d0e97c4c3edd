// One translation unit for these test files, so that LibTorch's headers are
// parsed once for all of them, not once per file (build time on two cores).
// Included by paths from the checkout's root, so that the object does not
// depend on the checkout's folder (ccache reuses it from a clone elsewhere).
#include "tests/train/clip_classes_test.cc"  // NOLINT(build/include)
#include "tests/train/training_set_test.cc"  // NOLINT(build/include)
#include "tests/train/label_critic_test.cc"  // NOLINT(build/include)
#include "tests/train/pair_discriminator_test.cc"  // NOLINT(build/include)
#include "tests/train/weight_average_test.cc"  // NOLINT(build/include)
#include "tests/train/contrastive_trainer_test.cc"  // NOLINT(build/include)
