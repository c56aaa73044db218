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

use glam::{DMat3, DVec3, Mat3, Vec3};
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
/// 5 triangles) and how many, and the mask of the edges it crosses.
struct FlatCase {
    edges: [u8; 15],
    count: u8,
    crossed: u16,
}

static FLAT_CASES: LazyLock<Vec<FlatCase>> = LazyLock::new(|| {
    CASES
        .iter()
        .map(|tris| {
            let mut edges = [0; 15];
            let mut crossed = 0u16;
            for (n, &e) in tris.iter().flatten().enumerate() {
                edges[n] = e;
                crossed |= 1 << e;
            }
            FlatCase { edges, count: (3 * tris.len()) as u8, crossed }
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

/// The field's gradient at grid points by central differences (one-sided at the borders), in
/// index space: ∇_world = J⁻ᵀ ∇_index (J the step vectors as columns), applied once per vertex
/// after interpolating along the edge.
struct Gradient<'a> {
    grid: &'a VolumeGrid,
    inv_t: Mat3,
}

impl Gradient<'_> {
    #[inline(always)]
    fn index_space(&self, p: [usize; 3]) -> Vec3 {
        let g = self.grid;
        let [nx, ny, nz] = g.dims;
        let v = &g.values;
        let at = (p[0] * ny + p[1]) * nz + p[2];
        if p[0] > 0 && p[0] + 1 < nx && p[1] > 0 && p[1] + 1 < ny && p[2] > 0 && p[2] + 1 < nz {
            // Interior (nearly every vertex): by index strides.
            let (sx, sy) = (ny * nz, nz);
            return 0.5 * Vec3::new(v[at + sx] - v[at - sx], v[at + sy] - v[at - sy], v[at + 1] - v[at - 1]);
        }
        let mut d = Vec3::ZERO;
        for a in 0..3 {
            let (mut lo, mut hi) = (p, p);
            lo[a] = p[a].saturating_sub(1);
            hi[a] = (p[a] + 1).min(g.dims[a] - 1);
            let span = (hi[a] - lo[a]).max(1) as f32;
            d[a] = (g.value(hi[0], hi[1], hi[2]) - g.value(lo[0], lo[1], lo[2])) / span;
        }
        d
    }
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
    let gradient = Gradient { grid, inv_t: jac.inverse().transpose().as_mat3() };
    // A few runs per thread balance the load (one run when there is one thread: nothing to
    // merge); within a run, consecutive slabs share a plane's flags and the vertices on it.
    let slabs = nx - 1;
    let threads = rayon::current_num_threads();
    let runs = if threads == 1 { 1 } else { (4 * threads).clamp(1, slabs) };
    let mut parts: Vec<Vec<Mesh>> = (0..runs)
        .into_par_iter()
        .map(|r| {
            let mut run = Run::new(grid, &gradient, levels);
            for i in r * slabs / runs..(r + 1) * slabs / runs {
                run.slab(i);
            }
            run.meshes
        })
        .collect();
    if let [part] = parts.as_mut_slice() {
        let mut meshes = std::mem::take(part);
        meshes.iter_mut().for_each(|m| m.normals.iter_mut().for_each(|n| *n = n.normalize_or_zero()));
        return meshes;
    }
    (0..levels.len()).map(|l| merge(parts.iter().map(|p| &p[l]).collect())).collect()
}

/// The runs' pieces of one level's mesh joined in order, each copied in parallel into its place
/// in the whole (no reallocation on the way), its normals made unit on the way.
fn merge(pieces: Vec<&Mesh>) -> Mesh {
    let mut mesh = Mesh {
        positions: bytemuck::zeroed_vec(pieces.iter().map(|p| p.positions.len()).sum()),
        normals: bytemuck::zeroed_vec(pieces.iter().map(|p| p.normals.len()).sum()),
        indices: vec![0; pieces.iter().map(|p| p.indices.len()).sum()],
        colors: Vec::new(),
    };
    let positions = split(&mut mesh.positions, pieces.iter().map(|p| p.positions.len()));
    let normals = split(&mut mesh.normals, pieces.iter().map(|p| p.normals.len()));
    let indices = split(&mut mesh.indices, pieces.iter().map(|p| p.indices.len()));
    let bases = pieces.iter().scan(0u32, |base, p| {
        let first = *base;
        *base += p.positions.len() as u32;
        Some(first)
    });
    let jobs: Vec<_> = pieces.iter().zip(bases).zip(positions.into_iter().zip(normals).zip(indices)).collect();
    jobs.into_par_iter().for_each(|((piece, base), ((positions, normals), indices))| {
        positions.copy_from_slice(&piece.positions);
        for (n, g) in normals.iter_mut().zip(&piece.normals) {
            *n = g.normalize_or_zero();
        }
        for (i, &p) in indices.iter_mut().zip(&piece.indices) {
            *i = p + base;
        }
    });
    mesh
}

/// `all` cut into consecutive pieces of the given lengths.
fn split<T>(mut all: &mut [T], lengths: impl Iterator<Item = usize>) -> Vec<&mut [T]> {
    lengths
        .map(|n| {
            let (piece, rest) = std::mem::take(&mut all).split_at_mut(n);
            all = rest;
            piece
        })
        .collect()
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
        self.points.clear();
        self.points.resize(values.len(), 0);
        // One simple loop per level vectorises; a loop over levels inside would not. An
        // orbital's ± pair, the usual case, gets one loop for both: one read of the plane.
        if let [a, b] = levels {
            for (bits, &v) in self.points.iter_mut().zip(values) {
                *bits = u8::from(a.sign * v > a.value) | u8::from(b.sign * v > b.value) << 1;
            }
        } else {
            for (l, level) in levels.iter().enumerate() {
                for (bits, &v) in self.points.iter_mut().zip(values) {
                    *bits |= u8::from(level.sign * v > level.value) << l;
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
                    let left = row.windows(2).position(|w| w[0] != w[1]).unwrap_or(nz - 1);
                    (left, row.windows(2).rposition(|w| w[0] != w[1]).map_or(0, |k| k + 1))
                }
            };
            self.left.push(left as u32);
            self.right.push(right as u32);
        }
    }
}

/// 1 in every byte of a u64.
const BYTES: u64 = 0x0101_0101_0101_0101;
/// Multiplying bytes of 0 or 1 by this gathers byte c into bit c of the top byte.
const GATHER: u64 = 0x0102_0408_1020_4080;

/// Per cell k in start..end of a row of cells (corner rows `rows[dx][dy]`), the levels whose
/// flags differ among its eight corners (bit L: level L crosses it); byte-wide loops that
/// vectorise, in place of a test per cell.
fn mixed_cells(rows: [[&[u8]; 2]; 2], start: usize, end: usize, columns: &mut [Vec<u8>; 2], mixed: &mut Vec<u8>) {
    let span = |dx: usize, dy: usize| &rows[dx][dy][start..=end];
    let (a, b, c, d) = (span(0, 0), span(1, 0), span(0, 1), span(1, 1));
    let [any, all] = columns;
    any.clear();
    any.extend(a.iter().zip(b).zip(c).zip(d).map(|(((a, b), c), d)| a | b | c | d));
    all.clear();
    all.extend(a.iter().zip(b).zip(c).zip(d).map(|(((a, b), c), d)| a & b & c & d));
    mixed.clear();
    mixed.extend(
        any.iter().zip(&any[1..]).zip(all.iter().zip(&all[1..])).map(|((o0, o1), (a0, a1))| (o0 | o1) ^ (a0 & a1)),
    );
}

/// A vertex made on an edge, valid while its stamp (which row of which plane) matches: the
/// cache is never cleared, only overwritten.
#[derive(Clone, Copy)]
struct Cached {
    stamp: u32,
    vertex: u32,
}

/// Vertices made on the edges of the two rows of cells around the current one, per level:
/// x edges (between planes i and i + 1) by row parity, y and z edges by plane parity (shared
/// with the next slab) and, for z, row parity.
struct EdgeCache {
    x: Vec<Cached>,
    y: Vec<Cached>,
    z: Vec<Cached>,
}

/// Consecutive slabs extracted by one thread.
struct Run<'a> {
    grid: &'a VolumeGrid,
    gradient: &'a Gradient<'a>,
    levels: &'a [Level],
    meshes: Vec<Mesh>,
    caches: Vec<EdgeCache>,
    /// Flags of the slab's two planes, and which plane the second one is.
    flags: [PlaneFlags; 2],
    flagged: Option<usize>,
    /// Scratch for a row of cells: per point the OR and AND of its column of four flags, and per
    /// cell the levels crossing it.
    columns: [Vec<u8>; 2],
    mixed: Vec<u8>,
    /// The static tables, dereferenced once.
    cases: &'static [FlatCase],
    edges: [(usize, usize, usize); 12],
}

