// Embedded SPIR-V of every compute shader in shaders/passes and shaders/tests.
#pragma once
#include <cstdint>
#include <span>
#include <string_view>

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

} // namespace nbvh::shaders
