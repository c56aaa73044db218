//! Transfer functions: how a sample's value (and gradient) becomes colour and opacity.
//!
//! Two families: Naka et al.'s power law α = k1·ρ^k2 (the default), and Jang and Varetto's shaped
//! functions of the normalised value, one per sign, optionally weighted by the gradient
//! magnitude (a 2D transfer function), lit from the gradient and with boundaries enhanced.

use serde::{Deserialize, Serialize};

/// Jang and Varetto's five shapes, drawn as the paper draws them: on the signed value
/// s = value / max|value| ∈ [−1, 1], each lobe's shape placed at s = ±centre (its sign).
///
/// The halves are not mirror images of each other: a right half falls off towards larger s, a
/// left half towards smaller s. The paper pairs them so that both fall off towards ψ = 0: the
/// right half on ψ < 0 and the left half on ψ > 0 rise from the empty space towards the
/// extreme value and reveal the nested shells around the cores (all of them with the centre at
/// 1, the extreme itself); swapped, they are shells with a sharp outside. Every shape is clear
/// where ψ ≈ 0 unless its centre is near 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Shape {
    /// A band of constant opacity |s − c| ≤ w/2: a thick isosurface.
    Uniform,
    /// exp(−((s − c)/w)²): a soft shell around the iso-value c.
    #[default]
    Gaussian,
    /// The bell's half left of its peak: exp(−((s − c)/w)²) for s ≤ c, nothing above.
    LeftHalfGaussian,
    /// The bell's half right of its peak: exp(−((s − c)/w)²) for s ≥ c, nothing below.
    RightHalfGaussian,
    /// (½ + ½·cos 2π(s − c)/w)^8 from half a period before c on, away from zero: contour shells
    /// at c, c ± w, c ± 2w, … towards the lobe's extreme value.
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

    /// Opacity factor in [0, 1] at the signed value `s` of a shape placed at the signed centre
    /// `c` with width `w`; `outward` (±1) is the sign of the values its lobe colours (the way
    /// the contours run) — the CPU reference of `shape_factor` in volume_common.wgsl.
    pub fn at(self, s: f32, c: f32, w: f32, outward: f32) -> f32 {
        let w = w.max(1e-4);
        let bell = (-((s - c) / w).powi(2)).exp();
        match self {
            Shape::Uniform => f32::from((s - c).abs() <= 0.5 * w),
            Shape::Gaussian => bell,
            Shape::LeftHalfGaussian => f32::from(s <= c) * bell,
            Shape::RightHalfGaussian => f32::from(s >= c) * bell,
            Shape::Sinusoidal => {
                if (s - c) * outward < -0.5 * w {
                    0.0
                } else {
                    (0.5 + 0.5 * (std::f32::consts::TAU * (s - c) / w).cos()).powi(8)
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
    /// Centre, as a fraction of max|value|: the shape sits at ±centre on the signed value.
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

/// Opacity per reference step below which the shaders drop a shaped sample.
pub const SHAPED_FLOOR: f32 = 1e-5;

impl Lobe {
    /// The smallest |s| at which this lobe can reach [`SHAPED_FLOOR`] (infinite when it never
    /// does). Every shape is zero or below the floor from there towards s = 0, on either sign;
    /// the half bells are bounded by the whole bell.
    pub fn lowest_visible(&self) -> f32 {
        if self.opacity < SHAPED_FLOOR {
            return f32::INFINITY;
        }
        let w = self.width.max(1e-4);
        let reach = match self.shape {
            Shape::Uniform | Shape::Sinusoidal => 0.5 * w,
            // exp(−x²)·opacity ≥ floor for |x| ≤ √ln(opacity / floor).
            _ => w * (self.opacity / SHAPED_FLOOR).ln().sqrt(),
        };
        (self.center - reach).max(0.0)
    }

    /// Its shape's factor at the signed value `s`, for the lobe of values of sign `sign` (±1):
    /// the shape sits at s = sign·centre.
    pub fn factor(&self, s: f32, sign: f32) -> f32 {
        self.shape.at(s, sign * self.center, self.width, sign)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum TransferKind {
    /// Naka et al.: α = k1·ρ^k2.
    #[default]
    PowerLaw,
    /// Jang and Varetto: shaped functions of the value, per sign.
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
    /// Jang and Varetto's pairing for nested cores: the left half on ψ > 0 and the right half on ψ < 0,
    /// each peaked at its extreme value, so opacity grows from the empty space to the cores.
    /// The width keeps ψ = 0 under the shaders' visibility floor of 10⁻⁵ (2·e^−(1/0.28)² ≈ 6·10⁻⁶):
    /// empty space stays exactly clear.
    pub fn nested_cores(&mut self) {
        self.kind = TransferKind::Shaped;
        self.positive = Lobe { shape: Shape::LeftHalfGaussian, center: 1.0, width: 0.28, opacity: 2.0 };
        self.negative = Lobe { shape: Shape::RightHalfGaussian, ..self.positive };
    }

    /// The smallest |s| (s = value / max|value|) a shaped sample needs to be seen: the lowest of
    /// both lobes for a signed field, the positive lobe's otherwise. The gradient terms only
    /// lower opacity, so they cannot lower this.
    pub fn lowest_visible(&self, signed: bool) -> f32 {
        let positive = self.positive.lowest_visible();
        if signed { positive.min(self.negative.lowest_visible()) } else { positive }
    }

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

/// An object's clipping plane: points p of the object's frame with n·(p − c) > offset are cut
/// away, c the centre of the object's bounds (n need not be unit length; it is normalised when
/// used). It cuts every representation of the object: its clouds, isosurfaces and molecular
/// surface, and its atoms and bonds when `atoms` is set.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ClipPlane {
    pub enabled: bool,
    pub normal: [f32; 3],
    /// Signed distance (bohr) of the plane from the object's centre along the normal.
    pub offset: f32,
    /// Whether atoms and bonds are cut too (a sphere or stick crossing the plane shows its
    /// cut face).
    pub atoms: bool,
}

impl Default for ClipPlane {
    fn default() -> Self {
        Self { enabled: false, normal: [0.0, 0.0, 1.0], offset: 0.0, atoms: false }
    }
}

impl ClipPlane {
    /// The plane as the shaders take it, in the object's frame: (unit n, d) with the points
    /// n·p > d cut away, `centre` the point the offset is measured from; `None` when off.
    pub fn plane(&self, centre: glam::Vec3) -> Option<glam::Vec4> {
        let n = glam::Vec3::from(self.normal).normalize_or(glam::Vec3::Z);
        self.enabled.then(|| n.extend(n.dot(centre) + self.offset))
    }

    /// Whether point `p` (object frame) is kept (the CPU reference of the shaders' test).
    pub fn keeps(&self, centre: glam::Vec3, p: glam::Vec3) -> bool {
        self.plane(centre).is_none_or(|q| q.truncate().dot(p) <= q.w)
    }
}

/// What a plane that cuts nothing looks like to the shaders: every point lies 10³⁰ bohr
/// before it (0·p > 10³⁰ never holds, and no sphere reaches it).
pub const NO_CUT: glam::Vec4 = glam::Vec4::new(0.0, 0.0, 0.0, 1e30);

#[cfg(test)]
mod tests {
    use super::*;

    /// The plane's offset runs along the unit normal from the centre it is given; off, it keeps
    /// everything.
    #[test]
    fn a_clipping_plane_keeps_the_near_side_of_its_offset() {
        let centre = glam::Vec3::new(1.0, 2.0, 3.0);
        let mut clip = ClipPlane { enabled: true, normal: [0.0, 0.0, 2.0], offset: 0.5, atoms: false };
        assert_eq!(clip.plane(centre), Some(glam::Vec4::new(0.0, 0.0, 1.0, 3.5)));
        assert!(clip.keeps(centre, glam::Vec3::new(9.0, -9.0, 3.4)));
        assert!(!clip.keeps(centre, glam::Vec3::new(1.0, 2.0, 3.6)));
        clip.enabled = false;
        assert_eq!(clip.plane(centre), None);
        assert!(clip.keeps(centre, glam::Vec3::splat(100.0)));
        // What the shaders take for "off" cuts nothing anywhere.
        assert!(NO_CUT.truncate().dot(glam::Vec3::splat(1e6)) <= NO_CUT.w);
    }

    /// The paper's formulas written out with numbers: g(x) = e^(−x²), s the signed value.
    #[test]
    fn shapes_are_drawn_on_the_signed_value() {
        let close = |a: f32, b: f32| (a - b).abs() < 1e-6;
        let lobe = |shape, center, width| Lobe { shape, center, width, opacity: 1.0 };
        // Right half on ψ < 0 at −0.5: g((s + 0.5)/0.1) from the peak towards zero, none beyond.
        let right = lobe(Shape::RightHalfGaussian, 0.5, 0.1);
        assert!(close(right.factor(-0.5, -1.0), 1.0));
        assert!(close(right.factor(-0.45, -1.0), 0.778_800_8)); // e^(−0.25)
        assert!(close(right.factor(-0.4, -1.0), 0.367_879_4)); // e^(−1)
        assert_eq!(right.factor(-0.55, -1.0), 0.0);
        assert_eq!(right.factor(-0.9, -1.0), 0.0);
        assert!(right.factor(0.0, -1.0) < 1.4e-11); // e^(−25): empty space stays clear
        // Left half on ψ > 0 at +0.5: its mirror image.
        let left = lobe(Shape::LeftHalfGaussian, 0.5, 0.1);
        assert!(close(left.factor(0.45, 1.0), 0.778_800_8));
        assert_eq!(left.factor(0.55, 1.0), 0.0);
        assert!(left.factor(0.0, 1.0) < 1.4e-11);
        // Swapped, each falls off towards the extreme value instead, and is clear near zero too.
        assert!(close(right.factor(0.6, 1.0), 0.367_879_4));
        assert_eq!(right.factor(0.45, 1.0), 0.0);
        assert!(close(left.factor(-0.6, -1.0), 0.367_879_4));
        assert_eq!(left.factor(-0.45, -1.0), 0.0);
        // Centred on the extreme, the paper's pairing rises all the way to the cores.
        let core = lobe(Shape::LeftHalfGaussian, 1.0, 0.4);
        assert!(core.factor(0.2, 1.0) < core.factor(0.6, 1.0) && core.factor(0.6, 1.0) < core.factor(1.0, 1.0));
        // The preset: exactly clear at ψ = 0 (under the shaders' floor of 10⁻⁵), full at the extremes.
        let mut t = Transfer::default();
        t.nested_cores();
        for (lobe, sign) in [(t.positive, 1.0), (t.negative, -1.0)] {
            assert!(lobe.opacity * lobe.factor(0.0, sign) < 1e-5);
            assert!(close(lobe.factor(sign, sign), 1.0));
        }
        // Symmetric shapes: the same for either sign.
        let uniform = lobe(Shape::Uniform, 0.3, 0.1);
        assert_eq!((uniform.factor(-0.3, -1.0), uniform.factor(-0.36, -1.0)), (1.0, 0.0));
        assert!(close(lobe(Shape::Gaussian, 0.3, 0.1).factor(-0.2, -1.0), 0.367_879_4));
        // Contours every w from c away from zero: peaks at ±(c + k·w), zero half-way and inside c.
        let contours = lobe(Shape::Sinusoidal, 0.1, 0.2);
        for sign in [1.0, -1.0] {
            assert!(close(contours.factor(sign * 0.5, sign), 1.0));
            assert!(contours.factor(sign * 0.6, sign) < 1e-6);
            assert_eq!(contours.factor(sign * -0.05, sign), 0.0);
        }
    }

    /// Below the lowest visible |s| no shape reaches the shaders' floor, on either sign.
    #[test]
    fn nothing_is_visible_below_the_lowest_visible_value() {
        for shape in Shape::ALL {
            for (center, width, opacity) in [(0.25, 0.08, 0.9), (1.0, 0.28, 2.0), (0.1, 0.2, 1.0), (0.6, 0.05, 5.0)] {
                let lobe = Lobe { shape, center, width, opacity };
                let low = lobe.lowest_visible();
                for sign in [1.0, -1.0] {
                    let seen = (0..=2000)
                        .map(|i| i as f32 / 2000.0)
                        .filter(|&s| lobe.opacity * lobe.factor(sign * s, sign) >= SHAPED_FLOOR)
                        .fold(f32::INFINITY, f32::min);
                    assert!(seen >= low, "{shape:?} {center} {width}: seen at {seen}, lowest {low}");
                    if matches!(shape, Shape::Uniform | Shape::Gaussian) {
                        assert!(seen - low < 1e-3, "{shape:?} {center} {width}: {seen} is far above {low}");
                    }
                }
            }
        }
        let mut t = Transfer::default();
        t.nested_cores();
        assert!(t.lowest_visible(true) > 0.0 && t.lowest_visible(true) < 0.05);
        t.positive.opacity = 0.0;
        assert_eq!(t.lowest_visible(false), f32::INFINITY);
    }
}
