// Procedural textures [KRS17 §8.2]: fractal value noise on an integer-hashed lattice (exact
// in float32 and float64, so the reference matches), filtered by the LOD: an octave fades
// out as its cells approach the pixel footprint, and its mean takes its place.
// Twin of reference/texture.py.
uniform float u_texture_scale;     // scene units per noise cell
uniform float u_texture_strength;  // 0: plain albedo, 1: full contrast
uniform vec3 u_eye;                // camera position in world space: textures stay put

uint lattice_hash(ivec2 c) {
    uint h = uint(c.x) * 0x8da6b343u ^ uint(c.y) * 0xd8163841u;
    h ^= h >> 13u;
    h *= 0x85ebca6bu;
    return h ^ (h >> 16u);
}

float lattice(ivec2 c) { return float(lattice_hash(c) & 0xffffu) / 65535.0; }

float value_noise(vec2 x) {
    vec2 i = floor(x), f = x - i, u = f * f * (3.0 - 2.0 * f);
    ivec2 c = ivec2(i);
    return mix(mix(lattice(c), lattice(c + ivec2(1, 0)), u.x),
               mix(lattice(c + ivec2(0, 1)), lattice(c + ivec2(1, 1)), u.x), u.y);
}

// Octaves 1, 2, 4, … cells per unit of x; footprint = pixel size in units of x.
float texture_fbm(vec2 x, float footprint) {
    float sum = 0.0, norm = 0.0, amp = 1.0, freq = 1.0;
    for (int o = 0; o < TEXTURE_OCTAVES; ++o) {
        float keep = clamp(2.0 - 4.0 * footprint * freq, 0.0, 1.0);
        sum += amp * (0.5 + (value_noise(freq * x + float(o) * TEXTURE_OCTAVE_SHIFT) - 0.5) * keep);
        norm += amp;
        amp *= 0.5;
        freq *= 2.0;
    }
    return sum / norm;
}

// Albedo factor with mean 1: the pattern's contrast scaled by the strength.
float texture_modulation(float pattern) { return 1.0 + u_texture_strength * (2.0 * pattern - 1.0); }

#ifdef KRS_TRIPLANAR_TEXTURE
// [Gei07]: the texture projected along x, y and z, blended by |n|⁴ (world point p_world).
float triplanar(vec3 p_world, vec3 n, float footprint) {
    vec3 w = pow(abs(n), vec3(4.0));
    w /= w.x + w.y + w.z;
    vec3 x = p_world / u_texture_scale;
    float f = footprint / u_texture_scale;
    return w.x * texture_fbm(x.yz, f) + w.y * texture_fbm(x.zx, f) + w.z * texture_fbm(x.xy, f);
}
#endif

#ifdef KRS_KERNEL_TEXTURE
vec3 perpendicular(vec3 d) {
    vec3 a = abs(d.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 0.0, 1.0);
    return normalize(a - dot(a, d) * d);
}

// (along, around) in scene units on kernel `level` at its kernel-space point xk
// (camera-relative; eye = the camera's world position, which planes need).
vec2 kernel_uv(int level, vec3 xk, vec3 eye) {
    int type = int(kernel_rec_float(level, 0).w);
    float r = kernel_rec_float(level, 1).w;
    if (type == KERNEL_SPHERE) {
        vec3 q = xk - kernel_rec_float(level, 1).xyz;
        return r * vec2(atan(q.z, q.x), acos(clamp(q.y / max(length(q), 1e-30), -1.0, 1.0)));
    }
    if (type == KERNEL_CAPSULE) {
        vec3 a = kernel_rec_float(level, 1).xyz, d = normalize(kernel_rec_float(level, 2).xyz - a);
        vec3 e1 = perpendicular(d), e2 = cross(d, e1), q = xk - a;
        return vec2(dot(q, d), r * atan(dot(q, e2), dot(q, e1)));
    }
#ifdef KRS_KERNEL_TOROIDAL_CAPSULE
    if (type == KERNEL_TOROIDAL_CAPSULE) {  // the arc's frame in units of R: angles from the
        vec4 P = kernel_rec_float(level, 2);  // bisector along, from the arc's plane around
        vec3 a = vec3(arc_local(vec4r(P), vec3r(xk - kernel_rec_float(level, 1).xyz)));
        return vec2(atan(a.y, a.x) / dot(P, P), r * atan(a.z, length(a.xy) - 1.0));
    }
#endif
    vec3 u = kernel_rec_float(level, 1).xyz, e1 = perpendicular(u), q = xk + eye;  // plane
    return vec2(dot(q, e1), dot(q, cross(u, e1)));
}

// Bark streaks along a branch; a ground plane's patches the same across (GROUND_STRETCH).
float kernel_texture(int level, vec3 xk, vec3 eye, float footprint) {
    vec2 stretch = vec2(BARK_STRETCH);
#ifdef KRS_KERNEL_PLANE  // a scene without a plane reads no kernel type here
    if (int(kernel_rec_float(level, 0).w) == KERNEL_PLANE) stretch = vec2(GROUND_STRETCH);
#endif
    vec2 x = stretch * kernel_uv(level, xk, eye) / u_texture_scale;
    return texture_fbm(x, max(stretch.x, stretch.y) * footprint / u_texture_scale);
}
#endif
