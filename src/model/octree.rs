//! Lee et al.'s hybrid point/polygon level of detail for big surfaces: a mesh's triangles binned
//! into an octree whose cells shrink to about an atom's size, empty cells dropped; per frame,
//! cells outside the view or facing away are skipped, a cell whose projected size falls under
//! a threshold is drawn as one point splat (its area-weighted centre and normal, sized so that
//! neighbours overlap), and nearer cells as their triangles.
//!
//! The triangles are reordered along a Morton curve of their centroids, so every cell holds a
//! contiguous run of them: drawing a cell's triangles is drawing one index range, and runs of
//! neighbouring cells merge into one range.

use std::ops::Range;

use glam::{Mat4, Vec3};
use rayon::prelude::*;

use super::isosurface::Mesh;

/// One cell: the box of its triangles, the run of triangles it holds, its children, and what a
/// splat standing for it needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Box of the cell's triangles (not of the octree cell): tight, for culling.
    pub lo: Vec3,
    pub hi: Vec3,
    /// Its triangles: `indices[3·start..3·end]` of the reordered mesh.
    pub triangles: (u32, u32),
    /// Children: `cells[first..first + count]` (count 0: a leaf).
    pub first_child: u32,
    pub child_count: u32,
    /// Area-weighted centre and unit normal of its triangles.
    pub centre: Vec3,
    pub normal: Vec3,
    /// Area-weighted mean of its vertices' colours (white for a one-colour mesh).
    pub color: Vec3,
    /// Cosine of the widest angle between `normal` and a triangle's normal (−1: any way).
    pub cone: f32,
    /// Length of the area-weighted mean of its triangles' unit normals: 1 for a flat cell, less
    /// the more they spread.
    pub flatness: f32,
}

impl Cell {
    /// Half the box's diagonal: a sphere around the centre of the box that holds the cell.
    pub fn radius(&self) -> f32 {
        0.5 * (self.hi - self.lo).length()
    }
}

/// The octree of one mesh, with the mesh's triangles in cell order.
#[derive(Debug, Clone, Default)]
pub struct SurfaceOctree {
    /// Cell 0 is the root; every cell's children are contiguous.
    pub cells: Vec<Cell>,
    /// The mesh's indices reordered so each cell's triangles are contiguous.
    pub indices: Vec<u32>,
}

/// A point's radius as a fraction of its cell's (half its box's diagonal): smaller discs spill
/// less past the silhouette, and neighbours still overlap. Measured on the 10⁵-atom SES
/// (zoomed out 2×, 8 px): eye-facing discs of 1.0 gave a mean image difference of 3.5/255 and
/// of 0.6 2.2/255; discs across the cell's normal of 0.7 give 2.0/255, with fewer holes than
/// 0.6 and less spill than 0.8.
pub const SPLAT_RADIUS: f32 = 0.7;

/// A cell drawn as one point: where, which way it faces, and its radius (object units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Splat {
    pub centre: Vec3,
    pub radius: f32,
    /// The mean of its triangles' unit normals (shorter than 1 where they spread: the shading
    /// averages over them).
    pub normal: Vec3,
    pub color: Vec3,
}

/// The camera as the selection needs it.
#[derive(Debug, Clone, Copy)]
pub struct LodView {
    pub clip_from_object: Mat4,
    /// The eye in the mesh's frame.
    pub eye: Vec3,
    /// Viewport height in pixels.
    pub height_px: f32,
    /// A cell whose projected size is under this many pixels is drawn as a point.
    pub threshold_px: f32,
    /// Skip cells whose triangles all face away from the eye (closed surfaces only).
    pub back_faces: bool,
}

/// Most triangles a cluster holds: the topmost cells with at most this many are the units the
/// GPU's occlusion test keeps or drops whole. Smaller ones are culled more finely but each
/// costs a draw; measured on the 10⁵-atom SES (lavapipe), 128–1024 drew equally fast within
/// the runs' spread.
pub const CLUSTER_TRIANGLES: u32 = 256;

/// A run of triangles drawn together: neighbouring leaves of one cluster.
#[derive(Debug, Clone, PartialEq)]
pub struct Batch {
    pub triangles: Range<u32>,
    /// Box of the leaves it holds.
    pub lo: Vec3,
    pub hi: Vec3,
    /// The cluster's cell: stays the same from frame to frame while the leaves drawn of it
    /// change, so the GPU can remember which were seen.
    pub cluster: u32,
}

