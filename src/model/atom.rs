//! An atom (element, nuclear charge, position in bohr) and a bond between two atoms.

use glam::DVec3;

use super::elements::{ElementData, element};

#[derive(Debug, Clone, PartialEq)]
pub struct Atom {
    /// Atomic number; 0 for a dummy centre.
    pub z: u32,
    /// Nuclear charge as the file gives it (cube files: often Z, may be 0 or a pseudo charge).
    pub charge: f64,
    /// Position in bohr.
    pub position: DVec3,
    /// A ghost carries basis functions or a label but no nucleus; drawn faintly, never bonded.
    pub ghost: bool,
}

impl Atom {
    pub fn element(&self) -> &'static ElementData {
        element(self.z)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bond {
    pub a: u32,
    pub b: u32,
}
