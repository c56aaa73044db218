//! Excited states as a program lists them: per state its excitation energy, wavelength,
//! oscillator strength, spin, symmetry and main one-electron transitions.

use serde::Serialize;

use super::spectrum::{self, Line};
use super::units::EV_PER_HARTREE;

/// hc in eV·nm: a photon of E eV has a wavelength of `EV_NM / E` nm (CODATA 2018).
pub const EV_NM: f64 = 1_239.841_984;

/// The excited states a file lists, in the file's order.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct ExcitedStates {
    /// The program that computed them ("Gaussian", "ORCA", "Q-Chem").
    pub program: String,
    /// The method as the file names it ("TD-DFT/TDA", "TD"), "" when it does not.
    pub method: String,
    pub states: Vec<ExcitedState>,
    /// The state whose density the file holds (1-based, as `states[k].number`), if any.
    pub density_of: Option<usize>,
    /// What the file leaves unsaid about its states (Q-Chem's fchk names no spins), "" when
    /// nothing.
    pub note: String,
}

/// One excited state.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct ExcitedState {
    /// 1-based, as the program numbers it.
    pub number: usize,
    /// Excitation energy above the ground state, eV.
    pub energy_ev: f64,
    /// The state's total energy (hartree), where the file gives it.
    pub total_energy_hartree: Option<f64>,
    /// Oscillator strength (length gauge), where the file gives it.
    pub oscillator_strength: Option<f64>,
    /// "Singlet", "Triplet", …, or ⟨S²⟩'s label an unrestricted run prints ("3.012"); "" when
    /// not given.
    pub spin: String,
    /// The irreducible representation ("Bu", "A"), "" when not given.
    pub symmetry: String,
    /// ⟨S²⟩ where printed.
    pub s_squared: Option<f64>,
    /// The one-electron transitions printed for the state, largest first.
    pub transitions: Vec<Transition>,
    /// Whether a restricted run's amplitudes are printed normalised to 1 (ORCA's `c`, Q-Chem's
    /// log) rather than to ½ (Gaussian, PySCF, Q-Chem's fchk): the transition density needs
    /// the convention, NTO weights (normalised) do not.
    pub amplitudes_normalised_to_one: bool,
}

/// One orbital-to-orbital contribution to a state.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Transition {
    /// 1-based orbital numbers within their spin, as Gaussian prints them (ORCA's 0-based and
    /// Q-Chem's occupied/virtual counts are converted).
    pub from: usize,
    pub to: usize,
    /// The printed coefficient (Gaussian, Q-Chem: the amplitude; ORCA: c).
    pub coefficient: f64,
    /// "alpha" or "beta" in unrestricted runs, "" otherwise.
    pub spin: String,
    /// A de-excitation (Gaussian's `<-`: the Y part of TD-DFT).
    pub deexcitation: bool,
}

impl ExcitedStates {
    /// Each state's line in a UV-vis spectrum (energy eV, oscillator strength); none for a state
    /// without a strength.
    pub fn lines(&self) -> Vec<Option<Line>> {
        (self.states.iter()).map(|s| Some(Line { position: s.energy_ev, height: s.oscillator_strength? })).collect()
    }

    /// The UV-vis spectrum from `from` to `to` eV in `points` steps: each state's oscillator
    /// strength broadened to a Gaussian of full width `fwhm` eV at half maximum.
    pub fn uv_vis(&self, range: (f64, f64), points: usize, fwhm: f64) -> Vec<[f64; 2]> {
        let lines: Vec<Line> = self.lines().into_iter().flatten().collect();
        spectrum::broadened(&lines, range, points, fwhm, false)
    }

    /// The state (index into `states`) whose band is highest at `energy_ev` in [`Self::uv_vis`]
    /// (a click on the spectrum); else the nearest state within `tolerance` eV (dark states
    /// have no band).
    pub fn band_at(&self, energy_ev: f64, fwhm: f64, tolerance: f64) -> Option<usize> {
        spectrum::tallest_at(&self.lines(), energy_ev, fwhm, false, tolerance).or_else(|| {
            (self.states.iter().enumerate())
                .filter(|(_, s)| (s.energy_ev - energy_ev).abs() <= tolerance)
                .min_by(|a, b| (a.1.energy_ev - energy_ev).abs().total_cmp(&(b.1.energy_ev - energy_ev).abs()))
                .map(|(k, _)| k)
        })
    }
}

impl ExcitedState {
    /// The wavelength of a photon of the excitation energy, nm (infinite for 0 eV).
    pub fn wavelength_nm(&self) -> f64 {
        EV_NM / self.energy_ev
    }

    /// The excitation energy in hartree.
    pub fn energy_hartree(&self) -> f64 {
        self.energy_ev / EV_PER_HARTREE
    }

    /// The transitions with the largest |coefficient| first, at most `n`.
    pub fn main_transitions(&self, n: usize) -> Vec<&Transition> {
        let mut t: Vec<&Transition> = self.transitions.iter().collect();
        t.sort_by(|a, b| b.coefficient.abs().total_cmp(&a.coefficient.abs()));
        t.truncate(n);
        t
    }
}

/// The oscillator strength of a transition of `energy_hartree` with transition dipole `dipole`
/// (a.u., length gauge): f = ⅔ ΔE |μ|².
pub fn oscillator_strength(energy_hartree: f64, dipole: [f64; 3]) -> f64 {
    2.0 / 3.0 * energy_hartree * dipole.iter().map(|d| d * d).sum::<f64>()
}

impl std::fmt::Display for Transition {
    /// "34 -> 36 0.52587", "35 <- 37 -0.01172", "34 -> 36 (beta) 0.7".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let arrow = if self.deexcitation { "<-" } else { "->" };
        let spin = if self.spin.is_empty() { String::new() } else { format!(" ({})", self.spin) };
        write!(f, "{} {arrow} {}{spin} {:.5}", self.from, self.to, self.coefficient)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wavelength_and_strength_follow_the_printed_numbers() {
        // Gaussian 09, divinylbenzene's first state: 5.6287 eV, 220.27 nm, f=0.0018; the fchk's
        // ETran record gives ΔE = 0.2068494 Eh and μ = (0.0919606, 0.0699523, −0.000347).
        let s = ExcitedState { energy_ev: 5.6287, ..Default::default() };
        assert!((s.wavelength_nm() - 220.27).abs() < 0.01, "{}", s.wavelength_nm());
        let f = oscillator_strength(0.2068494, [0.0919606, 0.0699523, -0.000347]);
        assert!((f - 0.0018).abs() < 5e-5, "{f}");
        let t = |c: f64| Transition { from: 1, to: 2, coefficient: c, spin: String::new(), deexcitation: false };
        let s = ExcitedState { transitions: vec![t(0.1), t(-0.6), t(0.3)], ..Default::default() };
        let main: Vec<f64> = s.main_transitions(2).iter().map(|t| t.coefficient).collect();
        assert_eq!(main, vec![-0.6, 0.3]);
        assert_eq!(t(-0.6).to_string(), "1 -> 2 -0.60000");
    }
}
