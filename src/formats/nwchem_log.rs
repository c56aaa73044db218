//! NWChem outputs (GUIDE §10): the geometry, the basis and the final orbitals a job prints.
//!
//! ```text
//!  Output coordinates in angstroms (scale by  1.889725989 to convert to a.u.)   per geometry
//!   No.       Tag          Charge          X              Y              Z
//!  ---- ---------------- ---------- -------------- -------------- --------------
//!     1 C                    6.0000     0.23680554     1.41416660     0.00000000
//!                       Basis "ao basis" -> "ao basis" (cartesian)     or (spherical)
//!   C (Carbon)                                                         per tag
//!   1 S  7.16168370E+01  0.154329                                      shell, type, exponent,
//!   2 L  …                                                             coefficient(s) (L: s, p)
//!          Total SCF energy =   -379.768962491035                      (or DFT)
//!  Vector    1  Occ=2.000000D+00  E=-1.104059D+01  Symmetry=bu          the orbital analysis
//!                                  Final MO vectors                    `print "final vectors"`
//!             1           2           3      …                         6 a block
//!        ----------- ----------- -----------
//!    1       0.70148     0.70154    -0.00965                           function, coefficients
//! ```
//! The rows of `Final MO vectors` are numbered only: each atom (in the geometry's order) takes the
//! shells of the basis tag of its own tag (else of its element), functions in NWChem's order:
//! cartesian in the model's order (xx, xy, xz, yy, yz, zz), spherical m = −l … +l (p as x, y,
//! z) with the Condon–Shortley phase (the odd m > 0 functions change sign: [`condon_shortley`]).
//! Energies and occupations come from the orbital analysis (`Vector  n  Occ=… E=…`); an
//! orbital it leaves out gets its occupation from the closed and open shells and no energy.
//! Coefficients are printed to 5 decimals and the basis' contraction coefficients to 6: the
//! residual is measured and reported, never repaired. An unrestricted job prints its alpha
//! vectors (`global array: alpha evecs…`), then its beta ones, each with its own analysis.

use std::collections::HashMap;

use glam::DVec3;

use super::ParseError;
use super::logs::{Geometry, LogLines, decimals, error, frames, trailing_numbers, trajectory};
use super::printed::column_numbers;
use super::printed::{self, OpenShell, Orbital, PrintedShell, Row, Section, aufbau, pure_index};
use super::text::parse_real;
use super::wavefunction::OverlapFn;
use crate::model::Document;
use crate::model::basis::{MAX_L, ShellKind, n_cartesian};
use crate::model::orbitals::Spin;
use crate::model::units::BOHR_PER_ANGSTROM;

/// Width of the `Final MO vectors` columns (`F12.5`).
const COLUMN: usize = 12;

/// The input lines that make NWChem print what the viewer needs to draw orbitals.
pub const ORBITAL_KEYWORDS: &str = "print \"final vectors\" (in the scf or dft block)";

/// Parses an NWChem output, checking its orbitals (if printed) with `overlap`.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    let log = LogLines::new(file, text);
    let mut geometries = Vec::new();
    let mut doc = read(&log, overlap, &mut geometries)?;
    super::log_modes::attach(&mut doc, super::log_modes::nwchem(&log, &geometries));
    Ok(doc)
}

