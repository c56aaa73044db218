// Builds the depth pyramid (depth_pyramid_common.wgsl) from the frame's depth: one invocation
// per tile, then one per block.

@group(0) @binding(0) var depth: texture_depth_2d;
@group(0) @binding(1) var<storage, read_write> pyramid: array<f32>;
@group(0) @binding(2) var<uniform> size: PyramidSize;

@compute @workgroup_size(64)
fn cs_tiles(@builtin(global_invocation_id) gid: vec3<u32>) {
    let frame = vec2<i32>(size.frame.xy);
    let t = pyramid_tiles(frame);
    let k = i32(gid.x);
    if (k >= t.x * t.y) {
        return;
    }
    let lo = vec2<i32>(k % t.x, k / t.x) * PYRAMID_TILE;
    let hi = min(lo + PYRAMID_TILE, frame);
    var far = 0.0;
    for (var y = lo.y; y < hi.y; y++) {
        for (var x = lo.x; x < hi.x; x++) {
            far = max(far, textureLoad(depth, vec2<i32>(x, y), 0));
        }
    }
    pyramid[k] = far;
}

@compute @workgroup_size(64)
fn cs_blocks(@builtin(global_invocation_id) gid: vec3<u32>) {
    let frame = vec2<i32>(size.frame.xy);
    let t = pyramid_tiles(frame);
    let b = pyramid_blocks(frame);
    let k = i32(gid.x);
    if (k >= b.x * b.y) {
        return;
    }
    let lo = vec2<i32>(k % b.x, k / b.x) * PYRAMID_BLOCK;
    let hi = min(lo + PYRAMID_BLOCK, t);
    var far = 0.0;
    for (var y = lo.y; y < hi.y; y++) {
        for (var x = lo.x; x < hi.x; x++) {
            far = max(far, pyramid[y * t.x + x]);
        }
    }
    pyramid[pyramid_blocks_at(frame) + k] = far;
}
