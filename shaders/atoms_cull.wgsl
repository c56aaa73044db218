// Per frame: one workgroup per spatial cell of atoms, the cells in the frustum nearest first
// (ordered on the CPU), and one invocation per bond. Seed 002's screen-size level of detail: a
// sphere whose projected radius is at most `viewport.w` pixels is rasterised here exactly (per
// pixel ray–sphere test, nearest wins through an atomic maximum of the inverted depth, then its
// id written where it won), after a test that skips it when every pixel it could cover already
// holds something nearer (occlusion culling: nearer cells ran first); bigger spheres are
// appended to the list the impostor quads draw. Bonds thinner than a third of a pixel are left
// to the atoms.

@group(1) @binding(0) var<storage, read_write> lists: array<atomic<u32>>;
@group(1) @binding(1) var<storage, read_write> splat: array<atomic<u32>>;

const LISTS: u32 = 8u;
// The rasteriser's largest footprint side (pixels): bounds the loop whatever the inputs.
const MAX_SIDE: i32 = 40;
// Largest half side (pixels) of the square a big sphere writes as an occluder.
const MAX_OCCLUDER: i32 = 48;
// Whether this frame may have spheres too big for the rasteriser (the CPU knows from the
// nearest cell): then they are culled and occlude. Without them the code is left out, which
// llvmpipe runs measurably faster.
override BIG_SPHERES: bool = true;

fn index_of(gid: vec3<u32>) -> u32 {
    return gid.x + gid.y * g.counts.w;
}

struct Screen {
    // x, y: pixel position of the centre; z: projected radius (px); w: 0 culled, 1 splat,
    // 2 quad, 3 quad through the eye's plane
    p: vec4<f32>,
};

// Where atom i lands on screen, and how it is drawn.
fn screen_of(i: u32) -> Screen {
    var s: Screen;
    s.p = vec4<f32>(0.0);
    let r = radius_of(i);
    if (r <= 0.0) {
        return s;
    }
    let c = g.clip_from_world * vec4<f32>(positions[i].xyz, 1.0);
    if (c.w <= r) {
        // At or behind the eye's plane: a quad (clipped by the rasteriser) if in front at all,
        // with no screen position to test or occlude with.
        s.p.w = select(0.0, 3.0, c.w > -r);
        return s;
    }
    let r_px = r * g.viewport.z / c.w;
    let ndc = c.xy / c.w;
    let slack = 2.0 * (r_px + 1.0) / g.viewport.xy;
    if (any(abs(ndc) > vec2<f32>(1.0) + slack) || c.z > c.w + r * 2.0) {
        return s;
    }
    s.p = vec4<f32>((ndc.x + 1.0) * 0.5 * g.viewport.x, (1.0 - ndc.y) * 0.5 * g.viewport.y, r_px,
        select(2.0, 1.0, r_px <= g.viewport.w));
    return s;
}

// The pixels a splatted sphere may cover, clamped to the viewport.
// The pixels whose centres (at .5) lie within the projected splat radius (never under half a
// pixel; a sphere's perspective silhouette is a hair wider than its projected radius).
fn footprint(s: Screen) -> vec4<i32> {
    let e = max(s.p.z, 0.5) * 1.05 + 0.02;
    let lo = max(vec2<i32>(ceil(s.p.xy - 0.5 - e)), vec2<i32>(0));
    let hi = min(vec2<i32>(floor(s.p.xy - 0.5 + e)), vec2<i32>(g.viewport.xy) - 1);
    return vec4<i32>(lo, min(hi, lo + MAX_SIDE));
}

// The depth key of atom i at pixel (x, y): larger is nearer; 0 where the ray misses.
fn key_at(i: u32, x: i32, y: i32) -> u32 {
    let d = ray_through(vec2<f32>(f32(x) + 0.5, f32(y) + 0.5));
    let t = hit_sphere(d, positions[i].xyz, splat_radius(i));
    if (t < 0.0) {
        return 0u;
    }
    let depth = depth_of(g.eye.xyz + d * t);
    if (depth < 0.0 || depth > 1.0) {
        return 0u;
    }
    return 0xffffffffu - bitcast<u32>(depth);
}

