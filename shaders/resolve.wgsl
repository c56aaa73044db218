// Copies the floating-point scene buffer (where hundreds of faint slices were blended without
// 8-bit rounding) to the output target.

@group(0) @binding(0) var scene: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the screen.
    let x = f32((vi << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(vi & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(scene, vec2<i32>(pos.xy), 0);
    return vec4<f32>(c.rgb, 1.0);
}

// Translucent surfaces over the scene, in exact depth order (seed 003). Prepended:
// oit_common.wgsl.

struct SurfaceOptics {
    // rgb: diffuse a; w: the specular exponent n.
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
    d: vec4<f32>,
    f: vec4<f32>,
    g: vec4<f32>,
    glow_d: vec4<f32>,
    glow_f: vec4<f32>,
    glow_g: vec4<f32>,
    // xy: the surfaces of the same object (bits); a surface glows inside any other.
    same_object: vec4<u32>,
};

@group(1) @binding(0) var<uniform> lists: ListInfo;
@group(1) @binding(1) var<storage, read> heads: array<u32>;
@group(1) @binding(2) var<storage, read> nodes: array<FragmentNode>;
@group(1) @binding(3) var<uniform> optics: array<SurfaceOptics, 64>;
@group(1) @binding(4) var<storage, read_write> deep_pixels: atomic<u32>;

// Fragments sorted per pixel; a pixel with more keeps its nearest and is counted.
const MAX_DEPTH_COMPLEXITY: u32 = 48u;
const MIN_N_DOT_V: f32 = 0.01;

fn surface_bit(surface: u32) -> vec2<u32> {
    return select(vec2<u32>(1u << surface, 0u), vec2<u32>(0u, 1u << (surface - 32u)), surface >= 32u);
}

// Front to back: nearer first, ties by surface (scene::translucency::sort_fragments).
fn before(depth_a: f32, surface_a: u32, depth_b: f32, surface_b: u32) -> bool {
    return depth_a < depth_b || (depth_a == depth_b && surface_a < surface_b);
}

@fragment
fn fs_composite(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<u32>(pos.xy);
    let behind = textureLoad(scene, vec2<i32>(px), 0).rgb;
    var order: array<u32, MAX_DEPTH_COMPLEXITY>;
    var depth: array<f32, MAX_DEPTH_COMPLEXITY>;
    var surface: array<u32, MAX_DEPTH_COMPLEXITY>;
    var count = 0u;
    var total = 0u;
    var link = heads[px.y * lists.width + px.x];
    // Insertion sort that keeps the nearest MAX_DEPTH_COMPLEXITY.
    loop {
        if (link == 0u || link > lists.capacity) {
            break;
        }
        let node = nodes[link - 1u];
        total += 1u;
        let s = node_surface(node);
        var k = count;
        if (count == MAX_DEPTH_COMPLEXITY) {
            if (!before(node.depth, s, depth[count - 1u], surface[count - 1u])) {
                link = node.next;
                continue;
            }
            k = count - 1u;
        } else {
            count += 1u;
        }
        while (k > 0u && before(node.depth, s, depth[k - 1u], surface[k - 1u])) {
            order[k] = order[k - 1u];
            depth[k] = depth[k - 1u];
            surface[k] = surface[k - 1u];
            k -= 1u;
        }
        order[k] = link - 1u;
        depth[k] = node.depth;
        surface[k] = s;
        link = node.next;
    }
    if (total > count) {
        atomicAdd(&deep_pixels, 1u);
    }
    if (count == 0u) {
        return vec4<f32>(behind, 1.0);
    }
    // A surface whose first fragment faces away encloses the eye.
    var seen = vec2<u32>(0u);
    var inside = vec2<u32>(0u);
    for (var i = 0u; i < count; i += 1u) {
        let bit = surface_bit(surface[i]);
        if (all((seen & bit) == vec2<u32>(0u))) {
            seen |= bit;
            if (unpack2x16float(nodes[order[i]].cosines).x < 0.0) {
                inside |= bit;
            }
        }
    }
    var color = vec3<f32>(0.0);
    var through = vec3<f32>(1.0);
    for (var i = 0u; i < count; i += 1u) {
        let node = nodes[order[i]];
        let s = surface[i];
        let o = optics[s];
        let cosines = unpack2x16float(node.cosines);
        let n_dot_v = cosines.x;
        let n_dot_l = cosines.y;
        let r_dot_v = unpack2x16float(node.highlight_surface & 0xffffu).x;
        let glow = any((inside & ~o.same_object.xy) != vec2<u32>(0u));
        let d = select(o.d.rgb, o.glow_d.rgb, glow);
        let f = select(o.f.rgb, o.glow_f.rgb, glow);
        let g = select(o.g.rgb, o.glow_g.rgb, glow);
        let cos_v = max(abs(n_dot_v), MIN_N_DOT_V);
        var lum = d / (1.0 + f * cos_v);
        if (n_dot_l > 0.0 && n_dot_v > 0.0) {
            let highlight = pow(max(r_dot_v, 0.0), o.a.w);
            lum += o.a.rgb * n_dot_l + o.b.rgb / (1.0 + o.c.rgb * n_dot_v) * highlight;
        }
        color += through * lum;
        through *= exp(-g / cos_v);
        let bit = surface_bit(s);
        if (n_dot_v > 0.0) {
            inside |= bit;
        } else {
            inside &= ~bit;
        }
    }
    return vec4<f32>(color + through * behind, 1.0);
}
