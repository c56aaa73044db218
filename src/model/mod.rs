//! The in-memory model: molecules, elements, bonds and volume grids.
//!
//! Everything here is in bohr and knows nothing of files, the GPU or the UI.

pub mod basis;
pub mod bonds;
pub mod document;
mod element_table;
pub mod elements;
pub mod grid;
pub mod molecule;
pub mod orbitals;
pub mod solid_harmonics;
pub mod units;

pub use document::Document;
pub use grid::{GridStats, VolumeGrid};
pub use molecule::{Atom, Bond, Molecule};
pub use orbitals::{MolecularOrbital, Spin, Wavefunction};
