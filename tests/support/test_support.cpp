#include "tests/support/test_support.h"

#include <cstdlib>

namespace nbvh::test {
namespace fs = std::filesystem;

std::optional<fs::path> shared_dir() {
    if (const char* env = std::getenv("NBVH_SHARED_DIR"); env && fs::is_directory(env)) return fs::path(env);
    fs::path p = fs::path(NBVH_SOURCE_DIR).parent_path() / "shared";
    if (fs::is_directory(p / "scenes")) return p;
    return std::nullopt;
}
fs::path scenes_dir() { return *shared_dir() / "scenes"; }
fs::path source_dir() { return NBVH_SOURCE_DIR; }
fs::path binary_dir() { return NBVH_BINARY_DIR; }

fs::path temp_dir(const std::string& name) {
    fs::path p = fs::path(NBVH_BINARY_DIR) / "test_tmp" / name;
    fs::remove_all(p);
    fs::create_directories(p);
    return p;
}

} // namespace nbvh::test
