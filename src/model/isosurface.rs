//! Isosurfaces of a grid by marching cubes, in parallel over slabs of cells.
//!
//! The case table is not typed in: it is derived once from the cube's faces. On each face the
//! corners "inside" (value above the level) form runs in the face's cyclic order; each run is cut
//! off by one segment from the edge where the walk enters it to the edge where it leaves. Two
//! faces sharing an edge walk it in opposite directions, so the segments chain into closed loops,
//! one polygon each. An ambiguous face (diagonal corners inside) always separates its inside
//! corners, and because that choice depends on the face alone, neighbouring cells agree and the
//! surface is closed. Normals come from the field's gradient, not from the triangles.

use std::sync::LazyLock;

use glam::{Affine3A, DMat3, DVec3, Mat3A, Vec3, Vec3A};
use rayon::prelude::*;

use super::VolumeGrid;

/// A triangle mesh in world coordinates (bohr). Triangles wind counter-clockwise seen from
/// outside (where the field is below the level); normals point outside.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub indices: Vec<u32>,
    /// Linear RGB per vertex (a molecular surface coloured by its atoms); empty: the surface's
    /// one colour.
    pub colors: Vec<[f32; 3]>,
}

impl Mesh {
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Total area (bohr²).
    pub fn area(&self) -> f64 {
        self.triangles().map(|[a, b, c]| 0.5 * (b - a).cross(c - a).length()).sum()
    }

    /// Enclosed volume (bohr³) of a closed mesh wound counter-clockwise seen from outside: the
    /// divergence theorem, one signed tetrahedron per triangle.
    pub fn volume(&self) -> f64 {
        self.triangles().map(|[a, b, c]| a.dot(b.cross(c)) / 6.0).sum()
    }

    /// The corner positions of each triangle, in double precision.
    pub fn triangles(&self) -> impl Iterator<Item = [DVec3; 3]> + '_ {
        self.indices.chunks_exact(3).map(|t| std::array::from_fn(|c| self.positions[t[c] as usize].as_dvec3()))
    }

    /// Merges vertices at bit-identical positions (marching cubes computes a shared edge's
    /// vertex the same way in both slabs that meet there), giving a closed surface one vertex
    /// per point: what mesh files and topology checks want.
    pub fn welded(&self) -> Mesh {
        let mut map = std::collections::HashMap::with_capacity(self.positions.len());
        let mut out = Mesh::default();
        let remap: Vec<u32> = self
            .positions
            .iter()
            .zip(&self.normals)
            .enumerate()
            .map(|(i, (p, n))| {
                *map.entry(p.to_array().map(f32::to_bits)).or_insert_with(|| {
                    out.positions.push(*p);
                    out.normals.push(*n);
                    if let Some(c) = self.colors.get(i) {
                        out.colors.push(*c);
                    }
                    (out.positions.len() - 1) as u32
                })
            })
            .collect();
        out.indices = self.indices.iter().map(|&i| remap[i as usize]).collect();
        out
    }
}

/// One surface to extract: where `sign·value = level` (level > 0 for orbitals' ± pair), the
/// inside being `sign·value > level`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    pub value: f32,
    pub sign: f32,
}

impl Level {
    /// The surfaces an iso value gives: +v and −v for a signed field, v alone otherwise.
    pub fn pair(iso: f32, signed: bool) -> Vec<Level> {
        let iso = iso.abs();
        let mut levels = vec![Level { value: iso, sign: 1.0 }];
        if signed {
            levels.push(Level { value: iso, sign: -1.0 });
        }
        levels
    }
}

/// Cube corner `c` sits at offset (c & 1, c >> 1 & 1, c >> 2 & 1) along the grid axes (i, j, k).
fn corner(c: usize) -> [usize; 3] {
    [c & 1, (c >> 1) & 1, (c >> 2) & 1]
}

/// The 12 edges as corner pairs (low corner first), grouped by axis.
static EDGES: LazyLock<[(usize, usize, usize); 12]> = LazyLock::new(|| {
    let mut edges = [(0, 0, 0); 12];
    let mut n = 0;
    for axis in 0..3 {
        for c in (0..8).filter(|c| c & (1 << axis) == 0) {
            edges[n] = (c, c | 1 << axis, axis);
            n += 1;
        }
    }
    edges
});

fn edge_between(a: usize, b: usize) -> usize {
    EDGES.iter().position(|&(p, q, _)| (p, q) == (a.min(b), a.max(b))).expect("corners share an edge")
}

/// Per case (bit c set: corner c inside), triangles as triples of edge numbers.
static CASES: LazyLock<Vec<Vec<[u8; 3]>>> = LazyLock::new(|| (0..256).map(triangulate_case).collect());

/// The case table flattened for the extraction loop: per case, its triangles' edges (at most
/// 5 triangles) and how many.
struct FlatCase {
    edges: [u8; 15],
    count: u8,
}

static FLAT_CASES: LazyLock<Vec<FlatCase>> = LazyLock::new(|| {
    CASES
        .iter()
        .map(|tris| {
            let mut edges = [0; 15];
            for (n, &e) in tris.iter().flatten().enumerate() {
                edges[n] = e;
            }
            FlatCase { edges, count: (3 * tris.len()) as u8 }
        })
        .collect()
});

