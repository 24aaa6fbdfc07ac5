#include "engine/render/texture_path.h"

#include <algorithm>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh::render {

namespace {

// Largest image edge the renderer creates (vk::Image; the glTF loader skips larger images).
constexpr uint32_t MAX_IMAGE_EDGE = 16384;
// Allocations beside the texture images (buffers of the passes, neural stage, staging, timers).
constexpr uint32_t OTHER_ALLOCATIONS = 128;

const char* request_name(TexturePathRequest r) {
    switch (r) {
    case TexturePathRequest::automatic: return "auto";
    case TexturePathRequest::buffer: return "buffer";
    case TexturePathRequest::array: return "array";
    }
    return "?";
}

} // namespace

TexturePathRequest parse_texture_path(std::string_view text) {
    if (text == "auto") return TexturePathRequest::automatic;
    if (text == "buffer") return TexturePathRequest::buffer;
    if (text == "array") return TexturePathRequest::array;
    throw Error(strfmt("--texture-path must be auto, buffer or array (got '%.*s')", int(text.size()), text.data()));
}

const char* texture_path_name(TexturePath p) {
    switch (p) {
    case TexturePath::none: return "none";
    case TexturePath::buffer: return "buffer";
    case TexturePath::array: return "array";
    }
    return "?";
}

TextureCaps texture_caps(const vk::DeviceFeatures& f) {
    TextureCaps c;
    c.runtime_descriptor_array = f.runtime_descriptor_array;
    c.sampled_image_array_nonuniform = f.sampled_image_array_nonuniform;
    c.max_sampled_images = f.max_sampled_images;
    c.max_per_stage_resources = f.max_per_stage_resources;
    c.max_image_dimension_2d = f.max_image_dimension_2d;
    c.max_memory_allocations = f.max_memory_allocations;
    c.max_storage_buffer_range = f.max_storage_buffer_range;
    return c;
}

std::string texture_array_unavailable(const TextureCaps& c) {
    std::string missing;
    if (!c.runtime_descriptor_array) missing = "runtimeDescriptorArray";
    if (!c.sampled_image_array_nonuniform)
        missing += std::string(missing.empty() ? "" : " and ") + "shaderSampledImageArrayNonUniformIndexing";
    return missing.empty() ? "" : "the device lacks " + missing;
}

TexturePath choose_texture_path(const TextureCaps& caps, bool scene_textures, TexturePathRequest request) {
    const std::string why_not = texture_array_unavailable(caps);
    if (request == TexturePathRequest::array && !why_not.empty())
        throw Error("--texture-path array: " + why_not + " (descriptor indexing); use --texture-path buffer");
    if (!scene_textures) return TexturePath::none;
    if (request == TexturePathRequest::buffer) return TexturePath::buffer;
    return why_not.empty() ? TexturePath::array : TexturePath::buffer;
}

uint64_t texel_budget_bytes(uint64_t range) {
    const uint64_t r = range ? range : (128ull << 20);
    return std::clamp<uint64_t>(r / 4 * 3, 96ull << 20, 1ull << 30);
}

bool texture_valid(const Texture& t) {
    return t.width > 0 && t.height > 0 && t.rgba8.size() >= size_t(t.width) * t.height * 4;
}

TexelBufferPlan plan_texel_buffer(const std::vector<Texture>& textures, uint64_t budget) {
    TexelBufferPlan p;
    p.halvings.assign(textures.size(), 0);
    std::vector<uint32_t> w(textures.size(), 1), h(textures.size(), 1);
    for (size_t i = 0; i < textures.size(); ++i)
        if (texture_valid(textures[i])) {
            w[i] = textures[i].width;
            h[i] = textures[i].height;
        }
    auto bytes = [&](size_t i) { return uint64_t(w[i]) * h[i] * 4; };
    for (size_t i = 0; i < textures.size(); ++i) p.bytes += bytes(i);
    while (p.bytes > budget && !textures.empty()) {
        size_t largest = 0;
        for (size_t i = 1; i < textures.size(); ++i)
            if (bytes(i) > bytes(largest)) largest = i;
        if (w[largest] <= 1 && h[largest] <= 1) break;
        p.bytes -= bytes(largest);
        w[largest] = std::max(1u, w[largest] / 2);
        h[largest] = std::max(1u, h[largest] / 2);
        p.bytes += bytes(largest);
        ++p.halvings[largest];
        ++p.total_halvings;
    }
    return p;
}

