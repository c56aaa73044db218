//! The excited-state tables TD, TDA and CIS jobs print in their logs: Gaussian's
//! `Excited State   1:      Singlet-A      5.6287 eV  220.27 nm  f=0.0018  <S**2>=0.000` with
//! `34 -> 36  0.52587` lines; ORCA's `STATE  1:  E=   0.196688 au      5.352 eV …` blocks
//! (`33a ->  35a  :  0.562531 (c=  0.75002079)`, orbitals counted from 0) and its
//! `ABSORPTION SPECTRUM VIA TRANSITION ELECTRIC DIPOLE MOMENTS` table for the oscillator
//! strengths; Q-Chem's `Excited state   1: excitation energy (eV) =    3.6052` blocks
//! (`Strength`, `D( 34) --> V(  1) amplitude =  0.7005`, virtuals counted after the occupied).
//! A log with several TD sections (an optimisation of an excited state) gives its last.

use super::ParseError;
use super::logs::LogLines;
use super::text::parse_real;
use crate::model::excited::{ExcitedState, ExcitedStates, Transition};
use crate::model::units::EV_PER_HARTREE;

/// The number after `prefix` in `t` (the first token after it), if `t` has one.
fn number_after(t: &str, prefix: &str) -> Option<f64> {
    let (_, rest) = t.split_once(prefix)?;
    parse_real(rest.split_whitespace().next()?)
}

/// Gaussian's `Excited State` blocks; `None` when the log has none.
pub(crate) fn gaussian(log: &LogLines) -> Result<Option<ExcitedStates>, ParseError> {
    let mut states: Vec<ExcitedState> = Vec::new();
    let mut i = 0;
    while i < log.lines.len() {
        let t = log.lines[i].trim();
        i += 1;
        let Some(rest) = t.strip_prefix("Excited State") else { continue };
        let expected = "`Excited State  N:  Spin-Sym  E eV  λ nm  f=…`";
        let (number, rest) = rest.split_once(':').ok_or_else(|| log.error_at(i - 1, expected))?;
        let number: usize = number.trim().parse().map_err(|_| log.error_at(i - 1, expected))?;
        let tokens: Vec<&str> = rest.split_whitespace().collect();
        let energy =
            tokens.iter().position(|&w| w == "eV").and_then(|k| k.checked_sub(1)).and_then(|k| parse_real(tokens[k]));
        let Some(energy_ev) = energy else { return Err(log.error_at(i - 1, expected)) };
        let label = tokens.first().copied().unwrap_or("");
        let (spin, symmetry) = label.split_once('-').unwrap_or((label, ""));
        if number == 1 {
            // A new TD section: the last one is the log's answer.
            states.clear();
        }
        let mut state = ExcitedState {
            number,
            energy_ev,
            oscillator_strength: number_after(rest, "f="),
            spin: spin.to_string(),
            symmetry: symmetry.to_string(),
            s_squared: number_after(rest, "<S**2>="),
            ..Default::default()
        };
        while let Some(transition) = log.lines.get(i).and_then(|l| gaussian_transition(l)) {
            state.transitions.push(transition);
            i += 1;
        }
        if let Some(e) = log.lines.get(i + 1).and_then(|l| number_after(l, "E(TD-HF/TD-KS) =")) {
            state.total_energy_hartree = Some(e);
        }
        states.push(state);
    }
    Ok((!states.is_empty()).then(|| ExcitedStates {
        program: "Gaussian".into(),
        method: String::new(),
        states,
        ..Default::default()
    }))
}

