//! Empty space skipped: slices cut only through the bricks of a grid where the transfer
//! function in use can show something. The planes stay those of the whole box, so the picture
//! is the same; what is left out are fragments every program would discard. On a CPU
//! rasteriser the time is that of the fragments drawn, so less area is what pays.

use glam::{DVec3, Vec3};

use super::opacity::visibility_threshold;
use super::slicing::{GridBox, Slices, hull_triangles};
use super::{DensityScale, SliceMode, TransferKind, VolumeSettings};
use crate::model::bricks::BrickRanges;

/// Values within this fraction below the floor still count as visible: textures of half
/// floats round values by up to 2⁻¹¹.
const MARGIN: f32 = 0.01;

/// The smallest value (in the grid's units; |value| for a signed field) that `settings` can
/// show, for a grid whose largest |value| is `max_abs`; None when any value may be seen (a
/// transfer function with opacity near zero), so nothing can be skipped.
pub fn visible_floor(settings: &VolumeSettings, signed: bool, max_abs: f32) -> Option<f32> {
    // The smallest t the shader's `transfer_value` must give (|t| for a signed field).
    let t = match settings.transfer.kind {
        TransferKind::PowerLaw => visibility_threshold(settings.k1, settings.k2, signed),
        TransferKind::Shaped => settings.transfer.lowest_visible(signed),
    };
    if t.is_nan() || t <= 0.0 {
        return None;
    }
    let value = match (signed, settings.density_scale) {
        (false, DensityScale::Log { .. }) => {
            let (lo, inv_span) = settings.density_scale.log_uniforms();
            if inv_span <= 0.0 {
                return None;
            }
            10f32.powf(lo + t / inv_span)
        }
        _ => t * max_abs,
    };
    (value > 0.0).then_some(value * (1.0 - MARGIN))
}

/// Which occupied cells of a `dims` block (x slowest) touch an empty one or the block's
/// outside, counting the 26 around each.
fn on_surface(occupied: &[bool], dims: [usize; 3]) -> Vec<bool> {
    let at = |i: usize, j: usize, k: usize| occupied[(i * dims[1] + j) * dims[2] + k];
    let mut surface = vec![false; occupied.len()];
    for i in 0..dims[0] {
        for j in 0..dims[1] {
            for k in 0..dims[2] {
                let cell = (i * dims[1] + j) * dims[2] + k;
                if !occupied[cell] {
                    continue;
                }
                let edge = [i, j, k].iter().zip(dims).any(|(&c, n)| c == 0 || c + 1 == n);
                surface[cell] =
                    edge || (i - 1..=i + 1).any(|a| (j - 1..=j + 1).any(|b| (k - 1..=k + 1).any(|c| !at(a, b, c))));
            }
        }
    }
    surface
}

/// The slices' box cut along brick boundaries into cells, and which cells hold a visible value.
#[derive(Debug, Clone, PartialEq)]
pub struct Occupancy {
    /// Where the cuts fall along each of the box's edges, as fractions (0 first, 1 last).
    cuts: [Vec<f32>; 3],
    /// Per cell, x slowest.
    occupied: Vec<bool>,
    /// Occupied cells with an empty cell or the box's outside among their 26 neighbours.
    surface: Vec<bool>,
}

impl Occupancy {
    /// The cells of `grid_box` (a box of the bricks' grid, edges along its axes) and which of
    /// them lie in a brick of `bricks` flagged in `occupied`. None where the box does not follow
    /// the grid's axes.
    pub fn new(grid_box: &GridBox, bricks: &BrickRanges, occupied: &[bool]) -> Option<Self> {
        if occupied.len() != bricks.ranges.len() {
            return None;
        }
        let grid_from_world = bricks.world_from_grid.inverse();
        let origin = grid_box.origin.as_dvec3();
        let lo = grid_from_world.transform_point3(origin);
        let mut cuts: [Vec<f32>; 3] = Default::default();
        let mut brick_of: [Vec<usize>; 3] = Default::default();
        for a in 0..3 {
            let along = grid_from_world.transform_vector3(grid_box.edges[a].as_dvec3());
            let length = along[a];
            let off_axis =
                (along - DVec3::from_array(std::array::from_fn(|b| if b == a { length } else { 0.0 }))).length();
            if length <= 1e-9 || off_axis > 1e-4 * length {
                return None;
            }
            let (start, end) = (lo[a], lo[a] + length);
            let edge = bricks.edge as f64;
            let mut points = vec![start];
            let first = (start / edge).floor() as i64 + 1;
            points.extend(
                (first..).map(|b| b as f64 * edge).take_while(|&c| c < end - 1e-6).filter(|&c| c > start + 1e-6),
            );
            points.push(end);
            cuts[a] = points.iter().map(|&c| ((c - start) / length) as f32).collect();
            cuts[a][0] = 0.0;
            *cuts[a].last_mut()? = 1.0;
            let last = bricks.counts[a] - 1;
            brick_of[a] =
                points.windows(2).map(|w| (((w[0] + w[1]) * 0.5 / edge).floor().max(0.0) as usize).min(last)).collect();
        }
        let mut flags = Vec::with_capacity(brick_of.iter().map(Vec::len).product());
        for &bi in &brick_of[0] {
            for &bj in &brick_of[1] {
                for &bk in &brick_of[2] {
                    flags.push(occupied[bricks.index([bi, bj, bk])]);
                }
            }
        }
        let surface = on_surface(&flags, brick_of.each_ref().map(Vec::len));
        Some(Self { cuts, occupied: flags, surface })
    }

