#include "bridge/bvh_broadcast.h"

#include <string>

#include "gtest/gtest.h"
#include "motion/bvh.h"

namespace stylus::bridge {
namespace {

TEST(BvhBroadcastTest, TextFramesArriveInAnyPieces) {
  BroadcastTextReader reader;
  const std::string stream = "0 Avatar00 1 2.5 -3 ||\n1 Avatar01 4 5 6 ||\n0 Avatar00 7 8 9 ||\n";
  std::vector<BroadcastFrame> frames;
  for (char c : stream) {  // One byte at a time: TCP may split anywhere.
    for (BroadcastFrame& f : reader.Feed(std::string(1, c))) frames.push_back(std::move(f));
  }
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].avatar_index, 0);
  EXPECT_EQ(frames[0].avatar_name, "Avatar00");
  EXPECT_EQ(frames[0].values, (std::vector<double>{1, 2.5, -3}));
  EXPECT_EQ(frames[1].avatar_name, "Avatar01");
  EXPECT_EQ(frames[2].values, (std::vector<double>{7, 8, 9}));
  EXPECT_EQ(reader.malformed(), 0);
}

TEST(BvhBroadcastTest, BadTextFramesAreCountedAndSkipped) {
  BroadcastTextReader reader;
  const std::string long_name(65, 'n');  // Names are the sender's: 64 bytes at most.
  auto frames = reader.Feed("0 Avatar00 1 x 3 ||\nAvatar00 1 2 ||\n0 Avatar00 nan 1 ||\n0 " +
                            long_name + " 1 ||\n0 A 1 2 ||");
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].avatar_name, "A");
  EXPECT_EQ(reader.malformed(), 4);
  // Text with no "||" cannot grow the reader past its bound.
  const std::string junk(BroadcastTextReader::kMaxFrameBytes / 2, '1');
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(reader.Feed(junk).empty());
  EXPECT_GE(reader.malformed(), 2);
  // The next "||" ends what is left of the junk; the frame after it reads.
  EXPECT_TRUE(reader.Feed("||").empty());
  EXPECT_EQ(reader.Feed("2 B 9 ||").size(), 1u);
}

TEST(BvhBroadcastTest, TextFormatReadsBack) {
  BroadcastFrame f{3, "Hero", {0.25, -12.5, 1e-3}, -1};
  BroadcastTextReader reader;
  auto back = reader.Feed(FormatBroadcastText(f));
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].avatar_index, 3);
  EXPECT_EQ(back[0].avatar_name, "Hero");
  EXPECT_EQ(back[0].values, f.values);
}

TEST(BvhBroadcastTest, BinaryFramesRoundTripAndForeignDatagramsAreRefused) {
  BroadcastFrame f{1, "Avatar01", {1.5, -2, 3.25, 90}, 77};
  const std::string d = FormatBroadcastBinary(f, true);
  ASSERT_EQ(d.size(), 64u + 16u);
  EXPECT_EQ(static_cast<unsigned char>(d[0]), 0xFF);
  EXPECT_EQ(static_cast<unsigned char>(d[1]), 0xDD);
  absl::StatusOr<BroadcastFrame> back = ParseBroadcastBinary(d);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->avatar_index, 1);
  EXPECT_EQ(back->avatar_name, "Avatar01");
  EXPECT_EQ(back->frame_index, 77);
  EXPECT_EQ(back->values, f.values);
  EXPECT_NE(ParseBroadcastBinary(d.substr(0, 70)).status().message().find("says 4 values"),
            std::string::npos);
  EXPECT_NE(ParseBroadcastBinary("hello").status().message().find("64-byte header"),
            std::string::npos);
  std::string foreign = d;
  foreign[0] = 'C';
  EXPECT_NE(ParseBroadcastBinary(foreign).status().message().find("0xDDFF"), std::string::npos);
  // A reference bone's six values come first when byte 9 says so.
  BroadcastFrame r{0, "A", {9, 9, 9, 9, 9, 9, 1, 2, 3}, 0};
  std::string with_reference = FormatBroadcastBinary(r, false);
  with_reference[9] = 1;
  back = ParseBroadcastBinary(with_reference);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->values, (std::vector<double>{1, 2, 3}));
}

TEST(BvhBroadcastTest, ValuesWithOrWithoutDisplacementBecomeTheFilesRow) {
  const char* kFile =
      "HIERARCHY\nROOT Hips\n{\n OFFSET 0 90 0\n CHANNELS 6 Xposition Yposition Zposition "
      "Zrotation "
      "Xrotation Yrotation\n JOINT Spine\n {\n  OFFSET 0 10 0\n  CHANNELS 3 Zrotation Xrotation "
      "Yrotation\n  End Site\n  {\n   OFFSET 0 10 0\n  }\n }\n}\nMOTION\nFrames: 1\nFrame Time: "
      "0.0166667\n0 90 0 0 0 0 0 0 0\n";
  absl::StatusOr<motion::Motion> m = motion::ParseBvh(kFile, "stage.bvh");
  ASSERT_TRUE(m.ok()) << m.status();
  const motion::Skeleton& sk = m->skeleton;
  // As the file has it: 9 values.
  auto row = BroadcastRow(sk, {1, 2, 3, 4, 5, 6, 7, 8, 9});
  ASSERT_TRUE(row.ok());
  EXPECT_EQ(*row, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
  // With displacement: six per joint; the spine's position is dropped.
  row = BroadcastRow(sk, {1, 2, 3, 4, 5, 6, 0, 10, 0, 7, 8, 9});
  ASSERT_TRUE(row.ok());
  EXPECT_EQ(*row, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
  row = BroadcastRow(sk, {1, 2, 3});
  ASSERT_FALSE(row.ok());
  EXPECT_NE(
      row.status().message().find("a frame of 3 values, but the skeleton file has 9 channels"),
      std::string::npos)
      << row.status();
}

}  // namespace
}  // namespace stylus::bridge
