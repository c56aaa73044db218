//! What a value becomes before the transfer function sees it, and an opacity scale chosen from
//! the grid so the first picture has contrast. A density's maximum is the nuclear cusp, so ρ/max
//! shows only the cores: by default densities are mapped logarithmically between bounds in
//! atomic units, where the valence shell and the van der Waals surface lie. These functions are
//! the CPU reference of the shader's `transfer_value` (volume_common.wgsl).

use serde::{Deserialize, Serialize};

/// How a density's values become t ∈ [0, 1] (orbitals are always |ψ| / max |ψ|).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum DensityScale {
    /// ρ / max ρ.
    Linear,
    /// log ρ between `lo` and `hi` (a.u.) mapped onto 0..1, clamped.
    Log { lo: f32, hi: f32 },
}

impl Default for DensityScale {
    /// 10⁻³ a.u. (about the van der Waals surface) to 1 a.u. (inside the bonds and lone pairs).
    fn default() -> Self {
        DensityScale::Log { lo: 1e-3, hi: 1.0 }
    }
}

impl DensityScale {
    /// The shader's `log_lo` and `inv_log_span` (log10 units); zeros when linear.
    pub fn log_uniforms(self) -> (f32, f32) {
        match self {
            DensityScale::Linear => (0.0, 0.0),
            DensityScale::Log { lo, hi } => {
                let (a, b) = (lo.max(1e-12).log10(), hi.max(lo * 1.0001).max(1e-12).log10());
                (a, 1.0 / (b - a).max(1e-6))
            }
        }
    }

    /// t of a density value `rho` on a grid whose largest value is `max`.
    pub fn t(self, rho: f32, max: f32) -> f32 {
        match self {
            DensityScale::Linear => (rho / max.max(1e-30)).max(0.0),
            DensityScale::Log { .. } if rho <= 0.0 => 0.0,
            DensityScale::Log { .. } => {
                let (lo, inv_span) = self.log_uniforms();
                ((rho.log10() - lo) * inv_span).clamp(0.0, 1.0)
            }
        }
    }
}

/// The extinction law's base for a value, before k1: t^(2·k2) for an orbital (ρ = ψ²), t^k2 for
/// a density.
pub fn law(value: f32, signed: bool, max_abs: f32, scale: DensityScale, k2: f32) -> f32 {
    if signed { (value.abs() / max_abs.max(1e-30)).powf(2.0 * k2) } else { scale.t(value, max_abs).powf(k2) }
}

/// Extinction per reference step below which a sample cannot be seen.
const INVISIBLE: f32 = 1e-4;

/// The smallest scaled |value| whose opacity k1·ρ^k2 reaches [`INVISIBLE`]
/// (ρ = value² for an orbital, value for a density): the shaders' `visible_min`.
pub fn visibility_threshold(k1: f32, k2: f32, signed: bool) -> f32 {
    if k1 <= 0.0 {
        return f32::INFINITY;
    }
    let rho = (INVISIBLE / k1).powf(1.0 / k2.max(1e-3));
    if signed { rho.sqrt() } else { rho }
}

/// Optical depth the densest lines of sight get with the automatic k1.
const TARGET_DEPTH: f64 = 2.5;
/// Which line of sight counts as "densest": this quantile of all grid lines' sums.
const QUANTILE: f64 = 0.98;

/// A k1 for the power law that gives the densest lines through the grid (the 98th percentile of
/// the sums of the law along every grid line, all three axes) an optical depth of 2.5: opaque
/// enough to show the shape, never a solid block. `values` are in cube order (x slowest).
pub fn auto_k1(values: &[f32], dims: [usize; 3], signed: bool, max_abs: f32, scale: DensityScale, k2: f32) -> f32 {
    let [nx, ny, nz] = dims;
    if values.len() != nx * ny * nz || values.is_empty() {
        return 0.2;
    }
    let f: Vec<f32> = values.iter().map(|&v| law(v, signed, max_abs, scale, k2)).collect();
    let at = |i: usize, j: usize, k: usize| f[(i * ny + j) * nz + k] as f64;
    let mut sums = Vec::with_capacity(nx * ny + ny * nz + nx * nz);
    for i in 0..nx {
        for j in 0..ny {
            sums.push((0..nz).map(|k| at(i, j, k)).sum::<f64>());
        }
    }
    for j in 0..ny {
        for k in 0..nz {
            sums.push((0..nx).map(|i| at(i, j, k)).sum::<f64>());
        }
    }
    for i in 0..nx {
        for k in 0..nz {
            sums.push((0..ny).map(|j| at(i, j, k)).sum::<f64>());
        }
    }
    sums.sort_by(f64::total_cmp);
    let s = sums[((sums.len() - 1) as f64 * QUANTILE) as usize];
    if s <= 0.0 { 0.2 } else { (TARGET_DEPTH / s).clamp(0.005, 2.0) as f32 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_scale_spreads_the_decades_and_auto_k1_reaches_the_target_depth() {
        let log = DensityScale::default();
        assert_eq!(log.t(1e-4, 100.0), 0.0);
        assert!((log.t(1e-3, 100.0)).abs() < 1e-6);
        assert!((log.t(0.0316, 100.0) - 0.5).abs() < 1e-3, "half-way in log");
        assert_eq!(log.t(50.0, 100.0), 1.0, "the cusp saturates");
        // Linear: the valence density is nothing next to a cusp of 100 a.u.
        assert!(DensityScale::Linear.t(0.05, 100.0) < 1e-3 && log.t(0.05, 100.0) > 0.5);
        // A uniform block of 10³ with law 1 everywhere: every line sums to 10.
        let k1 = auto_k1(&vec![1.0; 1000], [10; 3], true, 1.0, log, 0.5);
        assert!((k1 - 0.25).abs() < 1e-6, "{k1}");
    }
}
