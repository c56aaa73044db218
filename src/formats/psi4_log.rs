//! Psi4 outputs (GUIDE §10): the geometry, the basis (`print_basis true`) and the orbitals
//! (`print_mos true`) a job prints.
//!
//! ```text
//!     Geometry (in Angstrom), charge = 0, multiplicity = 1:         (or in Bohr) per geometry
//!        Center              X                  Y                   Z               Mass
//!     ------------   -----------------  -----------------  -----------------  ---------------
//!          C           -1.415253322400     0.230221785400     0.000000000000    12.000000000000
//!   ==> AO Basis Functions <==
//!     [ STO-3G ]
//!     spherical                                                     (or cartesian)
//!     ****
//!     C   1                                                         a symmetry-unique atom
//!     S   3 1.00                                                    shell, primitives
//!                         71.61683700           0.15432897          exponent, coefficient
//!     ****
//!   @DF-RHF Final Energy:  -379.77011151550613
//!   ==> Molecular Orbitals <==
//!                             1            2                        5 a block
//!  1    C1 s0         0.7014836    0.7015422                        function: atom, label
//!             Ene   -11.0407466  -11.0406841                        energies, symmetries,
//!             Sym            Bu           Ag                        occupations
//!             Occ             2            2
//! ```
//! Psi4 prints the basis of the symmetry-unique atoms: every atom takes the shells of the unique
//! atom with its label. Pure functions are labelled `d0`, `d+1`, `d-1`, … (m = 0, +1, −1, …, the
//! model's order; p as `p0`, `p+1`, `p-1`: z, x, y), cartesian ones by their letters. The
//! contraction coefficients are for normalised primitives. Coefficients are printed to 7
//! decimals: the residual is measured and reported, never repaired. Only a restricted job's
//! orbitals are read (one set, `Occ` 0, 1 or 2).

use std::collections::HashMap;

use glam::DVec3;

use super::logs::{Geometry, LogLines, decimals, error, frames, trailing_numbers, trajectory};
use super::printed::{self, Orbital, PrintedShell, Row, Section, cartesian_index, next_block, pure_index};
use super::text::parse_real;
use super::wavefunction::OverlapFn;
use super::{MAX_Z, ParseError};
use crate::model::Document;
use crate::model::basis::{MAX_L, ShellKind};
use crate::model::elements::atomic_number;
use crate::model::orbitals::Spin;
use crate::model::units::BOHR_PER_ANGSTROM;

/// Width of Psi4's coefficient columns.
const COLUMN: usize = 13;

/// The options that make Psi4 print what the viewer needs to draw orbitals.
pub const ORBITAL_KEYWORDS: &str = "set { print_basis true  print_mos true }";

/// Parses a Psi4 output, checking its orbitals (if printed) with `overlap`.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    let log = LogLines::new(file, text);
    let mut geometries = Vec::new();
    let mut doc = read(&log, overlap, &mut geometries)?;
    super::log_modes::attach(&mut doc, super::log_modes::psi4(&log, &geometries));
    Ok(doc)
}