/// The document of `log` without its normal modes; `geometries` receives every geometry printed.
fn read(log: &LogLines, overlap: Option<OverlapFn>, geometries: &mut Vec<Geometry>) -> Result<Document, ParseError> {
    let file = log.file;
    let mut tags: Vec<Vec<String>> = Vec::new();
    let mut energies = Vec::new();
    let mut basis: Option<(bool, HashMap<String, Vec<PrintedShell>>)> = None;
    let mut vectors: Option<Vectors> = None;
    // From the orbital analyses, alpha (or restricted) then beta: number → (occupation, energy,
    // symmetry).
    let mut analysis: [HashMap<usize, (f64, f64, String)>; 2] = Default::default();
    let mut spin = 0;
    let mut shells_count = (None, None);
    let mut electrons = (None, None);
    let mut i = 0;
    while i < log.lines.len() {
        let t = log.lines[i].trim();
        if t.starts_with("Output coordinates in") {
            let (g, n, next) = coordinates(log, i)?;
            geometries.push(g);
            tags.push(n);
            i = next;
            continue;
        } else if (t.starts_with("Total SCF energy") || t.starts_with("Total DFT energy"))
            && let Some(e) = t.rsplit('=').next().and_then(|v| parse_real(v.trim()))
        {
            energies.push((i, e));
        } else if t.starts_with("Basis \"ao basis\"") && !t.starts_with("Basis \"ao basis\" -> \"\"") {
            let cartesian = !t.contains("(spherical)");
            let (b, next) = ao_basis(log, i)?;
            basis = Some((cartesian, b));
            i = next;
            continue;
        } else if t.ends_with("Final Molecular Orbital Analysis")
            || t.ends_with("Final Alpha Molecular Orbital Analysis")
        {
            spin = 0;
            analysis = Default::default();
        } else if t.ends_with("Final Beta Molecular Orbital Analysis") {
            spin = 1;
            analysis[1].clear();
        } else if let Some(rest) = t.strip_prefix("Vector") {
            if let Some((n, entry)) = analysis_line(rest) {
                analysis[spin].insert(n, entry);
            }
        } else if let Some(rest) = t.strip_prefix("Alpha electrons :") {
            electrons.0 = rest.trim().parse::<usize>().ok();
        } else if let Some(rest) = t.strip_prefix("Beta electrons :") {
            electrons.1 = rest.trim().parse::<usize>().ok();
        } else if let Some(rest) = t.strip_prefix("closed shells") {
            shells_count.0 = rest.trim_start_matches([' ', '=']).trim().parse::<usize>().ok();
        } else if let Some(rest) = t.strip_prefix("open shells") {
            shells_count.1 = rest.trim_start_matches([' ', '=']).trim().parse::<usize>().ok();
        } else if t == "Final MO vectors" {
            let (v, next) = final_vectors(log, i)?;
            vectors = Some(v);
            i = next;
            continue;
        }
        i += 1;
    }
    let frames = frames(geometries, &energies);
    if frames.is_empty() {
        return Err(error(
            file,
            log.lines.len().max(1),
            "an `Output coordinates in angstroms` table",
            "none in the file",
        ));
    }
    let why = match (&vectors, &basis) {
        (Some((line, sets, decimals)), Some((cartesian, basis))) => {
            let k = geometries.iter().rposition(|g| g.line < *line).unwrap_or(geometries.len() - 1);
            let (geometry, tags) = (&geometries[k], &tags[k]);
            let mut shells = Vec::with_capacity(tags.len());
            let mut section = Section { line: *line, decimals: *decimals, ..Default::default() };
            for (a, tag) in tags.iter().enumerate() {
                let letters: String = tag.chars().take_while(char::is_ascii_alphabetic).collect();
                let found = basis.get(tag).or_else(|| basis.get(&letters)).or_else(|| {
                    let symbol = crate::model::elements::ELEMENTS
                        .get(geometry.z[a] as usize)
                        .map(|e| e.symbol.to_ascii_uppercase());
                    symbol.and_then(|s| basis.get(&s))
                });
                let Some(found) = found else {
                    return Err(log.error_at(
                        geometry.line,
                        format!("a basis set for tag {tag} (atom {}) in the printed basis", a + 1),
                    ));
                };
                for s in found {
                    let n = if *cartesian || s.l == 1 { n_cartesian(s.l) } else { 2 * s.l as usize + 1 };
                    for f in 0..n {
                        section.rows.push(Row { line: *line, atom: a, label: format!("{}:{f}", s.l) });
                    }
                }
                shells.push(found.clone());
            }
            // Restricted: closed and open shells; unrestricted: the DFT module's electrons.
            let restricted = sets.len() == 1;
            let counts = if restricted {
                let (closed, open) = (shells_count.0.unwrap_or(0), shells_count.1.unwrap_or(0));
                (closed + open, closed)
            } else {
                (electrons.0.unwrap_or(0), electrons.1.unwrap_or(0))
            };
            for (s, columns) in sets.iter().enumerate() {
                let spin = if s == 0 { Spin::Alpha } else { Spin::Beta };
                for (k, coefficients) in columns.iter().enumerate() {
                    let (occupation, energy, symmetry) = analysis[s]
                        .get(&(k + 1))
                        .cloned()
                        .unwrap_or_else(|| (aufbau(k, spin, restricted, counts), f64::NAN, String::new()));
                    section.orbitals.push(Orbital {
                        energy,
                        occupation,
                        spin,
                        symmetry,
                        coefficients: coefficients.clone(),
                    });
                }
            }
            if sets.iter().flatten().any(|c| c.len() != section.rows.len()) {
                return Err(log.error_at(
                    *line,
                    format!("{} rows of coefficients (the printed basis set's functions)", section.rows.len()),
                ));
            }
            let cartesian = *cartesian;
            if !cartesian {
                condon_shortley(&mut section);
            }
            let function_of = move |label: &str, l: u32| -> Option<(ShellKind, usize)> {
                let (ll, f) = label.split_once(':')?;
                let (ll, f): (u32, usize) = (ll.parse().ok()?, f.parse().ok()?);
                if ll != l {
                    return None;
                }
                if cartesian || l == 1 {
                    Some((ShellKind::Cartesian, f))
                } else {
                    Some((ShellKind::Pure, pure_index(f as i32 - l as i32)))
                }
            };
            let mut doc = printed::document(log, "NWChem", geometry, &shells, &section, &function_of, overlap)?;
            let missing = section.orbitals.iter().filter(|o| o.energy.is_nan()).count();
            if missing > 0 {
                doc.problems.push(format!(
                    "{file}: {missing} orbitals have no energy: the orbital analysis lists only some (`print \"final vectors analysis\"` lists all)"
                ));
            }
            super::logs::note_one_geometry(&mut doc, file, frames.len(), geometry.line);
            return Ok(doc);
        }
        (None, _) => format!("the output prints no orbital coefficients (add `{ORBITAL_KEYWORDS}`)"),
        (Some(_), None) => "the output prints the orbitals but not the basis set (`Basis \"ao basis\"`)".to_string(),
    };
    let mut doc = trajectory(file, file, &frames);
    doc.problems.push(format!("{file}: no orbitals to draw: {why}"));
    Ok(doc)
}

