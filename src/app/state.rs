//! What the user has set: plain data, separate from what owns GPU resources.

use serde::{Deserialize, Serialize};

use crate::model::orbitals::{Quantity, Spin, Wavefunction};
use crate::scene::{Camera, RenderSettings};

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct ViewState {
    pub camera: Camera,
    pub settings: RenderSettings,
    /// Which volume of the document is shown.
    pub volume: usize,
    /// Element and number beside every atom.
    #[serde(default)]
    pub labels: bool,
}

/// Keyboard rotation step, radians.
pub const KEY_ROTATE: f32 = 5.0 * std::f32::consts::PI / 180.0;
/// Keyboard zoom factor per press.
pub const KEY_ZOOM: f32 = 1.1;
/// Mouse orbit, radians per point dragged.
pub const DRAG_ROTATE: f32 = 0.008;

/// The orbital browser's choices.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrbitalView {
    pub shown: Quantity,
    pub spin: Spin,
    /// Evaluate per slice sample (seed 004's direct mode) instead of on a GPU-filled grid.
    pub direct: bool,
    /// Restrict the orbital to the shells ticked in `shell_mask`.
    pub ao_filter: bool,
    pub shell_mask: Vec<bool>,
    /// Points per axis of the GPU grid.
    pub grid_points: usize,
}

impl Default for OrbitalView {
    fn default() -> Self {
        Self {
            shown: Quantity::Density,
            spin: Spin::Alpha,
            direct: false,
            ao_filter: false,
            shell_mask: Vec::new(),
            grid_points: 72,
        }
    }
}

impl OrbitalView {
    /// Opens on the HOMO, as a chemist expects.
    pub fn for_wavefunction(wf: &Wavefunction) -> Self {
        let shown = wf.homo(Spin::Alpha).map_or(Quantity::Density, Quantity::Orbital);
        Self { shown, shell_mask: vec![true; wf.basis.shells.len()], ..Self::default() }
    }

    /// The spin whose orbitals are listed (restricted wavefunctions have only alpha).
    pub fn spin_of(&self, wf: &Wavefunction) -> Spin {
        if wf.restricted { Spin::Alpha } else { self.spin }
    }
}