/// The document of `log` without its normal modes; `geometries` receives every geometry printed.
fn read(log: &LogLines, overlap: Option<OverlapFn>, geometries: &mut Vec<Geometry>) -> Result<Document, ParseError> {
    let file = log.file;
    let mut labels: Vec<Vec<String>> = Vec::new();
    let mut energies = Vec::new();
    let mut basis: Option<AoBasis> = None;
    let mut section: Option<Section> = None;
    let mut i = 0;
    while i < log.lines.len() {
        let t = log.lines[i].trim();
        if t.starts_with("Geometry (in Angstrom)") || t.starts_with("Geometry (in Bohr)") {
            let (g, n, next) = coordinates(log, i)?;
            geometries.push(g);
            labels.push(n);
            i = next;
            continue;
        } else if t.starts_with('@')
            && t.contains("Final Energy:")
            && let Some(e) = t.split_whitespace().last().and_then(parse_real)
        {
            energies.push((i, e));
        } else if t == "==> AO Basis Functions <==" {
            let (b, next) = ao_basis(log, i)?;
            basis = Some(b);
            i = next;
            continue;
        } else if t == "==> Molecular Orbitals <==" {
            let (s, next) = molecular_orbitals(log, i)?;
            section = Some(s);
            i = next;
            continue;
        }
        i += 1;
    }
    let frames = frames(geometries, &energies);
    if frames.is_empty() {
        return Err(error(file, log.lines.len().max(1), "a `Geometry (in Angstrom)` table", "none in the file"));
    }
    let why = match (&section, &basis) {
        (Some(section), Some((spherical, basis))) => {
            let k = geometries.iter().rposition(|g| g.line < section.line).unwrap_or(geometries.len() - 1);
            let (geometry, labels) = (&geometries[k], &labels[k]);
            let mut shells = Vec::with_capacity(labels.len());
            for (a, label) in labels.iter().enumerate() {
                let letters: String = label.chars().take_while(char::is_ascii_alphabetic).collect();
                let Some(found) = basis.get(label).or_else(|| basis.get(&letters)) else {
                    return Err(log.error_at(
                        geometry.line,
                        format!("a basis set for {label} (atom {}) in the printed basis", a + 1),
                    ));
                };
                shells.push(found.clone());
            }
            let spherical = *spherical;
            let function_of = move |label: &str, l: u32| function_of(label, l, spherical);
            let mut doc = printed::document(log, "Psi4", geometry, &shells, section, &function_of, overlap)?;
            super::logs::note_one_geometry(&mut doc, file, frames.len(), geometry.line);
            return Ok(doc);
        }
        (None, None) => format!("the output prints neither the basis set nor the orbitals (add `{ORBITAL_KEYWORDS}`)"),
        (None, Some(_)) => {
            "the output prints the basis set but not the orbitals (add `set print_mos true`)".to_string()
        }
        (Some(_), None) => {
            "the output prints the orbitals but not the basis set (add `set print_basis true`)".to_string()
        }
    };
    let mut doc = trajectory(file, file, &frames);
    doc.problems.push(format!("{file}: no orbitals to draw: {why}"));
    Ok(doc)
}

/// A row's label: `s0`; `p0`, `p+1`, `p-1` (z, x, y); pure `d0`, `d+1`, `d-1`, … in a spherical
/// basis; cartesian `dxx`, `fxyz`, … (or `pz`) by their letters.
fn function_of(label: &str, l: u32, spherical: bool) -> Option<(ShellKind, usize)> {
    let label = label.to_ascii_lowercase();
    let mut chars = label.chars();
    if chars.next()? != printed::letter(l) {
        return None;
    }
    let rest = chars.as_str();
    if l == 0 {
        return matches!(rest, "" | "0").then_some((ShellKind::Cartesian, 0));
    }
    if let Some(i) = cartesian_index(rest, l) {
        return Some((ShellKind::Cartesian, i));
    }
    let m: i32 = rest.trim_start_matches('+').parse().ok()?;
    if m.unsigned_abs() > l {
        return None;
    }
    if l == 1 {
        // p0 = z, p+1 = x, p−1 = y.
        return Some((ShellKind::Cartesian, [2, 0, 1][pure_index(m)]));
    }
    spherical.then_some((ShellKind::Pure, pure_index(m)))
}

