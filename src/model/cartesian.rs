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
