#include "context.h"

#include "engine/core/log.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>

namespace nbvh::vk {

const char* result_name(VkResult r) {
    switch (r) {
#define NBVH_CASE(x) case x: return #x
        NBVH_CASE(VK_SUCCESS);
        NBVH_CASE(VK_NOT_READY);
        NBVH_CASE(VK_TIMEOUT);
        NBVH_CASE(VK_EVENT_SET);
        NBVH_CASE(VK_EVENT_RESET);
        NBVH_CASE(VK_INCOMPLETE);
        NBVH_CASE(VK_ERROR_OUT_OF_HOST_MEMORY);
        NBVH_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY);
        NBVH_CASE(VK_ERROR_INITIALIZATION_FAILED);
        NBVH_CASE(VK_ERROR_DEVICE_LOST);
        NBVH_CASE(VK_ERROR_MEMORY_MAP_FAILED);
        NBVH_CASE(VK_ERROR_LAYER_NOT_PRESENT);
        NBVH_CASE(VK_ERROR_EXTENSION_NOT_PRESENT);
        NBVH_CASE(VK_ERROR_FEATURE_NOT_PRESENT);
        NBVH_CASE(VK_ERROR_INCOMPATIBLE_DRIVER);
        NBVH_CASE(VK_ERROR_TOO_MANY_OBJECTS);
        NBVH_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED);
        NBVH_CASE(VK_ERROR_FRAGMENTED_POOL);
        NBVH_CASE(VK_ERROR_UNKNOWN);
        NBVH_CASE(VK_ERROR_OUT_OF_POOL_MEMORY);
        NBVH_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE);
        NBVH_CASE(VK_ERROR_FRAGMENTATION);
        NBVH_CASE(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS);
#undef NBVH_CASE
    default: return "VkResult(unknown)";
    }
}

void fail_vk(const char* file, int line, const char* expr, VkResult result) {
    std::fprintf(stderr, "nbvh: Vulkan call failed at %s:%d: %s returned %s (%d)\n", file, line, expr,
                 result_name(result), int(result));
    std::fflush(stderr);
    std::abort();
}

DeviceChoice parse_device_choice(std::string_view text) {
    if (text == "auto") return DeviceChoice::automatic;
    if (text == "gpu") return DeviceChoice::gpu;
    if (text == "cpu") return DeviceChoice::cpu;
    throw Error("unknown --device '" + std::string(text) + "' (expected auto, gpu or cpu)");
}

DeviceSpec parse_device_spec(std::string_view text) {
    constexpr std::string_view prefix = "gpu:";
    const bool indexed = text.substr(0, prefix.size()) == prefix;
    const std::string_view digits = indexed ? text.substr(prefix.size()) : std::string_view();
    const bool ok =
        indexed ? !digits.empty() && digits.size() <= 4 &&
                      std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })
                : text == "auto" || text == "gpu" || text == "cpu";
    if (!ok)
        throw Error("unknown --device '" + std::string(text) +
                    "' (expected auto, gpu, gpu:N with N the GPU's number from 0, or cpu)");
    if (!indexed) return {parse_device_choice(text), -1};
    return {DeviceChoice::gpu, std::stoi(std::string(digits))};
}

const char* device_choice_name(DeviceChoice c) {
    switch (c) {
    case DeviceChoice::gpu: return "gpu";
    case DeviceChoice::cpu: return "cpu";
    default: return "auto";
    }
}

// --- validation messenger and debug-utils entry points ---------------------------------------

struct Context::Debug {
    std::atomic<int> messages{0};
    PFN_vkCreateDebugUtilsMessengerEXT create_messenger = nullptr;
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger = nullptr;
    PFN_vkSetDebugUtilsObjectNameEXT set_name = nullptr;
    PFN_vkCmdBeginDebugUtilsLabelEXT begin_label = nullptr;
    PFN_vkCmdEndDebugUtilsLabelEXT end_label = nullptr;
};

static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* debug = static_cast<std::atomic<int>*>(user);
    const char* text = data && data->pMessage ? data->pMessage : "(no message)";
    if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        debug->fetch_add(1);
        log_error("vulkan validation: %s", text);
    } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        debug->fetch_add(1);
        log_warn("vulkan validation: %s", text);
    }
    return VK_FALSE; // never abort the call: the count is checked by tests
}

