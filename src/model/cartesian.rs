//! A linear combination of basis functions written out as plain cartesian Gaussians:
//! ψ(r) = Σ_s R_s(|r − A_s|) · Σ_c w_sc x^a y^b z^c, R_s(r) = Σ_p d_p e^(−α_p r²).
//!
//! This is what GPU kernels evaluate: pure shells are folded into cartesian weights and every
//! normalisation into the primitive coefficients and weights, so a kernel needs no tables.
//! [`CartesianExpansion::value`] is its CPU reference, term for term.

use glam::DVec3;

use super::basis::cartesian_powers;

#[derive(Debug, Clone, PartialEq)]
pub struct CartesianShell {
    pub center: DVec3,
    pub l: u32,
    /// Beyond this distance (bohr) the shell's contribution is negligible.
    pub cutoff: f64,
    /// (α, d) per primitive.
    pub primitives: Vec<[f64; 2]>,
    /// One weight per cartesian component, in orbcloud's order ([`cartesian_powers`]).
    pub weights: Vec<f64>,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct CartesianExpansion {
    pub shells: Vec<CartesianShell>,
}

impl CartesianExpansion {
    pub fn value(&self, p: DVec3) -> f64 {
        self.shells
            .iter()
            .map(|s| {
                let d = p - s.center;
                let r2 = d.length_squared();
                if r2 > s.cutoff * s.cutoff {
                    return 0.0;
                }
                let radial: f64 = s.primitives.iter().map(|[a, c]| c * (-a * r2).exp()).sum();
                let angular: f64 = cartesian_powers(s.l)
                    .iter()
                    .zip(&s.weights)
                    .map(|([a, b, c], w)| w * d.x.powi(*a as i32) * d.y.powi(*b as i32) * d.z.powi(*c as i32))
                    .sum();
                radial * angular
            })
            .sum()
    }
}

impl CartesianExpansion {
    /// The combination Σ_i c_i χ_i of a prepared basis's functions (an orbital's coefficients,
    /// or a masked subset), shells with no weight left out.
    pub fn from_coefficients(basis: &super::gto::PreparedBasis, coefficients: &[f64]) -> Self {
        let (weights, active) = basis.monomial_coefficients(coefficients);
        Self::over_shells(basis, &weights, &active)
    }

    /// The combination whose cartesian weights are `weights` (the basis's cartesians), over the
    /// shells `keep` marks.
    fn over_shells(basis: &super::gto::PreparedBasis, weights: &[f64], keep: &[bool]) -> Self {
        let mut shells = Vec::new();
        for (s, &on) in basis.shells.iter().zip(keep) {
            let n = super::basis::n_cartesian(s.l);
            if on {
                shells.push(CartesianShell {
                    center: s.center(),
                    l: s.l,
                    cutoff: s.cutoff,
                    primitives: s.primitives().map(|p| [basis.exponents[p], basis.coefficients[p]]).collect(),
                    weights: weights[s.first_cartesian as usize..s.first_cartesian as usize + n].to_vec(),
                });
            }
        }
        Self { shells }
    }
}

/// A density Σ_i n_i ψ_i² whose orbitals are written out over one set of shells (those any of
/// them uses; an orbital's weights are zero on the shells it does not), so that a kernel reads
/// each shell's primitives once for several orbitals: what the GPU's density-derivative pass
/// evaluates. [`CartesianDensity::density`] is its CPU reference.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CartesianDensity {
    /// One expansion per orbital, all over the same shells in the same order.
    pub orbitals: Vec<CartesianExpansion>,
    /// n_i per orbital (any sign).
    pub occupations: Vec<f64>,
}

