// Embedded SPIR-V of every compute shader in shaders/passes and shaders/tests.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace nbvh::shaders {

namespace detail {
struct Entry {
    const char* name;
    const uint32_t* words;
    const uint32_t* count;
};
extern const Entry TABLE[];
} // namespace detail

// SPIR-V words of the shader at `path` relative to shaders/ (e.g. "passes/trace.comp"); throws
// nbvh::Error when no such shader was compiled in.
std::span<const uint32_t> find(std::string_view path);

bool contains(std::string_view path);

// The shader a pass runs as in a variant ("texture_array": compiled with -DNB_TEXTURE_ARRAY=1,
// engine/render/texture_path.h): "passes/shade.comp#texture_array" where it was compiled (passes that
// sample textures, shaders/CMakeLists.txt), else `path` itself (the variant would be the same shader).
std::string variant(std::string_view path, std::string_view variant);

// Every embedded name, variants included (tests).
std::vector<std::string_view> names();

} // namespace nbvh::shaders
