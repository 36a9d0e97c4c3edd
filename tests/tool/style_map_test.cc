#include "tool/style_map.h"

#include "gtest/gtest.h"

namespace stylus::model {
namespace {

size_t Count(const std::string& s, const std::string& what) {
  size_t n = 0;
  for (size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}

TEST(StyleMapTest, DrawsEveryPointAndALegendEntryPerLabel) {
  std::vector<StylePoint> points;
  for (int i = 0; i < 9; ++i) {
    std::vector<float> code(5, 0.f);
    code[i % 3] = 10.f + i;  // Three separated groups.
    points.push_back({i % 3 == 0 ? "old" : (i % 3 == 1 ? "proud" : "tired"), code});
  }
  absl::StatusOr<std::string> svg = StyleMapSvg(points, "t");
  ASSERT_TRUE(svg.ok()) << svg.status();
  EXPECT_EQ(Count(*svg, "<circle"), 9u + 3u);
  EXPECT_EQ(Count(*svg, ">proud<"), 1u);
  EXPECT_EQ(svg->find("nan"), std::string::npos);
}

TEST(StyleMapTest, RejectsTooFewOrRaggedCodes) {
  EXPECT_FALSE(StyleMapSvg({{"a", {1}}, {"b", {2}}}, "t").ok());
  EXPECT_FALSE(StyleMapSvg({{"a", {1, 2}}, {"b", {2}}, {"c", {3, 4}}}, "t").ok());
}

}  // namespace
}  // namespace stylus::model
