//! What one opened file gives the viewer: a molecule and zero or more volumes.

use super::excited::ExcitedStates;
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
    /// Normal modes of vibration (Molden `[FREQ]`…, fchk `Vib-Modes`, frequency jobs' logs).
    pub vibrations: Option<Vibrations>,
    /// Excited states the file lists (a TD job's log or fchk); their densities, where the file
    /// holds one, are the wavefunction's ([`Wavefunction::excited`]).
    pub excited: Option<ExcitedStates>,
    /// Parts of the file that could not be read while the rest opened, each saying where and
    /// what was expected (a malformed mode section).
    pub problems: Vec<String>,
    /// The coordinate a scan job varied and its value at each frame of `structure` (a Gaussian
    /// `opt=modredundant` scan's log): its frames are a scan of geometries.
    pub job_scan: Option<super::scan::JobScan>,
    /// The scan this document is a frame of (a `.scan.toml`): `molecule` is its skeleton at the
    /// object's value, and its orbitals are quantities of their own ([`crate::scene::Source::Scan`]).
    pub scan: Option<std::sync::Arc<super::scan::Scan>>,
}

impl Document {
    /// Bounds (bohr) of the atoms (as spheres of their covalent radius) and every volume's box; `None` for
    /// an empty document.
    pub fn bounds(&self) -> Option<(glam::DVec3, glam::DVec3)> {
        let atoms = self.molecule.atoms.iter().flat_map(|a| {
            let r = glam::DVec3::splat(a.element().covalent_radius as f64 * super::units::BOHR_PER_ANGSTROM);
            [a.position - r, a.position + r]
        });
        let points = atoms.chain(self.volumes.iter().flat_map(super::grid::VolumeGrid::corners));
        points.fold(None, |acc, p| match acc {
            None => Some((p, p)),
            Some((lo, hi)) => Some((lo.min(p), hi.max(p))),
        })
    }
}

/// How far apart two files' atoms may be and still be one molecule (bohr): cube writers print
/// six decimals, some of them in ångström.
const SAME_PLACE: f64 = 1e-4;

impl Document {
    /// Whether `other` holds the same atoms at the same places (the same molecule written by
    /// another run or tool).
    pub fn same_atoms(&self, other: &Document) -> bool {
        let (a, b) = (&self.molecule.atoms, &other.molecule.atoms);
        a.len() == b.len() && a.iter().zip(b).all(|(a, b)| a.z == b.z && a.position.distance(b.position) <= SAME_PLACE)
    }

    /// Whether it is values on grids and nothing else (a cube file): another such file of the
    /// same molecule can [`Self::join`] it.
    pub fn is_grid_only(&self) -> bool {
        !self.volumes.is_empty() && self.wavefunction.is_none() && self.structure.is_none()
    }

    /// Whether it lists excited states with their printed transitions and has no orbitals of its
    /// own (a TD job's log): the orbitals of another file of the same atoms give them their
    /// natural transition orbitals ([`Self::join`]).
    pub fn carries_transitions(&self) -> bool {
        self.wavefunction.is_none()
            && self.excited.as_ref().is_some_and(|e| e.states.iter().any(|s| !s.transitions.is_empty()))
    }

    /// Whether `other` holds the same molecule, perhaps turned or moved: the same elements in
    /// the same order at the same distances from one another (a program's log and its
    /// checkpoint may write different orientations). Molecules of more than
    /// [`MOST_ATOMS_COMPARED`] atoms are compared in place ([`Self::same_atoms`]).
    pub fn same_molecule(&self, other: &Document) -> bool {
        let (a, b) = (&self.molecule.atoms, &other.molecule.atoms);
        if a.len() > MOST_ATOMS_COMPARED {
            return self.same_atoms(other);
        }
        a.len() == b.len()
            && a.iter().zip(b).all(|(x, y)| x.z == y.z)
            && (0..a.len()).all(|i| {
                (0..i).all(|j| {
                    let d = a[i].position.distance(a[j].position) - b[i].position.distance(b[j].position);
                    d.abs() <= SAME_SHAPE
                })
            })
    }

    /// Whether `other` can [`Self::join`] this document.
    pub fn joins(&self, other: &Document) -> bool {
        let grids = self.is_grid_only() && other.is_grid_only() && self.same_atoms(other);
        let states = self.wavefunction.is_some() && other.carries_transitions() && self.same_molecule(other);
        grids || states
    }

