// The Vulkan context: instance, validation messenger, physical-device choice, one logical device with
// one compute queue, and the device features the renderer branches on. Compute only (no surface).
//
// Everything device-owned (buffers, images, pipelines, command buffers) keeps a `const Context&` and
// must be destroyed before the Context; member order in the owner gives that for free.
#pragma once
#include "engine/core/error.h"

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace nbvh::vk {

// Name of a VkResult ("VK_ERROR_DEVICE_LOST"), or its number when unknown.
const char* result_name(VkResult result);
[[noreturn]] void fail_vk(const char* file, int line, const char* expr, VkResult result);

} // namespace nbvh::vk

// A failed Vulkan call is a broken invariant: abort with file, line, expression and the result's name.
// Always on. (No Vulkan / unsupported device is a user error: Context throws nbvh::Error instead.)
#define NBVH_VK_CHECK(expr)                                                                       \
    do {                                                                                          \
        VkResult nbvh_vk_result_ = (expr);                                                        \
        if (nbvh_vk_result_ != VK_SUCCESS)                                                        \
            ::nbvh::vk::fail_vk(__FILE__, __LINE__, #expr, nbvh_vk_result_);                      \
    } while (0)

namespace nbvh::vk {

// --device auto|gpu|gpu:N|cpu. auto prefers a real GPU (discrete, then integrated, then virtual) and falls
// back to a CPU implementation (Mesa lavapipe); gpu fails without a GPU; cpu picks lavapipe. gpu:N takes
// the N-th usable GPU (from 0) in PCI bus order, nvidia-smi's numbering (the driver's enumeration order
// where a GPU does not report its PCI address: VK_EXT_pci_bus_info), so that several processes can share
// one host's GPUs (scripts/bench/study_multi.sh).
enum class DeviceChoice { automatic, gpu, cpu };
DeviceChoice parse_device_choice(std::string_view text); // auto|gpu|cpu; throws Error on anything else
const char* device_choice_name(DeviceChoice choice);
struct DeviceSpec {
    DeviceChoice choice = DeviceChoice::automatic;
    int gpu_index = -1; // gpu:N; -1: the best GPU
};
DeviceSpec parse_device_spec(std::string_view text); // auto|gpu|gpu:N|cpu; throws Error on anything else
// The --device help of every command that takes one.
inline constexpr const char* DEVICE_OPTION_HELP =
    "Vulkan device: auto, gpu, gpu:N (the N-th GPU in PCI order, nvidia-smi's number) or cpu (lavapipe)";

struct ContextOptions {
    DeviceChoice device = DeviceChoice::automatic;
    int gpu_index = -1; // with DeviceChoice::gpu: the N-th GPU in PCI bus order (-1: the best one)
    void set_device(const DeviceSpec& s) {
        device = s.choice;
        gpu_index = s.gpu_index;
    }
    void set_device(std::string_view text) { set_device(parse_device_spec(text)); } // a --device argument
    // Khronos validation layer + debug messenger. Also switched on by NBVH_VALIDATION=1 in the
    // environment (NBVH_VALIDATION=0 switches it off). Debug builds default to on.
#ifdef NDEBUG
    bool validation = false;
#else
    bool validation = true;
#endif
    // Extra extensions the caller needs (the viewer: the window system's surface extensions and
    // VK_KHR_swapchain). One the driver lacks is a user error (nbvh::Error naming it).
    std::vector<std::string> instance_extensions;
    std::vector<std::string> device_extensions;
};

// One supported VK_NV_cooperative_matrix configuration (D = A*B + C, A is MxK, B is KxN).
struct CoopMatrixShape {
    uint32_t m = 0, n = 0, k = 0;
    VkComponentTypeNV a = VK_COMPONENT_TYPE_FLOAT16_NV, b = VK_COMPONENT_TYPE_FLOAT16_NV;
    VkComponentTypeNV c = VK_COMPONENT_TYPE_FLOAT16_NV, d = VK_COMPONENT_TYPE_FLOAT16_NV;
    VkScopeNV scope = VK_SCOPE_SUBGROUP_NV;
    std::string describe() const; // "16x16x16 f16*f16+f16->f16 subgroup"
};

// What the chosen device can do. Every `bool` here is also *enabled* on the logical device when true.
struct DeviceFeatures {
    std::string device_name;
    // VkPhysicalDeviceVulkan11Properties::deviceUUID as 8-4-4-4-12 hex digits: on NVIDIA the GPU's UUID
    // (nvidia-smi -L, CUDA's cudaDeviceProp::uuid), which is how the CUDA trainer finds the same GPU.
    std::string device_uuid;
    std::string driver_name; // e.g. "llvmpipe" / "NVIDIA" (VkPhysicalDeviceVulkan12Properties)
    std::string driver_info; // driver version text as the driver reports it
    uint32_t api_version = 0;
    uint32_t driver_version = 0;
    uint32_t vendor_id = 0;
    bool is_cpu = false; // a software implementation (lavapipe)

    bool fp16 = false;           // shaderFloat16
    bool int8 = false;           // shaderInt8
    bool int16 = false;          // shaderInt16
    bool int64 = false;          // shaderInt64
    bool storage16 = false;      // storageBuffer16BitAccess
    bool storage8 = false;       // storageBuffer8BitAccess
    bool scalar_layout = false;  // scalarBlockLayout (required: every shared struct uses it)
    bool buffer_device_address = false;
    bool memory_model = false;   // vulkanMemoryModel
    bool descriptor_partially_bound = false; // texture arrays may leave slots unwritten
    // Descriptor indexing (core 1.2) for arrays of sampled images (engine/render/texture_path.h):
    bool runtime_descriptor_array = false;          // runtimeDescriptorArray
    bool sampled_image_array_nonuniform = false;    // shaderSampledImageArrayNonUniformIndexing
    bool subgroup_size_control = false;
    bool coop_matrix_nv = false; // VK_NV_cooperative_matrix
    std::vector<CoopMatrixShape> coop_matrix_shapes;

    bool pipeline_statistics = false; // VK_KHR_pipeline_executable_properties (NBVH_PIPELINE_STATS=1)
    bool subgroup_shuffle = false;    // subgroupShuffle* in compute shaders

    uint32_t subgroup_size = 0;
    uint32_t min_subgroup_size = 0, max_subgroup_size = 0; // equal to subgroup_size without control
    uint32_t max_shared_memory = 0;          // bytes per workgroup
    uint32_t sm_count = 0;                   // NVIDIA's SMs (VK_NV_shader_sm_builtins; 0: unknown)
    uint64_t max_storage_buffer_range = 0;   // bytes per storage-buffer binding
    uint64_t max_allocation_size = 0;        // bytes per VkDeviceMemory
    uint64_t device_local_bytes = 0;         // the largest device-local memory heap (0: unknown)
    uint32_t max_push_constants = 0;         // bytes
    uint32_t max_workgroup_invocations = 0;
    uint32_t max_workgroup_count[3] = {0, 0, 0};
    // Combined image samplers one compute pipeline may see (the smallest of the per-stage and per-set
    // sampler and sampled-image limits), resources per stage, the largest 2D image edge, allocations.
    uint32_t max_sampled_images = 0;
    uint32_t max_per_stage_resources = 0;
    uint32_t max_image_dimension_2d = 0;
    uint32_t max_memory_allocations = 0;     // maxMemoryAllocationCount
    float timestamp_period = 0.0f;           // nanoseconds per timestamp tick
    uint32_t timestamp_valid_bits = 0;       // of the compute queue; 0 = no timestamps

    std::string summary() const; // multi-line, for `nbvh info` and logs
};

class Context {
public:
    explicit Context(const ContextOptions& options = {});
    ~Context();
    Context(Context&& other) noexcept;
    Context& operator=(Context&& other) noexcept;
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    VkInstance instance() const { return instance_; }
    VkPhysicalDevice physical_device() const { return physical_; }
    VkDevice device() const { return device_; }
    VkQueue queue() const { return queue_; }
    uint32_t queue_family() const { return queue_family_; }
    const DeviceFeatures& features() const { return features_; }

    // Validation: whether the layer is active, and how many warnings + errors it reported so far
    // (each is also logged). Tests assert this stays 0.
    bool validation_enabled() const { return messenger_ != VK_NULL_HANDLE; }
    int validation_message_count() const;
    void reset_validation_message_count();

    // A memory type with all `required` flags (and all `preferred` ones when such a type exists).
    // Aborts when none fits `required` (every device has device-local and host-visible memory).
    uint32_t find_memory_type(uint32_t type_bits, VkMemoryPropertyFlags required,
                              VkMemoryPropertyFlags preferred = 0) const;

    // Debug names and labels (no-ops when VK_EXT_debug_utils is unavailable).
    void set_name(VkObjectType type, uint64_t handle, const char* name) const;
    template <class Handle> void set_name(VkObjectType type, Handle handle, const std::string& name) const {
        set_name(type, reinterpret_cast<uint64_t>(handle), name.c_str());
    }
    void begin_label(VkCommandBuffer cmd, const char* name) const;
    void end_label(VkCommandBuffer cmd) const;

    // Record with `record`, submit to the queue and wait (uploads, downloads, one-off work).
    void run_now(const std::function<void(VkCommandBuffer)>& record) const;

    void wait_idle() const;

private:
    struct Debug; // heap-held so the messenger's user pointer survives moves
    void destroy();
    void create_instance(bool validation, const std::vector<std::string>& extra_extensions);
    void pick_physical_device(DeviceChoice choice, int gpu_index);
    void create_device(const std::vector<std::string>& extra_extensions);

    std::unique_ptr<Debug> debug_;
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    uint32_t queue_family_ = 0;
    VkCommandPool transient_pool_ = VK_NULL_HANDLE; // for run_now
    VkPhysicalDeviceMemoryProperties memory_{};
    DeviceFeatures features_;
};

} // namespace nbvh::vk