/// The six faces, each as its four corners counter-clockwise seen from outside the cube.
fn faces() -> Vec<[usize; 4]> {
    let mut faces = Vec::new();
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in 0..2 {
            // Counter-clockwise about +axis in the (u, v) plane; reversed on the low side,
            // whose outward normal is −axis.
            let mut ring: Vec<usize> =
                [(0, 0), (1, 0), (1, 1), (0, 1)].iter().map(|&(a, b)| side << axis | a << u | b << v).collect();
            if side == 0 {
                ring.reverse();
            }
            faces.push([ring[0], ring[1], ring[2], ring[3]]);
        }
    }
    faces
}

fn triangulate_case(case: usize) -> Vec<[u8; 3]> {
    let inside = |c: usize| case & (1 << c) != 0;
    // next[e]: the edge where the loop through edge e continues.
    let mut next = [usize::MAX; 12];
    for ring in faces() {
        for t in 0..4 {
            let prev = ring[(t + 3) % 4];
            if !inside(ring[t]) || inside(prev) {
                continue;
            }
            // A run of inside corners starts at t; it ends before the first outside corner.
            let mut u = t;
            while inside(ring[(u + 1) % 4]) {
                u = (u + 1) % 4;
            }
            next[edge_between(prev, ring[t])] = edge_between(ring[u], ring[(u + 1) % 4]);
        }
    }
    let mut triangles = Vec::new();
    let mut seen = [false; 12];
    for start in 0..12 {
        if next[start] == usize::MAX || seen[start] {
            continue;
        }
        let mut polygon = Vec::new();
        let mut e = start;
        while !seen[e] {
            seen[e] = true;
            polygon.push(e as u8);
            e = next[e];
        }
        // The walk runs counter-clockwise seen from outside the surface (the side away from the
        // inside corners): fan it in that order.
        for w in 1..polygon.len() - 1 {
            triangles.push([polygon[0], polygon[w], polygon[w + 1]]);
        }
    }
    triangles
}

/// Where a vertex lands and how its normal is made, in single precision: world = origin +
/// steps·(i, j, k), and ∇_world = J⁻ᵀ ∇_index (J the steps as columns). Each vertex is placed
/// from its own index coordinates, so a vertex that two runs both make is bit-identical.
struct Frame {
    world_from_index: Affine3A,
    inv_t: Mat3A,
}

/// At most this many levels are extracted in one pass (one bit each per grid point).
pub const MAX_LEVELS: usize = 8;

/// Extracts one mesh per level (at most [`MAX_LEVELS`]; more are ignored), all in one pass over
/// the grid, in parallel over runs of slabs.
pub fn extract(grid: &VolumeGrid, levels: &[Level]) -> Vec<Mesh> {
    let levels = &levels[..levels.len().min(MAX_LEVELS)];
    let [nx, ny, nz] = grid.dims;
    if nx < 2 || ny < 2 || nz < 2 || levels.is_empty() {
        return vec![Mesh::default(); levels.len()];
    }
    let jac = DMat3::from_cols(grid.step(0), grid.step(1), grid.step(2));
    let frame = Frame {
        world_from_index: Affine3A::from_mat3_translation(jac.as_mat3(), grid.origin().as_vec3()),
        inv_t: Mat3A::from(jac.inverse().transpose().as_mat3()),
    };
    // A few runs per thread balance the load (one run when there is one thread: nothing to
    // merge); within a run, consecutive slabs share a plane's flags and the vertices on it.
    let slabs = nx - 1;
    let threads = rayon::current_num_threads();
    let runs = if threads == 1 { 1 } else { (4 * threads).clamp(1, slabs) };
    let parts: Vec<Vec<Mesh>> = (0..runs)
        .into_par_iter()
        .map(|r| {
            let mut run = Run::new(grid, &frame, levels);
            for i in r * slabs / runs..(r + 1) * slabs / runs {
                run.slab(i);
            }
            run.finish()
        })
        .collect();
    // Each level's pieces, joined in parallel with the other levels' (one run: nothing to copy).
    let mut pieces: Vec<Vec<Mesh>> = (0..levels.len()).map(|_| Vec::with_capacity(runs)).collect();
    for part in parts {
        for (level, mesh) in pieces.iter_mut().zip(part) {
            level.push(mesh);
        }
    }
    pieces.into_par_iter().map(merge).collect()
}

/// The runs' pieces of one level's mesh joined in order onto the first (no zeroed whole to copy
/// into), its normals made unit on the way.
fn merge(pieces: Vec<Mesh>) -> Mesh {
    let mut pieces = pieces.into_iter();
    let mut mesh = pieces.next().unwrap_or_default();
    let rest: Vec<Mesh> = pieces.collect();
    mesh.positions.reserve(rest.iter().map(|p| p.positions.len()).sum());
    mesh.normals.reserve(rest.iter().map(|p| p.normals.len()).sum());
    mesh.indices.reserve(rest.iter().map(|p| p.indices.len()).sum());
    for piece in &rest {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(&piece.positions);
        mesh.normals.extend_from_slice(&piece.normals);
        mesh.indices.extend(piece.indices.iter().map(|&i| i + base));
    }
    mesh.normals.iter_mut().for_each(|n| *n = n.normalize_or_zero());
    mesh
}

