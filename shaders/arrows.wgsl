// Arrows as impostors (a normal mode's displacements): each arrow's box is rasterised, and each
// fragment meets its eye ray with the arrow's shaft (a cylinder closed at its foot) and head (a
// cone on a disc), writing the lit colour and a depth in front of everything else.
// model::arrow::Arrow::hit is the CPU reference of `hit_arrow`.

// An arrow's depth is its true depth scaled into [0, IN_FRONT): arrows still hide one another
// in their true order, but nothing else hides them. They are what a chemist playing a mode
// looks at, and a cloud or a translucent surface around the molecule would otherwise veil them
// (clouds stop and translucent fragments are dropped at the opaque depth).
const IN_FRONT: f32 = 1e-3;

struct ArrowUniforms {
    clip_from_object: mat4x4<f32>,
    // xyz: the eye (object frame)
    eye: vec4<f32>,
    // xyz: unit direction towards the light
    light: vec4<f32>,
    // rgb: linear colour
    color: vec4<f32>,
};

struct Arrow {
    start: vec3<f32>,
    shaft_radius: f32,
    to: vec3<f32>,
    head_radius: f32,
    head_length: f32,
    pad0: f32,
    pad1: f32,
    pad2: f32,
};

@group(0) @binding(0) var<uniform> u: ArrowUniforms;
@group(0) @binding(1) var<storage, read> arrows: array<Arrow>;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) object: vec3<f32>,
    @location(1) @interpolate(flat) index: u32,
};

// The arrow's frame: x, y across it, z along it from `start` to `to`.
fn frame(a: Arrow) -> mat3x3<f32> {
    let z = normalize(a.to - a.start);
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(z.x) > 0.9);
    let x = normalize(cross(helper, z));
    return mat3x3<f32>(x, cross(z, x), z);
}

// The 12 triangles of a box, as corner numbers (bit 0: x, bit 1: y, bit 2: z).
const BOX = array<u32, 36>(
    0u, 2u, 1u, 1u, 2u, 3u, 4u, 5u, 6u, 5u, 7u, 6u,
    0u, 1u, 4u, 1u, 5u, 4u, 2u, 6u, 3u, 3u, 6u, 7u,
    0u, 4u, 2u, 2u, 4u, 6u, 1u, 3u, 5u, 3u, 7u, 5u,
);

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) k: u32) -> VertexOut {
    let a = arrows[k];
    let f = frame(a);
    let r = max(a.shaft_radius, a.head_radius);
    let c = BOX[vi];
    let corner = vec3<f32>(f32(c & 1u), f32((c >> 1u) & 1u), f32((c >> 2u) & 1u));
    let p = a.start + f[0] * (corner.x * 2.0 - 1.0) * r + f[1] * (corner.y * 2.0 - 1.0) * r
        + (a.to - a.start) * corner.z;
    var out: VertexOut;
    out.clip = u.clip_from_object * vec4<f32>(p, 1.0);
    out.object = p;
    out.index = k;
    return out;
}

// The nearest hit in front of `o` along unit `d`: (t, normal) in the arrow's frame, t < 0 when
// the ray misses.
fn hit_arrow(a: Arrow, o: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    let length = distance(a.start, a.to);
    let neck = length - a.head_length;
    var best = vec4<f32>(-1.0, 0.0, 0.0, 0.0);
    // The shaft's side.
    let r = a.shaft_radius;
    let qa = d.x * d.x + d.y * d.y;
    let qb = 2.0 * (o.x * d.x + o.y * d.y);
    let qc = o.x * o.x + o.y * o.y - r * r;
    let disc = qb * qb - 4.0 * qa * qc;
    if (qa > 1e-12 && disc >= 0.0) {
        for (var s = -1.0; s <= 1.0; s += 2.0) {
            let t = (-qb + s * sqrt(disc)) / (2.0 * qa);
            let p = o + d * t;
            if (t > 0.0 && p.z >= 0.0 && p.z <= neck && (best.x < 0.0 || t < best.x)) {
                best = vec4<f32>(t, p.x / r, p.y / r, 0.0);
            }
        }
    }
    // The head's side: x² + y² = k²(L − z)².
    let k = a.head_radius / max(a.head_length, 1e-6);
    let k2 = k * k;
    let w = length - o.z;
    let ca = d.x * d.x + d.y * d.y - k2 * d.z * d.z;
    let cb = 2.0 * (o.x * d.x + o.y * d.y + k2 * w * d.z);
    let cc = o.x * o.x + o.y * o.y - k2 * w * w;
    let cdisc = cb * cb - 4.0 * ca * cc;
    if (abs(ca) > 1e-12 && cdisc >= 0.0) {
        for (var s = -1.0; s <= 1.0; s += 2.0) {
            let t = (-cb + s * sqrt(cdisc)) / (2.0 * ca);
            let p = o + d * t;
            if (t > 0.0 && p.z >= neck && p.z <= length && (best.x < 0.0 || t < best.x)) {
                best = vec4<f32>(t, normalize(vec3<f32>(p.x, p.y, k2 * (length - p.z))));
            }
        }
    }
    // The discs closing the shaft's foot and the head's base.
    if (abs(d.z) > 1e-12) {
        for (var i = 0; i < 2; i++) {
            let h = select(0.0, neck, i == 1);
            let radius = select(r, a.head_radius, i == 1);
            let t = (h - o.z) / d.z;
            let p = o + d * t;
            if (t > 0.0 && p.x * p.x + p.y * p.y <= radius * radius && (best.x < 0.0 || t < best.x)) {
                best = vec4<f32>(t, 0.0, 0.0, -1.0);
            }
        }
    }
    return best;
}

struct FragOut {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
    @builtin(frag_depth) depth: f32,
};

@fragment
fn fs_main(in: VertexOut) -> FragOut {
    let a = arrows[in.index];
    let f = frame(a);
    let eye = u.eye.xyz;
    let dir = normalize(in.object - eye);
    // The ray in the arrow's frame (the frame is orthonormal: its transpose inverts it).
    let to_local = transpose(f);
    let hit = hit_arrow(a, to_local * (eye - a.start), to_local * dir);
    if (hit.x < 0.0) {
        discard;
    }
    let p = eye + dir * hit.x;
    let n = normalize(f * hit.yzw);
    let clip = u.clip_from_object * vec4<f32>(p, 1.0);
    let l = u.light.xyz;
    let view = -dir;
    let diffuse = max(dot(n, l), 0.0);
    let specular = pow(max(dot(reflect(-l, n), view), 0.0), 32.0);
    var out: FragOut;
    out.color = vec4<f32>(u.color.rgb * (0.25 + 0.75 * diffuse) + vec3<f32>(0.35 * specular), 1.0);
    // An arrow is an annotation: nothing to pick.
    out.id = 0u;
    out.depth = IN_FRONT * clip.z / clip.w;
    return out;
}
