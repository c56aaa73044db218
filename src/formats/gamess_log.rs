//! GAMESS-US outputs (GUIDE §10): the geometry, the basis and the orbitals a job prints.
//!
//! ```text
//!  ATOM      ATOMIC                      COORDINATES (BOHR)         one table per geometry
//!            CHARGE         X                   Y                   Z
//!  C           6.0     2.6723873767       -0.4474975755        0.0000000000
//!      ATOMIC BASIS SET                                             the symmetry-unique atoms
//!  C                                                                in input order, by name
//!       3   S       1            71.6168373    0.154328967295       shell, type, primitive,
//!       4   L       4             2.9412494   -0.099967229187    0.155916274999   exponent, (s, p)
//!  NUMBER OF OCCUPIED ORBITALS (ALPHA)          =   35
//!  FINAL R-B3LYP ENERGY IS     -382.0506353326 AFTER  17 ITERATIONS
//!           EIGENVECTORS                                            (`----- BETA SET -----`
//!                       1          2                                before the beta ones)
//!                   -10.0162   -10.0162                             energies
//!                      BU         AG                                symmetries
//!     1  C  1  S    0.699297   0.699293                             function, atom, coefficients
//! ```
//! GAMESS prints the basis of the symmetry-unique atoms only: every atom takes the shells of a
//! unique atom of its name whose functions its rows list. Functions are always cartesian (its
//! `ISPHER=1` drops combinations, not functions), printed as `S`, `X`, `XX`, `XXY`…, mapped to
//! the model's order by their letters; `L` shells are an s and a p shell sharing exponents. The
//! printed contraction coefficients are for normalised primitives. Occupations follow the
//! numbers of occupied orbitals of each spin. Coefficients are printed to 6 decimals: the
//! residual is measured and reported, never repaired.

use glam::DVec3;

use super::ParseError;
use super::logs::{Geometry, LogLines, decimals, error, frames, trailing_numbers, trajectory};
use super::printed::{
    self, NamedShells, OpenShell, Orbital, PrintedShell, Row, Section, aufbau, cartesian_index, next_block,
};
use super::text::parse_real;
use super::wavefunction::OverlapFn;
use crate::model::Document;
use crate::model::basis::{MAX_L, ShellKind};
use crate::model::elements::atomic_number;
use crate::model::orbitals::Spin;
use crate::model::units::BOHR_PER_ANGSTROM;

/// Width of GAMESS's coefficient columns (`F11.6`).
const COLUMN: usize = 11;

/// Parses a GAMESS-US output, checking its orbitals (if printed) with `overlap`.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    let log = LogLines::new(file, text);
    let mut geometries = Vec::new();
    let mut doc = read(&log, overlap, &mut geometries)?;
    super::log_modes::attach(&mut doc, super::log_modes::gamess(&log, &geometries));
    Ok(doc)
}