    /// Takes in `other`, a file of the same atoms: its data sets appended to this grid-only
    /// document's (a potential cube joining the density cube made beside it; returns the index
    /// of the first one appended), or its excited states' printed transitions given to this
    /// document's orbitals (a TD log joining its checkpoint: the states this document lists take
    /// their transitions, matched by number and energy, unless they have their own, and their
    /// spin and symmetry where the file names none; a document listing none takes the log's).
    /// Refused, with the reason, otherwise.
    pub fn join(&mut self, other: Document) -> Result<usize, String> {
        // Transitions name orbitals, not places: a log may write its molecule turned.
        if self.wavefunction.is_some() && other.carries_transitions() {
            if !self.same_molecule(&other) {
                return Err(format!("{}: its molecule is not that of {}", other.source, self.source));
            }
            let theirs = other.excited.unwrap_or_default();
            match &mut self.excited {
                None => self.excited = Some(theirs),
                Some(ours) => {
                    for state in &mut ours.states {
                        let twin = theirs
                            .states
                            .iter()
                            .find(|t| t.number == state.number && (t.energy_ev - state.energy_ev).abs() < STATE_ENERGY);
                        // A file's own amplitudes (Q-Chem's fchk holds them all) are kept over
                        // a log's printed few; what the file leaves unsaid the log says.
                        if let Some(twin) = twin {
                            if state.transitions.is_empty() {
                                state.transitions = twin.transitions.clone();
                                state.amplitudes_normalised_to_one = twin.amplitudes_normalised_to_one;
                            }
                            if state.spin.is_empty() {
                                state.spin = twin.spin.clone();
                            }
                            if state.symmetry.is_empty() {
                                state.symmetry = twin.symmetry.clone();
                            }
                            state.s_squared = state.s_squared.or(twin.s_squared);
                        }
                    }
                    if ours.states.iter().all(|s| !s.spin.is_empty()) {
                        ours.note.clear();
                    }
                }
            }
            // The log's own problems (it has no orbitals to draw) are not this document's.
            return Ok(self.volumes.len());
        }
        if !self.same_atoms(&other) {
            return Err(format!("{}: its atoms are not those of {}", other.source, self.source));
        }
        if !self.is_grid_only() || !other.is_grid_only() {
            return Err(format!(
                "{}: only data sets on grids, or a TD log's states onto orbitals, join another file's",
                other.source
            ));
        }
        let first = self.volumes.len();
        self.volumes.extend(other.volumes);
        self.problems.extend(other.problems);
        Ok(first)
    }
}

/// The most atoms whose distances [`Document::same_molecule`] compares (n² of them).
const MOST_ATOMS_COMPARED: usize = 2000;

/// How much two files' interatomic distances may differ in one molecule (bohr): logs print
/// ångström to 6 decimals.
const SAME_SHAPE: f64 = 1e-3;

/// How far two files' excitation energies of one state may differ (eV): a log prints 4
/// decimals, an fchk's `ETran` records more.
const STATE_ENERGY: f64 = 1e-3;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::atom::Atom;
    use crate::model::grid::VolumeGrid;

    fn cube(atoms: &[(u32, [f64; 3])], label: &str) -> Document {
        let atoms = atoms
            .iter()
            .map(|&(z, p)| Atom { z, charge: z as f64, position: glam::DVec3::from_array(p), ghost: false })
            .collect();
        let grid = VolumeGrid::new(label, [2, 2, 2], glam::DMat4::IDENTITY, vec![0.0; 8]);
        Document {
            source: format!("{label}.cube"),
            molecule: Molecule::new(atoms),
            volumes: vec![grid],
            ..Default::default()
        }
    }

    #[test]
    fn a_cube_of_the_same_atoms_joins_and_others_are_refused() {
        let water = [(8, [0.0, 0.0, 0.0]), (1, [1.4, 1.1, 0.0]), (1, [-1.4, 1.1, 0.0])];
        let mut density = cube(&water, "density");
        let mut moved = water;
        moved[1].1[0] += 1e-5;
        assert_eq!(density.join(cube(&moved, "potential")), Ok(1));
        assert_eq!(density.volumes.len(), 2);
        assert_eq!(density.volumes[1].label, "potential");

        moved[1].1[0] += 1e-2;
        let e = density.join(cube(&moved, "far")).unwrap_err();
        assert!(e.contains("far.cube") && e.contains("not those of density.cube"), "{e}");
        let e = density.join(cube(&water[..2], "fewer")).unwrap_err();
        assert!(e.contains("not those"), "{e}");
        let mut swapped = water;
        swapped[0].0 = 7;
        assert!(density.join(cube(&swapped, "nitrogen")).is_err());
        let mut orbitals = cube(&water, "molden");
        orbitals.wavefunction = None;
        orbitals.volumes.clear();
        assert!(density.join(orbitals).unwrap_err().contains("only data sets"));
        assert_eq!(density.volumes.len(), 2, "a refused file leaves the document as it was");
    }
}
