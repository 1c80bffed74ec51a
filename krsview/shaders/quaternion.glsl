// Quaternions as vec4(real, i, j, k) [KRS17 §6.2]; twin of algebra/quaternion.py.
vec4r qpure(vec3r v) { return vec4r(0.0, v); }

vec4r qmul(vec4r p, vec4r q) {
    return vec4r(p.x * q.x - dot(p.yzw, q.yzw), p.x * q.yzw + q.x * p.yzw + cross(p.yzw, q.yzw));
}

vec4r qinv(vec4r q) { return vec4r(q.x, -q.yzw) / dot(q, q); }
