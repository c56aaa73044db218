//! The in-memory model: molecules, elements, bonds, volume grids, basis sets and orbitals
//! (with their evaluation: `gto`, `overlap`, `solid_harmonics`).
//!
//! Everything here is in bohr and knows nothing of files, the GPU or the UI.

pub mod arrow;
pub mod atom;
mod atomic_masses;
pub mod basis;
pub mod basis_labels;
pub mod bonds;
pub mod boys;
pub mod bricks;
pub mod cartesian;
pub mod correlation;
pub mod document;
pub mod eigen;
mod element_table;
pub mod elements;
pub mod esp;
mod evaluation;
pub mod excited;
pub mod excited_density;
pub mod extent;
pub mod grid;
pub mod gto;
pub mod isosurface;
pub mod measure;
pub mod molecule;
pub mod nci;
pub mod neighbours;
pub mod nto;
pub mod octree;
mod orbital_sums;
pub mod orbitals;
pub mod overlap;
pub mod promolecular;
pub mod rigid;
pub mod scan;
mod separable;
pub mod simplify;
pub mod solid_harmonics;
pub mod spectrum;
pub mod structure;
pub mod superpose;
pub mod surface;
pub mod synthetic;
pub mod transition;
pub mod units;
pub mod vibrations;

pub use document::Document;
pub use grid::{GridSpec, GridStats, VolumeGrid};
pub use gto::PreparedBasis;
pub use molecule::{Atom, Bond, Molecule};
pub use orbitals::{MolecularOrbital, Spin, Wavefunction};
pub use structure::{Structure, StructureView};