// Cell header words in cell_data: first atom, atom count, centre x, y, z, radius (f32 bits).
const CELL_WORDS: u32 = 6u;
// Largest atom radius any style draws (bohr): pads a cell's bounds.
const MAX_ATOM_RADIUS: f32 = 5.0;
// A cell covering more pixels than this is not tested as a whole (the test would cost more
// than it saves).
const MAX_CELL_TEST_PIXELS: i32 = 256;

// Whether the whole cell is hidden behind what is already drawn: its bounding sphere's screen
// rectangle holds only nearer depths. Every lane tests on its own: llvmpipe runs a workgroup's
// lanes in SIMD, where a barrier costs more than the repeated loads.
fn cell_hidden(cell: u32) -> bool {
    let base = CELL_WORDS * cell;
    let centre = vec3<f32>(bitcast<f32>(cell_data[base + 2u]), bitcast<f32>(cell_data[base + 3u]),
        bitcast<f32>(cell_data[base + 4u]));
    let radius = bitcast<f32>(cell_data[base + 5u]) + MAX_ATOM_RADIUS;
    let c = g.clip_from_world * vec4<f32>(centre, 1.0);
    if (c.w <= radius) {
        return false;
    }
    let r_px = radius * g.viewport.z / c.w;
    let p = vec2<f32>((c.x / c.w + 1.0) * 0.5 * g.viewport.x, (1.0 - c.y / c.w) * 0.5 * g.viewport.y);
    let lo = max(vec2<i32>(floor(p - r_px - 1.0)), vec2<i32>(0));
    let hi = min(vec2<i32>(ceil(p + r_px + 1.0)), vec2<i32>(g.viewport.xy) - 1);
    let size = max(hi - lo + 1, vec2<i32>(0));
    if (size.x * size.y > MAX_CELL_TEST_PIXELS) {
        return false;
    }
    let front = centre + normalize(g.eye.xyz - centre) * radius;
    let key = 0xffffffffu - bitcast<u32>(clamp(depth_of(front), 0.0, 1.0));
    return hidden(vec4<i32>(lo, hi), key);
}

// Invocation `lane` of the workgroup for the `slot`-th nearest cell: each of its atoms once.
fn cell_of(wid: vec3<u32>) -> u32 {
    let slot = wid.x + wid.y * 65535u;
    if (slot >= g.cells.x) {
        return 0xffffffffu;
    }
    return atomicLoad(&lists[g.cells.y + slot]);
}

// The depth key of the sphere's point nearest the eye: no pixel of it can be nearer.
fn front_key(i: u32) -> u32 {
    let c = positions[i].xyz;
    let front = c + normalize(g.eye.xyz - c) * splat_radius(i);
    return 0xffffffffu - bitcast<u32>(clamp(depth_of(front), 0.0, 1.0));
}

// Whether every pixel of the footprint already holds something nearer than `key` (occluded:
// nothing to draw). Cells are visited nearest first, so most hidden atoms stop here.
fn hidden(f: vec4<i32>, key: u32) -> bool {
    let w = i32(g.viewport.x);
    for (var y = f.y; y <= f.w; y++) {
        for (var x = f.x; x <= f.z; x++) {
            if (atomicLoad(&splat[u32(y * w + x)]) <= key) {
                return false;
            }
        }
    }
    return true;
}

// A sphere too big to rasterise here: culled if what is drawn hides it, else appended to the
// quads' list and its inscribed square written at its centre's depth, a conservative occluder
// (the sphere's surface is nearer there) that lets farther atoms be culled.
fn big_sphere(i: u32, s: Screen) {
    let e = max(s.p.z, 0.5) * 1.05 + 0.02;
    let whole = 2.0 * e + 1.0 <= f32(MAX_SIDE);
    if (whole && s.p.w == 2.0 && hidden(footprint(s), front_key(i))) {
        return;
    }
    let k = atomicAdd(&lists[1], 1u);
    atomicStore(&lists[LISTS + k], i);
    let h = s.p.z * 0.7;
    if (h < 1.0 || h > f32(MAX_OCCLUDER) || s.p.w != 2.0) {
        return;
    }
    let key = 0xffffffffu - bitcast<u32>(clamp(depth_of(positions[i].xyz), 0.0, 1.0));
    let lo = max(vec2<i32>(ceil(s.p.xy - 0.5 - h)), vec2<i32>(0));
    let hi = min(vec2<i32>(floor(s.p.xy - 0.5 + h)), vec2<i32>(g.viewport.xy) - 1);
    let w = i32(g.viewport.x);
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            let pixel = u32(y * w + x);
            if (key > atomicLoad(&splat[pixel])) {
                atomicMax(&splat[pixel], key);
            }
        }
    }
}

