//! What a Gaussian TD job adds to its fchk file: the excited states (`ETran …` records) and
//! one excited state's density (`Total CI Rho(1) Density`, or the relaxed `Total CI Density`
//! when the job computed it) beside the ground state's (`Total SCF Density`).
//!
//! ```text
//! ETran scalars        I  N= 20   states, values per state (16), ?, ?, the state whose
//!                                 density the file holds, 0 …
//! ETran spin           I  N= states   0 singlet, 2 triplet
//! ETran sym            I  N= states   (Gaussian 09 writes 0 whatever the irrep)
//! ETran state values   R  N= …    per state: total energy (Eh), transition dipole ⟨0|r|n⟩
//!                                 (3, a.u.), velocity dipole (3), magnetic dipole (3), 6 more;
//!                                 then, after a frequency job, derivatives of the chosen state's
//! ```
//! Density matrices are lower triangles row by row (P11, P21, P22, P31, …) over the file's
//! functions, taken into the model's order the way the orbitals are.

use super::ParseError;
use super::fchk::FchkFile;
use crate::model::Wavefunction;
use crate::model::excited::{ExcitedState, ExcitedStates, oscillator_strength};
use crate::model::excited_density::ExcitedDensity;
use crate::model::units::EV_PER_HARTREE;

/// The densities a TD fchk may hold for its excited state, the preferred first: the relaxed
/// density when the job asked for it, else the unrelaxed one-particle density.
const EXCITED_DENSITIES: [&str; 2] = ["Total CI Density", "Total CI Rho(1) Density"];

/// How far the file's ground-state density may lie from the one its orbitals make (max |ΔP|):
/// the fchk prints 9 significant digits, so both agree to about 1e-8; a function order or
/// normalisation read differently from the orbitals' shows as order-one differences.
const GROUND_MATCH: f64 = 1e-5;

fn error(file: &str, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
    ParseError { file: file.to_string(), line, expected: expected.into(), found: found.into() }
}

impl FchkFile {
    /// The excited states of the `ETran` records; `None` when the file has none.
    pub(super) fn excited_states(&self, file: &str) -> Result<Option<ExcitedStates>, ParseError> {
        if !self.records.contains_key("ETran scalars") {
            return Ok(None);
        }
        let scalars = self.ints(file, "ETran scalars", None)?;
        let line = self.line_of("ETran scalars");
        let (Some(&count), Some(&per_state)) = (scalars.first(), scalars.get(1)) else {
            return Err(error(file, line, "the state count and values per state", "fewer than 2 values"));
        };
        let (count, per_state) = match (usize::try_from(count), usize::try_from(per_state)) {
            (Ok(c), Ok(p)) if p >= 4 => (c, p),
            _ => {
                return Err(error(
                    file,
                    line,
                    "a state count ≥ 0 and ≥ 4 values per state",
                    format!("{count}, {per_state}"),
                ));
            }
        };
        let values = self.reals(file, "ETran state values", None)?;
        if values.len() < count * per_state {
            return Err(error(
                file,
                self.line_of("ETran state values"),
                format!("{count} states × {per_state} values"),
                format!("{} values", values.len()),
            ));
        }
        let ground = match self.records.get("SCF Energy") {
            Some(_) => self.real(file, "SCF Energy")?,
            None => return Err(self.missing(file, "SCF Energy")),
        };
        let optional_ints = |label: &str| -> Result<Vec<i64>, ParseError> {
            match self.records.get(label) {
                Some(_) => Ok(self.ints(file, label, Some(count))?.to_vec()),
                None => Ok(Vec::new()),
            }
        };
        let (spins, syms) = (optional_ints("ETran spin")?, optional_ints("ETran sym")?);
        let states = (0..count)
            .map(|k| {
                let v = &values[k * per_state..(k + 1) * per_state];
                let excitation = v[0] - ground;
                ExcitedState {
                    number: k + 1,
                    energy_ev: excitation * EV_PER_HARTREE,
                    total_energy_hartree: Some(v[0]),
                    oscillator_strength: Some(oscillator_strength(excitation, [v[1], v[2], v[3]])),
                    spin: match spins.get(k) {
                        Some(0) => "Singlet".into(),
                        Some(2) => "Triplet".into(),
                        _ => String::new(),
                    },
                    // Gaussian 09 writes 0 for every irrep: no symmetry to tell.
                    symmetry: syms.get(k).filter(|&&s| s != 0).map_or(String::new(), |s| format!("irrep {s}")),
                    s_squared: None,
                    transitions: Vec::new(),
                    amplitudes_normalised_to_one: false,
                }
            })
            .collect::<Vec<_>>();
        let density_of = self.density_state(file, scalars, &states)?;
        let method = self.job.split_whitespace().nth(1).unwrap_or("").to_string();
        Ok(Some(ExcitedStates { program: self.writer().to_string(), method, states, density_of, note: String::new() }))
    }

