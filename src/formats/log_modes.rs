//! Normal modes from the frequency sections of GAMESS-US, NWChem, Psi4 and Q-Chem logs, each
//! taken as printed: wavenumbers (an imaginary one negative), IR intensities in km/mol and each
//! atom's Cartesian displacement in the program's own normalisation, at the geometry the
//! program computed them at. Translations and rotations are left out.
//!
//! ```text
//! GAMESS-US   NORMAL COORDINATE ANALYSIS IN THE HARMONIC APPROXIMATION
//!              MODES    1 TO    6 ARE TAKEN AS ROTATIONS AND TRANSLATIONS.   (these left out)
//!                  FREQUENCIES IN CM**-1, IR INTENSITIES IN DEBYE**2/AMU-ANGSTROM**2,
//!                                  1           2    …                          5 a block
//!                FREQUENCY:       825.18 I      3.88                           `I`: imaginary
//!             IR INTENSITY:     21.64357     0.00000
//!               1   C            X -0.00849050  0.00000000                     x, y, z rows per atom
//!                                Y -0.05023254  0.00000000
//! NWChem       NORMAL MODE EIGENVECTORS IN CARTESIAN COORDINATES               (the last: projected)
//!                                  1           2    …                          6 a block
//!              P.Frequency       -0.00        0.00                            3N modes, rigid ones 0.00
//!                        1     0.00000    -0.00000                            one row per coordinate
//!              Normal Eigenvalue ||           Projected Infra Red Intensities
//!                 7       49.010 ||    0.000030   0.001   0.030   0.068       (KM/mol): third after ||
//! Psi4         ==> Harmonic Vibrational Analysis <==
//!                Vibration                       7                   8        3 a block, vibrations only
//!                Freq [cm^-1]                 137.2531            825.1i      `i`: imaginary
//!                IR activ [km/mol]              0.0544              0.0000
//!                ------------------------------------------------------
//!                    1   C                0.00 -0.00 -0.11    0.00 …        x y z per mode, per atom
//! Q-Chem       VIBRATIONAL ANALYSIS
//!               Mode:                 1                      2              3 a block, vibrations only
//!               Frequency:        47.24                 -80.82             negative: imaginary
//!               IR Intens:        0.031                  0.000
//!                              X      Y      Z        X      Y      Z
//!               C         -0.000 -0.000 -0.079   -0.000  0.000 -0.086       per atom
//!               TransDip   0.000  0.000  0.006    0.000 -0.000  0.000
//! ```
//! GAMESS and NWChem print Cartesian displacements normalised with the masses (Σ m·|d|² = 1),
//! Psi4 and Q-Chem normalised to Σ |d|² = 1. GAMESS prints intensities in D²/(amu·Å²), here
//! converted to km/mol. The geometry: the last one printed before the section, except Psi4's
//! finite differences, whose reference is the last geometry computed before they begin (Psi4 1.2
//! and 1.3) or the first after (1.7); the displaced ones differ from it by ~0.005 bohr.

use glam::DVec3;

use super::ParseError;
use super::logs::{Geometry, LogLines};
use super::printed::column_numbers;
use super::text::parse_real;
use crate::model::Document;
use crate::model::vibrations::{NormalMode, Vibrations};

/// km/mol per D²/(amu·Å²): N_A·π/(3·c²·4πε₀) · (3.33564e-20 C / √(1.66054e-27 kg))².
pub const KM_PER_MOL_PER_DEBYE2_AMU_ANGSTROM2: f64 = 42.2561;

/// Puts the modes read into `doc`; a malformed section leaves the modes out, not the file.
pub(crate) fn attach(doc: &mut Document, modes: Result<Option<Vibrations>, ParseError>) {
    match modes {
        Ok(modes) => doc.vibrations = modes,
        Err(e) => doc.problems.push(format!("normal modes left out: {e}")),
    }
}