/// `  34 -> 36  0.52587`, `  35 <- 37 -0.01172`, `  34A -> 36A  0.7`.
fn gaussian_transition(line: &str) -> Option<Transition> {
    let t: Vec<&str> = line.split_whitespace().collect();
    let [from, arrow, to, c] = t[..] else { return None };
    let deexcitation = match arrow {
        "->" => false,
        "<-" => true,
        _ => return None,
    };
    let orbital = |w: &str| -> Option<(usize, &'static str)> {
        let (digits, spin) = match w.strip_suffix('A') {
            Some(d) => (d, "alpha"),
            None => w.strip_suffix('B').map_or((w, ""), |d| (d, "beta")),
        };
        Some((digits.parse().ok()?, spin))
    };
    let ((from, spin), (to, _)) = (orbital(from)?, orbital(to)?);
    Some(Transition { from, to, coefficient: parse_real(c)?, spin: spin.to_string(), deexcitation })
}

/// ORCA's `STATE` blocks with the oscillator strengths of its absorption spectrum; `None` when
/// the log has none.
pub(crate) fn orca(log: &LogLines) -> Result<Option<ExcitedStates>, ParseError> {
    let mut states: Vec<ExcitedState> = Vec::new();
    let mut method = String::new();
    let mut multiplicity = "";
    let mut spectrum: Option<usize> = None;
    let mut i = 0;
    while i < log.lines.len() {
        let t = log.lines[i].trim();
        i += 1;
        if let Some((kind, which)) = t.split_once("EXCITED STATES")
            && (which.is_empty() || which.trim_start().starts_with('('))
        {
            if spectrum.is_some() {
                // A new TD section after a finished one: the last is the log's answer.
                states.clear();
                spectrum = None;
            }
            method = kind.trim().to_string();
            multiplicity = match which.trim() {
                "(SINGLETS)" => "Singlet",
                "(TRIPLETS)" => "Triplet",
                _ => "",
            };
            continue;
        }
        if t.starts_with("ABSORPTION SPECTRUM VIA TRANSITION ELECTRIC DIPOLE MOMENTS") {
            spectrum = Some(i - 1);
            continue;
        }
        let Some(rest) = t.strip_prefix("STATE") else { continue };
        let Some((number, rest)) = rest.split_once(':') else { continue };
        let Ok(number) = number.trim().parse::<usize>() else { continue };
        // Other sections print `STATE n:` lines too; a state's has its energy in au.
        let Some(au) = number_after(rest, "E=").filter(|_| rest.contains(" au ")) else { continue };
        let spin = match number_after(rest, "Mult") {
            Some(1.0) => "Singlet".to_string(),
            Some(3.0) => "Triplet".to_string(),
            Some(m) => format!("multiplicity {m}"),
            None => multiplicity.to_string(),
        };
        let symmetry = rest.split_once("Sym:").and_then(|(_, s)| s.split_whitespace().next()).unwrap_or("");
        let mut state = ExcitedState {
            number,
            energy_ev: au * EV_PER_HARTREE,
            spin,
            symmetry: symmetry.to_string(),
            s_squared: number_after(rest, "<S**2> ="),
            ..Default::default()
        };
        // The transitions, up to a blank line (or the next state, when none is printed).
        while let Some(l) = log.lines.get(i).map(|l| l.trim()) {
            if let Some(tr) = orca_transition(l) {
                state.transitions.push(tr);
            } else if !state.transitions.is_empty() || !l.is_empty() {
                break;
            }
            i += 1;
        }
        // ORCA writes `a` for alpha and for restricted orbitals alike: beta ones tell.
        if state.transitions.iter().any(|t| t.spin == "beta") {
            state.transitions.iter_mut().filter(|t| t.spin.is_empty()).for_each(|t| t.spin = "alpha".into());
        }
        // Its weights c² of a restricted state sum to 1.
        state.amplitudes_normalised_to_one = true;
        states.push(state);
    }
    if states.is_empty() {
        return Ok(None);
    }
    if let Some(header) = spectrum {
        orca_spectrum(log, header, &mut states)?;
    }
    Ok(Some(ExcitedStates { program: "ORCA".into(), method, states, ..Default::default() }))
}

