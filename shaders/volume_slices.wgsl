// Slices sampling the grid's 3D texture. Prepended: volume_common.wgsl.

fn sample_at(uvw: vec3<f32>) -> f32 {
    return textureSampleLevel(volume, volume_sampler, uvw, 0.0).r;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    if (clipped(in.world)) {
        discard;
    }
    let value = sample_at(in.uvw);
    var grad = vec3<f32>(0.0);
    if (needs_gradient()) {
        // Central differences one texel apart, then from texture to world coordinates
        // (uvw = M p + t, so the world gradient is Mᵀ times the texture gradient).
        let h = 1.0 / vec3<f32>(textureDimensions(volume));
        let dx = vec3<f32>(h.x, 0.0, 0.0);
        let dy = vec3<f32>(0.0, h.y, 0.0);
        let dz = vec3<f32>(0.0, 0.0, h.z);
        let g_tex = vec3<f32>(
            (sample_at(in.uvw + dx) - sample_at(in.uvw - dx)) / (2.0 * h.x),
            (sample_at(in.uvw + dy) - sample_at(in.uvw - dy)) / (2.0 * h.y),
            (sample_at(in.uvw + dz) - sample_at(in.uvw - dz)) / (2.0 * h.z),
        );
        let m = mat3x3<f32>(u.tex_from_world[0].xyz, u.tex_from_world[1].xyz, u.tex_from_world[2].xyz);
        grad = transpose(m) * g_tex;
    }
    let c = shade(value, grad, in.from_eye);
    if (c.a < 0.0) {
        discard;
    }
    return c;
}
