//! How an object shows its normal modes: the mode animated, its amplitude and speed, its
//! displacement arrows, and the IR spectrum's broadening. Plain data, saved in sessions.

use serde::{Deserialize, Serialize};

/// Linear RGB of a mode's arrows.
pub const ARROW_COLOR: [f32; 3] = [0.95, 0.75, 0.1];

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct VibrationState {
    /// The mode shown (0-based, as the file lists them), if any.
    pub mode: Option<usize>,
    /// Whether the atoms oscillate (else they rest at the largest displacement).
    pub playing: bool,
    /// The largest atom's displacement at the turning points, bohr.
    pub amplitude: f32,
    /// Oscillations per second on screen.
    pub speed: f32,
    /// Each atom's displacement drawn as an arrow (scaled with the amplitude).
    pub arrows: bool,
    /// The IR spectrum's broadening: full width at half maximum, cm⁻¹.
    pub fwhm: f32,
    /// Lorentzian (else Gaussian) bands.
    pub lorentzian: bool,
}

impl Default for VibrationState {
    fn default() -> Self {
        Self { mode: None, playing: true, amplitude: 0.4, speed: 1.0, arrows: true, fwhm: 15.0, lorentzian: true }
    }
}

impl VibrationState {
    /// Where in its oscillation the shown mode is `seconds` into the animation (radians); a
    /// paused mode rests at its largest displacement.
    pub fn phase(&self, seconds: f64) -> f64 {
        match self.playing {
            true => std::f64::consts::TAU * self.speed as f64 * seconds,
            false => std::f64::consts::FRAC_PI_2,
        }
    }

    /// What the arrows depend on: when it changes they are built again.
    pub fn arrows_key(&self) -> Option<(usize, u32)> {
        self.mode.filter(|_| self.arrows).map(|m| (m, self.amplitude.to_bits()))
    }
}
