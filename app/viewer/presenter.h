// The viewer's window and swapchain: a GLFW window without a client API, its Vulkan surface, a
// swapchain, and the per-frame commands that put the film on screen:
//   renderer output (linear RGBA32F, on the GPU) -> display pass (tone map + sRGB -> RGBA8 bytes, as
//   `nbvh render`'s PNGs; display_pass.h) -> film image
//   -> clear + aspect-preserving blit into the swapchain image -> render pass (UI drawn on top,
//   loadOp LOAD) -> [copy to a readback buffer for --screenshot] -> present.
// One frame in flight: the path tracer waits for its own submissions anyway, so more would buy
// nothing but complexity. Presentation needs the Context's queue family to support the surface.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "app/viewer/display_pass.h"
#include "engine/core/image.h"
#include "engine/vk/buffer.h"
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

// What a frame shows: the renderer's linear output on the GPU (WavefrontRenderer::output()); in the
// split view a second film right of a column; in the difference and FLIP views bytes made on the host.
struct FilmSource {
    const vk::Buffer* linear = nullptr; // width*height RGBA32F pixels, rows top to bottom
    uint32_t width = 0, height = 0;
    float exposure = 0.0f;              // stops
    ToneMap tone_map = ToneMap::aces;   // as nbvh render's PNGs
    const vk::Buffer* linear_right = nullptr; // split view: columns >= split_column come from this film
    uint32_t split_column = 0;
    const std::vector<uint32_t>* rgba8 = nullptr; // shown instead of the films (display-pass packing)
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

    // Draws one frame: the film (display pass on the GPU, then scaled to the window), `ui` records draw
    // commands inside the render pass. Fills `shot` (when not null and can_read_back()) with the window
    // content. Returns false when nothing was presented (minimised window, or the swapchain was out of
    // date and has been recreated).
    bool draw(const FilmSource& film, const std::function<void(VkCommandBuffer)>& ui, Screenshot* shot = nullptr);

private:
    void create_swapchain();
    void destroy_swapchain();
    void ensure_film_image(uint32_t width, uint32_t height);
    void destroy_film_image();

    const vk::Context& ctx_;
    const Window& window_;
    VkSurfaceKHR surface_ = VK_NULL_HANDLE;
    VkSurfaceFormatKHR format_{};
    VkRenderPass render_pass_ = VK_NULL_HANDLE;
    VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
    VkExtent2D extent_{};
    uint32_t min_image_count_ = 2;
    bool can_read_back_ = false;
    std::vector<VkImage> images_;
    std::vector<VkImageView> views_;
    std::vector<VkFramebuffer> framebuffers_;
    std::vector<VkSemaphore> render_done_; // one per swapchain image (presentation holds it)

    VkImage film_image_ = VK_NULL_HANDLE;
    VkDeviceMemory film_memory_ = VK_NULL_HANDLE;
    uint32_t film_width_ = 0, film_height_ = 0;
    vk::Buffer packed_;   // RGBA8 film bytes, written by the display pass
    DisplayPass display_;
    vk::Buffer packed_right_; // the split view's right film, by its own pass (one descriptor set each)
    DisplayPass display_right_;
    vk::Buffer upload_;   // host bytes (difference / FLIP views)
    vk::Buffer readback_; // host-visible swapchain copy (screenshots)

    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkCommandBuffer cmd_ = VK_NULL_HANDLE;
    VkSemaphore acquired_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
};

} // namespace nbvh::viewer
