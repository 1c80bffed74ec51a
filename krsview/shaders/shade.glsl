// Lambert + ambient shading, gamma-encoded [KRS17 §8.1]; twin of reference/shade.py.
#define GAMMA 2.2

vec3 encode(vec3 linear) { return pow(clamp(linear, 0.0, 1.0), vec3(1.0 / GAMMA)); }

vec3 lambert(vec3 albedo, vec3 n) {
    vec3 light = u_ambient;
    for (int k = 0; k < u_light_count; ++k)
        light += max(dot(n, u_light_dir[k]), 0.0) * u_light_color[k];
    return albedo * light;
}
