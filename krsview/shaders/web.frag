// The exported web page's and Shadertoy's fragment stage [issue 18]: the app's own tracer and
// shading in GLSL ES 3.00. share/web.py bakes the scene's uniforms into constants, relative
// to the exported camera's eye O, and turns the camera's uniforms into globals that
// orbit_camera sets per pixel from the page's (or Shadertoy's) mouse: the eye moves to
// u_eye_shift (relative to O) and rays start there instead of at the origin.
#include "effects.glsl"
#include "scene_block.glsl"
#include "trace.glsl"
#include "shade.glsl"

uniform vec3 u_eye_shift;     // the eye, relative to O (set by orbit_camera)
uniform vec3 u_orbit_target;  // the point orbited, relative to O (the scene camera's target)
uniform vec3 u_orbit_east;    // horizontal axes ⟂ u_orbit_up: yaw 0 looks along north
uniform vec3 u_orbit_north;
uniform vec3 u_orbit_up;      // the scene camera's up
uniform vec3 u_orbit_start;   // yaw, pitch and distance of O seen from the target
uniform float u_epsilon_scale;

// The camera for `orbit` = (yaw turned, pitch turned, distance factor) from the exported
// view (0, 0, 1), with the basis of compile/camera.py's view_of.
void orbit_camera(vec2 resolution, vec3 orbit) {
    float yaw = u_orbit_start.x + orbit.x;
    float pitch = clamp(u_orbit_start.y + orbit.y, -1.55, 1.55);
    vec3 away = cos(pitch) * sin(yaw) * u_orbit_east + sin(pitch) * u_orbit_up
              + cos(pitch) * cos(yaw) * u_orbit_north;
    u_eye_shift = u_orbit_target + u_orbit_start.z * orbit.z * away;
    u_forward = -away;
    u_right = normalize(cross(u_forward, u_orbit_up));
    u_up = cross(u_right, u_forward);
    u_resolution = resolution;
    u_footprint = 2.0 * u_tan_half / resolution.y;
    u_detail_footprint = u_footprint;
    u_eps_per_t = u_footprint * u_epsilon_scale;
}

// The pixel at window position `frag` (pixel centres at .5), traced and shaded as
// pixel.glsl does, from the eye at u_eye_shift.
vec4 krs_image(vec2 frag) {
    vec3r dir = pixel_ray(vec2(frag.x, u_resolution.y - frag.y));  // the canvas: rows bottom → top
    real start[COMPONENT_SLOTS];
    for (int c = 0; c < COMPONENT_SLOTS; ++c) start[c] = 0.0;
    real t;
    int iterations, slots;
    vec3r o = u_eye_shift;
    if (!trace_ray(o, dir, start, t, iterations, slots)) return vec4(encode(background(dir)), 1.0);
    int level;
    vec3 n, xk;
    nearest_kernel(o + t * dir, t, slots, level, n, xk);
    return vec4(encode(shade(o + t * dir, dir, t, level, n, xk)), 1.0);
}

#ifndef KRS_SHADERTOY
uniform vec3 u_orbit;         // the page's mouse: yaw, pitch, distance factor
uniform vec2 u_canvas;        // the canvas in pixels
out vec4 out_color;

void main() {
    orbit_camera(u_canvas, u_orbit);
    out_color = krs_image(gl_FragCoord.xy);
}
#endif
