// server/registry: the packages a server hosts, by name and version.
#include "server/registry.h"

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>

#include "gtest/gtest.h"
#include "model/package.h"
#include "tests/test_support.h"

namespace stylus {
namespace {

namespace fs = std::filesystem;

// A fresh model directory under /tmp holding cyclic/<version> for each of
// `versions`, every one a link to the shipped cyclic/v1.
fs::path CyclicVersions(const std::string& name, std::initializer_list<const char*> versions) {
  const fs::path root = fs::temp_directory_path() / name;
  fs::remove_all(root);
  fs::create_directories(root / "cyclic");
  const fs::path v1 = fs::path(testing::SourceDir()) / "models/cyclic/v1";
  for (const char* v : versions) fs::create_directory_symlink(v1, root / "cyclic" / v);
  return root;
}

// A bare model name picks its highest version by number, not by spelling:
// v10 after v9 and v2, and numbered versions after other names such as
// "dev" (every package here is cyclic/v1, linked).
TEST(RegistryTest, BareNameTakesTheHighestVersionByNumber) {
  const fs::path root = CyclicVersions("stylus_registry_versions", {"dev", "v2", "v9", "v10"});
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

// The default package: the --default-model flag's, else the one the model
// directory's DEFAULT file names, else the first in sorted order; a
// default that names no package, or a DEFAULT file that does not name
// exactly one, refuses to start with the file named.
TEST(RegistryTest, DefaultComesFromTheFlagThenTheDefaultFileThenSortedOrder) {
  const fs::path root = CyclicVersions("stylus_registry_default", {"v1", "v2", "v3"});
  const auto write_default = [&](const std::string& text) {
    std::ofstream(root / model::kDefaultPackageFile) << text;
  };
  const auto default_of = [&](const std::string& flag) -> std::string {
    auto registry = server::ModelRegistry::Create(root.string(), flag);
    if (!registry.ok()) return std::string(registry.status().message());
    return (*registry)->default_id();
  };
  EXPECT_EQ(default_of(""), "cyclic/v1");  // no file: sorted order
  write_default("# the shipped default\ncyclic/v2\n\n");
  EXPECT_EQ(default_of(""), "cyclic/v2");
  EXPECT_EQ(default_of("cyclic/v3"), "cyclic/v3");  // the flag wins
  auto registry = server::ModelRegistry::Create(root.string(), "");
  ASSERT_TRUE(registry.ok());
  EXPECT_EQ((*registry)->Get("")->id, "cyclic/v2");

  write_default("cyclic/v7\n");
  auto missing = server::ModelRegistry::Create(root.string(), "");
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("'cyclic/v7'"), std::string::npos);
  EXPECT_NE(missing.status().message().find((root / "DEFAULT").string()), std::string::npos)
      << missing.status();
  auto flagged = server::ModelRegistry::Create(root.string(), "cyclic/v9");
  EXPECT_NE(flagged.status().message().find("--default-model"), std::string::npos)
      << flagged.status();

  write_default("cyclic/v1\ncyclic/v2\n");
  auto two = server::ModelRegistry::Create(root.string(), "");
  EXPECT_EQ(two.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(two.status().message().find("found 2"), std::string::npos) << two.status();
  fs::remove_all(root);
}

// The shipped model directory names its default, and it is served.
TEST(RegistryTest, TheShippedDefaultFileNamesAShippedPackage) {
  const std::string models = testing::SourceDir() + "/models";
  auto registry = server::ModelRegistry::Create(models, "");
  ASSERT_TRUE(registry.ok()) << registry.status();
  EXPECT_EQ((*registry)->default_id(), testing::DefaultPackage());
}

}  // namespace
}  // namespace stylus
