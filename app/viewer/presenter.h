// The viewer's window and swapchain: a GLFW window without a client API, its Vulkan surface, a
// swapchain, and the per-frame commands that put the film on screen:
//   film stage (film_stage.h: display pass -> RGBA8 film image) -> clear + aspect-preserving blit into
//   the swapchain image -> render pass (UI drawn on top, loadOp LOAD) -> [copy to a readback buffer for
//   --screenshot] -> present.
// FRAMES_IN_FLIGHT frames in flight: draw() submits and presents without waiting; it waits only for the
// frame that last used the same slot (and for a screenshot's own frame). Recording, submission, the film
// image and semaphores are engine/vk objects (FrameSlot); what engine/vk has no notion of (surface,
// swapchain, its image views and framebuffers, the UI render pass) stays here. Presentation needs the
// Context's queue family to support the surface.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "app/viewer/film_stage.h"
#include "engine/vk/buffer.h"
#include "engine/vk/commands.h"
#include "engine/vk/context.h"

struct GLFWwindow;

namespace nbvh::viewer {

// glfwInit + a window. Throws nbvh::Error "no display available (set DISPLAY or use nbvh render)"
// without a display, and a clear line when GLFW has no Vulkan loader.
class Window {
public:
    Window(int width, int height, const std::string& title);
    ~Window();
    Window(const Window&) = delete;
    Window& operator=(const Window&) = delete;

    GLFWwindow* handle() const { return window_; }
    // Instance extensions the surface needs (VK_KHR_surface + the platform's).
    static std::vector<std::string> required_instance_extensions();
    bool should_close() const;
    void request_close();
    void set_title(const std::string& title);
    void framebuffer_size(uint32_t* width, uint32_t* height) const;
    // Paths of files dropped on the window since the last call (GLFW drop callback).
    std::vector<std::string> take_dropped();

private:
    static void on_drop(GLFWwindow* window, int count, const char** paths);
    GLFWwindow* window_ = nullptr;
    std::vector<std::string> dropped_;
};

// 8-bit RGB pixels read back from the window (for --screenshot), rows top to bottom.
struct Screenshot {
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> rgb;
};

class Presenter {
public:
    Presenter(const vk::Context& ctx, const Window& window);
    ~Presenter();
    Presenter(const Presenter&) = delete;
    Presenter& operator=(const Presenter&) = delete;

    VkRenderPass render_pass() const { return render_pass_; }
    uint32_t min_image_count() const { return min_image_count_; }
    uint32_t image_count() const { return uint32_t(images_.size()); }
    VkFormat format() const { return format_.format; }
    bool can_read_back() const { return can_read_back_; }

    // Draws one frame: the film (film stage on the GPU, then scaled to the window), `ui` records draw
    // commands inside the render pass. Submits and presents without waiting for the GPU (it waits for
    // the frame FRAMES_IN_FLIGHT back). Fills `shot` (when not null and can_read_back()) with the window
    // content, waiting for this frame. Returns false when nothing was presented (minimised window, or
    // the swapchain was out of date and has been recreated).
    bool draw(const FilmSource& film, const std::function<void(VkCommandBuffer)>& ui, Screenshot* shot = nullptr);

private:
    void create_swapchain();
    void destroy_swapchain();
    void recreate_swapchain();

    const vk::Context& ctx_;
    const Window& window_;
    VkSurfaceKHR surface_ = VK_NULL_HANDLE;
    VkSurfaceFormatKHR format_{};
    VkRenderPass render_pass_ = VK_NULL_HANDLE;
    VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
    VkExtent2D extent_{};
    uint32_t min_image_count_ = 2;
    bool can_read_back_ = false;
    std::vector<VkImage> images_;           // owned by the swapchain
    std::vector<VkImageView> views_;
    std::vector<VkFramebuffer> framebuffers_;
    std::vector<vk::Semaphore> render_done_; // one per swapchain image (presentation holds it)
    vk::Buffer readback_;                    // host-visible swapchain copy (screenshots)

    std::vector<std::unique_ptr<FrameSlot>> frames_; // FRAMES_IN_FLIGHT
    uint64_t frame_ = 0;                             // frames drawn; slot frame_ % FRAMES_IN_FLIGHT next
};

} // namespace nbvh::viewer
