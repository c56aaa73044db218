// Per frame: one workgroup per spatial cell of atoms, the cells in the frustum nearest first
// (ordered on the CPU), and one invocation per bond. Occlusion culling in two phases: the cells
// seen last frame are rasterised first; a coarse depth pyramid (the farthest depth of 8×8-pixel
// tiles and of 8×8-tile blocks) is built from them; every other cell whose bounds it hides is
// skipped, the rest rasterised; after a second pyramid only the cells that may show write ids
// (or, with packed words, are only marked seen). Lee et al.'s screen-size level of detail: a
// sphere whose projected radius is at most `viewport.w` pixels is rasterised here exactly (per
// pixel ray–sphere test, nearest wins through an atomic maximum of the inverted depth), after a
// test that skips it when every pixel it could cover already holds something nearer (nearer
// cells and atoms ran first); bigger spheres are appended to the list the impostor quads draw.
// Bonds thinner than a third of a pixel are left to the atoms.

// The splat buffer (binding 1 of group 1) and how a pixel's depth key and atom id are kept in
// it come from atoms_splat_pair.wgsl or atoms_splat_packed.wgsl: depth_key, draw_depth, draw_id,
// coarse_load, coarse_store and PACKED.

@group(1) @binding(0) var<storage, read_write> lists: array<atomic<u32>>;
// The cell lists' indirect dispatch arguments (x, y, z, unused): FIRST, REST then IDS. Bound only
// where the lists are filled (a buffer may not be indirect and writable in one dispatch).
@group(2) @binding(0) var<storage, read_write> args: array<atomic<u32>>;

// Words of `lists` counting the cell lists' entries (after the two indirect draws).
const FIRST: u32 = 8u;
const LEFT: u32 = 9u;
const REST: u32 = 10u;
const IDS: u32 = 11u;
// Coarse depth: a tile is TILE×TILE pixels, a block BLOCK×BLOCK tiles; each holds the smallest
// (farthest) depth key of its pixels.
const TILE: i32 = 8;
const BLOCK: i32 = 8;
// The most tiles or blocks along a side one coarse test reads.
const COARSE_SPAN: i32 = 8;
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
    // 2 quad, 3 quad through the eye's plane, 4 quad cut by the clipping plane
    p: vec4<f32>,
    // The centre (bohr) and the radius the rasteriser draws (never under half a pixel)
    centre: vec3<f32>,
    radius: f32,
    // The centre's clip z and w
    zw: vec2<f32>,
};