/// The document of `log` without its normal modes; `geometries` receives every geometry printed.
fn read(log: &LogLines, overlap: Option<OverlapFn>, geometries: &mut Vec<Geometry>) -> Result<Document, ParseError> {
    let file = log.file;
    let mut names: Vec<Vec<String>> = Vec::new();
    let mut energies = Vec::new();
    let mut basis: Option<NamedShells> = None;
    let mut sections: Vec<(Spin, Section)> = Vec::new();
    let mut occupied = (None, None);
    let mut i = 0;
    while i < log.lines.len() {
        let t = log.lines[i].trim();
        if (t.starts_with("ATOM") && t.contains("COORDINATES (BOHR)")) || t == "COORDINATES OF ALL ATOMS ARE (ANGS)" {
            let (g, n, next) = coordinates(log, i)?;
            geometries.push(g);
            names.push(n);
            i = next;
            continue;
        } else if t.starts_with("FINAL") && t.contains("ENERGY IS") {
            if let Some(e) = t.split("ENERGY IS").nth(1).and_then(|r| r.split_whitespace().next()).and_then(parse_real)
            {
                energies.push((i, e));
            }
        } else if t == "ATOMIC BASIS SET" {
            let (b, next) = atomic_basis(log, i)?;
            basis = Some(b);
            i = next;
            continue;
        } else if t.starts_with("NUMBER OF OCCUPIED ORBITALS (ALPHA)")
            || t.starts_with("NUMBER OF OCCUPIED ORBITALS (BETA )")
        {
            // With core potentials a second line says how many are kept: the later line wins.
            let n = t.rsplit('=').next().and_then(|v| v.trim().parse::<usize>().ok());
            if n.is_some() {
                if t.contains("(ALPHA)") {
                    occupied.0 = n;
                } else {
                    occupied.1 = n;
                }
            }
        } else if (t == "EIGENVECTORS" || t == "MOLECULAR ORBITALS")
            && log.lines.get(i + 1).is_some_and(|l| l.trim().starts_with("---"))
        {
            let beta = (i.saturating_sub(6)..i).any(|k| log.lines[k].contains("BETA SET"));
            let (section, next) = eigenvectors(log, i)?;
            let spin = if beta { Spin::Beta } else { Spin::Alpha };
            // A later section of a spin replaces the earlier (the guess's, an earlier step's).
            if spin == Spin::Alpha {
                sections.clear();
            }
            sections.retain(|s| s.0 != spin);
            sections.push((spin, section));
            i = next;
            continue;
        }
        i += 1;
    }
    let frames = frames(geometries, &energies);
    if frames.is_empty() {
        return Err(error(file, log.lines.len().max(1), "an `ATOM … COORDINATES (BOHR)` table", "none in the file"));
    }
    let title = file.to_string();
    let why = match (sections.first(), &basis) {
        (Some((_, first)), Some(basis)) => {
            let k = geometries.iter().rposition(|g| g.line < first.line).unwrap_or(geometries.len() - 1);
            let (geometry, names) = (&geometries[k], &names[k]);
            let Some(alpha) = occupied.0 else {
                return Err(log.error_at(first.line, "`NUMBER OF OCCUPIED ORBITALS (ALPHA)` before the orbitals"));
            };
            let counts = (alpha, occupied.1.unwrap_or(alpha));
            let restricted = sections.len() == 1;
            let mut section = Section { line: first.line, decimals: first.decimals, ..Default::default() };
            for (spin, s) in &sections {
                if !section.rows.is_empty() && s.rows.len() != section.rows.len() {
                    return Err(log.error_at(s.line, format!("{} rows of coefficients, as the alpha orbitals", section.rows.len())));
                }
                section.rows.clone_from(&s.rows);
                for (k, o) in s.orbitals.iter().enumerate() {
                    let occupation = aufbau(k, *spin, restricted, counts);
                    section.orbitals.push(Orbital { occupation, spin: *spin, ..o.clone() });
                }
            }
            let shells = atom_shells(log, geometry, names, basis, &section)?;
            let mut doc = printed::document(log, "GAMESS", geometry, &shells, &section, &function_of, overlap)?;
            super::logs::note_one_geometry(&mut doc, file, frames.len(), geometry.line);
            return Ok(doc);
        }
        (None, _) => "the output prints no orbitals (`EIGENVECTORS`: NPRINT=-5 or lower hides them; NPRINT=3 or `$GUESS PRTMO=.T. $END` prints them all)".to_string(),
        (Some(_), None) => "the output prints the orbitals but not the basis set (`ATOMIC BASIS SET`, hidden by NPRINT=-5 or lower)".to_string(),
    };
    let mut doc = trajectory(file, &title, &frames);
    doc.problems.push(format!("{file}: no orbitals to draw: {why}"));
    Ok(doc)
}

/// Reads a row's label (`S`, `X`, `XXY`…): always cartesian.
fn function_of(label: &str, l: u32) -> Option<(ShellKind, usize)> {
    if l == 0 {
        return label.eq_ignore_ascii_case("S").then_some((ShellKind::Cartesian, 0));
    }
    cartesian_index(label, l).map(|i| (ShellKind::Cartesian, i))
}

/// `ATOM ATOMIC COORDINATES (BOHR)` at `header` (the heading's second line follows) or, at each
/// step of an optimisation, `COORDINATES OF ALL ATOMS ARE (ANGS)` (a heading `ATOM CHARGE X Y Z`
/// and dashes follow): rows `name charge x y z` until a blank line. Returns the geometry (bohr),
/// the atoms' names and the next line.
fn coordinates(log: &LogLines, header: usize) -> Result<(Geometry, Vec<String>, usize), ParseError> {
    let angstrom = log.lines[header].contains("(ANGS)");
    let heading = if angstrom { "the heading `ATOM CHARGE X Y Z`" } else { "the heading's second line `CHARGE X Y Z`" };
    let want = if angstrom { "ATOM" } else { "CHARGE" };
    if !log.get(header + 1, heading)?.trim_start().starts_with(want) {
        return Err(log.error_at(header + 1, heading));
    }
    let mut i = header + 2;
    if angstrom && log.get(i, "a line of dashes")?.trim_start().starts_with("---") {
        i += 1;
    }
    let scale = if angstrom { BOHR_PER_ANGSTROM } else { 1.0 };
    let mut g = Geometry { line: header, z: Vec::new(), positions: Vec::new() };
    let mut names = Vec::new();
    while let Some(l) = log.lines.get(i).filter(|l| !l.trim().is_empty()) {
        let t: Vec<&str> = l.split_whitespace().collect();
        let row = "an atom row `name charge x y z`";
        let v: Option<Vec<f64>> =
            t.get(1..).filter(|v| v.len() == 4).and_then(|v| v.iter().map(|x| parse_real(x)).collect());
        let v = v.ok_or_else(|| log.error_at(i, row))?;
        g.z.push(printed::element_of(v[0], t[0]));
        g.positions.push(DVec3::new(v[1], v[2], v[3]) * scale);
        names.push(t[0].to_ascii_uppercase());
        i += 1;
    }
    if g.z.is_empty() {
        return Err(log.error_at(i, "at least one atom row in the coordinate table"));
    }
    Ok((g, names, i))
}

