// KRS distance [KRS17 Alg. 1] and nearest kernel with world normal [KRS14 §6.1];
// twin of reference/krs.py. Folding clips each level to its mirror's negative side.
#include "kernels.glsl"
#include "lod.glsl"

// Reflect p if it lies behind mirror i, the plane u·p = w; returns that signed distance e.
// With the level of detail the walk reads slot i's ball (c, r) at every level, and
// compile/balls.py centres it on the mirror's plane, so e = u·(p − c) needs no w: 7 scalars a
// level, not 8. Without it e = u·p − w reads the mirror alone (4 scalars, not 6 with c).
// Culling on or off, a variant folds alike, so culling changes no value, bit for bit.
real fold(int i, vec3r c, inout vec3r p) {
    vec3r u = u_mirrors[i].xyz;
#ifdef KRS_LOD
    real e = dot(p - c, u);
#else
    real e = dot(p, u) - u_mirrors[i].w;
#endif
    p -= 2.0 * max(e, 0.0) * u;  // no branch: llvmpipe would run it anyway
    return e;
}

// The KRS whose kernels K_0..K_n and mirrors R_0..R_{n−1} sit in slots first..first + n.
// Exact level culling [issue 17]: once d ≤ dist(x, C_i), the ball of everything levels i..0
// would still test (compile/balls.py, krs_bounds; r < 0: none), the walk stops with the
// same value. Most rays far from the finer levels pay for a few levels instead of n.
// Level of detail [issue 27, KRS14 LOD]: at the first ball C_i at least lod.depth levels
// below the top (where ρ cuts, compile/lod.py), the ball stands for levels i..0
// (d = min(d, dist(x, C_i)), a lower bound of what they would give) and the walk stops:
// detail smaller than ρ costs nothing (lod.glsl; reference/krs.py says which geometry that
// draws). Such a ball holds its part of the levels below, so it reaches at most its
// diameter, lod.reach (under 2Kρ), beyond the ball of any slot above (compile/balls.py: the
// balls are not nested): culling then stops once d ≤ dist(x, C_i) − lod.reach, still with
// the value the whole walk would give.
#ifdef KRS_COUNT_LEVELS
int g_levels = 0;   // levels walked so far by this invocation (bench paths' measure)
#endif

// Level slot i (top: the KRS's top slot) of Alg. 1 on the point x with the distance d found
// above it: culling, the level of detail, the fold (its e returned) and the kernel; false
// where the walk ends here. A level-of-detail cut only notes its slot in `cut` and leaves x
// as it is: krs_lod_cut adds the ball's distance once, after the walk. On llvmpipe each read
// of the uniform block is a gather per component that costs far more than the arithmetic
// around it, and a branch's reads run whether any pixel takes it or not (docs/speed.md): the
// ball (c, r) is read once, and its centre c serves culling, the level of detail and the
// fold alike.
bool krs_level(int i, int top, inout vec3r x, inout real d, KrsLod lod, out real e,
               inout int cut) {
#ifdef KRS_COUNT_LEVELS
    ++g_levels;
#endif
    e = 0.0;
    vec4r b = u_bounds[i];
#ifdef KRS_CULLING
    if (b.w >= 0.0 && length(x - b.xyz) - b.w - lod.reach >= d) return false;
#endif
#ifdef KRS_LOD
    if (b.w >= 0.0 && top - i >= lod.depth) { cut = i; return false; }
#endif
    e = fold(i, b.xyz, x);
    real k = kernel_distance_of(i, x, KRS_LEVEL_KERNELS);
    g_slot = k < d ? i : g_slot;  // ties to the coarser level, as krs_nearest
    d = min(d, k);
    return true;
}

// The walk's value: d, with the level-of-detail ball of slot `cut` (−1: none) drawn at the
// point x where the walk stopped, d = min(d, dist(x, C_cut)).
real krs_lod_cut(int cut, vec3r x, real d) {
#ifdef KRS_LOD
    if (cut >= 0) {
        vec4r b = u_bounds[cut];
        real k = length(x - b.xyz) - b.w;
        g_cut = k < d ? cut : -1;
        d = min(d, k);
    }
#endif
    return d;
}

real krs_distance(int first, int n, vec3r xw, KrsLod lod) {
    vec3r x = xw;
    real d = kernel_distance_of(first + n, x, KRS_TOP_KERNELS);
    g_slot = first + n;
    g_cut = -1;
    real e;
    int cut = -1;
    int top = first + n - 1;
    for (int i = top; i >= first; --i) if (!krs_level(i, top, x, d, lod, e, cut)) break;
    return krs_lod_cut(cut, x, d);
}

