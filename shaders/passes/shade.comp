// Pass 3: shades the closest hit of every ray in queue pc.in_queue.
//   miss  -> environment radiance (MIS-weighted against environment NEE);
//   hit   -> emitted radiance (MIS-weighted against emissive NEE), then, if the path may grow:
//            next-event estimation: one light sample (environment, emissive triangle or punctual light,
//            lib/lights.glsl nb_light_strategies), evaluated here and appended to the shadow queue with its
//            MIS weight (power heuristic; punctual lights are delta lights: weight 1, NEE only);
//            BSDF sampling + Russian roulette: the continuation ray is appended to queue 1 - in_queue.
// Radiance goes to sample_radiance[slot] (the path's slot in the wave, NB_RAY_PIXEL: no races).
#version 460
#include "lib/bindings.glsl"
#include "lib/material.glsl"
#include "lib/env.glsl"
#include "lib/lights.glsl"
#include "lib/path_sampler.glsl"
#include "lib/neural_surface.glsl"
#include "shared/intersect.h"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

vec3 ray_offset(vec3 p, vec3 n) { return nb_ray_offset(p, n, params.ray_epsilon); }

void main() {
    uint i = gl_GlobalInvocationID.x;
    uint q = pc.in_queue;
    if (i >= queue_count(q)) return;
    vec3 org = ray_load3(q, NB_RAY_ORIGIN, i);
    vec3 dir = ray_load3(q, NB_RAY_DIR, i);
    vec3 throughput = ray_load3(q, NB_RAY_THROUGHPUT, i);
    uint slot = ray_load1(q, NB_RAY_PIXEL, i);
    uint depth = ray_load1(q, NB_RAY_DEPTH, i) & ~NB_RAY_BACKFACE_BIT;
    PathSampler ps = nb_path_sampler(slot, depth, ray_load1(q, NB_RAY_RNG, i));
    float prev_pdf = uintBitsToFloat(ray_load1(q, NB_RAY_PDF, i));
    float p_env, p_emissive, p_punctual;
    nb_light_strategies(p_env, p_emissive, p_punctual);

    uint instance = hit_load1(NB_HIT_INSTANCE, i);
    if (instance == NB_NO_HIT) {
        if (NB_HAS_ENVIRONMENT) {
            float w = 1.0f;
            if (prev_pdf > 0.0f) w = nb_power_heuristic(prev_pdf, p_env * nb_env_pdf(dir));
            sample_radiance[slot] += throughput * nb_env_radiance(dir) * w;
        }
        return;
    }
    float t = uintBitsToFloat(hit_load1(NB_HIT_T, i));
    uint tri_index = hit_load1(NB_HIT_TRIANGLE, i);
    Surface s = (NB_HAS_NEURAL && tri_index == NB_NEURAL_TRIANGLE)
                    ? nb_make_neural_surface(i, org, dir, t, ps)
                    : nb_make_surface(instance, tri_index, hit_load_bary(i), org, dir, t);
    vec3 wo = -dir;

    if (NB_HAS_EMISSION && dot(s.emission, s.emission) > 0.0f) {
        float w = 1.0f;
        if (prev_pdf > 0.0f && params.light_count > 0u) {
            float cos_l = abs(dot(s.ng, dir));
            float light_pdf = p_emissive * nb_emissive_area_pdf(materials[s.material]) * t * t / max(cos_l, 1.0e-8f);
            w = nb_power_heuristic(prev_pdf, light_pdf);
        }
        sample_radiance[slot] += throughput * s.emission * w;
    }
    if (depth + 1u >= params.max_depth) return; // the next segment would exceed --max-depth
    // Rays leaving a neural hit seen from behind skip back-facing neural hits (NB_RAY_BACKFACE_BIT).
    uint escape = (NB_HAS_NEURAL && tri_index == NB_NEURAL_TRIANGLE && nb_neural_escapes(i, dir)) ? NB_RAY_BACKFACE_BIT : 0u;

    // Next-event estimation.
    if (NB_HAS_ENVIRONMENT || NB_HAS_EMISSION || NB_HAS_PUNCTUAL) {
        vec3 wi;
        float light_pdf = 0.0f, dist = NB_INF;
        vec3 le = vec3(0.0f);
        bool delta = false; // punctual: light_pdf is a discrete probability, no MIS
        // Which light within the strategy: only scenes with emitters or punctual lights draw it.
        vec2 pick = (NB_HAS_EMISSION || NB_HAS_PUNCTUAL) ? nb_path_2d(ps, NB_PAIR_LIGHT_PICK) : vec2(0.0f);
        vec2 ul = nb_path_2d(ps, NB_PAIR_LIGHT);
        // The strategy comes from the light sample's own first coordinate, rescaled to [0, 1) for the
        // chosen strategy (nb_sample_reuse): under --sampler sobol the samples of each strategy stay
        // a stratified 2D net instead of a random subset of one (default scene, 240x135, 64 spp, two
        // seeds: FLIP 0.0268 -> 0.0248; engine/render/README.md; the strategy had a pair of its own).
        float u = ul.x;
        if (NB_HAS_ENVIRONMENT && u < p_env) {
            ul.x = nb_sample_reuse(u, 0.0f, p_env);
            le = nb_env_sample(ul, wi, light_pdf);
            light_pdf *= p_env;
        } else if (NB_HAS_EMISSION && p_emissive > 0.0f && u < p_env + p_emissive) {
            ul.x = nb_sample_reuse(u, p_env, p_emissive);
            le = nb_emissive_sample(s.p, pick.y, ul, wi, dist, light_pdf);
            light_pdf *= p_emissive;
        } else if (NB_HAS_PUNCTUAL && p_punctual > 0.0f) {
            le = nb_punctual_sample(s.p, pick.y, wi, dist, light_pdf);
            light_pdf *= p_punctual;
            delta = true;
        }
        if (light_pdf > 0.0f && dot(le, le) > 0.0f) {
            float bsdf_pdf;
            vec3 f = nb_bsdf_eval(s, wo, wi, bsdf_pdf);
            if (dot(f, f) > 0.0f) {
                float mis = delta ? 1.0f : nb_power_heuristic(light_pdf, bsdf_pdf);
                vec3 contrib = throughput * f * le * (mis / light_pdf);
                uint k = atomicAdd(counters.shadow_count, 1u);
                vec3 o = ray_offset(s.p, s.ng);
                if (params.sort_rays != 0u) atomicAdd(rs_bins[NB_RS_SHADOW_BINS + nb_rs_bin(o, wi)], 1u);
                shadow_store3(NB_SHADOW_ORIGIN, k, o);
                shadow_store3(NB_SHADOW_DIR, k, wi);
                // Stop short of the light (its surface must not occlude itself).
                float tmax = dist >= NB_INF ? NB_INF : max(0.0f, length(s.p + wi * dist - o) * (1.0f - 1.0e-4f));
                shadow_store1(NB_SHADOW_TMAX, k, floatBitsToUint(tmax));
                shadow_store3(NB_SHADOW_CONTRIB, k, contrib);
                shadow_store1(NB_SHADOW_PIXEL, k, slot | escape);
            }
        }
    }

    // Continuation.
    vec3 wi, weight;
    float pdf;
    vec2 lobe = nb_path_2d(ps, NB_PAIR_LOBE);
    if (!nb_bsdf_sample(s, wo, lobe.x, nb_path_2d(ps, NB_PAIR_BSDF), wi, weight, pdf)) return;
    throughput *= weight;
    if (depth + 1u >= params.rr_start_depth) {
        float survive = min(1.0f, max(throughput.x, max(throughput.y, throughput.z)));
        if (!(lobe.y < survive)) return;
        throughput /= survive;
    }
    if (!(max(throughput.x, max(throughput.y, throughput.z)) > 0.0f)) return;
    // Without anything to sample by NEE, emitters hit by BSDF sampling take the full weight.
    if (!(NB_HAS_ENVIRONMENT || NB_HAS_EMISSION)) pdf = -1.0f;
    uint out_q = 1u - q;
    uint k = out_q == 0u ? atomicAdd(counters.ray_count0, 1u) : atomicAdd(counters.ray_count1, 1u);
    vec3 n_side = dot(wi, s.ng) >= 0.0f ? s.ng : -s.ng; // transmission leaves through the back
    vec3 next_org = ray_offset(s.p, n_side);
    if (params.sort_rays != 0u) atomicAdd(rs_bins[NB_RS_PATH_BINS(out_q) + nb_rs_bin(next_org, wi)], 1u);
    ray_store3(out_q, NB_RAY_ORIGIN, k, next_org);
    ray_store3(out_q, NB_RAY_DIR, k, wi);
    ray_store3(out_q, NB_RAY_THROUGHPUT, k, throughput);
    ray_store1(out_q, NB_RAY_PIXEL, k, slot);
    ray_store1(out_q, NB_RAY_DEPTH, k, (depth + 1u) | escape);
    ray_store1(out_q, NB_RAY_RNG, k, nb_path_next_rng(ps));
    ray_store1(out_q, NB_RAY_PDF, k, floatBitsToUint(pdf));
    ray_store1(out_q, NB_RAY_T_RESUME, k, floatBitsToUint(0.0f));
}
