"""Ways out of krsview: camera-path frames and video, web page and Shadertoy export, meshes,
and batch rendering on Ray [issue 18]."""