impl<'a> Run<'a> {
    fn new(grid: &'a VolumeGrid, gradient: &'a Gradient<'a>, levels: &'a [Level]) -> Self {
        let nz = grid.dims[2];
        let empty = Cached { stamp: u32::MAX, vertex: 0 };
        let cache = || EdgeCache { x: vec![empty; 2 * nz], y: vec![empty; 2 * nz], z: vec![empty; 4 * nz] };
        Self {
            grid,
            gradient,
            levels,
            meshes: vec![Mesh::default(); levels.len()],
            caches: (0..levels.len()).map(|_| cache()).collect(),
            flags: Default::default(),
            flagged: None,
            columns: Default::default(),
            mixed: Vec::new(),
            cases: &FLAT_CASES,
            edges: *EDGES,
        }
    }

    /// The cells between planes i and i + 1.
    fn slab(&mut self, i: usize) {
        let [_, ny, nz] = self.grid.dims;
        if self.flagged == Some(i) {
            self.flags.swap(0, 1);
        } else {
            self.flags[0].classify(self.grid, self.levels, i);
        }
        self.flags[1].classify(self.grid, self.levels, i + 1);
        self.flagged = Some(i + 1);
        let flags = std::mem::take(&mut self.flags);
        for j in 0..ny - 1 {
            let points = [&flags[0].points, &flags[1].points];
            let rows = [
                [&points[0][j * nz..(j + 1) * nz], &points[0][(j + 1) * nz..(j + 2) * nz]],
                [&points[1][j * nz..(j + 1) * nz], &points[1][(j + 1) * nz..(j + 2) * nz]],
            ];
            // Before every row's first change (after every row's last) the four rows are
            // constant: those cells are crossed only when the rows' flags differ there.
            let ends = |f: &dyn Fn(&PlaneFlags, usize) -> u32| {
                [f(&flags[0], j), f(&flags[0], j + 1), f(&flags[1], j), f(&flags[1], j + 1)]
            };
            let same_at = |k: usize| rows.iter().flatten().all(|r| r[k] == rows[0][0][k]);
            let start = if same_at(0) { *ends(&|p, r| p.left[r]).iter().min().unwrap_or(&0) as usize } else { 0 };
            let end =
                if same_at(nz - 1) { *ends(&|p, r| p.right[r]).iter().max().unwrap_or(&0) as usize } else { nz - 1 };
            if start >= end {
                continue;
            }
            let mut mixed = std::mem::take(&mut self.mixed);
            mixed_cells(rows, start, end, &mut self.columns, &mut mixed);
            // Most cells in the span are inside or outside everything: skip them eight at a time.
            for (q, chunk) in mixed.chunks(8).enumerate() {
                if chunk.len() == 8 && u64::from_le_bytes(chunk.try_into().unwrap_or_default()) == 0 {
                    continue;
                }
                for (n, &levels) in chunk.iter().enumerate().filter(|(_, m)| **m != 0) {
                    let k = start + 8 * q + n;
                    // Corner c of cell k is rows[c & 1][c >> 1 & 1][k + (c >> 2)].
                    let flag = |c: usize| rows[c & 1][(c >> 1) & 1][k + (c >> 2)];
                    self.cell([i, j, k], u64::from_le_bytes(std::array::from_fn(flag)), levels);
                }
            }
            self.mixed = mixed;
        }
        self.flags = flags;
    }

