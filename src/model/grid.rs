//! Scalar values on a (possibly non-orthogonal) regular grid.

use glam::{DMat3, DMat4, DVec3};

/// Summary statistics of a grid, computed once when the grid is built.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct GridStats {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
    /// Standard deviation of the values (population).
    pub sigma: f64,
    /// max(|min|, |max|): the scale the transfer function normalises by.
    pub max_abs: f64,
}

impl GridStats {
    pub fn of(values: &[f32]) -> Self {
        if values.is_empty() {
            return Self::default();
        }
        let (mut min, mut max, mut sum, mut sum2) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0.0);
        for &v in values {
            let v = v as f64;
            min = min.min(v);
            max = max.max(v);
            sum += v;
            sum2 += v * v;
        }
        let n = values.len() as f64;
        let mean = sum / n;
        let sigma = (sum2 / n - mean * mean).max(0.0).sqrt();
        Self { min, max, mean, sigma, max_abs: min.abs().max(max.abs()) }
    }
}

/// The shape and placement of a regular grid, the one type every grid path shares (evaluation
/// on the CPU, GPU fills, scans' common grids, cube files): `dims` points, point (i, j, k) at
/// `world_from_grid`·(i, j, k) in bohr; values stored x slowest, z fastest (cube order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridSpec {
    pub dims: [usize; 3],
    pub world_from_grid: DMat4,
}

impl GridSpec {
    /// From an origin and the three step vectors (bohr).
    pub fn new(origin: DVec3, steps: [DVec3; 3], dims: [usize; 3]) -> Self {
        Self { dims, world_from_grid: VolumeGrid::affine(origin, steps) }
    }

    /// `n` points per axis spanning the box `lo..hi` exactly (spacing = extent / (n − 1), as
    /// cubegen does).
    pub fn cube(lo: DVec3, hi: DVec3, n: usize) -> Self {
        let n = n.max(2);
        let step = (hi - lo) / (n - 1) as f64;
        Self::new(lo, [DVec3::X * step.x, DVec3::Y * step.y, DVec3::Z * step.z], [n; 3])
    }

    /// Cubic voxels over the box `lo..hi`, `points` along its longest side, the (slightly
    /// larger) grid centred on the box.
    pub fn cubic_voxels(lo: DVec3, hi: DVec3, points: usize) -> Self {
        let extent = (hi - lo).max(DVec3::splat(1e-6));
        let points = points.max(2);
        let step = extent.max_element() / (points - 1) as f64;
        let dims = extent.to_array().map(|e| ((e / step - 1e-9).ceil() as usize + 1).clamp(2, points));
        let span = DVec3::new(dims[0] as f64 - 1.0, dims[1] as f64 - 1.0, dims[2] as f64 - 1.0) * step;
        let origin = lo - 0.5 * (span - extent);
        Self::new(origin, [DVec3::X * step, DVec3::Y * step, DVec3::Z * step], dims)
    }

    /// Points `spacing` apart (bohr) from `lo`, enough to reach `hi` on every axis.
    pub fn spaced(lo: DVec3, hi: DVec3, spacing: f64) -> Self {
        let dims = ((hi - lo) / spacing).ceil().to_array().map(|n| n.max(1.0) as usize + 1);
        Self::new(lo, [DVec3::X * spacing, DVec3::Y * spacing, DVec3::Z * spacing], dims)
    }

    pub fn origin(&self) -> DVec3 {
        self.world_from_grid.w_axis.truncate()
    }

    /// The step vector along grid axis `axis` (bohr).
    pub fn step(&self, axis: usize) -> DVec3 {
        self.world_from_grid.col(axis).truncate()
    }

    pub fn point(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.origin() + i as f64 * self.step(0) + j as f64 * self.step(1) + k as f64 * self.step(2)
    }

    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The lowest and highest corner of the grid's box (axis-aligned steps), bohr.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let [a, b, c] = self.dims.map(|d| d.max(1) - 1);
        let (lo, hi) = (self.origin(), self.point(a, b, c));
        (lo.min(hi), lo.max(hi))
    }
}

/// What the values mean, which decides how they are coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum ValueKind {
    /// Signed (an orbital ψ): two colours by sign, opacity from ψ².
    Signed,
    /// Non-negative (a density ρ): one colour ramp.
    Density,
}

