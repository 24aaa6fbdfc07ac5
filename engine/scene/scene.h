// The CPU scene: what the glTF loader produces and every later stage (BVH, renderer, trainer) reads.
// Units: glTF metres; matrices are column-major glm, object -> world.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace nbvh {

struct Aabb {
    glm::vec3 lo{3.4e38f};
    glm::vec3 hi{-3.4e38f};
    void grow(const glm::vec3& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
    void grow(const Aabb& b) { lo = glm::min(lo, b.lo); hi = glm::max(hi, b.hi); }
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    glm::vec3 extent() const { return empty() ? glm::vec3(0.0f) : hi - lo; }
    glm::vec3 center() const { return 0.5f * (lo + hi); }
};

// sRGB base colours are stored as 8-bit sRGB and decoded on fetch (GPU: sRGB view or manual decode).
struct Texture {
    std::string name;
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> rgba8; // width*height*4, row-major, top row first
    bool srgb = false;          // used as base colour / emissive (decode sRGB on fetch); else linear data
};

// Reference to a texture with its UV set and KHR_texture_transform, as uv' = M * (uv, 1).
struct TextureRef {
    int32_t texture = -1; // index into Scene::textures, -1 = none
    uint32_t uv_set = 0;
    glm::mat3 transform{1.0f};
};

enum class AlphaMode : uint32_t { opaque = 0, mask = 1, blend = 2 };

// glTF metallic-roughness material (+ KHR_materials_transmission, KHR_materials_emissive_strength).
struct Material {
    std::string name;
    glm::vec4 base_color{1.0f};
    TextureRef base_color_tex;
    float metallic = 1.0f, roughness = 1.0f;
    TextureRef metallic_roughness_tex; // B = metallic, G = roughness (glTF)
    TextureRef normal_tex;
    float normal_scale = 1.0f;
    glm::vec3 emissive{0.0f}; // already multiplied by emissive_strength
    TextureRef emissive_tex;
    AlphaMode alpha_mode = AlphaMode::opaque;
    float alpha_cutoff = 0.5f;
    float transmission = 0.0f;
    bool double_sided = false;
};

// One glTF mesh with all its triangle primitives merged. Attributes are per vertex; every triangle
// carries its material. Invalid triangles (non-finite, out-of-range indices) were dropped by the loader.
struct Mesh {
    std::string name;
    std::string split_from;           // glTF mesh this one was cut from by material (neural assets), or ""
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;   // always present (generated when missing), unit length
    std::vector<glm::vec4> tangents;  // empty unless a material of this mesh uses a normal map
    std::vector<glm::vec2> uv0, uv1;  // empty when absent
    std::vector<uint32_t> indices;    // 3 per triangle
    std::vector<uint32_t> triangle_material; // 1 per triangle, index into Scene::materials
    uint32_t triangle_count() const { return uint32_t(indices.size() / 3); }
    Aabb bounds() const;
};

struct Instance {
    std::string name;     // glTF node name (used by --neural globs)
    uint32_t mesh = 0;    // index into Scene::meshes
    glm::mat4 object_to_world{1.0f};
    bool neural = false;  // represented by an N-BVH when a model is given
};

struct Camera {
    glm::vec3 eye{0.0f, 0.0f, 3.0f};
    glm::vec3 target{0.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float yfov = 0.8f; // radians
};

// A KHR_lights_punctual light in world space. Intensity is in the extension's units: candela for point and
// spot lights, lux for directional ones; the renderer takes 1 cd (1 lux) as 1 unit of its radiance scale
// (as the glTF sample viewer does), so a point light of I cd gives irradiance I / d^2 at distance d (m).
enum class LightType : uint32_t { point = 0, spot = 1, directional = 2 };

struct PunctualLight {
    std::string name;
    LightType type = LightType::point;
    glm::vec3 color{1.0f};             // linear RGB
    float intensity = 1.0f;            // cd (point, spot) or lux (directional)
    glm::vec3 position{0.0f};          // world (m); unused by directional lights
    glm::vec3 direction{0.0f, 0.0f, -1.0f}; // world, unit: where the light shines (the node's -z); unused by point lights
    float range = 0.0f;                // m; 0 = infinite (point and spot only)
    float inner_cone = 0.0f;           // spot: radians, 0 <= inner < outer <= pi/2
    float outer_cone = 0.7853982f;
};

// Equirectangular environment (linear RGB), or a constant colour when `pixels` is empty.
struct Environment {
    uint32_t width = 0, height = 0;
    std::vector<float> rgb;        // width*height*3
    glm::vec3 constant{0.0f};      // used when rgb is empty
    float intensity = 1.0f;
    float rotation = 0.0f;         // radians about +y
    bool empty() const { return rgb.empty() && constant == glm::vec3(0.0f); }
};

struct Scene {
    std::string source;            // path it was loaded from
    std::vector<Mesh> meshes;
    std::vector<Material> materials; // never empty after loading (a default material is appended)
    std::vector<Texture> textures;
    std::vector<Instance> instances;
    Camera camera;
    bool has_camera = false;       // a glTF camera was found
    Environment environment;
    std::vector<PunctualLight> lights; // KHR_lights_punctual, transformed by their nodes
    Aabb world_bounds() const;
};

} // namespace nbvh
