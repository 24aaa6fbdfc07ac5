// Replays every seed of both fuzz corpora through the fuzz target bodies (fuzz_targets.h), so a normal build
// checks in seconds what the fuzzer starts from: the generated model seeds (model_seeds.h), the committed
// glTF seeds (corpus/gltf/, regression inputs included), model regression inputs (corpus/model-regressions/)
// and ../shared/scenes/bad when present. Each must load or be rejected with one nbvh::Error line; "valid_*"
// seeds must load.
#include <algorithm>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "engine/core/log.h"
#include "tests/fuzz/fuzz_targets.h"
#include "tests/fuzz/model_seeds.h"
#include "tests/support/test_support.h"

namespace {

namespace fs = std::filesystem;
using nbvh::fuzz::Outcome;

struct Quiet {
    Quiet() { nbvh::set_log_level(nbvh::LogLevel::quiet); }
    ~Quiet() { nbvh::set_log_level(nbvh::LogLevel::info); }
};

std::vector<uint8_t> read_bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::vector<fs::path> files_under(const fs::path& dir) {
    std::vector<fs::path> out;
    if (!fs::is_directory(dir)) return out;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) out.push_back(e.path());
    std::sort(out.begin(), out.end());
    return out;
}

bool must_load(const std::string& name) { return name.rfind("valid_", 0) == 0; }

// Runs `target` and turns an escaping exception (anything but a handled nbvh::Error) into a test failure.
template <class Target>
void replay(const std::string& name, bool expect_load, Target&& target) {
    SCOPED_TRACE(name);
    try {
        const Outcome o = target();
        if (expect_load) {
            EXPECT_EQ(o, Outcome::loaded) << name << " is a valid seed but was rejected";
        }
    } catch (const std::exception& e) {
        ADD_FAILURE() << name << ": exception other than nbvh::Error escaped: " << e.what();
    }
}

// `self_contained`: the files need no other file (what the fuzzer sees), so valid_* must load from bytes too.
void replay_gltf_files(const std::vector<fs::path>& files, bool self_contained) {
    for (const fs::path& p : files) {
        const std::string name = p.filename().string();
        const std::vector<uint8_t> bytes = read_bytes(p);
        replay(name + " (bytes)", self_contained && must_load(name), [&] { return nbvh::fuzz::gltf_input(bytes); });
        const std::string ext = p.extension().string();
        if (ext == ".gltf" || ext == ".glb")
            replay(name + " (in place)", must_load(name), [&] { return nbvh::fuzz::gltf_file(p); });
    }
}

TEST(FuzzReplay, GeneratedModelSeeds) {
    const Quiet quiet;
    const std::vector<nbvh::fuzz::Seed> seeds = nbvh::fuzz::model_seeds();
    ASSERT_GE(seeds.size(), 10u);
    size_t valid = 0;
    for (const nbvh::fuzz::Seed& s : seeds) {
        valid += must_load(s.name);
        replay(s.name, must_load(s.name), [&] { return nbvh::fuzz::model_input(s.bytes); });
    }
    EXPECT_GE(valid, 3u);
}

TEST(FuzzReplay, ModelRegressionInputs) {
    const Quiet quiet;
    for (const fs::path& p : files_under(nbvh::test::source_dir() / "tests/fuzz/corpus/model-regressions")) {
        const std::vector<uint8_t> bytes = read_bytes(p);
        replay(p.filename().string(), false, [&] { return nbvh::fuzz::model_input(bytes); });
    }
}

TEST(FuzzReplay, CommittedGltfSeeds) {
    const Quiet quiet;
    const std::vector<fs::path> files = files_under(nbvh::test::source_dir() / "tests/fuzz/corpus/gltf");
    ASSERT_GE(files.size(), 3u);
    replay_gltf_files(files, true);
}

TEST(FuzzReplay, SharedBadScenes) {
    NBVH_REQUIRE_SHARED();
    const fs::path bad = nbvh::test::scenes_dir() / "bad";
    if (!fs::is_directory(bad)) GTEST_SKIP() << bad << " not found";
    const Quiet quiet;
    replay_gltf_files(files_under(bad), false);
}

} // namespace
