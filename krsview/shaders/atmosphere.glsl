// Sky, fog and tone mapping: what makes a preset look like a scene; twin of
// reference/atmosphere.py. Each part is its own effect.
#ifdef KRS_SKY
uniform vec3 u_sky_zenith;

// Horizon (the material's background) to zenith above, darkening below; a glow towards
// the first light.
vec3 sky(vec3 dir) {
    vec3 c = dir.y >= 0.0 ? mix(u_background, u_sky_zenith, sqrt(dir.y))
                          : u_background * mix(1.0, 0.6, min(-3.0 * dir.y, 1.0));
    if (u_light_count > 0)
        c += 2.0 * u_light_color[0] * pow(max(dot(dir, u_light_dir[0]), 0.0), SUN_SHARPNESS);
    return c;
}
#endif

vec3 background(vec3 dir) {
#ifdef KRS_SKY
    if (EFFECT_ON(KRS_SKY_BIT)) return sky(dir);
#endif
    return u_background;
}

#ifdef KRS_FOG
uniform float u_fog_density;

vec3 fog(vec3 color, vec3 dir, float t) {
    return mix(color, background(dir), 1.0 - exp(-u_fog_density * t));
}
#endif

#ifdef KRS_TONE_MAPPING
uniform float u_exposure;

// The ACES filmic curve fitted by Narkowicz (2015), after the exposure scale.
vec3 tone_map(vec3 linear) {
    vec3 x = u_exposure * linear;
    return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}
#endif
