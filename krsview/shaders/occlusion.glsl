// Ambient occlusion from AO_SAMPLES distance samples along the normal [KRS17 §8.5]: a sample
// at height h that finds the geometry nearer than h is occluded by (h − d)/h, weighted 2^−k;
// twin of reference/occlusion.py. It costs AO_SAMPLES distance evaluations per pixel.
uniform float u_ao_step;
uniform float u_ao_strength;

float ambient_occlusion(vec3r p, vec3 n) {
    float occlusion = 0.0, weight = 0.5;
    for (int k = 1; k <= AO_SAMPLES; ++k) {
        float h = float(k) * u_ao_step;
        occlusion += weight * clamp((h - float(scene_distance(p + h * n))) / h, 0.0, 1.0);
        weight *= 0.5;
    }
    return clamp(1.0 - u_ao_strength * occlusion, 0.0, 1.0);
}
