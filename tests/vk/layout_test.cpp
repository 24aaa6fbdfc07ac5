// Layout test of every GPU-shared struct (CONVENTIONS.md "One definition of everything the GPU
// shares"): shaders/tests/layout.comp fills element 0 and 1 of each struct listed in
// shaders/tests/layout_fields.h with distinct values and stores them with GLSL's scalar layout; the
// C++ build of the same fill functions must produce the same bytes, field by field.
#include "engine/vk/kernel_runner.h"
#include "shaders/tests/layout_fields.h"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <string>
#include <vector>

using namespace nbvh::vk;

namespace {

template <class F> bool same_bytes(const F& a, const F& b) { return std::memcmp(&a, &b, sizeof(F)) == 0; }

// Every 4-byte word non-zero: the field list covered every member (fill values are never 0).
template <class T> int zero_words(const T& s) {
    static_assert(sizeof(T) % 4 == 0, "shared structs are made of 4-byte scalars");
    uint32_t words[sizeof(T) / 4];
    std::memcpy(words, &s, sizeof(T));
    int zeros = 0;
    for (uint32_t w : words) zeros += w == 0u;
    return zeros;
}

struct LayoutResults {
    std::vector<std::unique_ptr<Buffer>> buffers; // one per struct, in binding order
    int validation_messages = 0;
};

// Runs layout.comp once with one output buffer per struct (sized from the C++ sizeof).
LayoutResults& results() {
    static LayoutResults r = [] {
        static KernelRunner run; // outlives the buffers (function statics die in reverse order)
        LayoutResults out;
        std::vector<const Buffer*> bindings;
#define NB_MAKE_BUFFER(T, binding)                                                                       \
    out.buffers.push_back(std::make_unique<Buffer>(run.output<T>(NB_LAYOUT_ELEMENTS, #T)));              \
    EXPECT_EQ(out.buffers.size() - 1, size_t(binding)) << "NB_LAYOUT_STRUCTS bindings must be 0, 1, 2, ...";
        NB_LAYOUT_STRUCTS(NB_MAKE_BUFFER)
#undef NB_MAKE_BUFFER
        for (auto& b : out.buffers) bindings.push_back(b.get());
        run.dispatch({.shader = "tests/layout.comp", .bindings = bindings, .items = NB_LAYOUT_ELEMENTS,
                      .group_size = 1});
        out.validation_messages = run.validation_messages();
        return out;
    }();
    return r;
}

} // namespace

TEST(VkLayout, NoValidationMessages) { EXPECT_EQ(results().validation_messages, 0); }

// One test per struct: TEST(VkLayout, GpuFoo).
#define NB_CHECK_FIELD(f)                                                                          \
    EXPECT_TRUE(same_bytes(gpu[e].f, cpu.f)) << "field '" #f "' of element " << e                  \
                                             << " differs between GLSL and C++ layout";
#define NB_LAYOUT_TEST(T, binding)                                                                 \
    TEST(VkLayout, T) {                                                                            \
        const Buffer& buffer = *results().buffers.at(binding);                                     \
        std::vector<T> gpu = buffer.download<T>(NB_LAYOUT_ELEMENTS);                                \
        for (uint32_t e = 0; e < NB_LAYOUT_ELEMENTS; ++e) {                                        \
            T cpu;                                                                                 \
            std::memset(&cpu, 0, sizeof(T));                                                       \
            nb_layout_fill_##T(cpu, e);                                                            \
            EXPECT_EQ(zero_words(cpu), 0) << "NB_LAYOUT_FIELDS_" #T " misses a field";            \
            NB_LAYOUT_FIELDS_##T(NB_CHECK_FIELD)                                                   \
            EXPECT_TRUE(same_bytes(gpu[e], cpu)) << #T " element " << e << " differs (size or padding)"; \
        }                                                                                          \
    }
NB_LAYOUT_STRUCTS(NB_LAYOUT_TEST)
