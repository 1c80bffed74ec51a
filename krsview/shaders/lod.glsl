// The level of detail [issue 27]: one field over space, ρ(p) = u_lod · ε_per_t · |p|, the
// camera's pixel footprint at camera-relative p, so primary rays, shadow rays, the pre-pass
// and occlusion all meet the same geometry; twin of reference/geometry.py, Lod. A KRS's walk
// draws a subtree whose ball is smaller than ρ as that ball (krs.glsl); a MöKRS's, a level
// whose bound is smaller (mokrs.glsl).
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