    /// The triangles of a crossed cell, for the levels whose bits are set in `levels`, from its
    /// corners' flags (byte c: corner c).
    fn cell(&mut self, cell: [usize; 3], word: u64, mut levels: u8) {
        while levels != 0 {
            let l = levels.trailing_zeros() as usize;
            levels &= levels - 1;
            // Bit l of each corner's flags gathered into the case's bit c.
            let case = (((word >> l) & BYTES).wrapping_mul(GATHER) >> 56) as usize;
            let flat = &self.cases[case];
            // Each crossed edge's vertex once, then the triangles by edge.
            let mut ids = [0u32; 12];
            let mut crossed = flat.crossed;
            while crossed != 0 {
                let e = crossed.trailing_zeros() as usize;
                ids[e] = self.vertex(l, cell, e);
                crossed &= crossed - 1;
            }
            let indices = &mut self.meshes[l].indices;
            indices.extend(flat.edges[..flat.count as usize].iter().map(|&e| ids[e as usize]));
        }
    }

    /// The vertex of level `l` on edge `e` of cell `cell`, made once.
    fn vertex(&mut self, l: usize, cell: [usize; 3], e: usize) -> u32 {
        let [_, ny, nz] = self.grid.dims;
        let (c0, c1, axis) = self.edges[e];
        let [dx, dy, dz] = corner(c0);
        let [i, j, k] = cell;
        let row = j + dy;
        let plane = i + dx;
        let cache = &mut self.caches[l];
        let (slot, stamp) = match axis {
            0 => (&mut cache.x[(row & 1) * nz + k + dz], i * ny + row),
            1 => (&mut cache.y[(plane & 1) * nz + k + dz], plane * ny + j),
            _ => (&mut cache.z[((plane & 1) * 2 + (row & 1)) * nz + k], plane * ny + row),
        };
        let stamp = stamp as u32;
        if slot.stamp == stamp {
            return slot.vertex;
        }
        let (grid, level) = (self.grid, self.levels[l]);
        let p0: [usize; 3] = std::array::from_fn(|a| cell[a] + corner(c0)[a]);
        let p1: [usize; 3] = std::array::from_fn(|a| cell[a] + corner(c1)[a]);
        let (v0, v1) = (level.sign * grid.value(p0[0], p0[1], p0[2]), level.sign * grid.value(p1[0], p1[1], p1[2]));
        let t = ((level.value - v0) / (v1 - v0)).clamp(0.0, 1.0);
        let mut g = DVec3::new(p0[0] as f64, p0[1] as f64, p0[2] as f64);
        g[axis] += t as f64;
        // Outside is where the signed field falls: the normal is −∇(sign·value), made unit when
        // the runs are joined (away from this loop's chain of dependent work).
        let grad = self.gradient.index_space(p0).lerp(self.gradient.index_space(p1), t);
        let mesh = &mut self.meshes[l];
        mesh.positions.push(grid.world_from_grid.transform_point3(g).as_vec3());
        mesh.normals.push(self.gradient.inv_t * grad * -level.sign);
        let vertex = (mesh.positions.len() - 1) as u32;
        *slot = Cached { stamp, vertex };
        vertex
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