impl LodView {
    /// Pixels per object unit at clip w = 1: the projection's y scale times half the height
    /// (Size = r·(n/z_eye)·(h/(t − b)), Lee et al.).
    pub fn px_per_unit(&self) -> f32 {
        let m = self.clip_from_object;
        Vec3::new(m.x_axis.y, m.y_axis.y, m.z_axis.y).length() * 0.5 * self.height_px
    }

    /// The coarsest of the versions whose errors (object units, growing) are given that this
    /// view shows under `max_px` pixels anywhere in the box `lo..hi`: measured at its nearest
    /// corner. 0 (the mesh itself) when the eye is in the box's plane or nearer.
    pub fn coarsest_within(&self, errors: impl IntoIterator<Item = f32>, (lo, hi): (Vec3, Vec3), max_px: f32) -> usize {
        let nearest =
            box_corners(lo, hi).iter().map(|p| (self.clip_from_object * p.extend(1.0)).w).fold(f32::INFINITY, f32::min);
        if nearest <= 0.0 {
            return 0;
        }
        let px_per_unit = self.px_per_unit() / nearest;
        errors.into_iter().take_while(|e| e * px_per_unit <= max_px).count().saturating_sub(1)
    }
}

/// One level of a surface's detail: the octree of a version of its mesh (the mesh itself
/// first, then coarser ones) and that version's error against the mesh
/// ([`super::simplify::Simplified::error`]).
#[derive(Debug, Clone, Default)]
pub struct LodLevel {
    pub tree: SurfaceOctree,
    pub error: f32,
}

impl LodLevel {
    /// `mesh`'s own octree, then its coarser versions' ([`super::simplify::levels`]: `versions`
    /// at most, each keeping `keep` of the previous one's triangles, within `max_error`), cells
    /// of `leaf_size`. The versions are made while the mesh's own tree is built.
    pub fn all(mesh: &Mesh, leaf_size: f32, (keep, max_error, versions): (f32, f32, usize)) -> Vec<LodLevel> {
        let (own, coarser) = rayon::join(
            || SurfaceOctree::build(mesh, leaf_size),
            || super::simplify::levels(mesh, keep, max_error, versions),
        );
        let mut levels = vec![LodLevel { tree: own, error: 0.0 }];
        levels.par_extend(
            coarser
                .into_par_iter()
                .map(|v| LodLevel { tree: SurfaceOctree::build_with(mesh, &v.indices, leaf_size), error: v.error }),
        );
        levels
    }
}

/// What one frame draws of a mesh.
#[derive(Debug, Clone, Default)]
pub struct Selection {
    /// Triangle runs, merged where they touch within a cluster.
    pub batches: Vec<Batch>,
    pub splats: Vec<Splat>,
    /// Triangles drawn, cells visited.
    pub triangles: u32,
    pub visited: u32,
}

/// A cell's contents summed: its triangles' box, area-weighted centre, normal and colour, their
/// area and the cosine of the normal cone.
#[derive(Debug, Clone, Copy)]
struct Sums {
    lo: Vec3,
    hi: Vec3,
    centre: Vec3,
    normal: Vec3,
    color: Vec3,
    area: f32,
    cone: f32,
}

impl Default for Sums {
    fn default() -> Self {
        let zero = Vec3::ZERO;
        Self {
            lo: Vec3::INFINITY,
            hi: Vec3::NEG_INFINITY,
            centre: zero,
            normal: zero,
            color: zero,
            area: 0.0,
            cone: -1.0,
        }
    }
}

impl Sums {
    /// A parent's sums from its children's; its cone holds every child's cone (a cone of
    /// half-angle a around n_c lies within ∠(n, n_c) + a of the parent's normal n).
    fn merge(children: &[Sums]) -> Sums {
        let mut out = Sums::default();
        for c in children {
            out.lo = out.lo.min(c.lo);
            out.hi = out.hi.max(c.hi);
            out.centre += c.centre;
            out.normal += c.normal;
            out.color += c.color;
            out.area += c.area;
        }
        let n = out.normal.normalize_or_zero();
        out.cone = if n == Vec3::ZERO {
            -1.0
        } else {
            let spread =
                |c: &Sums| c.normal.normalize_or_zero().dot(n).clamp(-1.0, 1.0).acos() + c.cone.clamp(-1.0, 1.0).acos();
            children
                .iter()
                .map(|c| if spread(c) >= std::f32::consts::PI { -1.0 } else { spread(c).cos() })
                .fold(1.0, f32::min)
        };
        out
    }
}

