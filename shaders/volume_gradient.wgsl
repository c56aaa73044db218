// The gradient of the sampled field by central differences one texel apart, in world units
// (uvw = M p + t, so the world gradient is Mᵀ times the texture gradient). The module that
// prepends this defines `field(uvw) -> f32`. Prepended: volume_common.wgsl.

fn field_gradient(uvw: vec3<f32>) -> vec3<f32> {
    let h = 1.0 / vec3<f32>(textureDimensions(volume));
    let dx = vec3<f32>(h.x, 0.0, 0.0);
    let dy = vec3<f32>(0.0, h.y, 0.0);
    let dz = vec3<f32>(0.0, 0.0, h.z);
    let g_tex = vec3<f32>(
        (field(uvw + dx) - field(uvw - dx)) / (2.0 * h.x),
        (field(uvw + dy) - field(uvw - dy)) / (2.0 * h.y),
        (field(uvw + dz) - field(uvw - dz)) / (2.0 * h.z),
    );
    return world_gradient(u, g_tex);
}

// Mᵀ g: a texture-space gradient in world units.
fn world_gradient(c: VolumeUniforms, g_tex: vec3<f32>) -> vec3<f32> {
    let m = mat3x3<f32>(c.tex_from_world[0].xyz, c.tex_from_world[1].xyz, c.tex_from_world[2].xyz);
    return transpose(m) * g_tex;
}