    /// The box around the occupied cells, as fractions of the edges (lo, hi); `None` when no
    /// cell is.
    pub fn occupied_bounds(&self) -> Option<([f32; 3], [f32; 3])> {
        let [ni, nj, nk] = self.cuts.each_ref().map(|c| c.len() - 1);
        let mut bounds: Option<([f32; 3], [f32; 3])> = None;
        for (n, _) in self.occupied.iter().enumerate().filter(|(_, o)| **o) {
            let cell = [n / (nj * nk), (n / nk) % nj, n % nk];
            debug_assert!(cell[0] < ni);
            let lo: [f32; 3] = std::array::from_fn(|a| self.cuts[a][cell[a]]);
            let hi: [f32; 3] = std::array::from_fn(|a| self.cuts[a][cell[a] + 1]);
            bounds = Some(match bounds {
                None => (lo, hi),
                Some((l, h)) => (std::array::from_fn(|a| l[a].min(lo[a])), std::array::from_fn(|a| h[a].max(hi[a]))),
            });
        }
        bounds
    }

    /// Whether every cell is occupied (skipping would only add triangles).
    pub fn is_full(&self) -> bool {
        self.occupied.iter().all(|&o| o)
    }

    /// The slices [`GridBox::slices`] cuts from `grid_box` (the box this was made for), each cut
    /// down to the convex hull of its section through the occupied cells: the same planes,
    /// `starts` and `nearest`, one convex polygon per plane (no seams inside a slice, few
    /// triangles), covering every fragment that can be seen.
    pub fn slices(&self, grid_box: &GridBox, mode: SliceMode, count: u32, eye: Vec3, view_dir: Vec3) -> Slices {
        let whole = grid_box.slices(mode, count, eye, view_dir);
        let planes = whole.starts.len();
        let n = whole.normal;
        let [ni, nj, nk] = self.cuts.each_ref().map(Vec::len);
        let e = grid_box.edges;
        let mut points = Vec::with_capacity(ni * nj * nk);
        for &a in &self.cuts[0] {
            for &b in &self.cuts[1] {
                for &c in &self.cuts[2] {
                    points.push(grid_box.origin + e[0] * a + e[1] * b + e[2] * c);
                }
            }
        }
        let depths: Vec<f32> = points.iter().map(|p| p.dot(n)).collect();
        let point = |i: usize, j: usize, k: usize| (i * nj + j) * nk + k;
        // Each cell on the occupied region's surface in the buckets of the planes that may
        // cross it (back to front); cells inside it add nothing to a hull.
        let mut buckets: Vec<Vec<[usize; 8]>> = vec![Vec::new(); planes];
        let spacing = whole.spacing.max(1e-30);
        for (cell, _) in self.surface.iter().enumerate().filter(|(_, s)| **s) {
            let (i, j, k) = (cell / ((nj - 1) * (nk - 1)), (cell / (nk - 1)) % (nj - 1), cell % (nk - 1));
            // Corner c has bit 0 for x, 1 for y, 2 for z, as GridBox::corners.
            let corners: [usize; 8] = std::array::from_fn(|c| point(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2)));
            let (lo, hi) = corners
                .iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &c| (l.min(depths[c]), h.max(depths[c])));
            // Plane j from the front lies at nearest + j·spacing; one more either side for
            // rounding (the cut below finds nothing where none crosses).
            let first = ((lo - whole.nearest) / spacing).floor() as i64 - 1;
            let last = ((hi - whole.nearest) / spacing).ceil() as i64 + 1;
            for front in first.max(0)..=last.min(planes as i64 - 1) {
                buckets[planes - 1 - front as usize].push(corners);
            }
        }
        let (bu, bv) = n.any_orthonormal_pair();
        let mut vertices = Vec::new();
        let mut starts = Vec::with_capacity(planes);
        let mut section = Vec::new();
        for (back, cells) in buckets.iter().enumerate() {
            starts.push(vertices.len() as u32);
            let d = whole.depths[back];
            section.clear();
            for corners in cells {
                for &(a, b) in &GridBox::EDGES {
                    let (pa, pb) = (corners[a], corners[b]);
                    let (da, db) = (depths[pa] - d, depths[pb] - d);
                    if (da < 0.0) != (db < 0.0) {
                        section.push(points[pa].lerp(points[pb], da / (da - db)));
                    }
                }
            }
            hull_triangles(&mut section, bu, bv, &mut vertices);
        }
        Slices { vertices, starts, ..whole }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::VolumeGrid;
    use glam::DMat4;

    fn area(tris: &[Vec3]) -> f32 {
        tris.chunks(3).map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()).sum()
    }

    /// A 33³ grid of spacing 0.5 with one bright spot at its centre.
    fn spot() -> VolumeGrid {
        let n = 33;
        let world_from_grid = DMat4::from_scale(DVec3::splat(0.5));
        let values = (0..n * n * n)
            .map(|p| {
                let (i, j, k) = (p / (n * n), (p / n) % n, p % n);
                let r2 = [i, j, k].iter().map(|&c| (c as f32 - 16.0).powi(2)).sum::<f32>();
                (-r2 / 8.0).exp()
            })
            .collect();
        VolumeGrid::new("spot", [n; 3], world_from_grid, values)
    }

    #[test]
    fn slices_over_occupied_bricks_keep_the_planes_and_cover_less() {
        let grid = spot();
        let bricks = BrickRanges::of(&grid, 8);
        let grid_box = GridBox { origin: Vec3::ZERO, edges: [Vec3::X * 16.0, Vec3::Y * 16.0, Vec3::Z * 16.0] };
        let occupied = bricks.occupied(0.01, true);
        let occupancy = Occupancy::new(&grid_box, &bricks, &occupied).unwrap();
        assert!(!occupancy.is_full());
        for (mode, view) in
            [(SliceMode::ViewAligned, Vec3::new(0.3, -0.5, -1.0)), (SliceMode::AxisAligned, Vec3::NEG_Z)]
        {
            let eye = Vec3::splat(8.0) - 40.0 * view.normalize();
            let whole = grid_box.slices(mode, 40, eye, view);
            let some = occupancy.slices(&grid_box, mode, 40, eye, view);
            assert_eq!((some.normal, some.spacing, some.nearest), (whole.normal, whole.spacing, whole.nearest));
            assert_eq!(some.starts.len(), whole.starts.len());
            // The spot (values ≥ 0.01 within 6 points of the centre) lies in the middle 2³
            // bricks: an eighth of the box.
            assert!(area(&some.vertices) < 0.2 * area(&whole.vertices), "{mode:?}");
            for v in &some.vertices {
                assert!(v.cmpge(Vec3::splat(4.0 - 1e-3)).all() && v.cmple(Vec3::splat(12.0 + 1e-3)).all(), "{v}");
            }
            // Every slice covers the whole plane's cut through the middle bricks (a convex
            // region, which is its own hull): their area is the cut's.
            let middle = GridBox { origin: Vec3::splat(4.0), edges: [Vec3::X * 8.0, Vec3::Y * 8.0, Vec3::Z * 8.0] };
            for (s, &start) in some.starts.iter().enumerate() {
                let end = some.starts.get(s + 1).map_or(some.vertices.len(), |&e| e as usize);
                let mut cut = Vec::new();
                middle.cut(some.normal, some.depths[s], &mut cut);
                assert!((area(&some.vertices[start as usize..end]) - area(&cut)).abs() < 1e-3, "slice {s}");
            }
        }
        // All occupied: nothing to skip.
        let all = Occupancy::new(&grid_box, &bricks, &vec![true; bricks.ranges.len()]).unwrap();
        assert!(all.is_full());
    }

    #[test]
    fn the_floor_follows_the_transfer_function() {
        let mut s = VolumeSettings::default();
        let power = visible_floor(&s, true, 2.0).unwrap();
        assert!((power - 2.0 * visibility_threshold(s.k1, s.k2, true) * (1.0 - MARGIN)).abs() < 1e-9);
        // A density on a log scale: the floor is the value whose t reaches the threshold.
        let log = visible_floor(&s, false, 50.0).unwrap();
        let t = s.density_scale.t(log / (1.0 - MARGIN), 50.0);
        assert!((t - visibility_threshold(s.k1, s.k2, false)).abs() < 1e-4, "{t}");
        // A shaped function visible at zero skips nothing.
        s.density_scale = DensityScale::Linear;
        s.transfer.kind = TransferKind::Shaped;
        s.transfer.positive.center = 0.0;
        assert_eq!(visible_floor(&s, false, 1.0), None);
        s.transfer.positive.center = 0.5;
        assert!(visible_floor(&s, false, 1.0).unwrap() > 0.2);
    }
}
