//! Molecular orbitals over a basis: coefficients, energies, occupations, spin.

use serde::Serialize;

use super::basis::Basis;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Spin {
    Alpha,
    Beta,
}

#[derive(Debug, Clone, PartialEq)]
pub struct MolecularOrbital {
    /// Energy in hartree (NaN when the file gives none).
    pub energy: f64,
    /// Electrons in the orbital: 0..2 for restricted, 0..1 for unrestricted.
    pub occupation: f64,
    pub spin: Spin,
    /// Symmetry label as written ("" when none).
    pub symmetry: String,
    /// One coefficient per basis function, in the basis's function order.
    pub coefficients: Vec<f64>,
}

/// How a file's coefficients were made to describe orthonormal orbitals.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct Normalization {
    /// The writer the reader recognised ("ORCA", "Turbomole", "unknown", …).
    pub program: String,
    /// The repair applied, if any ("none" when the file was right as written).
    pub repair: String,
    /// max |CᵀSC − I| over the orbitals after the repair.
    pub residual: f64,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Wavefunction {
    pub basis: Basis,
    /// Alpha orbitals first (all orbitals of a restricted calculation are alpha), then beta.
    pub orbitals: Vec<MolecularOrbital>,
    /// True when alpha and beta share spatial orbitals.
    pub restricted: bool,
    pub normalization: Normalization,
}

impl Wavefunction {
    /// Orbitals of one spin, with their indices into `orbitals`, in file order.
    pub fn of_spin(&self, spin: Spin) -> impl Iterator<Item = (usize, &MolecularOrbital)> {
        self.orbitals.iter().enumerate().filter(move |(_, o)| o.spin == spin)
    }

    /// Index of the highest occupied orbital of a spin (by energy), if any.
    pub fn homo(&self, spin: Spin) -> Option<usize> {
        self.of_spin(spin)
            .filter(|(_, o)| o.occupation > 1e-6)
            .max_by(|a, b| a.1.energy.total_cmp(&b.1.energy))
            .map(|(i, _)| i)
    }

    /// Index of the lowest unoccupied orbital of a spin (by energy), if any.
    pub fn lumo(&self, spin: Spin) -> Option<usize> {
        self.of_spin(spin)
            .filter(|(_, o)| o.occupation <= 1e-6)
            .min_by(|a, b| a.1.energy.total_cmp(&b.1.energy))
            .map(|(i, _)| i)
    }
}
