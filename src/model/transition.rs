//! A state's transition density ρ₀ₙ(r) = c Σ_ia X_ia φ_i(r) φ_a(r) from the excitation
//! amplitudes a program prints for it (Gaussian's `->` lines; the de-excitations `<-` of a full
//! TD-DFT solve are left out, as the natural transition orbitals leave them out: exact for TDA
//! and CIS, where Y = 0), c = 2 for a restricted singlet's spin-adapted amplitudes normalised
//! to ½ (Gaussian, PySCF, Q-Chem's fchk: each spin's excitation carries X), √2 for those
//! normalised to 1 (ORCA's and Q-Chem's logs), and 1 per spin of an unrestricted run. Where the electron density oscillates when light
//! drives the transition: its dipole μ = ∫ r ρ₀ₙ gives the oscillator strength ⅔ ΔE |μ|².

use glam::DVec3;

use super::Document;
use super::excited::oscillator_strength;
use super::gto::{GridSpec, PreparedBasis};
use super::orbitals::{Spin, Wavefunction};
use super::units::EV_PER_HARTREE;

/// One state's transition density as a sum of orbital products.
#[derive(Debug, Clone, PartialEq)]
pub struct TransitionDensity {
    /// The state, as the program numbers it.
    pub state: usize,
    /// (c·X_ia, i, a): weights and orbital indices into the wavefunction's orbitals.
    terms: Vec<(f64, usize, usize)>,
}

/// Why a state has no transition density here.
pub fn why_none(doc: &Document, state: usize) -> String {
    let listed = doc.excited.as_ref().and_then(|e| e.states.iter().find(|s| s.number == state));
    match (listed, &doc.wavefunction) {
        (None, _) => format!("{}: no excited state {state} is listed", doc.source),
        (Some(_), None) => format!(
            "{}: state {state}'s transitions need the file's orbitals (open its checkpoint with it)",
            doc.source
        ),
        (Some(s), Some(_)) if s.spin.to_ascii_lowercase().starts_with("triplet") => format!(
            "{}: state {state} is a triplet: its transition density from the singlet ground state vanishes",
            doc.source
        ),
        (Some(_), Some(_)) => {
            format!("{}: state {state} prints no transition between orbitals the file has", doc.source)
        }
    }
}

impl TransitionDensity {
    /// State `state`'s transition density from `doc`'s listed transitions over its orbitals
    /// (numbered within their spin, 1-based, as the programs print them). `None` when the state
    /// is not listed, prints no transition, names an orbital the file lacks, or is a restricted
    /// run's triplet (whose transition density from a singlet vanishes): [`why_none`] says which.
    pub fn of_state(doc: &Document, state: usize) -> Option<Self> {
        let wf = doc.wavefunction.as_ref()?;
        let listed = doc.excited.as_ref()?.states.iter().find(|s| s.number == state)?;
        if wf.restricted && listed.spin.to_ascii_lowercase().starts_with("triplet") {
            return None;
        }
        // A restricted singlet's amplitudes normalised to ½ carry c = 2; normalised to 1, √2.
        let factor = match (wf.restricted, listed.amplitudes_normalised_to_one) {
            (false, _) => 1.0,
            (true, false) => 2.0,
            (true, true) => std::f64::consts::SQRT_2,
        };
        let mut terms: Vec<(f64, usize, usize)> = Vec::new();
        for t in listed.transitions.iter().filter(|t| !t.deexcitation) {
            let spin = match (wf.restricted, t.spin.as_str()) {
                (true, _) | (false, "alpha") => Spin::Alpha,
                (false, _) => Spin::Beta,
            };
            let index = |n: usize| wf.of_spin(spin).nth(n.checked_sub(1)?).map(|(i, _)| i);
            terms.push((factor * t.coefficient, index(t.from)?, index(t.to)?));
        }
        (!terms.is_empty()).then_some(Self { state, terms })
    }

    /// Its values on `grid` (each orbital it names evaluated once).
    pub fn grid(&self, wf: &Wavefunction, prepared: &PreparedBasis, grid: &GridSpec) -> Vec<f32> {
        let mut values: std::collections::HashMap<usize, Vec<f32>> = std::collections::HashMap::new();
        for &(_, i, a) in &self.terms {
            for k in [i, a] {
                values.entry(k).or_insert_with(|| prepared.eval_grid_f32(&wf.orbitals[k].coefficients, grid));
            }
        }
        let mut out = vec![0.0f64; grid.len()];
        for &(c, i, a) in &self.terms {
            for ((o, &x), &y) in out.iter_mut().zip(&values[&i]).zip(&values[&a]) {
                *o += c * f64::from(x) * f64::from(y);
            }
        }
        out.into_iter().map(|v| v as f32).collect()
    }

    /// Its values at `points` (bohr).
    pub fn at_points(&self, wf: &Wavefunction, prepared: &PreparedBasis, points: &[DVec3]) -> Vec<f64> {
        points
            .iter()
            .map(|&p| {
                let basis = prepared.basis_values(p);
                let orbital =
                    |k: usize| wf.orbitals[k].coefficients.iter().zip(&basis).map(|(c, b)| c * b).sum::<f64>();
                self.terms.iter().map(|&(c, i, a)| c * orbital(i) * orbital(a)).sum()
            })
            .collect()
    }

    /// Its dipole ∫ r ρ₀ₙ (a.u.) from the basis's dipole matrices `moments`
    /// ([`super::overlap::moment_matrices`]); the origin does not matter, as ∫ ρ₀ₙ = 0.
    pub fn dipole(&self, wf: &Wavefunction, moments: &[Vec<f64>; 3]) -> [f64; 3] {
        let n = wf.basis.n_functions();
        moments.each_ref().map(|m| {
            self.terms
                .iter()
                .map(|&(c, i, a)| {
                    let (ci, ca) = (&wf.orbitals[i].coefficients, &wf.orbitals[a].coefficients);
                    let mut sum = 0.0;
                    for mu in 0..n {
                        let row = &m[mu * n..(mu + 1) * n];
                        sum += ci[mu] * row.iter().zip(ca).map(|(x, y)| x * y).sum::<f64>();
                    }
                    c * sum
                })
                .sum()
        })
    }

    /// The oscillator strength its dipole gives at `energy_ev` (length gauge).
    pub fn oscillator_strength(&self, wf: &Wavefunction, moments: &[Vec<f64>; 3], energy_ev: f64) -> f64 {
        oscillator_strength(energy_ev / EV_PER_HARTREE, self.dipole(wf, moments))
    }
}
