// Empty zones: balls whose inside the tracer skips, removing the geometry there [KRS17 §8.4];
// twin of reference/distortion.py. max(D, r − |p − c|) still never overshoots: the remaining
// geometry is farther than D and lies outside every ball.
uniform int u_empty_zone_count;
uniform vec4 u_empty_zones[MAX_EMPTY_ZONES];  // camera-relative centre, radius

// The largest r − |p − c| (how deep p is inside a zone) and the index of that zone.
real zone_depth(vec3r p, out int zone) {
    real depth = -FAR_AWAY;
    zone = -1;
    for (int z = 0; z < u_empty_zone_count; ++z) {
        real e = u_empty_zones[z].w - length(p - u_empty_zones[z].xyz);
        if (e > depth) { depth = e; zone = z; }
    }
    return depth;
}
