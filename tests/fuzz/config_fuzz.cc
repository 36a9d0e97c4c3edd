// libFuzzer target: a model package's config.txt, read by both families'
// parsers, and a joint map file (motion/rig_roles.h).
#include <cstdint>
#include <string>

#include "model/contrastive/contrastive_config.h"
#include "model/cyclic/cyclic_config.h"
#include "motion/rig_roles.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  (void)stylus::model::ContrastiveConfig::Parse(text, "config.txt");
  (void)stylus::model::CyclicConfig::Parse(text, "config.txt");
  (void)stylus::motion::ParseJointMap(text, "joint_map.txt");
  return 0;
}
