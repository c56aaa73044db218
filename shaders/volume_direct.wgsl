// Jang and Varetto's direct mode: no grid at all; each slice fragment evaluates the orbital (and its
// analytic gradient) from its basis functions at its own position.
// Prepended: volume_common.wgsl, gto_common.wgsl.

@fragment
fn fs_direct(in: VertexOut) -> @location(0) vec4<f32> {
    if (clipped(in.world)) {
        discard;
    }
    var v: vec4<f32>;
    if (needs_gradient()) {
        v = gto_value_and_gradient(in.world);
    } else {
        v = vec4<f32>(gto_value(in.world), 0.0, 0.0, 0.0);
    }
    let c = shade(v.x, v.yzw, in.from_eye);
    if (c.a < 0.0) {
        discard;
    }
    return c;
}
