#include "image.h"

#include "buffer.h"
#include "engine/core/log.h"

#include <cstring>
#include <utility>

namespace nbvh::vk {

VkFormat to_vk(ImageFormat f) {
    switch (f) {
    case ImageFormat::rgba8: return VK_FORMAT_R8G8B8A8_UNORM;
    case ImageFormat::rgba8_srgb: return VK_FORMAT_R8G8B8A8_SRGB;
    case ImageFormat::rgba32f: return VK_FORMAT_R32G32B32A32_SFLOAT;
    case ImageFormat::r32f: return VK_FORMAT_R32_SFLOAT;
    }
    return VK_FORMAT_UNDEFINED;
}

uint32_t texel_bytes(ImageFormat f) {
    switch (f) {
    case ImageFormat::rgba8:
    case ImageFormat::rgba8_srgb: return 4;
    case ImageFormat::rgba32f: return 16;
    case ImageFormat::r32f: return 4;
    }
    return 0;
}

// Layout transition of the whole (single-mip, single-layer) image, with a conservative memory
// dependency between transfers and compute shaders.
static void transition(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                      VK_ACCESS_TRANSFER_WRITE_BIT;
    if (from == VK_IMAGE_LAYOUT_UNDEFINED) b.srcAccessMask = 0;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkPipelineStageFlags stages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
    vkCmdPipelineBarrier(cmd, from == VK_IMAGE_LAYOUT_UNDEFINED ? VkPipelineStageFlags(VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT) : stages,
                         stages, 0, 0, nullptr, 0, nullptr, 1, &b);
}

Image::Image(const Context& ctx, uint32_t width, uint32_t height, ImageFormat format, uint32_t usage,
             const std::string& name)
    : ctx_(&ctx), width_(width), height_(height), format_(format), usage_(usage), name_(name) {
    if (width == 0 || height == 0 || width > 16384 || height > 16384)
        throw Error(strfmt("image '%s': size %ux%u is outside 1..16384", name.c_str(), width, height));
    NBVH_CHECK_MSG(usage != 0, "image needs a usage");
    NBVH_CHECK_MSG(!(format == ImageFormat::rgba8_srgb && (usage & image_storage)),
                   "sRGB images cannot be storage images");

    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = to_vk(format);
    info.extent = {width, height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    if (usage & image_sampled) info.usage |= VK_IMAGE_USAGE_SAMPLED_BIT;
    if (usage & image_storage) info.usage |= VK_IMAGE_USAGE_STORAGE_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    NBVH_VK_CHECK(vkCreateImage(ctx.device(), &info, nullptr, &image_));

    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(ctx.device(), image_, &req);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    memory_bytes_ = req.size;
    alloc.memoryTypeIndex = ctx.find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkResult r = vkAllocateMemory(ctx.device(), &alloc, nullptr, &memory_);
    if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY) {
        destroy();
        throw Error(strfmt("out of memory allocating image '%s' (%ux%u)", name.c_str(), width, height));
    }
    NBVH_VK_CHECK(r);
    NBVH_VK_CHECK(vkBindImageMemory(ctx.device(), image_, memory_, 0));

    VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = image_;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = info.format;
    view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    NBVH_VK_CHECK(vkCreateImageView(ctx.device(), &view, nullptr, &view_));
    ctx.set_name(VK_OBJECT_TYPE_IMAGE, image_, name);
    ctx.set_name(VK_OBJECT_TYPE_IMAGE_VIEW, view_, name);

    ctx.run_now([&](VkCommandBuffer cmd) {
        transition(cmd, image_, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    });
}

Image::~Image() { destroy(); }

Image::Image(Image&& o) noexcept { *this = std::move(o); }

Image& Image::operator=(Image&& o) noexcept {
    if (this != &o) {
        destroy();
        ctx_ = o.ctx_;
        image_ = std::exchange(o.image_, VK_NULL_HANDLE);
        view_ = std::exchange(o.view_, VK_NULL_HANDLE);
        memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
        width_ = o.width_;
        height_ = o.height_;
        format_ = o.format_;
        usage_ = o.usage_;
        memory_bytes_ = o.memory_bytes_;
        name_ = std::move(o.name_);
    }
    return *this;
}

void Image::destroy() {
    if (!ctx_) return;
    if (view_) vkDestroyImageView(ctx_->device(), view_, nullptr);
    if (image_) vkDestroyImage(ctx_->device(), image_, nullptr);
    if (memory_) vkFreeMemory(ctx_->device(), memory_, nullptr);
    view_ = VK_NULL_HANDLE;
    image_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
}

void Image::copy(bool to_image, VkBuffer staging) const {
    ctx_->run_now([&](VkCommandBuffer cmd) {
        VkImageLayout io = to_image ? VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL : VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        transition(cmd, image_, VK_IMAGE_LAYOUT_GENERAL, io);
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {width_, height_, 1};
        if (to_image)
            vkCmdCopyBufferToImage(cmd, staging, image_, io, 1, &region);
        else
            vkCmdCopyImageToBuffer(cmd, image_, io, staging, 1, &region);
        transition(cmd, image_, io, VK_IMAGE_LAYOUT_GENERAL);
        if (!to_image) {
            VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
            host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
            host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
            vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0,
                                 nullptr, 0, nullptr);
        }
    });
}

void Image::upload(const void* texels, size_t bytes) {
    size_t expected = size_t(width_) * height_ * texel_bytes(format_);
    NBVH_CHECK_MSG(bytes == expected, name_.c_str());
    Buffer staging(*ctx_, bytes, MemoryKind::host, 0, name_ + " (staging)");
    std::memcpy(staging.mapped(), texels, bytes);
    copy(true, staging.handle());
}

void Image::download(void* texels, size_t bytes) const {
    size_t expected = size_t(width_) * height_ * texel_bytes(format_);
    NBVH_CHECK_MSG(bytes == expected, name_.c_str());
    Buffer staging(*ctx_, bytes, MemoryKind::host, 0, name_ + " (readback)");
    copy(false, staging.handle());
    std::memcpy(texels, staging.mapped(), bytes);
}

Sampler::Sampler(const Context& ctx, const SamplerDesc& desc) : ctx_(&ctx) {
    VkSamplerCreateInfo info{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    info.magFilter = info.minFilter = desc.linear ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
    info.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    VkSamplerAddressMode mode = desc.repeat ? VK_SAMPLER_ADDRESS_MODE_REPEAT : VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    info.addressModeU = info.addressModeV = info.addressModeW = mode;
    info.maxLod = 0.0f;
    NBVH_VK_CHECK(vkCreateSampler(ctx.device(), &info, nullptr, &sampler_));
}

Sampler::~Sampler() {
    if (ctx_ && sampler_) vkDestroySampler(ctx_->device(), sampler_, nullptr);
}

Sampler::Sampler(Sampler&& o) noexcept { *this = std::move(o); }

Sampler& Sampler::operator=(Sampler&& o) noexcept {
    if (this != &o) {
        if (ctx_ && sampler_) vkDestroySampler(ctx_->device(), sampler_, nullptr);
        ctx_ = o.ctx_;
        sampler_ = std::exchange(o.sampler_, VK_NULL_HANDLE);
    }
    return *this;
}

} // namespace nbvh::vk