/// NWChem's pure functions carry the Condon–Shortley phase: its m = +1, +3, +5 functions are
/// the negatives of the model's real solid harmonics (d+1 = −xz, f+1, f+3, g+1, g+3, …), so their
/// coefficients change sign. Seen in NWChem 7.0's RHF carbon atom (aug-cc-pCVQZ): every orbital
/// is symmetric about the axis of its doubly occupied p orbital only with these signs.
fn condon_shortley(section: &mut Section) {
    let flipped: Vec<bool> = (section.rows.iter())
        .map(|r| {
            let lf = r.label.split_once(':').and_then(|(l, f)| Some((l.parse::<i64>().ok()?, f.parse::<i64>().ok()?)));
            lf.is_some_and(|(l, f)| l >= 2 && (f - l) > 0 && (f - l) % 2 == 1)
        })
        .collect();
    for o in &mut section.orbitals {
        for (c, _) in o.coefficients.iter_mut().zip(&flipped).filter(|(_, f)| **f) {
            *c = -*c;
        }
    }
}

/// `1  Occ=2.000000D+00  E=-1.104059D+01  Symmetry=bu` (after `Vector`).
fn analysis_line(rest: &str) -> Option<(usize, (f64, f64, String))> {
    let mut t = rest.split_whitespace();
    let n: usize = t.next()?.parse().ok()?;
    let (mut occ, mut e, mut sym) = (None, None, String::new());
    let tokens: Vec<&str> = t.collect();
    let mut k = 0;
    while k < tokens.len() {
        let (key, value) = match tokens[k].split_once('=') {
            Some((key, "")) => {
                k += 1;
                (key, tokens.get(k).copied().unwrap_or(""))
            }
            Some((key, value)) => (key, value),
            None => ("", ""),
        };
        match key {
            "Occ" => occ = parse_real(value),
            "E" => e = parse_real(value),
            "Symmetry" => sym = value.to_string(),
            _ => {}
        }
        k += 1;
    }
    Some((n, (occ?, e?, sym)))
}

