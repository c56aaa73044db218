// A full-screen pass over the frame's float colour (group 1): one triangle that covers the
// screen. Prepended to the resolve (resolve.wgsl) and a cloud's resolve with translucent
// surfaces (volume_interleave.wgsl).

@group(1) @binding(0) var scene: texture_2d<f32>;

@vertex
fn vs_fullscreen(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let x = f32((vi << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(vi & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}
