//! What one opened file gives the viewer: a molecule and zero or more volumes.

use super::{Molecule, VolumeGrid};

#[derive(Debug, Clone, Default)]
pub struct Document {
    /// Where it came from, for status lines and error messages.
    pub source: String,
    pub title: String,
    pub molecule: Molecule,
    /// One volume per data set (a multi-orbital cube gives several).
    pub volumes: Vec<VolumeGrid>,
}
