// server/style_bank: named style codes, per model.
#include "server/style_bank.h"

#include "gtest/gtest.h"

namespace stylus::server {
namespace {

TEST(StyleBankTest, NamesAreKeptPerModel) {
  StyleBank bank;
  ASSERT_TRUE(bank.Save("contrastive/v8", "old", model::StyleCode{{1, 2}}).ok());
  ASSERT_TRUE(bank.Save("cyclic/v2", "old", model::StyleCode{{3}}).ok());
  EXPECT_EQ(bank.Get("contrastive/v8", "old")->values, (std::vector<float>{1, 2}));
  EXPECT_EQ(bank.Get("cyclic/v2", "old")->values, (std::vector<float>{3}));
  // Saving again replaces the code.
  ASSERT_TRUE(bank.Save("cyclic/v2", "old", model::StyleCode{{4}}).ok());
  EXPECT_EQ(bank.Get("cyclic/v2", "old")->values, (std::vector<float>{4}));
}

TEST(StyleBankTest, UnknownNamesAndBadNamesAreErrors) {
  StyleBank bank;
  absl::StatusOr<model::StyleCode> missing = bank.Get("contrastive/v8", "young");
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("young"), absl::string_view::npos);
  EXPECT_NE(missing.status().message().find("contrastive/v8"), absl::string_view::npos);
  EXPECT_EQ(bank.Save("m", "", {}).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(bank.Save("m", std::string(201, 'x'), {}).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(bank.Save("m", std::string(200, 'x'), {}).ok());
}

}  // namespace
}  // namespace stylus::server
