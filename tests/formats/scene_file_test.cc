// FBX, glTF and COLLADA through the formats library, against files real
// tools wrote: Blender (headless) exports the rigs in ../shared/data/rigs and a
// Bandai clip, Stylus reads them, and Blender imports what Stylus writes.
#include "formats/scene_file.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/kinematics.h"
#include "motion/rig_roles.h"
#include "tests/test_support.h"

namespace stylus::formats {
namespace {

namespace fs = std::filesystem;
using motion::Motion;
using motion::Vec3;

std::string SharedRigs() { return testing::SourceDir() + "/../shared/data/rigs"; }
std::string Script(const std::string& name) { return testing::SourceDir() + "/tests/formats/" + name; }

// Blender's path, or "" (the tests that need it are skipped, or fail under CI).
std::string Blender() {
  for (const char* p : {"/usr/bin/blender", "/usr/local/bin/blender"}) {
    if (fs::exists(p)) return p;
  }
  return "";
}

#define REQUIRE_BLENDER()                                                              \
  do {                                                                                 \
    if (Blender().empty()) {                                                           \
      if (testing::UnderCi()) FAIL() << "Blender not installed (required under CI)";   \
      GTEST_SKIP() << "Blender not installed (Debian's blender); skipping";            \
    }                                                                                  \
  } while (0)

// Runs a Blender script headless; its output goes to `log`.
int RunBlender(const std::string& script, const std::string& args, const std::string& log) {
  std::string command = absl::StrCat(Blender(), " -b --factory-startup --python '", script, "' -- ",
                                     args, " > '", log, "' 2>&1");
  return std::system(command.c_str());
}

class SceneFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() / absl::StrCat("stylus_formats_", ::getpid(), "_",
                                                      ::testing::UnitTest::GetInstance()->random_seed()))
               .string();
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // Blender's exports of `bvh` (see blender_export.py) into dir_.
  void Export(const std::string& bvh, const std::string& flags = "") {
    ASSERT_EQ(RunBlender(Script("blender_export.py"), absl::StrCat("'", bvh, "' '", dir_, "' ", flags),
                         dir_ + "/export.log"),
              0)
        << "see " << dir_ << "/export.log";
  }
  std::string Out(const std::string& stem, const std::string& suffix) const {
    return dir_ + "/" + stem + suffix;
  }

  std::string dir_;
};

std::string Stem(const std::string& path) { return fs::path(path).stem().string(); }

double LegOf(const Motion& m) {
  motion::GlobalPose first = motion::ForwardKinematics(m.skeleton, motion::PoseAt(m, 0));
  absl::StatusOr<motion::RigRoles> roles = motion::FindRigRoles(m.skeleton, first);
  EXPECT_TRUE(roles.ok()) << roles.status();
  return roles.ok() ? motion::LegLength(m.skeleton, *roles) : 1.0;
}

// Largest distance between same-named joints over all frames, over the
// reference's leg length. Every joint of `reference` must be in `other`.
double MaxError(const Motion& reference, const Motion& other) {
  EXPECT_EQ(reference.num_frames, other.num_frames);
  auto a = motion::GlobalPositions(reference);
  auto b = motion::GlobalPositions(other);
  double worst = 0;
  for (int j = 0; j < reference.skeleton.num_joints(); ++j) {
    std::optional<int> k = other.skeleton.Find(reference.skeleton.joint(j).name);
    EXPECT_TRUE(k.has_value()) << reference.skeleton.joint(j).name;
    if (!k) continue;
    for (int f = 0; f < std::min(reference.num_frames, other.num_frames); ++f) {
      worst = std::max(worst, motion::Norm(a[f][j] - b[f][*k]));
    }
  }
  return worst / LegOf(reference);
}

Motion ReadOk(const std::string& path, const ReadOptions& options = {}) {
  absl::StatusOr<Motion> m = ReadMotionFile(path, options);
  EXPECT_TRUE(m.ok()) << m.status();
  return m.ok() ? *m : Motion{};
}

