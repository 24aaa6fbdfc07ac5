// RAII 2D images and samplers. Compute-only: every image lives in VK_IMAGE_LAYOUT_GENERAL after
// creation (valid for sampling and for storage access in compute shaders), so passes never track
// layouts; only the upload/download copies transition around themselves.
#pragma once
#include "context.h"

#include <string>

namespace nbvh::vk {

enum class ImageFormat {
    rgba8,      // VK_FORMAT_R8G8B8A8_UNORM (linear data: normal maps, roughness/metallic)
    rgba8_srgb, // VK_FORMAT_R8G8B8A8_SRGB (base color, emission); sampled only (no storage)
    rgba32f,    // VK_FORMAT_R32G32B32A32_SFLOAT (film, environment maps)
    r32f,       // VK_FORMAT_R32_SFLOAT
};
VkFormat to_vk(ImageFormat format);
uint32_t texel_bytes(ImageFormat format);

enum ImageUsage : uint32_t {
    image_sampled = 1u, // combined image sampler
    image_storage = 2u, // storage image (imageLoad/imageStore)
};

class Image {
public:
    Image() = default;
    Image(const Context& ctx, uint32_t width, uint32_t height, ImageFormat format, uint32_t usage,
          const std::string& name = "image");
    ~Image();
    Image(Image&& other) noexcept;
    Image& operator=(Image&& other) noexcept;
    Image(const Image&) = delete;
    Image& operator=(const Image&) = delete;

    // Tightly packed rows of width * texel_bytes(format) bytes; blocking.
    void upload(const void* texels, size_t bytes);
    void download(void* texels, size_t bytes) const;

    VkImage handle() const { return image_; }
    VkImageView view() const { return view_; }
    uint32_t width() const { return width_; }
    uint32_t height() const { return height_; }
    ImageFormat format() const { return format_; }
    uint32_t usage() const { return usage_; }
    const std::string& name() const { return name_; }
    uint64_t memory_bytes() const { return memory_bytes_; } // size of its allocation
    explicit operator bool() const { return image_ != VK_NULL_HANDLE; }

private:
    void destroy();
    void copy(bool to_image, VkBuffer staging) const;
    const Context* ctx_ = nullptr;
    VkImage image_ = VK_NULL_HANDLE;
    VkImageView view_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    uint32_t width_ = 0, height_ = 0;
    ImageFormat format_ = ImageFormat::rgba8;
    uint32_t usage_ = 0;
    uint64_t memory_bytes_ = 0;
    std::string name_;
};

struct SamplerDesc {
    bool linear = true;          // bilinear filtering (no mipmaps)
    bool repeat = true;          // wrap; false = clamp to edge
};

class Sampler {
public:
    Sampler() = default;
    Sampler(const Context& ctx, const SamplerDesc& desc = {});
    ~Sampler();
    Sampler(Sampler&& other) noexcept;
    Sampler& operator=(Sampler&& other) noexcept;
    Sampler(const Sampler&) = delete;
    Sampler& operator=(const Sampler&) = delete;
    VkSampler handle() const { return sampler_; }

private:
    const Context* ctx_ = nullptr;
    VkSampler sampler_ = VK_NULL_HANDLE;
};

} // namespace nbvh::vk
