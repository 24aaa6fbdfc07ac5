// The bodies of the two fuzz targets, shared by the libFuzzer mains (fuzz_model.cpp, fuzz_gltf.cpp) and the
// seed replay unit test (fuzz_replay_test.cpp), so the corpus is replayed through exactly what is fuzzed.
//
// The contract under test (CONVENTIONS.md "Errors and lifetime"): any input either loads, into a result whose
// documented invariants hold, or is rejected with nbvh::Error. Any other exception escapes these functions
// (libFuzzer reports it as a crash; the replay test fails naming the seed); a loaded result that breaks an
// invariant aborts through NBVH_CHECK. Crashes, hangs and huge allocations are caught by the sanitizers and
// libFuzzer's -timeout / -rss_limit_mb.
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>

namespace nbvh::fuzz {

enum class Outcome { loaded, rejected };

// .nbvh model reader: parse_model on the bytes as given, and again with the section and header checksums
// recomputed (so mutations reach the section decoders behind them); whatever loads must give a GPU layout for
// every LoD and asset and survive a serialise / parse round trip unchanged. Also import_official_tree.
// Returns the outcome of parsing the bytes as given.
Outcome model_input(std::span<const uint8_t> bytes);

// glTF loader: load_gltf takes a path (it and tinygltf read files), so the bytes are written to a private
// temporary directory of this process, as in.glb when they start with the GLB magic "glTF", else as
// in.gltf, and loaded from there (relative URIs resolve inside that directory).
Outcome gltf_input(std::span<const uint8_t> bytes);
// The same checks on a file in place (the replay test uses it so external .bin/.png files resolve).
Outcome gltf_file(const std::filesystem::path& path);

} // namespace nbvh::fuzz
