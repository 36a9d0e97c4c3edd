// Helpers shared by the test binaries: where the sources and the Bandai data are.
#ifndef STYLUS_TESTS_TEST_SUPPORT_H_
#define STYLUS_TESTS_TEST_SUPPORT_H_

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "gtest/gtest.h"
#include "motion/dataset.h"
#include "motion/motion.h"

namespace stylus::testing {

inline std::string SourceDir() { return STYLUS_SOURCE_DIR; }
// The shipped default package, as models/DEFAULT names it (e.g.
// "contrastive/v10"; the server reads the file with model::ReadDefaultPackage,
// which the registry tests check against this), and its directory.
inline std::string DefaultPackage() {
  std::ifstream in(SourceDir() + "/models/DEFAULT");
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') return line;
  return "";
}
inline std::string DefaultPackageDir() { return SourceDir() + "/models/" + DefaultPackage(); }
inline std::string FixturePath(const std::string& rel) {
  return SourceDir() + "/tests/fixtures/" + rel;
}

// Frames [begin, end) of `m` as a motion of their own.
inline motion::Motion Frames(const motion::Motion& m, int begin, int end) {
  motion::Motion out = m;
  const int c = m.skeleton.num_channels();
  out.num_frames = end - begin;
  out.values.assign(m.values.begin() + static_cast<size_t>(begin) * c,
                    m.values.begin() + static_cast<size_t>(end) * c);
  return out;
}

// Appends the frames of `chunk` (same skeleton) to `all`.
inline void Append(const motion::Motion& chunk, motion::Motion* all) {
  all->values.insert(all->values.end(), chunk.values.begin(), chunk.values.end());
  all->num_frames += chunk.num_frames;
}

// Copies the model package `from` (every file: weights, statistics,
// skeleton, guards) into a fresh directory `name` under the test temp dir,
// its config.txt without the lines whose key is in `drop` and with `append`.
inline std::string CopyPackage(const std::string& from, const std::string& name,
                               const std::vector<std::string>& drop,
                               const std::string& append = "") {
  namespace fs = std::filesystem;
  const std::string dir = ::testing::TempDir() + "/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const fs::directory_entry& f : fs::directory_iterator(from)) {
    if (f.is_regular_file() && f.path().filename() != "config.txt") {
      fs::copy_file(f.path(), dir + "/" + f.path().filename().string());
    }
  }
  std::ifstream in(from + "/config.txt");
  std::ofstream out(dir + "/config.txt");
  for (std::string line; std::getline(in, line);) {
    const std::string key = line.substr(0, line.find(' '));
    if (std::find(drop.begin(), drop.end(), key) == drop.end()) out << line << "\n";
  }
  out << append;
  return dir;
}

// Polls `condition` every millisecond until it holds (true) or `timeout`
// passes (false): waits on what a test needs, not on a guessed sleep.
template <typename Condition>
bool WaitFor(Condition condition, std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// A style library folder `name` under the test's temporary folder, made
// afresh, of links to Bandai dataset-2 takes (`takes`: names without the
// "dataset-2_" prefix and ".bvh"); the data stays where it is. Its path.
inline std::string LinkLibrary(const std::string& data, const std::string& name,
                               const std::vector<std::string>& takes) {
  namespace fs = std::filesystem;
  const std::string dir = ::testing::TempDir() + "/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const std::string& take : takes) {
    const std::string file = "dataset-2_" + take + ".bvh";
    fs::create_symlink(fs::absolute(data + "/dataset-2/" + file), dir + "/" + file);
  }
  return dir;
}

inline bool UnderCi() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

}  // namespace stylus::testing

// Sets `var` (a std::string) to the Bandai data directory, or leaves the test:
// skipped with a visible message on a machine without the data, failed under
// CI=true, where real-data tests must run.
#define STYLUS_REQUIRE_BANDAI(var)                                                                \
  std::string var;                                                                                \
  do {                                                                                            \
    std::optional<std::string> found =                                                            \
        stylus::motion::FindBandaiData(stylus::testing::SourceDir());                             \
    if (!found) {                                                                                 \
      if (stylus::testing::UnderCi()) {                                                           \
        FAIL() << "Bandai data not found at ../shared/data/bandai or $STYLUS_DATA (required "     \
                  "under CI)";                                                                    \
      }                                                                                           \
      GTEST_SKIP() << "Bandai data not found at ../shared/data/bandai or $STYLUS_DATA; skipping"; \
    }                                                                                             \
    var = *found;                                                                                 \
  } while (0)

#endif  // STYLUS_TESTS_TEST_SUPPORT_H_
