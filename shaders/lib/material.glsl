// Surface points and the glTF metallic-roughness BSDF: Lambert diffuse + GGX specular (height-correlated
// Smith, Schlick Fresnel, glTF spec appendix B), plus thin-walled specular transmission for
// KHR_materials_transmission (a delta lobe: straight through, tinted by the base colour).
#ifndef NB_MATERIAL_GLSL
#define NB_MATERIAL_GLSL
#include "lib/bindings.glsl"
#include "lib/textures.glsl"
#include "shared/sampling.h"

struct Surface {
    vec3 p;          // world position
    vec3 ng;         // geometric normal, facing the incoming ray
    vec3 n;          // shading normal (interpolated, normal-mapped), on the side of ng
    vec3 base;       // linear base colour
    float metallic;
    float alpha;     // GGX alpha
    float transmission;
    vec3 emission;   // emitted radiance (two-sided)
    uint material;
};

// Emitted radiance of a triangle at barycentrics (emissive factor x emissive texture).
vec3 nb_triangle_emission(GpuMaterial m, GpuTriangle tri, vec2 bary) {
    vec3 e = m.emissive;
    if (NB_HAS_TEXTURES && m.emissive_tex.texture >= 0) {
        vec2 uv0, uv1;
        nb_triangle_uvs(tri, bary, uv0, uv1);
        e *= nb_srgb_to_linear3(nb_sample_texture(m.emissive_tex.texture, nb_tex_coord(m.emissive_tex, uv0, uv1)).xyz);
    }
    return e;
}

Surface nb_make_surface(uint instance, uint tri_index, vec2 bary, vec3 ray_org, vec3 ray_dir, float t) {
    GpuInstance inst = instances[instance];
    GpuTriangle tri = triangles[tri_index];
    GpuVertex a = vertices[tri.v0], b = vertices[tri.v1], c = vertices[tri.v2];
    GpuMaterial m = materials[tri.material];
    float w = 1.0f - bary.x - bary.y;

    Surface s;
    s.material = tri.material;
    vec3 p_obj = w * a.position + bary.x * b.position + bary.y * c.position;
    s.p = nb_xform_point(inst.object_to_world, p_obj);
    vec3 ng = nb_xform_normal(inst.world_to_object, cross(b.position - a.position, c.position - a.position));
    float ng_len = length(ng);
    ng = ng_len > 0.0f ? ng / ng_len : -ray_dir;
    if (dot(ng, ray_dir) > 0.0f) ng = -ng;
    s.ng = ng;

    vec3 n_obj = w * a.normal + bary.x * b.normal + bary.y * c.normal;
    vec3 n = nb_xform_normal(inst.world_to_object, n_obj);
    vec2 uv0 = vec2(0.0f), uv1 = vec2(0.0f);
    if (NB_HAS_TEXTURES) nb_triangle_uvs(tri, bary, uv0, uv1);
    if (NB_HAS_NORMAL_MAPS && m.normal_tex.texture >= 0) {
        vec3 tn = nb_sample_texture(m.normal_tex.texture, nb_tex_coord(m.normal_tex, uv0, uv1)).xyz * 2.0f - 1.0f;
        tn.xy *= m.normal_scale;
        vec4 tan_obj = w * a.tangent + bary.x * b.tangent + bary.y * c.tangent;
        vec3 nn = normalize(n);
        vec3 tw = nb_xform_vector(inst.object_to_world, tan_obj.xyz);
        vec3 tt, bb;
        if (dot(tw, tw) > 1.0e-12f && !isnan(nn.x)) {
            tt = normalize(tw - nn * dot(nn, tw)); // Gram-Schmidt
            bb = cross(nn, tt) * (a.tangent.w < 0.0f ? -1.0f : 1.0f);
        } else {
            nb_make_basis(nn, tt, bb); // no tangents: an arbitrary frame (official implementation §8)
        }
        n = tt * tn.x + bb * tn.y + nn * tn.z;
    }
    float n_len = length(n);
    n = (n_len > 0.0f && !isnan(n_len)) ? n / n_len : ng;
    if (dot(n, ng) < 0.0f) n = -n; // shading normal on the side the ray came from
    s.n = n;

    vec4 base = m.base_color;
    float metallic = m.metallic, roughness = m.roughness;
    if (NB_HAS_TEXTURES) {
        if (m.base_color_tex.texture >= 0) {
            vec4 tb = nb_sample_texture(m.base_color_tex.texture, nb_tex_coord(m.base_color_tex, uv0, uv1));
            base *= vec4(nb_srgb_to_linear3(tb.xyz), tb.w);
        }
        if (m.metallic_roughness_tex.texture >= 0) {
            vec4 mr = nb_sample_texture(m.metallic_roughness_tex.texture, nb_tex_coord(m.metallic_roughness_tex, uv0, uv1));
            roughness *= mr.y;
            metallic *= mr.z;
        }
    }
    s.base = clamp(base.xyz, 0.0f, 1.0f);
    s.metallic = clamp(metallic, 0.0f, 1.0f);
    s.alpha = nb_ggx_alpha(clamp(roughness, 0.0f, 1.0f));
    s.transmission = NB_HAS_TRANSMISSION ? clamp(m.transmission, 0.0f, 1.0f) * (1.0f - s.metallic) : 0.0f;
    s.emission = NB_HAS_EMISSION ? nb_triangle_emission(m, tri, bary) : vec3(0.0f);
    return s;
}

