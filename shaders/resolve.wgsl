// Copies the floating-point scene buffer (where hundreds of faint slices were blended without
// 8-bit rounding) to the output target. Prepended: fullscreen.wgsl, oit_common.wgsl,
// oit_sort.wgsl.

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(scene, vec2<i32>(pos.xy), 0);
    return vec4<f32>(c.rgb, 1.0);
}

// Translucent surfaces over the scene, in exact depth order (Koide and Miyata, docs/references.md). Prepended:
// oit_common.wgsl, oit_sort.wgsl.

@fragment
fn fs_composite(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<u32>(pos.xy);
    let behind = textureLoad(scene, vec2<i32>(px), 0).rgb;
    let count = gather(px);
    if (count == 0u) {
        return vec4<f32>(behind, 1.0);
    }
    var walk = begin_walk(count);
    for (var i = 0u; i < count; i += 1u) {
        walk = step_walk(walk, i);
    }
    return vec4<f32>(walk.color + walk.through * behind, 1.0);
}

// Weighted blended transparency's resolve: the weighted average colour over what the
// fragments let through (their product of 1 − α).
@group(3) @binding(0) var accum: texture_2d<f32>;
@group(3) @binding(1) var revealage: texture_2d<f32>;

@fragment
fn fs_weighted(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<i32>(pos.xy);
    let behind = textureLoad(scene, px, 0).rgb;
    let sum = textureLoad(accum, px, 0);
    let through = textureLoad(revealage, px, 0).r;
    if (sum.a <= 1e-6) {
        return vec4<f32>(behind, 1.0);
    }
    return vec4<f32>(sum.rgb / sum.a * (1.0 - through) + behind * through, 1.0);
}
