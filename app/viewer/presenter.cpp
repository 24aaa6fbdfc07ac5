#include "app/viewer/presenter.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh::viewer {

namespace {

bool is_srgb(VkFormat f) { return f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_R8G8B8A8_SRGB; }
bool is_bgra(VkFormat f) { return f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM; }

void glfw_error(int code, const char* text) { log_debug("glfw error %d: %s", code, text); }

} // namespace

// --- Window -------------------------------------------------------------------------------------

Window::Window(int width, int height, const std::string& title) {
    const char* x11 = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if ((!x11 || !*x11) && (!wayland || !*wayland))
        throw Error("no display available (set DISPLAY or use nbvh render)");
    glfwSetErrorCallback(glfw_error);
    if (!glfwInit()) throw Error("no display available (set DISPLAY or use nbvh render)");
    if (!glfwVulkanSupported()) {
        glfwTerminate();
        throw Error("GLFW found no Vulkan loader for windows (install libvulkan1 and a Vulkan driver)");
    }
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!window_) {
        glfwTerminate();
        throw Error("no display available (set DISPLAY or use nbvh render)");
    }
    glfwSetWindowUserPointer(window_, this); // Dear ImGui's GLFW backend keeps its state elsewhere
    glfwSetDropCallback(window_, on_drop);
}

void Window::on_drop(GLFWwindow* window, int count, const char** paths) {
    auto* self = static_cast<Window*>(glfwGetWindowUserPointer(window));
    if (!self) return;
    for (int i = 0; i < count; ++i)
        if (paths[i]) self->dropped_.emplace_back(paths[i]);
}

std::vector<std::string> Window::take_dropped() {
    std::vector<std::string> out;
    out.swap(dropped_);
    return out;
}

Window::~Window() {
    if (window_) glfwDestroyWindow(window_);
    glfwTerminate();
}

std::vector<std::string> Window::required_instance_extensions() {
    uint32_t count = 0;
    const char** names = glfwGetRequiredInstanceExtensions(&count);
    if (!names) throw Error("GLFW cannot make Vulkan surfaces on this display");
    return std::vector<std::string>(names, names + count);
}

bool Window::should_close() const { return glfwWindowShouldClose(window_); }
void Window::request_close() { glfwSetWindowShouldClose(window_, GLFW_TRUE); }
void Window::set_title(const std::string& title) { glfwSetWindowTitle(window_, title.c_str()); }
void Window::framebuffer_size(uint32_t* width, uint32_t* height) const {
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    *width = uint32_t(std::max(w, 0));
    *height = uint32_t(std::max(h, 0));
}

// --- Presenter ----------------------------------------------------------------------------------