// Each rig's BVH, exported by Blender as FBX, GLB, glTF and COLLADA, reads back with
// the BVH's joints, frames, rate and positions (within 0.1% of the leg).
TEST_F(SceneFileTest, BlenderExportsReadAsTheBvh) {
  REQUIRE_BLENDER();
  STYLUS_REQUIRE_BANDAI(data);
  if (!fs::exists(SharedRigs())) {
    if (testing::UnderCi()) FAIL() << SharedRigs() << " missing (required under CI)";
    GTEST_SKIP() << SharedRigs() << " missing";
  }
  for (const std::string& bvh : {SharedRigs() + "/mixamo_55joints_30fps.bvh",
                                 SharedRigs() + "/mocapbank_19joints_30fps.bvh",
                                 data + "/dataset-1/dataset-1_walk_old_001.bvh"}) {
    SCOPED_TRACE(bvh);
    Export(bvh);
    Motion reference = ReadOk(bvh);
    for (const char* ext : {".fbx", ".glb", ".gltf", ".dae"}) {
      // Blender's COLLADA writer leaves an unkeyed root bone (the Bandai
      // rig's joint_Root) out of the animation and keys its child against a
      // transform it does not write: docs/pipelines.md "Limits".
      if (std::string(ext) == ".dae" && bvh.find("bandai") != std::string::npos) continue;
      Motion read = ReadOk(Out(Stem(bvh), ext));
      EXPECT_EQ(read.skeleton.num_joints(), reference.skeleton.num_joints()) << ext;
      EXPECT_NEAR(read.fps(), reference.fps(), 0.01) << ext;
      double error = MaxError(reference, read);
      std::printf("%s%s: %d joints, %d frames, max error %.2e of the leg\n", Stem(bvh).c_str(), ext,
                  read.skeleton.num_joints(), read.num_frames, error);
      EXPECT_LT(error, 1e-3) << ext;
      if (std::string(ext) == ".fbx") {
        // Blender's leaf bones ("_end") come back as the BVH's End Sites.
        double worst = 0;
        int sites = 0;
        for (int f = 0; f < reference.num_frames; f += 10) {
          const motion::GlobalPose a = motion::ForwardKinematics(reference.skeleton, motion::PoseAt(reference, f));
          const motion::GlobalPose b = motion::ForwardKinematics(read.skeleton, motion::PoseAt(read, f));
          for (int j = 0; j < reference.skeleton.num_joints(); ++j) {
            const motion::Joint& want = reference.skeleton.joint(j);
            const int k = *read.skeleton.Find(want.name);
            ASSERT_EQ(read.skeleton.joint(k).end_sites.size(), want.end_sites.size()) << want.name;
            for (size_t e = 0; e < want.end_sites.size(); ++e) {
              const Vec3 pa = a.positions[j] + motion::Rotate(a.rotations[j], want.end_sites[e]);
              const Vec3 pb = b.positions[k] + motion::Rotate(b.rotations[k], read.skeleton.joint(k).end_sites[e]);
              worst = std::max(worst, motion::Norm(pa - pb));
              sites += f == 0;
            }
          }
        }
        std::printf("  %d End Sites from the FBX's leaf bones, within %.2e of the leg\n", sites,
                    worst / LegOf(reference));
        EXPECT_LT(worst / LegOf(reference), 2e-3) << sites << " End Sites";
      }
      // A zero pose is the file's rest pose: the skeleton's offsets are the
      // BVH's bone vectors (Blender's glTF writes the rest pose in its nodes).
      if (std::string(ext) == ".glb" || std::string(ext) == ".gltf") {
        for (int j = 1; j < reference.skeleton.num_joints(); ++j) {
          const motion::Joint& want = reference.skeleton.joint(j);
          const motion::Joint& got = read.skeleton.joint(*read.skeleton.Find(want.name));
          EXPECT_LT(motion::Norm(want.offset - got.offset), 1e-4 * LegOf(reference)) << want.name;
        }
      }
    }
  }
}