/// `Output coordinates in angstroms|a.u.` at `header`: the heading, dashes, rows
/// `n tag charge x y z`. Returns the geometry (bohr), the tags and the next line.
fn coordinates(log: &LogLines, header: usize) -> Result<(Geometry, Vec<String>, usize), ParseError> {
    let scale = if log.lines[header].contains("in angstroms") { BOHR_PER_ANGSTROM } else { 1.0 };
    let mut i = header + 1;
    while log.get(i, "the heading `No. Tag Charge X Y Z`")?.trim().is_empty() {
        i += 1;
    }
    if !log.lines[i].trim_start().starts_with("No.") {
        return Err(log.error_at(i, "the heading `No. Tag Charge X Y Z`"));
    }
    i += 1;
    if log.get(i, "a line of dashes")?.trim().starts_with("---") {
        i += 1;
    }
    let mut g = Geometry { line: header, z: Vec::new(), positions: Vec::new() };
    let mut tags = Vec::new();
    while let Some(l) = log.lines.get(i).filter(|l| !l.trim().is_empty()) {
        let t: Vec<&str> = l.split_whitespace().collect();
        let row = "an atom row `n tag charge x y z`";
        if t.len() != 6 {
            return Err(log.error_at(i, row));
        }
        let v: Option<Vec<f64>> = t[2..].iter().map(|x| parse_real(x)).collect();
        let v = v.ok_or_else(|| log.error_at(i, row))?;
        g.z.push(printed::element_of(v[0], t[1]));
        g.positions.push(DVec3::new(v[1], v[2], v[3]) * scale);
        tags.push(t[1].to_ascii_uppercase());
        i += 1;
    }
    if g.z.is_empty() {
        return Err(log.error_at(i, "at least one atom row in the coordinate table"));
    }
    Ok((g, tags, i))
}

/// `Basis "ao basis" -> …` at `header`: per tag a line `C (Carbon)`, dashes, a heading, dashes,
/// then primitives `shell type exponent coefficient(s)`, blank lines between shells; ends at a
/// line of neither kind (`Summary of …`).
fn ao_basis(log: &LogLines, header: usize) -> Result<(HashMap<String, Vec<PrintedShell>>, usize), ParseError> {
    let mut out: HashMap<String, Vec<PrintedShell>> = HashMap::new();
    let mut tag: Option<String> = None;
    let mut open: Option<OpenShell> = None;
    let close = |open: &mut Option<OpenShell>, shells: Option<&mut Vec<PrintedShell>>| {
        if let (Some(o), Some(shells)) = (open.take(), shells) {
            shells.extend(o.finish());
        }
    };
    let mut i = header + 1;
    while let Some(l) = log.lines.get(i) {
        let t = l.trim();
        let tokens: Vec<&str> = t.split_whitespace().collect();
        if t.is_empty() || t.starts_with("---") || t.starts_with("Exponent") {
            close(&mut open, tag.as_ref().and_then(|k| out.get_mut(k)));
        } else if tokens.len() == 2 && tokens[1].starts_with('(') && tokens[1].ends_with(')') {
            close(&mut open, tag.as_ref().and_then(|k| out.get_mut(k)));
            let name = tokens[0].to_ascii_uppercase();
            out.insert(name.clone(), Vec::new());
            tag = Some(name);
        } else if tokens.first().is_some_and(|s| s.parse::<usize>().is_ok()) && tag.is_some() {
            let row = "a primitive `shell type exponent coefficient(s)`";
            let kind = tokens.get(1).map(|k| k.to_ascii_uppercase()).unwrap_or_default();
            let two = kind == "L" || kind == "SP";
            let known = two || (kind.len() == 1 && "SPDFGH".find(kind.as_str()).is_some_and(|l| l as u32 <= MAX_L));
            let v: Option<Vec<f64>> = tokens.get(2..).unwrap_or_default().iter().map(|x| parse_real(x)).collect();
            let want = if two { 3 } else { 2 };
            let v = v.filter(|v| known && v.len() == want && v[0] > 0.0).ok_or_else(|| log.error_at(i, row))?;
            if open.as_ref().is_some_and(|o| o.number != tokens[0] || o.kind != kind) {
                close(&mut open, tag.as_ref().and_then(|k| out.get_mut(k)));
            }
            let o = open.get_or_insert_with(|| OpenShell { number: tokens[0].to_string(), kind, ..Default::default() });
            o.exponents.push(v[0]);
            o.columns.push(v[1..].to_vec());
        } else {
            break;
        }
        i += 1;
    }
    close(&mut open, tag.as_ref().and_then(|k| out.get_mut(k)));
    if out.values().all(Vec::is_empty) {
        return Err(log.error_at(i, "a tag's shells (`C (Carbon)`, then `1 S exponent coefficient`)"));
    }
    Ok((out, i))
}