/// The last line (0-based) whose trimmed text satisfies `is`.
fn last(log: &LogLines, is: impl Fn(&str) -> bool) -> Option<usize> {
    log.lines.iter().rposition(|l| is(l.trim()))
}

/// The last geometry printed before line `at`.
fn geometry_before<'a>(log: &LogLines, geometries: &'a [Geometry], at: usize) -> Result<&'a Geometry, ParseError> {
    geometries
        .iter()
        .rfind(|g| g.line < at)
        .ok_or_else(|| log.error_at(at, "a geometry printed before the normal modes"))
}

fn vibrations(modes: Vec<NormalMode>, geometry: &Geometry) -> Vibrations {
    Vibrations {
        modes,
        geometry: geometry.positions.clone(),
        geometry_from: format!("the coordinates at line {}", geometry.line + 1),
    }
}

/// The index of the next non-blank line at or after `i`.
fn skip_blank(log: &LogLines, mut i: usize) -> usize {
    while log.lines.get(i).is_some_and(|l| l.trim().is_empty()) {
        i += 1;
    }
    i
}

/// The numbers after `label` on line `i` (`I` after a number, or an `i` suffix, makes it
/// imaginary: negative), exactly `count` of them; the error says what the line should hold.
fn labelled_numbers(log: &LogLines, i: usize, label: &str, count: usize) -> Result<Vec<f64>, ParseError> {
    let expected = format!("`{label}` and {count} numbers");
    let rest = log.get(i, &expected)?.trim_start().strip_prefix(label).ok_or_else(|| log.error_at(i, &expected))?;
    let mut values: Vec<f64> = Vec::with_capacity(count);
    for token in rest.split_whitespace() {
        if token == "I" {
            let last = values.last_mut().ok_or_else(|| log.error_at(i, &expected))?;
            *last = -last.abs();
        } else if let Some(v) = token.strip_suffix('i').and_then(parse_real) {
            values.push(-v.abs());
        } else {
            values.push(parse_real(token).filter(|v| v.is_finite()).ok_or_else(|| log.error_at(i, &expected))?);
        }
    }
    if values.len() != count {
        return Err(log.error_at(i, expected));
    }
    Ok(values)
}

/// Three numbers per column at the end of line `i`, after `head` tokens.
fn triples(log: &LogLines, i: usize, head: usize, columns: usize, expected: &str) -> Result<Vec<DVec3>, ParseError> {
    let l = log.get(i, expected)?;
    let t: Vec<&str> = l.split_whitespace().collect();
    if t.len() != head + 3 * columns {
        return Err(log.error_at(i, expected));
    }
    let v: Option<Vec<f64>> = t[head..].iter().map(|x| parse_real(x).filter(|v| v.is_finite())).collect();
    let v = v.ok_or_else(|| log.error_at(i, expected))?;
    Ok(v.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect())
}

