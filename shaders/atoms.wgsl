// Ball-and-stick impostors: camera-facing quads, exact ray–sphere and ray–cylinder
// intersection per fragment, lit, with the true surface depth written.

struct Globals {
    clip_from_world: mat4x4<f32>,
    // xyz: eye position (bohr)
    eye: vec4<f32>,
    // xyz: unit direction towards the light
    light: vec4<f32>,
    // xyz: camera up vector
    up: vec4<f32>,
    // x: high bits of this object's atom pick ids; the atom index is added
    pick: vec4<u32>,
};

@group(0) @binding(0) var<uniform> g: Globals;

const CORNERS = array<vec2<f32>, 6>(
    vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
    vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
);

struct FragOut {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
    @builtin(frag_depth) depth: f32,
};

fn shade(base: vec3<f32>, n: vec3<f32>, view: vec3<f32>) -> vec3<f32> {
    let l = g.light.xyz;
    let diffuse = max(dot(n, l), 0.0);
    let h = normalize(l + view);
    let specular = pow(max(dot(n, h), 0.0), 48.0);
    // A little rim light keeps dark atoms readable on a dark background.
    let rim = pow(1.0 - max(dot(n, view), 0.0), 3.0);
    return base * (0.22 + 0.78 * diffuse) + vec3<f32>(0.35 * specular + 0.08 * rim);
}

fn depth_of(world: vec3<f32>) -> f32 {
    let c = g.clip_from_world * vec4<f32>(world, 1.0);
    return c.z / c.w;
}

// ---- spheres ----

struct SphereOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) center: vec3<f32>,
    @location(2) @interpolate(flat) radius: f32,
    @location(3) @interpolate(flat) color: vec4<f32>,
    @location(4) @interpolate(flat) atom: u32,
};

@vertex
fn vs_sphere(
    @builtin(vertex_index) vi: u32,
    @builtin(instance_index) atom: u32,
    @location(0) center: vec3<f32>,
    @location(1) radius: f32,
    @location(2) color: vec4<f32>,
) -> SphereOut {
    let to_eye = g.eye.xyz - center;
    let dist = max(length(to_eye), radius * 1.01);
    let f = to_eye / dist;
    var right = cross(g.up.xyz, f);
    if (dot(right, right) < 1e-8) {
        right = cross(vec3<f32>(1.0, 0.0, 0.0), f);
    }
    right = normalize(right);
    let up = cross(f, right);
    // Half-size of the silhouette cone's cross-section in the plane through the centre.
    let s = radius * dist / sqrt(dist * dist - radius * radius);
    let c = CORNERS[vi];
    let world = center + (right * c.x + up * c.y) * s;
    var out: SphereOut;
    out.clip = g.clip_from_world * vec4<f32>(world, 1.0);
    out.world = world;
    out.center = center;
    out.radius = radius;
    out.color = color;
    out.atom = atom;
    return out;
}

@fragment
fn fs_sphere(in: SphereOut) -> FragOut {
    let ro = g.eye.xyz;
    let rd = normalize(in.world - ro);
    let oc = ro - in.center;
    let b = dot(oc, rd);
    let c = dot(oc, oc) - in.radius * in.radius;
    let disc = b * b - c;
    if (disc < 0.0) {
        discard;
    }
    let t = -b - sqrt(disc);
    let hit = ro + rd * t;
    let n = normalize(hit - in.center);
    var out: FragOut;
    out.color = vec4<f32>(shade(in.color.rgb, n, -rd), 1.0);
    out.id = g.pick.x | in.atom;
    out.depth = depth_of(hit);
    return out;
}

// ---- cylinders ----

struct CylinderOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) p0: vec3<f32>,
    @location(2) @interpolate(flat) p1: vec3<f32>,
    @location(3) @interpolate(flat) radius: f32,
    @location(4) @interpolate(flat) color: vec4<f32>,
    @location(5) @interpolate(flat) atom: u32,
};

@vertex
fn vs_cylinder(
    @builtin(vertex_index) vi: u32,
    @location(0) p0: vec3<f32>,
    @location(1) radius: f32,
    @location(2) p1: vec3<f32>,
    @location(3) color: vec4<f32>,
    @location(4) atom: u32,
) -> CylinderOut {
    let axis = p1 - p0;
    let len = max(length(axis), 1e-6);
    let a = axis / len;
    let mid = 0.5 * (p0 + p1);
    let to_eye = g.eye.xyz - mid;
    var side = cross(a, to_eye);
    if (dot(side, side) < 1e-10) {
        side = cross(a, g.up.xyz);
    }
    side = normalize(side);
    let dist = max(length(to_eye), radius * 1.01);
    let s = radius * dist / sqrt(dist * dist - radius * radius);
    let c = CORNERS[vi];
    // The quad spans the axis (widened by the radius at both ends) and the silhouette width.
    let along = mix(-radius, len + radius, 0.5 * (c.x + 1.0));
    let world = p0 + a * along + side * (c.y * s);
    var out: CylinderOut;
    out.clip = g.clip_from_world * vec4<f32>(world, 1.0);
    out.world = world;
    out.p0 = p0;
    out.p1 = p1;
    out.radius = radius;
    out.color = color;
    out.atom = atom;
    return out;
}

@fragment
fn fs_cylinder(in: CylinderOut) -> FragOut {
    let ro = g.eye.xyz;
    let rd = normalize(in.world - ro);
    let axis = in.p1 - in.p0;
    let len = length(axis);
    let a = axis / len;
    let oc = ro - in.p0;
    let d_perp = rd - a * dot(rd, a);
    let o_perp = oc - a * dot(oc, a);
    let qa = dot(d_perp, d_perp);
    let qb = dot(d_perp, o_perp);
    let qc = dot(o_perp, o_perp) - in.radius * in.radius;
    let disc = qb * qb - qa * qc;
    if (disc < 0.0 || qa < 1e-12) {
        discard;
    }
    let t = (-qb - sqrt(disc)) / qa;
    let hit = ro + rd * t;
    let h = dot(hit - in.p0, a);
    if (h < 0.0 || h > len) {
        discard;
    }
    let n = normalize(hit - in.p0 - a * h);
    var out: FragOut;
    out.color = vec4<f32>(shade(in.color.rgb, n, -rd), 1.0);
    out.id = g.pick.x | in.atom;
    out.depth = depth_of(hit);
    return out;
}
