// Each pixel's fragment list gathered, sorted front to back and walked (Koide and Miyata, docs/references.md): shared by
// the resolve (resolve.wgsl) and a cloud the surfaces run through (volume_interleave.wgsl).
// Prepended: oit_common.wgsl.

@group(2) @binding(0) var<uniform> lists: ListInfo;
@group(2) @binding(1) var<storage, read> heads: array<u32>;
@group(2) @binding(2) var<storage, read> nodes: array<FragmentNode>;
@group(2) @binding(3) var<uniform> optics: array<SurfaceOptics, 64>;
@group(2) @binding(4) var<storage, read_write> deep_pixels: atomic<u32>;
@group(2) @binding(5) var opaque_depth: texture_depth_2d;

// Fragments sorted per pixel; a pixel with more keeps its nearest and is counted.
const MAX_DEPTH_COMPLEXITY: u32 = 48u;

var<private> order: array<u32, MAX_DEPTH_COMPLEXITY>;
var<private> sorted_depth: array<f32, MAX_DEPTH_COMPLEXITY>;
var<private> sorted_surface: array<u32, MAX_DEPTH_COMPLEXITY>;

fn surface_bit(surface: u32) -> vec2<u32> {
    return select(vec2<u32>(1u << surface, 0u), vec2<u32>(0u, 1u << (surface - 32u)), surface >= 32u);
}

// Front to back: nearer first, ties by surface (scene::translucency::sort_fragments).
fn before(depth_a: f32, surface_a: u32, depth_b: f32, surface_b: u32) -> bool {
    return depth_a < depth_b || (depth_a == depth_b && surface_a < surface_b);
}

// Sorts the pixel's fragments into the private arrays (insertion sort keeping the nearest
// MAX_DEPTH_COMPLEXITY); returns how many.
fn gather(px: vec2<u32>) -> u32 {
    var count = 0u;
    var total = 0u;
    var link = heads[px.y * lists.width + px.x];
    loop {
        if (link == 0u || link > lists.capacity) {
            break;
        }
        let node = nodes[link - 1u];
        total += 1u;
        let s = node_surface(node);
        var k = count;
        if (count == MAX_DEPTH_COMPLEXITY) {
            if (!before(node.depth, s, sorted_depth[count - 1u], sorted_surface[count - 1u])) {
                link = node.next;
                continue;
            }
            k = count - 1u;
        } else {
            count += 1u;
        }
        while (k > 0u && before(node.depth, s, sorted_depth[k - 1u], sorted_surface[k - 1u])) {
            order[k] = order[k - 1u];
            sorted_depth[k] = sorted_depth[k - 1u];
            sorted_surface[k] = sorted_surface[k - 1u];
            k -= 1u;
        }
        order[k] = link - 1u;
        sorted_depth[k] = node.depth;
        sorted_surface[k] = s;
        link = node.next;
    }
    if (total > count) {
        atomicAdd(&deep_pixels, 1u);
    }
    return count;
}

// The walk front to back: what is composited so far, what gets through, and which surfaces
// enclose the ray here.
struct Walk {
    color: vec3<f32>,
    through: vec3<f32>,
    inside: vec2<u32>,
    // The transmission of the last fragment composited.
    last: vec3<f32>,
};

// A surface whose first fragment faces away encloses the eye.
fn begin_walk(count: u32) -> Walk {
    var seen = vec2<u32>(0u);
    var inside = vec2<u32>(0u);
    for (var i = 0u; i < count; i += 1u) {
        let bit = surface_bit(sorted_surface[i]);
        if (all((seen & bit) == vec2<u32>(0u))) {
            seen |= bit;
            if (unpack2x16float(nodes[order[i]].cosines).x < 0.0) {
                inside |= bit;
            }
        }
    }
    return Walk(vec3<f32>(0.0), vec3<f32>(1.0), inside, vec3<f32>(1.0));
}

// Composites sorted fragment i behind what the walk holds; a front face enters its surface,
// a back face leaves it, and a fragment inside another object's surface glows.
fn step_walk(walk: Walk, i: u32) -> Walk {
    let node = nodes[order[i]];
    let s = sorted_surface[i];
    let o = optics[s];
    let cosines = unpack2x16float(node.cosines);
    let r_dot_v = unpack2x16float(node.highlight_surface & 0xffffu).x;
    let glow = any((walk.inside & ~o.same_object.xy) != vec2<u32>(0u));
    let shaded = koide(o, cosines.y, cosines.x, r_dot_v, glow);
    var out = walk;
    out.color += walk.through * shaded.luminance;
    out.through *= shaded.transmission;
    out.last = shaded.transmission;
    let bit = surface_bit(s);
    out.inside = select(walk.inside & ~bit, walk.inside | bit, cosines.x > 0.0);
    return out;
}