/// GAMESS-US's `NORMAL COORDINATE ANALYSIS` (the last in the file), at the last coordinate table
/// before it.
pub(crate) fn gamess(log: &LogLines, geometries: &[Geometry]) -> Result<Option<Vibrations>, ParseError> {
    let Some(start) = last(log, |t| t == "NORMAL COORDINATE ANALYSIS IN THE HARMONIC APPROXIMATION") else {
        return Ok(None);
    };
    let geometry = geometry_before(log, geometries, start)?;
    let atoms = geometry.z.len();
    let n = 3 * atoms;
    let end = (start..log.lines.len()).find(|&k| log.lines[k].contains("END OF NORMAL COORDINATE ANALYSIS"));
    let end = end.unwrap_or(log.lines.len());
    let within = |is: &dyn Fn(&str) -> bool| (start..end).find(|&k| is(log.lines[k].trim()));
    // `MODES    1 TO    6 ARE TAKEN AS ROTATIONS AND TRANSLATIONS.`: 1-based, inclusive.
    let rigid = match within(&|t| t.starts_with("MODES") && t.contains("ARE TAKEN AS ROTATIONS AND TRANSLATIONS")) {
        Some(k) => {
            let w: Vec<usize> = log.lines[k].split_whitespace().filter_map(|w| w.parse().ok()).collect();
            match w[..] {
                [a, b] if 1 <= a && a <= b && b <= n => a - 1..b,
                _ => {
                    return Err(log.error_at(
                        k,
                        format!("`MODES i TO j ARE TAKEN AS ROTATIONS AND TRANSLATIONS.` with 1 ≤ i ≤ j ≤ {n}"),
                    ));
                }
            }
        }
        None => 0..0,
    };
    // Intensities in D²/(amu·Å²) (GAMESS-US 2018) are converted; in km/mol they are kept.
    let scale = within(&|t| t.starts_with("FREQUENCIES IN CM**-1")).and_then(|k| {
        let l = log.lines[k];
        if l.contains("IR INTENSITIES IN DEBYE**2/AMU-ANGSTROM**2") {
            Some(KM_PER_MOL_PER_DEBYE2_AMU_ANGSTROM2)
        } else if l.contains("IR INTENSITIES IN KM/MOL") {
            Some(1.0)
        } else {
            None
        }
    });
    let mut modes: Vec<NormalMode> = Vec::with_capacity(n);
    let mut i = start + 1;
    while modes.len() < n {
        // The next block: its columns' numbers continuing the modes read.
        let block = (i..end).find(|&k| column_numbers(log.lines[k]).is_some_and(|c| c[0] == modes.len() + 1));
        let Some(block) = block.filter(|&k| !log.lines[i..k].iter().any(|l| l.contains("FREQUENCY:"))) else {
            let at = (i..end).find(|&k| log.lines[k].contains("FREQUENCY:")).unwrap_or(end);
            return Err(log.error_at(
                at,
                format!(
                    "a block of modes from {} (the {n} modes of the {atoms} atoms at line {})",
                    modes.len() + 1,
                    geometry.line + 1
                ),
            ));
        };
        let k = column_numbers(log.lines[block]).map_or(0, |c| c.len()).min(n - modes.len());
        i = skip_blank(log, block + 1);
        let frequencies = labelled_numbers(log, i, "FREQUENCY:", k)?;
        let mut intensities = None;
        i += 1;
        while log.lines.get(i).is_some_and(|l| !l.trim().is_empty()) {
            if log.lines[i].trim_start().starts_with("IR INTENSITY:") {
                intensities = Some(labelled_numbers(log, i, "IR INTENSITY:", k)?);
            }
            i += 1;
        }
        i = skip_blank(log, i);
        let mut columns = vec![Vec::with_capacity(atoms); k];
        for a in 0..atoms {
            let mut xyz = vec![[0.0; 3]; k];
            for (c, axis) in ["X", "Y", "Z"].into_iter().enumerate() {
                let expected = format!(
                    "atom {}'s {axis} row of the block at line {}: `{}{axis}` and {k} displacements (the {atoms} atoms at line {})",
                    a + 1,
                    block + 1,
                    if c == 0 { format!("{}  symbol  ", a + 1) } else { String::new() },
                    geometry.line + 1
                );
                let l = log.get(i, &expected)?;
                let t: Vec<&str> = l.split_whitespace().collect();
                let head_ok = match c {
                    0 => t.len() == k + 3 && t[0].parse::<usize>().ok() == Some(a + 1) && t[2] == axis,
                    _ => t.len() == k + 1 && t[0] == axis,
                };
                let values: Option<Vec<f64>> =
                    t.get(t.len().saturating_sub(k)..).and_then(|v| v.iter().map(|x| parse_real(x)).collect());
                let values = values.filter(|_| head_ok).ok_or_else(|| log.error_at(i, expected))?;
                for (m, v) in values.into_iter().enumerate() {
                    xyz[m][c] = v;
                }
                i += 1;
            }
            for (m, d) in xyz.into_iter().enumerate() {
                columns[m].push(DVec3::from_array(d));
            }
        }
        if log.lines.get(i).is_some_and(|l| l.split_whitespace().next().is_some_and(|w| w.parse::<usize>().is_ok())) {
            return Err(log.error_at(
                i,
                format!(
                    "the end of the block at line {} after its {atoms} atoms (the geometry at line {})",
                    block + 1,
                    geometry.line + 1
                ),
            ));
        }
        for (m, displacement) in columns.into_iter().enumerate() {
            let intensity = intensities.as_ref().zip(scale).map(|(v, s)| v[m] * s);
            modes.push(NormalMode { frequency_cm1: frequencies[m], ir_intensity: intensity, displacement });
        }
    }
    let modes = modes.into_iter().enumerate().filter(|(k, _)| !rigid.contains(k)).map(|(_, m)| m).collect();
    Ok(Some(vibrations(modes, geometry)))
}