/// Values on `dims` grid points. Index (i, j, k) maps to the world (bohr) through
/// `world_from_grid`; storage is x slowest, z fastest, as in cube files.
#[derive(Debug, Clone, PartialEq)]
pub struct VolumeGrid {
    pub label: String,
    pub dims: [usize; 3],
    pub world_from_grid: DMat4,
    pub values: Vec<f32>,
    pub stats: GridStats,
    pub kind: ValueKind,
}

impl VolumeGrid {
    /// Builds a grid; `values.len()` must equal the product of `dims`.
    pub fn new(label: impl Into<String>, dims: [usize; 3], world_from_grid: DMat4, values: Vec<f32>) -> Self {
        assert_eq!(values.len(), dims[0] * dims[1] * dims[2], "grid values do not match dims");
        let stats = GridStats::of(&values);
        // A grid with clearly negative values is an orbital (or a difference density).
        let kind = if stats.min < -1e-3 * stats.max_abs { ValueKind::Signed } else { ValueKind::Density };
        Self { label: label.into(), dims, world_from_grid, values, stats, kind }
    }

    /// `world_from_grid` from an origin and the three step vectors (columns), all bohr.
    pub fn affine(origin: DVec3, steps: [DVec3; 3]) -> DMat4 {
        DMat4::from_cols(steps[0].extend(0.0), steps[1].extend(0.0), steps[2].extend(0.0), origin.extend(1.0))
    }

    pub fn origin(&self) -> DVec3 {
        self.world_from_grid.w_axis.truncate()
    }

    /// The step vector along grid axis `axis` (bohr).
    pub fn step(&self, axis: usize) -> DVec3 {
        self.world_from_grid.col(axis).truncate()
    }

