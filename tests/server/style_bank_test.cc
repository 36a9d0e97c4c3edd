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

// A saved style keeps its code and cadence, not the clip it was encoded from
// (whatever its length, a name costs a few values).
TEST(StyleBankTest, ASavedStyleDoesNotHoldItsClip) {
  StyleBank bank;
  model::StyleCode code{{1, 2}};
  code.cadence = motion::Cadence{motion::Cadence::Source::kSteps, 0.5, 1};
  code.example = std::make_shared<const motion::MovementClip>();
  ASSERT_TRUE(bank.Save("contrastive/v10", "old", code).ok());
  const absl::StatusOr<model::StyleCode> saved = bank.Get("contrastive/v10", "old");
  ASSERT_TRUE(saved.ok());
  EXPECT_EQ(saved->example, nullptr);
  ASSERT_TRUE(saved->cadence.has_value());
  EXPECT_EQ(saved->cadence->period_s, 0.5);
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

TEST(StyleBankTest, ANameSavedOnAnotherModelSaysWhere) {
  StyleBank bank;
  ASSERT_TRUE(bank.Save("contrastive/v10", "old", model::StyleCode{{1, 2}}).ok());
  absl::StatusOr<model::StyleCode> missing = bank.Get("live/v3", "old");
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find(
                "saved names belong to one model; 'old' is saved for contrastive/v10: save it "
                "again on live/v3"),
            absl::string_view::npos)
      << missing.status();
}

}  // namespace
}  // namespace stylus::server
