// RAII Vulkan buffer with its own memory allocation (one VkDeviceMemory per buffer: the renderer
// has a few dozen long-lived buffers, so a sub-allocator would buy nothing yet).
#pragma once
#include "context.h"

#include <span>
#include <string>
#include <vector>

namespace nbvh::vk {

enum class MemoryKind {
    device,   // device-local; filled through a staging buffer
    host,     // host-visible and coherent, persistently mapped (readback, small per-frame uniforms)
};

class Buffer {
public:
    Buffer() = default;
    // `bytes` may be 0 (a 4-byte buffer is made: Vulkan has no empty buffers, and shaders may still
    // bind it). Every buffer can be a storage buffer and a transfer source/destination; add e.g.
    // VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT through `extra_usage`. Throws nbvh::Error when the size
    // exceeds what the device can allocate.
    Buffer(const Context& ctx, VkDeviceSize bytes, MemoryKind kind = MemoryKind::device,
           VkBufferUsageFlags extra_usage = 0, const std::string& name = "buffer");
    ~Buffer();
    Buffer(Buffer&& other) noexcept;
    Buffer& operator=(Buffer&& other) noexcept;
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;

    VkBuffer handle() const { return buffer_; }
    VkDeviceSize size() const { return size_; } // the size asked for (>= 4 actually allocated)
    MemoryKind kind() const { return kind_; }
    const std::string& name() const { return name_; }
    explicit operator bool() const { return buffer_ != VK_NULL_HANDLE; }
    // Host pointer of a MemoryKind::host buffer (nullptr otherwise).
    void* mapped() const { return mapped_; }

    // Blocking copies between host memory and the buffer (through a staging buffer when device-local).
    void upload(const void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);
    void download(void* data, VkDeviceSize bytes, VkDeviceSize offset = 0) const;
    // Set every 32-bit word to `word` (vkCmdFillBuffer; size rounded down to 4 bytes).
    void fill(uint32_t word);

    template <class T> void upload(std::span<const T> items, VkDeviceSize offset = 0) {
        upload(items.data(), items.size_bytes(), offset);
    }
    template <class T> void upload(const std::vector<T>& items, VkDeviceSize offset = 0) {
        upload(items.data(), items.size() * sizeof(T), offset);
    }
    template <class T> std::vector<T> download(size_t count, VkDeviceSize offset = 0) const {
        std::vector<T> out(count);
        download(out.data(), count * sizeof(T), offset);
        return out;
    }

private:
    void destroy();
    const Context* ctx_ = nullptr;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkDeviceSize size_ = 0;
    MemoryKind kind_ = MemoryKind::device;
    void* mapped_ = nullptr;
    std::string name_;
};

// Convenience: a device buffer holding `items`.
template <class T>
Buffer make_buffer(const Context& ctx, const std::vector<T>& items, const std::string& name,
                   VkBufferUsageFlags extra_usage = 0) {
    Buffer b(ctx, items.size() * sizeof(T), MemoryKind::device, extra_usage, name);
    if (!items.empty()) b.upload(items);
    return b;
}

} // namespace nbvh::vk