/// `ATOMIC BASIS SET` at `header`: per unique atom its name on a line of its own, then shells
/// `shell type primitive exponent coefficient(s)` (an `L` shell's two: s and p), blank lines
/// between shells; ends at `TOTAL NUMBER OF BASIS SET SHELLS`.
fn atomic_basis(log: &LogLines, header: usize) -> Result<(NamedShells, usize), ParseError> {
    let mut atoms: NamedShells = Vec::new();
    let mut i = header + 1;
    let mut open: Option<OpenShell> = None;
    let close = |open: &mut Option<OpenShell>, atoms: &mut NamedShells| {
        if let (Some(o), Some((_, shells))) = (open.take(), atoms.last_mut()) {
            shells.extend(o.finish());
        }
    };
    while !log
        .get(i, "the heading `SHELL TYPE PRIMITIVE EXPONENT CONTRACTION COEFFICIENT(S)`")?
        .trim_start()
        .starts_with("SHELL TYPE")
    {
        i += 1;
    }
    i += 1;
    loop {
        let l = log.get(i, "`TOTAL NUMBER OF BASIS SET SHELLS` closing the basis set")?;
        let t = l.trim();
        if t.starts_with("TOTAL NUMBER OF BASIS SET SHELLS") {
            close(&mut open, &mut atoms);
            break;
        }
        // Drop the parenthesised unnormalised coefficients some versions print beside.
        let mut depth = 0i32;
        let cleaned: String = t
            .chars()
            .filter(|&c| {
                match c {
                    '(' => depth += 1,
                    ')' => {
                        depth -= 1;
                        return false;
                    }
                    _ => {}
                }
                depth == 0
            })
            .collect();
        let tokens: Vec<&str> = cleaned.split_whitespace().collect();
        if tokens.is_empty() {
            close(&mut open, &mut atoms);
        } else if tokens.len() == 1 && tokens[0].chars().next().is_some_and(|c| c.is_ascii_alphabetic()) {
            close(&mut open, &mut atoms);
            atoms.push((tokens[0].to_ascii_uppercase(), Vec::new()));
        } else if tokens[0].parse::<usize>().is_ok() && !atoms.is_empty() {
            let row = "a primitive `shell type primitive exponent coefficient(s)`";
            let kind = tokens.get(1).map(|k| k.to_ascii_uppercase()).unwrap_or_default();
            let known =
                kind == "L" || (kind.len() == 1 && "SPDFGH".find(kind.as_str()).is_some_and(|l| l as u32 <= MAX_L));
            let want = if kind == "L" { 2 } else { 1 };
            let v: Option<Vec<f64>> = tokens.get(3..).unwrap_or_default().iter().map(|x| parse_real(x)).collect();
            let v = v.filter(|v| known && v.len() == 1 + want && v[0] > 0.0).ok_or_else(|| log.error_at(i, row))?;
            if open.as_ref().is_some_and(|o| o.number != tokens[0] || o.kind != kind) {
                close(&mut open, &mut atoms);
            }
            let o = open.get_or_insert_with(|| OpenShell { number: tokens[0].to_string(), kind, ..Default::default() });
            o.exponents.push(v[0]);
            o.columns.push(v[1..].to_vec());
        } else {
            return Err(log.error_at(i, "a shell's primitive, an atom's name or `TOTAL NUMBER OF BASIS SET SHELLS`"));
        }
        i += 1;
    }
    if atoms.iter().all(|a| a.1.is_empty()) {
        return Err(log.error_at(i, "an atom's shells in the basis set"));
    }
    Ok((atoms, i + 1))
}

