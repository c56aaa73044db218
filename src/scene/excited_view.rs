//! How an object shows its excited states: the state picked and the UV-vis spectrum's
//! broadening and axis. Plain data, saved in sessions.

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ExcitedView {
    /// The state picked (0-based, as the file lists them), if any.
    pub state: Option<usize>,
    /// The bands' full width at half maximum, eV (Gaussian bands, as UV-vis spectra are drawn).
    pub fwhm_ev: f32,
    /// The spectrum's axis in nm (else eV).
    pub nanometres: bool,
}

impl Default for ExcitedView {
    fn default() -> Self {
        Self { state: None, fwhm_ev: 0.3, nanometres: false }
    }
}
