//! Transfer functions: how a sample's value (and gradient) becomes colour and opacity.
//!
//! Two families: seed 000's power law α = k1·ρ^k2 (the default), and seed 004's shaped
//! functions of the normalised value, one per sign, optionally weighted by the gradient
//! magnitude (a 2D transfer function), lit from the gradient and with boundaries enhanced.

use serde::{Deserialize, Serialize};

/// Seed 004's five shapes, as functions of t = |value| / max|value| ∈ [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Shape {
    /// A band of constant opacity |t − c| ≤ w/2: a thick isosurface.
    Uniform,
    /// exp(−((t − c)/w)²): a soft shell around the iso-value c.
    #[default]
    Gaussian,
    /// Full opacity for t ≥ c, a Gaussian tail below: a solid core inside the iso-value.
    LeftHalfGaussian,
    /// Full opacity for t ≤ c, a Gaussian tail above: everything outside the iso-value.
    RightHalfGaussian,
    /// (½ + ½·cos 2π(t − c)/w)^8 for t ≥ c − w/2: contour shells at c, c + w, c + 2w, …
    Sinusoidal,
}

impl Shape {
    pub const ALL: [Shape; 5] =
        [Shape::Uniform, Shape::Gaussian, Shape::LeftHalfGaussian, Shape::RightHalfGaussian, Shape::Sinusoidal];

    pub fn name(self) -> &'static str {
        match self {
            Shape::Uniform => "uniform (isosurface)",
            Shape::Gaussian => "Gaussian",
            Shape::LeftHalfGaussian => "left half Gaussian",
            Shape::RightHalfGaussian => "right half Gaussian",
            Shape::Sinusoidal => "sinusoidal (contours)",
        }
    }

    /// Opacity factor in [0, 1] at normalised value `t` for centre `c` and width `w` — the CPU
    /// reference of `shape_factor` in volume_common.wgsl.
    pub fn factor(self, t: f32, c: f32, w: f32) -> f32 {
        let w = w.max(1e-4);
        let g = |x: f32| (-(x * x)).exp();
        match self {
            Shape::Uniform => f32::from((t - c).abs() <= 0.5 * w),
            Shape::Gaussian => g((t - c) / w),
            Shape::LeftHalfGaussian => {
                if t >= c {
                    1.0
                } else {
                    g((t - c) / w)
                }
            }
            Shape::RightHalfGaussian => {
                if t <= c {
                    1.0
                } else {
                    g((t - c) / w)
                }
            }
            Shape::Sinusoidal => {
                if t < c - 0.5 * w {
                    0.0
                } else {
                    (0.5 + 0.5 * (std::f32::consts::TAU * (t - c) / w).cos()).powi(8)
                }
            }
        }
    }

    pub fn index(self) -> u32 {
        Self::ALL.iter().position(|&s| s == self).unwrap_or(0) as u32
    }
}

/// One sign's shaped transfer function.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Lobe {
    pub shape: Shape,
    /// Centre c, as a fraction of max|value|.
    pub center: f32,
    /// Width w, as a fraction of max|value|.
    pub width: f32,
    /// Peak opacity per reference step.
    pub opacity: f32,
}

impl Default for Lobe {
    fn default() -> Self {
        Self { shape: Shape::Gaussian, center: 0.25, width: 0.08, opacity: 0.9 }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum TransferKind {
    /// Seed 000: α = k1·ρ^k2.
    #[default]
    PowerLaw,
    /// Seed 004: shaped functions of the value, per sign.
    Shaped,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Transfer {
    pub kind: TransferKind,
    /// For ψ > 0 (or a density).
    pub positive: Lobe,
    /// For ψ < 0.
    pub negative: Lobe,
    /// 2D transfer function: opacity also rises with the gradient magnitude, g^gradient_power,
    /// g = |∇ψ| / max|∇ψ| (0 turns it off).
    pub gradient_power: f32,
    /// Diffuse and specular lighting with the gradient as the normal.
    pub shading: bool,
    /// Boundary enhancement: opacity × (1 − b + b·g^0.5), b ∈ [0, 1].
    pub boundary: f32,
}

impl Default for Transfer {
    fn default() -> Self {
        Self {
            kind: TransferKind::PowerLaw,
            positive: Lobe::default(),
            negative: Lobe::default(),
            gradient_power: 0.0,
            shading: false,
            boundary: 0.0,
        }
    }
}

impl Transfer {
    /// Whether the shaders need the gradient at each sample.
    pub fn needs_gradient(&self) -> bool {
        self.shading || self.gradient_power > 0.0 || self.boundary > 0.0
    }
}

/// Colour presets for the two signs (linear RGB).
pub const PRESETS: &[(&str, [f32; 3], [f32; 3])] = &[
    ("red / blue", [0.90, 0.12, 0.10], [0.10, 0.30, 0.95]),
    ("red / white", [0.90, 0.10, 0.08], [0.85, 0.85, 0.85]),
    ("orange / teal", [0.95, 0.45, 0.05], [0.05, 0.55, 0.60]),
    ("gold / purple", [0.85, 0.65, 0.10], [0.45, 0.15, 0.75]),
    ("green / magenta", [0.15, 0.70, 0.20], [0.75, 0.10, 0.60]),
];

/// A clipping plane: points with n·p > offset are cut away (n need not be unit length; it is
/// normalised when used).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ClipPlane {
    pub enabled: bool,
    pub normal: [f32; 3],
    /// Signed distance (bohr) of the plane from the scene centre along the normal.
    pub offset: f32,
}

impl Default for ClipPlane {
    fn default() -> Self {
        Self { enabled: false, normal: [0.0, 0.0, 1.0], offset: 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_peak_where_they_should() {
        assert_eq!(Shape::Uniform.factor(0.30, 0.3, 0.1), 1.0);
        assert_eq!(Shape::Uniform.factor(0.40, 0.3, 0.1), 0.0);
        assert!((Shape::Gaussian.factor(0.3, 0.3, 0.1) - 1.0).abs() < 1e-6);
        assert!(Shape::Gaussian.factor(0.5, 0.3, 0.1) < 0.02);
        assert_eq!(Shape::LeftHalfGaussian.factor(0.9, 0.3, 0.1), 1.0);
        assert!(Shape::LeftHalfGaussian.factor(0.1, 0.3, 0.1) < 0.02);
        assert_eq!(Shape::RightHalfGaussian.factor(0.1, 0.3, 0.1), 1.0);
        assert!(Shape::RightHalfGaussian.factor(0.9, 0.3, 0.1) < 0.02);
        // Contours every w from c on: peaks at c + k·w, zero half-way and below the first.
        assert!((Shape::Sinusoidal.factor(0.5, 0.1, 0.2) - 1.0).abs() < 1e-5);
        assert!(Shape::Sinusoidal.factor(0.6, 0.1, 0.2) < 1e-6);
        assert_eq!(Shape::Sinusoidal.factor(0.0, 0.1, 0.1), 0.0);
    }
}