/// `Geometry (in Angstrom|Bohr)` at `header`: a blank line, the heading `Center X Y Z Mass` and
/// dashes (when printed), rows `label x y z [mass]`. Returns the geometry (bohr), the labels and the next line.
fn coordinates(log: &LogLines, header: usize) -> Result<(Geometry, Vec<String>, usize), ParseError> {
    let scale = if log.lines[header].contains("Angstrom") { BOHR_PER_ANGSTROM } else { 1.0 };
    let mut i = header + 1;
    while log.get(i, "the heading `Center X Y Z Mass`")?.trim().is_empty() {
        i += 1;
    }
    // The heading and its dashes (absent from an optimisation's "Structure for next step").
    if log.lines[i].trim_start().starts_with("Center") {
        i += 1;
        if log.get(i, "a line of dashes")?.trim().starts_with("---") {
            i += 1;
        }
    }
    let mut g = Geometry { line: header, z: Vec::new(), positions: Vec::new() };
    let mut labels = Vec::new();
    while let Some(l) = log.lines.get(i).filter(|l| !l.trim().is_empty()) {
        let t: Vec<&str> = l.split_whitespace().collect();
        let row = "an atom row `label x y z mass`";
        if t.len() < 4 {
            return Err(log.error_at(i, row));
        }
        let v: Option<Vec<f64>> = t[1..4].iter().map(|x| parse_real(x)).collect();
        let v = v.ok_or_else(|| log.error_at(i, row))?;
        let letters: String = t[0].chars().take_while(char::is_ascii_alphabetic).collect();
        let z = atomic_number(&letters)
            .filter(|&z| z <= MAX_Z)
            .ok_or_else(|| log.error_at(i, "an element symbol beginning the atom's label"))?;
        g.z.push(z);
        g.positions.push(DVec3::new(v[0], v[1], v[2]) * scale);
        labels.push(t[0].to_ascii_uppercase());
        i += 1;
    }
    if g.z.is_empty() {
        return Err(log.error_at(i, "at least one atom row in the geometry table"));
    }
    Ok((g, labels, i))
}

/// Whether the basis is spherical, and each unique atom's shells by its label.
type AoBasis = (bool, HashMap<String, Vec<PrintedShell>>);

/// `==> AO Basis Functions <==` at `header`: `[ NAME ]`, `spherical` or `cartesian`, then per
/// unique atom `****`, `LABEL  n`, shells `S   3 1.00` with their primitives `exponent
/// coefficient`; the section ends at the first line after a `****` that opens no atom.
fn ao_basis(log: &LogLines, header: usize) -> Result<(AoBasis, usize), ParseError> {
    let mut i = header + 1;
    let mut spherical = None;
    while spherical.is_none() {
        let t = log.get(i, "`spherical` or `cartesian`")?.trim();
        match t {
            "spherical" => spherical = Some(true),
            "cartesian" => spherical = Some(false),
            _ if t.is_empty() || t.starts_with('[') => {}
            _ => return Err(log.error_at(i, "`spherical` or `cartesian`")),
        }
        i += 1;
    }
    let mut out: HashMap<String, Vec<PrintedShell>> = HashMap::new();
    while let Some(l) = log.lines.get(i) {
        if l.trim() != "****" {
            break;
        }
        i += 1;
        let Some(atom) = log.lines.get(i) else { break };
        let t: Vec<&str> = atom.split_whitespace().collect();
        let [label, number] = t[..] else { break };
        if number.parse::<usize>().is_err() || !label.starts_with(|c: char| c.is_ascii_alphabetic()) {
            break;
        }
        i += 1;
        let mut shells = Vec::new();
        while let Some(l) = log.lines.get(i) {
            let t: Vec<&str> = l.split_whitespace().collect();
            if t.first() == Some(&"****") {
                break;
            }
            let shell = "a shell `S|P|D|F|G|H  primitives  1.00` or `****`";
            let kind = t.first().map(|k| k.to_ascii_uppercase()).unwrap_or_default();
            let l_of = (kind.len() == 1).then(|| "SPDFGH".find(kind.as_str())).flatten().map(|l| l as u32);
            let l_of = l_of.filter(|&l| l <= MAX_L).ok_or_else(|| log.error_at(i, shell))?;
            let count: usize =
                t.get(1).and_then(|n| n.parse().ok()).filter(|&n| n > 0).ok_or_else(|| log.error_at(i, shell))?;
            let mut p = PrintedShell { l: l_of, exponents: Vec::new(), coefficients: Vec::new() };
            for _ in 0..count {
                i += 1;
                let expected = "a primitive `exponent coefficient`";
                let v: Option<Vec<f64>> = log.get(i, expected)?.split_whitespace().map(parse_real).collect();
                let v = v.filter(|v| v.len() == 2 && v[0] > 0.0).ok_or_else(|| log.error_at(i, expected))?;
                p.exponents.push(v[0]);
                p.coefficients.push(v[1]);
            }
            shells.push(p);
            i += 1;
        }
        out.entry(label.to_ascii_uppercase()).or_insert(shells);
    }
    if out.is_empty() {
        return Err(log.error_at(i, "`****` and an atom `LABEL  n` opening the basis set"));
    }
    Ok(((spherical.unwrap_or(true), out), i))
}