/// How many of a geometry's 3N modes are translations and rotations: 5 for a linear molecule,
/// 3 for an atom, else 6.
fn rigid_modes(positions: &[DVec3]) -> usize {
    match positions {
        [] | [_] => 3,
        [a, rest @ ..] => {
            let far =
                rest.iter().map(|p| *p - *a).max_by(|u, v| u.length().total_cmp(&v.length())).unwrap_or(DVec3::ZERO);
            let off_axis = rest.iter().any(|p| far.normalize_or_zero().cross(*p - *a).length() > 1e-3);
            if off_axis { 6 } else { 5 }
        }
    }
}

/// NWChem's `NORMAL MODE EIGENVECTORS IN CARTESIAN COORDINATES` (the last: the projected ones)
/// and the `Infra Red Intensities` table after it, at the last coordinate table before them.
/// The translations and rotations are the modes of smallest |frequency| (0.00 once projected).
pub(crate) fn nwchem(log: &LogLines, geometries: &[Geometry]) -> Result<Option<Vibrations>, ParseError> {
    let Some(start) = last(log, |t| t == "NORMAL MODE EIGENVECTORS IN CARTESIAN COORDINATES") else {
        return Ok(None);
    };
    let geometry = geometry_before(log, geometries, start)?;
    let atoms = geometry.z.len();
    let n = 3 * atoms;
    let mut frequencies: Vec<f64> = Vec::with_capacity(n);
    let mut columns: Vec<Vec<f64>> = Vec::with_capacity(n);
    let mut i = start + 1;
    while columns.len() < n {
        let block = (i..log.lines.len().min(i + 8))
            .find(|&k| column_numbers(log.lines[k]).is_some_and(|c| c[0] == columns.len() + 1));
        let Some(block) = block else {
            return Err(log.error_at(
                skip_blank(log, i),
                format!(
                    "a block of modes from {} (the {n} modes of the {atoms} atoms at line {})",
                    columns.len() + 1,
                    geometry.line + 1
                ),
            ));
        };
        let k = column_numbers(log.lines[block]).map_or(0, |c| c.len()).min(n - columns.len());
        i = skip_blank(log, block + 1);
        let projected = log.get(i, "a `P.Frequency` line")?.trim_start().starts_with("P.Frequency");
        let label = if projected { "P.Frequency" } else { "Frequency" };
        frequencies.extend(labelled_numbers(log, i, label, k)?);
        i = skip_blank(log, i + 1);
        let mut block_columns = vec![Vec::with_capacity(n); k];
        for row in 0..n {
            let expected = format!(
                "row {} of the block at line {}: the coordinate's number and {k} displacements (3 × {atoms} atoms at line {})",
                row + 1,
                block + 1,
                geometry.line + 1
            );
            let t: Vec<&str> = log.get(i, &expected)?.split_whitespace().collect();
            let values: Option<Vec<f64>> = (t.len() == k + 1 && t[0].parse::<usize>().ok() == Some(row + 1))
                .then(|| t[1..].iter().map(|x| parse_real(x)).collect())
                .flatten();
            for (c, v) in values.ok_or_else(|| log.error_at(i, expected))?.into_iter().enumerate() {
                block_columns[c].push(v);
            }
            i += 1;
        }
        if log
            .lines
            .get(i)
            .is_some_and(|l| l.split_whitespace().next().and_then(|w| w.parse::<usize>().ok()) == Some(n + 1))
        {
            return Err(log.error_at(
                i,
                format!(
                    "the end of the block at line {} after its {n} rows (3 × {atoms} atoms at line {})",
                    block + 1,
                    geometry.line + 1
                ),
            ));
        }
        columns.extend(block_columns);
    }
    // `  k   freq || au  (debye/angs)**2  KM/mol  arbitrary`.
    let mut intensities: Vec<Option<f64>> = vec![None; n];
    if let Some(table) = (i..log.lines.len()).find(|&k| log.lines[k].contains("Infra Red Intensities")) {
        let mut k = table + 1;
        while log
            .lines
            .get(k)
            .is_some_and(|l| !l.contains("||") || !l.trim_start().starts_with(|c: char| c.is_ascii_digit()))
            && k < table + 4
        {
            k += 1;
        }
        while let Some(l) = log.lines.get(k).filter(|l| l.contains("||")) {
            let (head, rest) = l.split_once("||").unwrap_or_default();
            let mode = head.split_whitespace().next().and_then(|w| w.parse::<usize>().ok());
            let Some(mode) = mode else { break };
            let value = rest.split_whitespace().nth(2).and_then(parse_real);
            match (mode.checked_sub(1).and_then(|m| intensities.get_mut(m)), value) {
                (Some(slot), Some(v)) => *slot = Some(v),
                _ => {
                    return Err(
                        log.error_at(k, format!("a mode from 1 to {n} and its intensity in the (KM/mol) column"))
                    );
                }
            }
            k += 1;
        }
    }
    // The rigid modes: those of smallest |frequency|.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| frequencies[a].abs().total_cmp(&frequencies[b].abs()));
    let rigid = &order[..rigid_modes(&geometry.positions).min(n)];
    let modes = (0..n)
        .filter(|m| !rigid.contains(m))
        .map(|m| NormalMode {
            frequency_cm1: frequencies[m],
            ir_intensity: intensities[m],
            displacement: columns[m].chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect(),
        })
        .collect();
    Ok(Some(vibrations(modes, geometry)))
}

