// Pass 1: one camera ray per path slot of the wave (pc.wave_samples samples of pc.pixel_count pixels,
// shared/wavefront_gpu.h) into path-ray queue pc.in_queue (pinhole camera, jitter inside the
// pixel: lib/path_sampler.glsl, row 0 at the top). Also clears the wave's sample radiance.
#version 460
#include "lib/bindings.glsl"
#include "lib/path_sampler.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    uint paths = pc.pixel_count * pc.wave_samples;
    if (i == 0u) {
        if (pc.in_queue == 0u) counters.ray_count0 = paths;
        else counters.ray_count1 = paths;
    }
    if (i >= paths) return;
    uint pixel = nb_slot_pixel(i, pc.pixel_offset, pc.wave_samples);
    uint x = pixel % params.width;
    uint y = pixel / params.width;
    PathSampler ps = nb_camera_path_sampler(i, pixel);
    vec2 jitter = nb_path_2d(ps, NB_PAIR_CAMERA);
    float jx = jitter.x;
    float jy = jitter.y;
    float sx = (2.0f * (float(x) + jx) / float(params.width) - 1.0f) * params.aspect * params.cam_tan_half_fov;
    float sy = (1.0f - 2.0f * (float(y) + jy) / float(params.height)) * params.cam_tan_half_fov;
    vec3 dir = normalize(params.cam_forward + sx * params.cam_right + sy * params.cam_up);

    uint q = pc.in_queue;
    ray_store3(q, NB_RAY_ORIGIN, i, params.cam_eye);
    ray_store3(q, NB_RAY_DIR, i, dir);
    ray_store3(q, NB_RAY_THROUGHPUT, i, vec3(1.0f));
    ray_store1(q, NB_RAY_PIXEL, i, i);
    ray_store1(q, NB_RAY_DEPTH, i, 0u);
    ray_store1(q, NB_RAY_RNG, i, ps.rng);
    ray_store1(q, NB_RAY_PDF, i, floatBitsToUint(-1.0f));
    ray_store1(q, NB_RAY_T_RESUME, i, floatBitsToUint(0.0f));
    sample_radiance[i] = vec3(0.0f);
}
