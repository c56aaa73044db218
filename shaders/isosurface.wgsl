// Opaque isosurfaces: a triangle mesh per surface, lit with the field's gradient as the normal,
// writing colour, depth and the surface's pick id.

struct SurfaceUniforms {
    clip_from_world: mat4x4<f32>,
    // xyz: eye position (bohr)
    eye: vec4<f32>,
    // xyz: unit direction towards the light
    light: vec4<f32>,
    // rgb: linear colour
    color: vec4<f32>,
    // x: pick id
    pick: vec4<u32>,
    // The object's clipping plane (xyz: unit normal, w: distance): points p with
    // dot(xyz, p) > w are cut away; (0, 0, 0, 1e30) cuts nothing.
    cut: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: SurfaceUniforms;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    // linear RGB times the surface's colour (white where the surface has one colour)
    @location(2) tint: vec3<f32>,
};

@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>, @location(2) tint: vec3<f32>) -> VertexOut {
    var out: VertexOut;
    out.clip = u.clip_from_world * vec4<f32>(position, 1.0);
    out.world = position;
    out.normal = normal;
    out.tint = tint;
    return out;
}

struct FragOut {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
};

// Whether the clipping plane cuts `p` (object frame) away.
fn cut_away(p: vec3<f32>) -> bool {
    return dot(u.cut.xyz, p) > u.cut.w;
}

@fragment
fn fs_main(in: VertexOut) -> FragOut {
    if (cut_away(in.world)) {
        discard;
    }
    var out: FragOut;
    out.color = vec4<f32>(lit(in.world, in.normal, in.tint), 1.0);
    out.id = u.pick.x;
    return out;
}

// The surface's colour (times `tint`) at `world` with normal `normal`: headlight diffuse,
// specular and rim.
fn lit(world: vec3<f32>, normal: vec3<f32>, tint: vec3<f32>) -> vec3<f32> {
    let view = normalize(u.eye.xyz - world);
    var n = normalize(normal);
    // A surface cut open by the grid's box or the clipping plane shows its inside: light that
    // side too, a little darker so the cut reads as one.
    var inner = 1.0;
    if (dot(n, view) < 0.0) {
        n = -n;
        inner = 0.6;
    }
    return shade(n, view, tint, 1.0) * inner;
}

// Headlight diffuse, specular (times `highlight`) and rim of the surface's colour times `tint`,
// with unit normal `n` and unit direction to the eye `view`.
fn shade(n: vec3<f32>, view: vec3<f32>, tint: vec3<f32>, highlight: f32) -> vec3<f32> {
    let l = u.light.xyz;
    let diffuse = max(dot(n, l), 0.0);
    let h = normalize(l + view);
    let specular = pow(max(dot(n, h), 0.0), 40.0) * highlight;
    let rim = pow(1.0 - max(dot(n, view), 0.0), 3.0);
    return u.color.rgb * tint * (0.25 + 0.75 * diffuse) + vec3<f32>(0.3 * specular + 0.06 * rim);
}

// Lee et al.'s points: a cell of the surface too small on screen to be worth its triangles,
// drawn as a disc at the cell's centre, lit with the cell's mean normal (`lit_spread`). The
// disc lies across that normal (a surfel: seen edge-on at a silhouette it narrows instead of
// spilling past it, and neighbours overlap in depth as the surface does), turned towards the
// eye by SURFEL_TILT so that no disc is seen exactly edge-on, and big enough that neighbours
// overlap (no holes). A cell whose normals spread too far for a mean faces the eye.
const SURFEL_TILT: f32 = 0.5;

struct SplatOut {
    @builtin(position) clip: vec4<f32>,
    // −1..1 across the disc
    @location(0) corner: vec2<f32>,
    @location(1) world: vec3<f32>,
    @location(2) normal: vec3<f32>,
    @location(3) tint: vec3<f32>,
    // the point of the disc (the clipping plane cuts discs per pixel)
    @location(4) point: vec3<f32>,
};

@vertex
fn vs_splat(
    @builtin(vertex_index) vertex: u32,
    @location(0) centre: vec3<f32>,
    @location(1) radius: f32,
    @location(2) normal: vec3<f32>,
    @location(3) tint: vec3<f32>,
) -> SplatOut {
    // A triangle strip: (−1, −1), (1, −1), (−1, 1), (1, 1).
    let corner = vec2<f32>(f32(vertex & 1u) * 2.0 - 1.0, f32(vertex >> 1u) * 2.0 - 1.0);
    var out: SplatOut;
    let v = normalize(u.eye.xyz - centre);
    let flat = length(normal);
    var facing = v;
    if (flat > 1e-3) {
        facing = normalize(normal / flat + SURFEL_TILT * v);
    }
    var t1 = cross(facing, vec3<f32>(0.0, 1.0, 0.0));
    if (dot(t1, t1) < 1e-6) {
        t1 = cross(facing, vec3<f32>(1.0, 0.0, 0.0));
    }
    t1 = normalize(t1);
    let t2 = cross(facing, t1);
    let world = centre + radius * (corner.x * t1 + corner.y * t2);
    out.clip = u.clip_from_world * vec4<f32>(world, 1.0);
    out.corner = corner;
    out.world = centre;
    out.normal = normal;
    out.tint = tint;
    out.point = world;
    return out;
}

