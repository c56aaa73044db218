// Slices sampling the grid's 3D texture, a slab of planes per fragment (volume_slab.wgsl).
// Prepended: volume_common.wgsl, volume_gradient.wgsl, volume_field.wgsl, volume_slab.wgsl.

@fragment
fn fs_main(in: SlabOut) -> @location(0) vec4<f32> {
    // Read once: the uniforms handed by value to a function called per sample would be loaded
    // whole per call.
    let c = u;
    let samples = slab_samples(in);
    var acc = vec4<f32>(0.0);
    for (var j = 0u; j < SLAB; j += 1u) {
        let uvw = in.uvw + in.step_uvw * f32(j);
        var grad = vec3<f32>(0.0);
        if (needs_gradient()) {
            grad = field_gradient(uvw);
        }
        // The direction from the eye is the fragment's for every sample (so is what depends on
        // it alone, which the compiler takes out of the loop).
        let s = shade_with(c, FIELD, SHAPED, GRADIENT, field(uvw), grad, in.from_eye);
        acc = behind(acc, s.rgb, s.a, slab_takes(in, samples, j) && s.a >= 0.0);
    }
    // Nothing to add: no read-modify-write of the frame buffer.
    if (acc.a <= 0.0) {
        discard;
    }
    return acc;
}