// Where atom i lands on screen, and how it is drawn: each atom's clip position once.
fn screen_of(i: u32) -> Screen {
    var s: Screen;
    s.p = vec4<f32>(0.0);
    let r = radius_of(i);
    if (r <= 0.0) {
        return s;
    }
    s.centre = positions[i].xyz;
    // Wholly beyond the clipping plane: culled; crossing it: a quad, which draws the cut face
    // (and is no occluder).
    let beyond = beyond_cut(s.centre);
    if (beyond >= r) {
        return s;
    }
    let c = g.clip_from_world * vec4<f32>(s.centre, 1.0);
    s.zw = c.zw;
    s.radius = max(r, 0.5 * c.w / g.viewport.z);
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
    if (beyond > -r) {
        s.p.w = 4.0;
    }
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

// The depth key of a screen's sphere at pixel (x, y): larger is nearer; 0 where the ray
// misses. The hit's clip z and w are linear in the ray parameter along the pixel's ray
// (`clip_zw`, `ray_zw`: no matrix per pixel).
fn key_at(s: Screen, x: i32, y: i32) -> u32 {
    let px = vec2<f32>(f32(x) + 0.5, f32(y) + 0.5);
    let ndc = vec2<f32>(2.0 * px.x / g.viewport.x - 1.0, 1.0 - 2.0 * px.y / g.viewport.y);
    let d = g.ray_f0.xyz + ndc.x * g.ray_fx.xyz + ndc.y * g.ray_fy.xyz - g.eye.xyz;
    let t = hit_sphere(d, s.centre, s.radius);
    if (t < 0.0) {
        return 0u;
    }
    let zw = g.clip_zw.xy + t * (g.ray_zw.xy + ndc.x * g.ray_zw.zw + ndc.y * g.ray_zw_y.xy);
    let depth = zw.x / zw.y;
    if (depth < 0.0 || depth > 1.0) {
        return 0u;
    }
    return 0xffffffffu - bitcast<u32>(depth);
}

// The largest screen rectangle (pixels) of a cell tested pixel by pixel.
const MAX_EXACT_CELL_PIXELS: i32 = 1024;

// Cell header words in cell_data: first atom, atom count, centre x, y, z, radius (f32 bits).
const CELL_WORDS: u32 = 6u;

fn tiles() -> vec2<i32> {
    return (vec2<i32>(g.viewport.xy) + TILE - 1) / TILE;
}

fn blocks() -> vec2<i32> {
    return (tiles() + BLOCK - 1) / BLOCK;
}

// Coarse depth words: the tiles, then the blocks.
fn blocks_at() -> u32 {
    let t = tiles();
    return u32(t.x * t.y);
}

// Whether the coarse depths say every pixel of the rectangle `f` (inclusive pixel bounds)
// holds something nearer than `key`: read from tiles where few enough cover it, else from
// blocks; unknown (false) for a rectangle wider still.
fn coarse_hidden(f: vec4<i32>, key: u32) -> bool {
    var lo = f.xy / TILE;
    var hi = f.zw / TILE;
    var at = 0u;
    var w = tiles().x;
    if (any(hi - lo >= vec2<i32>(COARSE_SPAN))) {
        lo /= BLOCK;
        hi /= BLOCK;
        at = blocks_at();
        w = blocks().x;
        if (any(hi - lo >= vec2<i32>(COARSE_SPAN))) {
            return false;
        }
    }
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            if (coarse_load(at + u32(y * w + x)) <= key) {
                return false;
            }
        }
    }
    return true;
}

// Whether any of a cell's atoms may show: its bounding sphere's screen rectangle is not hidden
// by the coarse depths at the sphere's nearest depth. The sphere holds the atom centres; it is
// padded by the largest atom drawn, or the half pixel a far atom still covers.
fn cell_may_show(cell: u32) -> bool {
    let base = CELL_WORDS * cell;
    let centre = vec3<f32>(bitcast<f32>(cell_data[base + 2u]), bitcast<f32>(cell_data[base + 3u]),
        bitcast<f32>(cell_data[base + 4u]));
    let c = g.clip_from_world * vec4<f32>(centre, 1.0);
    let inner = bitcast<f32>(cell_data[base + 5u]);
    let radius = inner + max(g.sticks.y, 0.5 * (c.w + inner) / g.viewport.z);
    if (c.w <= radius) {
        return true;
    }
    let r_px = radius * g.viewport.z / c.w;
    let p = vec2<f32>((c.x / c.w + 1.0) * 0.5 * g.viewport.x, (1.0 - c.y / c.w) * 0.5 * g.viewport.y);
    let lo = max(vec2<i32>(floor(p - r_px - 1.0)), vec2<i32>(0));
    let hi = min(vec2<i32>(ceil(p + r_px + 1.0)), vec2<i32>(g.viewport.xy) - 1);
    if (any(hi < lo)) {
        return false;
    }
    let rect = vec4<i32>(lo, hi);
    let key = nearest_key(c.zw, radius);
    if (coarse_hidden(rect, key)) {
        return false;
    }
    // A tile with a gap in it (the background between molecules) hides nothing behind it; a
    // rectangle small enough is then tested pixel by pixel (the test stops at the first pixel
    // not nearer).
    let size = hi - lo + 1;
    return size.x * size.y > MAX_EXACT_CELL_PIXELS || !hidden(rect, key, false);
}

// The invocation's index in a one-dimensional dispatch laid out in rows.
fn flat_index(gid: vec3<u32>, groups: vec3<u32>) -> u32 {
    return gid.x + gid.y * groups.x * 64u;
}

