// Seed 004's direct mode: no grid at all; each slice fragment evaluates the orbital from its
// basis functions at its own position. Prepended: volume_common.wgsl, gto_common.wgsl.

@fragment
fn fs_direct(in: VertexOut) -> @location(0) vec4<f32> {
    let c = shade(gto_value(in.world), in.from_eye);
    if (c.a < 0.0) {
        discard;
    }
    return c;
}
