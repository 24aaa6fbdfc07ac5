// The shading surface of a neural hit: position on the ray, the predicted normal (world space, turned
// towards the incoming ray, used as geometric and shading normal), the predicted albedo as base colour
// (it learned factor x texture), and the rest from the asset's glTF material: metallic and roughness
// as factor x texture summarised over the triangles of the N-BVH node that answered the hit
// (engine/neural/node_materials.h; a neural hit has no uv): a linear function of the predicted albedo
// plus a random two-point spread (default; --neural-materials fit without it), their mean
// (--neural-materials node, models of format 4), or the whole asset's mean
// (--neural-materials asset, models without per-node materials: asset_table.h asset_shading), transmission and
// emission factors, unless the user overrides metallic/roughness (--neural-metallic,
// --neural-roughness). Included by passes/shade.comp after lib/material.glsl.
#ifndef NB_NEURAL_SURFACE_GLSL
#define NB_NEURAL_SURFACE_GLSL
#include "lib/neural_bindings.glsl"
#include "lib/path_sampler.glsl"

// ps: the path's numbers; the spread's sign is its NB_PAIR_MATERIAL bit (drawn only where the spread is
// on, and without moving the path's later numbers: nb_path_bit).
Surface nb_make_neural_surface(uint ray, vec3 ray_org, vec3 ray_dir, float t, PathSampler ps) {
    GpuNeuralRayState st = nb_state_load(ray);
    Surface s;
    GpuNeuralAsset asset = neural_assets[instances[st.instance].blas_root];
    GpuMaterial m = materials[asset.material];
    s.material = asset.material;
    s.p = ray_org + ray_dir * t;
    vec3 n = st.normal;
    if (!(dot(n, n) > 0.0f)) n = -ray_dir;
    if (dot(n, ray_dir) > 0.0f) n = -n;
    s.ng = n;
    s.n = n;
    s.base = clamp(vec3(unpackHalf2x16(st.albedo_rg), unpackHalf2x16(st.albedo_b).x), 0.0f, 1.0f);
    vec2 mr = vec2(asset.metallic, asset.roughness);
    if (neural_params.material_fits != 0u) {
        uint b = neural_params.material_fits + NB_NODE_FIT_WORDS * st.hit_leaf;
        mr = nb_node_fit_eval(unpackHalf2x16(nbvh_bounds_words[b]), unpackHalf2x16(nbvh_bounds_words[b + 1u]),
                              unpackHalf2x16(nbvh_bounds_words[b + 2u]), unpackHalf2x16(nbvh_bounds_words[b + 3u]), s.base);
        if (neural_params.material_spread != 0u)
            mr = nb_node_fit_spread(mr, unpackHalf2x16(nbvh_bounds_words[b + 4u]),
                                    nb_path_bit(ps, NB_PAIR_MATERIAL));
    } else if (neural_params.materials != 0u) {
        mr = unpackUnorm2x16(nbvh_bounds_words[neural_params.materials + st.hit_leaf]);
    }
    float metallic = neural_params.metallic < 0.0f ? mr.x : neural_params.metallic;
    float roughness = neural_params.roughness < 0.0f ? mr.y : neural_params.roughness;
    s.metallic = clamp(metallic, 0.0f, 1.0f);
    s.alpha = nb_ggx_alpha(clamp(roughness, 0.0f, 1.0f));
    bool from_material = neural_params.metallic < 0.0f && neural_params.roughness < 0.0f;
    s.transmission = (NB_HAS_TRANSMISSION && from_material) ? clamp(m.transmission, 0.0f, 1.0f) * (1.0f - s.metallic) : 0.0f;
    s.emission = NB_HAS_EMISSION ? m.emissive : vec3(0.0f);
    return s;
}

// True when the rays leaving neural hit `ray` skip back-facing neural hits: the hit's asset has
// backface_escape and its predicted normal faces along the incoming ray (shared/neural_query.h
// nb_backface_skip).
bool nb_neural_escapes(uint ray, vec3 ray_dir) {
    GpuNeuralRayState st = nb_state_load(ray);
    return neural_assets[instances[st.instance].blas_root].backface_escape != 0u && nb_faces_along(st.normal, ray_dir, 0.0f);
}

#endif