    /// The state the excited density belongs to: the one `ETran scalars` names (its fifth
    /// value) when its energy is the `CIS Energy` record's, else the first state whose energy
    /// is; `None` without an excited density. A file whose `CIS Energy` is no state's is refused.
    fn density_state(&self, file: &str, scalars: &[i64], states: &[ExcitedState]) -> Result<Option<usize>, ParseError> {
        if !EXCITED_DENSITIES.iter().any(|l| self.records.contains_key(*l)) {
            return Ok(None);
        }
        let named = scalars.get(4).and_then(|&s| usize::try_from(s).ok()).filter(|&s| s >= 1 && s <= states.len());
        if !self.records.contains_key("CIS Energy") {
            return Ok(Some(named.unwrap_or(1)));
        }
        let cis = self.real(file, "CIS Energy")?;
        // ETran prints 9 significant digits: 1e-6 Eh on a few hundred hartree.
        let matches = |k: usize| {
            let e = states[k - 1].total_energy_hartree.unwrap_or(f64::NAN);
            (cis - e).abs() <= 1e-5 * cis.abs().max(1.0)
        };
        match named.filter(|&k| matches(k)).or_else(|| (1..=states.len()).find(|&k| matches(k))) {
            Some(k) => Ok(Some(k)),
            None => Err(error(
                file,
                self.line_of("CIS Energy"),
                "the energy of a state of `ETran state values`",
                format!("{cis:.6} Eh"),
            )),
        }
    }

    /// The excited state's density and the ground state's, in the model's function order
    /// (`file_to_model`), over `wf`'s basis; `None` when the file holds no excited density.
    /// The ground state's is checked against the one `wf`'s orbitals make, which catches a
    /// function order or normalisation the matrices do not share with the orbitals.
    pub(super) fn excited_density(
        &self,
        file: &str,
        file_to_model: &[usize],
        wf: &Wavefunction,
        state: usize,
    ) -> Result<Option<ExcitedDensity>, ParseError> {
        let Some(label) = EXCITED_DENSITIES.iter().copied().find(|l| self.records.contains_key(*l)) else {
            return Ok(None);
        };
        let n = file_to_model.len();
        let triangle = n * (n + 1) / 2;
        let full = |label: &str| -> Result<Vec<f64>, ParseError> {
            let lower = self.reals(file, label, Some(triangle))?;
            let mut p = vec![0.0; n * n];
            let mut k = 0;
            for i in 0..n {
                for j in 0..=i {
                    let (a, b) = (file_to_model[i], file_to_model[j]);
                    p[a * n + b] = lower[k];
                    p[b * n + a] = lower[k];
                    k += 1;
                }
            }
            Ok(p)
        };
        let excited = full(label)?;
        let ground = match self.records.get("Total SCF Density") {
            Some(_) => full("Total SCF Density")?,
            None => return Err(self.missing(file, "Total SCF Density")),
        };
        let mut from_orbitals = vec![0.0; n * n];
        for o in wf.orbitals.iter().filter(|o| o.occupation != 0.0) {
            for (i, ci) in o.coefficients.iter().enumerate() {
                for (j, cj) in o.coefficients.iter().enumerate() {
                    from_orbitals[i * n + j] += o.occupation * ci * cj;
                }
            }
        }
        let deviation = ground.iter().zip(&from_orbitals).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        if deviation > GROUND_MATCH {
            return Err(error(
                file,
                self.line_of("Total SCF Density"),
                "the ground-state density the orbitals make",
                format!("a matrix {deviation:.2e} from it (functions ordered or normalised differently?)"),
            ));
        }
        ExcitedDensity::new(state, label, &wf.basis, ground, excited)
            .map(Some)
            .map_err(|e| error(file, self.line_of(label), "a density matrix over the basis", e))
    }
}

#[cfg(test)]
mod tests {
    use crate::model::Document;

    fn reals(label: &str, v: &[f64]) -> String {
        let mut s = format!("{label:<43}R   N={:>12}\n", v.len());
        for row in v.chunks(5) {
            s.extend(row.iter().map(|x| format!("{x:>16.8E}")));
            s.push('\n');
        }
        s
    }

    fn ints(label: &str, v: &[i64]) -> String {
        let mut s = format!("{label:<43}I   N={:>12}\n", v.len());
        for row in v.chunks(6) {
            s.extend(row.iter().map(|x| format!("{x:>12}")));
            s.push('\n');
        }
        s
    }

