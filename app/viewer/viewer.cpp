#include "app/viewer/viewer.h"

#include <memory>

#include <GLFW/glfw3.h>
#include <imgui.h>

#include "app/viewer/imgui_layer.h"
#include "app/viewer/presenter.h"
#include "app/viewer/script.h"
#include "app/viewer/viewer_session.h"
#include "engine/core/error.h"
#include "engine/core/image.h"
#include "engine/core/log.h"
#include "engine/neural/model_file.h"
#include "engine/vk/context.h"

namespace nbvh::viewer {

void run_viewer(const ViewerArgs& a) {
    if (!a.screenshot.empty() && !is_png_path(a.screenshot))
        throw Error(strfmt("--screenshot '%s': expected a .png file name", a.screenshot.c_str()));
    // The script is checked before the window opens: a typo fails in milliseconds.
    ScriptRunner script;
    if (!a.script.empty()) script = ScriptRunner(load_script(a.script));
    Window window(int(a.width), int(a.height), "nbvh view"); // fails first without a display

    std::shared_ptr<const NeuralModel> model;
    if (!a.model.empty()) model = std::make_shared<const NeuralModel>(load_model(a.model));
    SceneOptions so;
    so.neural_glob = a.neural_glob;
    so.env = a.env;
    so.subdivide = a.subdivide;
    uint32_t fb_w = 0, fb_h = 0;
    window.framebuffer_size(&fb_w, &fb_h);
    const uint32_t width = fb_w ? fb_w : a.width, height = fb_h ? fb_h : a.height;
    auto view = load_viewer_scene(a.scene, so, model, a.model, float(width) / float(height));

    vk::ContextOptions copt;
    copt.set_device(a.device);
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
        ViewerSession session(ctx, std::move(view), so, s, width, height);
        session.set_script(std::move(script));
        if (copt.gpu_index >= 0) session.train_on_gpu(ctx.features().device_uuid); // train where it renders
        Screenshot shot;
        uint32_t frame = 0;
        bool last = false;
        while (!window.should_close() && !last) {
            if (session.idle() && a.frames == 0) glfwWaitEventsTimeout(0.05); // converged: do not spin
            else glfwPollEvents();
            window.framebuffer_size(&fb_w, &fb_h);
            // Input of the previous frame's UI pass applies here, so the panel shows this frame's numbers.
            last = !session.begin_frame(fb_w, fb_h, window.take_dropped());
            last |= a.frames > 0 && frame + 1 >= a.frames;
            ui.new_frame();
            session.ui(window, fb_w, fb_h);
            ImGui::Render();
            const bool want_shot = session.wants_screenshot() || (last && !a.screenshot.empty());
            shot = Screenshot{};
            presenter.draw(session.film(),
                           session.settings().show_ui ? std::function<void(VkCommandBuffer)>(ImGuiLayer::record)
                                                      : std::function<void(VkCommandBuffer)>(),
                           want_shot ? &shot : nullptr);
            session.end_frame(shot);
            const PanelInfo& info = session.info();
            window.set_title(strfmt("nbvh view: %s | %u spp | %.1f ms/frame", info.scene.c_str(), info.samples,
                                    info.frame_ms));
            ++frame;
        }
        ctx.wait_idle();
        if (!a.screenshot.empty()) {
            if (shot.width > 0) {
                save_png_8bit(a.screenshot, int(shot.width), int(shot.height), 3, shot.rgb.data());
                log_info("view: saved the window (%ux%u) to %s", shot.width, shot.height, a.screenshot.c_str());
            } else if (session.renderers().main() && frame > 0) {
                // The surface cannot be read back (or the window closed early): save the film.
                const Image film = session.renderers().main()->read_output();
                PngEncode enc;
                enc.exposure = session.settings().exposure;
                enc.tone_map = ToneMap::aces;
                save_png(a.screenshot, film, enc);
                log_info("view: saved the film (%dx%d) to %s", film.width, film.height, a.screenshot.c_str());
            } else {
                throw Error("no frame was drawn; no screenshot written");
            }
        }
        const PanelInfo& info = session.info();
        log_info("view: %u frames, renderer builds %u, live setting changes %u", frame, info.renderer_builds,
                 info.live_updates);
    }
    if (ctx.validation_enabled() && ctx.validation_message_count() > 0)
        throw Error(strfmt("%d Vulkan validation messages (see the log above)", ctx.validation_message_count()));
}

} // namespace nbvh::viewer
