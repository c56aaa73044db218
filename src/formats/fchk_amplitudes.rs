//! What a Q-Chem CIS or TDA job run with `GUI = 2` adds to its fchk file: its excited states'
//! excitation energies, oscillator strengths and every state's transition amplitudes, from
//! which the states' natural transition orbitals, transition densities and hole–electron
//! analysis follow as they do from a log's printed amplitudes.
//!
//! ```text
//! Number of Excited States                   I               10
//! Excitation Energies                        R   N=          10   hartree
//! Oscillator Strengths                       R   N=          10
//! Alpha Amplitudes                           R   N=         100   per state o × v values,
//!                                                                  occupied-major: X_ia at
//!                                                                  (state·o + i)·v + a
//! Beta Amplitudes                            R   N=         100   a restricted run's: the alpha
//!                                                                  ones again, triplets too
//! ```
//! o is the alpha electron count and v the orbitals past them (`Alpha Orbital Energies`' count
//! less o). Each state's alpha amplitudes square-sum to ½ (Q-Chem's log prints √2·X, square-
//! summing to 1), the spin-adapted normalisation Gaussian prints, so they are the transitions'
//! coefficients as they are. As found in Q-Chem 5.4's `water_cis` and `dvb_td` and 7.0's
//! `water_cis` (cclib's regression data): the file lists the triplets before the singlets, names
//! neither, and the log numbers the states by excitation energy, as the states are numbered here.
//!
//! A full TD-DFT's `Alpha X Amplitudes` and `Alpha Y Amplitudes` and an unrestricted run's
//! amplitudes are not read: their states are listed without transitions, saying so.

use super::ParseError;
use super::fchk::FchkFile;
use crate::model::Wavefunction;
use crate::model::excited::{ExcitedState, ExcitedStates, Transition};
use crate::model::units::EV_PER_HARTREE;

/// A state's smallest amplitudes are left out of its transitions while their squares sum to no
/// more than this: the transition matrix then lies within 1e-7 (Frobenius) of the file's, so the
/// natural transition orbitals' weights and coefficients within about 1e-7 of the whole's, and a
/// large molecule's states keep the few amplitudes that matter of their o × v values.
const DROPPED_NORM: f64 = 1e-14;

/// How far a state's Σ X_ia² may lie from ½: the file prints 9 significant digits, so the sum
/// agrees to about 1e-8; amplitudes read in another layout or another normalisation miss it by
/// order one.
const NORM_MATCH: f64 = 1e-5;

/// Each state's transitions, and why they were left out when they were.
type Amplitudes = (Vec<Vec<Transition>>, Option<String>);

fn error(file: &str, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
    ParseError { file: file.to_string(), line, expected: expected.into(), found: found.into() }
}

/// The states of a Q-Chem fchk, numbered by excitation energy, with their transitions where the
/// file holds a restricted CIS or TDA run's amplitudes over the orbitals; and what was left out,
/// for the document's problems.
pub(super) struct QchemStates {
    pub states: ExcitedStates,
    pub left_out: Option<String>,
}

impl FchkFile {
    /// Q-Chem's `Number of Excited States` and what follows it; `None` without that record or
    /// with no state.
    pub(super) fn qchem_excited_states(
        &self,
        file: &str,
        n_alpha: usize,
        wf: &Wavefunction,
    ) -> Result<Option<QchemStates>, ParseError> {
        if !self.records.contains_key("Number of Excited States") {
            return Ok(None);
        }
        let count = self.int(file, "Number of Excited States")?;
        let count = usize::try_from(count).map_err(|_| {
            error(file, self.line_of("Number of Excited States"), "a state count ≥ 0", format!("{count}"))
        })?;
        if count == 0 {
            return Ok(None);
        }
        let energies = self.reals(file, "Excitation Energies", Some(count))?;
        let strengths = match self.records.get("Oscillator Strengths") {
            Some(_) => Some(self.reals(file, "Oscillator Strengths", Some(count))?),
            None => None,
        };
        if let Some(k) = energies.iter().position(|e| !e.is_finite() || *e <= 0.0) {
            return Err(error(
                file,
                self.line_of("Excitation Energies"),
                "excitation energies > 0 (hartree)",
                format!("{} for state {} of the file", energies[k], k + 1),
            ));
        }
        let mut states: Vec<ExcitedState> = (0..count)
            .map(|k| ExcitedState {
                number: 0,
                energy_ev: energies[k] * EV_PER_HARTREE,
                oscillator_strength: strengths.map(|f| f[k]),
                ..Default::default()
            })
            .collect();
        let (transitions, left_out) = self.amplitudes(file, count, n_alpha, wf)?;
        for (state, t) in states.iter_mut().zip(transitions) {
            state.transitions = t;
        }
        // Numbered as the log numbers them: by energy (a stable sort keeps the file's order
        // between states of one energy).
        states.sort_by(|a, b| a.energy_ev.total_cmp(&b.energy_ev));
        for (k, s) in states.iter_mut().enumerate() {
            s.number = k + 1;
        }
        let transitions = match left_out {
            None => {
                "transitions: `Alpha Amplitudes` (X, square-summing to ½) but the smallest, whose squares sum to under 1e-14; "
            }
            Some(_) => "",
        };
        let note = format!(
            "{transitions}numbered by excitation energy, as Q-Chem's log numbers them; the fchk does not \
             say which states are singlets and which triplets (its log does: join it with --transitions)"
        );
        Ok(Some(QchemStates {
            states: ExcitedStates {
                program: "Q-Chem".into(),
                method: if left_out.is_none() { "CIS/TDA".into() } else { String::new() },
                states,
                density_of: None,
                note,
            },
            left_out,
        }))
    }

