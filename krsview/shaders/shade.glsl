// Shading of a hit [KRS17 §8]: Lambert + ambient with the scene's effects (texture, shadows,
// ambient occlusion, fog), then tone mapping and gamma; twin of reference/shade.py.
#include "atmosphere.glsl"
#if defined(KRS_TRIPLANAR_TEXTURE) || defined(KRS_KERNEL_TEXTURE)
#include "texture.glsl"
#endif
#if defined(KRS_SHADOWS) || defined(KRS_SOFT_SHADOWS)
#include "shadows.glsl"
#endif
#ifdef KRS_AMBIENT_OCCLUSION
#include "occlusion.glsl"
#endif

vec3 encode(vec3 linear) {
#ifdef KRS_TONE_MAPPING
    if (EFFECT_ON(KRS_TONE_MAPPING_BIT)) linear = tone_map(linear);
#endif
    return pow(clamp(linear, 0.0, 1.0), vec3(1.0 / GAMMA));
}

// Linear radiance of the hit at p (ray distance t along dir) on kernel `level` with world
// normal n and kernel-space point xk.
vec3 shade(vec3r p, vec3 dir, real t_ray, int level, vec3 n, vec3 xk) {
    float t = float(t_ray);
    vec3 albedo = kernel_rec_float(level, 0).rgb;
    float footprint = u_detail_footprint * t;
#ifdef KRS_TRIPLANAR_TEXTURE
    if (EFFECT_ON(KRS_TRIPLANAR_TEXTURE_BIT))
        albedo *= texture_modulation(triplanar(vec3(p) + u_eye, n, footprint));
#endif
#ifdef KRS_KERNEL_TEXTURE
    if (EFFECT_ON(KRS_KERNEL_TEXTURE_BIT))
        albedo *= texture_modulation(kernel_texture(level, xk, u_eye, footprint));
#endif
    vec3 light = u_ambient;
#ifdef KRS_AMBIENT_OCCLUSION
    if (EFFECT_ON(KRS_AMBIENT_OCCLUSION_BIT)) light *= ambient_occlusion(p, n);
#endif
    for (int k = 0; k < u_light_count; ++k) {
        float cos_l = max(dot(n, u_light_dir[k]), 0.0);
#if defined(KRS_SHADOWS) || defined(KRS_SOFT_SHADOWS)
        if (cos_l > 0.0 && shadows_on())
            cos_l *= light_visibility(k, p, n, u_eps_per_t * t);
#endif
        light += cos_l * u_light_color[k];
    }
    vec3 color = albedo * light;
#ifdef KRS_FOG
    if (EFFECT_ON(KRS_FOG_BIT)) color = fog(color, dir, t);
#endif
    return color;
}