fn rasterise(i: u32) {
    let s = screen_of(i);
    if (s.p.w >= 2.0) {
        if (BIG_SPHERES) {
            big_sphere(i, s);
        } else {
            let k = atomicAdd(&lists[1], 1u);
            atomicStore(&lists[LISTS + k], i);
        }
        return;
    }
    if (s.p.w == 0.0) {
        return;
    }
    let f = footprint(s);
    if (hidden(f, front_key(i))) {
        return;
    }
    let w = i32(g.viewport.x);
    for (var y = f.y; y <= f.w; y++) {
        for (var x = f.x; x <= f.z; x++) {
            let key = key_at(i, x, y);
            let pixel = u32(y * w + x);
            if (key > atomicLoad(&splat[pixel])) {
                atomicMax(&splat[pixel], key);
            }
        }
    }
}

fn write_id(i: u32) {
    let s = screen_of(i);
    if (s.p.w != 1.0) {
        return;
    }
    let f = footprint(s);
    if (hidden(f, front_key(i))) {
        return;
    }
    let w = i32(g.viewport.x);
    let ids = u32(g.viewport.x) * u32(g.viewport.y);
    for (var y = f.y; y <= f.w; y++) {
        for (var x = f.x; x <= f.z; x++) {
            let key = key_at(i, x, y);
            let pixel = u32(y * w + x);
            if (key != 0u && key == atomicLoad(&splat[pixel])) {
                atomicStore(&splat[ids + pixel], i + 1u);
            }
        }
    }
}

// One lane's share of one cell's atoms: `which` 0 rasterises depth keys, 1 (after 0) has
// each splatted atom write its id where its depth won.
fn cell_pass(wid: vec3<u32>, lane: u32, which: u32) {
    let cell = cell_of(wid);
    if (cell == 0xffffffffu || cell_hidden(cell)) {
        return;
    }
    let first = cell_data[CELL_WORDS * cell];
    let count = cell_data[CELL_WORDS * cell + 1u];
    for (var k = lane; k < count; k += 64u) {
        let i = cell_data[g.cells.z + first + k];
        if (which == 0u) {
            rasterise(i);
        } else {
            write_id(i);
        }
    }
}

@compute @workgroup_size(64)
fn cs_atoms(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    cell_pass(wid, lane, 0u);
}

@compute @workgroup_size(64)
fn cs_splat_ids(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    cell_pass(wid, lane, 1u);
}

@compute @workgroup_size(64)
fn cs_bonds(@builtin(global_invocation_id) gid: vec3<u32>) {
    let b = index_of(gid);
    if (b >= g.counts.y || (g.counts.z & STYLE_CYLINDERS) == 0u) {
        return;
    }
    let bond = bonds[b];
    if (((flags_of(bond.x) | flags_of(bond.y)) & FLAG_HIDDEN) != 0u) {
        return;
    }
    let p0 = positions[bond.x].xyz;
    let p1 = positions[bond.y].xyz;
    // The bond's bounding sphere against the frustum; its nearer end for the thickness.
    let mid = 0.5 * (p0 + p1);
    let reach = 0.5 * length(p1 - p0) + g.sticks.x;
    let c = g.clip_from_world * vec4<f32>(mid, 1.0);
    if (c.w > reach) {
        let ndc = c.xy / c.w;
        let slack = 2.0 * reach * g.viewport.z / c.w / g.viewport.xy;
        if (any(abs(ndc) > vec2<f32>(1.0) + slack)) {
            return;
        }
        let near_w = max(c.w - reach, 1e-6);
        if (g.sticks.x * g.viewport.z / near_w < 0.33) {
            return;
        }
    }
    let k = atomicAdd(&lists[5], 1u);
    atomicStore(&lists[LISTS + g.counts.x + k], b);
}
