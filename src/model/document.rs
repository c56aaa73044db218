//! What one opened file gives the viewer: a molecule and zero or more volumes.

use super::vibrations::Vibrations;
use super::{Molecule, StructureView, VolumeGrid, Wavefunction};

#[derive(Debug, Clone, Default)]
pub struct Document {
    /// Where it came from, for status lines and error messages.
    pub source: String,
    pub title: String,
    pub molecule: Molecule,
    /// One volume per data set (a multi-orbital cube gives several).
    pub volumes: Vec<VolumeGrid>,
    /// Basis set and orbitals (Molden, fchk); `None` for grid-only files.
    pub wavefunction: Option<Wavefunction>,
    /// Residues, chains, models and per-atom annotations (PDB, mmCIF, multi-frame XYZ);
    /// `molecule` is the model it shows.
    pub structure: Option<StructureView>,
    /// Normal modes of vibration (Molden `[FREQ]`…, fchk `Vib-Modes`).
    pub vibrations: Option<Vibrations>,
    /// Parts of the file that could not be read while the rest opened, each saying where and
    /// what was expected (a malformed mode section).
    pub problems: Vec<String>,
}

impl Document {
    /// Bounds (bohr) of the atoms (as spheres of their covalent radius) and every volume's box; `None` for
    /// an empty document.
    pub fn bounds(&self) -> Option<(glam::DVec3, glam::DVec3)> {
        let atoms = self.molecule.atoms.iter().flat_map(|a| {
            let r = glam::DVec3::splat(a.element().covalent_radius as f64 * super::units::BOHR_PER_ANGSTROM);
            [a.position - r, a.position + r]
        });
        let points = atoms.chain(self.volumes.iter().flat_map(|v| v.corners()));
        points.fold(None, |acc, p| match acc {
            None => Some((p, p)),
            Some((lo, hi)) => Some((lo.min(p), hi.max(p))),
        })
    }
}
