// Slices sampling the grid's 3D texture. Prepended: volume_common.wgsl.

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let c = shade(textureSampleLevel(volume, volume_sampler, in.uvw, 0.0).r, in.from_eye);
    if (c.a < 0.0) {
        discard;
    }
    return c;
}