/// `==> Molecular Orbitals <==` at `header`: blocks of up to 5 orbitals — their numbers, rows
/// `n  C1 s0  coefficients`, then `Ene`, `Sym`, `Occ` lines.
fn molecular_orbitals(log: &LogLines, header: usize) -> Result<(Section, usize), ParseError> {
    let mut section = Section { line: header, ..Default::default() };
    let mut first_decimals = None;
    let mut i = header + 1;
    while let Some((block, numbers)) = next_block(log, i, section.orbitals.len()) {
        i = block;
        let k = numbers.len();
        i += 1;
        while log.lines.get(i).is_some_and(|l| l.trim().is_empty()) {
            i += 1;
        }
        let first_block = section.orbitals.is_empty();
        let mut columns: Vec<Vec<f64>> = vec![Vec::new(); k];
        let mut row = 0;
        while let Some(l) = log.lines.get(i) {
            let Some((values, head)) = trailing_numbers(l, k, COLUMN) else { break };
            let t: Vec<&str> = head.split_whitespace().collect();
            let [n, atom, label] = t[..] else { break };
            if n.parse::<usize>().ok() != Some(row + 1) {
                break;
            }
            let digits: String = atom.chars().skip_while(|c| !c.is_ascii_digit()).collect();
            let Some(atom) = digits.parse::<usize>().ok().filter(|&a| a > 0) else {
                return Err(log.error_at(i, "an atom's label and number (`C1`) in the row"));
            };
            if first_decimals.is_none() {
                first_decimals = l.split_whitespace().last().and_then(decimals);
            }
            let new = Row { line: i, atom: atom - 1, label: label.to_string() };
            section.take_row(log, (header, row, first_block), new, values, &mut columns)?;
            row += 1;
            i += 1;
        }
        let before = (!first_block).then_some(section.rows.len());
        log.block_rows(i, row, before, (numbers[0], numbers[k - 1]), block)?;
        while log.lines.get(i).is_some_and(|l| l.trim().is_empty()) {
            i += 1;
        }
        let mut line_of = |key: &str| -> Result<Vec<String>, ParseError> {
            let l = log.get(i, key)?;
            let t: Vec<&str> = l.split_whitespace().collect();
            if t.first() != Some(&key) || t.len() != k + 1 {
                return Err(log.error_at(i, format!("`{key}` and {k} values under the block at line {}", block + 1)));
            }
            i += 1;
            Ok(t[1..].iter().map(ToString::to_string).collect())
        };
        let energies = line_of("Ene")?;
        let symmetries = line_of("Sym")?;
        let occupations = line_of("Occ")?;
        for (c, coefficients) in columns.into_iter().enumerate() {
            let energy = parse_real(&energies[c]);
            let occupation = parse_real(&occupations[c]).filter(|o| (0.0..=2.0).contains(o));
            let (Some(energy), Some(occupation)) = (energy, occupation) else {
                return Err(log.error_at(
                    i - 1,
                    format!("numbers in the `Ene` and `Occ` lines of the block at line {}", block + 1),
                ));
            };
            section.orbitals.push(Orbital {
                energy,
                occupation,
                spin: Spin::Alpha,
                symmetry: symmetries[c].clone(),
                coefficients,
            });
        }
    }
    if section.orbitals.is_empty() {
        return Err(log.error_at(i, "a block of orbitals: their numbers `1 2 3 4 5`"));
    }
    section.decimals = first_decimals.unwrap_or(7);
    Ok((section, i))
}

#[cfg(test)]
#[path = "psi4_log_tests.rs"]
mod tests;
