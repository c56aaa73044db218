//! Arrows: a shaft (a cylinder closed at its foot) and a head (a cone on a disc), what a normal
//! mode's displacements are drawn as. Their ray intersection here is the CPU reference of the
//! GPU's arrow impostors (`shaders/arrows.wgsl`).

use glam::DVec3;

use super::vibrations::Vibrations;

/// An arrow from `from` to `to` (bohr).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arrow {
    pub from: DVec3,
    pub to: DVec3,
    pub shaft_radius: f64,
    pub head_radius: f64,
    /// Length of the head along the arrow (at most the arrow's).
    pub head_length: f64,
}

/// How long the longest arrow of a mode is for each bohr of amplitude: longer than the motion,
/// to be seen.
pub const ARROW_LENGTH_PER_AMPLITUDE: f64 = 6.0;

impl Arrow {
    /// An arrow from `from` along `vector`, its shaft and head sized for atoms a bohr or two
    /// apart.
    pub fn along(from: DVec3, vector: DVec3) -> Self {
        let length = vector.length();
        Self { from, to: from + vector, shaft_radius: 0.13, head_radius: 0.3, head_length: (0.4 * length).min(0.7) }
    }

    /// The nearest point where the ray `origin + t·dir` (`dir` of unit length) meets the arrow, in
    /// front of the origin: `t` and the outward unit normal there.
    pub fn hit(&self, origin: DVec3, dir: DVec3) -> Option<(f64, DVec3)> {
        let axis = self.to - self.from;
        let length = axis.length();
        if length < 1e-12 {
            return None;
        }
        let z = axis / length;
        let (x, y) = z.any_orthonormal_pair();
        let rel = origin - self.from;
        let (o, d) = (DVec3::new(rel.dot(x), rel.dot(y), rel.dot(z)), DVec3::new(dir.dot(x), dir.dot(y), dir.dot(z)));
        let neck = length - self.head_length;
        let mut best: Option<(f64, DVec3)> = None;
        let mut consider = |t: f64, n: DVec3| {
            if t > 1e-9 && best.is_none_or(|(b, _)| t < b) {
                best = Some((t, n));
            }
        };
        // The shaft's side: x² + y² = r², 0 ≤ z ≤ neck.
        let r = self.shaft_radius;
        for t in roots(d.x * d.x + d.y * d.y, 2.0 * (o.x * d.x + o.y * d.y), o.x * o.x + o.y * o.y - r * r) {
            let p = o + d * t;
            if (0.0..=neck).contains(&p.z) {
                consider(t, DVec3::new(p.x, p.y, 0.0) / r);
            }
        }
        // The head's side: x² + y² = k²(L − z)², neck ≤ z ≤ L, k = R / H.
        let k = self.head_radius / self.head_length.max(1e-12);
        let (k2, w) = (k * k, length - o.z);
        let a = d.x * d.x + d.y * d.y - k2 * d.z * d.z;
        let b = 2.0 * (o.x * d.x + o.y * d.y + k2 * w * d.z);
        let c = o.x * o.x + o.y * o.y - k2 * w * w;
        for t in roots(a, b, c) {
            let p = o + d * t;
            if (neck..=length).contains(&p.z) {
                consider(t, DVec3::new(p.x, p.y, k2 * (length - p.z)).normalize());
            }
        }
        // The discs closing the shaft's foot and the head's base, both facing back.
        for (h, radius) in [(0.0, r), (neck, self.head_radius)] {
            if d.z.abs() > 1e-12 {
                let t = (h - o.z) / d.z;
                let p = o + d * t;
                if p.x * p.x + p.y * p.y <= radius * radius {
                    consider(t, DVec3::NEG_Z);
                }
            }
        }
        best.map(|(t, n)| (t, x * n.x + y * n.y + z * n.z))
    }
}

/// The real roots of a·t² + b·t + c (one for a linear equation, none when there is none).
fn roots(a: f64, b: f64, c: f64) -> Vec<f64> {
    if a.abs() < 1e-14 {
        return if b.abs() < 1e-14 { Vec::new() } else { vec![-c / b] };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return Vec::new();
    }
    let s = disc.sqrt();
    vec![(-b - s) / (2.0 * a), (-b + s) / (2.0 * a)]
}

