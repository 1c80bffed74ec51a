// The level of detail [issue 27]: one field over space, ρ(p) = u_lod · ε_per_t · |p|, the
// camera's pixel footprint at camera-relative p, so primary rays, shadow rays, the pre-pass
// and occlusion all meet the same geometry; twin of reference/geometry.py, Lod. A KRS's walk
// draws the ball of the slot where ρ cuts it for everything below (krs.glsl); a MöKRS's, a
// level whose bound is smaller (mokrs.glsl).
#ifdef KRS_LOD
uniform float u_lod;  // render.lod (> 0)
#endif

// ρ at camera-relative points as far as `reach` from the eye; a test of a ball takes ρ at
// its far side, the most any of its points has.
real lod_radius(real reach) {
#ifdef KRS_LOD
    return u_lod * u_eps_per_t * reach;
#else
    return 0.0;
#endif
}

#ifndef KRS_MOBIUS
// A step's level of detail in one KRS: its walk cuts at the first slot with a ball at least
// `depth` levels below the top, and culling reaches `reach` further than a ball: the cut
// ball's diameter (compile/lod.py says why).
struct KrsLod {
    int depth;
    real reach;
};

#ifdef KRS_LOD
// Per component: (ln A, 1/ln q, 2K, 0), the envelope r̂_k = A·q^k of its slots' cut radii
// and how far a ball cut below reaches at most, per ρ; 1/ln q ≥ 0: nothing cuts
// (compile/lod.py, lod_cut).
#ifdef KRS_COMPOUND
uniform vec4 u_lod_cut[COMPONENT_SLOTS];
#define LOD_CUT(c) u_lod_cut[c]
#else
uniform vec4 u_lod_cut;
#define LOD_CUT(c) u_lod_cut
#endif
#endif

#define LOD_DEEPEST 1048576  // a depth past every level: ρ = 0, or nothing cuts

// Component c's cut at ρ (its slots first..first + n − 1): the first depth k whose envelope
// A·q^k is below ρ, k = ⌊ln(ρ/A) / ln q⌋ + 1 ≥ 0, in float; the reach is twice the radius
// of that slot's ball, one read a step, or 2Kρ where the cut falls below it (twin:
// compile/lod.py, krs_lod).
KrsLod krs_lod(int c, int first, int n, real rho) {
#ifdef KRS_LOD
    vec4 f = LOD_CUT(c);
    float x = (log(max(float(rho), 1e-30)) - f.x) * f.y;
    int depth = f.y >= 0.0 ? LOD_DEEPEST : int(clamp(floor(min(x, float(LOD_DEEPEST))) + 1.0,
                                                     0.0, float(LOD_DEEPEST)));
    int slot = first + n - 1 - min(depth, n);
    real r = u_bounds[max(slot, first)].w;
    real reach = slot < first ? 0.0 : r >= 0.0 ? 2.0 * r : real(f.z) * rho;
    return KrsLod(depth, reach);
#else
    return KrsLod(LOD_DEEPEST, 0.0);
#endif
}
#endif