// Appends `cell` to the list counted at lists[count] and stored from lists[at], and widens its
// indirect dispatch (args[head]: one workgroup per cell, at most 65,535; each walks the list
// in strides of that).
fn push(count: u32, at: u32, head: u32, cell: u32) {
    let k = atomicAdd(&lists[count], 1u);
    atomicStore(&lists[at + k], cell);
    atomicMax(&args[head], min(k + 1u, 65535u));
}

// The frame's cells in view split: those seen last frame go first, the others are left for
// the occlusion test.
@compute @workgroup_size(64)
fn cs_split(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let slot = flat_index(gid, groups);
    if (slot >= g.cells.x) {
        return;
    }
    let cell = atomicLoad(&lists[g.cells.y + slot]);
    if (atomicLoad(&lists[g.cell_lists.w + cell]) + 1u == g.cells.w) {
        push(FIRST, g.cell_lists.x, 0u, cell);
    } else {
        let k = atomicAdd(&lists[LEFT], 1u);
        atomicStore(&lists[g.cell_lists.y + k], cell);
    }
}

// The left cells the coarse depths do not hide are rasterised next.
@compute @workgroup_size(64)
fn cs_cull_left(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let slot = flat_index(gid, groups);
    if (slot >= atomicLoad(&lists[LEFT])) {
        return;
    }
    let cell = atomicLoad(&lists[g.cell_lists.y + slot]);
    if (cell_may_show(cell)) {
        push(REST, g.cell_lists.z, 4u, cell);
    }
}

// With every depth drawn: the cells that may show write ids, and are seen this frame.
@compute @workgroup_size(64)
fn cs_cull_shown(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let slot = flat_index(gid, groups);
    if (slot >= g.cells.x) {
        return;
    }
    let cell = atomicLoad(&lists[g.cells.y + slot]);
    if (cell_may_show(cell)) {
        // The left list is spent: its words hold this list.
        push(IDS, g.cell_lists.y, 8u, cell);
        atomicStore(&lists[g.cell_lists.w + cell], g.cells.w);
    }
}

// Coarse depths: each tile's farthest pixel, then each block's farthest tile.
@compute @workgroup_size(64)
fn cs_depth_tiles(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let t = tiles();
    let k = i32(flat_index(gid, groups));
    if (k >= t.x * t.y) {
        return;
    }
    let lo = vec2<i32>(k % t.x, k / t.x) * TILE;
    let hi = min(lo + TILE, vec2<i32>(g.viewport.xy));
    let w = i32(g.viewport.x);
    var far = 0xffffffffu;
    for (var y = lo.y; y < hi.y; y++) {
        for (var x = lo.x; x < hi.x; x++) {
            far = min(far, depth_key(u32(y * w + x)));
        }
    }
    coarse_store(u32(k), far);
}

@compute @workgroup_size(64)
fn cs_depth_blocks(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let b = blocks();
    let t = tiles();
    let k = i32(flat_index(gid, groups));
    if (k >= b.x * b.y) {
        return;
    }
    let lo = vec2<i32>(k % b.x, k / b.x) * BLOCK;
    let hi = min(lo + BLOCK, t);
    var far = 0xffffffffu;
    for (var y = lo.y; y < hi.y; y++) {
        for (var x = lo.x; x < hi.x; x++) {
            far = min(far, coarse_load(u32(y * t.x + x)));
        }
    }
    coarse_store(blocks_at() + u32(k), far);
}

// The depth key of a sphere's nearest depth, from its centre's clip z and w: the centre moved
// by its radius towards the eye along the view direction (depth grows with the distance along
// it), so no pixel of it can be nearer. Radius 0: the centre's own key.
fn nearest_key(zw: vec2<f32>, radius: f32) -> u32 {
    let front = zw - radius * g.clip_zw.zw;
    return 0xffffffffu - bitcast<u32>(clamp(front.x / front.y, 0.0, 1.0));
}

// Whether every pixel of the footprint already holds something nearer than `key` (occluded:
// nothing to draw): from the coarse depths when they are built (`coarse`), else pixel by
// pixel. Cells are visited nearest first, so most hidden atoms stop here.
fn hidden(f: vec4<i32>, key: u32, coarse: bool) -> bool {
    if (coarse && coarse_hidden(f, key)) {
        return true;
    }
    let w = i32(g.viewport.x);
    for (var y = f.y; y <= f.w; y++) {
        for (var x = f.x; x <= f.z; x++) {
            if (depth_key(u32(y * w + x)) <= key) {
                return false;
            }
        }
    }
    return true;
}

