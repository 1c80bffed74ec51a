// Wind: component c bends about the horizontal axis A through its foot b_c by a_c(t)·height,
// a time-dependent Lipschitz distortion [KRS17 §5.2, §10]; twin of reference/wind.py (the
// map, its bound ‖Dg‖ ≤ 1 + |a|ρ and its normal are derived there). Time is u_time only.
// A KRS steps by it (distance.glsl); a MöKRS, component 0, maps its probes through it
// (mokrs.glsl, is_unbounding).
uniform float u_time;          // scene.time, seconds
uniform vec3 u_wind_axis;      // A = normalize(up × wind), horizontal
uniform vec4 u_wind;           // radians of lean per unit height, gust, phase step (s),
                               // most |a| × the largest reach (the most a step shrinks)
uniform vec3 u_wind_freq;      // the gusts' three angular frequencies, radians per second
uniform vec3 u_wind_weight;    // and their weights (sum 1)
uniform vec4 u_wind_base[COMPONENT_SLOTS];  // foot (camera-relative); w: reach, 0: stands
uniform vec4 u_wind_ball[COMPONENT_SLOTS];  // holds the bent component at any time; w < 0: none

// n(t): the gusts' sway about the mean lean, |n| ≤ 1.
float wind_gust(float t) { return dot(u_wind_weight, sin(u_wind_freq * t)); }

// a_c(t), radians per unit height; each component its own phase, so neighbours do not sway
// in step. (Kept per pixel in an array, the rates cost the grove more than their sines.)
float wind_rate(int c) {
    float t = u_time + float(c) * u_wind.z;
    return float(u_wind_base[c].w > 0.0) * u_wind.x * (1.0 + u_wind.y * wind_gust(t));
}

// The factor of the LOD threshold ε(t) in the wind, one for the frame: 1 / (1 + most·reach),
// the least the step's shrink 1 / (1 + |a|ρ) gets at any time and point (reference/wind.py,
// lod_scale); a KRS's (distance.glsl) and a MöKRS's (mokrs.glsl) alike.
real wind_lod_scale() { return 1.0 / (1.0 + u_wind.w); }

// How far v moves when turned about A by `angle` (Rodrigues, with 1 − cos = 2 sin²(angle/2)
// against cancellation): exactly 0 at angle 0, so an idle wind leaves every point as it is.
vec3r wind_turn(vec3r v, float angle) {
    vec3r axis = vec3r(u_wind_axis);
    real s = sin(angle), h = sin(0.5 * angle);
    return cross(axis, v) * s + (axis * dot(axis, v) - v) * (2.0 * h * h);
}

// The ρ of the step's bound 1 + |a|(ρ + δ) at p for component c with free radius D: the
// distance to its axis line, or where smaller (ρ + (ŵ·r)⁺)/2 + |a|(ρ + D)²/8 (ŵ = A × up,
// the wind), from ‖Dg‖ = (β + √(4 + 4α + β²))/2; reference/wind.py derives both.
real wind_rho(int c, vec3r p, real D, float a) {
    vec3r r = p - u_wind_base[c].xyz;
    real rho = length(cross(vec3r(u_wind_axis), r));
    real along = max(dot(vec3r(cross(u_wind_axis, vec3(0.0, 1.0, 0.0))), r), 0.0);
    real far = rho + max(D, 0.0);
    return min(rho, 0.5 * (rho + along) + 0.125 * abs(a) * far * far);
}

// g: where component c's rest geometry is looked up for the world point p, with its rate a.
vec3r unwind(int c, vec3r p, float a) {
    vec3r r = p - u_wind_base[c].xyz;
    return p + wind_turn(r, -a * float(max(r.y, 0.0)));
}

// How far p is from the ball holding component c at any time (scene/effects.py,
// swept_ball): a lower bound of its distance that needs no shrinking, so far from the tree
// the step is not shortened by the bend's bound. −FAR_AWAY where c stands.
real wind_ball_distance(int c, vec3r p) {
    vec4 ball = u_wind_ball[c];
    return ball.w < 0.0 ? -FAR_AWAY : length(p - vec3r(ball.xyz)) - ball.w;
}

// World normal Dgᵀ g from the gradient g at q = g(p): turned back, less the shear's part.
vec3 wind_normal(int c, vec3 p, vec3 q, vec3 g) {
    vec3 r = p - u_wind_base[c].xyz;
    float a = wind_rate(c);
    vec3 n = g + vec3(wind_turn(g, a * max(r.y, 0.0)));
    if (r.y > 0.0) n.y -= a * dot(cross(u_wind_axis, q - u_wind_base[c].xyz), g);
    return normalize(n);
}
