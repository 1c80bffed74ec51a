// Scene data: the compiled KRS (compile/krs.py holds the same layout) and view.
// Positions are camera-relative: the eye sits at the origin. The KERNEL_<KIND> codes,
// RECORD_VEC4, MAX_COMPONENTS and MAX_LIGHTS come from compile/constants.py.
#define FAR_AWAY 1e30

// Precision of the geometry (render.precision): `real` and its vectors are what distances,
// folds, Möbius maps and ray positions are computed in; shading stays in float. GLSL has no
// double sin/cos, so the twist angle is always a float (twist.glsl).
#ifdef KRS_DOUBLE
#define real double
#define vec2r dvec2
#define vec3r dvec3
#define vec4r dvec4
#define mat3r dmat3
#else
#define real float
#define vec2r vec2
#define vec3r vec3
#define vec4r vec4
#define mat3r mat3
#endif

// KRS_SLOTS level slots: one per level, or in a compound, component c's level i is slot
// first_c + i (its mirror and its kernel record share the slot).
// In double precision a compound's slots outgrow a 64 KiB uniform block: a storage buffer
// holds them (same layout: a dvec4 array has a 32-byte stride in std140 and std430).
#ifdef KRS_DOUBLE
layout(std430, binding = BINDING_KRS_BLOCK) readonly buffer KRSBlock {
#else
layout(std140) uniform KRSBlock {
#endif
#ifdef KRS_MOBIUS
    vec4r u_mobius[KRS_SLOTS * MOBIUS_RECORD];   // per level: H_i = G_i⁻¹ (mobius.glsl)
#else
    vec4r u_mirrors[KRS_SLOTS];                  // u.xyz, w: the plane u·x = w
    vec4r u_bounds[KRS_SLOTS];                   // culling ball (c, r) before fold i, c on
                                                 // mirror i's plane (krs.glsl, fold)
#endif
    vec4r u_kernels[KRS_SLOTS * RECORD_VEC4];    // per level: RECORD_VEC4 vec4s
};
uniform int u_n;            // KRS: number of mirrors, kernels K_0..K_n; MöKRS: levels

// Compound [KRS17 §5.1]: the tracer keeps one free distance per component. A single KRS or
// MöKRS is the compound of one, and then all of this folds to constants.
#ifdef KRS_COMPOUND
uniform int u_components;
uniform ivec2 u_component[MAX_COMPONENTS];  // per component: first slot, mirror count n
#define COMPONENTS u_components
#define COMPONENT_SLOTS MAX_COMPONENTS
#else
#define COMPONENTS 1
#define COMPONENT_SLOTS 1
#endif

uniform vec3r u_forward;    // camera basis in `real`: rounded to float it turns the view by
                            // ~1e-7 rad, many pixels of a deep zoom
uniform vec3r u_right;
uniform vec3r u_up;
uniform vec2 u_resolution;
uniform float u_tan_half;
uniform float u_footprint;  // pixel size at unit distance (the LOD measure [KRS17 §4])
// ... of the pixel whose detail is drawn: the textures' filter, the normals' smoothing (the
// window's for a viewer's coarse moving image: compile/camera.py, View.detail_height)
uniform float u_detail_footprint;
uniform float u_eps_per_t;  // the detail's pixel footprint × ε-scale
uniform int u_max_iterations;
uniform float u_xi_bonus;   // binary tracing [KRS17 Alg. 2]
uniform float u_xi_penalty;
uniform float u_relaxation;      // relaxed tracing: ω
uniform float u_max_distance;

// The primary ray through the pixel centre at window position `frag`. Rows run top → bottom,
// as in NumPy: every target's texel row 0 holds the image's top row, so llvmpipe, which draws
// a pass's bins from row 0 on, starts with what is usually the costliest, a crown, and ends
// with the cheap sky or ground, and an image drawn in bands is drawn from the top.
vec3r pixel_ray(vec2 frag) {
    vec2 ndc = vec2(2.0 * frag.x / u_resolution.x - 1.0, 1.0 - 2.0 * frag.y / u_resolution.y);
    float aspect = u_resolution.x / u_resolution.y;
    return normalize(u_forward + real(ndc.x * u_tan_half * aspect) * u_right
                     + real(ndc.y * u_tan_half) * u_up);
}

uniform int u_light_count;  // lights in the first of MAX_LIGHTS slots
uniform vec3 u_light_dir[MAX_LIGHTS];
uniform vec3 u_light_color[MAX_LIGHTS];   // colour × intensity
uniform vec3 u_ambient;
uniform vec3 u_background;