// Probability of picking the GGX lobe among the non-delta lobes (by their albedo estimates).
float nb_specular_probability(Surface s, float n_dot_v) {
    vec3 f0 = mix(vec3(0.04f), s.base, s.metallic);
    float ws = nb_luminance(nb_fresnel_schlick(f0, n_dot_v));
    float wd = nb_luminance(s.base) * (1.0f - s.metallic) * (1.0f - s.transmission);
    return wd > 0.0f ? clamp(ws / (ws + wd), 0.1f, 0.9f) : 1.0f;
}

// f(wo, wi) * cos(theta_i) of the non-delta lobes and the solid-angle pdf with which
// nb_bsdf_sample produces wi (including the probability of not picking transmission).
vec3 nb_bsdf_eval(Surface s, vec3 wo, vec3 wi, out float pdf) {
    pdf = 0.0f;
    float n_dot_v = dot(s.n, wo);
    float n_dot_l = dot(s.n, wi);
    if (n_dot_v <= 0.0f || n_dot_l <= 0.0f || dot(s.ng, wi) <= 0.0f) return vec3(0.0f);
    vec3 h = normalize(wo + wi);
    float n_dot_h = max(dot(s.n, h), 0.0f);
    float v_dot_h = max(dot(wo, h), 0.0f);
    vec3 f0 = mix(vec3(0.04f), s.base, s.metallic);
    vec3 F = nb_fresnel_schlick(f0, v_dot_h);
    vec3 spec = F * (nb_ggx_d(n_dot_h, s.alpha) * nb_ggx_v(n_dot_l, n_dot_v, s.alpha));
    vec3 diff = s.base * ((1.0f - s.metallic) * (1.0f - s.transmission) * NB_INV_PI);
    float p_spec = nb_specular_probability(s, n_dot_v);
    pdf = (1.0f - s.transmission) *
          (p_spec * nb_ggx_pdf(n_dot_v, n_dot_h, s.alpha) + (1.0f - p_spec) * n_dot_l * NB_INV_PI);
    return (spec + diff) * n_dot_l;
}

// Samples a continuation direction. weight = f cos / pdf; pdf < 0 marks the delta transmission lobe.
// u0 picks the lobe, (u1, u2) the direction. Returns false when the path ends (sample below the surface).
bool nb_bsdf_sample(Surface s, vec3 wo, float u0, vec2 u, out vec3 wi, out vec3 weight, out float pdf) {
    float u1 = u.x;
    float u2 = u.y;
    weight = vec3(0.0f);
    pdf = 0.0f;
    wi = s.n;
    if (NB_HAS_TRANSMISSION && u0 < s.transmission) {
        wi = -wo; // thin-walled: passes straight through
        weight = s.base;
        pdf = -1.0f;
        return true;
    }
    if (NB_HAS_TRANSMISSION) u0 = (u0 - s.transmission) / max(1.0f - s.transmission, 1.0e-6f);
    vec3 t, b;
    nb_make_basis(s.n, t, b);
    vec3 wo_local = vec3(dot(wo, t), dot(wo, b), dot(wo, s.n));
    if (wo_local.z <= 0.0f) return false;
    vec3 wi_local;
    if (u0 < nb_specular_probability(s, wo_local.z)) {
        vec3 h = nb_ggx_sample_vndf(wo_local, s.alpha, u1, u2);
        wi_local = reflect(-wo_local, h);
    } else {
        wi_local = nb_sample_cosine(u1, u2);
    }
    wi = normalize(t * wi_local.x + b * wi_local.y + s.n * wi_local.z);
    vec3 f = nb_bsdf_eval(s, wo, wi, pdf);
    if (!(pdf > 0.0f)) return false;
    weight = f / pdf;
    return true;
}

#endif
