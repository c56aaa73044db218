// The value at texture coordinate uvw: the grid's 3D texture, filtered trilinearly.
// Prepended: volume_common.wgsl.

fn field(uvw: vec3<f32>) -> f32 {
    return textureSampleLevel(volume, volume_sampler, uvw, 0.0).r;
}
