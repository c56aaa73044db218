// Slices sampling the grid's 3D texture. Prepended: volume_common.wgsl, volume_gradient.wgsl,
// volume_field.wgsl.

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    if (clipped(in.world)) {
        discard;
    }
    var grad = vec3<f32>(0.0);
    if (needs_gradient()) {
        grad = field_gradient(in.uvw);
    }
    let c = shade(field(in.uvw), grad, in.from_eye);
    if (c.a < 0.0) {
        discard;
    }
    return c;
}