// Stylus's own glTF, of a BVH (a stick figure skinned to the skeleton) and of
// a Blender file with a mesh (its nodes and mesh kept), reads back the same
// and imports into Blender as an armature with the bones and frames, its
// joints where Stylus put them.
TEST_F(SceneFileTest, WrittenGltfImportsIntoBlender) {
  REQUIRE_BLENDER();
  if (!fs::exists(SharedRigs())) {
    if (testing::UnderCi()) FAIL() << SharedRigs() << " missing (required under CI)";
    GTEST_SKIP() << SharedRigs() << " missing";
  }
  const std::string bvh = SharedRigs() + "/mocapbank_19joints_30fps.bvh";
  Export(bvh, "--mesh");
  Motion clip = ReadOk(bvh);
  struct Case {
    std::string out, like;
    int meshes;
  };
  for (const Case& c : {Case{dir_ + "/stick.glb", "", 1}, Case{dir_ + "/stick.gltf", bvh, 1},
                        Case{dir_ + "/kept.glb", Out(Stem(bvh), "_mesh.glb"), 1}}) {
    SCOPED_TRACE(c.out);
    Motion source = c.like.empty() || c.like == bvh ? clip : ReadOk(c.like);
    WriteOptions options;
    options.like = c.like;
    ASSERT_TRUE(WriteMotionFile(source, c.out, options).ok());
    Motion back = ReadOk(c.out);
    EXPECT_LT(MaxError(source, back), 1e-3);
    const int frame = 40;
    const std::string report = c.out + ".txt";
    ASSERT_EQ(RunBlender(Script("blender_check.py"),
                         absl::StrCat("'", c.out, "' '", report, "' ", frame, " 30"), c.out + ".log"),
              0)
        << "see " << c.out << ".log";
    std::ifstream in(report);
    std::string line;
    std::map<std::string, Vec3> heads;
    std::map<std::string, int> facts;
    while (std::getline(in, line)) {
      std::vector<std::string> t = absl::StrSplit(line, ' ');
      if (t[0] == "head" && t.size() >= 5) {
        std::string name = line.substr(5, line.size() - 5);
        name = name.substr(0, name.size() - (t[t.size() - 1].size() + t[t.size() - 2].size() +
                                              t[t.size() - 3].size() + 3));
        heads[name] = Vec3{std::stod(t[t.size() - 3]), std::stod(t[t.size() - 2]), std::stod(t[t.size() - 1])};
      } else if (t.size() == 2) {
        facts[t[0]] = std::stoi(t[1]);
      }
    }
    EXPECT_EQ(facts["armatures"], 1);
    EXPECT_EQ(facts["meshes"], c.meshes);
    EXPECT_EQ(facts["frames"], source.num_frames);
    EXPECT_EQ(static_cast<int>(heads.size()), source.skeleton.num_joints());
    auto world = motion::GlobalPositions(source);
    double leg = LegOf(source), worst = 0;
    for (int j = 0; j < source.skeleton.num_joints(); ++j) {
      auto it = heads.find(source.skeleton.joint(j).name);
      ASSERT_NE(it, heads.end()) << source.skeleton.joint(j).name;
      worst = std::max(worst, motion::Norm(it->second - world[frame][j]) / leg);
    }
    std::printf("%s in Blender: %zu bones, %d frames, joints within %.2e of the leg\n",
                fs::path(c.out).filename().c_str(), heads.size(), facts["frames"], worst);
    EXPECT_LT(worst, 1e-3);
  }
}

// Clear errors, each naming the file and what to do.
TEST_F(SceneFileTest, BadFilesSayWhatIsWrong) {
  EXPECT_EQ(ReadMotionFile(dir_ + "/missing.glb").status().code(), absl::StatusCode::kNotFound);
  absl::Status unknown = ReadMotionFile(dir_ + "/clip.mp4").status();
  EXPECT_EQ(unknown.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(unknown.message().find(".fbx"), std::string::npos) << unknown;
  std::ofstream(dir_ + "/garbage.glb") << "this is not a glTF file";
  absl::Status garbage = ReadMotionFile(dir_ + "/garbage.glb").status();
  EXPECT_EQ(garbage.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(garbage.message().find("garbage.glb"), std::string::npos) << garbage;
  Motion m;
  EXPECT_EQ(WriteMotionFile(m, dir_ + "/out.fbx").code(), absl::StatusCode::kInvalidArgument);

  REQUIRE_BLENDER();
  if (!fs::exists(SharedRigs())) GTEST_SKIP() << SharedRigs() << " missing";
  const std::string bvh = SharedRigs() + "/mocapbank_19joints_30fps.bvh";
  Export(bvh, "--two");
  absl::Status still = ReadMotionFile(Out(Stem(bvh), "_still.glb")).status();
  EXPECT_NE(still.message().find("no animation"), std::string::npos) << still;
  absl::Status two = ReadMotionFile(Out(Stem(bvh), "_two.fbx")).status();
  EXPECT_NE(two.message().find("--animation"), std::string::npos) << two;
  EXPECT_NE(two.message().find("aside"), std::string::npos) << two;
  // Chosen by name: "aside" is the clip a unit away, the other the clip.
  Motion clip = ReadOk(bvh);
  auto a = motion::GlobalPositions(clip);
  for (const char* name : {"mocapbank_19joints_30fps|mocapbank_19joints_30fps", "mocapbank_19joints_30fps|aside"}) {
    ReadOptions options;
    options.animation = name;
    Motion read = ReadOk(Out(Stem(bvh), "_two.fbx"), options);
    ASSERT_EQ(read.num_frames, clip.num_frames) << name;
    auto b = motion::GlobalPositions(read);
    std::optional<int> hips = read.skeleton.Find("Hips");
    ASSERT_TRUE(hips.has_value());
    double apart = motion::Norm(a[clip.num_frames / 2][0] - b[clip.num_frames / 2][*hips]);
    EXPECT_NEAR(apart, std::string(name).find("aside") != std::string::npos ? 1.0 : 0.0, 1e-3) << name;
  }
  ReadOptions options;
  options.animation = "nothing";
  absl::Status missing = ReadMotionFile(Out(Stem(bvh), "_two.fbx"), options).status();
  EXPECT_NE(missing.message().find("has no animation 'nothing'"), std::string::npos) << missing;
}

}  // namespace
}  // namespace stylus::formats
