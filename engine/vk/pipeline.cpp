#include "pipeline.h"

#include "engine/core/log.h"
#include "shaders/shader_registry.h"

#include <algorithm>
#include <cstdlib>
#include <string>
#include <utility>

namespace nbvh::vk {

static VkDescriptorType to_vk(BindingType t) {
    switch (t) {
    case BindingType::storage_buffer: return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    case BindingType::combined_image_sampler: return VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    case BindingType::storage_image: return VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    }
    return VK_DESCRIPTOR_TYPE_MAX_ENUM;
}

ComputePipeline::ComputePipeline(const Context& ctx, const PipelineDesc& desc) : ctx_(&ctx), desc_(desc) {
    VkDevice dev = ctx.device();
    NBVH_CHECK_MSG(desc.push_constant_bytes <= 128 && desc.push_constant_bytes % 4 == 0,
                   "push constants must be a multiple of 4 and at most 128 bytes");
    const std::span<const uint32_t> spirv = shaders::find(desc.shader); // throws Error if unknown

    // Set layout from the binding list; arrays may be partially bound when the device supports it.
    std::vector<VkDescriptorSetLayoutBinding> bindings;
    std::vector<VkDescriptorBindingFlags> flags;
    bool any_flags = false;
    for (const Binding& b : desc.bindings) {
        NBVH_CHECK(b.count >= 1);
        bindings.push_back({b.binding, to_vk(b.type), b.count, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
        bool partial = b.count > 1 && ctx.features().descriptor_partially_bound;
        flags.push_back(partial ? VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT : 0);
        any_flags |= partial;
    }
    VkDescriptorSetLayoutBindingFlagsCreateInfo flag_info{
        VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO};
    flag_info.bindingCount = uint32_t(flags.size());
    flag_info.pBindingFlags = flags.data();
    VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    set_info.pNext = any_flags ? &flag_info : nullptr;
    set_info.bindingCount = uint32_t(bindings.size());
    set_info.pBindings = bindings.data();
    NBVH_VK_CHECK(vkCreateDescriptorSetLayout(dev, &set_info, nullptr, &set_layout_));

    VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, desc.push_constant_bytes};
    VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &set_layout_;
    layout_info.pushConstantRangeCount = desc.push_constant_bytes ? 1u : 0u;
    layout_info.pPushConstantRanges = &push;
    NBVH_VK_CHECK(vkCreatePipelineLayout(dev, &layout_info, nullptr, &layout_));

    VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    module_info.codeSize = spirv.size_bytes();
    module_info.pCode = spirv.data();
    VkShaderModule module = VK_NULL_HANDLE;
    NBVH_VK_CHECK(vkCreateShaderModule(dev, &module_info, nullptr, &module));

    std::vector<VkSpecializationMapEntry> entries;
    std::vector<uint32_t> values;
    for (const SpecConstant& s : desc.spec) {
        entries.push_back({s.id, uint32_t(values.size() * 4), 4});
        values.push_back(s.value);
    }
    VkSpecializationInfo spec{uint32_t(entries.size()), entries.data(), values.size() * 4, values.data()};

    VkPipelineShaderStageRequiredSubgroupSizeCreateInfoEXT subgroup{
        VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_REQUIRED_SUBGROUP_SIZE_CREATE_INFO_EXT};
    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module;
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = entries.empty() ? nullptr : &spec;
    if (desc.required_subgroup_size) {
        const DeviceFeatures& f = ctx.features();
        if (!f.subgroup_size_control || desc.required_subgroup_size < f.min_subgroup_size ||
            desc.required_subgroup_size > f.max_subgroup_size) {
            vkDestroyShaderModule(dev, module, nullptr);
            destroy();
            throw Error(strfmt("%s needs subgroup size %u, which device '%s' cannot provide", desc.shader.c_str(),
                               desc.required_subgroup_size, f.device_name.c_str()));
        }
        subgroup.requiredSubgroupSize = desc.required_subgroup_size;
        info.stage.pNext = &subgroup;
    }
    info.layout = layout_;
    const bool stats = statistics_requested(ctx);
    if (stats) info.flags |= VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR;
    NBVH_VK_CHECK(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_));
    vkDestroyShaderModule(dev, module, nullptr);
    ctx.set_name(VK_OBJECT_TYPE_PIPELINE, pipeline_, desc.shader);
    if (stats) log_statistics(ctx);
}

bool ComputePipeline::statistics_requested(const Context& ctx) {
    const char* env = std::getenv("NBVH_PIPELINE_STATS");
    return env && *env && std::string(env) != "0" && ctx.features().pipeline_statistics;
}

// The driver's statistics of the compiled pipeline (registers, shared memory, instruction counts: whatever
// the driver reports), one log line per executable. A benchmarking aid: NBVH_PIPELINE_STATS=1.
void ComputePipeline::log_statistics(const Context& ctx) const {
    VkDevice dev = ctx.device();
    auto get_execs = (PFN_vkGetPipelineExecutablePropertiesKHR)vkGetDeviceProcAddr(
        dev, "vkGetPipelineExecutablePropertiesKHR");
    auto get_stats = (PFN_vkGetPipelineExecutableStatisticsKHR)vkGetDeviceProcAddr(
        dev, "vkGetPipelineExecutableStatisticsKHR");
    if (!get_execs || !get_stats) return;
    VkPipelineInfoKHR pinfo{VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR};
    pinfo.pipeline = pipeline_;
    uint32_t n = 0;
    if (get_execs(dev, &pinfo, &n, nullptr) != VK_SUCCESS) return;
    for (uint32_t e = 0; e < n; ++e) {
        VkPipelineExecutableInfoKHR einfo{VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR};
        einfo.pipeline = pipeline_;
        einfo.executableIndex = e;
        uint32_t m = 0;
        if (get_stats(dev, &einfo, &m, nullptr) != VK_SUCCESS) continue;
        std::vector<VkPipelineExecutableStatisticKHR> st(m, {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR});
        if (get_stats(dev, &einfo, &m, st.data()) != VK_SUCCESS) continue;
        std::string line = "pipeline statistics " + desc_.shader + ":";
        for (const VkPipelineExecutableStatisticKHR& x : st) {
            line += strfmt(" %s=", x.name);
            switch (x.format) {
            case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR: line += x.value.b32 ? "true" : "false"; break;
            case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR: line += strfmt("%lld", (long long)x.value.i64); break;
            case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR: line += strfmt("%llu", (unsigned long long)x.value.u64); break;
            case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_FLOAT64_KHR: line += strfmt("%g", x.value.f64); break;
            default: line += "?"; break;
            }
        }
        log_info("%s", line.c_str());
    }
}

ComputePipeline::~ComputePipeline() { destroy(); }

ComputePipeline::ComputePipeline(ComputePipeline&& o) noexcept { *this = std::move(o); }

ComputePipeline& ComputePipeline::operator=(ComputePipeline&& o) noexcept {
    if (this != &o) {
        destroy();
        ctx_ = o.ctx_;
        desc_ = std::move(o.desc_);
        set_layout_ = std::exchange(o.set_layout_, VK_NULL_HANDLE);
        layout_ = std::exchange(o.layout_, VK_NULL_HANDLE);
        pipeline_ = std::exchange(o.pipeline_, VK_NULL_HANDLE);
    }
    return *this;
}

void ComputePipeline::destroy() {
    if (!ctx_) return;
    VkDevice dev = ctx_->device();
    if (pipeline_) vkDestroyPipeline(dev, pipeline_, nullptr);
    if (layout_) vkDestroyPipelineLayout(dev, layout_, nullptr);
    if (set_layout_) vkDestroyDescriptorSetLayout(dev, set_layout_, nullptr);
    pipeline_ = VK_NULL_HANDLE;
    layout_ = VK_NULL_HANDLE;
    set_layout_ = VK_NULL_HANDLE;
}

// --- DescriptorSet ------------------------------------------------------------------------------

DescriptorSet::DescriptorSet(const Context& ctx, const ComputePipeline& pipeline)
    : ctx_(&ctx), name_(pipeline.name()), bindings_(pipeline.desc().bindings) {
    std::vector<VkDescriptorPoolSize> sizes;
    for (const Binding& b : bindings_) sizes.push_back({to_vk(b.type), b.count});
    VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pool_info.maxSets = 1;
    pool_info.poolSizeCount = uint32_t(sizes.size());
    pool_info.pPoolSizes = sizes.data();
    NBVH_VK_CHECK(vkCreateDescriptorPool(ctx.device(), &pool_info, nullptr, &pool_));
    VkDescriptorSetLayout layout = pipeline.set_layout();
    VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    alloc.descriptorPool = pool_;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &layout;
    NBVH_VK_CHECK(vkAllocateDescriptorSets(ctx.device(), &alloc, &set_));
    ctx.set_name(VK_OBJECT_TYPE_DESCRIPTOR_SET, set_, name_);
}

DescriptorSet::~DescriptorSet() {
    if (ctx_ && pool_) vkDestroyDescriptorPool(ctx_->device(), pool_, nullptr); // frees the set
}

DescriptorSet::DescriptorSet(DescriptorSet&& o) noexcept { *this = std::move(o); }

DescriptorSet& DescriptorSet::operator=(DescriptorSet&& o) noexcept {
    if (this != &o) {
        if (ctx_ && pool_) vkDestroyDescriptorPool(ctx_->device(), pool_, nullptr);
        ctx_ = o.ctx_;
        name_ = std::move(o.name_);
        bindings_ = std::move(o.bindings_);
        pool_ = std::exchange(o.pool_, VK_NULL_HANDLE);
        set_ = std::exchange(o.set_, VK_NULL_HANDLE);
    }
    return *this;
}

const Binding& DescriptorSet::find(uint32_t binding, BindingType type) const {
    for (const Binding& b : bindings_)
        if (b.binding == binding) {
            NBVH_CHECK_MSG(b.type == type, "descriptor bound with the wrong type");
            return b;
        }
    NBVH_CHECK_MSG(false, "binding not declared in the pipeline's binding list");
}

DescriptorSet& DescriptorSet::bind(uint32_t binding, const Buffer& buffer, VkDeviceSize offset, VkDeviceSize range) {
    find(binding, BindingType::storage_buffer);
    NBVH_CHECK_MSG(buffer.handle() != VK_NULL_HANDLE, "binding an empty Buffer");
    VkDeviceSize bytes = range == VK_WHOLE_SIZE ? std::max<VkDeviceSize>(buffer.size(), 4) - offset : range;
    const uint64_t limit = ctx_->features().max_storage_buffer_range;
    if (bytes > limit)
        throw Error(strfmt("%s: binding %u ('%s') is %.1f MiB, more than this device's storage-buffer range of "
                           "%.1f MiB; use a smaller scene or a device with a larger limit",
                           name_.c_str(), binding, buffer.name().c_str(), bytes / 1048576.0, limit / 1048576.0));
    VkDescriptorBufferInfo info{buffer.handle(), offset, range == VK_WHOLE_SIZE ? VK_WHOLE_SIZE : range};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set_;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w.pBufferInfo = &info;
    vkUpdateDescriptorSets(ctx_->device(), 1, &w, 0, nullptr);
    return *this;
}

DescriptorSet& DescriptorSet::bind(uint32_t binding, const Image& image, const Sampler& sampler, uint32_t index) {
    const Binding& b = find(binding, BindingType::combined_image_sampler);
    NBVH_CHECK_MSG(index < b.count, "texture index beyond the binding's array size");
    NBVH_CHECK_MSG(image.usage() & image_sampled, "image was not created sampled");
    VkDescriptorImageInfo info{sampler.handle(), image.view(), VK_IMAGE_LAYOUT_GENERAL};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set_;
    w.dstBinding = binding;
    w.dstArrayElement = index;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w.pImageInfo = &info;
    vkUpdateDescriptorSets(ctx_->device(), 1, &w, 0, nullptr);
    return *this;
}

DescriptorSet& DescriptorSet::bind_storage(uint32_t binding, const Image& image) {
    find(binding, BindingType::storage_image);
    NBVH_CHECK_MSG(image.usage() & image_storage, "image was not created as a storage image");
    VkDescriptorImageInfo info{VK_NULL_HANDLE, image.view(), VK_IMAGE_LAYOUT_GENERAL};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set_;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    w.pImageInfo = &info;
    vkUpdateDescriptorSets(ctx_->device(), 1, &w, 0, nullptr);
    return *this;
}

} // namespace nbvh::vk