/// One plane's flags: per grid point, bit L set when the point is inside level L; per row of
/// points, how many leading cells and from which cell on its flags stay the same (the row's
/// first and last change), so that rows of cells are walked only where a surface can cross.
#[derive(Default)]
struct PlaneFlags {
    points: Vec<u8>,
    /// Per row: the first k with flags[k] ≠ flags[k + 1] (nz − 1 when none).
    left: Vec<u32>,
    /// Per row: one past the last such k (0 when none).
    right: Vec<u32>,
}

impl PlaneFlags {
    fn classify(&mut self, grid: &VolumeGrid, levels: &[Level], i: usize) {
        let [_, ny, nz] = grid.dims;
        let values = &grid.values[i * ny * nz..(i + 1) * ny * nz];
        self.points.resize(values.len(), 0);
        // One simple loop per level vectorises; a loop over levels inside would not. An
        // orbital's ± pair, the usual case, gets one loop for both: one read of the plane.
        match levels {
            // −v > w exactly when v < −w: no multiplications.
            [a, b] if a.sign == 1.0 && b.sign == -1.0 => pair_flags(values, a.value, -b.value, &mut self.points),
            _ => {
                self.points.fill(0);
                for (l, level) in levels.iter().enumerate() {
                    for (bits, &v) in self.points.iter_mut().zip(values) {
                        *bits |= u8::from(level.sign * v > level.value) << l;
                    }
                }
            }
        }
        self.left.clear();
        self.right.clear();
        for row in self.points.chunks_exact(nz) {
            // Most rows are uniform: a fold that vectorises tells them before any scan.
            let (and, or) = row.iter().fold((u8::MAX, 0u8), |(a, o), &b| (a & b, o | b));
            let (left, right) = match and == or {
                true => (nz - 1, 0),
                false => {
                    let mut changes = differences(&row[..nz - 1], &row[1..], 0, nz - 1).map(|(k, _)| k);
                    let left = changes.next().unwrap_or(nz - 1);
                    (left, changes.last().unwrap_or(left) + 1)
                }
            };
            self.left.push(left as u32);
            self.right.push(right as u32);
        }
    }
}

/// Per value, bit 0 set when it is above `above` and bit 1 when it is below `below`.
fn pair_flags(values: &[f32], above: f32, below: f32, flags: &mut [u8]) {
    let (whole, rest) = values.as_chunks::<16>();
    let (out, out_rest) = flags.as_chunks_mut::<16>();
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE2 is part of x86-64.
    unsafe {
        pair_flags_sse2(whole, above, below, out);
    }
    #[cfg(not(target_arch = "x86_64"))]
    for (v, o) in whole.iter().zip(out.iter_mut()) {
        *o = v.map(|v| u8::from(v > above) | u8::from(v < below) << 1);
    }
    for (bits, &v) in out_rest.iter_mut().zip(rest) {
        *bits = u8::from(v > above) | u8::from(v < below) << 1;
    }
}

/// [`pair_flags`] sixteen values at a time in SSE2 registers: the compiler's own loop packs each
/// comparison's four lanes separately, twice the work.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse2")]
fn pair_flags_sse2(values: &[[f32; 16]], above: f32, below: f32, flags: &mut [[u8; 16]]) {
    use std::arch::x86_64::*;
    let (high, low) = (_mm_set1_ps(above), _mm_set1_ps(below));
    // Four masks of all ones or zeros to sixteen bytes of −1 or 0.
    let bytes = |m: [__m128; 4]| {
        let m = m.map(|m| _mm_castps_si128(m));
        _mm_packs_epi16(_mm_packs_epi32(m[0], m[1]), _mm_packs_epi32(m[2], m[3]))
    };
    for (v, o) in values.iter().zip(flags.iter_mut()) {
        let v: [__m128; 4] = bytemuck::cast(*v);
        let (is_above, is_below) = (bytes(v.map(|x| _mm_cmpgt_ps(x, high))), bytes(v.map(|x| _mm_cmplt_ps(x, low))));
        // −(−1) = 1 for above, −(−2) = 2 for below.
        let sum = _mm_add_epi8(is_above, _mm_add_epi8(is_below, is_below));
        *o = bytemuck::cast(_mm_sub_epi8(_mm_setzero_si128(), sum));
    }
}