/// Most levels an octree gets (a Morton code of 3 × 10 bits).
const MAX_DEPTH: u32 = 10;

impl SurfaceOctree {
    /// Bins `mesh`'s triangles into cells split at their midpoints until a cell's side is at most
    /// `leaf_size` (an atom's size) or the tree is [`MAX_DEPTH`] deep; empty cells are never made.
    pub fn build(mesh: &Mesh, leaf_size: f32) -> Self {
        Self::build_with(mesh, &mesh.indices, leaf_size)
    }

    /// [`Self::build`] for other triangles over `mesh`'s vertices (a coarser version of it):
    /// the cells split the same box as the mesh's own tree.
    pub fn build_with(mesh: &Mesh, indices: &[u32], leaf_size: f32) -> Self {
        let n = indices.len() / 3;
        if n == 0 {
            return Self::default();
        }
        let tri = |t: usize| std::array::from_fn::<Vec3, 3, _>(|c| mesh.positions[indices[3 * t + c] as usize]);
        let (lo, hi) =
            mesh.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let side = (hi - lo).max_element().max(1e-6);
        let depth = ((side / leaf_size.max(1e-6)).log2().ceil().max(0.0) as u32).min(MAX_DEPTH);
        let scale = (1u32 << depth) as f32 / side;
        // Each triangle's Morton code at the leaves' level, then the triangles in that order.
        let mut keyed: Vec<(u32, u32)> = (0..n)
            .into_par_iter()
            .map(|t| {
                let [a, b, c] = tri(t);
                let cell = (((a + b + c) / 3.0 - lo) * scale).floor();
                let max = (1u32 << depth) - 1;
                let q = |v: f32| (v.max(0.0) as u32).min(max);
                (morton(q(cell.x), q(cell.y), q(cell.z)), t as u32)
            })
            .collect();
        keyed.par_sort_unstable();
        let indices: Vec<u32> =
            keyed.iter().flat_map(|&(_, t)| (0..3).map(move |c| indices[3 * t as usize + c])).collect();
        let codes: Vec<u32> = keyed.iter().map(|&(k, _)| k).collect();
        let mut tree = Self { cells: Vec::new(), indices };
        // Breadth first: a cell's children are made together, so they sit side by side, after
        // their parent. The cells' contents are summed afterwards, leaves first.
        let bare = |run: Range<u32>| Cell {
            lo: Vec3::INFINITY,
            hi: Vec3::NEG_INFINITY,
            triangles: (run.start, run.end),
            first_child: 0,
            child_count: 0,
            centre: Vec3::ZERO,
            normal: Vec3::ZERO,
            color: Vec3::ONE,
            cone: -1.0,
            flatness: 1.0,
        };
        tree.cells.push(bare(0..n as u32));
        let mut level = vec![(0usize, 0u32)]; // (cell, its depth)
        while !level.is_empty() {
            let mut next = Vec::new();
            for (cell, d) in level {
                if d >= depth {
                    continue;
                }
                let (start, end) = tree.cells[cell].triangles;
                // Children: runs of equal code prefix at depth d + 1.
                let shift = 3 * (depth - d - 1);
                let first = tree.cells.len() as u32;
                let mut s = start;
                while s < end {
                    let key = codes[s as usize] >> shift;
                    let e = s + codes[s as usize..end as usize].partition_point(|&c| c >> shift == key) as u32;
                    next.push((tree.cells.len(), d + 1));
                    tree.cells.push(bare(s..e));
                    s = e;
                }
                let count = tree.cells.len() as u32 - first;
                tree.cells[cell].first_child = first;
                tree.cells[cell].child_count = count;
            }
            level = next;
        }
        tree.summarise(&mesh.positions, &mesh.colors);
        tree
    }

