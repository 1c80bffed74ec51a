// Editor overlay: handles, the route and a mirror disc, in camera-relative world coordinates
// (the eye is the origin, as for the tracer), projected by the view's matrix.
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec4 in_color;
layout(location = 2) in float in_size;   // point diameter in pixels

uniform mat4 u_view_projection;

out vec3 v_relative;
out vec4 v_color;

void main() {
    v_relative = in_position;
    v_color = in_color;
    gl_PointSize = in_size;
    gl_Position = u_view_projection * vec4(in_position, 1.0);
}