/// Psi4's `==> Harmonic Vibrational Analysis <==` (the last), at the geometry of the job: the
/// first computed after `FINDIF` (the reference of the finite differences) when there is one,
/// else the last before the analysis.
pub(crate) fn psi4(log: &LogLines, geometries: &[Geometry]) -> Result<Option<Vibrations>, ParseError> {
    let Some(start) = last(log, |t| t == "==> Harmonic Vibrational Analysis <==") else {
        return Ok(None);
    };
    // Finite differences begin at the first marker after any earlier analysis (`FINDIF` from
    // Psi4 1.3, which prints it again before the analysis; a sentence in 1.2). The reference is
    // the last geometry computed before it (1.2, 1.3: the gradient that chose the projection)
    // or, when none was, the first after it (1.7 computes the reference first).
    let previous = log.lines[..start].iter().rposition(|l| l.trim() == "==> Harmonic Vibrational Analysis <==");
    let marker = (previous.map_or(0, |p| p + 1)..start).find(|&k| {
        let t = log.lines[k].trim();
        t == "FINDIF" || t.starts_with("Using finite-differences of gradients")
    });
    let reference = marker.and_then(|m| {
        let before = geometries.iter().rfind(|g| g.line < m && previous.is_none_or(|p| g.line > p));
        before.or_else(|| geometries.iter().find(|g| g.line > m && g.line < start))
    });
    let geometry = match reference {
        Some(g) => g,
        None => geometry_before(log, geometries, start)?,
    };
    let atoms = geometry.z.len();
    let mut modes: Vec<NormalMode> = Vec::new();
    let mut i = start + 1;
    let first = (i..log.lines.len())
        .find(|&k| log.lines[k].trim_start().starts_with("Vibration ") || log.lines[k].contains("==>"));
    i = match first.filter(|&k| !log.lines[k].contains("==>")) {
        Some(k) => k,
        None => return Err(log.error_at(first.unwrap_or(log.lines.len()), "a block of modes `Vibration  7  8  9`")),
    };
    while log.lines.get(i).is_some_and(|l| l.trim_start().starts_with("Vibration ")) {
        let block = i;
        let numbers = log.lines[i].trim_start().strip_prefix("Vibration").and_then(column_numbers);
        let k = numbers.map_or(0, |c| c.len());
        if k == 0 {
            return Err(log.error_at(i, "`Vibration` and the modes' numbers"));
        }
        i += 1;
        let frequencies = labelled_numbers(log, i, "Freq [cm^-1]", k)?;
        let mut intensities = None;
        loop {
            i += 1;
            let l = log.get(i, "a line of dashes before the displacements")?.trim_start();
            if l.starts_with("---") {
                break;
            }
            if l.starts_with("IR activ [km/mol]") {
                intensities = Some(labelled_numbers(log, i, "IR activ [km/mol]", k)?);
            } else if l.is_empty() || l.starts_with("Vibration") {
                return Err(log.error_at(
                    i,
                    format!("a line of dashes before the displacements of the block at line {}", block + 1),
                ));
            }
        }
        i += 1;
        let mut columns = vec![Vec::with_capacity(atoms); k];
        for a in 0..atoms {
            let expected = format!(
                "atom {}'s row of the block at line {}: `{}  symbol` and {} displacements (the {atoms} atoms at line {})",
                a + 1,
                block + 1,
                a + 1,
                3 * k,
                geometry.line + 1
            );
            let ok = log
                .lines
                .get(i)
                .is_some_and(|l| l.split_whitespace().next().and_then(|w| w.parse().ok()) == Some(a + 1));
            if !ok {
                return Err(log.error_at(i, expected));
            }
            for (c, d) in triples(log, i, 2, k, &expected)?.into_iter().enumerate() {
                columns[c].push(d);
            }
            i += 1;
        }
        if log.lines.get(i).is_some_and(|l| !l.trim().is_empty()) {
            return Err(log.error_at(
                i,
                format!(
                    "a blank line after the {atoms} atoms' rows of the block at line {} (the geometry at line {})",
                    block + 1,
                    geometry.line + 1
                ),
            ));
        }
        for (m, displacement) in columns.into_iter().enumerate() {
            let ir_intensity = intensities.as_ref().map(|v| v[m]);
            modes.push(NormalMode { frequency_cm1: frequencies[m], ir_intensity, displacement });
        }
        i = skip_blank(log, i);
    }
    Ok(Some(vibrations(modes, geometry)))
}