static bool env_flag(const char* name, bool fallback) {
    const char* v = std::getenv(name);
    if (!v || !*v) return fallback;
    return !(std::strcmp(v, "0") == 0 || std::strcmp(v, "off") == 0 || std::strcmp(v, "false") == 0);
}

// --- construction ------------------------------------------------------------------------------

Context::Context(const ContextOptions& options) : debug_(std::make_unique<Debug>()) {
    try {
        create_instance(env_flag("NBVH_VALIDATION", options.validation), options.instance_extensions);
        pick_physical_device(options.device, options.device == DeviceChoice::gpu ? options.gpu_index : -1);
        create_device(options.device_extensions);
    } catch (...) {
        destroy();
        throw;
    }
}

Context::~Context() { destroy(); }

Context::Context(Context&& o) noexcept { *this = std::move(o); }

Context& Context::operator=(Context&& o) noexcept {
    if (this != &o) {
        destroy();
        debug_ = std::move(o.debug_);
        instance_ = std::exchange(o.instance_, VK_NULL_HANDLE);
        messenger_ = std::exchange(o.messenger_, VK_NULL_HANDLE);
        physical_ = std::exchange(o.physical_, VK_NULL_HANDLE);
        device_ = std::exchange(o.device_, VK_NULL_HANDLE);
        queue_ = std::exchange(o.queue_, VK_NULL_HANDLE);
        queue_family_ = o.queue_family_;
        transient_pool_ = std::exchange(o.transient_pool_, VK_NULL_HANDLE);
        memory_ = o.memory_;
        features_ = std::move(o.features_);
    }
    return *this;
}

void Context::destroy() {
    if (device_) {
        vkDeviceWaitIdle(device_);
        if (transient_pool_) vkDestroyCommandPool(device_, transient_pool_, nullptr);
        vkDestroyDevice(device_, nullptr);
    }
    if (messenger_ && debug_ && debug_->destroy_messenger)
        debug_->destroy_messenger(instance_, messenger_, nullptr);
    if (instance_) vkDestroyInstance(instance_, nullptr);
    transient_pool_ = VK_NULL_HANDLE;
    device_ = VK_NULL_HANDLE;
    messenger_ = VK_NULL_HANDLE;
    instance_ = VK_NULL_HANDLE;
}