impl CartesianDensity {
    /// The density of `sets` (each an orbital's coefficients over `basis`'s functions and its
    /// occupation).
    pub fn new(basis: &super::gto::PreparedBasis, sets: &[(&[f64], f64)]) -> Self {
        let expanded: Vec<(Vec<f64>, Vec<bool>)> = sets.iter().map(|(c, _)| basis.monomial_coefficients(c)).collect();
        let mut used = vec![false; basis.shells.len()];
        for (_, active) in &expanded {
            for (u, a) in used.iter_mut().zip(active) {
                *u |= a;
            }
        }
        Self {
            orbitals: expanded.iter().map(|(w, _)| CartesianExpansion::over_shells(basis, w, &used)).collect(),
            occupations: sets.iter().map(|(_, n)| *n).collect(),
        }
    }

    /// ρ at a point.
    pub fn density(&self, p: DVec3) -> f64 {
        self.orbitals.iter().zip(&self.occupations).map(|(o, n)| n * o.value(p).powi(2)).sum()
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::model::basis::{Basis, Shell, ShellKind};
    use crate::model::gto::PreparedBasis;

    #[test]
    fn a_density_of_orbitals_over_shared_shells_equals_the_evaluator() {
        // Two orbitals using different shells: each is written out over the union, with zero
        // weights on the shells it does not use.
        let shell = |l: u32, kind: ShellKind, x: f64| Shell {
            atom: 0,
            center: DVec3::new(x, 0.2, -0.1),
            l,
            kind,
            exponents: vec![1.5, 0.3],
            coefficients: vec![0.4, 0.7],
        };
        let basis = Basis {
            shells: vec![
                shell(0, ShellKind::Pure, 0.0),
                shell(2, ShellKind::Pure, 1.0),
                shell(3, ShellKind::Cartesian, -1.0),
            ],
        };
        let prepared = PreparedBasis::new(&basis);
        let n = prepared.n_functions();
        let a: Vec<f64> = (0..n).map(|i| if i < 6 { 0.3 + 0.1 * i as f64 } else { 0.0 }).collect();
        let b: Vec<f64> = (0..n).map(|i| if i == 0 || i >= 6 { 0.5 - 0.05 * i as f64 } else { 0.0 }).collect();
        let density = CartesianDensity::new(&prepared, &[(&a, 2.0), (&b, -0.5)]);
        assert_eq!(density.orbitals.len(), 2);
        assert!(density.orbitals.iter().all(|o| o.shells.len() == 3));
        for k in 0..20 {
            let p = DVec3::new(k as f64 * 0.15 - 1.5, 0.1 * (k % 3) as f64, 0.3);
            let want = 2.0 * prepared.orbital_value(&a, p).powi(2) - 0.5 * prepared.orbital_value(&b, p).powi(2);
            assert!((density.density(p) - want).abs() <= 1e-12 * want.abs().max(1.0));
        }
    }

    #[test]
    fn expansion_equals_the_evaluator() {
        // Cartesian and pure shells up to h, contracted, on three centres.
        let mut shells = Vec::new();
        for (i, l) in (0..=5u32).enumerate() {
            for kind in [ShellKind::Cartesian, ShellKind::Pure] {
                shells.push(Shell {
                    atom: i % 3,
                    center: DVec3::new(i as f64 * 0.4 - 1.0, 0.3 * (i % 2) as f64, -0.2 * i as f64),
                    l,
                    kind,
                    exponents: vec![2.5, 0.6, 0.15],
                    coefficients: vec![0.2, 0.5, 0.4],
                });
            }
        }
        let basis = Basis { shells };
        let prepared = PreparedBasis::new(&basis);
        let n = prepared.n_functions();
        let coefficients: Vec<f64> = (0..n).map(|i| ((i * 37 % 11) as f64 - 5.0) / 7.0).collect();
        let e = CartesianExpansion::from_coefficients(&prepared, &coefficients);
        for k in 0..40 {
            let p = DVec3::new((k as f64 * 0.37).sin() * 2.0, (k as f64 * 0.91).cos() * 1.5, k as f64 * 0.05 - 1.0);
            let want = prepared.orbital_value(&coefficients, p);
            let got = e.value(p);
            assert!((got - want).abs() <= 1e-10 * want.abs().max(1.0), "{p}: {got} vs {want}");
        }
    }
}
