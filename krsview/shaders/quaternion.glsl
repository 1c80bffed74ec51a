// Quaternions as vec4(real, i, j, k) [KRS17 §6.2]; twin of algebra/quaternion.py.
vec4 qpure(vec3 v) { return vec4(0.0, v); }

vec4 qmul(vec4 p, vec4 q) {
    return vec4(p.x * q.x - dot(p.yzw, q.yzw), p.x * q.yzw + q.x * p.yzw + cross(p.yzw, q.yzw));
}

vec4 qinv(vec4 q) { return vec4(q.x, -q.yzw) / dot(q, q); }
