// Sphere tracing [Har96] with LOD threshold ε = footprint × t × ε-scale [KRS17 §4];
// twin of reference/trace.py.
#include "krs.glsl"

bool sphere_trace(vec3 origin, vec3 dir, out float t, out int iterations) {
    t = 0.0;
    for (iterations = 0; iterations < u_max_iterations;) {
        float d = krs_distance(origin + t * dir);
        ++iterations;
        if (d <= u_eps_per_t * t) return true;
        t += d;
        if (t > u_max_distance) return false;
    }
    return false;
}
