// Compute pipelines built from embedded SPIR-V (shaders/CMakeLists.txt), and descriptor sets for them.
//
//   ComputePipeline trace(ctx, {.shader = "passes/trace.comp",
//                               .bindings = {{0, BindingType::storage_buffer}, {1, BindingType::storage_buffer}},
//                               .spec = {{0, 1u}},           // constant_id = 0 -> 1
//                               .push_constant_bytes = sizeof(TracePush)});
//   DescriptorSet set(ctx, trace);
//   set.bind(0, rays).bind(1, hits);
//
// One descriptor set (set = 0) per pipeline; the binding list must match the shader's declarations
// (the validation layer reports any mismatch).
#pragma once
#include "buffer.h"
#include "image.h"

#include <string>
#include <vector>

namespace nbvh::vk {

enum class BindingType { storage_buffer, combined_image_sampler, storage_image };

struct Binding {
    uint32_t binding = 0;
    BindingType type = BindingType::storage_buffer;
    uint32_t count = 1; // > 1: an array (texture arrays; may be partially written when the device allows)
};

struct SpecConstant {
    uint32_t id = 0;    // layout(constant_id = id)
    uint32_t value = 0; // bit pattern: bool (0/1), uint, int, or a float through floatBitsToUint
};

struct PipelineDesc {
    std::string shader;                 // path relative to shaders/, e.g. "passes/trace.comp"
    std::vector<Binding> bindings;      // set 0
    std::vector<SpecConstant> spec;     // specialization constants
    uint32_t push_constant_bytes = 0;   // <= 128 (the guaranteed minimum)
    uint32_t required_subgroup_size = 0; // 0 = driver's choice; else needs subgroup size control
};

class ComputePipeline {
public:
    ComputePipeline() = default;
    ComputePipeline(const Context& ctx, const PipelineDesc& desc);
    ~ComputePipeline();
    ComputePipeline(ComputePipeline&& other) noexcept;
    ComputePipeline& operator=(ComputePipeline&& other) noexcept;
    ComputePipeline(const ComputePipeline&) = delete;
    ComputePipeline& operator=(const ComputePipeline&) = delete;

    VkPipeline handle() const { return pipeline_; }
    VkPipelineLayout layout() const { return layout_; }
    VkDescriptorSetLayout set_layout() const { return set_layout_; }
    const PipelineDesc& desc() const { return desc_; }
    const std::string& name() const { return desc_.shader; }
    explicit operator bool() const { return pipeline_ != VK_NULL_HANDLE; }

private:
    void destroy();
    static bool statistics_requested(const Context& ctx);
    void log_statistics(const Context& ctx) const;
    const Context* ctx_ = nullptr;
    PipelineDesc desc_;
    VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
};

// A descriptor set for one pipeline's set 0, in its own small pool. bind() writes immediately, so
// bind everything before recording the dispatch (and do not rebind while a submission using the set
// is in flight).
class DescriptorSet {
public:
    DescriptorSet() = default;
    DescriptorSet(const Context& ctx, const ComputePipeline& pipeline);
    ~DescriptorSet();
    DescriptorSet(DescriptorSet&& other) noexcept;
    DescriptorSet& operator=(DescriptorSet&& other) noexcept;
    DescriptorSet(const DescriptorSet&) = delete;
    DescriptorSet& operator=(const DescriptorSet&) = delete;

    // Storage buffer (whole buffer, or [offset, offset + range)). Throws nbvh::Error when the range
    // exceeds the device's maxStorageBufferRange (128 MiB on lavapipe).
    DescriptorSet& bind(uint32_t binding, const Buffer& buffer, VkDeviceSize offset = 0,
                        VkDeviceSize range = VK_WHOLE_SIZE);
    // Combined image sampler (element `index` of an array binding).
    DescriptorSet& bind(uint32_t binding, const Image& image, const Sampler& sampler, uint32_t index = 0);
    // Storage image.
    DescriptorSet& bind_storage(uint32_t binding, const Image& image);

    VkDescriptorSet handle() const { return set_; }

private:
    const Binding& find(uint32_t binding, BindingType type) const;
    const Context* ctx_ = nullptr;
    std::string name_;
    std::vector<Binding> bindings_;
    VkDescriptorPool pool_ = VK_NULL_HANDLE;
    VkDescriptorSet set_ = VK_NULL_HANDLE;
};

} // namespace nbvh::vk