    /// Fills every cell's box, centre, normal, colour and cone: each leaf from its triangles (in
    /// parallel), each parent from its children (children come after their parent).
    fn summarise(&mut self, positions: &[Vec3], colors: &[[f32; 3]]) {
        let indices = &self.indices;
        let corner = |t: usize, k: usize| positions[indices[3 * t + k] as usize];
        let leaves: Vec<(usize, Sums)> = (self.cells.par_iter().enumerate())
            .filter(|(_, c)| c.child_count == 0)
            .map(|(i, cell)| {
                let run = cell.triangles.0 as usize..cell.triangles.1 as usize;
                let mut sums = Sums::default();
                for t in run.clone() {
                    let [a, b, c] = [corner(t, 0), corner(t, 1), corner(t, 2)];
                    let cross = (b - a).cross(c - a);
                    let area = 0.5 * cross.length();
                    let tint = |k: usize| colors.get(indices[3 * t + k] as usize).map_or(Vec3::ONE, |&c| Vec3::from(c));
                    sums.lo = sums.lo.min(a).min(b).min(c);
                    sums.hi = sums.hi.max(a).max(b).max(c);
                    sums.centre += (a + b + c) / 3.0 * area;
                    sums.normal += cross * 0.5;
                    sums.color += (tint(0) + tint(1) + tint(2)) / 3.0 * area;
                    sums.area += area;
                }
                let normal = sums.normal.normalize_or_zero();
                sums.cone = if normal == Vec3::ZERO {
                    -1.0
                } else {
                    run.map(|t| {
                        (corner(t, 1) - corner(t, 0)).cross(corner(t, 2) - corner(t, 0)).normalize_or_zero().dot(normal)
                    })
                    .fold(1.0, f32::min)
                };
                (i, sums)
            })
            .collect();
        let mut sums = vec![Sums::default(); self.cells.len()];
        for (i, s) in leaves {
            sums[i] = s;
        }
        for i in (0..self.cells.len()).rev() {
            let cell = self.cells[i];
            if cell.child_count > 0 {
                let kids = cell.first_child as usize..(cell.first_child + cell.child_count) as usize;
                sums[i] = Sums::merge(&sums[kids]);
            }
            let s = &sums[i];
            let c = &mut self.cells[i];
            (c.lo, c.hi, c.normal, c.cone) = (s.lo, s.hi, s.normal.normalize_or_zero(), s.cone);
            c.flatness = if s.area > 0.0 { (s.normal.length() / s.area).min(1.0) } else { 1.0 };
            c.centre = if s.area > 0.0 { s.centre / s.area } else { 0.5 * (s.lo + s.hi) };
            c.color = if s.area > 0.0 { s.color / s.area } else { Vec3::ONE };
        }
    }

