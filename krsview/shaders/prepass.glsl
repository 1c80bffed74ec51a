// Low-resolution pre-pass [KRS17 §10, KRS14 §4; issue 17 §2]: one cone per tile of
// u_tile × u_tile pixels finds how far every ray of the tile is free, per component, and
// each full-resolution ray starts there (tests: the hit mask equals the one without it).
//
// The cone: the tile's rays leave the eye with directions within σ of the centre ray's
// (σ = the largest |dir_q − dir_centre| over the tile's corner pixels; the angle is largest
// at a corner). At parameter u a ray is within u·σ of the centre ray's point, and the ray
// stops where its distance is below ε(u) ≤ u·ε_per_t, so with σ' = σ + ε_per_t the ball of
// radius s + (t + 2s)·σ' around the centre ray's point t + s holds every tile ray's points on
// [t, t + 2s] with their ε-balls. Probed as the binary tracer does [KRS17 Alg. 2]: free →
// t += 2s and s grows; blocked → s shrinks, until s is no larger than PREPASS_STOP times the
// cone's own width t·σ' (the cone creeps on with probes narrower than itself, which its 16 or
// more rays need not take: compile/constants.py).
// The probing starts at t0: 0, or where the cone of the coarser tile around this one stopped
// (prepass.frag; render.prepass_levels).
uniform int u_tile;

// Where a coarse pass stores its tiles: blocks of PREPASS_BLOCK × PREPASS_BLOCK tiles alternate
// between four quarter images, block (i, j) at (i / 2, j / 2) of quarter (i % 2, j % 2),
// quarter k starting at k × stride, on a corner of llvmpipe's 64-pixel bins. llvmpipe gives
// each bin to one thread, and a coarse image of up to 64 × 64 tiles (the whole of it at
// 320×180) lies in one or two bins, all of the tree's cones in one; each quarter samples the
// whole image, so the threads share the cones, and a block keeps neighbouring tiles together
// in a SIMD group (gpu/renderer.py draws each quarter; gpu/coarse.py, coarse_layout, gives
// the strides; docs/speed.md).
ivec2 coarse_texel(ivec2 tile, ivec2 stride) {
    ivec2 block = tile / PREPASS_BLOCK;
    return (block & 1) * stride + (block >> 1) * PREPASS_BLOCK + tile % PREPASS_BLOCK;
}

#ifdef KRS_PREPASS_COARSE
real cone_free(int c, vec3r dir, real sigma, real t0) {
    real t = t0, s = INITIAL_PROBE;
    for (int i = 0; i < u_max_iterations; ++i) {
        if (t > u_max_distance) break;
        if (is_unbounding(c, (t + s) * dir, s + (t + 2.0 * s) * sigma)) {
            t += 2.0 * s;
            s *= u_xi_bonus;
        } else {
            if (s <= PREPASS_STOP * t * sigma) break;
            s *= u_xi_penalty;
        }
    }
    return t;
}

// The tile's spread σ' (see above), for the tile whose first pixel is `corner`.
real cone_spread(vec2 corner, vec3r centre) {
    real sigma = 0.0;
    for (int k = 0; k < 4; ++k) {
        vec2 q = corner + 0.5 + vec2(k & 1, k >> 1) * float(u_tile - 1);
        sigma = max(sigma, length(pixel_ray(q) - centre));
    }
    return sigma + real(u_eps_per_t);
}
#endif

#ifdef KRS_PREPASS
// Free distance per component: components 4k..4k + 3 in target k (compile/constants.py:
// PREPASS_TARGETS × 4 = MAX_COMPONENTS).
uniform sampler2D u_free[PREPASS_TARGETS];
uniform ivec2 u_free_stride;  // the finest coarse pass's quarter stride (coarse_texel)

// Where the ray of `pixel` starts, per component: its tile's free distance. The tile is
// pixel / u_tile, found in float ((p + ½)/t lies ½/t clear of an integer): llvmpipe divides
// integers one lane at a time, which cost the free tiles' pass a fifth of its time.
void ray_start(ivec2 pixel, out real start[COMPONENT_SLOTS]) {
    ivec2 texel = coarse_texel(ivec2((vec2(pixel) + 0.5) / float(u_tile)), u_free_stride);
    vec4 t[PREPASS_TARGETS];
    for (int k = 0; k < PREPASS_TARGETS; ++k) t[k] = texelFetch(u_free[k], texel, 0);
    for (int c = 0; c < COMPONENT_SLOTS; ++c) start[c] = real(t[c / 4][c % 4]);
}
#else
void ray_start(ivec2 pixel, out real start[COMPONENT_SLOTS]) {
    for (int c = 0; c < COMPONENT_SLOTS; ++c) start[c] = 0.0;
}
#endif
