#include "assets/default_scene.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "assets/procedural_mesh.h"
#include "assets/rope_knot.h"
#include "engine/scene/environment.h" // nbvh::default_sky()

namespace nbvh::assets {
namespace {

// Material slots of the default scene.
enum : uint32_t { MAT_GROUND, MAT_PEDESTAL, MAT_KNOT, MAT_LAMP, MAT_CHROME, MAT_BLUE, MAT_COUNT };

// Two-tone checker, `cells` squares per side, with a faint per-cell tint so the floor is not flat
// grey (8-bit sRGB, as glTF base colour textures are).
Texture make_checker(uint32_t size, uint32_t cells) {
    Texture t;
    t.name = "checker";
    t.width = t.height = size;
    t.rgba8.resize(size_t(size) * size * 4);
    const uint32_t cell = size / cells;
    for (uint32_t y = 0; y < size; ++y)
        for (uint32_t x = 0; x < size; ++x) {
            const uint32_t cx = x / cell, cy = y / cell;
            const bool light = ((cx + cy) & 1u) == 0;
            const int tint = int((cx * 7u + cy * 13u) % 5u) - 2; // −2..2, deterministic
            const int base = light ? 196 : 72;
            uint8_t* p = &t.rgba8[(size_t(y) * size + x) * 4];
            p[0] = uint8_t(base + 2 * tint);
            p[1] = uint8_t(base + tint);
            p[2] = uint8_t(base - 2 + (light ? -6 : 8));
            p[3] = 255;
        }
    return t;
}

Material make_material(const char* name, const glm::vec3& colour, float metallic, float roughness) {
    Material m;
    m.name = name;
    m.base_color = glm::vec4(colour, 1.0f);
    m.metallic = metallic;
    m.roughness = roughness;
    return m;
}

uint32_t add_mesh(Scene& s, Mesh mesh) {
    s.meshes.push_back(std::move(mesh));
    return uint32_t(s.meshes.size() - 1);
}

void add_instance(Scene& s, const char* name, uint32_t mesh, const glm::mat4& m, bool neural = false) {
    Instance inst;
    inst.name = name;
    inst.mesh = mesh;
    inst.object_to_world = m;
    inst.neural = neural;
    s.instances.push_back(inst);
}

glm::mat4 translate(const glm::vec3& t) { return glm::translate(glm::mat4(1.0f), t); }

} // namespace

Scene make_default_scene() {
    Scene s;
    s.source = DEFAULT_SCENE_NAME;

    s.textures.push_back(make_checker(512, 32));
    s.materials.resize(MAT_COUNT);
    s.materials[MAT_GROUND] = make_material("ground_checker", glm::vec3(1.0f), 0.0f, 0.7f);
    s.materials[MAT_GROUND].base_color_tex.texture = 0;
    s.materials[MAT_PEDESTAL] = make_material("pedestal_stone", {0.75f, 0.73f, 0.70f}, 0.0f, 0.55f);
    s.materials[MAT_KNOT] = make_material("rope_terracotta", {0.78f, 0.36f, 0.22f}, 0.0f, 0.5f);
    s.materials[MAT_LAMP] = make_material("lamp_emissive", {1.0f, 1.0f, 1.0f}, 0.0f, 1.0f);
    s.materials[MAT_LAMP].emissive = glm::vec3(14.0f, 9.0f, 4.5f); // warm glow, radiance units
    s.materials[MAT_CHROME] = make_material("chrome", {0.92f, 0.92f, 0.95f}, 1.0f, 0.12f);
    s.materials[MAT_BLUE] = make_material("blue_paint", {0.08f, 0.22f, 0.65f}, 0.0f, 0.6f);

    // Ground: 16 m square, 32 checker cells -> 0.5 m squares.
    add_instance(s, "ground", add_mesh(s, make_ground("ground", 16.0f, MAT_GROUND)), glm::mat4(1.0f));

    // Pedestal: a 0.3 m high cylinder, top at y = 0.3.
    const float pedestal_top = 0.3f;
    add_instance(s, "pedestal", add_mesh(s, make_cylinder("pedestal", 0.8f, 0.5f * pedestal_top, 96, MAT_PEDESTAL)),
                 translate({0.0f, 0.5f * pedestal_top, 0.0f}));

    // The detailed asset: the knot stands upright (its plane is xy), turned towards the camera a little,
    // and rests 1 cm above the pedestal.
    Mesh knot = make_rope_knot(RopeKnotParams{}, MAT_KNOT);
    const glm::mat4 turn = glm::rotate(glm::mat4(1.0f), glm::radians(-25.0f), glm::vec3(0, 1, 0)) *
                           glm::rotate(glm::mat4(1.0f), glm::radians(8.0f), glm::vec3(1, 0, 0));
    float min_y = 1e30f;
    for (const glm::vec3& p : knot.positions) min_y = std::min(min_y, (turn * glm::vec4(p, 1.0f)).y);
    const uint32_t knot_mesh = add_mesh(s, std::move(knot));
    add_instance(s, "neural_rope_knot", knot_mesh, translate({0.0f, pedestal_top + 0.01f - min_y, 0.0f}) * turn, true);

    // The emissive object: a small glowing sphere to the front-left of the knot.
    add_instance(s, "lamp_sphere", add_mesh(s, make_sphere("lamp_sphere", 0.12f, 48, 24, MAT_LAMP)),
                 translate({-1.15f, 1.6f, 0.45f}));

    // Props.
    add_instance(s, "chrome_sphere", add_mesh(s, make_sphere("chrome_sphere", 0.4f, 96, 48, MAT_CHROME)),
                 translate({1.55f, 0.4f, -0.35f}));
    add_instance(s, "blue_box", add_mesh(s, make_box("blue_box", glm::vec3(0.3f), MAT_BLUE)),
                 translate({-1.5f, 0.3f, -0.7f}) * glm::rotate(glm::mat4(1.0f), glm::radians(30.0f), glm::vec3(0, 1, 0)));

    s.camera.eye = glm::vec3(0.3f, 1.3f, 3.4f);
    s.camera.target = glm::vec3(0.0f, 0.95f, 0.0f);
    s.camera.up = glm::vec3(0.0f, 1.0f, 0.0f);
    s.camera.yfov = 0.75f; // ~43 degrees
    s.has_camera = true;

    s.environment = default_sky();
    return s;
}

} // namespace nbvh::assets
