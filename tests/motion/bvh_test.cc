#include "motion/bvh.h"

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "gtest/gtest.h"
#include "motion/kinematics.h"
#include "tests/test_support.h"

namespace stylus::motion {
namespace {

TEST(BvhTest, ReadsMixedOrdersTabsCrlfAndThreeChannelJoints) {
  absl::StatusOr<Motion> m = ReadBvhFile(testing::FixturePath("bvh/good/mixed_orders_crlf.bvh"));
  ASSERT_TRUE(m.ok()) << m.status();
  const Skeleton& sk = m->skeleton;
  ASSERT_EQ(sk.num_joints(), 3);
  EXPECT_EQ(sk.joint(1).name, "left thigh");
  EXPECT_EQ(sk.rotation_order(0).Name(), "XYZ");
  EXPECT_EQ(sk.rotation_order(1).Name(), "YZX");
  EXPECT_EQ(sk.rotation_order(2).Name(), "XZY");
  EXPECT_EQ(sk.num_channels(), 12);
  EXPECT_EQ(m->num_frames, 3);
  EXPECT_NEAR(m->frame_time, 0.008333, 1e-12);
  EXPECT_DOUBLE_EQ(m->frame(2)[3], 1e-3);
  EXPECT_DOUBLE_EQ(m->frame(2)[4], 2.5);
  EXPECT_DOUBLE_EQ(m->frame(2)[5], -32.5);
  ASSERT_EQ(sk.joint(2).end_sites.size(), 1u);
  EXPECT_EQ(sk.joint(2).end_sites[0].y, 30);
  EXPECT_EQ(*sk.Find("spine"), 2);
  EXPECT_FALSE(sk.Find("nope").has_value());
}

TEST(BvhTest, RoundTripReproducesValuesAndForwardKinematics) {
  for (const char* name : {"bvh/good/mixed_orders_crlf.bvh", "bvh/good/three_joint.bvh"}) {
    absl::StatusOr<Motion> m = ReadBvhFile(testing::FixturePath(name));
    ASSERT_TRUE(m.ok()) << m.status();
    absl::StatusOr<Motion> back = ParseBvh(FormatBvh(*m), "formatted");
    ASSERT_TRUE(back.ok()) << back.status();
    EXPECT_TRUE(back->skeleton.SameTopology(m->skeleton))
        << back->skeleton.DescribeMismatch(m->skeleton);
    EXPECT_EQ(back->values, m->values);  // Shortest exact decimals: bit-identical.
    EXPECT_EQ(back->frame_time, m->frame_time);
    EXPECT_LT(MaxPositionDifference(*m, *back), 1e-9);
  }
}

TEST(BvhTest, WriteFileIsAtomicAndReportsUnwritablePaths) {
  absl::StatusOr<Motion> m = ReadBvhFile(testing::FixturePath("bvh/good/three_joint.bvh"));
  ASSERT_TRUE(m.ok());
  const std::string path = ::testing::TempDir() + "/bvh_test_out.bvh";
  ASSERT_TRUE(WriteBvhFile(*m, path).ok());
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  EXPECT_TRUE(ReadBvhFile(path).ok());
  const absl::Status bad = WriteBvhFile(*m, "/nonexistent-dir/x.bvh");
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("/nonexistent-dir/x.bvh"), std::string::npos);
  EXPECT_EQ(ReadBvhFile("/nonexistent-dir/x.bvh").status().code(), absl::StatusCode::kNotFound);
}

struct BadCase {
  std::string file;
  int line;
  std::string expect;
};

std::vector<BadCase> LoadCorpus() {
  std::ifstream in(testing::FixturePath("bvh/bad/expected.txt"));
  std::vector<BadCase> cases;
  std::string text;
  while (std::getline(in, text)) {
    if (text.empty() || text[0] == '#') continue;
    std::vector<std::string> parts = absl::StrSplit(text, absl::MaxSplits(' ', 2));
    cases.push_back({parts[0], std::stoi(parts[1]), parts[2]});
  }
  return cases;
}

TEST(BvhTest, MalformedCorpusGivesSpecificErrorsWithLines) {
  const std::vector<BadCase> cases = LoadCorpus();
  ASSERT_GE(cases.size(), 15u);
  // Every file in the corpus folder is listed, so none goes untested.
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(testing::FixturePath("bvh/bad"))) {
    files += e.path().extension() == ".bvh";
  }
  EXPECT_EQ(files, static_cast<int>(cases.size()));
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.file);
    absl::StatusOr<Motion> m = ReadBvhFile(testing::FixturePath("bvh/bad/" + c.file));
    ASSERT_FALSE(m.ok());
    EXPECT_EQ(m.status().code(), absl::StatusCode::kInvalidArgument);
    const std::string msg(m.status().message());
    EXPECT_NE(msg.find(absl::StrCat(c.file, ":", c.line, ": ")), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.expect), std::string::npos) << msg;
  }
}

