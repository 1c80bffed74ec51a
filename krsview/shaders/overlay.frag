// Composites the overlay with the traced image by depth [KRS17 §8.3]: where the tracer hit a
// surface nearer than the overlay fragment, the fragment is behind geometry and drawn faint
// (so a handle behind a branch can still be found), else at full strength.
uniform sampler2D u_color;       // traced rgb, hit
uniform sampler2D u_normal;      // traced xyz, depth t along the unit ray
uniform vec2 u_window;
uniform vec2 u_image;            // size of the traced image in pixels
uniform vec2 u_texture;          // and of its textures (context.texture_side)
uniform float u_hidden_alpha;
uniform bool u_points;

in vec3 v_relative;
in vec4 v_color;
out vec4 frag_color;

void main() {
    if (u_points && length(gl_PointCoord - 0.5) > 0.5)
        discard;                                   // round handles
    // the image: rows top → bottom (scene_block.glsl, pixel_ray); the window: bottom → top;
    // the image's part of its textures (they may be a texel larger)
    vec2 at = vec2(gl_FragCoord.x, u_window.y - gl_FragCoord.y) / u_window * u_image;
    vec2 uv = clamp(at, vec2(0.5), u_image - 0.5) / u_texture;
    bool hit = texture(u_color, uv).a > 0.5;
    float t_surface = texture(u_normal, uv).w;
    bool hidden = hit && t_surface < length(v_relative) * (1.0 - 1e-4);
    frag_color = vec4(v_color.rgb, v_color.a * (hidden ? u_hidden_alpha : 1.0));
}