/// Each atom's displacement along mode `mode` of `v` as an arrow from its place in the modes'
/// geometry, the longest [`ARROW_LENGTH_PER_AMPLITUDE`] × `amplitude` bohr; atoms that hardly
/// move get none. `None` when the mode is not there.
pub fn mode_arrows(v: &Vibrations, mode: usize, amplitude: f64) -> Option<Vec<Arrow>> {
    let m = v.modes.get(mode)?;
    let scale = ARROW_LENGTH_PER_AMPLITUDE * amplitude / m.largest_displacement().max(1e-12);
    let arrows = v.geometry.iter().zip(&m.displacement).map(|(p, d)| (*p, *d * scale));
    Some(arrows.filter(|(_, d)| d.length() > 0.1).map(|(p, d)| Arrow::along(p, d)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::vibrations::NormalMode;

    #[test]
    fn rays_meet_the_shaft_the_head_and_the_discs() {
        let a = Arrow { from: DVec3::ZERO, to: DVec3::Z * 2.0, shaft_radius: 0.1, head_radius: 0.3, head_length: 0.5 };
        // From the side at the shaft's height: its side, facing the ray.
        let (t, n) = a.hit(DVec3::new(-5.0, 0.0, 0.5), DVec3::X).unwrap();
        assert!((t - 4.9).abs() < 1e-12 && (n - DVec3::NEG_X).length() < 1e-12);
        // At the head's middle height the cone's radius is half its base's.
        let (t, n) = a.hit(DVec3::new(-5.0, 0.0, 1.75), DVec3::X).unwrap();
        assert!((t - (5.0 - 0.15)).abs() < 1e-12, "{t}");
        assert!(n.x < 0.0 && n.z > 0.0, "the cone's normal leans to the tip: {n}");
        // From below: the shaft's foot, then (outside the shaft) the head's base.
        let (t, n) = a.hit(DVec3::new(0.05, 0.0, -1.0), DVec3::Z).unwrap();
        assert!((t - 1.0).abs() < 1e-12 && n == DVec3::NEG_Z);
        let (t, _) = a.hit(DVec3::new(0.2, 0.0, -1.0), DVec3::Z).unwrap();
        assert!((t - 2.5).abs() < 1e-12);
        // From above along the axis: the tip.
        let (t, _) = a.hit(DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z).unwrap();
        assert!((t - 3.0).abs() < 1e-9);
        assert!(a.hit(DVec3::new(-5.0, 0.0, 2.1), DVec3::X).is_none(), "above the tip");
        assert!(a.hit(DVec3::new(-5.0, 0.2, 0.5), DVec3::X).is_none(), "beside the shaft");
        assert!(a.hit(DVec3::new(5.0, 0.0, 0.5), DVec3::X).is_none(), "behind the origin");
    }

    #[test]
    fn a_modes_arrows_start_at_the_atoms_and_the_longest_has_its_length() {
        let v = Vibrations {
            modes: vec![NormalMode {
                frequency_cm1: 1600.0,
                ir_intensity: None,
                displacement: vec![DVec3::new(0.0, 0.0, 0.5), DVec3::new(0.001, 0.0, 0.0), DVec3::new(0.0, -0.25, 0.0)],
            }],
            geometry: vec![DVec3::ZERO, DVec3::X * 3.0, DVec3::Y * 3.0],
            geometry_from: String::new(),
        };
        let arrows = mode_arrows(&v, 0, 0.5).expect("the mode is there");
        assert!(mode_arrows(&v, 1, 0.5).is_none());
        assert_eq!(arrows.len(), 2, "the atom that hardly moves has none");
        assert_eq!((arrows[0].from, arrows[0].to), (DVec3::ZERO, DVec3::Z * 3.0), "6 × 0.5 bohr");
        assert_eq!(arrows[1].to, DVec3::new(0.0, 3.0 - 1.5, 0.0), "half as long");
    }
}