/// Q-Chem's `VIBRATIONAL ANALYSIS` (the last), at the last orientation before it.
pub(crate) fn qchem(log: &LogLines, geometries: &[Geometry]) -> Result<Option<Vibrations>, ParseError> {
    let Some(start) = last(log, |t| t.trim_matches('*').trim() == "VIBRATIONAL ANALYSIS") else {
        return Ok(None);
    };
    let geometry = geometry_before(log, geometries, start)?;
    let atoms = geometry.z.len();
    let mut modes: Vec<NormalMode> = Vec::new();
    let mut i =
        (start..log.lines.len()).find(|&k| log.lines[k].trim_start().starts_with("Mode:")).unwrap_or(log.lines.len());
    if i == log.lines.len() {
        return Err(log.error_at(start, "a block of modes `Mode:  1  2  3` after `VIBRATIONAL ANALYSIS`"));
    }
    while log.lines.get(i).is_some_and(|l| l.trim_start().starts_with("Mode:")) {
        let block = i;
        let numbers = log.lines[i].trim_start().strip_prefix("Mode:").and_then(column_numbers);
        let k = numbers.filter(|c| c[0] == modes.len() + 1).map_or(0, |c| c.len());
        if k == 0 {
            return Err(log.error_at(i, format!("`Mode:` and the modes' numbers from {}", modes.len() + 1)));
        }
        i += 1;
        let frequencies = labelled_numbers(log, i, "Frequency:", k)?;
        let mut intensities = None;
        loop {
            i += 1;
            let l = log.get(i, "the heading `X  Y  Z` of the displacements")?.trim_start();
            if l.starts_with('X') {
                break;
            }
            if l.starts_with("IR Intens:") {
                intensities = Some(labelled_numbers(log, i, "IR Intens:", k)?);
            } else if l.is_empty() || l.starts_with("Mode:") {
                return Err(log.error_at(
                    i,
                    format!("the heading `X  Y  Z` of the displacements of the block at line {}", block + 1),
                ));
            }
        }
        i += 1;
        let mut columns = vec![Vec::with_capacity(atoms); k];
        for (a, &z) in geometry.z.iter().enumerate() {
            let symbol = crate::model::elements::ELEMENTS.get(z as usize).map_or("X", |e| e.symbol);
            let expected = format!(
                "atom {}'s row of the block at line {}: `{symbol}` and {} displacements (the {atoms} atoms at line {})",
                a + 1,
                block + 1,
                3 * k,
                geometry.line + 1
            );
            let ok = log
                .lines
                .get(i)
                .and_then(|l| l.split_whitespace().next())
                .is_some_and(|w| w.eq_ignore_ascii_case(symbol));
            if !ok {
                return Err(log.error_at(i, expected));
            }
            for (c, d) in triples(log, i, 1, k, &expected)?.into_iter().enumerate() {
                columns[c].push(d);
            }
            i += 1;
        }
        if !log.lines.get(i).is_some_and(|l| l.trim_start().starts_with("TransDip")) {
            return Err(log.error_at(
                i,
                format!(
                    "`TransDip` after the {atoms} atoms' rows of the block at line {} (the geometry at line {})",
                    block + 1,
                    geometry.line + 1
                ),
            ));
        }
        for (m, displacement) in columns.into_iter().enumerate() {
            let ir_intensity = intensities.as_ref().map(|v| v[m]);
            modes.push(NormalMode { frequency_cm1: frequencies[m], ir_intensity, displacement });
        }
        i = skip_blank(log, i + 1);
    }
    Ok(Some(vibrations(modes, geometry)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rigid_modes_count_five_for_a_line_and_six_otherwise() {
        let line = [DVec3::ZERO, DVec3::X, DVec3::X * 2.5];
        let bent = [DVec3::ZERO, DVec3::X, DVec3::Y];
        assert_eq!((rigid_modes(&line), rigid_modes(&bent), rigid_modes(&[DVec3::ZERO])), (5, 6, 3));
    }

    #[test]
    fn imaginary_frequencies_are_negative_in_every_notation() {
        let text = "       FREQUENCY:       825.18 I      3.88\n  Freq [cm^-1]   12.5i   30.0\n";
        let log = LogLines::new("f.out", text);
        assert_eq!(labelled_numbers(&log, 0, "FREQUENCY:", 2).unwrap(), vec![-825.18, 3.88]);
        assert_eq!(labelled_numbers(&log, 1, "Freq [cm^-1]", 2).unwrap(), vec![-12.5, 30.0]);
        let e = labelled_numbers(&log, 1, "Freq [cm^-1]", 3).unwrap_err();
        assert_eq!(e.line, 2);
    }
}
