// Texture lookups: nb_sample_texture(texture, uv) is the one API; two implementations, chosen per
// renderer (engine/render/texture_path.h):
//   default:          the RGBA8 texel buffer (layout: GpuTextureInfo in shared/scene_gpu.h), bilinear in
//                     the shader;
//   NB_TEXTURE_ARRAY: one sampler2D per texture (binding NB_BIND_TEXELS), four texelFetch per lookup.
// Both: the same bilinear footprint and weights (nb_bilinear_footprint) on the raw 8-bit values, REPEAT
// wrapping, texel centres at half-integers, v = 0 at the top row (glTF), one level (no mip maps),
// non-linearised values (the caller decodes sRGB).
#ifndef NB_TEXTURES_GLSL
#define NB_TEXTURES_GLSL
#include "lib/bindings.glsl"
#include "shared/sampling.h"

// The bilinear footprint of uv in a w x h texture, the same for both paths: texels x0/x1, y0/y1 (REPEAT-
// wrapped) and the weights f of x1/y1. The uv is wrapped first, so huge coordinates cannot overflow.
void nb_bilinear_footprint(vec2 uv, int w, int h, out ivec2 lo, out ivec2 hi, out vec2 f) {
    uv = uv - floor(uv);
    vec2 p = uv * vec2(float(w), float(h)) - 0.5f;
    f = p - floor(p);
    int x = int(floor(p.x));
    int y = int(floor(p.y));
    lo = ivec2(((x % w) + w) % w, ((y % h) + h) % h);
    hi = ivec2(((x + 1) % w + w) % w, ((y + 1) % h + h) % h);
}

#ifdef NB_TEXTURE_ARRAY

// One image per glTF texture (RGBA8 UNORM: raw values, sRGB decoded after filtering as the buffer path
// does), one level (engine/render/texture_array.h).
layout(set = 0, binding = NB_BIND_TEXELS) uniform sampler2D texture_images[];

// Bilinear lookup; returns the raw (non-linearised) texel values. Four texelFetch and the shader's own
// weights, not the sampler's filter: the hardware filter quantises its weights (8 bits on NVIDIA) and,
// measured on the H100, disagreed with the buffer path by up to 0.16 of the emissive scale along a REPEAT
// seam row (TextureArrayGpu.DirectLookupsAgreeWithinTheFilterPrecision); with the shared footprint both
// paths give the same value.
vec4 nb_sample_texture(int texture, vec2 uv) {
    ivec2 size = textureSize(texture_images[nonuniformEXT(texture)], 0);
    ivec2 lo, hi;
    vec2 f;
    nb_bilinear_footprint(uv, size.x, size.y, lo, hi, f);
    vec4 a = texelFetch(texture_images[nonuniformEXT(texture)], ivec2(lo.x, lo.y), 0);
    vec4 b = texelFetch(texture_images[nonuniformEXT(texture)], ivec2(hi.x, lo.y), 0);
    vec4 c = texelFetch(texture_images[nonuniformEXT(texture)], ivec2(lo.x, hi.y), 0);
    vec4 d = texelFetch(texture_images[nonuniformEXT(texture)], ivec2(hi.x, hi.y), 0);
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

#else

// All textures' RGBA8 texels, packed (layout: GpuTextureInfo at binding NB_BIND_TEXTURE_INFOS).
layout(set = 0, binding = NB_BIND_TEXELS, scalar) readonly buffer TexelBuffer { uint texels[]; };

vec4 nb_texel(GpuTextureInfo ti, int x, int y) {
    return unpackUnorm4x8(texels[ti.offset + uint(y) * ti.width + uint(x)]);
}

// Bilinear lookup; returns the raw (non-linearised) texel values.
vec4 nb_sample_texture(int texture, vec2 uv) {
    GpuTextureInfo ti = texture_infos[texture];
    ivec2 lo, hi;
    vec2 f;
    nb_bilinear_footprint(uv, int(ti.width), int(ti.height), lo, hi, f);
    vec4 a = nb_texel(ti, lo.x, lo.y), b = nb_texel(ti, hi.x, lo.y);
    vec4 c = nb_texel(ti, lo.x, hi.y), d = nb_texel(ti, hi.x, hi.y);
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

#endif

vec3 nb_srgb_to_linear3(vec3 c) {
    return vec3(nb_srgb_to_linear(c.x), nb_srgb_to_linear(c.y), nb_srgb_to_linear(c.z));
}

// Texture coordinates of a reference at a surface point (KHR_texture_transform applied).
vec2 nb_tex_coord(GpuTexRef ref, vec2 uv0, vec2 uv1) {
    vec3 uv = vec3(ref.uv_set == 1u ? uv1 : uv0, 1.0f);
    vec2 r = vec2(dot(ref.row0, uv), dot(ref.row1, uv));
    // Non-finite uvs (bad input) fall back to the origin instead of poisoning the texel index.
    return (isnan(r.x) || isinf(r.x) || isnan(r.y) || isinf(r.y)) ? vec2(0.0f) : r;
}

// Interpolated uv sets of a triangle at barycentrics (u, v) of vertices 1 and 2.
void nb_triangle_uvs(GpuTriangle tri, vec2 bary, out vec2 uv0, out vec2 uv1) {
    GpuVertex a = vertices[tri.v0], b = vertices[tri.v1], c = vertices[tri.v2];
    float w = 1.0f - bary.x - bary.y;
    uv0 = w * vec2(a.u0, a.v0) + bary.x * vec2(b.u0, b.v0) + bary.y * vec2(c.u0, c.v0);
    uv1 = w * a.uv1 + bary.x * b.uv1 + bary.y * c.uv1;
}

// Base-colour alpha of a material at a surface point (for alpha masks).
float nb_material_alpha(GpuMaterial m, GpuTriangle tri, vec2 bary) {
    float alpha = m.base_color.w;
    if (NB_HAS_TEXTURES && m.base_color_tex.texture >= 0) {
        vec2 uv0, uv1;
        nb_triangle_uvs(tri, bary, uv0, uv1);
        alpha *= nb_sample_texture(m.base_color_tex.texture, nb_tex_coord(m.base_color_tex, uv0, uv1)).w;
    }
    return alpha;
}

#endif
