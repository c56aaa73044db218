// Occlusion culling of a big surface's batches (runs of triangles of one octree cluster, chosen
// on the CPU by Lee et al.'s level of detail) in two phases, into indirect draws:
// - cs_split, before drawing: the batches whose cluster was seen last frame are drawn first;
// - cs_cull, after the depth pyramid is built from what the first draws left: every batch whose
//   box the pyramid does not hide is marked seen, and those not drawn yet are drawn next.
// A batch is dropped only where its fragments would fail the depth test everywhere, so the
// picture is the one drawing every batch gives.

struct CullUniforms {
    clip_from_object: mat4x4<f32>,
    // x: batches this frame; y: this frame's number (a cluster seen last frame holds y − 1)
    counts: vec4<u32>,
};

struct Batch {
    lo: vec3<f32>,
    first_index: u32,
    hi: vec3<f32>,
    index_count: u32,
    // x: the cluster (an index into `seen`)
    cluster: vec4<u32>,
};

// Vulkan's and wgpu's indexed indirect draw.
struct DrawArgs {
    index_count: u32,
    instance_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
};

@group(0) @binding(0) var<uniform> cull: CullUniforms;
@group(0) @binding(1) var<storage, read> batches: array<Batch>;
@group(0) @binding(2) var<storage, read_write> seen: array<u32>;
@group(0) @binding(3) var<storage, read_write> early: array<DrawArgs>;
@group(0) @binding(4) var<storage, read_write> late: array<DrawArgs>;
@group(1) @binding(0) var<storage, read> pyramid: array<f32>;
@group(1) @binding(1) var<uniform> size: PyramidSize;
@group(1) @binding(2) var depth: texture_depth_2d;

// The most tiles (then blocks) along a side one test reads; a rectangle wider in blocks is
// taken as visible.
const SPAN: i32 = 8;
const MAX_BLOCKS: i32 = 32;
// A rectangle of at most this many pixels the pyramid does not hide (a tile with a gap in it:
// the background between molecules) is tested pixel by pixel.
const MAX_EXACT_PIXELS: i32 = 1024;

fn draw_of(b: Batch, shown: bool) -> DrawArgs {
    var d = DrawArgs(0u, 0u, 0u, 0, 0u);
    if (shown) {
        d = DrawArgs(b.index_count, 1u, b.first_index, 0, 0u);
    }
    return d;
}

@compute @workgroup_size(64)
fn cs_split(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= cull.counts.x) {
        return;
    }
    let b = batches[i];
    early[i] = draw_of(b, seen[b.cluster.x] + 1u == cull.counts.y);
}

// Whether the pyramid hides the box: every tile (or block) its screen rectangle covers holds
// only depths nearer than the box's nearest corner. A box reaching the eye's plane is shown.
fn hidden(b: Batch) -> bool {
    let frame = vec2<i32>(size.frame.xy);
    var lo_px = vec2<f32>(1e30);
    var hi_px = vec2<f32>(-1e30);
    var near = 1.0;
    for (var k = 0u; k < 8u; k++) {
        let corner = select(b.lo, b.hi, vec3<bool>((k & 1u) != 0u, (k & 2u) != 0u, (k & 4u) != 0u));
        let c = cull.clip_from_object * vec4<f32>(corner, 1.0);
        if (c.w <= 1e-6 || c.z < 0.0) {
            return false;
        }
        let ndc = c.xyz / c.w;
        let px = vec2<f32>((ndc.x + 1.0) * 0.5, (1.0 - ndc.y) * 0.5) * vec2<f32>(frame);
        lo_px = min(lo_px, px);
        hi_px = max(hi_px, px);
        near = min(near, ndc.z);
    }
    let lo = max(vec2<i32>(floor(lo_px)), vec2<i32>(0));
    let hi = min(vec2<i32>(floor(hi_px)), frame - 1);
    if (any(hi < lo)) {
        // Off screen: nothing of it is drawn.
        return true;
    }
    if (coarse_hidden(lo, hi, near)) {
        return true;
    }
    let extent = hi - lo + 1;
    if (extent.x * extent.y > MAX_EXACT_PIXELS) {
        return false;
    }
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            if (textureLoad(depth, vec2<i32>(x, y), 0) >= near) {
                return false;
            }
        }
    }
    return true;
}

// Whether the pyramid's tiles (or, for a wide rectangle, blocks) over the pixels lo..=hi all
// hold only depths nearer than `near`.
fn coarse_hidden(lo: vec2<i32>, hi: vec2<i32>, near: f32) -> bool {
    let frame = vec2<i32>(size.frame.xy);
    var first = lo / PYRAMID_TILE;
    var last = hi / PYRAMID_TILE;
    var at = 0;
    var row = pyramid_tiles(frame).x;
    if (any(last - first >= vec2<i32>(SPAN))) {
        first /= PYRAMID_BLOCK;
        last /= PYRAMID_BLOCK;
        at = pyramid_blocks_at(frame);
        row = pyramid_blocks(frame).x;
        if (any(last - first >= vec2<i32>(MAX_BLOCKS))) {
            return false;
        }
    }
    for (var y = first.y; y <= last.y; y++) {
        for (var x = first.x; x <= last.x; x++) {
            if (pyramid[at + y * row + x] >= near) {
                return false;
            }
        }
    }
    return true;
}

@compute @workgroup_size(64)
fn cs_cull(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= cull.counts.x) {
        return;
    }
    let b = batches[i];
    let shown = !hidden(b);
    if (shown) {
        seen[b.cluster.x] = cull.counts.y;
    }
    late[i] = draw_of(b, shown && early[i].index_count == 0u);
}