    /// Each state's transitions from `Alpha Amplitudes` (in the file's state order), or none
    /// with the reason they were left out.
    fn amplitudes(
        &self,
        file: &str,
        count: usize,
        n_alpha: usize,
        wf: &Wavefunction,
    ) -> Result<Amplitudes, ParseError> {
        let none = |why: &str| Ok((vec![Vec::new(); count], Some(why.to_string())));
        if !self.records.contains_key("Alpha Amplitudes") {
            if self.records.contains_key("Alpha X Amplitudes") || self.records.contains_key("Alpha Y Amplitudes") {
                return none(
                    "a full TD-DFT's `Alpha X Amplitudes` and `Alpha Y Amplitudes` are not read: the states \
                     are listed without their transitions",
                );
            }
            return none("the file holds no `Alpha Amplitudes`: the states are listed without their transitions");
        }
        if !wf.restricted {
            return none(
                "an unrestricted run's amplitudes are not read: the states are listed without their transitions",
            );
        }
        let line = self.line_of("Alpha Amplitudes");
        let n_mo = wf.orbitals.len();
        let (o, v) = (n_alpha, n_mo.saturating_sub(n_alpha));
        let per_state = o * v;
        let expected = count.checked_mul(per_state).filter(|_| o <= n_mo);
        let x = self.reals(file, "Alpha Amplitudes", None)?;
        if expected != Some(x.len()) || per_state == 0 {
            return Err(error(
                file,
                line,
                format!("{count} states × {o} occupied × {v} virtual orbitals = {} amplitudes", count * per_state),
                format!("{} (a frozen core, or another layout?)", x.len()),
            ));
        }
        // A restricted run writes the alpha amplitudes again as the beta ones.
        if self.records.contains_key("Beta Amplitudes") {
            self.reals(file, "Beta Amplitudes", Some(x.len()))?;
        }
        let mut out = Vec::with_capacity(count);
        for (k, state) in x.chunks(per_state).enumerate() {
            let norm: f64 = state.iter().map(|c| c * c).sum();
            // NaN amplitudes fail this too.
            if (norm - 0.5).abs().is_nan() || (norm - 0.5).abs() > NORM_MATCH {
                return Err(error(
                    file,
                    line,
                    "amplitudes whose squares sum to ½ for each state (a restricted CIS or TDA run's)",
                    format!("{norm:.6} for state {} of the file", k + 1),
                ));
            }
            // The smallest first, dropped while their squares add up to at most DROPPED_NORM.
            let mut order: Vec<usize> = (0..state.len()).collect();
            order.sort_unstable_by(|&a, &b| state[a].abs().total_cmp(&state[b].abs()));
            let mut dropped = 0.0;
            let small = order.iter().take_while(|&&ia| {
                dropped += state[ia] * state[ia];
                dropped <= DROPPED_NORM
            });
            let mut keep = vec![true; state.len()];
            for &ia in small {
                keep[ia] = false;
            }
            let transitions = (state.iter().enumerate())
                .filter(|&(ia, _)| keep[ia])
                .map(|(ia, &c)| Transition {
                    from: ia / v + 1,
                    to: o + ia % v + 1,
                    coefficient: c,
                    spin: String::new(),
                    deexcitation: false,
                })
                .collect();
            out.push(transitions);
        }
        Ok((out, None))
    }
}
