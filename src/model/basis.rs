//! Gaussian basis sets: shells of contracted primitives on atoms, cartesian or pure.
//!
//! Conventions inside orbcloud (readers convert to these once):
//! - positions in bohr;
//! - contraction coefficients multiply *normalised* primitives (as Molden and fchk write them);
//! - every basis function — each cartesian component, each real solid harmonic — has unit norm;
//! - cartesian components in alphabetical order of their exponents (x before y before z, higher
//!   powers first): l=2 xx, xy, xz, yy, yz, zz; l=3 xxx, xxy, xxz, xyy, xyz, xzz, yyy, yyz, yzz,
//!   zzz; and so on ([`cartesian_powers`]);
//! - pure functions in the order m = 0, +1, −1, +2, −2, … (Molden's and Gaussian's), real
//!   solid harmonics without the Condon–Shortley phase (d+2 = x² − y², f+3 = x³ − 3xy²).

use glam::DVec3;

/// Highest angular momentum the viewer evaluates (h functions).
pub const MAX_L: u32 = 5;

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum ShellKind {
    Cartesian,
    Pure,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Shell {
    /// Index of the atom the shell sits on.
    pub atom: usize,
    /// Centre in bohr (the atom's position).
    pub center: DVec3,
    pub l: u32,
    pub kind: ShellKind,
    pub exponents: Vec<f64>,
    /// Contraction coefficients for normalised primitives, one per exponent.
    pub coefficients: Vec<f64>,
}

impl Shell {
    /// Number of basis functions: (l+1)(l+2)/2 cartesian or 2l+1 pure.
    pub fn n_functions(&self) -> usize {
        match self.kind {
            ShellKind::Cartesian => n_cartesian(self.l),
            ShellKind::Pure => 2 * self.l as usize + 1,
        }
    }
}

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Basis {
    pub shells: Vec<Shell>,
}

impl Basis {
    pub fn n_functions(&self) -> usize {
        self.shells.iter().map(Shell::n_functions).sum()
    }

    /// Index of each shell's first function.
    pub fn shell_offsets(&self) -> Vec<usize> {
        let mut offsets = Vec::with_capacity(self.shells.len());
        let mut n = 0;
        for s in &self.shells {
            offsets.push(n);
            n += s.n_functions();
        }
        offsets
    }
}

pub fn n_cartesian(l: u32) -> usize {
    ((l + 1) * (l + 2) / 2) as usize
}

/// Cartesian exponents (a, b, c) of x^a y^b z^c for angular momentum `l`, in orbcloud's order.
pub fn cartesian_powers(l: u32) -> Vec<[u32; 3]> {
    let mut out = Vec::with_capacity(n_cartesian(l));
    for a in (0..=l).rev() {
        for b in (0..=l - a).rev() {
            out.push([a, b, l - a - b]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cartesian_order_is_alphabetical() {
        assert_eq!(cartesian_powers(1), vec![[1, 0, 0], [0, 1, 0], [0, 0, 1]]);
        assert_eq!(cartesian_powers(2), vec![[2, 0, 0], [1, 1, 0], [1, 0, 1], [0, 2, 0], [0, 1, 1], [0, 0, 2]]);
        for l in 0..=MAX_L {
            assert_eq!(cartesian_powers(l).len(), n_cartesian(l));
        }
    }
}
