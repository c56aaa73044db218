// Atoms drawn from storage buffers: spheres and cylinders too big for the compute rasteriser
// as camera-facing quads with exact ray intersection and depth (instances from the lists
// atoms_cull.wgsl made), the small spheres it rasterised resolved to colour, id and depth in
// one full-screen pass, and bonds as lines in the lines style.

@group(1) @binding(0) var<storage, read> lists: array<u32>;
@group(1) @binding(1) var<storage, read> splat: array<u32>;

const CORNERS = array<vec2<f32>, 6>(
    vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
    vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
);

struct FragOut {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
    @builtin(frag_depth) depth: f32,
};

// QuteMol's depth cue: darker with depth across the molecule, so front reads from back.
fn cued(color: vec3<f32>, world: vec3<f32>) -> vec3<f32> {
    if (g.cue.z <= 0.0) {
        return color;
    }
    let w = (g.clip_from_world * vec4<f32>(world, 1.0)).w;
    let f = clamp((w - g.cue.x) / max(g.cue.y - g.cue.x, 1e-6), 0.0, 1.0);
    return color * (1.0 - g.cue.z * f);
}

fn shade(base: vec3<f32>, n: vec3<f32>, view: vec3<f32>) -> vec3<f32> {
    let l = g.light.xyz;
    let diffuse = max(dot(n, l), 0.0);
    let h = normalize(l + view);
    let specular = pow(max(dot(n, h), 0.0), 48.0);
    // A little rim light keeps dark atoms readable on a dark background.
    let rim = pow(1.0 - max(dot(n, view), 0.0), 3.0);
    return base * (0.22 + 0.78 * diffuse) + vec3<f32>(0.35 * specular + 0.08 * rim);
}

// The lit sphere of atom i where the ray eye + t·d hits it first.
fn sphere_fragment(i: u32, d: vec3<f32>, t: f32) -> FragOut {
    let center = positions[i].xyz;
    let hit = g.eye.xyz + d * t;
    let n = normalize(hit - center);
    var out: FragOut;
    out.color = vec4<f32>(cued(shade(color_of(i), n, -normalize(d)), hit), 1.0);
    out.id = g.pick.x | i;
    out.depth = depth_of(hit);
    return out;
}

// ---- spheres as quads ----

struct SphereOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) atom: u32,
};

@vertex
fn vs_sphere(@builtin(vertex_index) vi: u32, @builtin(instance_index) k: u32) -> SphereOut {
    let atom = lists[LISTS + k];
    let center = positions[atom].xyz;
    let radius = radius_of(atom);
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
    out.atom = atom;
    return out;
}

@fragment
fn fs_sphere(in: SphereOut) -> FragOut {
    let d = in.world - g.eye.xyz;
    let centre = positions[in.atom].xyz;
    let radius = radius_of(in.atom);
    let t = hit_sphere(d, centre, radius);
    if (t < 0.0) {
        discard;
    }
    if (beyond_cut(g.eye.xyz + d * t) > 0.0) {
        // Cut away where the ray enters: the cut face, where the ray crosses the plane inside.
        let p = g.eye.xyz + d * cut_crossing(d);
        if (dot(g.cut.xyz, d) >= 0.0 || distance(p, centre) > radius) {
            discard;
        }
        return cut_face(in.atom, d, p);
    }
    return sphere_fragment(in.atom, d, t);
}

// The ray parameter where the ray eye + t·d crosses the clipping plane.
fn cut_crossing(d: vec3<f32>) -> f32 {
    return (g.cut.w - dot(g.cut.xyz, g.eye.xyz)) / dot(g.cut.xyz, d);
}

// The flat face the clipping plane leaves of atom i's sphere or half-bond, at `p`.
fn cut_face(i: u32, d: vec3<f32>, p: vec3<f32>) -> FragOut {
    var out: FragOut;
    out.color = vec4<f32>(cued(shade(color_of(i), g.cut.xyz, -normalize(d)), p), 1.0);
    out.id = g.pick.x | i;
    out.depth = depth_of(p);
    return out;
}

// ---- spheres the compute rasteriser drew ----

