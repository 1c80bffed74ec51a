// Composites the overlay with the traced image by depth [KRS17 §8.3]: where the tracer hit a
// surface nearer than the overlay fragment, the fragment is behind geometry and drawn faint
// (so a handle behind a branch can still be found), else at full strength.
uniform sampler2D u_color;       // traced rgb, hit
uniform sampler2D u_normal;      // traced xyz, depth t along the unit ray
#include "window_image.glsl"
uniform float u_hidden_alpha;
uniform bool u_points;

in vec3 v_relative;
in vec4 v_color;
out vec4 frag_color;

void main() {
    if (u_points && length(gl_PointCoord - 0.5) > 0.5)
        discard;                                   // round handles
    vec2 uv = window_image_uv();
    bool hit = texture(u_color, uv).a > 0.5;
    float t_surface = texture(u_normal, uv).w;
    bool hidden = hit && t_surface < length(v_relative) * (1.0 - 1e-4);
    frag_color = vec4(v_color.rgb, v_color.a * (hidden ? u_hidden_alpha : 1.0));
}
