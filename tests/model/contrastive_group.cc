// One translation unit for these test files, so that LibTorch's headers are
// parsed once for all of them, not once per file (build time on two cores).
// Included by paths from the checkout's root, so that the object does not
// depend on the checkout's folder (ccache reuses it from a clone elsewhere).
#include "tests/model/contrastive/contrastive_net_test.cc"  // NOLINT(build/include)
#include "tests/model/contrastive/contrastive_model_test.cc"  // NOLINT(build/include)
#include "tests/model/contrastive/contrastive_config_test.cc"  // NOLINT(build/include)
#include "tests/model/contrastive/window_streamer_test.cc"  // NOLINT(build/include)
#include "tests/model/content_guard_test.cc"  // NOLINT(build/include)
