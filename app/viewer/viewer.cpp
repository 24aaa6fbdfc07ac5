#include "app/viewer/viewer.h"

#include <chrono>
#include <memory>

#include <vulkan/vulkan.h>
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_vulkan.h>

#include "app/scene_arg.h"
#include "app/viewer/orbit_camera.h"
#include "app/viewer/presenter.h"
#include "app/viewer/ui_panel.h"
#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "engine/core/image.h"
#include "engine/core/log.h"
#include "engine/neural/model_file.h"
#include "engine/render/wavefront.h"
#include "engine/scene/camera.h"
#include "engine/scene/environment.h"
#include "engine/scene/gltf_loader.h"
#include "engine/vk/context.h"

namespace nbvh::viewer {

namespace {

void imgui_check_vk(VkResult r) {
    if (r != VK_SUCCESS) vk::fail_vk(__FILE__, __LINE__, "Dear ImGui Vulkan backend", r);
}

// Dear ImGui context + the GLFW and Vulkan backends of Debian's libimgui (draws in the presenter's
// render pass).
class ImGuiLayer {
public:
    ImGuiLayer(const vk::Context& ctx, const Window& window, const Presenter& presenter) : ctx_(ctx) {
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
    ~ImGuiLayer() {
        ctx_.wait_idle();
        ImGui_ImplVulkan_Shutdown();
        ImGui_ImplGlfw_Shutdown();
        ImGui::DestroyContext();
        vkDestroyDescriptorPool(ctx_.device(), pool_, nullptr);
    }
    ImGuiLayer(const ImGuiLayer&) = delete;
    ImGuiLayer& operator=(const ImGuiLayer&) = delete;

    void new_frame() {
        ImGui_ImplVulkan_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
    }
    static void record(VkCommandBuffer cmd) { ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd); }

private:
    const vk::Context& ctx_;
    VkDescriptorPool pool_ = VK_NULL_HANDLE;
};

// As nbvh render: --env, else the scene's, else the default sky when nothing else lights the scene.
Environment choose_environment(const Scene& scene, const std::string& env_path) {
    if (!env_path.empty()) return load_environment(env_path);
    if (!scene.environment.empty()) return scene.environment;
    if (!render::derive_features(scene, Environment{}).emission) return default_sky();
    return Environment{};
}

// Mouse and keys -> camera (only when the UI does not want them). Returns whether the view moved.
bool handle_input(OrbitCamera& cam, ViewSettings& s, Window& window, float viewport_height) {
    const ImGuiIO& io = ImGui::GetIO();
    bool moved = false;
    if (!io.WantCaptureMouse) {
        const ImVec2 d = io.MouseDelta;
        const bool drag = d.x != 0.0f || d.y != 0.0f;
        const bool pan = ImGui::IsMouseDown(ImGuiMouseButton_Middle) || (ImGui::IsMouseDown(0) && io.KeyShift);
        if (drag && pan) {
            cam.pan(d.x, d.y, viewport_height);
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

} // namespace

void run_viewer(const ViewerArgs& a) {
    if (!a.screenshot.empty() && !is_png_path(a.screenshot))
        throw Error(strfmt("--screenshot '%s': expected a .png file name", a.screenshot.c_str()));
    Window window(int(a.width), int(a.height), "nbvh view"); // fails first without a display

    SceneLoadOptions lo;
    lo.neural_glob = a.neural_glob;
    NeuralModel model;
    const bool has_model = !a.model.empty();
    if (has_model) model = load_model(a.model);
    const Scene scene = app::load_scene_for_model(a.scene, lo, has_model ? &model : nullptr, a.model);
    const Environment env = choose_environment(scene, a.env);
    uint32_t fb_w = 0, fb_h = 0;
    window.framebuffer_size(&fb_w, &fb_h);
    uint32_t width = fb_w ? fb_w : a.width, height = fb_h ? fb_h : a.height;
    const Camera home = scene.has_camera ? scene.camera : auto_frame(scene, float(width) / float(height));
    const auto t0 = std::chrono::steady_clock::now();
    const SceneAccel accel = build_scene_accel(scene);
    log_info("view: BVHs built in %.1f ms",
             std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());

    vk::ContextOptions copt;
    copt.device = vk::parse_device_choice(a.device);
    copt.instance_extensions = Window::required_instance_extensions();
    copt.device_extensions = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
    vk::Context ctx(copt);
    log_info("view: %s", ctx.features().device_name.c_str());
    if (ctx.validation_enabled()) log_info("view: Vulkan validation on");
    {
        Presenter presenter(ctx, window);
        ImGuiLayer ui(ctx, window, presenter);

        ViewSettings s;
        s.max_depth = int(a.max_depth);
        s.lod = int(a.lod);
        s.secondary_lod = a.secondary_lod;
        s.show_ui = !a.hide_ui;
        if (has_model) {
            s.lod = std::min(s.lod, int(model.lod_count) - 1);
            s.secondary_lod = std::min(s.secondary_lod, int(model.lod_count) - 1);
        }
        PanelInfo info;
        info.scene = a.scene;
        info.device = ctx.features().device_name;
        info.has_model = has_model;
        if (has_model) info.lod_node_counts = model.lod_node_counts;

        OrbitCamera cam(home);
        std::unique_ptr<render::WavefrontRenderer> renderer;
        bool rebuild = true, camera_moved = false, restart = false;
        Screenshot shot;
        uint32_t frame = 0;

        while (!window.should_close()) {
            const bool idle = renderer && s.max_samples > 0 && renderer->accumulated_samples() >= uint32_t(s.max_samples);
            if (idle && a.frames == 0) glfwWaitEventsTimeout(0.05); // converged: do not spin
            else glfwPollEvents();
            window.framebuffer_size(&fb_w, &fb_h);
            if (fb_w > 0 && fb_h > 0 && (fb_w != width || fb_h != height)) {
                width = fb_w; // the film follows the window
                height = fb_h;
                rebuild = true;
            }
            // Input of the previous frame's UI pass applies here, so the panel below shows this frame's numbers.
            if (rebuild) {
                render::RenderOptions o;
                o.width = width;
                o.height = height;
                o.spp = 1;
                o.max_depth = uint32_t(s.max_depth);
                if (has_model) {
                    o.neural.model = s.neural ? &model : nullptr;
                    o.neural.classical = !s.neural;
                    o.neural.lod = uint32_t(s.lod);
                    o.neural.secondary_lod = s.secondary_lod;
                    o.neural.roughness = s.override_material ? s.roughness : -1.0f;
                    o.neural.metallic = s.override_material ? s.metallic : -1.0f;
                }
                try {
                    ctx.wait_idle();
                    // Settings are uploads (WavefrontRenderer::apply); a new renderer only for what needs
                    // new buffers or pipelines (window size, leaves per round, overrides of a classical view).
                    if (renderer && renderer->apply(o)) {
                        info.live_updates++;
                    } else {
                        auto next = std::make_unique<render::WavefrontRenderer>(ctx, scene, accel, env, cam.camera(), o);
                        renderer = std::move(next);
                        info.renderer_builds++;
                    }
                    info.status.clear();
                } catch (const Error& e) {
                    if (!renderer) throw; // nothing to fall back to
                    info.status = strfmt("not applied: %s", e.what());
                }
                rebuild = false;
                camera_moved = false;
            }
            if (camera_moved || restart) renderer->set_camera(cam.camera());
            camera_moved = restart = false;

            const bool converged = s.max_samples > 0 && renderer->accumulated_samples() >= uint32_t(s.max_samples);
            if (!converged) {
                const auto f0 = std::chrono::steady_clock::now();
                // The mean stays on the GPU: the presenter's display pass tone-maps it there.
                render::RenderResult r = renderer->render_progressive(uint32_t(s.spp_per_frame), false);
                info.frame_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - f0).count();
                info.rays_per_second = r.stats.rays_per_second();
                info.neural_path = r.stats.neural_path;
                info.neural_queries_per_ray = r.stats.neural_queries_per_ray();
            }
            info.samples = renderer->accumulated_samples();
            info.width = width;
            info.height = height;
            ui.new_frame();
            PanelActions act;
            if (s.show_ui) act = draw_panel(s, info);
            camera_moved |= handle_input(cam, s, window, float(height));
            if (act.reset_camera) {
                cam.reset();
                camera_moved = true;
            }
            rebuild |= act.rebuild;
            restart |= act.reset_accumulation;
            ImGui::Render();
            const bool last = a.frames > 0 && frame + 1 >= a.frames;
            const bool want_shot = last && !a.screenshot.empty();
            FilmSource film; // the renderer's size: a failed rebuild keeps the previous renderer
            film.linear = &renderer->output();
            film.width = renderer->width();
            film.height = renderer->height();
            film.exposure = s.exposure;
            film.tone_map = ToneMap::aces; // as nbvh render's PNGs
            presenter.draw(film, s.show_ui ? std::function<void(VkCommandBuffer)>(ImGuiLayer::record)
                                     : std::function<void(VkCommandBuffer)>(),
                           want_shot ? &shot : nullptr);
            window.set_title(strfmt("nbvh view: %s | %u spp | %.1f ms/frame", a.scene.c_str(), info.samples,
                                    info.frame_ms));
            ++frame;
            if (last) break;
        }
        ctx.wait_idle();
        if (!a.screenshot.empty()) {
            if (shot.width > 0) {
                save_png_8bit(a.screenshot, int(shot.width), int(shot.height), 3, shot.rgb.data());
                log_info("view: saved the window (%ux%u) to %s", shot.width, shot.height, a.screenshot.c_str());
            } else if (renderer && frame > 0) {
                // The surface cannot be read back (or the window closed early): save the film.
                const Image film = renderer->read_output();
                PngEncode enc;
                enc.exposure = s.exposure;
                enc.tone_map = ToneMap::aces;
                save_png(a.screenshot, film, enc);
                log_info("view: saved the film (%dx%d) to %s", film.width, film.height, a.screenshot.c_str());
            } else {
                throw Error("no frame was drawn; no screenshot written");
            }
        }
    }
    if (ctx.validation_enabled() && ctx.validation_message_count() > 0)
        throw Error(strfmt("%d Vulkan validation messages (see the log above)", ctx.validation_message_count()));
}

} // namespace nbvh::viewer
