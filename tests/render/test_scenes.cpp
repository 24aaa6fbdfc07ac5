#include "tests/render/test_scenes.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/bvh/scene_accel.h"
#include "engine/vk/context.h"

namespace nbvh::test {

LavapipeRender render_lavapipe(const Scene& scene, const Environment& env, const Camera& camera,
                               const render::RenderOptions& options) {
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::cpu;
    o.validation = true;
    vk::Context ctx(o);
    const SceneAccel accel = build_scene_accel(scene);
    render::WavefrontRenderer r(ctx, scene, accel, env, camera, options);
    LavapipeRender out;
    out.features = r.features();
    out.result = r.render();
    out.validation = ctx.validation_message_count();
    out.validation_enabled = ctx.validation_enabled();
    return out;
}

Scene make_quad_scene() {
    Scene s;
    Mesh m;
    m.name = "quad";
    m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    m.normals.assign(4, glm::vec3(0, 0, 1));
    m.uv0 = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.triangle_material = {0, 0};
    s.meshes.push_back(m);
    Material mat;
    mat.base_color = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    mat.metallic = 0.0f;
    mat.roughness = 0.5f;
    s.materials.push_back(mat);
    Instance inst;
    inst.name = "quad";
    inst.mesh = 0;
    s.instances.push_back(inst);
    s.camera.eye = {0, 0, 3};
    s.camera.target = {0, 0, 0};
    s.has_camera = true;
    return s;
}

namespace {

// A texture from f(x, y) -> RGBA in [0, 255].
template <class F> Texture make_texture(const char* name, uint32_t w, uint32_t h, bool srgb, F f) {
    Texture t;
    t.name = name;
    t.width = w;
    t.height = h;
    t.srgb = srgb;
    t.rgba8.resize(size_t(w) * h * 4);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const glm::vec4 c = f(x, y);
            for (int k = 0; k < 4; ++k)
                t.rgba8[(size_t(y) * w + x) * 4 + k] = uint8_t(std::lround(std::clamp(c[k], 0.0f, 255.0f)));
        }
    return t;
}

// The unit quad of make_quad_scene (z = 0, facing +z, uv v = 0 at the top) with tangents, one material.
uint32_t add_quad(Scene& s, uint32_t material, const glm::mat4& object_to_world, const char* name) {
    Mesh m;
    m.name = name;
    m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    m.normals.assign(4, glm::vec3(0, 0, 1));
    m.tangents.assign(4, glm::vec4(1, 0, 0, 1));
    m.uv0 = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.triangle_material = {material, material};
    s.meshes.push_back(m);
    Instance inst;
    inst.name = name;
    inst.mesh = uint32_t(s.meshes.size() - 1);
    inst.object_to_world = object_to_world;
    s.instances.push_back(inst);
    return inst.mesh;
}

} // namespace

Scene make_textured_scene() {
    Scene s;
    // 0: base colour, 64x48 (non-square, not a power of two): 8-texel checker over colour gradients.
    s.textures.push_back(make_texture("base", 64, 48, true, [](uint32_t x, uint32_t y) {
        const float check = ((x / 8 + y / 8) & 1u) ? 1.0f : 0.55f;
        return glm::vec4(30.0f + 200.0f * check * float(x) / 63.0f, 40.0f + 190.0f * check * float(y) / 47.0f,
                         60.0f + 150.0f * check, 255.0f);
    }));
    // 1: metallic-roughness (G roughness, B metallic), smooth ramps.
    s.textures.push_back(make_texture("mr", 32, 32, false, [](uint32_t x, uint32_t y) {
        return glm::vec4(255.0f, 40.0f + 200.0f * float(x) / 31.0f, 255.0f * float(y) / 31.0f, 255.0f);
    }));
    // 2: normal map of sine bumps.
    s.textures.push_back(make_texture("normal", 32, 32, false, [](uint32_t x, uint32_t y) {
        const float a = 0.6f * std::sin(float(x) * 0.785f), b = 0.6f * std::cos(float(y) * 0.785f);
        const glm::vec3 n = glm::normalize(glm::vec3(a, b, 1.0f));
        return glm::vec4((n * 0.5f + 0.5f) * 255.0f, 255.0f);
    }));
    // 3: emissive, 16x24: red and green ramps, blue 4-texel checker (hard edges, also across the wrap).
    s.textures.push_back(make_texture("emissive", 16, 24, true, [](uint32_t x, uint32_t y) {
        return glm::vec4(16.0f * float(x), 10.0f * float(y), ((x / 4 + y / 4) & 1u) ? 255.0f : 0.0f, 255.0f);
    }));
    // 4: alpha mask of discs.
    s.textures.push_back(make_texture("mask", 32, 32, true, [](uint32_t x, uint32_t y) {
        const float dx = float(x % 16) - 7.5f, dy = float(y % 16) - 7.5f;
        return glm::vec4(230.0f, 200.0f, 120.0f, dx * dx + dy * dy < 36.0f ? 255.0f : 0.0f);
    }));

    Material floor;
    floor.name = "floor";
    floor.base_color_tex.texture = 0;
    // uv' = scale * uv + offset: (3.5, 2.25) and (-0.3, 0.7).
    floor.base_color_tex.transform = glm::mat3(3.5f, 0.0f, 0.0f, 0.0f, 2.25f, 0.0f, -0.3f, 0.7f, 1.0f);
    floor.metallic_roughness_tex.texture = 1;
    floor.metallic_roughness_tex.transform = floor.base_color_tex.transform;
    floor.metallic = 1.0f;
    floor.roughness = 1.0f;
    floor.double_sided = true;
    Material wall;
    wall.name = "emissive wall";
    wall.base_color = glm::vec4(0.05f, 0.05f, 0.05f, 1.0f);
    wall.metallic = 0.0f;
    wall.emissive = glm::vec3(TEXTURED_SCENE_EMISSIVE_SCALE);
    wall.emissive_tex.texture = TEXTURED_SCENE_EMISSIVE_TEXTURE;
    wall.double_sided = true;
    Material panel;
    panel.name = "bumpy panel";
    panel.base_color_tex.texture = 0;
    panel.normal_tex.texture = 2;
    panel.metallic_roughness_tex.texture = 1;
    panel.double_sided = true;
    Material mask;
    mask.name = "mask";
    mask.base_color_tex.texture = 4;
    mask.alpha_mode = AlphaMode::mask;
    mask.alpha_cutoff = 0.5f;
    mask.metallic = 0.0f;
    mask.roughness = 0.6f;
    mask.double_sided = true;
    s.materials = {floor, wall, panel, mask};

    const glm::mat4 I(1.0f);
    add_quad(s, 0, glm::scale(glm::rotate(glm::translate(I, {0, -1, 0}), -1.5708f, {1, 0, 0}), {3, 3, 1}), "floor");
    add_quad(s, 1, glm::scale(glm::translate(I, {-1, 0, -0.5f}), {0.8f, 0.8f, 1}), "emissive wall");
    add_quad(s, 2, glm::scale(glm::rotate(glm::translate(I, {1, 0, -0.5f}), 0.35f, {0, 1, 0}), {0.8f, 0.8f, 1}),
             "bumpy panel");
    add_quad(s, 3, glm::scale(glm::translate(I, {1, 0, 0.3f}), {0.5f, 0.5f, 1}), "mask");
    s.camera.eye = {0.0f, 0.3f, 4.2f};
    s.camera.target = {0.0f, -0.1f, 0.0f};
    s.camera.yfov = 0.75f;
    s.has_camera = true;
    return s;
}

} // namespace nbvh::test
