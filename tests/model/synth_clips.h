// Four synthesized styled walks written as BVH (no dataset needed), shared by
// the model test files.
#ifndef STYLUS_TESTS_MODEL_SYNTH_CLIPS_H_
#define STYLUS_TESTS_MODEL_SYNTH_CLIPS_H_

#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/synth.h"

namespace stylus::testing {

// An empty directory <test tmp>/<name>_<pid>: ctest runs the tests of one
// binary as parallel processes, so a directory shared between processes
// could be emptied under another.
inline std::string FreshDir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "/" + name + "_" + std::to_string(getpid());
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// normal, old, run and proud (turning) walks of 64 frames, written once per
// test process.
inline const std::vector<std::string>& FourClips() {
  static const std::vector<std::string> paths = [] {
    std::vector<std::string> out;
    const std::string dir = FreshDir("synth_clips");
    for (const char* style :
         {"normal,frames=64", "old,frames=64", "run,frames=64", "proud,frames=64,turn=30"}) {
      const std::string path =
          dir + "/" + std::string(style).substr(0, std::string(style).find(',')) + ".bvh";
      EXPECT_TRUE(
          motion::WriteBvhFile(*motion::Synthesize(*motion::ParseSynthStyle(style)), path).ok());
      out.push_back(path);
    }
    return out;
  }();
  return paths;
}

// The four walks under labelled Bandai names (3 styles, 3 contents), for
// label-guided training.
inline const std::vector<std::string>& LabelledClips() {
  static const std::vector<std::string> paths = [] {
    const std::string dir = FreshDir("labelled_clips");
    const char* names[] = {"dataset-9_walk_normal_001.bvh", "dataset-9_walk_old_001.bvh",
                           "dataset-9_run_normal_001.bvh", "dataset-9_turn_proud_001.bvh"};
    std::vector<std::string> out;
    for (int i = 0; i < 4; ++i) {
      out.push_back(dir + "/" + names[i]);
      std::filesystem::copy_file(FourClips()[i], out.back());
    }
    return out;
  }();
  return paths;
}

}  // namespace stylus::testing

#endif  // STYLUS_TESTS_MODEL_SYNTH_CLIPS_H_