/// Asks for `values` to be brought into the cache ahead of their use: a hint, no effect on any
/// result.
#[inline]
fn prefetch(values: &[f32]) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of x86-64; a prefetch reads nothing and never faults.
    unsafe {
        prefetch_sse(values);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse")]
#[inline]
fn prefetch_sse(values: &[f32]) {
    use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
    for line in values.chunks(16) {
        _mm_prefetch::<_MM_HINT_T0>(line.as_ptr().cast());
    }
}

/// 1 in every byte of a u64.
const BYTES: u64 = 0x0101_0101_0101_0101;
/// Multiplying bytes of 0 or 1 by this gathers byte c into bit c of the top byte.
const GATHER: u64 = 0x0102_0408_1020_4080;

/// For a row of cells k in start..end (corner rows `rows[dx][dy]`): per point k in start..=end
/// its column of four flags as one word (byte dx + 2·dy: `rows[dx][dy][k]`), so that cell k's
/// eight corners are `columns[k] | columns[k + 1] << 32` (byte c: corner c); and per cell the
/// levels whose flags differ among its corners (bit L: level L crosses it). Loops that
/// vectorise, in place of a test per cell.
fn mixed_cells(rows: [[&[u8]; 2]; 2], start: usize, end: usize, columns: &mut Vec<u32>, mixed: &mut Vec<u8>) {
    let span = |dx: usize, dy: usize| &rows[dx][dy][start..=end];
    let (a, b, c, d) = (span(0, 0), span(1, 0), span(0, 1), span(1, 1));
    columns.clear();
    columns.extend(a.iter().zip(b).zip(c).zip(d).map(|(((&a, &b), &c), &d)| u32::from_le_bytes([a, b, c, d])));
    let any = |w: u32| w | w >> 8 | w >> 16 | w >> 24;
    let all = |w: u32| w & w >> 8 & w >> 16 & w >> 24;
    mixed.clear();
    mixed.extend(columns.iter().zip(&columns[1..]).map(|(&w0, &w1)| ((any(w0) | any(w1)) ^ (all(w0) & all(w1))) as u8));
}

/// The places k in start..end where two rows of flags differ, with `a[k] ^ b[k]`, found eight
/// bytes at a time.
#[inline(always)]
fn differences<'r>(a: &'r [u8], b: &'r [u8], start: usize, end: usize) -> Differences<'r> {
    let (a, b) = if start < end { (&a[start..end], &b[start..end]) } else { (&a[..0], &b[..0]) };
    let ((words_a, tail_a), (words_b, tail_b)) = (a.as_chunks::<8>(), b.as_chunks::<8>());
    Differences { words: (words_a, words_b), tail: (tail_a, tail_b), next: 0, word: 0, at: start, start }
}

struct Differences<'r> {
    words: (&'r [[u8; 8]], &'r [[u8; 8]]),
    tail: (&'r [u8], &'r [u8]),
    /// The next word to test (the tail, padded, after the last whole one).
    next: usize,
    /// The current word's differing bytes not yet returned, and where its byte 0 is.
    word: u64,
    at: usize,
    start: usize,
}

impl Iterator for Differences<'_> {
    type Item = (usize, u8);

    #[inline(always)]
    fn next(&mut self) -> Option<(usize, u8)> {
        while self.word == 0 {
            let (a, b) = self.words;
            let (x, y) = match (a.get(self.next), b.get(self.next)) {
                (Some(x), Some(y)) => (*x, *y),
                _ if self.next == a.len() && !self.tail.0.is_empty() => {
                    let pad = |t: &[u8]| std::array::from_fn(|n| t.get(n).copied().unwrap_or(0));
                    (pad(self.tail.0), pad(self.tail.1))
                }
                _ => return None,
            };
            self.word = u64::from_le_bytes(x) ^ u64::from_le_bytes(y);
            self.at = self.start + 8 * self.next;
            self.next += 1;
        }
        let n = self.word.trailing_zeros() / 8;
        let difference = (self.word >> (8 * n)) as u8;
        self.word &= !(0xff << (8 * n));
        Some((self.at + n as usize, difference))
    }
}

/// Where rows `a` and `b` of flags, whose first and last changes are `(left, right)` as in
/// [`PlaneFlags`], can differ: each is constant up to its first change and after its last.
fn span(a: &[u8], b: &[u8], (left_a, right_a): (u32, u32), (left_b, right_b): (u32, u32)) -> (usize, usize) {
    let n = a.len();
    let start = if a[0] == b[0] { left_a.min(left_b) as usize + 1 } else { 0 };
    let end = if a[n - 1] == b[n - 1] { right_a.max(right_b) as usize } else { n };
    (start, end)
}

/// Where a level's table of vertex ids keeps an edge's: the table holds one section per kind of
/// edge, each indexed by j·nz + k of the edge's low point: edges along i between the slab's two
/// planes, then edges along j and along k in its planes by plane parity (the second plane's are
/// the next slab's first). Entries of uncrossed edges are stale and never read: a cell's case
/// uses exactly its crossed edges.
fn section(axis: usize, parity: usize) -> usize {
    match axis {
        0 => 0,
        1 => 1 + parity,
        _ => 3 + parity,
    }
}

/// Sections in a table of vertex ids.
const SECTIONS: usize = 5;

/// Per case, its triangles' corners as offsets into a level's table of vertex ids from the
/// cell's j·nz + k, for a slab whose low plane has the given parity; unused entries are 0.
fn case_offsets(cases: &[FlatCase], [ny, nz]: [usize; 2], parity: usize) -> Vec<[u32; 15]> {
    let edge_offset: [usize; 12] = std::array::from_fn(|e| {
        let (c0, _, axis) = EDGES[e];
        let [dx, dy, dz] = corner(c0);
        section(axis, (parity + dx) & 1) * ny * nz + dy * nz + dz
    });
    cases
        .iter()
        .map(|case| {
            std::array::from_fn(|n| match n < case.count as usize {
                true => edge_offset[case.edges[n] as usize] as u32,
                false => 0,
            })
        })
        .collect()
}

