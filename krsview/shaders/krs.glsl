// KRS distance [KRS17 Alg. 1] and nearest kernel with world normal [KRS14 §6.1];
// twin of reference/krs.py. Folding clips each level to its mirror's negative side.
#include "kernels.glsl"

// Reflect p if it lies behind mirror i (u·p − w > 0); returns that signed distance u·p − w.
real fold(int i, inout vec3r p) {
    vec4r m = u_mirrors[i];
    real e = dot(p, m.xyz) - m.w;
    p -= 2.0 * max(e, 0.0) * m.xyz;  // no branch: llvmpipe would run it anyway
    return e;
}

// The KRS whose kernels K_0..K_n and mirrors R_0..R_{n−1} sit in slots first..first + n.
// Exact level culling [issue 17]: once d ≤ dist(x, C_i), the ball of everything levels i..0
// would still test (compile/krs.py, krs_bounds; r < 0: none), the walk stops with the
// same value. Most rays far from the finer levels pay for a few levels instead of n.
// Level of detail [issue 27, KRS14 LOD]: at the first ball C_i whose radius is below rho,
// the ball stands for levels i..0 (d = min(d, dist(x, C_i)), a lower bound of what they
// would give) and the walk stops: detail smaller than rho costs nothing (distance.glsl,
// lod_radius; reference/krs.py says which geometry that draws). Such a ball holds its part
// of the levels below and is less than 2·rho across, so it reaches at most 2·rho beyond the
// ball of any slot above (compile/balls.py: the balls are not nested): culling then stops
// once d ≤ dist(x, C_i) − 2·rho, still with the value the whole walk would give.
#ifdef KRS_COUNT_LEVELS
int g_levels = 0;   // levels walked so far by this invocation (bench paths' measure)
#endif
real krs_distance(int first, int n, vec3r xw, real rho) {
    vec3r x = xw;
    real d = kernel_distance_of(first + n, x, KRS_TOP_KERNELS);
#ifdef KRS_LOD
    real reach = 2.0 * rho;  // how far a ball drawn below may reach beyond C_i (below)
#else
    real reach = 0.0;
#endif
    for (int i = first + n - 1; i >= first; --i) {
#ifdef KRS_COUNT_LEVELS
        ++g_levels;
#endif
#if defined(KRS_CULLING) || defined(KRS_LOD)
        vec4r b = u_bounds[i];
#endif
#ifdef KRS_CULLING
        if (b.w >= 0.0 && length(x - b.xyz) - b.w - reach >= d) break;
#endif
#ifdef KRS_LOD  // the ball's distance only where it cuts: culling off pays no more
        if (b.w >= 0.0 && b.w < rho) { d = min(d, length(x - b.xyz) - b.w); break; }
#endif
        fold(i, x);
        d = min(d, kernel_distance_of(i, x, KRS_LEVEL_KERNELS));
    }
    return d;
}

#ifdef KRS_SMOOTH_SHADING
uniform float u_smooth_width;  // scene units

// [KRS14 Alg. 2]: near mirror i the reflection is blended in over a band of the given width
// (0 at −width/2, ½ on the plane, 1 at +width/2), so the two copies' normals meet smoothly.
real mirror_weight(real e, float width) {
    return EFFECT_ON(KRS_SMOOTH_SHADING_BIT) ? clamp(e / width + 0.5, 0.0, 1.0)
                                             : (e > 0.0 ? 1.0 : 0.0);
}
#else
real mirror_weight(real e, float width) { return e > 0.0 ? 1.0 : 0.0; }
#endif

// Winning level slot j (ties to the coarser level), the point x_j in its kernel's space, and the
// world normal M ∇k_j(x_j) with M = A_{n−1} ⋯ A_j, A_i = I − 2 w_i u_i u_iᵀ accumulated while
// walking down [KRS14 §6.1]: w_i = 1 where mirror i folded x, else 0 (smoothed near the plane).
real krs_nearest(int first, int n, vec3r xw, float width, out int level, out vec3 normal,
                 out vec3r xk) {
    vec3r x = xw;
    xk = xw;
    real d = kernel_distance_of(first + n, x, KRS_TOP_KERNELS);
    level = first + n;
    mat3r M = mat3r(1.0), Mk = mat3r(1.0);
    for (int i = first + n - 1; i >= first; --i) {
        vec3r u = u_mirrors[i].xyz;
        real e = fold(i, x);
        M -= 2.0 * mirror_weight(e, width) * outerProduct(M * u, u);
        real di = kernel_distance_of(i, x, KRS_LEVEL_KERNELS);
        if (di < d) { d = di; level = i; xk = x; Mk = M; }
    }
    vec3r gk = kernel_gradient(level, xk), g = Mk * gk;
    normal = vec3(length(g) > 0.0 ? normalize(g) : gk);
    return d;
}