TEST(BvhTest, DeepChainParsesWithoutRecursion) {
  const int depth = 5000;
  std::string text =
      "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation "
      "Xrotation Yrotation\n";
  for (int i = 1; i < depth; ++i)
    absl::StrAppend(&text, "JOINT j", i,
                    "\n{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n");
  text += "End Site\n{\nOFFSET 0 1 0\n}\n";
  for (int i = 0; i < depth; ++i) text += "}\n";
  text += "MOTION\nFrames: 1\nFrame Time: 0.04\n";
  for (int c = 0; c < 6 + 3 * (depth - 1); ++c) text += "0 ";
  text += "\n";
  absl::StatusOr<Motion> m = ParseBvh(text, "deep");
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ(m->skeleton.num_joints(), depth);
  const GlobalPose g = ForwardKinematics(m->skeleton, PoseAt(*m, 0));
  EXPECT_NEAR(g.positions.back().y, depth - 1, 1e-9);
  // The writer is iterative too.
  EXPECT_TRUE(ParseBvh(FormatBvh(*m), "deep-again").ok());
}

TEST(BvhTest, JointLimitAndLyingHeaderDoNotAllocate) {
  BvhLimits limits;
  limits.max_joints = 10;
  std::string text =
      "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n";
  for (int i = 1; i < 20; ++i)
    absl::StrAppend(&text, "JOINT j", i, "\n{\nOFFSET 0 1 0\nCHANNELS 0\n");
  absl::StatusOr<Motion> m = ParseBvh(text, "wide", limits);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("more than 10 joints"), std::string::npos);
  // A header claiming ten million frames of a 12-channel rig but holding one row.
  absl::StatusOr<Motion> lying = ParseBvh(
      "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n}\n"
      "MOTION\nFrames: 10000000\nFrame Time: 0.03\n0 0 0\n",
      "lying");
  ASSERT_FALSE(lying.ok());
  EXPECT_NE(lying.status().message().find("truncated"), std::string::npos);
}

TEST(BvhTest, RejectsValueErrorsAnywhereInTheFile) {
  // Fuzz-style: cutting a valid file at every byte never crashes; every cut
  // before the last row's end is an error.
  std::ifstream in(testing::FixturePath("bvh/good/three_joint.bvh"));
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const size_t last_row = text.rfind('\n', text.size() - 2);
  for (size_t cut = 0; cut < text.size(); ++cut) {
    absl::StatusOr<Motion> m = ParseBvh(text.substr(0, cut), "cut");
    if (cut <= last_row) {
      EXPECT_FALSE(m.ok()) << "cut at " << cut;
    }
  }
}

}  // namespace
}  // namespace stylus::motion

namespace stylus::motion {
namespace {

TEST(BvhTest, RandomMutationsNeverCrash) {
  std::ifstream in(testing::FixturePath("bvh/good/mixed_orders_crlf.bvh"), std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  std::mt19937 rng(42);
  const std::string alphabet = "0123456789.-+eE \t\r\n{}#ABCxyzJOINTEnd\x00\xff";
  int rejected = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string s = text;
    const int edits = 1 + trial % 4;
    for (int e = 0; e < edits; ++e) {
      const size_t at = rng() % s.size();
      switch (rng() % 3) {
        case 0:
          s[at] = alphabet[rng() % alphabet.size()];
          break;
        case 1:
          s.erase(at, 1 + rng() % 8);
          break;
        default:
          s.insert(at, 1, alphabet[rng() % alphabet.size()]);
      }
    }
    absl::StatusOr<Motion> m = ParseBvh(s, "mutant");
    if (!m.ok()) {
      ++rejected;
      EXPECT_EQ(m.status().code(), absl::StatusCode::kInvalidArgument);
      EXPECT_EQ(m.status().message().rfind("mutant:", 0), 0u) << m.status();
    } else {
      EXPECT_EQ(m->values.size(), static_cast<size_t>(m->num_frames) * m->skeleton.num_channels());
    }
  }
  EXPECT_GT(rejected, 1000);  // Most mutations break the file.
}

}  // namespace
}  // namespace stylus::motion
