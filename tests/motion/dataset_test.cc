#include "motion/dataset.h"

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace stylus::motion {
namespace {

TEST(DatasetTest, ParsesLabelsFromFileNames) {
  std::optional<ClipLabel> l = ParseClipName("/x/y/dataset-1_walk-back_not-confident_003.bvh");
  ASSERT_TRUE(l.has_value());
  EXPECT_EQ(l->dataset, "dataset-1");
  EXPECT_EQ(l->content, "walk-back");
  EXPECT_EQ(l->style, "not-confident");
  EXPECT_EQ(l->take, 3);
  EXPECT_FALSE(ParseClipName("walk.bvh").has_value());
  EXPECT_FALSE(ParseClipName("dataset-1_walk_old_001.txt").has_value());
  EXPECT_FALSE(ParseClipName("dataset-1_walk_old_x.bvh").has_value());
}

// A small fake dataset: empty files are enough for the index.
std::string MakeTree(const std::string& name, const std::vector<std::string>& files) {
  const std::string dir = ::testing::TempDir() + "/" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  for (const std::string& f : files) std::ofstream(dir + "/" + f) << "";
  return dir;
}

TEST(DatasetTest, SplitIsDeterministicStratifiedAndIndependentOfOtherFiles) {
  std::vector<std::string> files;
  for (const char* style : {"old", "young"}) {
    for (int take = 1; take <= 10; ++take) {
      files.push_back(std::string("dataset-2_walk_") + style + "_" + (take < 10 ? "00" : "0") +
                      std::to_string(take) + ".bvh");
    }
  }
  const std::string dir = MakeTree("ds_a", files);
  absl::StatusOr<DatasetIndex> a = IndexDataset({dir});
  ASSERT_TRUE(a.ok()) << a.status();
  EXPECT_EQ(a->Split(true).size(), 2u);  // One take of each (content, style) of ten.
  std::set<std::string> held_styles;
  for (const ClipEntry* c : a->Split(true)) held_styles.insert(c->label.style);
  EXPECT_EQ(held_styles.size(), 2u);

  // Same answer again, and with unrelated files added.
  files.push_back("dataset-2_run_old_001.bvh");
  files.push_back("notes.bvh");
  const std::string dir2 = MakeTree("ds_b", files);
  absl::StatusOr<DatasetIndex> b = IndexDataset({dir2});
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b->skipped.size(), 1u);
  std::set<std::string> held_a, held_b;
  for (const ClipEntry* c : a->Split(true))
    held_a.insert(std::filesystem::path(c->path).filename());
  for (const ClipEntry* c : b->Split(true))
    held_b.insert(std::filesystem::path(c->path).filename());
  EXPECT_EQ(held_a, held_b);

  // Another seed picks other takes.
  absl::StatusOr<DatasetIndex> c = IndexDataset({dir}, {0.1, 12345});
  std::set<std::string> held_c;
  for (const ClipEntry* e : c->Split(true))
    held_c.insert(std::filesystem::path(e->path).filename());
  EXPECT_NE(held_a, held_c);
}

TEST(DatasetTest, MissingDirectoryIsNotFound) {
  EXPECT_EQ(IndexDataset({"/no/such/dir"}).status().code(), absl::StatusCode::kNotFound);
}

TEST(DatasetTest, BandaiSplitHoldsOutAboutTenPercentCoveringEveryContentAndStyle) {
  STYLUS_REQUIRE_BANDAI(dir);
  absl::StatusOr<DatasetIndex> index = IndexDataset({dir});
  ASSERT_TRUE(index.ok());
  const size_t total = index->clips.size(), test = index->Split(true).size();
  EXPECT_EQ(total, 874u);
  EXPECT_GT(test, total * 8 / 100);
  EXPECT_LT(test, total * 14 / 100);
  // Every content and every style with at least 5 clips has some held out.
  std::map<std::string, int> content_clips, style_clips;
  for (const ClipEntry& c : index->clips)
    ++content_clips[c.label.content], ++style_clips[c.label.style];
  std::set<std::string> contents, styles;
  for (const ClipEntry* c : index->Split(true))
    contents.insert(c->label.content), styles.insert(c->label.style);
  for (const auto& [name, n] : content_clips) EXPECT_TRUE(n < 5 || contents.count(name)) << name;
  for (const auto& [name, n] : style_clips) EXPECT_TRUE(n < 5 || styles.count(name)) << name;
  absl::StatusOr<DatasetIndex> again = IndexDataset({dir + "/dataset-2", dir + "/dataset-1"});
  ASSERT_TRUE(again.ok());
  for (size_t i = 0; i < total; ++i) EXPECT_EQ(again->clips[i].test, index->clips[i].test);
}

TEST(DatasetTest, StableHashIsFixed) {
  EXPECT_EQ(StableHash(""), 1469598103934665603ull);
  EXPECT_NE(StableHash("a"), StableHash("b"));
  EXPECT_NE(StableHash("a", 1), StableHash("a", 2));
}

}  // namespace
}  // namespace stylus::motion