/// Consecutive slabs extracted by one thread. Every crossed edge's vertex is made first, edge
/// by edge (the crossed edges of a row of flags are where neighbouring bytes differ); then each
/// crossed cell's triangles pick their vertices from the edges' ids.
struct Run<'a> {
    grid: &'a VolumeGrid,
    frame: &'a Frame,
    levels: &'a [Level],
    /// Per level: normal = −sign · J⁻ᵀ ∇_index (outside is where the signed field falls).
    normal_from_index: Vec<Mat3A>,
    meshes: Vec<Mesh>,
    /// Per level, the meshes' index count (their index vectors are written ahead, in whole
    /// cases, and cut to this length at the end).
    index_count: Vec<usize>,
    /// Per level, the vertex made on each crossed edge ([`section`]).
    ids: Vec<Vec<u32>>,
    /// [`case_offsets`] for slabs whose low plane is even, and odd.
    offsets: [Vec<[u32; 15]>; 2],
    /// Flags of planes by plane number modulo 3, and which plane each holds: a slab's two, and
    /// the one after, classified ahead so that the gradients' reads there find it in cache.
    flags: [PlaneFlags; 3],
    flagged: [Option<usize>; 3],
    /// The plane whose edges' vertices were made last.
    edged: Option<usize>,
    /// Scratch for a row of cells: per point its column of four flags, and per cell the levels
    /// crossing it ([`mixed_cells`]).
    columns: Vec<u32>,
    mixed: Vec<u8>,
    /// The static table, dereferenced once.
    cases: &'static [FlatCase],
    /// The grid's (ny, nz) that `offsets` were made for.
    offsets_for: [usize; 2],
}

/// A run's buffers, kept by its thread for the next run: what would otherwise be allocated and
/// zeroed for every run (in the parallel case several per call), for nothing but the stale
/// values that are never read.
#[derive(Default)]
struct Scratch {
    ids: Vec<Vec<u32>>,
    offsets: [Vec<[u32; 15]>; 2],
    offsets_for: [usize; 2],
    flags: [PlaneFlags; 3],
    columns: Vec<u32>,
    mixed: Vec<u8>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::default();
}

impl<'a> Run<'a> {
    fn new(grid: &'a VolumeGrid, frame: &'a Frame, levels: &'a [Level]) -> Self {
        let [_, ny, nz] = grid.dims;
        let mut scratch = SCRATCH.with_borrow_mut(std::mem::take);
        scratch.ids.resize_with(levels.len(), Vec::new);
        for ids in &mut scratch.ids {
            if ids.len() < SECTIONS * ny * nz {
                ids.resize(SECTIONS * ny * nz, 0);
            }
        }
        if scratch.offsets_for != [ny, nz] {
            scratch.offsets = [0, 1].map(|parity| case_offsets(&FLAT_CASES, [ny, nz], parity));
        }
        Self {
            grid,
            frame,
            levels,
            normal_from_index: levels.iter().map(|l| frame.inv_t * -l.sign).collect(),
            meshes: vec![Mesh::default(); levels.len()],
            index_count: vec![0; levels.len()],
            ids: scratch.ids,
            offsets: scratch.offsets,
            offsets_for: [ny, nz],
            flags: scratch.flags,
            flagged: [None; 3],
            edged: None,
            columns: scratch.columns,
            mixed: scratch.mixed,
            cases: &FLAT_CASES,
        }
    }

    fn classify(&mut self, plane: usize) {
        if plane < self.grid.dims[0] && self.flagged[plane % 3] != Some(plane) {
            self.flags[plane % 3].classify(self.grid, self.levels, plane);
            self.flagged[plane % 3] = Some(plane);
        }
    }

    /// The cells between planes i and i + 1.
    fn slab(&mut self, i: usize) {
        for plane in i..i + 3 {
            self.classify(plane);
        }
        let flags = std::mem::take(&mut self.flags);
        let (low, high) = (&flags[i % 3], &flags[(i + 1) % 3]);
        if self.edged != Some(i) {
            self.plane_edges(low, i);
        }
        self.plane_edges(high, i + 1);
        self.edged = Some(i + 1);
        self.slab_edges([low, high], i);
        self.cells([low, high], i);
        self.flags = flags;
    }

    /// The vertices on the crossed edges lying in plane i: along k within each row, along j
    /// between neighbouring rows.
    fn plane_edges(&mut self, flags: &PlaneFlags, i: usize) {
        let [_, ny, nz] = self.grid.dims;
        let parity = i & 1;
        for j in 0..ny {
            let row = &flags.points[j * nz..(j + 1) * nz];
            let (left, right) = (flags.left[j] as usize, flags.right[j] as usize);
            for (k, crossed) in differences(&row[..nz - 1], &row[1..], left, right) {
                self.edge::<2>(crossed, [i, j, k], parity);
            }
            if j + 1 < ny {
                let next = &flags.points[(j + 1) * nz..(j + 2) * nz];
                let (start, end) =
                    span(row, next, (flags.left[j], flags.right[j]), (flags.left[j + 1], flags.right[j + 1]));
                for (k, crossed) in differences(row, next, start, end) {
                    self.edge::<1>(crossed, [i, j, k], parity);
                }
            }
        }
    }