/// `33a ->  35a  :     0.562531 (c=  0.75002079)`: ORCA counts orbitals from 0; the
/// coefficient is c where printed, else the weight's square root.
fn orca_transition(line: &str) -> Option<Transition> {
    let (pair, values) = line.split_once(':')?;
    let (from, to) = pair.split_once("->")?;
    let orbital = |w: &str| -> Option<(usize, &'static str)> {
        let w = w.trim();
        let (digits, spin) = match w.strip_suffix('a') {
            Some(d) => (d, ""),
            None => (w.strip_suffix('b')?, "beta"),
        };
        Some((digits.parse::<usize>().ok()? + 1, spin))
    };
    let ((from, spin), (to, _)) = (orbital(from)?, orbital(to)?);
    let weight = parse_real(values.split_whitespace().next()?)?;
    let c = values.split_once("(c=").and_then(|(_, c)| parse_real(c.trim().trim_end_matches(')').trim()));
    let coefficient = c.unwrap_or_else(|| weight.sqrt());
    Some(Transition { from, to, coefficient, spin: spin.to_string(), deexcitation: false })
}

/// The absorption spectrum's rows: `0-1Ag ->  1-1Bu   5.352154   43168.0   231.7   0.005038390 …`
/// (ORCA 6: the k-th root of a multiplicity, energy in eV) or `   1   43168.0    231.7
/// 0.005038390 …` (ORCA 5: the state's number, energy in cm⁻¹). Sets each state's oscillator
/// strength, and ORCA 6's six-decimal energy.
fn orca_spectrum(log: &LogLines, header: usize, states: &mut [ExcitedState]) -> Result<(), ParseError> {
    let mut i = header + 1;
    let mut dashes = 0;
    // Dashes, two heading lines, dashes, then the rows up to a blank line or dashes.
    while dashes < 2 {
        let l = log.get(i, "the spectrum's table")?;
        if l.trim().starts_with("---") {
            dashes += 1;
        }
        i += 1;
    }
    let row = "a spectrum row `0-1Ag -> 1-1Bu  eV  cm-1  nm  fosc …` or `N  cm-1  nm  fosc …`";
    while let Some(l) = log.lines.get(i).map(|l| l.trim()).filter(|l| !l.is_empty() && !l.starts_with("---")) {
        let t: Vec<&str> = l.split_whitespace().collect();
        if let Some(arrow) = t.iter().position(|&w| w == "->") {
            // ORCA 6: `0-1Ag -> R-MSym eV cm-1 nm fosc …`.
            let target = t.get(arrow + 1).ok_or_else(|| log.error_at(i, row))?;
            let (root, rest) = target.split_once('-').ok_or_else(|| log.error_at(i, row))?;
            let root: usize = root.parse().map_err(|_| log.error_at(i, row))?;
            let mult = match rest.chars().next() {
                Some('1') => "Singlet".to_string(),
                Some('3') => "Triplet".to_string(),
                Some(d) => format!("multiplicity {d}"),
                None => String::new(),
            };
            let k = (states.iter().enumerate())
                .filter(|(_, s)| s.spin == mult)
                .nth(root - 1)
                .map(|(k, _)| k)
                .ok_or_else(|| log.error_at(i, format!("root {root} among the {mult} states listed")))?;
            let values: Option<Vec<f64>> =
                t.get(arrow + 2..arrow + 6).and_then(|v| v.iter().map(|w| parse_real(w)).collect());
            let values = values.ok_or_else(|| log.error_at(i, row))?;
            states[k].energy_ev = values[0];
            states[k].oscillator_strength = Some(values[3]);
        } else {
            // ORCA 5: `N cm-1 nm fosc …`.
            let n: usize = t.first().and_then(|w| w.parse().ok()).ok_or_else(|| log.error_at(i, row))?;
            let f = t.get(3).and_then(|w| parse_real(w)).ok_or_else(|| log.error_at(i, row))?;
            let k = states
                .iter()
                .position(|s| s.number == n)
                .ok_or_else(|| log.error_at(i, format!("state {n} listed")))?;
            states[k].oscillator_strength = Some(f);
        }
        i += 1;
    }
    Ok(())
}

