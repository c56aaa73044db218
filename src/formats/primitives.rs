//! The primitive model of AIM wavefunction files (`.wfn`, `.wfx`): every orbital is written as
//! coefficients over unnormalised cartesian primitives x^a y^b z^c exp(−α r²), each named by
//! its centre, a type code and its exponent; the coefficients absorb contraction and
//! normalisation.
//!
//! [`PrimitiveBasis`] turns such a list into the model's basis: one cartesian shell of one
//! primitive per (centre, l, exponent), its components unit-normalised as `model::basis` wants,
//! so a file coefficient c over x^a y^b z^c exp(−α r²) becomes c / N(α, a, b, c) on the
//! normalised component. A primitive written twice (writers that expand each contraction of a
//! generally contracted basis repeat the shared ones) is one function: its coefficients add.

use std::collections::HashMap;

use glam::DVec3;

use super::wavefunction::{cartesian_norm, powers};
use crate::model::basis::{Basis, Shell, ShellKind, cartesian_powers};

/// Highest type code: AIMAll's table runs from s (1) to h (36–56).
pub const MAX_TYPE: u32 = 56;

/// Types 1–35 (s to g) as AIMAll documents them; h (36–56) runs reverse alphabetically,
/// zzzzz to xxxxx.
const TYPES_TO_G: [&str; 35] = [
    "", "x", "y", "z", "xx", "yy", "zz", "xy", "xz", "yz", "xxx", "yyy", "zzz", "xxy", "xxz", "yyz", "xyy", "xzz",
    "yzz", "xyz", "xxxx", "yyyy", "zzzz", "xxxy", "xxxz", "xyyy", "yyyz", "xzzz", "yzzz", "xxyy", "xxzz", "yyzz",
    "xxyz", "xyyz", "xyzz",
];

/// Powers (a, b, c) of x^a y^b z^c for a type code 1..=[`MAX_TYPE`].
pub fn type_powers(code: u32) -> Option<[u32; 3]> {
    match code {
        1..=35 => Some(powers(TYPES_TO_G[code as usize - 1])),
        36..=MAX_TYPE => cartesian_powers(5).into_iter().rev().nth(code as usize - 36),
        _ => None,
    }
}

/// What the expected message says of type codes.
pub const TYPE_RANGE: &str = "a primitive type 1..=56 (AIMAll's codes: 1 s, 2–4 p, 5–10 d, 11–20 f, 21–35 g, 36–56 h)";

/// The model basis of a file's primitives, and where each primitive goes in it.
pub struct PrimitiveBasis {
    pub basis: Basis,
    /// Per file primitive: its model function and the factor 1/N(α, a, b, c) taking its
    /// coefficient to that function's.
    targets: Vec<(usize, f64)>,
    n_functions: usize,
}

impl PrimitiveBasis {
    /// `centres` index `positions` (bohr); `types` are valid codes and `exponents` positive
    /// (the readers check both where they read them). The slices have one entry per primitive.
    pub fn new(positions: &[DVec3], centres: &[usize], types: &[u32], exponents: &[f64]) -> Self {
        let mut shells: Vec<Shell> = Vec::new();
        let mut shell_of: HashMap<(usize, u32, u64), usize> = HashMap::new();
        let mut placed = Vec::with_capacity(centres.len());
        for ((&centre, &code), &alpha) in centres.iter().zip(types).zip(exponents) {
            let p = type_powers(code).unwrap_or([0, 0, 0]);
            let l = p.iter().sum();
            let shell = *shell_of.entry((centre, l, alpha.to_bits())).or_insert_with(|| {
                shells.push(Shell {
                    atom: centre,
                    center: positions[centre],
                    l,
                    kind: ShellKind::Cartesian,
                    exponents: vec![alpha],
                    coefficients: vec![1.0],
                });
                shells.len() - 1
            });
            let component = cartesian_powers(l).iter().position(|q| *q == p).unwrap_or(0);
            placed.push((shell, component, 1.0 / cartesian_norm(alpha, p)));
        }
        let basis = Basis { shells };
        let offsets = basis.shell_offsets();
        let targets = placed.into_iter().map(|(s, k, f)| (offsets[s] + k, f)).collect();
        Self { n_functions: basis.n_functions(), basis, targets }
    }

    /// An orbital's model coefficients from its coefficients over the file's primitives.
    pub fn orbital(&self, primitive_coefficients: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.n_functions];
        for (&(k, f), &c) in self.targets.iter().zip(primitive_coefficients) {
            out[k] += c * f;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::gto::PreparedBasis;

    #[test]
    fn the_type_table_covers_every_component_once() {
        for (l, range) in [(0, 1..=1), (1, 2..=4), (2, 5..=10), (3, 11..=20), (4, 21..=35), (5, 36..=56)] {
            let mut seen: Vec<[u32; 3]> = range.map(|c| type_powers(c).expect("a code")).collect();
            assert!(seen.iter().all(|p| p.iter().sum::<u32>() == l), "l = {l}");
            seen.sort();
            let mut all = cartesian_powers(l);
            all.sort();
            assert_eq!(seen, all, "l = {l}");
        }
        assert_eq!(type_powers(14), Some([2, 1, 0]), "xxy");
        assert_eq!(type_powers(26), Some([1, 3, 0]), "xyyy");
        assert_eq!(type_powers(36), Some([0, 0, 5]), "zzzzz");
        assert_eq!(type_powers(56), Some([5, 0, 0]), "xxxxx");
        assert_eq!(type_powers(0), None);
        assert_eq!(type_powers(57), None);
    }

    /// A primitive's value is its coefficient times x^a y^b z^c exp(−α r²), however it is
    /// grouped; a repeated primitive adds.
    #[test]
    fn primitives_keep_their_values() {
        let positions = [DVec3::ZERO, DVec3::new(0.0, 0.3, 1.4)];
        let centres = [0, 0, 1, 0, 1, 1];
        let types = [1, 15, 8, 1, 33, 8];
        let exponents = [1.3, 0.9, 0.7, 1.3, 1.1, 0.7];
        let coefficients = [0.4, -0.8, 0.3, 0.2, 0.5, 0.6];
        let pb = PrimitiveBasis::new(&positions, &centres, &types, &exponents);
        assert_eq!(pb.basis.shells.len(), 4, "s, f on atom 0; d, g on atom 1");
        let c = pb.orbital(&coefficients);
        let prepared = PreparedBasis::new(&pb.basis);
        for point in [DVec3::new(0.3, -0.2, 0.5), DVec3::new(-0.7, 0.4, 1.9)] {
            let mut want = 0.0;
            for i in 0..6 {
                let d = point - positions[centres[i]];
                let [a, b, e] = type_powers(types[i]).expect("code");
                want += coefficients[i]
                    * d.x.powi(a as i32)
                    * d.y.powi(b as i32)
                    * d.z.powi(e as i32)
                    * (-exponents[i] * d.length_squared()).exp();
            }
            let got = prepared.orbital_value(&c, point);
            assert!((got - want).abs() < 1e-13, "{got} vs {want}");
        }
    }
}