    /// What to draw this frame: cells in view, facing the eye (when asked), as points where they
    /// look smaller than the threshold and as triangles otherwise.
    pub fn select(&self, view: &LodView, out: &mut Selection) {
        out.batches.clear();
        out.splats.clear();
        out.triangles = 0;
        out.visited = 0;
        if self.cells.is_empty() {
            return;
        }
        let m = view.clip_from_object;
        let px_per_unit = view.px_per_unit();
        // (cell, its cluster: the topmost cell on its path with few enough triangles)
        let cluster_of = |c: u32, parent: Option<u32>| {
            let (s, e) = self.cells[c as usize].triangles;
            parent.or((e - s <= CLUSTER_TRIANGLES).then_some(c))
        };
        let mut stack = vec![(0u32, cluster_of(0, None))];
        while let Some((c, cluster)) = stack.pop() {
            out.visited += 1;
            let cell = &self.cells[c as usize];
            // Within a cluster a cell facing away stays: skipping it would split the cluster's
            // run into more draws, each costing more than the rasteriser's own culling of its
            // triangles (and the occlusion test hides a closed surface's far side whole).
            let within = cluster.is_some_and(|k| k != c);
            if outside_frustum(&m, cell.lo, cell.hi) || (view.back_faces && !within && faces_away(cell, view.eye)) {
                continue;
            }
            let centre = 0.5 * (cell.lo + cell.hi);
            let w = (m * centre.extend(1.0)).w;
            let r = cell.radius();
            let leaf = cell.child_count == 0;
            // Size on screen of the cell's diameter; a cell the eye is inside is never small.
            let size = if w > r { 2.0 * r * px_per_unit / w } else { f32::INFINITY };
            if size < view.threshold_px {
                // A point whose mean normal faces away shows little of a closed surface and
                // shades it darker than the front-facing triangles it stands for.
                if view.back_faces && cell.normal.dot(view.eye - cell.centre) < 0.0 {
                    continue;
                }
                let normal = cell.normal * cell.flatness;
                out.splats.push(Splat { centre: cell.centre, radius: r * SPLAT_RADIUS, normal, color: cell.color });
            } else if leaf {
                let (s, e) = cell.triangles;
                out.triangles += e - s;
                // A leaf under no small enough cell is its own cluster.
                let cluster = cluster.unwrap_or(c);
                match out.batches.last_mut() {
                    Some(last) if last.triangles.end == s && last.cluster == cluster => {
                        last.triangles.end = e;
                        (last.lo, last.hi) = (last.lo.min(cell.lo), last.hi.max(cell.hi));
                    }
                    _ => out.batches.push(Batch { triangles: s..e, lo: cell.lo, hi: cell.hi, cluster }),
                }
            } else {
                // Children pushed last first, so they pop in Morton order and their runs merge.
                for k in (0..cell.child_count).rev() {
                    let child = cell.first_child + k;
                    stack.push((child, cluster_of(child, cluster)));
                }
            }
        }
    }
}

/// The eight corners of the box `lo..hi` (bit 0 of the index picks x, bit 1 y, bit 2 z).
pub fn box_corners(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
    std::array::from_fn(|k| Vec3::new([lo.x, hi.x][k & 1], [lo.y, hi.y][(k >> 1) & 1], [lo.z, hi.z][k >> 2]))
}

/// Whether the box lies wholly outside one of the view's six clip planes.
fn outside_frustum(m: &Mat4, lo: Vec3, hi: Vec3) -> bool {
    let corners = box_corners(lo, hi).map(|p| *m * p.extend(1.0));
    let all = |f: &dyn Fn(&glam::Vec4) -> bool| corners.iter().all(f);
    all(&|c| c.x < -c.w)
        || all(&|c| c.x > c.w)
        || all(&|c| c.y < -c.w)
        || all(&|c| c.y > c.w)
        || all(&|c| c.z < 0.0)
        || all(&|c| c.z > c.w)
}

/// Whether every triangle of the cell faces away from `eye` seen from anywhere in its box:
/// the normals lie within the cone around `normal`, so the cell is hidden when the eye is
/// farther than the cone's half-angle beyond the back of each corner's tangent plane.
fn faces_away(cell: &Cell, eye: Vec3) -> bool {
    if cell.cone <= 0.0 {
        return false;
    }
    let sin = (1.0 - cell.cone * cell.cone).max(0.0).sqrt();
    box_corners(cell.lo, cell.hi).iter().all(|&corner| {
        let to_eye = (eye - corner).normalize_or_zero();
        cell.normal.dot(to_eye) < -sin
    })
}