#ifdef KRS_WALK_RESTART
// The walk restarted below the levels whose folds cannot change [issue 27]. An anchor is the
// walk's state before level slot j (aj; −1: none) at the ray distance where it was taken: x
// folded by the mirrors above (ax), the ray's direction folded alike (ad), the least |e| of
// those folds (am) and the least distance of the levels above (adist). Each fold is an
// isometry on each side of its mirror, so a point s < am further along the ray folds to
// ax + s·ad, adist − s bounds the levels above (1-Lipschitz), and where the level of detail
// cuts no higher than j no ball above cuts. The walk from j down
// is then Alg. 1's own value where it ends below adist − s; where that bound is what limits,
// it is only a lower bound (`bounded`): the anchor is dropped, and the next step walks from
// the top. (Walking on from the top in the same step cost more on llvmpipe, which runs a
// group of 8 pixels as long as its slowest: docs/speed.md.) The anchor moves to the deepest
// level whose min(margin, distance above) ≥ keep (κ times the last step), so the next steps
// fit under it; `saved`: an anchor was taken at this point.
real krs_restart(int first, int n, vec3r p, vec3r dir, real s, KrsLod lod, real keep,
                 inout int aj, inout vec3r ax, inout vec3r ad, inout real am,
                 inout real adist, out bool saved, out bool bounded) {
    int top = first + n - 1;
    bool again = aj >= 0 && s < min(am, adist) && top - aj <= lod.depth;
    int i = again ? aj : top;
    vec3r x = again ? ax + s * ad : p, u = again ? ad : dir;
    real bound = adist - s;
    real d = again ? bound : kernel_distance_of(first + n, p, KRS_TOP_KERNELS);
    real m = again ? am - s : FAR_AWAY;
    g_slot = again ? -1 : first + n;  // above the anchor: not known
    g_cut = -1;
    saved = false;
    int cut = -1;
    for (; i >= first;) {
        if (min(m, d) >= keep) {
            aj = i; ax = x; ad = u; am = m; adist = d;
            saved = true;
        }
        real e;
        bool on = krs_level(i, top, x, d, lod, e, cut);
        vec3r mu = u_mirrors[i].xyz;
        u -= 2.0 * (e > 0.0 ? dot(u, mu) : 0.0) * mu;
        m = min(m, abs(e));
        i = on ? i - 1 : first - 1;
    }
    d = krs_lod_cut(cut, x, d);
    bounded = again && d >= bound;
    if (bounded) aj = -1;
    return d;
}
#endif

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

// Level slot i of the walk to the nearest kernel: x folded, and A_i taken into M (below).
void fold_frame(int i, float width, inout vec3r x, inout mat3r M) {
    vec3r u = u_mirrors[i].xyz;
    real e = fold(i, u_bounds[i].xyz, x);
    M -= 2.0 * mirror_weight(e, width) * outerProduct(M * u, u);
}

// Winning level slot j (ties to the coarser level), the point x_j in its kernel's space, and the
// world normal M ∇k_j(x_j) with M = A_{n−1} ⋯ A_j, A_i = I − 2 w_i u_i u_iᵀ accumulated while
// walking down [KRS14 §6.1]: w_i = 1 where mirror i folded x, else 0 (smoothed near the plane).
// What the trace's walk at this very point handed on (trace.glsl, g_slot and g_cut) spares
// most of the kernels: it tested every level above where it stopped, so the least of them,
// `slot`, is the only one above that can win; below, the levels it culled could at most tie
// with it, and those under a ball that it cut (`cut`) could win only where that ball was
// nearer than every kernel it tested. So the walk folds down to `slot` and tests that one
// kernel, then, below a ball that won, folds on to `cut` and goes on as the whole walk does;
// without a known slot, the whole walk. llvmpipe runs every branch's reads, and a loop's body
// once even where no pixel enters it, so the folds alone and the kernels' tests are loops
// of their own, not branches in one.
real krs_nearest(int first, int n, vec3r xw, float width, int slot, int cut, out int level,
                 out vec3 normal, out vec3r xk) {
    bool known = slot >= first && slot <= first + n;
    vec3r x = xw;
    mat3r M = mat3r(1.0);
    int i = first + n - 1;
    for (; known && i >= slot; --i) fold_frame(i, width, x, M);
    level = known ? slot : first + n;
    xk = x;
    mat3r Mk = M;
    real d = kernel_distance_of(level, x, KRS_TOP_KERNELS | KRS_LEVEL_KERNELS);
    for (; known && cut >= 0 && i > cut; --i) fold_frame(i, width, x, M);
    for (; (!known || cut >= 0) && i >= first; --i) {
        fold_frame(i, width, x, M);
        real di = kernel_distance_of(i, x, KRS_LEVEL_KERNELS);
        if (di < d) { d = di; level = i; xk = x; Mk = M; }
    }
    vec3r gk = kernel_gradient(level, xk), g = Mk * gk;
    normal = vec3(length(g) > 0.0 ? normalize(g) : gk);
    return d;
}
