// A traced image drawn over a window (display.frag, overlay.frag; their sizes from
// gpu/context.image_uniforms): the image holds its rows top → bottom (scene_block.glsl,
// pixel_ray), the window bottom → top, and its textures may be a texel larger
// (context.texture_side).
uniform vec2 u_window;           // size of the target in pixels
uniform vec2 u_image;            // size of the image in pixels
uniform vec2 u_texture;          // and of its textures

// The texture coordinate of the image under this fragment, its edge texels clamped.
vec2 window_image_uv() {
    vec2 at = vec2(gl_FragCoord.x, u_window.y - gl_FragCoord.y) / u_window * u_image;
    return clamp(at, vec2(0.5), u_image - 0.5) / u_texture;
}