/// Interleaves the bits of x, y, z (10 each): z highest, so sorting by it walks the octree.
fn morton(x: u32, y: u32, z: u32) -> u32 {
    fn spread(v: u32) -> u32 {
        let mut v = v & 0x3ff;
        v = (v | (v << 16)) & 0x030000ff;
        v = (v | (v << 8)) & 0x0300f00f;
        v = (v | (v << 4)) & 0x030c30c3;
        (v | (v << 2)) & 0x09249249
    }
    spread(x) | (spread(y) << 1) | (spread(z) << 2)
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::AtomicBool;

    use glam::DVec3;

    use super::*;
    use crate::model::surface::{self, Sphere, SurfaceKind, SurfaceParams};

    /// Two atoms' solvent-excluded surface, about 3000 triangles, 10 bohr across.
    fn mesh() -> Mesh {
        let spheres =
            [Sphere { centre: DVec3::ZERO, radius: 3.2 }, Sphere { centre: DVec3::new(5.0, 1.0, 0.0), radius: 3.0 }];
        let mut p = SurfaceParams::auto(SurfaceKind::SolventExcluded, &spheres);
        p.resolution = 0.6;
        surface::build(&spheres, &p, &AtomicBool::new(false)).unwrap().mesh
    }

    fn looking_at_origin(from: Vec3, height_px: f32, threshold_px: f32) -> LodView {
        let view = glam::camera::rh::view::look_at_mat4(from, Vec3::ZERO, Vec3::Y);
        let proj = glam::camera::rh::proj::directx::perspective(0.8, 1.0, 0.1, 1.0e5);
        LodView { clip_from_object: proj * view, eye: from, height_px, threshold_px, back_faces: false }
    }

    #[test]
    fn cells_hold_contiguous_runs_of_every_triangle_once() {
        let mesh = mesh();
        let tree = SurfaceOctree::build(&mesh, 2.0);
        let n = mesh.triangle_count() as u32;
        let mut tris: Vec<[u32; 3]> = tree.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        let mut original: Vec<[u32; 3]> = mesh.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        tris.sort_unstable();
        original.sort_unstable();
        assert_eq!(tris, original, "a permutation of the triangles");
        assert_eq!(tree.cells[0].triangles, (0, n));
        let mut leaves = 0;
        for cell in &tree.cells {
            let (s, e) = cell.triangles;
            assert!(e > s, "no empty cell");
            if cell.child_count == 0 {
                leaves += 1;
                continue;
            }
            let kids = &tree.cells[cell.first_child as usize..(cell.first_child + cell.child_count) as usize];
            assert!(kids.len() <= 8);
            assert_eq!(kids[0].triangles.0, s);
            assert_eq!(kids.last().unwrap().triangles.1, e);
            for pair in kids.windows(2) {
                assert_eq!(pair[0].triangles.1, pair[1].triangles.0, "children tile their parent's run");
            }
            for k in kids {
                assert!(k.lo.cmpge(cell.lo).all() && k.hi.cmple(cell.hi).all(), "a child's box lies in its parent's");
            }
        }
        // Leaves are about the asked size: their triangles' centroids fit in a 2-bohr cell.
        assert!(leaves > 20, "{leaves} leaves");
        for cell in tree.cells.iter().filter(|c| c.child_count == 0) {
            let (s, e) = cell.triangles;
            let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            for t in s..e {
                let c = (0..3).map(|k| mesh.positions[tree.indices[3 * t as usize + k] as usize]).sum::<Vec3>() / 3.0;
                lo = lo.min(c);
                hi = hi.max(c);
            }
            assert!((hi - lo).max_element() <= 2.0 + 1e-4, "leaf spans {}", (hi - lo).max_element());
        }
    }

    #[test]
    fn near_cells_draw_triangles_far_ones_points_and_nothing_outside_the_view() {
        let mesh = mesh();
        let tree = SurfaceOctree::build(&mesh, 2.0);
        let n = mesh.triangle_count() as u32;
        let mut sel = Selection::default();
        // No threshold: every triangle, in runs that tile the mesh, one cluster each; each
        // batch's box holds its triangles.
        tree.select(&looking_at_origin(Vec3::new(0.0, 0.0, 40.0), 600.0, 0.0), &mut sel);
        assert_eq!((sel.triangles, sel.splats.len()), (n, 0));
        assert_eq!((sel.batches[0].triangles.start, sel.batches.last().unwrap().triangles.end), (0, n));
        for pair in sel.batches.windows(2) {
            assert_eq!(pair[0].triangles.end, pair[1].triangles.start);
            assert_ne!(pair[0].cluster, pair[1].cluster, "touching runs of one cluster merge");
        }
        for b in &sel.batches {
            let cluster = &tree.cells[b.cluster as usize];
            assert!(b.triangles.start >= cluster.triangles.0 && b.triangles.end <= cluster.triangles.1);
            assert!(cluster.triangles.1 - cluster.triangles.0 <= CLUSTER_TRIANGLES || cluster.child_count == 0);
            for k in 3 * b.triangles.start as usize..3 * b.triangles.end as usize {
                let p = mesh.positions[tree.indices[k] as usize];
                assert!(p.cmpge(b.lo).all() && p.cmple(b.hi).all(), "vertex {p} outside its batch's box");
            }
        }
        assert!(sel.batches.len() >= (n / CLUSTER_TRIANGLES) as usize, "{} batches", sel.batches.len());
        // Far away: the whole surface is a few pixels, one point.
        tree.select(&looking_at_origin(Vec3::new(0.0, 0.0, 4000.0), 600.0, 3.0), &mut sel);
        assert_eq!((sel.triangles, sel.splats.len()), (0, 1));
        assert!((sel.splats[0].radius - SPLAT_RADIUS * tree.cells[0].radius()).abs() < 1e-4, "{:?}", sel.splats[0]);
        assert!(tree.cells[0].radius() > 5.0 && tree.cells[0].radius() < 12.0, "{:?}", tree.cells[0]);
        // In between: some of each, and the points stand for what the triangles leave out.
        tree.select(&looking_at_origin(Vec3::new(0.0, 0.0, 150.0), 600.0, 8.0), &mut sel);
        assert!(
            sel.triangles < n && !sel.splats.is_empty(),
            "{} triangles, {} points",
            sel.triangles,
            sel.splats.len()
        );
        // Looking away: nothing.
        let mut away = looking_at_origin(Vec3::new(0.0, 0.0, 40.0), 600.0, 0.0);
        away.clip_from_object = glam::camera::rh::proj::directx::perspective(0.8, 1.0, 0.1, 1.0e5)
            * glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.0, 40.0), Vec3::new(0.0, 0.0, 80.0), Vec3::Y);
        tree.select(&away, &mut sel);
        assert_eq!((sel.triangles, sel.splats.len()), (0, 0));
    }

    #[test]
    fn the_coarsest_version_whose_error_shows_under_the_limit_is_drawn() {
        let errors = [0.0, 0.1, 0.2, 0.4, 0.8];
        let unit_box = (Vec3::splat(-1.0), Vec3::splat(1.0));
        let at = |z: f32| looking_at_origin(Vec3::new(0.0, 0.0, z), 600.0, 0.0);
        for z in [5.0f32, 50.0, 500.0, 5000.0] {
            let view = at(z);
            // Pixels per unit at the box's nearest corner (its w is the distance to the face).
            let px = view.px_per_unit() / (z - 1.0);
            let level = view.coarsest_within(errors, unit_box, 0.5);
            assert!(errors[level] * px <= 0.5, "z {z}: level {level}");
            if level + 1 < errors.len() {
                assert!(errors[level + 1] * px > 0.5, "z {z}: level {level} is not the coarsest");
            }
        }
        assert_eq!(at(5.0).coarsest_within(errors, unit_box, 0.5), 0);
        assert_eq!(at(500.0).coarsest_within(errors, unit_box, 0.5), 2);
        assert_eq!(at(5000.0).coarsest_within(errors, unit_box, 0.5), 4);
        // The eye inside the box: the mesh itself.
        assert_eq!(at(0.5).coarsest_within(errors, unit_box, 100.0), 0);
    }

    #[test]
    fn back_facing_cells_of_a_closed_surface_are_skipped() {
        let mesh = mesh();
        let tree = SurfaceOctree::build(&mesh, 1.0);
        let mut view = looking_at_origin(Vec3::new(0.0, 0.0, 40.0), 600.0, 0.0);
        view.back_faces = true;
        let mut sel = Selection::default();
        tree.select(&view, &mut sel);
        let n = mesh.triangle_count() as u32;
        // Cells within a cluster are drawn whatever way they face (one draw for the cluster),
        // so only whole clusters facing away are skipped.
        assert!(sel.triangles < n * 9 / 10 && sel.triangles > n / 3, "{} of {n}", sel.triangles);
        // Every triangle left out faces away from the eye.
        let mut drawn = vec![false; n as usize];
        for b in &sel.batches {
            for t in b.triangles.clone() {
                drawn[t as usize] = true;
            }
        }
        for (t, _) in drawn.iter().enumerate().filter(|(_, d)| !**d) {
            let [a, b, c] = std::array::from_fn::<Vec3, 3, _>(|k| mesh.positions[tree.indices[3 * t + k] as usize]);
            let normal = (b - a).cross(c - a);
            assert!(normal.dot(view.eye - a) < 0.0, "triangle {t} faces the eye but was skipped");
        }
    }
}
