#include "app/viewer/imgui_layer.h"

#include <algorithm>
#include <cmath>

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_vulkan.h>

namespace nbvh::viewer {

namespace {

void imgui_check_vk(VkResult r) {
    if (r != VK_SUCCESS) vk::fail_vk(__FILE__, __LINE__, "Dear ImGui Vulkan backend", r);
}

constexpr float SPLIT_GRAB_PIXELS = 6.0f;

} // namespace

ImGuiLayer::ImGuiLayer(const vk::Context& ctx, const Window& window, const Presenter& presenter) : ctx_(ctx) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr; // no imgui.ini written into the user's folder
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForVulkan(window.handle(), true);
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 4};
    VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pi.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    pi.maxSets = 4;
    pi.poolSizeCount = 1;
    pi.pPoolSizes = &size;
    NBVH_VK_CHECK(vkCreateDescriptorPool(ctx.device(), &pi, nullptr, &pool_));
    ImGui_ImplVulkan_InitInfo info{};
    info.Instance = ctx.instance();
    info.PhysicalDevice = ctx.physical_device();
    info.Device = ctx.device();
    info.QueueFamily = ctx.queue_family();
    info.Queue = ctx.queue();
    info.DescriptorPool = pool_;
    info.MinImageCount = presenter.min_image_count();
    info.ImageCount = std::max(presenter.image_count(), presenter.min_image_count());
    info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
    info.CheckVkResultFn = imgui_check_vk;
    ImGui_ImplVulkan_Init(&info, presenter.render_pass());
    ctx.run_now([](VkCommandBuffer cmd) { ImGui_ImplVulkan_CreateFontsTexture(cmd); });
    ImGui_ImplVulkan_DestroyFontUploadObjects();
}

ImGuiLayer::~ImGuiLayer() {
    ctx_.wait_idle();
    ImGui_ImplVulkan_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    vkDestroyDescriptorPool(ctx_.device(), pool_, nullptr);
}

void ImGuiLayer::new_frame() {
    ImGui_ImplVulkan_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
}

void ImGuiLayer::record(VkCommandBuffer cmd) { ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd); }

FilmRect film_rect(uint32_t ww, uint32_t wh, uint32_t fw, uint32_t fh) {
    FilmRect r;
    if (fw == 0 || fh == 0) return r;
    // As Presenter::draw's blit (rounded the same way).
    const float scale = std::min(float(ww) / float(fw), float(wh) / float(fh));
    const int dw = std::max(1, int(float(fw) * scale + 0.5f)), dh = std::max(1, int(float(fh) * scale + 0.5f));
    r.x = float(std::max(0, (int(ww) - dw) / 2));
    r.y = float(std::max(0, (int(wh) - dh) / 2));
    r.width = float(dw);
    r.height = float(dh);
    return r;
}

bool handle_input(OrbitCamera& cam, ViewSettings& s, Window& window, const FilmRect& film) {
    const ImGuiIO& io = ImGui::GetIO();
    bool moved = false;
    if (!io.WantCaptureMouse) {
        const ImVec2 d = io.MouseDelta;
        const bool drag = d.x != 0.0f || d.y != 0.0f;
        const bool pan = ImGui::IsMouseDown(ImGuiMouseButton_Middle) || (ImGui::IsMouseDown(0) && io.KeyShift);
        // The split line: a left drag that started on it moves it (not the camera).
        const float line_x = film.x + s.split * film.width;
        const bool on_line = s.view == ViewMode::split && film.width > 0.0f &&
                             std::fabs(io.MouseClickedPos[0].x - line_x) <= SPLIT_GRAB_PIXELS;
        if (on_line && ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
            s.split = std::clamp((io.MousePos.x - film.x) / film.width, 0.0f, 1.0f);
        } else if (drag && pan) {
            cam.pan(d.x, d.y, film.height > 0.0f ? film.height : 1.0f);
            moved = true;
        } else if (drag && ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
            cam.orbit(d.x, d.y);
            moved = true;
        }
        if (io.MouseWheel != 0.0f) {
            cam.zoom(io.MouseWheel);
            moved = true;
        }
    }
    if (!io.WantCaptureKeyboard) {
        auto down = [](int key) { return ImGui::IsKeyDown(key) ? 1.0f : 0.0f; };
        const float f = down(GLFW_KEY_W) - down(GLFW_KEY_S), r = down(GLFW_KEY_D) - down(GLFW_KEY_A);
        const float u = down(GLFW_KEY_E) - down(GLFW_KEY_Q);
        if (f != 0.0f || r != 0.0f || u != 0.0f) {
            cam.fly(f, r, u, std::min(io.DeltaTime, 0.1f));
            moved = true;
        }
        if (ImGui::IsKeyPressed(GLFW_KEY_R, false)) {
            cam.reset();
            moved = true;
        }
        if (ImGui::IsKeyPressed(GLFW_KEY_F1, false)) s.show_ui = !s.show_ui;
        if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false)) window.request_close();
    }
    return moved;
}

void draw_split_line(const ViewSettings& s, const FilmRect& film) {
    if (s.view != ViewMode::split || film.width <= 0.0f) return;
    ImDrawList* dl = ImGui::GetBackgroundDrawList();
    const float x = std::floor(film.x + s.split * film.width) + 0.5f;
    dl->AddLine(ImVec2(x, film.y), ImVec2(x, film.y + film.height), IM_COL32(255, 255, 255, 200), 1.0f);
    const float cy = film.y + 0.5f * film.height;
    dl->AddCircleFilled(ImVec2(x, cy), 5.0f, IM_COL32(255, 255, 255, 200));
    dl->AddText(ImVec2(x - 52.0f, film.y + 4.0f), IM_COL32(255, 255, 255, 220), "hybrid");
    dl->AddText(ImVec2(x + 6.0f, film.y + 4.0f), IM_COL32(255, 255, 255, 220), "classical");
}

} // namespace nbvh::viewer