    pub fn is_orthogonal(&self) -> bool {
        let (a, b, c) = (self.step(0), self.step(1), self.step(2));
        let tol = 1e-6 * a.length() * b.length().max(c.length());
        a.dot(b).abs() < tol && a.dot(c).abs() < tol && b.dot(c).abs() < tol
    }

    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (i * self.dims[1] + j) * self.dims[2] + k
    }

    /// Every `step`-th point along each axis (the last point kept where it falls on the step):
    /// the same field on a coarser grid over nearly the same box, for a device that cannot hold
    /// the whole grid. `kind` is kept.
    pub fn subsampled(&self, step: usize) -> VolumeGrid {
        let step = step.max(1);
        let dims = self.dims.map(|d| d.div_ceil(step).max(1));
        let mut values = Vec::with_capacity(dims.iter().product());
        for i in 0..dims[0] {
            for j in 0..dims[1] {
                for k in 0..dims[2] {
                    values.push(self.values[self.index(i * step, j * step, k * step)]);
                }
            }
        }
        let s = step as f64;
        let world = DMat4::from_cols(
            self.world_from_grid.x_axis * s,
            self.world_from_grid.y_axis * s,
            self.world_from_grid.z_axis * s,
            self.world_from_grid.w_axis,
        );
        let mut grid = VolumeGrid::new(format!("{} (one point in {step})", self.label), dims, world, values);
        grid.kind = self.kind;
        grid
    }

    pub fn value(&self, i: usize, j: usize, k: usize) -> f32 {
        self.values[self.index(i, j, k)]
    }

    /// World position (bohr) of grid point (i, j, k).
    pub fn point(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.world_from_grid.transform_point3(DVec3::new(i as f64, j as f64, k as f64))
    }

    /// The parallelepiped spanned by the grid points: origin plus edges (n−1)·step.
    pub fn box_edges(&self) -> DMat3 {
        DMat3::from_cols(
            self.step(0) * (self.dims[0].max(1) - 1) as f64,
            self.step(1) * (self.dims[1].max(1) - 1) as f64,
            self.step(2) * (self.dims[2].max(1) - 1) as f64,
        )
    }

    /// The eight corners of the grid's box in world space.
    pub fn corners(&self) -> [DVec3; 8] {
        let e = self.box_edges();
        let o = self.origin();
        std::array::from_fn(|n| {
            o + e.x_axis * (n & 1) as f64 + e.y_axis * ((n >> 1) & 1) as f64 + e.z_axis * ((n >> 2) & 1) as f64
        })
    }

    /// Index bounds (inclusive) of the points with |value| ≥ `threshold`, grown by one point on
    /// each side and clamped to the grid; `None` when no point reaches the threshold.
    pub fn active_bounds(&self, threshold: f32) -> Option<([usize; 3], [usize; 3])> {
        let [nx, ny, nz] = self.dims;
        let (mut lo, mut hi) = ([usize::MAX; 3], [0usize; 3]);
        for i in 0..nx {
            for j in 0..ny {
                let row = &self.values[self.index(i, j, 0)..self.index(i, j, 0) + nz];
                let first = row.iter().position(|v| v.abs() >= threshold);
                let Some(first) = first else { continue };
                let last = row.iter().rposition(|v| v.abs() >= threshold).unwrap_or(first);
                for (a, v) in [i, j, first].into_iter().enumerate() {
                    lo[a] = lo[a].min(v);
                }
                for (a, v) in [i, j, last].into_iter().enumerate() {
                    hi[a] = hi[a].max(v);
                }
            }
        }
        (lo[0] != usize::MAX)
            .then(|| (lo.map(|v| v.saturating_sub(1)), std::array::from_fn(|a| (hi[a] + 1).min(self.dims[a] - 1))))
    }

    /// Largest gradient magnitude (per bohr) by central differences over interior points.
    pub fn max_gradient(&self) -> f64 {
        let [nx, ny, nz] = self.dims;
        if nx < 3 || ny < 3 || nz < 3 {
            return 0.0;
        }
        // Differences along grid axes give Jᵀ∇ with J the step matrix: ∇ = J⁻ᵀ·(differences).
        let j = DMat3::from_cols(self.step(0), self.step(1), self.step(2));
        let inv_t = j.inverse().transpose();
        let mut best = 0.0f64;
        for i in 1..nx - 1 {
            for jj in 1..ny - 1 {
                for k in 1..nz - 1 {
                    let d = DVec3::new(
                        (self.value(i + 1, jj, k) - self.value(i - 1, jj, k)) as f64,
                        (self.value(i, jj + 1, k) - self.value(i, jj - 1, k)) as f64,
                        (self.value(i, jj, k + 1) - self.value(i, jj, k - 1)) as f64,
                    ) * 0.5;
                    best = best.max((inv_t * d).length());
                }
            }
        }
        best
    }

    /// Voxel volume in bohr³ (|det| of the step vectors).
    pub fn voxel_volume(&self) -> f64 {
        DMat3::from_cols(self.step(0), self.step(1), self.step(2)).determinant().abs()
    }

    /// Trilinear interpolation at fractional grid coordinates, clamped to the grid.
    pub fn sample(&self, g: DVec3) -> f64 {
        let clampi = |v: f64, n: usize| v.clamp(0.0, (n.max(1) - 1) as f64);
        let (x, y, z) = (clampi(g.x, self.dims[0]), clampi(g.y, self.dims[1]), clampi(g.z, self.dims[2]));
        let (i0, j0, k0) = (x.floor() as usize, y.floor() as usize, z.floor() as usize);
        let (i1, j1, k1) =
            ((i0 + 1).min(self.dims[0] - 1), (j0 + 1).min(self.dims[1] - 1), (k0 + 1).min(self.dims[2] - 1));
        let (fx, fy, fz) = (x - i0 as f64, y - j0 as f64, z - k0 as f64);
        let v = |i, j, k| self.value(i, j, k) as f64;
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let c00 = lerp(v(i0, j0, k0), v(i1, j0, k0), fx);
        let c10 = lerp(v(i0, j1, k0), v(i1, j1, k0), fx);
        let c01 = lerp(v(i0, j0, k1), v(i1, j0, k1), fx);
        let c11 = lerp(v(i0, j1, k1), v(i1, j1, k1), fx);
        lerp(lerp(c00, c10, fy), lerp(c01, c11, fy), fz)
    }

    /// Trilinear value at a world position (bohr); `None` outside the grid box.
    pub fn sample_world(&self, p: DVec3) -> Option<f64> {
        let g = self.world_from_grid.inverse().transform_point3(p);
        let inside = (0..3).all(|a| g[a] >= -1e-9 && g[a] <= (self.dims[a].max(1) - 1) as f64 + 1e-9);
        inside.then(|| self.sample(g))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn linear_grid() -> VolumeGrid {
        let dims = [4, 5, 6];
        let w = VolumeGrid::affine(
            DVec3::new(-1.0, 2.0, 0.5),
            [DVec3::new(0.5, 0.1, 0.0), DVec3::new(0.0, 0.4, 0.0), DVec3::new(0.0, 0.0, 0.3)],
        );
        let mut values = Vec::new();
        for i in 0..4 {
            for j in 0..5 {
                for k in 0..6 {
                    values.push((i as f32) + 10.0 * j as f32 - 3.0 * k as f32);
                }
            }
        }
        VolumeGrid::new("lin", dims, w, values)
    }

    #[test]
    fn geometry_follows_the_affine_map() {
        let g = linear_grid();
        assert_eq!(g.point(0, 0, 0), DVec3::new(-1.0, 2.0, 0.5));
        assert!((g.point(2, 1, 3) - DVec3::new(0.0, 2.6, 1.4)).length() < 1e-12);
        assert!(!g.is_orthogonal());
        assert!((g.voxel_volume() - 0.06).abs() < 1e-12);
        assert!((g.corners()[7] - g.point(3, 4, 5)).length() < 1e-12);
    }

    #[test]
    fn trilinear_sampling_is_exact_for_linear_fields() {
        let g = linear_grid();
        let v = g.sample(DVec3::new(1.5, 2.25, 4.5));
        assert!((v - (1.5 + 22.5 - 13.5)).abs() < 1e-9);
        let p = g.world_from_grid.transform_point3(DVec3::new(1.5, 2.25, 4.5));
        assert!((g.sample_world(p).unwrap() - v).abs() < 1e-9);
        assert!(g.sample_world(DVec3::new(100.0, 0.0, 0.0)).is_none());
    }

    #[test]
    fn active_bounds_enclose_the_significant_values() {
        let mut values = vec![0.0f32; 6 * 5 * 4];
        let g = VolumeGrid::new("a", [6, 5, 4], DMat4::IDENTITY, values.clone());
        assert_eq!(g.active_bounds(0.5), None);
        values[g.index(2, 1, 3)] = -1.0;
        values[g.index(3, 3, 1)] = 1.0;
        let g = VolumeGrid::new("a", [6, 5, 4], DMat4::IDENTITY, values);
        assert_eq!(g.active_bounds(0.5), Some(([1, 0, 0], [4, 4, 3])));
    }

    #[test]
    fn max_gradient_of_a_linear_field() {
        // value = i + 10 j − 3 k on steps (0.5, 0.1, 0)/(0, 0.4, 0)/(0, 0, 0.3): the world gradient
        // solves Jᵀ∇ = (1, 10, −3).
        let g = linear_grid();
        let j = DMat3::from_cols(g.step(0), g.step(1), g.step(2));
        let expected = (j.inverse().transpose() * DVec3::new(1.0, 10.0, -3.0)).length();
        assert!((g.max_gradient() - expected).abs() < 1e-4 * expected);
    }

    #[test]
    fn grid_specs_span_their_boxes() {
        let (lo, hi) = (DVec3::new(-1.0, -2.0, 0.5), DVec3::new(3.0, 2.0, 1.5));
        let cube = GridSpec::cube(lo, hi, 5);
        assert_eq!(cube.dims, [5; 3]);
        assert_eq!(cube.bounds(), (lo, hi));
        assert!((cube.point(2, 2, 2) - 0.5 * (lo + hi)).length() < 1e-12);
        let spaced = GridSpec::spaced(lo, hi, 0.3);
        assert_eq!(spaced.dims, [15, 15, 5]);
        let (_, top) = spaced.bounds();
        assert!(top.cmpge(hi).all() && (top - hi).max_element() < 0.3);
        // The same shape as a VolumeGrid built on it.
        let g = linear_grid();
        let spec = GridSpec { dims: g.dims, world_from_grid: g.world_from_grid };
        assert_eq!(spec.point(2, 1, 3), g.point(2, 1, 3));
        assert_eq!(spec.len(), g.values.len());
    }

    #[test]
    fn stats_and_kind() {
        let g = linear_grid();
        assert_eq!(g.kind, ValueKind::Signed);
        // Every other point: the same values at the same places.
        let coarse = g.subsampled(2);
        assert_eq!(coarse.dims, g.dims.map(|d| d.div_ceil(2)));
        let (i, j, k) = (1, 0, 0);
        assert_eq!(coarse.values[coarse.index(i, j, k)], g.values[g.index(2 * i, 2 * j, 2 * k)]);
        assert!((coarse.point(i, j, k) - g.point(2 * i, 2 * j, 2 * k)).length() < 1e-12);
        assert_eq!(g.stats.min, -15.0);
        assert_eq!(g.stats.max, 43.0);
        assert_eq!(g.stats.max_abs, 43.0);
        let d = VolumeGrid::new("d", [1, 1, 2], DMat4::IDENTITY, vec![1.0, 3.0]);
        assert_eq!(d.kind, ValueKind::Density);
        assert_eq!((d.stats.mean, d.stats.sigma), (2.0, 1.0));
    }
}