    fn scalar(label: &str, v: &str) -> String {
        format!("{label:<43}{v}\n")
    }

    /// H₂ in one s function per atom, the ground state's bonding orbital doubly occupied, the
    /// excited state's density one electron in each of bonding and antibonding; two states,
    /// the first a singlet with μ = (0, 0, 0.8) 0.5 Eh up. `cis` and `ground` replace the
    /// `CIS Energy` and the ground density's off-diagonal element.
    fn h2(cis: f64, ground_offdiagonal: Option<f64>) -> Document {
        let s12 = (-0.5f64 * 1.4 * 1.4).exp();
        let b = 1.0 / (2.0 + 2.0 * s12).sqrt();
        let a = 1.0 / (2.0 - 2.0 * s12).sqrt();
        let mut t =
            String::from("h2 td\nSP        RTD-HF                                                      minimal\n");
        t += &scalar("Number of atoms", "I                2");
        t += &scalar("Number of alpha electrons", "I                1");
        t += &scalar("Number of beta electrons", "I                1");
        t += &scalar("Number of basis functions", "I                2");
        t += &ints("Atomic numbers", &[1, 1]);
        t += &reals("Current cartesian coordinates", &[0.0, 0.0, 0.0, 0.0, 0.0, 1.4]);
        t += &ints("Shell types", &[0, 0]);
        t += &ints("Number of primitives per shell", &[1, 1]);
        t += &ints("Shell to atom map", &[1, 2]);
        t += &reals("Primitive exponents", &[1.0, 1.0]);
        t += &reals("Contraction coefficients", &[1.0, 1.0]);
        t += &scalar("SCF Energy", "R     -1.000000000000000E+00");
        t += &scalar("CIS Energy", &format!("R     {cis:.15E}"));
        t += &reals("Alpha Orbital Energies", &[-0.5, 0.3]);
        t += &reals("Alpha MO coefficients", &[b, b, a, -a]);
        let g = 2.0 * b * b;
        t += &reals("Total SCF Density", &[g, ground_offdiagonal.unwrap_or(g), g]);
        t += &reals("Total CI Rho(1) Density", &[b * b + a * a, b * b - a * a, b * b + a * a]);
        let mut scalars = vec![0i64; 20];
        scalars[..5].copy_from_slice(&[2, 16, 1, 10, 1]);
        t += &ints("ETran scalars", &scalars);
        t += &ints("ETran spin", &[0, 2]);
        t += &ints("ETran sym", &[0, 0]);
        let mut values = vec![0.0; 32];
        values[0] = -0.5;
        values[3] = 0.8;
        values[16] = -0.4;
        t += &reals("ETran state values", &values);
        super::super::fchk::parse("h2.fchk", &t, None).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn states_and_the_density_of_a_td_checkpoint() {
        let doc = h2(-0.5, None);
        assert!(doc.problems.is_empty(), "{:?}", doc.problems);
        let states = doc.excited.as_ref().expect("states");
        assert_eq!((states.states.len(), states.density_of), (2, Some(1)));
        let first = &states.states[0];
        assert!((first.energy_ev - 0.5 * crate::model::units::EV_PER_HARTREE).abs() < 1e-9);
        assert!((first.oscillator_strength.unwrap() - 2.0 / 3.0 * 0.5 * 0.64).abs() < 1e-12);
        assert_eq!((first.spin.as_str(), states.states[1].spin.as_str()), ("Singlet", "Triplet"));
        let excited = doc.wavefunction.as_ref().unwrap().excited.as_ref().expect("density");
        assert!((excited.electrons_moved() - 1.0).abs() < 1e-7, "{}", excited.electrons_moved());
        assert_eq!(excited.source, "Total CI Rho(1) Density");
    }

    #[test]
    fn records_that_disagree_leave_the_states_or_the_density_out() {
        // A CIS energy that is no state's: the states are left out, saying so; the orbitals open.
        let doc = h2(-0.45, None);
        assert!(doc.excited.is_none() && doc.wavefunction.as_ref().is_some_and(|wf| wf.excited.is_none()));
        assert!(
            doc.problems[0].contains("excited states (and their density) left out")
                && doc.problems[0].contains("-0.450000"),
            "{:?}",
            doc.problems
        );
        // A ground density that is not the orbitals': the functions' order or normalisation is
        // not theirs, so the excited density is left out.
        let doc = h2(-0.5, Some(0.0));
        assert!(doc.excited.is_some());
        assert!(doc.wavefunction.as_ref().unwrap().excited.is_none());
        assert!(doc.problems[0].contains("the ground-state density the orbitals make"), "{:?}", doc.problems);
    }
}