/// Each atom's shells: those of the first unique atom of its name (else of its element) whose
/// functions are the ones the atom's rows list.
fn atom_shells(
    log: &LogLines,
    geometry: &Geometry,
    names: &[String],
    unique: &NamedShells,
    section: &Section,
) -> Result<Vec<Vec<PrintedShell>>, ParseError> {
    let mut out = Vec::with_capacity(names.len());
    let mut row = 0;
    for (a, name) in names.iter().enumerate() {
        let labels: Vec<&str> =
            section.rows.iter().skip(row).take_while(|r| r.atom == a).map(|r| r.label.as_str()).collect();
        if labels.is_empty() {
            // The rows stop (or skip to a later atom) before this atom's functions.
            let at = section
                .rows
                .get(row)
                .map_or_else(|| section.rows.last().map_or(section.line, |r| r.line + 1), |r| r.line);
            return Err(log.error_at(at, format!("rows of coefficients for atom {} ({name})", a + 1)));
        }
        let fits = |shells: &[PrintedShell]| {
            let mut k = 0;
            for s in shells {
                let n = (s.l + 1) * (s.l + 2) / 2;
                for _ in 0..n {
                    match labels.get(k) {
                        Some(label) if function_of(label, s.l).is_some() => k += 1,
                        _ => return false,
                    }
                }
            }
            k == labels.len()
        };
        let element = |n: &str| {
            let letters: String = n.chars().take_while(char::is_ascii_alphabetic).collect();
            atomic_number(&letters)
        };
        let pick = unique
            .iter()
            .find(|u| &u.0 == name && fits(&u.1))
            .or_else(|| unique.iter().find(|u| element(&u.0).is_some_and(|z| z == geometry.z[a]) && fits(&u.1)));
        let Some((_, shells)) = pick else {
            let at = section.rows.get(row).map_or(section.line, |r| r.line);
            return Err(log.error_at(
                at,
                format!("the functions of a unique atom named {name} in the printed basis set (atom {})", a + 1),
            ));
        };
        row += labels.len();
        out.push(shells.clone());
    }
    Ok(out)
}

/// An `EIGENVECTORS` section at `header`: blocks of up to 5 orbitals — their numbers, energies,
/// symmetries (when printed), then one row per function — until a line that opens no block.
fn eigenvectors(log: &LogLines, header: usize) -> Result<(Section, usize), ParseError> {
    let mut section = Section { line: header, ..Default::default() };
    let mut i = header + 2;
    let mut first_decimals = None;
    while let Some((block, numbers)) = next_block(log, i, section.orbitals.len()) {
        i = block;
        let k = numbers.len();
        let l = log.get(i + 1, "the orbitals' energies")?;
        let energies: Option<Vec<f64>> = l.split_whitespace().map(parse_real).collect();
        let energies =
            energies.filter(|e| e.len() == k).ok_or_else(|| log.error_at(i + 1, format!("{k} orbital energies")))?;
        i += 2;
        let mut symmetries = vec![String::new(); k];
        if let Some(l) = log.lines.get(i) {
            let t: Vec<&str> = l.split_whitespace().collect();
            if t.len() == k && t.iter().all(|s| parse_real(s).is_none()) {
                symmetries = t.iter().map(ToString::to_string).collect();
                i += 1;
            }
        }
        let first_block = section.orbitals.is_empty();
        let mut columns: Vec<Vec<f64>> = vec![Vec::new(); k];
        let mut row = 0;
        while let Some(l) = log.lines.get(i) {
            let Some((values, head)) = trailing_numbers(l, k, COLUMN) else { break };
            let Some((number, atom, label)) = row_head(head) else { break };
            if number != row + 1 || atom == 0 {
                break;
            }
            if first_decimals.is_none() {
                first_decimals = l.split_whitespace().last().and_then(decimals);
            }
            let new = Row { line: i, atom: atom - 1, label: label.to_ascii_uppercase() };
            section.take_row(log, (header, row, first_block), new, values, &mut columns)?;
            row += 1;
            i += 1;
        }
        let before = (!first_block).then_some(section.rows.len());
        log.block_rows(i, row, before, (numbers[0], numbers[k - 1]), block)?;
        for (c, coefficients) in columns.into_iter().enumerate() {
            section.orbitals.push(Orbital {
                energy: energies[c],
                occupation: 0.0,
                spin: Spin::Alpha,
                symmetry: std::mem::take(&mut symmetries[c]),
                coefficients,
            });
        }
    }
    if section.orbitals.is_empty() {
        return Err(log.error_at(i, "a block of orbitals: their numbers `1 2 3 4 5`"));
    }
    section.decimals = first_decimals.unwrap_or(6);
    Ok((section, i))
}

/// A row's head `   56  C  1 XXXX` (`C  1XXXX` when the label fills its field): the function's
/// number, the atom's (from 1) and the function's label.
fn row_head(head: &str) -> Option<(usize, usize, &str)> {
    let head = head.trim_end();
    let label_at = head.trim_end_matches(|c: char| c.is_ascii_alphabetic()).len();
    let label = &head[label_at..];
    let rest = head[..label_at].trim_end();
    let digits_at = rest.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    let atom = rest[digits_at..].parse().ok()?;
    let mut tokens = rest[..digits_at].split_whitespace();
    let number = tokens.next()?.parse().ok()?;
    (!label.is_empty() && tokens.count() == 1).then_some((number, atom, label))
}

#[cfg(test)]
#[path = "gamess_log_tests.rs"]
mod tests;
