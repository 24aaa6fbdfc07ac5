#include "buffer.h"

#include "engine/core/log.h"

#include <algorithm>
#include <cstring>
#include <utility>

namespace nbvh::vk {

namespace {
// A transfer write (copy or fill) made visible to every later shader, indirect-argument or transfer
// read: run_now waits for completion, but the queue does not order memory for later submissions.
void transfer_write_to_later_use(VkCommandBuffer cmd) {
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                            VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT |
                             VK_PIPELINE_STAGE_TRANSFER_BIT,
                         0, 1, &barrier, 0, nullptr, 0, nullptr);
}
} // namespace

Buffer::Buffer(const Context& ctx, VkDeviceSize bytes, MemoryKind kind, VkBufferUsageFlags extra_usage,
               const std::string& name)
    : ctx_(&ctx), size_(bytes), kind_(kind), name_(name) {
    const DeviceFeatures& f = ctx.features();
    if (f.max_allocation_size && bytes > f.max_allocation_size)
        throw Error(strfmt("buffer '%s' needs %.1f MiB, more than the device allows in one allocation "
                           "(%.1f MiB)", name.c_str(), bytes / 1048576.0, f.max_allocation_size / 1048576.0));
    VkDeviceSize alloc_bytes = std::max<VkDeviceSize>(4, (bytes + 3) & ~VkDeviceSize(3));

    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = alloc_bytes;
    info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                 VK_BUFFER_USAGE_TRANSFER_DST_BIT | extra_usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    NBVH_VK_CHECK(vkCreateBuffer(ctx.device(), &info, nullptr, &buffer_));

    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(ctx.device(), buffer_, &req);
    VkMemoryPropertyFlags required = kind == MemoryKind::host
                                         ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                         : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    // Readback buffers prefer cached memory (uncached reads are very slow on discrete GPUs).
    VkMemoryPropertyFlags preferred = kind == MemoryKind::host ? VK_MEMORY_PROPERTY_HOST_CACHED_BIT : 0;
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    if (extra_usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) {
        flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        alloc.pNext = &flags;
    }
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = ctx.find_memory_type(req.memoryTypeBits, required, preferred);
    VkResult r = vkAllocateMemory(ctx.device(), &alloc, nullptr, &memory_);
    if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY) {
        destroy();
        throw Error(strfmt("out of %s memory allocating buffer '%s' (%.1f MiB)",
                           r == VK_ERROR_OUT_OF_DEVICE_MEMORY ? "device" : "host", name.c_str(),
                           bytes / 1048576.0));
    }
    NBVH_VK_CHECK(r);
    NBVH_VK_CHECK(vkBindBufferMemory(ctx.device(), buffer_, memory_, 0));
    if (kind == MemoryKind::host) NBVH_VK_CHECK(vkMapMemory(ctx.device(), memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
    ctx.set_name(VK_OBJECT_TYPE_BUFFER, buffer_, name);
}

Buffer::~Buffer() { destroy(); }

Buffer::Buffer(Buffer&& o) noexcept { *this = std::move(o); }

Buffer& Buffer::operator=(Buffer&& o) noexcept {
    if (this != &o) {
        destroy();
        ctx_ = o.ctx_;
        buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
        memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
        size_ = std::exchange(o.size_, 0);
        kind_ = o.kind_;
        mapped_ = std::exchange(o.mapped_, nullptr);
        name_ = std::move(o.name_);
    }
    return *this;
}

void Buffer::destroy() {
    if (!ctx_) return;
    if (buffer_) vkDestroyBuffer(ctx_->device(), buffer_, nullptr);
    if (memory_) vkFreeMemory(ctx_->device(), memory_, nullptr); // unmaps implicitly
    buffer_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
    mapped_ = nullptr;
}

void Buffer::upload(const void* data, VkDeviceSize bytes, VkDeviceSize offset) {
    NBVH_CHECK_MSG(offset + bytes <= size_, name_.c_str());
    if (bytes == 0) return;
    if (mapped_) {
        std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
        return;
    }
    Buffer staging(*ctx_, bytes, MemoryKind::host, 0, name_ + " (staging)");
    std::memcpy(staging.mapped(), data, bytes);
    ctx_->run_now([&](VkCommandBuffer cmd) {
        VkBufferCopy region{0, offset, bytes};
        vkCmdCopyBuffer(cmd, staging.handle(), buffer_, 1, &region);
        transfer_write_to_later_use(cmd);
    });
}

void Buffer::download(void* data, VkDeviceSize bytes, VkDeviceSize offset) const {
    NBVH_CHECK_MSG(offset + bytes <= size_, name_.c_str());
    if (bytes == 0) return;
    if (mapped_) {
        std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
        return;
    }
    Buffer staging(*ctx_, bytes, MemoryKind::host, 0, name_ + " (readback)");
    ctx_->run_now([&](VkCommandBuffer cmd) {
        // Earlier submissions' shader writes must be visible to the copy.
        VkMemoryBarrier before{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        before.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
        before.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                             VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &before, 0, nullptr, 0, nullptr);
        VkBufferCopy region{offset, 0, bytes};
        vkCmdCopyBuffer(cmd, buffer_, staging.handle(), 1, &region);
        VkMemoryBarrier after{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        after.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        after.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &after, 0,
                             nullptr, 0, nullptr);
    });
    std::memcpy(data, staging.mapped(), bytes);
}

void Buffer::fill(uint32_t word) {
    VkDeviceSize bytes = std::max<VkDeviceSize>(4, size_ & ~VkDeviceSize(3));
    ctx_->run_now([&](VkCommandBuffer cmd) {
        vkCmdFillBuffer(cmd, buffer_, 0, bytes, word);
        transfer_write_to_later_use(cmd);
    });
}

} // namespace nbvh::vk
