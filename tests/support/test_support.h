// Helpers shared by all test executables.
#pragma once
#include <filesystem>
#include <optional>
#include <string>

namespace nbvh::test {

// ../shared beside the checkout (CI and developers have it; a fresh user clone may not).
// Returns nullopt when absent; use NBVH_REQUIRE_SHARED() to skip a test cleanly then.
std::optional<std::filesystem::path> shared_dir();
std::filesystem::path scenes_dir(); // shared_dir()/scenes (call after NBVH_REQUIRE_SHARED)
std::filesystem::path source_dir();
std::filesystem::path binary_dir();
// A fresh empty directory under the build tree for a test's outputs.
std::filesystem::path temp_dir(const std::string& name);

} // namespace nbvh::test

#define NBVH_REQUIRE_SHARED()                                                                     \
    do {                                                                                          \
        if (!::nbvh::test::shared_dir())                                                          \
            GTEST_SKIP() << "../shared (scenes, reference data) not found beside the checkout";  \
    } while (0)