/// Q-Chem's `Excited state` blocks; `occupied` the alpha and beta electrons (virtual k of a
/// spin is orbital occupied + k). `None` when the log has none.
pub(crate) fn qchem(log: &LogLines, occupied: (usize, usize)) -> Result<Option<ExcitedStates>, ParseError> {
    let mut states: Vec<ExcitedState> = Vec::new();
    let mut method = String::new();
    let mut i = 0;
    while i < log.lines.len() {
        let t = log.lines[i].trim();
        i += 1;
        if let Some(m) = t.strip_suffix("Excitation Energies") {
            method = m.trim().to_string();
            continue;
        }
        let Some(rest) = t.strip_prefix("Excited state") else { continue };
        let Some((number, rest)) = rest.split_once(':') else { continue };
        let Ok(number) = number.trim().parse::<usize>() else { continue };
        let energy_ev = number_after(rest, "=").ok_or_else(|| log.error_at(i - 1, "`excitation energy (eV) = E`"))?;
        if number == 1 {
            states.clear();
        }
        let mut state = ExcitedState { number, energy_ev, ..Default::default() };
        while let Some(l) = log.lines.get(i).map(|l| l.trim()).filter(|l| !l.is_empty()) {
            if l.starts_with("Excited state") {
                break;
            }
            if l.starts_with("Total energy for state") {
                state.total_energy_hartree =
                    l.rsplit_once(':').and_then(|(_, v)| v.split_whitespace().next()).and_then(parse_real);
            } else if let Some(m) = l.strip_prefix("Multiplicity:") {
                state.spin = m.trim().to_string();
            } else if l.starts_with("<S**2>") {
                state.s_squared = number_after(l, ":");
            } else if l.starts_with("Strength") {
                state.oscillator_strength = number_after(l, ":");
            } else if let Some(tr) = qchem_transition(l, occupied) {
                state.transitions.push(tr);
            }
            i += 1;
        }
        // The log prints √2 times its fchk's amplitudes: a restricted state's squares sum to 1.
        state.amplitudes_normalised_to_one = true;
        states.push(state);
    }
    Ok((!states.is_empty()).then(|| ExcitedStates { program: "Q-Chem".into(), method, states, ..Default::default() }))
}