void check_texture_array_limits(const TextureCaps& c, const std::vector<Texture>& textures, uint32_t other_bindings) {
    const uint64_t n = std::max<size_t>(textures.size(), 1);
    if (n > c.max_sampled_images)
        throw Error(strfmt("texture array: the scene has %llu textures, more than the %u sampled images this device "
                           "allows per pipeline (maxDescriptorSet*/maxPerStageDescriptor* samplers and sampled "
                           "images); use --texture-path buffer", (unsigned long long)n, c.max_sampled_images));
    if (n + other_bindings > c.max_per_stage_resources)
        throw Error(strfmt("texture array: %llu textures and %u buffers exceed the device's %u resources per stage "
                           "(maxPerStageResources); use --texture-path buffer", (unsigned long long)n, other_bindings,
                           c.max_per_stage_resources));
    if (n + OTHER_ALLOCATIONS > c.max_memory_allocations)
        throw Error(strfmt("texture array: %llu textures (one allocation each) exceed the device's %u memory "
                           "allocations (maxMemoryAllocationCount); use --texture-path buffer",
                           (unsigned long long)n, c.max_memory_allocations));
    const uint32_t edge = std::min(c.max_image_dimension_2d, MAX_IMAGE_EDGE);
    for (const Texture& t : textures)
        if (texture_valid(t) && (t.width > edge || t.height > edge))
            throw Error(strfmt("texture array: texture '%s' is %ux%u, larger than the device's %u texels per edge "
                               "(maxImageDimension2D); use --texture-path buffer", t.name.c_str(), t.width, t.height,
                               edge));
}

TexturePlan plan_textures(const TextureCaps& caps, const Scene& scene, bool scene_textures,
                          TexturePathRequest request, uint32_t other_bindings) {
    TexturePlan p;
    p.path = choose_texture_path(caps, scene_textures, request);
    const std::string why_not = texture_array_unavailable(caps);
    if (p.path == TexturePath::none) {
        p.why = "no material of the scene samples a texture";
        return p;
    }
    p.textures = uint32_t(scene.textures.size());
    if (p.path == TexturePath::array) {
        check_texture_array_limits(caps, scene.textures, other_bindings);
        for (const Texture& t : scene.textures) p.bytes += texture_valid(t) ? uint64_t(t.width) * t.height * 4 : 4;
        p.why = strfmt("--texture-path %s: the device has descriptor indexing", request_name(request));
        return p;
    }
    p.budget = texel_budget_bytes(caps.max_storage_buffer_range);
    const TexelBufferPlan b = plan_texel_buffer(scene.textures, p.budget);
    p.bytes = b.bytes;
    p.halvings = b.total_halvings;
    p.why = request == TexturePathRequest::buffer ? "--texture-path buffer" : "--texture-path auto: " + why_not;
    return p;
}

std::string describe(const TexturePlan& p) {
    const double mib = double(p.bytes) / double(1u << 20);
    switch (p.path) {
    case TexturePath::none: return "none (" + p.why + ")";
    case TexturePath::buffer:
        return strfmt("buffer: %u texture%s in one RGBA8 storage buffer, %.1f MiB of %.0f MiB budget, %u halving%s "
                      "(%s)", p.textures, p.textures == 1 ? "" : "s", mib, double(p.budget) / double(1u << 20),
                      p.halvings, p.halvings == 1 ? "" : "s", p.why.c_str());
    case TexturePath::array:
        return strfmt("array: %u image%s in one sampler2D[] binding, %.1f MiB, full size (%s)", p.textures,
                      p.textures == 1 ? "" : "s", mib, p.why.c_str());
    }
    return "?";
}

} // namespace nbvh::render
