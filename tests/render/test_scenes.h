// Small scenes built in code for the renderer tests.
#pragma once
#include "engine/render/wavefront.h"
#include "engine/scene/scene.h"

namespace nbvh::test {

// One render on lavapipe with the Khronos validation layer on (the renderer tests' set-up).
struct LavapipeRender {
    render::RenderResult result;
    render::SceneFeatures features;
    int validation = 0;              // validation messages
    bool validation_enabled = false; // whether the layer was there to count them
};
LavapipeRender render_lavapipe(const Scene& scene, const Environment& env, const Camera& camera,
                               const render::RenderOptions& options);

// A unit quad in the z = 0 plane facing +z (two triangles), one grey material, one instance.
Scene make_quad_scene();

// Textures of every kind on quads (texture-path tests): a floor with a non-square sRGB base colour and a
// metallic-roughness texture under a KHR_texture_transform whose uvs run from -0.3 to 3.2 (REPEAT
// wrapping), an emissive wall (emissive factor EMISSIVE_SCALE x an sRGB texture with hard edges), a
// normal-mapped panel, and an alpha-masked quad in front of it. Texture 3 is the emissive one.
Scene make_textured_scene();
inline constexpr float TEXTURED_SCENE_EMISSIVE_SCALE = 2.0f;
inline constexpr int TEXTURED_SCENE_EMISSIVE_TEXTURE = 3;

} // namespace nbvh::test