    /// The vertices on the crossed edges between planes i and i + 1.
    fn slab_edges(&mut self, [low, high]: [&PlaneFlags; 2], i: usize) {
        let [_, ny, nz] = self.grid.dims;
        for j in 0..ny {
            let (a, b) = (&low.points[j * nz..(j + 1) * nz], &high.points[j * nz..(j + 1) * nz]);
            let (start, end) = span(a, b, (low.left[j], low.right[j]), (high.left[j], high.right[j]));
            for (k, crossed) in differences(a, b, start, end) {
                self.edge::<0>(crossed, [i, j, k], 0);
            }
        }
    }

    /// For each level whose bit is set in `crossed`, the vertex on the edge from point `p` along
    /// `AXIS`, its id kept in that axis's table (plane `parity`'s for j and k).
    #[inline(always)]
    fn edge<const AXIS: usize>(&mut self, mut crossed: u8, p: [usize; 3], parity: usize) {
        let [_, ny, nz] = self.grid.dims;
        let slot = section(AXIS, parity) * ny * nz + p[1] * nz + p[2];
        while crossed != 0 {
            let l = crossed.trailing_zeros() as usize;
            crossed &= crossed - 1;
            let id = self.vertex::<AXIS>(l, p);
            self.ids[l][slot] = id;
        }
    }

    /// The vertex of level `l` on the edge from grid point `p` along `AXIS`: linear
    /// interpolation of the field, and of its gradient by central differences (one-sided at the
    /// borders) in index space, turned into a world normal (made unit when the runs are joined,
    /// away from this loop).
    #[inline(always)]
    fn vertex<const AXIS: usize>(&mut self, l: usize, p: [usize; 3]) -> u32 {
        let [nx, ny, nz] = self.grid.dims;
        let values = &self.grid.values;
        let (sx, sy) = (ny * nz, nz);
        let stride = [sx, sy, 1][AXIS];
        let at = (p[0] * ny + p[1]) * nz + p[2];
        let level = self.levels[l];
        let (v0, v1) = (level.sign * values[at], level.sign * values[at + stride]);
        let t = ((level.value - v0) / (v1 - v0)).clamp(0.0, 1.0);
        let mut q = p;
        q[AXIS] += 1;
        // Both ends inside the border (nearly every vertex): central differences by strides.
        let interior = (0..3).all(|a| p[a] > 0 && q[a] + 1 < self.grid.dims[a]);
        let (g0, g1) = if interior {
            let central = |at: usize| {
                Vec3A::new(
                    values[at + sx] - values[at - sx],
                    values[at + sy] - values[at - sy],
                    values[at + 1] - values[at - 1],
                )
            };
            (central(at), central(at + stride))
        } else {
            (self.border_gradient(p, [nx, ny, nz]), self.border_gradient(q, [nx, ny, nz]))
        };
        let mut x = Vec3A::new(p[0] as u32 as f32, p[1] as u32 as f32, p[2] as u32 as f32);
        x[AXIS] += t;
        let mesh = &mut self.meshes[l];
        mesh.positions.push(self.frame.world_from_index.transform_point3a(x).into());
        mesh.normals.push((self.normal_from_index[l] * g0.lerp(g1, t)).into());
        (mesh.positions.len() - 1) as u32
    }

    /// Twice the field's gradient at grid point `p` in index space (the central differences'
    /// scale), one-sided where `p` is on the border.
    #[cold]
    fn border_gradient(&self, p: [usize; 3], dims: [usize; 3]) -> Vec3A {
        let g = self.grid;
        let mut d = Vec3A::ZERO;
        for a in 0..3 {
            let (mut lo, mut hi) = (p, p);
            lo[a] = p[a].saturating_sub(1);
            hi[a] = (p[a] + 1).min(dims[a] - 1);
            let span = (hi[a] - lo[a]).max(1) as f32;
            d[a] = 2.0 * (g.value(hi[0], hi[1], hi[2]) - g.value(lo[0], lo[1], lo[2])) / span;
        }
        d
    }

    /// The triangles of the crossed cells between planes i and i + 1.
    fn cells(&mut self, flags: [&PlaneFlags; 2], i: usize) {
        let [nx, ny, nz] = self.grid.dims;
        // The plane classified next slab, row by row, fetched from memory while these cells'
        // work goes on.
        let ahead = if i + 3 < nx { &self.grid.values[(i + 3) * ny * nz..(i + 4) * ny * nz] } else { &[] };
        let mut ahead = ahead.chunks(nz);
        for j in 0..ny - 1 {
            if let Some(row) = ahead.next() {
                prefetch(row);
            }
            let rows = flags.map(|f| [&f.points[j * nz..(j + 1) * nz], &f.points[(j + 1) * nz..(j + 2) * nz]]);
            // Before every row's first change (after every row's last) the four rows are
            // constant: those cells are crossed only when the rows' flags differ there.
            let same_at = |k: usize| rows.iter().flatten().all(|r| r[k] == rows[0][0][k]);
            let left = flags.iter().flat_map(|f| [f.left[j], f.left[j + 1]]).min().unwrap_or(0) as usize;
            let right = flags.iter().flat_map(|f| [f.right[j], f.right[j + 1]]).max().unwrap_or(0) as usize;
            let start = if same_at(0) { left } else { 0 };
            let end = if same_at(nz - 1) { right } else { nz - 1 };
            if start >= end {
                continue;
            }
            let (mut columns, mut mixed) = (std::mem::take(&mut self.columns), std::mem::take(&mut self.mixed));
            mixed_cells(rows, start, end, &mut columns, &mut mixed);
            // Most cells in the span are inside or outside everything: skip them eight at a time.
            let (words, tail) = mixed.as_chunks::<8>();
            let tail = std::array::from_fn(|n| tail.get(n).copied().unwrap_or(0));
            for (q, word) in words.iter().chain([&tail]).enumerate() {
                let mut word = u64::from_le_bytes(*word);
                while word != 0 {
                    let n = (word.trailing_zeros() / 8) as usize;
                    let levels = (word >> (8 * n)) as u8;
                    word &= !(0xff << (8 * n));
                    let at = 8 * q + n;
                    let corners = u64::from(columns[at]) | u64::from(columns[at + 1]) << 32;
                    self.cell(i & 1, j * nz + start + at, corners, levels);
                }
            }
            (self.columns, self.mixed) = (columns, mixed);
        }
    }

