// Möbius transformations H_i = G_i⁻¹ of the MöKRS levels [KRS17 §6.2, App. C]; twin of
// algebra/mobius.py (apply, map_ball, gradient). Record per level: a, b, c, d, then
// (pole.xyz, flags) with a pole, or (|a|/|d|, 0, 0, flags) for a similarity (c = 0);
// flags = has_pole + 2 · reflects.
#include "quaternion.glsl"

vec4 mobius_rec(int i, int k) { return u_mobius[i * MOBIUS_RECORD + k]; }

// L_H(p) = (a p + b)(c p + d)⁻¹ (Eq. 1).
vec3 mobius_apply(int i, vec3 p) {
    vec4 q = qpure(p);
    vec4 num = qmul(mobius_rec(i, 0), q) + mobius_rec(i, 1);
    vec4 den = qmul(mobius_rec(i, 2), q) + mobius_rec(i, 3);
    return qmul(num, qinv(den)).yzw;
}

// The image of a ball under L_H, from the diameter on the line through the pole (it maps
// to a diameter of the image); false if the ball holds the pole (image: an exterior).
// Float32-safe, unlike App. A's ρ² = |κ|² − γ. A similarity needs only the centre.
bool map_ball(int i, inout vec3 center, inout float radius) {
    vec4 pf = mobius_rec(i, 4);
    if ((int(pf.w) & 1) == 0) {  // a similarity: one point and a scale
        center = mobius_apply(i, center);
        radius *= pf.x;
        return true;
    }
    vec3 off = center - pf.xyz;
    float dist = length(off);
    if (dist <= radius) return false;
    vec3 u = off / dist;
    vec3 x1 = mobius_apply(i, center + radius * u), x2 = mobius_apply(i, center - radius * u);
    center = 0.5 * (x1 + x2);
    radius = 0.5 * length(x1 - x2);
    return true;
}

// dL_H at p as a matrix: columns (a − L_H(p) c) e_k (cp + d)⁻¹ [KRS17 App. C, Eq. 3].
mat3 mobius_jacobian(int i, vec3 p, vec3 image) {
    vec4 left = mobius_rec(i, 0) - qmul(qpure(image), mobius_rec(i, 2));
    vec4 right = qinv(qmul(mobius_rec(i, 2), qpure(p)) + mobius_rec(i, 3));
    return mat3(qmul(qmul(left, vec4(0, 1, 0, 0)), right).yzw,
                qmul(qmul(left, vec4(0, 0, 1, 0)), right).yzw,
                qmul(qmul(left, vec4(0, 0, 0, 1)), right).yzw);
}
