// A tiny labelled dataset for the judges' and evaluation's tests.
#ifndef STYLUS_TESTS_EVAL_TINY_DATASET_H_
#define STYLUS_TESTS_EVAL_TINY_DATASET_H_

#include <unistd.h>

#include <filesystem>
#include <string>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/synth.h"

namespace stylus::testing {

// dataset-9_{walk,run}_{old,proud}_00{1,2}.bvh, `frames` long, synthesized
// into a fresh directory `name` under the test's temporary directory.
inline std::string TinyLabelledDataset(const std::string& name, int frames = 48) {
  namespace fs = std::filesystem;
  // Per process: ctest runs each test in a process of its own, two at once,
  // and one's remove_all must not pull the files from under the other.
  const std::string dir = ::testing::TempDir() + "/" + name + "." + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const char* content : {"walk", "run"}) {
    for (const char* style : {"old", "proud"}) {
      for (int take = 1; take <= 2; ++take) {
        std::string spec = std::string(style) + ",frames=" + std::to_string(frames) +
                           ",turn=" + std::to_string(take * 10);
        if (std::string(content) == "run") spec += ",gait=run,speed=300,stride=240";
        const std::string path =
            dir + "/dataset-9_" + content + "_" + style + "_00" + std::to_string(take) + ".bvh";
        EXPECT_TRUE(
            motion::WriteBvhFile(*motion::Synthesize(*motion::ParseSynthStyle(spec)), path).ok());
      }
    }
  }
  return dir;
}

}  // namespace stylus::testing

#endif  // STYLUS_TESTS_EVAL_TINY_DATASET_H_