// A sphere too big to rasterise here: culled if what is drawn hides it, else appended to the
// quads' list and its inscribed square written at its centre's depth, a conservative occluder
// (the sphere's surface is nearer there) that lets farther atoms be culled.
fn big_sphere(i: u32, s: Screen, coarse: bool) {
    let e = max(s.p.z, 0.5) * 1.05 + 0.02;
    let whole = 2.0 * e + 1.0 <= f32(MAX_SIDE);
    if (whole && s.p.w == 2.0 && hidden(footprint(s), nearest_key(s.zw, s.radius), coarse)) {
        return;
    }
    let k = atomicAdd(&lists[1], 1u);
    atomicStore(&lists[LISTS + k], i);
    let h = s.p.z * 0.7;
    if (h < 1.0 || h > f32(MAX_OCCLUDER) || s.p.w != 2.0) {
        return;
    }
    let key = nearest_key(s.zw, 0.0);
    let lo = max(vec2<i32>(ceil(s.p.xy - 0.5 - h)), vec2<i32>(0));
    let hi = min(vec2<i32>(floor(s.p.xy - 0.5 + h)), vec2<i32>(g.viewport.xy) - 1);
    let w = i32(g.viewport.x);
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            draw_depth(u32(y * w + x), key, 0u);
        }
    }
}

fn rasterise(i: u32, coarse: bool) {
    let s = screen_of(i);
    if (s.p.w >= 2.0) {
        if (BIG_SPHERES) {
            big_sphere(i, s, coarse);
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
    if (hidden(f, nearest_key(s.zw, s.radius), coarse)) {
        return;
    }
    let w = i32(g.viewport.x);
    for (var y = f.y; y <= f.w; y++) {
        for (var x = f.x; x <= f.z; x++) {
            draw_depth(u32(y * w + x), key_at(s, x, y), i + 1u);
        }
    }
}

fn write_id(i: u32) {
    let s = screen_of(i);
    if (s.p.w != 1.0) {
        return;
    }
    let f = footprint(s);
    if (hidden(f, nearest_key(s.zw, s.radius), true)) {
        return;
    }
    let w = i32(g.viewport.x);
    for (var y = f.y; y <= f.w; y++) {
        for (var x = f.x; x <= f.z; x++) {
            draw_id(u32(y * w + x), key_at(s, x, y), i + 1u);
        }
    }
}

// One lane's share of the atoms of the cells in a list (counted at lists[count], stored from
// lists[at]), a cell per workgroup: `which` 0 rasterises depth keys, 1 (after 0) has each
// splatted atom write its id where its depth won.
fn cell_pass(wid: vec3<u32>, lane: u32, count: u32, at: u32, which: u32, coarse: bool) {
    let n = atomicLoad(&lists[count]);
    for (var slot = wid.x; slot < n; slot += 65535u) {
        let cell = atomicLoad(&lists[at + slot]);
        let first = cell_data[CELL_WORDS * cell];
        let atoms = cell_data[CELL_WORDS * cell + 1u];
        for (var k = lane; k < atoms; k += 64u) {
            let i = cell_data[g.cells.z + first + select(k, atoms - 1u - k, g.pick.z != 0u)];
            if (which == 0u) {
                rasterise(i, coarse);
            } else {
                write_id(i);
            }
        }
    }
}

@compute @workgroup_size(64)
fn cs_atoms_first(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    cell_pass(wid, lane, FIRST, g.cell_lists.x, 0u, false);
}

@compute @workgroup_size(64)
fn cs_atoms_rest(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    cell_pass(wid, lane, REST, g.cell_lists.z, 0u, true);
}

@compute @workgroup_size(64)
fn cs_splat_ids(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    cell_pass(wid, lane, IDS, g.cell_lists.y, 1u, true);
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
    if (min(beyond_cut(p0), beyond_cut(p1)) >= g.sticks.x) {
        return;
    }
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