Presenter::Presenter(const vk::Context& ctx, const Window& window)
    : ctx_(ctx), window_(window) {
    NBVH_VK_CHECK(glfwCreateWindowSurface(ctx_.instance(), window_.handle(), nullptr, &surface_));
    VkBool32 supported = VK_FALSE;
    NBVH_VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(ctx_.physical_device(), ctx_.queue_family(), surface_, &supported));
    if (!supported) {
        vkDestroySurfaceKHR(ctx_.instance(), surface_, nullptr);
        throw Error(strfmt("the Vulkan device %s cannot present to this window from its compute queue",
                           ctx_.features().device_name.c_str()));
    }
    // Prefer a UNORM format: the host writes sRGB-encoded bytes and the blit copies them unchanged.
    uint32_t count = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(ctx_.physical_device(), surface_, &count, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(count);
    vkGetPhysicalDeviceSurfaceFormatsKHR(ctx_.physical_device(), surface_, &count, formats.data());
    if (formats.empty()) throw Error("the window surface offers no formats");
    format_ = formats[0];
    for (VkFormat want : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_SRGB,
                          VK_FORMAT_R8G8B8A8_SRGB}) {
        auto it = std::find_if(formats.begin(), formats.end(), [&](const VkSurfaceFormatKHR& f) {
            return f.format == want && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
        });
        if (it != formats.end()) { format_ = *it; break; }
    }
    VkFormatProperties fp{};
    vkGetPhysicalDeviceFormatProperties(ctx_.physical_device(), format_.format, &fp);
    if (!(fp.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT))
        throw Error("the swapchain format does not support blits on this device");

    // UI pass: draws over the blitted film, ends ready to present.
    VkAttachmentDescription color{};
    color.format = format_.format;
    color.samples = VK_SAMPLE_COUNT_1_BIT;
    color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
    color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    color.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    color.finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &ref;
    VkSubpassDependency dep{};
    dep.srcSubpass = VK_SUBPASS_EXTERNAL;
    dep.dstSubpass = 0;
    dep.srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    dep.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    dep.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    dep.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    VkRenderPassCreateInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rp.attachmentCount = 1;
    rp.pAttachments = &color;
    rp.subpassCount = 1;
    rp.pSubpasses = &sub;
    rp.dependencyCount = 1;
    rp.pDependencies = &dep;
    NBVH_VK_CHECK(vkCreateRenderPass(ctx_.device(), &rp, nullptr, &render_pass_));

    // Frame slots: an sRGB swapchain gets sRGB film images (a blit between sRGB formats decodes and
    // re-encodes, identity up to rounding), a UNORM one UNORM images (the bytes are copied).
    for (uint32_t i = 0; i < FRAMES_IN_FLIGHT; ++i)
        frames_.push_back(std::make_unique<FrameSlot>(ctx_, is_srgb(format_.format), "viewer frame"));
    create_swapchain();
}

Presenter::~Presenter() {
    vkDeviceWaitIdle(ctx_.device());
    frames_.clear();
    destroy_swapchain();
    if (render_pass_) vkDestroyRenderPass(ctx_.device(), render_pass_, nullptr);
    if (surface_) vkDestroySurfaceKHR(ctx_.instance(), surface_, nullptr);
}

void Presenter::create_swapchain() {
    VkSurfaceCapabilitiesKHR caps{};
    NBVH_VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx_.physical_device(), surface_, &caps));
    uint32_t w = 0, h = 0;
    window_.framebuffer_size(&w, &h);
    extent_ = caps.currentExtent.width != UINT32_MAX ? caps.currentExtent : VkExtent2D{w, h};
    extent_.width = std::clamp(extent_.width, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent_.height = std::clamp(extent_.height, caps.minImageExtent.height, caps.maxImageExtent.height);
    if (extent_.width == 0 || extent_.height == 0) return; // minimised: try again next frame
    min_image_count_ = std::max(2u, caps.minImageCount);
    uint32_t image_count = caps.minImageCount + 1;
    if (caps.maxImageCount > 0) image_count = std::min(image_count, caps.maxImageCount);
    const VkImageUsageFlags need = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    if ((caps.supportedUsageFlags & need) != need)
        throw Error("the window surface does not support transfer-destination swapchain images");
    can_read_back_ = (caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) != 0;

    VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    info.surface = surface_;
    info.minImageCount = image_count;
    info.imageFormat = format_.format;
    info.imageColorSpace = format_.colorSpace;
    info.imageExtent = extent_;
    info.imageArrayLayers = 1;
    info.imageUsage = need | (can_read_back_ ? VkImageUsageFlags(VK_IMAGE_USAGE_TRANSFER_SRC_BIT) : VkImageUsageFlags(0));
    info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.preTransform = caps.currentTransform;
    info.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                              ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                              : VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha & -caps.supportedCompositeAlpha);
    info.presentMode = VK_PRESENT_MODE_FIFO_KHR; // always available; vsync keeps an idle viewer cheap
    info.clipped = VK_TRUE;
    NBVH_VK_CHECK(vkCreateSwapchainKHR(ctx_.device(), &info, nullptr, &swapchain_));

    uint32_t n = 0;
    vkGetSwapchainImagesKHR(ctx_.device(), swapchain_, &n, nullptr);
    images_.resize(n);
    vkGetSwapchainImagesKHR(ctx_.device(), swapchain_, &n, images_.data());
    for (VkImage image : images_) {
        VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
        vi.image = image;
        vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
        vi.format = format_.format;
        vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        VkImageView view = VK_NULL_HANDLE;
        NBVH_VK_CHECK(vkCreateImageView(ctx_.device(), &vi, nullptr, &view));
        views_.push_back(view);
        VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
        fb.renderPass = render_pass_;
        fb.attachmentCount = 1;
        fb.pAttachments = &view;
        fb.width = extent_.width;
        fb.height = extent_.height;
        fb.layers = 1;
        VkFramebuffer framebuffer = VK_NULL_HANDLE;
        NBVH_VK_CHECK(vkCreateFramebuffer(ctx_.device(), &fb, nullptr, &framebuffer));
        framebuffers_.push_back(framebuffer);
        render_done_.emplace_back(ctx_, "viewer render done");
    }
    if (can_read_back_)
        readback_ = vk::Buffer(ctx_, uint64_t(extent_.width) * extent_.height * 4, vk::MemoryKind::host, 0,
                               "viewer readback");
}

