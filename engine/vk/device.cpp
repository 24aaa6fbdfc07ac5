// Context, second half: physical-device choice, feature queries and logical-device creation.
#include "context.h"

#include "engine/core/log.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <optional>
#include <string>

namespace nbvh::vk {

namespace {

std::vector<VkExtensionProperties> device_extensions(VkPhysicalDevice pd) {
    uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> exts(count);
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &count, exts.data());
    return exts;
}

bool has_extension(const std::vector<VkExtensionProperties>& exts, const char* name) {
    return std::any_of(exts.begin(), exts.end(),
                       [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

// Compute queue family, preferring one with timestamps; UINT32_MAX when the device has none.
uint32_t compute_family(VkPhysicalDevice pd, uint32_t* timestamp_bits) {
    uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &count, nullptr);
    std::vector<VkQueueFamilyProperties> fams(count);
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &count, fams.data());
    uint32_t best = UINT32_MAX;
    for (uint32_t i = 0; i < count; ++i) {
        if (!(fams[i].queueFlags & VK_QUEUE_COMPUTE_BIT)) continue;
        if (best == UINT32_MAX || (fams[best].timestampValidBits == 0 && fams[i].timestampValidBits > 0))
            best = i;
    }
    if (best != UINT32_MAX && timestamp_bits) *timestamp_bits = fams[best].timestampValidBits;
    return best;
}

// Higher is better for --device auto: real GPUs first, software last.
int type_rank(VkPhysicalDeviceType type) {
    switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 1;
    default: return 0;
    }
}

const char* component_name(VkComponentTypeNV t) {
    switch (t) {
    case VK_COMPONENT_TYPE_FLOAT16_NV: return "f16";
    case VK_COMPONENT_TYPE_FLOAT32_NV: return "f32";
    case VK_COMPONENT_TYPE_FLOAT64_NV: return "f64";
    case VK_COMPONENT_TYPE_SINT8_NV: return "s8";
    case VK_COMPONENT_TYPE_SINT16_NV: return "s16";
    case VK_COMPONENT_TYPE_SINT32_NV: return "s32";
    case VK_COMPONENT_TYPE_UINT8_NV: return "u8";
    case VK_COMPONENT_TYPE_UINT16_NV: return "u16";
    case VK_COMPONENT_TYPE_UINT32_NV: return "u32";
    default: return "?";
    }
}

// PCI address (domain, bus, device, function) where the driver reports it (VK_EXT_pci_bus_info).
std::optional<std::array<uint32_t, 4>> pci_address(VkPhysicalDevice pd) {
    if (!has_extension(device_extensions(pd), VK_EXT_PCI_BUS_INFO_EXTENSION_NAME)) return std::nullopt;
    VkPhysicalDevicePCIBusInfoPropertiesEXT pci{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PCI_BUS_INFO_PROPERTIES_EXT};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &pci};
    vkGetPhysicalDeviceProperties2(pd, &p2);
    return std::array<uint32_t, 4>{pci.pciDomain, pci.pciBus, pci.pciDevice, pci.pciFunction};
}

struct Candidate {
    VkPhysicalDevice device;
    std::optional<std::array<uint32_t, 4>> pci;
};

// --device gpu:N: the N-th usable GPU in PCI bus order (nvidia-smi's numbering), or in the driver's
// enumeration order when any of them does not report its PCI address.
VkPhysicalDevice nth_gpu_in_pci_order(std::vector<Candidate> gpus, int n, const std::string& seen) {
    const bool all_pci =
        std::all_of(gpus.begin(), gpus.end(), [](const Candidate& c) { return c.pci.has_value(); });
    if (all_pci)
        std::stable_sort(gpus.begin(), gpus.end(),
                         [](const Candidate& a, const Candidate& b) { return *a.pci < *b.pci; });
    if (gpus.empty())
        throw Error(
            strfmt("--device gpu:%d: no usable GPU (Vulkan 1.2, scalar block layout, compute); Vulkan "
                   "devices found: %s",
                   n, seen.c_str()));
    if (n >= int(gpus.size()))
        throw Error(
            strfmt("--device gpu:%d: this machine has %zu usable GPU(s), gpu:0 to gpu:%zu; Vulkan devices "
                   "found: %s",
                   n, gpus.size(), gpus.size() - 1, seen.c_str()));
    if (!all_pci)
        log_info("--device gpu:%d: a GPU does not report its PCI address; counting in the driver's order", n);
    return gpus[size_t(n)].device;
}

} // namespace