void Context::create_instance(bool validation, const std::vector<std::string>& extra_extensions) {
    uint32_t loader_version = VK_API_VERSION_1_0;
    if (vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS || loader_version < VK_API_VERSION_1_2)
        throw Error("the Vulkan loader is older than Vulkan 1.2; install a newer libvulkan1");

    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    const char* validation_layer = "VK_LAYER_KHRONOS_validation";
    bool have_layer = std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) {
        return std::strcmp(l.layerName, validation_layer) == 0;
    });
    if (validation && !have_layer) {
        log_warn("validation requested but %s is not installed (Debian: vulkan-validationlayers); "
                 "continuing without it", validation_layer);
        validation = false;
    }

    count = 0;
    vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> exts(count);
    vkEnumerateInstanceExtensionProperties(nullptr, &count, exts.data());
    bool have_debug_utils = std::any_of(exts.begin(), exts.end(), [](const VkExtensionProperties& e) {
        return std::strcmp(e.extensionName, VK_EXT_DEBUG_UTILS_EXTENSION_NAME) == 0;
    });

    std::vector<const char*> enabled_exts;
    if (have_debug_utils) enabled_exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    for (const std::string& name : extra_extensions) {
        if (!std::any_of(exts.begin(), exts.end(), [&](const VkExtensionProperties& e) { return name == e.extensionName; }))
            throw Error(strfmt("the Vulkan loader lacks the instance extension %s", name.c_str()));
        enabled_exts.push_back(name.c_str());
    }

    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "nbvh";
    app.pEngineName = "nbvh";
    app.apiVersion = VK_API_VERSION_1_2; // the project targets Vulkan 1.2 core
    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pApplicationInfo = &app;
    info.enabledLayerCount = validation ? 1u : 0u;
    info.ppEnabledLayerNames = &validation_layer;
    info.enabledExtensionCount = uint32_t(enabled_exts.size());
    info.ppEnabledExtensionNames = enabled_exts.data();
    VkResult r = vkCreateInstance(&info, nullptr, &instance_);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER || r == VK_ERROR_INITIALIZATION_FAILED)
        throw Error(strfmt("no usable Vulkan driver (vkCreateInstance: %s); install a Vulkan driver "
                           "(Debian: mesa-vulkan-drivers for the CPU device)", result_name(r)));
    NBVH_VK_CHECK(r);

    if (have_debug_utils) {
        auto get = [&](const char* name) { return vkGetInstanceProcAddr(instance_, name); };
        debug_->create_messenger = (PFN_vkCreateDebugUtilsMessengerEXT)get("vkCreateDebugUtilsMessengerEXT");
        debug_->destroy_messenger = (PFN_vkDestroyDebugUtilsMessengerEXT)get("vkDestroyDebugUtilsMessengerEXT");
        debug_->set_name = (PFN_vkSetDebugUtilsObjectNameEXT)get("vkSetDebugUtilsObjectNameEXT");
        debug_->begin_label = (PFN_vkCmdBeginDebugUtilsLabelEXT)get("vkCmdBeginDebugUtilsLabelEXT");
        debug_->end_label = (PFN_vkCmdEndDebugUtilsLabelEXT)get("vkCmdEndDebugUtilsLabelEXT");
    }
    if (validation && debug_->create_messenger) {
        VkDebugUtilsMessengerCreateInfoEXT m{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
        m.messageSeverity =
            VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
        m.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
        m.pfnUserCallback = on_validation_message;
        m.pUserData = &debug_->messages;
        NBVH_VK_CHECK(debug_->create_messenger(instance_, &m, nullptr, &messenger_));
    }
}

int Context::validation_message_count() const { return debug_ ? debug_->messages.load() : 0; }
void Context::reset_validation_message_count() {
    if (debug_) debug_->messages = 0;
}

uint32_t Context::find_memory_type(uint32_t type_bits, VkMemoryPropertyFlags required,
                                   VkMemoryPropertyFlags preferred) const {
    for (int pass = 0; pass < 2; ++pass) {
        VkMemoryPropertyFlags want = pass == 0 ? (required | preferred) : required;
        for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
            if ((type_bits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & want) == want) return i;
    }
    NBVH_CHECK_MSG(false, "no Vulkan memory type with the required properties");
}

void Context::set_name(VkObjectType type, uint64_t handle, const char* name) const {
    if (!debug_->set_name || !device_ || !handle) return;
    VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    info.objectType = type;
    info.objectHandle = handle;
    info.pObjectName = name;
    debug_->set_name(device_, &info);
}

void Context::begin_label(VkCommandBuffer cmd, const char* name) const {
    if (!debug_->begin_label) return;
    VkDebugUtilsLabelEXT label{VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT};
    label.pLabelName = name;
    debug_->begin_label(cmd, &label);
}

void Context::end_label(VkCommandBuffer cmd) const {
    if (debug_->end_label) debug_->end_label(cmd);
}

void Context::run_now(const std::function<void(VkCommandBuffer)>& record) const {
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = transient_pool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    NBVH_VK_CHECK(vkAllocateCommandBuffers(device_, &alloc, &cmd));
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    NBVH_VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
    record(cmd);
    NBVH_VK_CHECK(vkEndCommandBuffer(cmd));

    VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence = VK_NULL_HANDLE;
    NBVH_VK_CHECK(vkCreateFence(device_, &fence_info, nullptr, &fence));
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    NBVH_VK_CHECK(vkQueueSubmit(queue_, 1, &submit, fence));
    NBVH_VK_CHECK(vkWaitForFences(device_, 1, &fence, VK_TRUE, UINT64_MAX));
    vkDestroyFence(device_, fence, nullptr);
    vkFreeCommandBuffers(device_, transient_pool_, 1, &cmd);
}

void Context::wait_idle() const { NBVH_VK_CHECK(vkDeviceWaitIdle(device_)); }

} // namespace nbvh::vk