@vertex
fn vs_fullscreen(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let p = vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u));
    return vec4<f32>(p * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_splats(@builtin(position) frag: vec4<f32>) -> FragOut {
    let w = u32(g.viewport.x);
    let pixel = u32(frag.y) * w + u32(frag.x);
    // Packed pixels are 64-bit words, id low; else the ids follow the depth keys.
    let id = select(splat[u32(g.viewport.x) * u32(g.viewport.y) + pixel], splat[2u * pixel], g.pick.y != 0u);
    if (id == 0u) {
        discard;
    }
    let i = id - 1u;
    let d = ray_through(frag.xy);
    // The rasteriser kept only pixels whose ray hits; rounding may still miss by a hair.
    let t = max(hit_sphere(d, positions[i].xyz, splat_radius(i)), 0.0);
    var out = sphere_fragment(i, d, t);
    if (t == 0.0) {
        out.depth = depth_of(positions[i].xyz);
    }
    return out;
}

// ---- bonds as cylinders, one instance per bond, each half in its atom's colour ----

struct CylinderOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) atoms: vec2<u32>,
};

@vertex
fn vs_cylinder(@builtin(vertex_index) vi: u32, @builtin(instance_index) k: u32) -> CylinderOut {
    let bond = bonds[lists[LISTS + g.counts.x + k]];
    let p0 = positions[bond.x].xyz;
    let p1 = positions[bond.y].xyz;
    let radius = g.sticks.x;
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
    out.atoms = bond;
    return out;
}

@fragment
fn fs_cylinder(in: CylinderOut) -> FragOut {
    let ro = g.eye.xyz;
    let rd = normalize(in.world - ro);
    let p0 = positions[in.atoms.x].xyz;
    let axis = positions[in.atoms.y].xyz - p0;
    let len = length(axis);
    let a = axis / len;
    let radius = g.sticks.x;
    let oc = ro - p0;
    let d_perp = rd - a * dot(rd, a);
    let o_perp = oc - a * dot(oc, a);
    let qa = dot(d_perp, d_perp);
    let qb = dot(d_perp, o_perp);
    let qc = dot(o_perp, o_perp) - radius * radius;
    let disc = qb * qb - qa * qc;
    if (disc < 0.0 || qa < 1e-12) {
        discard;
    }
    let t = (-qb - sqrt(disc)) / qa;
    let hit = ro + rd * t;
    let h = dot(hit - p0, a);
    if (h < 0.0 || h > len) {
        discard;
    }
    if (beyond_cut(hit) > 0.0) {
        // Cut away where the ray enters: the cut face, where the ray crosses the plane inside.
        let p = ro + rd * cut_crossing(rd);
        let hp = dot(p - p0, a);
        let off_axis = length(p - p0 - a * hp);
        if (dot(g.cut.xyz, rd) >= 0.0 || off_axis > radius || hp < 0.0 || hp > len) {
            discard;
        }
        return cut_face(select(in.atoms.y, in.atoms.x, hp < 0.5 * len), rd, p);
    }
    // The half nearer an atom is that atom's: its colour, and picking it picks the atom.
    let atom = select(in.atoms.y, in.atoms.x, h < 0.5 * len);
    let n = normalize(hit - p0 - a * h);
    var out: FragOut;
    out.color = vec4<f32>(cued(shade(color_of(atom), n, -rd), hit), 1.0);
    out.id = g.pick.x | atom;
    out.depth = depth_of(hit);
    return out;
}

// ---- bonds as lines (big structures) ----

struct LineOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) atom: u32,
    @location(1) world: vec3<f32>,
};

struct LineFrag {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
};

@vertex
fn vs_line(@builtin(vertex_index) vi: u32, @builtin(instance_index) b: u32) -> LineOut {
    // Two segments per bond: atom x to the middle, the middle to atom y.
    let bond = bonds[b];
    let p0 = positions[bond.x].xyz;
    let p1 = positions[bond.y].xyz;
    let ends = array<vec3<f32>, 4>(p0, 0.5 * (p0 + p1), 0.5 * (p0 + p1), p1);
    var out: LineOut;
    out.clip = g.clip_from_world * vec4<f32>(ends[vi], 1.0);
    out.atom = select(bond.y, bond.x, vi < 2u);
    out.world = ends[vi];
    if (((flags_of(bond.x) | flags_of(bond.y)) & FLAG_HIDDEN) != 0u) {
        // A bond to an atom the selection leaves out: a point outside the clip volume.
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
    }
    return out;
}

@fragment
fn fs_line(in: LineOut) -> LineFrag {
    if (beyond_cut(in.world) > 0.0) {
        discard;
    }
    var out: LineFrag;
    out.color = vec4<f32>(cued(color_of(in.atom), in.world), 1.0);
    out.id = g.pick.x | in.atom;
    return out;
}