    /// The meshes made, their indices cut to what the cases wrote.
    fn finish(mut self) -> Vec<Mesh> {
        for (mesh, &count) in self.meshes.iter_mut().zip(&self.index_count) {
            mesh.indices.truncate(count);
        }
        let scratch = Scratch {
            ids: self.ids,
            offsets: self.offsets,
            offsets_for: self.offsets_for,
            flags: self.flags,
            columns: self.columns,
            mixed: self.mixed,
        };
        SCRATCH.with_borrow_mut(|kept| *kept = scratch);
        self.meshes
    }

    /// The triangles of the crossed cell at j·nz + k `at` in a slab whose low plane has parity
    /// `parity`, for the levels whose bits are set in `levels`, from its corners' flags (byte c:
    /// corner c) and its edges' vertices. A case's whole row of 15 indices is written; the
    /// count moves on by its triangles'.
    #[inline(always)]
    fn cell(&mut self, parity: usize, at: usize, corners: u64, mut levels: u8) {
        while levels != 0 {
            let l = levels.trailing_zeros() as usize;
            levels &= levels - 1;
            // Bit l of each corner's flags gathered into the case's bit c.
            let case = (((corners >> l) & BYTES).wrapping_mul(GATHER) >> 56) as usize;
            let ids = &self.ids[l][at..];
            let (indices, count) = (&mut self.meshes[l].indices, &mut self.index_count[l]);
            if indices.len() < *count + 15 {
                indices.resize((2 * indices.len()).max(*count + 15), 0);
            }
            for (index, &offset) in indices[*count..*count + 15].iter_mut().zip(&self.offsets[parity][case]) {
                *index = ids[offset as usize];
            }
            *count += self.cases[case].count as usize;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f = R² − |x − c|² sampled on `n`³ points spanning ±1.5 R, optionally sheared.
    fn ball(n: usize, radius: f64, shear: f64) -> VolumeGrid {
        let h = 3.0 * radius / (n - 1) as f64;
        let steps = [DVec3::new(h, 0.0, 0.0), DVec3::new(shear * h, h, 0.0), DVec3::new(0.0, shear * h, h)];
        let origin = -(steps[0] + steps[1] + steps[2]) * ((n - 1) as f64 / 2.0) + DVec3::new(0.3, -0.2, 0.1);
        let world = VolumeGrid::affine(origin, steps);
        let center = DVec3::new(0.3, -0.2, 0.1);
        let mut values = Vec::with_capacity(n * n * n);
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let p = world.transform_point3(DVec3::new(i as f64, j as f64, k as f64));
                    values.push((radius * radius - (p - center).length_squared()) as f32);
                }
            }
        }
        VolumeGrid::new("ball", [n, n, n], world, values)
    }

    #[test]
    fn every_case_gives_closed_oriented_loops() {
        // Each edge crossed by the surface (its corners differ) is used by one polygon, once.
        for case in 0..256usize {
            let crossed: Vec<usize> =
                (0..12).filter(|&e| (case >> EDGES[e].0 & 1) != (case >> EDGES[e].1 & 1)).collect();
            let mut used: Vec<usize> = CASES[case].iter().flatten().map(|&e| e as usize).collect();
            used.sort();
            used.dedup();
            assert_eq!(used, crossed, "case {case:08b}");
        }
        assert!(CASES[0].is_empty() && CASES[255].is_empty());
        assert_eq!(CASES[1].len(), 1);
    }

    #[test]
    fn differences_and_spans_find_every_change() {
        // Rows with changes near both ends, across whole words and in the tail.
        let rows: [Vec<u8>; 4] = [
            (0..37).map(|k| u8::from(k == 3 || (20..29).contains(&k))).collect(),
            (0..37).map(|k| u8::from(k >= 36) << 1).collect(),
            vec![0; 37],
            (0..37).map(|k| u8::from(k < 9) | u8::from(k % 7 == 0) << 1).collect(),
        ];
        let ends = |r: &[u8]| {
            let changes: Vec<usize> = (0..r.len() - 1).filter(|&k| r[k] != r[k + 1]).collect();
            (*changes.first().unwrap_or(&(r.len() - 1)) as u32, changes.last().map_or(0, |k| *k as u32 + 1))
        };
        for a in &rows {
            let (left, right) = ends(a);
            let within: Vec<_> = differences(&a[..36], &a[1..], left as usize, right as usize).collect();
            let all: Vec<_> = (0..36).filter(|&k| a[k] != a[k + 1]).map(|k| (k, a[k] ^ a[k + 1])).collect();
            assert_eq!(within, all);
            for b in &rows {
                let (start, end) = span(a, b, ends(a), ends(b));
                let found: Vec<_> = differences(a, b, start, end).collect();
                let all: Vec<_> = (0..37).filter(|&k| a[k] != b[k]).map(|k| (k, a[k] ^ b[k])).collect();
                assert_eq!(found, all);
            }
        }
    }

    #[test]
    fn pair_flags_match_the_comparisons() {
        let values: Vec<f32> = (0..53).map(|n| ((n * 37 % 23) as f32 - 11.0) * 0.01).collect();
        let mut flags = vec![0xff; values.len()];
        pair_flags(&values, 0.05, -0.03, &mut flags);
        for (&v, &f) in values.iter().zip(&flags) {
            assert_eq!(f, u8::from(v > 0.05) | u8::from(v < -0.03) << 1, "{v}");
        }
    }

    #[test]
    fn case_offsets_follow_the_edges() {
        // Each triangle corner's offset names the table section and slot of its edge's low
        // point, from the cell's corner 0.
        let [ny, nz] = [5, 7];
        for parity in 0..2 {
            let offsets = case_offsets(&FLAT_CASES, [ny, nz], parity);
            for (case, flat) in FLAT_CASES.iter().enumerate() {
                for (n, &e) in flat.edges[..flat.count as usize].iter().enumerate() {
                    let (c0, c1, axis) = EDGES[e as usize];
                    let (p, q) = (corner(c0), corner(c1));
                    assert_eq!((0..3).filter(|&a| p[a] != q[a]).collect::<Vec<_>>(), vec![axis]);
                    let plane = (parity + p[0]) % 2;
                    let expected = section(axis, plane) * ny * nz + p[1] * nz + p[2];
                    assert_eq!(offsets[case][n] as usize, expected, "case {case} edge {e}");
                }
            }
        }
    }

    #[test]
    fn a_ball_is_closed_with_outward_normals_and_the_right_area() {
        for shear in [0.0, 0.35] {
            let r = 2.0;
            let grid = ball(41, r, shear);
            let mesh = extract(&grid, &[Level { value: 0.0, sign: 1.0 }]).remove(0);
            let area = mesh.area();
            let exact = 4.0 * std::f64::consts::PI * r * r;
            assert!((area / exact - 1.0).abs() < 0.01, "shear {shear}: area {area} vs {exact}");
            let center = DVec3::new(0.3, -0.2, 0.1);
            for [a, b, c] in mesh.triangles() {
                let n = (b - a).cross(c - a);
                assert!(n.dot((a + b + c) / 3.0 - center) > 0.0, "a triangle winds inwards");
            }
            for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
                let exact = (p.as_dvec3() - center).normalize();
                assert!(n.as_dvec3().dot(exact) > 0.995, "normal {n} at {p}");
            }
            // Closed: every edge of the welded mesh has exactly two triangles, in opposite
            // directions, and V − E + F = 2 for a sphere.
            let w = mesh.welded();
            let mut directed = std::collections::HashMap::new();
            for t in w.indices.chunks_exact(3) {
                for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                    *directed.entry((a, b)).or_insert(0) += 1;
                }
            }
            assert!(directed.iter().all(|(&(a, b), &n)| n == 1 && directed.get(&(b, a)) == Some(&1)));
            let (v, e, f) = (w.positions.len() as i64, directed.len() as i64 / 2, w.triangle_count() as i64);
            assert_eq!(v - e + f, 2, "shear {shear}");
        }
    }

    #[test]
    fn a_signed_field_gives_two_surfaces() {
        // ψ = x·exp(−r²): a p orbital, two lobes of equal area, mirror images.
        let n = 33;
        let h = 8.0 / (n - 1) as f64;
        let world = VolumeGrid::affine(DVec3::splat(-4.0), [DVec3::X * h, DVec3::Y * h, DVec3::Z * h]);
        let mut values = Vec::new();
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let p = world.transform_point3(DVec3::new(i as f64, j as f64, k as f64));
                    values.push((p.x * (-p.length_squared()).exp()) as f32);
                }
            }
        }
        let grid = VolumeGrid::new("p", [n, n, n], world, values);
        let meshes = extract(&grid, &Level::pair(0.1, true));
        let (plus, minus) = (&meshes[0], &meshes[1]);
        assert!(plus.triangle_count() > 100);
        assert!((plus.area() / minus.area() - 1.0).abs() < 1e-3);
        assert!(plus.positions.iter().all(|p| p.x > 0.0) && minus.positions.iter().all(|p| p.x < 0.0));
        // Normals point away from each lobe's centre.
        let c = |m: &Mesh| m.positions.iter().copied().sum::<Vec3>() / m.positions.len() as f32;
        for m in [plus, minus] {
            let centre = c(m);
            let outward = m.positions.iter().zip(&m.normals).filter(|(p, n)| (**p - centre).dot(**n) > 0.0).count();
            assert!(outward as f64 > 0.97 * m.positions.len() as f64);
        }
        assert!(extract(&grid, &Level::pair(10.0, true)).iter().all(Mesh::is_empty));
    }
}