@fragment
fn fs_splat(in: SplatOut) -> FragOut {
    if (dot(in.corner, in.corner) > 1.0 || cut_away(in.point)) {
        discard;
    }
    var out: FragOut;
    out.color = vec4<f32>(lit_spread(in.world, in.normal, in.tint), 1.0);
    out.id = u.pick.x;
    return out;
}

// `lit` for a cell whose unit normals spread around their mean `mean` (shorter than 1 the more
// they spread): lit with the mean's direction, but its highlight covers only part of a spread
// cell (the share of a cap of half-angle θ, cos θ = 2|mean| − 1, that a lobe of about 0.22 rad
// covers). Diffuse light from the shortened mean measured darker than the triangles.
fn lit_spread(world: vec3<f32>, mean: vec3<f32>, tint: vec3<f32>) -> vec3<f32> {
    let flat = clamp(length(mean), 1e-4, 1.0);
    let theta = acos(clamp(2.0 * flat - 1.0, -1.0, 1.0));
    let share = min(1.0, pow(0.22 / max(theta, 1e-3), 2.0));
    return shade(mean / flat, normalize(u.eye.xyz - world), tint, share);
}

// Translucent surfaces: every fragment in front of the opaque scene is appended to its
// pixel's list (resolve.wgsl sorts and composites them). Prepended: oit_common.wgsl.

@group(1) @binding(0) var<uniform> lists: ListInfo;
@group(1) @binding(1) var<storage, read_write> heads: array<atomic<u32>>;
@group(1) @binding(2) var<storage, read_write> nodes: array<FragmentNode>;
@group(1) @binding(3) var<storage, read_write> counter: atomic<u32>;
@group(1) @binding(4) var opaque_depth: texture_depth_2d;

// Whether the opaque scene hides this fragment. The translucent programs write storage, so
// the hardware depth test cannot run before them: they test here.
fn behind_opaque(in: VertexOut) -> bool {
    return in.clip.z >= textureLoad(opaque_depth, vec2<u32>(in.clip.xy), 0);
}

// N·L, N·V and R·V (R = 2(N·L)N − L, the reflected light) of a fragment.
fn cosines(in: VertexOut) -> vec3<f32> {
    let v = normalize(u.eye.xyz - in.world);
    let n = normalize(in.normal);
    let l = u.light.xyz;
    let n_dot_l = dot(n, l);
    let n_dot_v = dot(n, v);
    return vec3<f32>(n_dot_l, n_dot_v, 2.0 * n_dot_l * n_dot_v - dot(l, v));
}

@fragment
fn fs_collect(in: VertexOut) {
    if (behind_opaque(in) || cut_away(in.world)) {
        return;
    }
    let px = vec2<u32>(in.clip.xy);
    let c = cosines(in);
    let index = atomicAdd(&counter, 1u);
    if (index >= lists.capacity) {
        // Counted: the frame is drawn again in bands that fit.
        return;
    }
    let previous = atomicExchange(&heads[px.y * lists.width + px.x], index + 1u);
    nodes[index] = FragmentNode(
        in.clip.z,
        pack2x16float(vec2<f32>(c.y, c.x)),
        (pack2x16float(vec2<f32>(c.z, 0.0)) & 0xffffu) | (u.pick.y << 16u),
        previous,
    );
}

// Weighted blended transparency (McGuire & Bavoil 2013), kept to measure what exact order
// buys: one pass, no lists, colours averaged with depth weights; no order, hence no glow.
@group(1) @binding(5) var<uniform> optics: array<SurfaceOptics, 64>;

struct Weighted {
    @location(0) accum: vec4<f32>,
    @location(1) revealage: vec4<f32>,
};

@fragment
fn fs_weighted(in: VertexOut) -> Weighted {
    if (behind_opaque(in) || cut_away(in.world)) {
        discard;
    }
    let c = cosines(in);
    let shaded = koide(optics[u.pick.y], c.x, c.y, c.z, false);
    let alpha = clamp(1.0 - dot(shaded.transmission, vec3<f32>(1.0 / 3.0)), 0.0, 1.0);
    // Their weight of equation 10, on window depth.
    let near = 1.0 - in.clip.z;
    let w = clamp(alpha * 3e3 * near * near * near, 1e-2, 3e3);
    return Weighted(vec4<f32>(shaded.luminance * w, alpha * w), vec4<f32>(alpha));
}
