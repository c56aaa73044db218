//! Synthetic structures for benchmarks and tests: atoms packed as densely as in a protein.

use glam::DVec3;

use super::molecule::{Atom, Molecule};
use super::units::BOHR_PER_ANGSTROM;

/// Mean spacing of a protein's heavy atoms (about one atom per 10 Å³).
pub const PROTEIN_SPACING_ANG: f64 = 2.2;

/// `n` atoms (C, N, O, S, H in turn) on a jittered cubic lattice of
/// [`PROTEIN_SPACING_ANG`], centred on the origin; no bonds. Deterministic.
pub fn atom_box(n: usize) -> Molecule {
    let side = (n as f64).cbrt().ceil().max(1.0) as usize;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut jitter = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let spacing = PROTEIN_SPACING_ANG * BOHR_PER_ANGSTROM;
    let half = 0.5 * (side - 1) as f64;
    let atoms = (0..n)
        .map(|i| {
            let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
            let p = DVec3::new(x as f64 - half, y as f64 - half, z as f64 - half);
            let z_of = [6, 7, 8, 16, 1][i % 5];
            let position = (p + 0.3 * DVec3::new(jitter(), jitter(), jitter())) * spacing;
            Atom { z: z_of, charge: z_of as f64, position, ghost: false }
        })
        .collect();
    Molecule { atoms, bonds: Vec::new() }
}

#[cfg(test)]
mod tests {
    #[test]
    fn boxes_hold_what_was_asked() {
        let m = super::atom_box(1000);
        assert_eq!(m.atoms.len(), 1000);
        let (lo, hi) = m.bounds().unwrap();
        assert!((hi - lo).max_element() < 11.0 * super::PROTEIN_SPACING_ANG * super::BOHR_PER_ANGSTROM);
    }
}
