// Dear ImGui over the viewer's window: the context plus the GLFW and Vulkan backends of Debian's
// libimgui (drawn inside the presenter's UI render pass), and the mouse/keyboard handling that the
// UI does not capture (camera, split line, shortcuts).
#pragma once
#include <vulkan/vulkan.h>

#include "app/viewer/orbit_camera.h"
#include "app/viewer/presenter.h"
#include "app/viewer/ui_panel.h"
#include "engine/vk/context.h"

namespace nbvh::viewer {

class ImGuiLayer {
public:
    ImGuiLayer(const vk::Context& ctx, const Window& window, const Presenter& presenter);
    ~ImGuiLayer();
    ImGuiLayer(const ImGuiLayer&) = delete;
    ImGuiLayer& operator=(const ImGuiLayer&) = delete;

    void new_frame();
    static void record(VkCommandBuffer cmd);

private:
    const vk::Context& ctx_;
    VkDescriptorPool pool_ = VK_NULL_HANDLE;
};

// Where the film lies in the window (the presenter's aspect-preserving fit), in window pixels.
struct FilmRect {
    float x = 0.0f, y = 0.0f, width = 0.0f, height = 0.0f;
};
FilmRect film_rect(uint32_t window_width, uint32_t window_height, uint32_t film_width, uint32_t film_height);

// Mouse and keys -> camera and split line (only what the UI does not want). Returns whether the view
// moved. In the split view a left drag that starts within a few pixels of the line moves the line.
bool handle_input(OrbitCamera& camera, ViewSettings& settings, Window& window, const FilmRect& film);
// The split line (split view) over the film, and its grab handle.
void draw_split_line(const ViewSettings& settings, const FilmRect& film);

} // namespace nbvh::viewer