std::string CoopMatrixShape::describe() const {
    return strfmt("%ux%ux%u %s*%s+%s->%s %s", m, n, k, component_name(a), component_name(b),
                  component_name(c), component_name(d), scope == VK_SCOPE_SUBGROUP_NV ? "subgroup" : "other");
}

std::string DeviceFeatures::summary() const {
    auto yn = [](bool b) { return b ? "yes" : "no"; };
    std::string s =
        strfmt("device: %s (%s, %s%s), Vulkan %u.%u.%u, uuid %s\n", device_name.c_str(), driver_name.c_str(),
               driver_info.c_str(), is_cpu ? ", CPU" : "", VK_API_VERSION_MAJOR(api_version),
               VK_API_VERSION_MINOR(api_version), VK_API_VERSION_PATCH(api_version), device_uuid.c_str());
    s += strfmt("  fp16 %s, int8 %s, int16 %s, int64 %s, 16-bit storage %s, 8-bit storage %s, scalar layout %s\n",
                yn(fp16), yn(int8), yn(int16), yn(int64), yn(storage16), yn(storage8), yn(scalar_layout));
    s += strfmt("  buffer device address %s, memory model %s, partially bound descriptors %s\n",
                yn(buffer_device_address), yn(memory_model), yn(descriptor_partially_bound));
    s += strfmt("  runtime descriptor arrays %s, non-uniform sampled-image indexing %s, %u sampled images per "
                "pipeline, 2D images up to %u\n", yn(runtime_descriptor_array), yn(sampled_image_array_nonuniform),
                max_sampled_images, max_image_dimension_2d);
    s += strfmt("  subgroup size %u (min %u, max %u, control %s), shared memory %u B, storage range %llu B\n",
                subgroup_size, min_subgroup_size, max_subgroup_size, yn(subgroup_size_control),
                max_shared_memory, (unsigned long long)max_storage_buffer_range);
    s += strfmt("  timestamps: %u valid bits, %.3f ns/tick; SMs %s\n", timestamp_valid_bits, double(timestamp_period),
                sm_count ? std::to_string(sm_count).c_str() : "unknown");
    s += strfmt("  VK_NV_cooperative_matrix: %s", yn(coop_matrix_nv));
    for (const CoopMatrixShape& c : coop_matrix_shapes) s += "\n    " + c.describe();
    return s;
}

