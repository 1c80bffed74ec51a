"""GPU side: EGL context, shader builder and variant cache, uniform packing, renderer."""
