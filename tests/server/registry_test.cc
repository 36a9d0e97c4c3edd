// server/registry: the packages a server hosts, by name and version.
#include "server/registry.h"

#include <filesystem>

#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace stylus {
namespace {

// A bare model name picks its highest version by number, not by spelling:
// v10 after v9 and v2, and numbered versions after other names such as
// "dev" (every package here is cyclic/v1, linked).
TEST(RegistryTest, BareNameTakesTheHighestVersionByNumber) {
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() / "stylus_registry_versions";
  fs::remove_all(root);
  fs::create_directories(root / "cyclic");
  const fs::path v1 = fs::path(testing::SourceDir()) / "models/cyclic/v1";
  for (const char* v : {"dev", "v2", "v9", "v10"})
    fs::create_directory_symlink(v1, root / "cyclic" / v);
  auto registry = server::ModelRegistry::Create(root.string(), "");
  ASSERT_TRUE(registry.ok()) << registry.status();
  auto bare = (*registry)->Get("cyclic");
  ASSERT_TRUE(bare.ok()) << bare.status();
  EXPECT_EQ(bare->id, "cyclic/v10");
  ASSERT_TRUE((*registry)->Unload("cyclic/v10").ok());
  EXPECT_EQ((*registry)->Get("cyclic")->id, "cyclic/v9");
  ASSERT_TRUE((*registry)->Unload("cyclic/v9").ok());
  ASSERT_TRUE((*registry)->Unload("cyclic/v2").ok());
  EXPECT_EQ((*registry)->Get("cyclic")->id, "cyclic/dev");
  fs::remove_all(root);
}

}  // namespace
}  // namespace stylus