void Context::pick_physical_device(DeviceChoice choice, int gpu_index) {
    uint32_t count = 0;
    NBVH_VK_CHECK(vkEnumeratePhysicalDevices(instance_, &count, nullptr));
    std::vector<VkPhysicalDevice> devices(count);
    NBVH_VK_CHECK(vkEnumeratePhysicalDevices(instance_, &count, devices.data()));
    if (devices.empty())
        throw Error("no Vulkan device found (install a GPU driver, or mesa-vulkan-drivers for lavapipe)");

    std::string seen;
    int best_rank = -1;
    std::vector<Candidate> gpus; // usable GPUs, for gpu:N
    for (VkPhysicalDevice pd : devices) {
        VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
        VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(pd, &props);
        seen += strfmt("%s'%s'", seen.empty() ? "" : ", ", props.deviceName);
        // Only a 1.2 device can be asked for its 1.2 feature struct.
        if (props.apiVersion < VK_API_VERSION_1_2) {
            log_info("skipping Vulkan device '%s': Vulkan %u.%u < 1.2", props.deviceName,
                     VK_API_VERSION_MAJOR(props.apiVersion), VK_API_VERSION_MINOR(props.apiVersion));
            continue;
        }
        vkGetPhysicalDeviceFeatures2(pd, &f2);
        if (!f12.scalarBlockLayout || compute_family(pd, nullptr) == UINT32_MAX) {
            log_info("skipping Vulkan device '%s': no scalar block layout or no compute queue", props.deviceName);
            continue;
        }
        bool cpu = props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
        if (choice == DeviceChoice::cpu && !cpu) continue;
        if (choice == DeviceChoice::gpu && cpu) continue;
        if (gpu_index >= 0) {
            gpus.push_back({pd, pci_address(pd)});
            continue;
        }
        int rank = type_rank(props.deviceType);
        if (rank > best_rank) {
            best_rank = rank;
            physical_ = pd;
        }
    }
    if (gpu_index >= 0) {
        physical_ = nth_gpu_in_pci_order(gpus, gpu_index, seen);
        return;
    }
    if (!physical_) {
        const char* want = choice == DeviceChoice::gpu   ? "a GPU"
                           : choice == DeviceChoice::cpu ? "a CPU device (lavapipe: mesa-vulkan-drivers)"
                                                         : "any device";
        throw Error(strfmt("--device %s: no usable Vulkan 1.2 device with scalar block layout and compute; "
                           "wanted %s, found: %s", device_choice_name(choice), want, seen.c_str()));
    }
}