/// The `Final MO vectors`: their header's line, each set's orbitals' coefficients (one set, or
/// alpha then beta), their decimals.
type Vectors = (usize, Vec<Vec<Vec<f64>>>, u32);

/// `Final MO vectors` at `header`: blocks of up to 6 orbitals — their numbers, dashes, rows
/// `function coefficients`; an unrestricted job's `global array: alpha evecs…` blocks, then its
/// `global array: beta evecs…` ones. Returns the header, each set's orbitals and the decimals.
fn final_vectors(log: &LogLines, header: usize) -> Result<(Vectors, usize), ParseError> {
    let mut sets: Vec<Vec<Vec<f64>>> = vec![Vec::new()];
    let mut rows_first = None;
    let mut first_decimals = None;
    let mut i = header + 1;
    loop {
        while let Some(t) = log.lines.get(i).map(|l| l.trim()) {
            if t.starts_with("global array") && t.contains("beta") && sets.len() == 1 && !sets[0].is_empty() {
                sets.push(Vec::new());
            } else if !(t.is_empty() || t.starts_with("---") || t.starts_with("global array")) {
                break;
            }
            i += 1;
        }
        let orbitals = sets.last_mut().expect("a set");
        let Some(numbers) = log.lines.get(i).and_then(|l| column_numbers(l)) else { break };
        if numbers[0] != orbitals.len() + 1 {
            break;
        }
        let block = i;
        let k = numbers.len();
        i += 1;
        if log.get(i, "a line of dashes")?.trim().starts_with("---") {
            i += 1;
        }
        let mut columns: Vec<Vec<f64>> = vec![Vec::new(); k];
        let mut row = 0;
        while let Some(l) = log.lines.get(i) {
            let Some((values, head)) = trailing_numbers(l, k, COLUMN) else { break };
            if head.trim().parse::<usize>().ok() != Some(row + 1) {
                break;
            }
            if first_decimals.is_none() {
                first_decimals = l.split_whitespace().last().and_then(decimals);
            }
            for (c, v) in values.into_iter().enumerate() {
                columns[c].push(v);
            }
            row += 1;
            i += 1;
        }
        log.block_rows(i, row, rows_first, (numbers[0], numbers[k - 1]), block)?;
        rows_first = Some(row);
        orbitals.extend(columns);
    }
    if sets.iter().any(Vec::is_empty) {
        return Err(log.error_at(i, "a block of orbitals: their numbers `1 2 3 4 5 6`"));
    }
    if sets.len() == 2 && sets[0].len() != sets[1].len() {
        return Err(log.error_at(i, format!("{} beta orbitals, as many as the alpha ones", sets[0].len())));
    }
    Ok(((header, sets, first_decimals.unwrap_or(5)), i))
}

#[cfg(test)]
#[path = "nwchem_log_tests.rs"]
mod tests;