/// `D( 34) --> V(  1) amplitude =  0.7005` (with `alpha`/`beta` after it in unrestricted
/// runs; `X:` and `Y:` before it in RPA, Y written `<--`).
fn qchem_transition(line: &str, (alpha, beta): (usize, usize)) -> Option<Transition> {
    let line = line.strip_prefix("X:").or(line.strip_prefix("Y:")).unwrap_or(line).trim();
    let deexcitation = line.contains("<--");
    let (from, rest) = line.strip_prefix("D(")?.split_once(')')?;
    let rest = rest.trim_start().strip_prefix("-->").or(rest.trim_start().strip_prefix("<--"))?;
    let (to, rest) = rest.trim_start().strip_prefix("V(")?.split_once(')')?;
    let coefficient = number_after(rest, "=")?;
    let spin = if rest.contains("beta") {
        "beta"
    } else if rest.contains("alpha") {
        "alpha"
    } else {
        ""
    };
    let offset = if spin == "beta" { beta } else { alpha };
    Some(Transition {
        from: from.trim().parse().ok()?,
        to: offset + to.trim().parse::<usize>().ok()?,
        coefficient,
        spin: spin.to_string(),
        deexcitation,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ORCA 5 prints no `Sym:`/`Mult` on its state lines and numbers the spectrum's rows by
    /// state, energies in cm⁻¹: the multiplicity comes from the block's heading, f from the row.
    #[test]
    fn orca_5_states_and_spectrum() {
        let text = "\
------------------------------------
TD-DFT/TDA EXCITED STATES (SINGLETS)
------------------------------------

the weight of the individual excitations are printed if larger than 1.0e-02

STATE  1:  E=   0.196688 au      5.352 eV    43168.0 cm**-1 <S**2> =   0.000000
    33a ->  35a  :     0.562531 (c=  0.75002079)

STATE  2:  E=   0.210622 au      5.731 eV    46226.2 cm**-1 <S**2> =   0.000000
    34a ->  35a  :     0.934296

-----------------------------------------------------------------------------
         ABSORPTION SPECTRUM VIA TRANSITION ELECTRIC DIPOLE MOMENTS
-----------------------------------------------------------------------------
State   Energy    Wavelength  fosc         T2        TX        TY        TZ
        (cm-1)      (nm)                 (au**2)    (au)      (au)      (au)
-----------------------------------------------------------------------------
   1   43168.0    231.7   0.005038390   0.03842   0.16288   0.10906   0.00000
   2   46226.2    216.3   1.170940055   8.33915   2.88656   0.08326  -0.00000

";
        let s = orca(&LogLines::new("o.out", text)).unwrap().expect("states");
        assert_eq!(s.method, "TD-DFT/TDA");
        let f: Vec<Option<f64>> = s.states.iter().map(|s| s.oscillator_strength).collect();
        assert_eq!(f, vec![Some(0.005038390), Some(1.170940055)]);
        assert!((s.states[0].energy_ev - 0.196688 * EV_PER_HARTREE).abs() < 1e-12);
        assert_eq!((s.states[1].spin.as_str(), s.states[1].symmetry.as_str()), ("Singlet", ""));
        // Without `(c= …)` the coefficient is the weight's square root.
        assert!((s.states[1].transitions[0].coefficient - 0.934296f64.sqrt()).abs() < 1e-12);
    }

    /// An unrestricted Gaussian state: ⟨S²⟩'s label for the spin, A and B orbitals.
    #[test]
    fn gaussian_unrestricted_states() {
        let text = " Excited State   1:  3.010-A      2.1000 eV  590.40 nm  f=0.0100  <S**2>=2.015
      10A -> 11A        0.70000
      10B -> 11B       -0.20000

 Excited State   2:  3.020-B      2.5000 eV  495.94 nm  f=0.0000  <S**2>=2.020
      9A -> 11A        0.90000
";
        let s = gaussian(&LogLines::new("g.log", text)).unwrap().expect("states");
        assert_eq!(s.states.len(), 2);
        let a = &s.states[0];
        assert_eq!((a.spin.as_str(), a.symmetry.as_str(), a.s_squared), ("3.010", "A", Some(2.015)));
        let spins: Vec<&str> = a.transitions.iter().map(|t| t.spin.as_str()).collect();
        assert_eq!(spins, ["alpha", "beta"]);
        assert_eq!((s.states[1].energy_ev, s.states[1].oscillator_strength), (2.5, Some(0.0)));
    }

    #[test]
    fn transition_lines_of_each_program() {
        let g = gaussian_transition("      35 <- 37        -0.01172").unwrap();
        assert_eq!((g.from, g.to, g.coefficient, g.deexcitation), (35, 37, -0.01172, true));
        let g = gaussian_transition("     34B -> 36B        0.70000").unwrap();
        assert_eq!((g.from, g.to, g.spin.as_str()), (34, 36, "beta"));
        assert!(gaussian_transition(" This state for optimization").is_none());
        let o = orca_transition("33a ->  35a  :     0.562531 (c=  0.75002079)").unwrap();
        assert_eq!((o.from, o.to, o.coefficient), (34, 36, 0.75002079));
        let q = qchem_transition("D( 34) --> V(  2) amplitude = -0.2854", (35, 35)).unwrap();
        assert_eq!((q.from, q.to, q.coefficient), (34, 37, -0.2854));
        let q = qchem_transition("D( 30) --> V(  1) amplitude =  0.5 beta", (35, 33)).unwrap();
        assert_eq!((q.to, q.spin.as_str()), (34, "beta"));
    }
}