void Context::create_device(const std::vector<std::string>& extra_extensions) {
    const std::vector<VkExtensionProperties> exts = device_extensions(physical_);
    const bool has_ssc = has_extension(exts, VK_EXT_SUBGROUP_SIZE_CONTROL_EXTENSION_NAME);
    const bool has_coop = has_extension(exts, VK_NV_COOPERATIVE_MATRIX_EXTENSION_NAME);
    const bool has_nsi = has_extension(exts, VK_KHR_SHADER_NON_SEMANTIC_INFO_EXTENSION_NAME);
    const bool has_pep = has_extension(exts, VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
    const bool has_sm = has_extension(exts, VK_NV_SHADER_SM_BUILTINS_EXTENSION_NAME); // properties only

    // What the device supports.
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR pep{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
    VkPhysicalDeviceCooperativeMatrixFeaturesNV coop{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_COOPERATIVE_MATRIX_FEATURES_NV};
    VkPhysicalDeviceSubgroupSizeControlFeaturesEXT ssc{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_FEATURES_EXT};
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES, &f12};
    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f11};
    void** tail = &f12.pNext;
    if (has_ssc) { *tail = &ssc; tail = &ssc.pNext; }
    if (has_coop) { *tail = &coop; tail = &coop.pNext; }
    if (has_pep) { *tail = &pep; tail = &pep.pNext; }
    vkGetPhysicalDeviceFeatures2(physical_, &f2);

    VkPhysicalDeviceSubgroupSizeControlPropertiesEXT ssc_props{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_PROPERTIES_EXT};
    VkPhysicalDeviceVulkan12Properties p12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES};
    VkPhysicalDeviceVulkan11Properties p11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES, &p12};
    VkPhysicalDeviceShaderSMBuiltinsPropertiesNV sm_props{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_SM_BUILTINS_PROPERTIES_NV};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p11};
    void** ptail = &p12.pNext;
    if (has_ssc) { *ptail = &ssc_props; ptail = &ssc_props.pNext; }
    if (has_sm) { *ptail = &sm_props; ptail = &sm_props.pNext; }
    vkGetPhysicalDeviceProperties2(physical_, &p2);
    vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
    const VkPhysicalDeviceProperties& props = p2.properties;

    DeviceFeatures& d = features_;
    d.device_name = props.deviceName;
    static_assert(VK_UUID_SIZE == 16);
    d.device_uuid = format_uuid(p11.deviceUUID);
    d.driver_name = p12.driverName;
    d.driver_info = p12.driverInfo;
    d.api_version = props.apiVersion;
    d.driver_version = props.driverVersion;
    d.vendor_id = props.vendorID;
    d.is_cpu = props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    d.fp16 = f12.shaderFloat16;
    d.int8 = f12.shaderInt8;
    d.int16 = f2.features.shaderInt16;
    d.int64 = f2.features.shaderInt64;
    d.storage16 = f11.storageBuffer16BitAccess;
    d.storage8 = f12.storageBuffer8BitAccess;
    d.scalar_layout = f12.scalarBlockLayout;
    d.buffer_device_address = f12.bufferDeviceAddress;
    d.memory_model = f12.vulkanMemoryModel;
    d.descriptor_partially_bound = f12.descriptorBindingPartiallyBound && f12.runtimeDescriptorArray &&
                                   f12.shaderSampledImageArrayNonUniformIndexing;
    d.runtime_descriptor_array = f12.runtimeDescriptorArray;
    d.sampled_image_array_nonuniform = f12.shaderSampledImageArrayNonUniformIndexing;
    d.subgroup_size_control = has_ssc && ssc.subgroupSizeControl && ssc.computeFullSubgroups;
    d.coop_matrix_nv = has_coop && coop.cooperativeMatrix && d.fp16;
    d.pipeline_statistics = has_pep && pep.pipelineExecutableInfo;
    d.subgroup_size = p11.subgroupSize;
    d.subgroup_shuffle = (p11.subgroupSupportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
                         (p11.subgroupSupportedOperations & VK_SUBGROUP_FEATURE_SHUFFLE_BIT);
    d.min_subgroup_size = d.subgroup_size_control ? ssc_props.minSubgroupSize : p11.subgroupSize;
    d.max_subgroup_size = d.subgroup_size_control ? ssc_props.maxSubgroupSize : p11.subgroupSize;
    d.sm_count = has_sm ? sm_props.shaderSMCount : 0u;
    d.max_shared_memory = props.limits.maxComputeSharedMemorySize;
    d.max_storage_buffer_range = props.limits.maxStorageBufferRange;
    d.max_allocation_size = p11.maxMemoryAllocationSize;
    VkPhysicalDeviceMemoryProperties mem{};
    vkGetPhysicalDeviceMemoryProperties(physical_, &mem);
    for (uint32_t h = 0; h < mem.memoryHeapCount; ++h)
        if (mem.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            d.device_local_bytes = std::max<uint64_t>(d.device_local_bytes, mem.memoryHeaps[h].size);
    d.max_push_constants = props.limits.maxPushConstantsSize;
    d.max_workgroup_invocations = props.limits.maxComputeWorkGroupInvocations;
    for (int i = 0; i < 3; ++i) d.max_workgroup_count[i] = props.limits.maxComputeWorkGroupCount[i];
    const VkPhysicalDeviceLimits& lim = props.limits;
    d.max_sampled_images = std::min({lim.maxPerStageDescriptorSamplers, lim.maxPerStageDescriptorSampledImages,
                                     lim.maxDescriptorSetSamplers, lim.maxDescriptorSetSampledImages});
    d.max_per_stage_resources = lim.maxPerStageResources;
    d.max_image_dimension_2d = lim.maxImageDimension2D;
    d.max_memory_allocations = lim.maxMemoryAllocationCount;
    d.timestamp_period = props.limits.timestampPeriod;
    queue_family_ = compute_family(physical_, &d.timestamp_valid_bits);

    if (d.coop_matrix_nv) {
        auto get_props = (PFN_vkGetPhysicalDeviceCooperativeMatrixPropertiesNV)vkGetInstanceProcAddr(
            instance_, "vkGetPhysicalDeviceCooperativeMatrixPropertiesNV");
        uint32_t n = 0;
        if (get_props && get_props(physical_, &n, nullptr) == VK_SUCCESS && n > 0) {
            std::vector<VkCooperativeMatrixPropertiesNV> shapes(
                n, VkCooperativeMatrixPropertiesNV{VK_STRUCTURE_TYPE_COOPERATIVE_MATRIX_PROPERTIES_NV});
            NBVH_VK_CHECK(get_props(physical_, &n, shapes.data()));
            for (const auto& s : shapes)
                d.coop_matrix_shapes.push_back({s.MSize, s.NSize, s.KSize, s.AType, s.BType, s.CType, s.DType, s.scope});
        }
    }

    // What we enable: exactly the flags reported in DeviceFeatures (plus what they depend on).
    VkPhysicalDeviceCooperativeMatrixFeaturesNV coop_on{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_COOPERATIVE_MATRIX_FEATURES_NV};
    VkPhysicalDeviceSubgroupSizeControlFeaturesEXT ssc_on{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_FEATURES_EXT};
    VkPhysicalDeviceVulkan12Features e12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceVulkan11Features e11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES, &e12};
    VkPhysicalDeviceFeatures2 e2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &e11};
    e2.features.shaderInt16 = d.int16;
    e2.features.shaderInt64 = d.int64;
    e11.storageBuffer16BitAccess = d.storage16;
    e11.uniformAndStorageBuffer16BitAccess = f11.uniformAndStorageBuffer16BitAccess;
    e12.shaderFloat16 = d.fp16;
    e12.shaderInt8 = d.int8;
    e12.storageBuffer8BitAccess = d.storage8;
    e12.uniformAndStorageBuffer8BitAccess = f12.uniformAndStorageBuffer8BitAccess;
    e12.scalarBlockLayout = VK_TRUE;
    e12.bufferDeviceAddress = d.buffer_device_address;
    e12.vulkanMemoryModel = d.memory_model;
    e12.vulkanMemoryModelDeviceScope = d.memory_model && f12.vulkanMemoryModelDeviceScope;
    e12.hostQueryReset = f12.hostQueryReset;
    e12.descriptorIndexing = f12.descriptorIndexing;
    e12.descriptorBindingPartiallyBound = d.descriptor_partially_bound;
    e12.runtimeDescriptorArray = d.runtime_descriptor_array;
    e12.shaderSampledImageArrayNonUniformIndexing = d.sampled_image_array_nonuniform;
    e12.shaderStorageBufferArrayNonUniformIndexing = f12.shaderStorageBufferArrayNonUniformIndexing;
    std::vector<const char*> enabled;
    void** etail = &e12.pNext;
    if (d.subgroup_size_control) {
        ssc_on.subgroupSizeControl = VK_TRUE;
        ssc_on.computeFullSubgroups = VK_TRUE;
        *etail = &ssc_on;
        etail = &ssc_on.pNext;
        enabled.push_back(VK_EXT_SUBGROUP_SIZE_CONTROL_EXTENSION_NAME);
    }
    if (d.coop_matrix_nv) {
        coop_on.cooperativeMatrix = VK_TRUE;
        *etail = &coop_on;
        etail = &coop_on.pNext;
        enabled.push_back(VK_NV_COOPERATIVE_MATRIX_EXTENSION_NAME);
    }
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR pep_on{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
    if (d.pipeline_statistics) {
        pep_on.pipelineExecutableInfo = VK_TRUE;
        *etail = &pep_on;
        etail = &pep_on.pNext;
        enabled.push_back(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
    }
    if (has_nsi) enabled.push_back(VK_KHR_SHADER_NON_SEMANTIC_INFO_EXTENSION_NAME); // debugPrintf
    for (const std::string& name : extra_extensions) {
        if (!has_extension(exts, name.c_str()))
            throw Error(strfmt("the Vulkan device %s lacks the extension %s", d.device_name.c_str(), name.c_str()));
        enabled.push_back(name.c_str());
    }

    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue_info.queueFamilyIndex = queue_family_;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &e2};
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queue_info;
    info.enabledExtensionCount = uint32_t(enabled.size());
    info.ppEnabledExtensionNames = enabled.data();
    NBVH_VK_CHECK(vkCreateDevice(physical_, &info, nullptr, &device_));
    vkGetDeviceQueue(device_, queue_family_, 0, &queue_);

    VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    pool.queueFamilyIndex = queue_family_;
    NBVH_VK_CHECK(vkCreateCommandPool(device_, &pool, nullptr, &transient_pool_));
    log_debug("%s", d.summary().c_str());
}

} // namespace nbvh::vk