void Presenter::destroy_swapchain() {
    for (VkFramebuffer f : framebuffers_) vkDestroyFramebuffer(ctx_.device(), f, nullptr);
    for (VkImageView v : views_) vkDestroyImageView(ctx_.device(), v, nullptr);
    framebuffers_.clear();
    views_.clear();
    render_done_.clear();
    images_.clear();
    if (swapchain_) vkDestroySwapchainKHR(ctx_.device(), swapchain_, nullptr);
    swapchain_ = VK_NULL_HANDLE;
    readback_ = vk::Buffer();
}

void Presenter::recreate_swapchain() {
    vkDeviceWaitIdle(ctx_.device()); // every frame in flight is done with the old images
    destroy_swapchain();
    create_swapchain();
}

bool Presenter::draw(const FilmSource& film, const std::function<void(VkCommandBuffer)>& ui, Screenshot* shot) {
    uint32_t fw = 0, fh = 0;
    window_.framebuffer_size(&fw, &fh);
    if (fw == 0 || fh == 0) return false;
    if (!swapchain_ || fw != extent_.width || fh != extent_.height) {
        recreate_swapchain();
        if (!swapchain_) return false;
    }
    // The slot's previous frame must be done before its semaphore, buffers and image are reused.
    FrameSlot& f = *frames_[frame_ % FRAMES_IN_FLIGHT];
    f.cmd.wait();
    uint32_t index = 0;
    VkResult r = vkAcquireNextImageKHR(ctx_.device(), swapchain_, UINT64_MAX, f.acquired.handle(), VK_NULL_HANDLE,
                                       &index);
    if (r == VK_ERROR_OUT_OF_DATE_KHR) { // the semaphore was not signalled
        recreate_swapchain();
        return false;
    }
    if (r != VK_SUBOPTIMAL_KHR) NBVH_VK_CHECK(r);

    vk::CommandBuffer& cmd = f.cmd;
    cmd.begin();
    const vk::Image& image = f.film.record(cmd, film);
    const uint32_t width = image.width(), height = image.height();
    // Swapchain image: clear (letterbox bars), then the film scaled to fit with its aspect kept.
    const VkPipelineStageFlags T = VK_PIPELINE_STAGE_TRANSFER_BIT;
    const VkImage target = images_[index];
    cmd.transition(target, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, T, 0, T,
                   VK_ACCESS_TRANSFER_WRITE_BIT);
    const VkClearColorValue black{{0.0f, 0.0f, 0.0f, 1.0f}};
    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cmd.handle(), target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &black, 1, &range);
    cmd.transition(target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, T,
                   VK_ACCESS_TRANSFER_WRITE_BIT, T, VK_ACCESS_TRANSFER_WRITE_BIT);
    const float scale = std::min(float(extent_.width) / float(width), float(extent_.height) / float(height));
    const int32_t dw = std::max(1, int32_t(float(width) * scale + 0.5f));
    const int32_t dh = std::max(1, int32_t(float(height) * scale + 0.5f));
    const int32_t dx = (int32_t(extent_.width) - dw) / 2, dy = (int32_t(extent_.height) - dh) / 2;
    VkImageBlit blit{};
    blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.srcOffsets[1] = {int32_t(width), int32_t(height), 1};
    blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.dstOffsets[0] = {std::max(dx, 0), std::max(dy, 0), 0};
    blit.dstOffsets[1] = {std::max(dx, 0) + std::min(dw, int32_t(extent_.width)),
                          std::max(dy, 0) + std::min(dh, int32_t(extent_.height)), 1};
    const VkFilter filter = (dw == int32_t(width) && dh == int32_t(height)) ? VK_FILTER_NEAREST : VK_FILTER_LINEAR;
    cmd.transition(image.handle(), VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, T,
                   VK_ACCESS_TRANSFER_WRITE_BIT, T, VK_ACCESS_TRANSFER_READ_BIT);
    vkCmdBlitImage(cmd.handle(), image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, filter);
    cmd.transition(image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL, T,
                   VK_ACCESS_TRANSFER_READ_BIT, T, 0); // the image layer's convention (engine/vk/image.h)
    cmd.transition(target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, T,
                   VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                   VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    // UI on top.
    VkRenderPassBeginInfo rb{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rb.renderPass = render_pass_;
    rb.framebuffer = framebuffers_[index];
    rb.renderArea.extent = extent_;
    vkCmdBeginRenderPass(cmd.handle(), &rb, VK_SUBPASS_CONTENTS_INLINE);
    if (ui) ui(cmd.handle());
    vkCmdEndRenderPass(cmd.handle());
    const bool read = shot && can_read_back_;
    if (read) {
        cmd.transition(target, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                       VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, T,
                       VK_ACCESS_TRANSFER_READ_BIT);
        VkBufferImageCopy back{};
        back.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        back.imageExtent = {extent_.width, extent_.height, 1};
        vkCmdCopyImageToBuffer(cmd.handle(), target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback_.handle(), 1,
                               &back);
        cmd.transition(target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, T,
                       VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0);
        cmd.barrier(vk::Barrier::compute_to_host);
    }
    const VkSemaphore done = render_done_[index].handle();
    cmd.submit({.wait = f.acquired.handle(), .wait_stage = T | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                .signal = done});
    ++frame_;

    VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    pi.waitSemaphoreCount = 1;
    pi.pWaitSemaphores = &done;
    pi.swapchainCount = 1;
    pi.pSwapchains = &swapchain_;
    pi.pImageIndices = &index;
    r = vkQueuePresentKHR(ctx_.queue(), &pi);
    if (read) {
        cmd.wait();
        shot->width = extent_.width;
        shot->height = extent_.height;
        shot->rgb.resize(size_t(extent_.width) * extent_.height * 3);
        const uint8_t* src = static_cast<const uint8_t*>(readback_.mapped());
        const bool bgra = is_bgra(format_.format);
        for (size_t i = 0; i < size_t(extent_.width) * extent_.height; ++i) {
            shot->rgb[3 * i + 0] = src[4 * i + (bgra ? 2 : 0)];
            shot->rgb[3 * i + 1] = src[4 * i + 1];
            shot->rgb[3 * i + 2] = src[4 * i + (bgra ? 0 : 2)];
        }
    }
    if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) recreate_swapchain();
    else NBVH_VK_CHECK(r);
    return true;
}

} // namespace nbvh::viewer
