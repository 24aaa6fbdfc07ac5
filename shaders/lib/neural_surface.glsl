// The shading surface of a neural hit (issue 4): position on the ray, the predicted normal (world space,
// turned towards the incoming ray, used as geometric and shading normal), the predicted albedo as base
// colour, and the user's material constants (--neural-roughness, --neural-metallic). Included by
// passes/shade.comp after lib/material.glsl.
#ifndef NB_NEURAL_SURFACE_GLSL
#define NB_NEURAL_SURFACE_GLSL
#include "lib/neural_bindings.glsl"

Surface nb_make_neural_surface(uint ray, vec3 ray_org, vec3 ray_dir, float t) {
    GpuNeuralRayState st = neural_state[ray];
    Surface s;
    s.material = 0u;
    s.p = ray_org + ray_dir * t;
    vec3 n = st.normal;
    if (!(dot(n, n) > 0.0f)) n = -ray_dir;
    if (dot(n, ray_dir) > 0.0f) n = -n;
    s.ng = n;
    s.n = n;
    s.base = clamp(st.albedo, 0.0f, 1.0f);
    s.metallic = clamp(neural_params.metallic, 0.0f, 1.0f);
    s.alpha = nb_ggx_alpha(clamp(neural_params.roughness, 0.0f, 1.0f));
    s.transmission = 0.0f;
    s.emission = vec3(0.0f);
    return s;
}

#endif
