"""The fly-through viewer: camera, input, adaptive resolution, window loop and HUD."""
