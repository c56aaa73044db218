//! ORCA outputs (GUIDE §10): what an ORCA job prints, read into the model.
//!
//! ```text
//! CARTESIAN COORDINATES (A.U.)                                 bohr, one table per geometry
//!   NO LB      ZA    FRAG     MASS         X           Y           Z
//!    0 C     6.0000    0    12.011   -2.674441    0.435056    0.000000
//! BASIS SET IN INPUT FORMAT                                    `print[p_basis] 2`
//!  NewGTO C                                                    per element
//!  S 3                                                         shell, primitives
//!    1      71.6168370000      0.1543289700                    exponent, coefficient
//!   end;
//! FINAL SINGLE POINT ENERGY      -382.055108392562
//! MOLECULAR ORBITALS (RHF, ROHF)                               `print[p_mos] 1`; 6 a block
//!                       0         1                            orbitals, from 0 (again from 0:
//!                  -10.01641 -10.01636                         the beta ones), energies,
//!                    2.00000   2.00000                         occupations
//!                   --------  --------
//!   0C   1s         0.699236  0.699232                         atom (from 0), function
//! ```
//! ORCA writes p functions z, x, y and pure functions m = 0, +1, −1, … (orbcloud's order), the
//! f±3, g±3, g±4, h±3, h±4 functions with the opposite sign (as in its Molden files:
//! [`super::wavefunction::orca_flipped`]); its printed contraction coefficients are for
//! normalised primitives, as input. Coefficients are printed to 6 decimals: the residual is
//! measured and reported as such, no repair is tried on it. Each coordinate table followed by a
//! `FINAL SINGLE POINT ENERGY` is a frame.
//!
//! A frequency job's modes: `VIBRATIONAL FREQUENCIES` (`  6:      43.87 cm**-1`, the first five or
//! six, translations and rotations, exactly 0.00 and left out), `NORMAL MODES` (blocks of columns,
//! one row per Cartesian coordinate x₀ y₀ z₀ x₁ …: ORCA's mass-weighted modes taken back to
//! Cartesian displacements and normalised, as printed) and `IR SPECTRUM` (`Int` in km/mol), at the
//! last coordinate table before them.
//!
//! A relaxed surface scan (`%geom Scan D 9 8 3 2 = 0, 360, 12 end end` with `Opt`; the layout of
//! cclib's regression file data/ORCA/basicORCA6.0/dvb_scan_relaxed.out, ORCA 6.0.1) prints a
//! banner `RELAXED SURFACE SCAN STEP n` per point, then that point's constrained optimisation
//! (`GEOMETRY OPTIMIZATION CYCLE k`, each with its coordinates and energy), "THE OPTIMIZATION HAS
//! CONVERGED", a "FINAL ENERGY EVALUATION AT THE STATIONARY POINT" (coordinates and energy once
//! more) and "*** OPTIMIZATION RUN DONE ***"; at the end "The Calculated Surface using the 'Actual
//! Energy'", one row per point. Such a log keeps one frame per point, the last geometry before
//! the next banner, and the coordinate scanned from the echoed input block (atoms from 0, as
//! ORCA numbers them; `first, last, points`, or the values listed in `[ ]`), measured in each
//! point's geometry as the Gaussian reader does ([`super::logs::job_scan`]); a dihedral's values
//! are turned by whole turns to start where the job asked (`= 200, …` reads 200°, not −160°).

use std::collections::HashMap;

use glam::DVec3;

use super::logs::{Geometry, LogLines, decimals, error, frames, trailing_numbers, trajectory};
use super::structure::element_of;
use super::text::parse_real;
use super::wavefunction::{OverlapFn, orca_flipped};
use super::{MAX_Z, ParseError};
use crate::model::basis::{Basis, MAX_L, Shell, ShellKind};
use crate::model::orbitals::{MolecularOrbital, Spin};
use crate::model::scan::{Coordinate, JobScan};
use crate::model::vibrations::{NormalMode, Vibrations};
use crate::model::{Atom, Document};

/// The keywords that make ORCA print the basis set and the orbitals.
pub const ORBITAL_KEYWORDS: &str = "%output print[p_basis] 2 print[p_mos] 1 end";

/// Parses an ORCA output, checking its orbitals (if printed) with `overlap`.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    let log = LogLines::new(file, text);
    let mut doc = read(&log, overlap)?;
    // A malformed mode section leaves the modes out, not the file.
    match vibrations(&log) {
        Ok(modes) => doc.vibrations = modes,
        Err(e) => doc.problems.push(format!("normal modes left out: {e}")),
    }
    // A malformed table leaves the states out, not the file.
    match super::excited_logs::orca(&log) {
        Ok(states) => doc.excited = states,
        Err(e) => doc.problems.push(format!("excited states left out: {e}")),
    }
    Ok(doc)
}

/// The document of the log's geometries and, if printed, its basis and orbitals.
fn read(log: &LogLines, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    let file = log.file;
    let mut geometries = Vec::new();
    let mut energies = Vec::new();
    let mut basis: Option<(usize, HashMap<String, Vec<PrintedShell>>)> = None;
    let mut orbitals: Option<MoSection> = None;
    let mut title = String::new();
    // The echoed input (`| 10> D 9 8 3 2 = 0, 360, 12`): its lines and their text after `>`.
    let mut echoed: Vec<(usize, &str)> = Vec::new();
    // A relaxed surface scan's `RELAXED SURFACE SCAN STEP n` banners and the lines where an
    // optimisation gave up ("The optimization did not converge").
    let mut steps: Vec<usize> = Vec::new();
    let mut unconverged: Vec<usize> = Vec::new();
    let mut i = 0;
    while i < log.lines.len() {
        let t = log.lines[i].trim();
        if title.is_empty() && t.starts_with("|  1>") {
            title = t.trim_start_matches("|  1>").trim().to_string();
        }
        if let Some(text) = echoed_input(t) {
            echoed.push((i, text));
        } else if t.contains("RELAXED SURFACE SCAN STEP") {
            steps.push(i);
        } else if t.starts_with("The optimization did not converge") {
            unconverged.push(i);
        }
        if t == "CARTESIAN COORDINATES (A.U.)" {
            let (g, next) = coordinates(log, i)?;
            geometries.push(g);
            i = next;
            continue;
        } else if t.starts_with("FINAL SINGLE POINT ENERGY") {
            let e = t.split_whitespace().last().and_then(parse_real);
            energies.push((i, e.ok_or_else(|| log.error_at(i, "an energy after `FINAL SINGLE POINT ENERGY`"))?));
        } else if t == "BASIS SET IN INPUT FORMAT" {
            let (b, next) = input_basis(log, i)?;
            basis = Some((i, b));
            i = next;
            continue;
        } else if t.starts_with("MOLECULAR ORBITALS") {
            let (section, next) = mo_section(log, i)?;
            orbitals = Some(section);
            i = next;
            continue;
        }
        i += 1;
    }
    let all = frames(&geometries, &energies);
    let frames = if steps.is_empty() { all } else { scan_points(&all, &steps) };
    let Some(last) = frames.last().map(|f| f.0) else {
        return Err(error(file, log.lines.len().max(1), "a `CARTESIAN COORDINATES (A.U.)` table", "none in the file"));
    };
    for (g, _) in &frames {
        if g.z != last.z {
            return Err(log.error_at(
                g.line,
                format!("the same {} atoms in every geometry (as at line {})", last.z.len(), last.line + 1),
            ));
        }
    }
    let title = if title.is_empty() { file.to_string() } else { title };
    let why = match (&orbitals, &basis) {
        (Some(section), Some((_, basis))) => {
            let geometry = geometries.iter().rev().find(|g| g.line < section.line).unwrap_or(last);
            let mut doc = wavefunction_document(log, geometry, basis, section, overlap)?;
            super::logs::note_one_geometry(&mut doc, file, frames.len(), geometry.line);
            doc.title = title;
            return Ok(doc);
        }
        (None, None) => format!("the output prints neither the basis set nor the orbitals (add `{ORBITAL_KEYWORDS}`)"),
        (None, Some(_)) => "the output prints the basis set but not the orbitals (add `print[p_mos] 1`)".to_string(),
        (Some(_), None) => "the output prints the orbitals but not the basis set (add `print[p_basis] 2`)".to_string(),
    };
    let mut doc = trajectory(file, &title, &frames);
    doc.problems.push(format!("{file}: no orbitals to draw: {why}"));
    if !steps.is_empty() {
        for (k, &s) in steps.iter().enumerate() {
            let end = steps.get(k + 1).copied().unwrap_or(usize::MAX);
            if let Some(&u) = unconverged.iter().find(|&&u| u > s && u < end) {
                doc.problems.push(format!(
                    "{file}:{}: the scan's step {} did not converge: its frame is the optimisation's last geometry",
                    u + 1,
                    k + 1
                ));
            }
        }
        // An unreadable `%geom Scan` block leaves the coordinate out, not the frames.
        match relaxed_scan(log, &echoed, &steps, &frames) {
            Ok(scan) => doc.job_scan = Some(scan),
            Err(e) => doc.problems.push(format!("the scan's coordinate left out: {e}")),
        }
    }
    Ok(doc)
}

/// The text of an echoed input line (`| 10> D 9 8 3 2 = 0, 360, 12`) after its `>`.
fn echoed_input(line: &str) -> Option<&str> {
    let rest = line.strip_prefix('|')?.trim_start();
    let digits = rest.find(|c: char| !c.is_ascii_digit())?;
    if digits == 0 {
        return None;
    }
    rest[digits..].strip_prefix('>')
}

/// The points of a relaxed surface scan: for each `RELAXED SURFACE SCAN STEP` banner, the last
/// frame before the next (the constrained optimisation's converged geometry, evaluated once more
/// after "THE OPTIMIZATION HAS CONVERGED" and before "*** OPTIMIZATION RUN DONE ***"). A step
/// cut off before its first geometry has no point.
fn scan_points<'a>(all: &[(&'a Geometry, Option<f64>)], steps: &[usize]) -> Vec<(&'a Geometry, Option<f64>)> {
    let mut points = Vec::new();
    for (k, &s) in steps.iter().enumerate() {
        let end = steps.get(k + 1).copied().unwrap_or(usize::MAX);
        if let Some(&f) = all.iter().rev().find(|f| f.0.line > s && f.0.line < end) {
            points.push(f);
        }
    }
    points
}

/// What a relaxed scan's coordinate is read from, in words.
const SCAN: &str = "a scanned coordinate `B i j = start, end, points` (or `A i j k`, `D i j k l`; atoms from 0; or values `= [v1 v2 …]`)";

/// The coordinate of a relaxed surface scan, read from the echoed `%geom Scan … end` block, and
/// its value at each of `frames` (the scan's points).
///
/// ```text
/// |  9> %geom Scan
/// | 10> D 9 8 3 2 = 0, 360, 12          type, atoms (from 0), first, last value, points
/// | 11> end                             or `B 0 1 = [1.0 1.1 1.3]`, the values listed
/// | 12> end
/// ```
fn relaxed_scan(
    log: &LogLines,
    echoed: &[(usize, &str)],
    steps: &[usize],
    frames: &[(&Geometry, Option<f64>)],
) -> Result<JobScan, ParseError> {
    let Some((line, coordinate, points, first)) = scan_block(log, echoed)? else {
        return Err(
            log.error_at(steps[0], "a `%geom Scan … end` block in the echoed input naming the scanned coordinate")
        );
    };
    if frames.len() < 2 {
        return Err(log.error_at(
            line,
            format!("at least two of the scan's points optimised ({} `RELAXED SURFACE SCAN STEP`)", steps.len()),
        ));
    }
    let text = echoed.iter().find(|e| e.0 == line).map_or("", |e| e.1);
    Ok(super::logs::job_scan(log, line, text, coordinate, points, frames)?.starting_near(first))
}

/// The echoed input's `Scan` block inside `%geom`: its coordinate's line, the coordinate, the
/// number of points and the first value asked for. `None` when the input scans nothing; an error for a block that cannot be
/// read or that scans two coordinates (a grid of points, not a series along one coordinate).
fn scan_block(log: &LogLines, echoed: &[(usize, &str)]) -> Result<Option<(usize, Coordinate, usize, f64)>, ParseError> {
    // The input as tokens with their lines; `=`, `[` and `]` stand alone, commas separate.
    let mut tokens: Vec<(usize, String)> = Vec::new();
    for &(i, text) in echoed {
        let text = text.split('#').next().unwrap_or("");
        let spaced = text.replace(',', " ").replace('=', " = ").replace('[', " [ ").replace(']', " ] ");
        tokens.extend(spaced.split_whitespace().map(|t| (i, t.to_ascii_lowercase())));
    }
    let mut in_geom = false;
    let mut start = None;
    for (k, (_, t)) in tokens.iter().enumerate() {
        if t == "%geom" {
            in_geom = true;
        } else if t.starts_with(['%', '*', '!']) {
            in_geom = false;
        } else if in_geom && t == "scan" {
            start = Some(k + 1);
            break;
        }
    }
    let Some(mut k) = start else { return Ok(None) };
    let mut found: Option<(usize, Coordinate, usize, f64)> = None;
    loop {
        let Some((i, t)) = tokens.get(k) else {
            let last = echoed.last().map_or(0, |e| e.0);
            return Err(log.error_at(last, "`end` closing the `%geom Scan` block"));
        };
        let i = *i;
        if t == "end" {
            return Ok(found);
        }
        if t.starts_with(['%', '*', '!']) {
            return Err(log.error_at(i, "`end` closing the `%geom Scan` block"));
        }
        let expected = match t.as_str() {
            "b" => 2,
            "a" => 3,
            "d" => 4,
            _ => return Err(log.error_at(i, format!("{SCAN}: only bonds, angles and dihedrals are scanned here"))),
        };
        if let Some((first, ..)) = found {
            return Err(log.error_at(
                i,
                format!(
                    "one scanned coordinate (line {} scans one already: a scan of two is a grid of points, not a series along one coordinate)",
                    first + 1
                ),
            ));
        }
        k += 1;
        let mut atoms: Vec<usize> = Vec::new();
        while let Some(a) = tokens.get(k).and_then(|(_, t)| t.parse::<usize>().ok()) {
            atoms.push(a);
            k += 1;
        }
        if atoms.len() != expected || tokens.get(k).is_none_or(|(_, t)| t != "=") {
            return Err(log.error_at(i, format!("{SCAN}: {expected} atom numbers, then `=`")));
        }
        k += 1;
        let number = |k: usize| tokens.get(k).and_then(|(_, t)| parse_real(t)).filter(|v| v.is_finite());
        let (points, first) = if tokens.get(k).is_some_and(|(_, t)| t == "[") {
            k += 1;
            let first = number(k).unwrap_or(0.0);
            let mut n = 0;
            while number(k).is_some() {
                n += 1;
                k += 1;
            }
            if tokens.get(k).is_none_or(|(_, t)| t != "]") || n < 2 {
                return Err(log.error_at(i, format!("{SCAN}: two or more values between `[` and `]`")));
            }
            k += 1;
            (n, first)
        } else {
            let count = tokens.get(k + 2).and_then(|(_, t)| t.parse::<usize>().ok()).filter(|&n| n >= 2);
            let (Some(first), Some(_), Some(count)) = (number(k), number(k + 1), count) else {
                return Err(log.error_at(i, format!("{SCAN}: a first value, a last value and a number of points")));
            };
            k += 3;
            (count, first)
        };
        let coordinate = match atoms[..] {
            [a, b] => Coordinate::Distance([a, b]),
            [a, b, c] => Coordinate::Angle([a, b, c]),
            [a, b, c, d] => Coordinate::Dihedral([a, b, c, d]),
            _ => return Err(log.error_at(i, format!("{SCAN}: {expected} atom numbers, then `=`"))),
        };
        found = Some((i, coordinate, points, first));
    }
}

#[derive(Debug, Clone)]
struct PrintedShell {
    l: u32,
    exponents: Vec<f64>,
    coefficients: Vec<f64>,
}

#[derive(Debug, Clone, Default)]
struct MoSection {
    line: usize,
    /// Each row's line, atom (from 0) and function label ("1s", "2pz", "3dz2").
    rows: Vec<(usize, usize, String)>,
    /// Energy, occupation, spin, coefficients in the file's order.
    orbitals: Vec<(f64, f64, Spin, Vec<f64>)>,
    decimals: u32,
}

/// A `CARTESIAN COORDINATES (A.U.)` table at line `header`; returns it and the line after it.
fn coordinates(log: &LogLines, header: usize) -> Result<(Geometry, usize), ParseError> {
    let mut i = header + 1;
    while log.get(i, "the coordinate table")?.trim().starts_with("---") {
        i += 1;
    }
    if !log.get(i, "the heading `NO LB ZA FRAG MASS X Y Z`")?.trim_start().starts_with("NO") {
        return Err(log.error_at(i, "the heading `NO LB ZA FRAG MASS X Y Z`"));
    }
    i += 1;
    let mut g = Geometry { line: header, z: Vec::new(), positions: Vec::new() };
    while let Some(l) = log.lines.get(i).filter(|l| !l.trim().is_empty()) {
        let t: Vec<&str> = l.split_whitespace().collect();
        let row = "an atom row `NO LB ZA FRAG MASS X Y Z` (bohr)";
        if t.len() != 8 {
            return Err(log.error_at(i, row));
        }
        let symbol = t[1].trim_end_matches(|c: char| !c.is_ascii_alphabetic());
        let z = element_of(symbol)
            .map(u32::from)
            .filter(|&z| z <= MAX_Z)
            .ok_or_else(|| log.error_at(i, "an element symbol in the LB column"))?;
        let xyz: Option<Vec<f64>> = t[5..].iter().map(|v| parse_real(v)).collect();
        let xyz = xyz.ok_or_else(|| log.error_at(i, row))?;
        g.z.push(z);
        g.positions.push(DVec3::new(xyz[0], xyz[1], xyz[2]));
        i += 1;
    }
    if g.z.is_empty() {
        return Err(log.error_at(i, "at least one atom row in the coordinate table"));
    }
    Ok((g, i))
}

/// `BASIS SET IN INPUT FORMAT` at line `header`: per element `NewGTO X`, shells, `end;`.
fn input_basis(log: &LogLines, header: usize) -> Result<(HashMap<String, Vec<PrintedShell>>, usize), ParseError> {
    let mut out: HashMap<String, Vec<PrintedShell>> = HashMap::new();
    let mut i = header + 1;
    while let Some(l) = log.lines.get(i) {
        let t = l.trim();
        if t.is_empty() || t.starts_with('#') || (t.starts_with("---") && i == header + 1) {
            i += 1;
            continue;
        }
        let Some(element) = t.strip_prefix("NewGTO") else { break };
        let element = element.trim().trim_matches('"').to_ascii_lowercase();
        let mut shells = Vec::new();
        i += 1;
        loop {
            let l = log.get(i, "a shell `S 3` or `end;`")?;
            let t: Vec<&str> = l.split_whitespace().collect();
            if t.first() == Some(&"end;") {
                i += 1;
                break;
            }
            let shell = "a shell `S|P|D|F|G|H  primitives` or `end;`";
            let l_of =
                t.first().and_then(|s| "SPDFGH".find(s.to_ascii_uppercase().as_str())).filter(|_| t[0].len() == 1);
            let l_of = l_of.map(|l| l as u32).filter(|&l| l <= MAX_L).ok_or_else(|| log.error_at(i, shell))?;
            let count: usize =
                t.get(1).and_then(|n| n.parse().ok()).filter(|&n| n > 0).ok_or_else(|| log.error_at(i, shell))?;
            let mut p = PrintedShell { l: l_of, exponents: Vec::new(), coefficients: Vec::new() };
            for _ in 0..count {
                i += 1;
                let expected = "a primitive `k  exponent  coefficient`";
                let v: Option<Vec<f64>> = log.get(i, expected)?.split_whitespace().map(parse_real).collect();
                let v = v.filter(|v| v.len() == 3 && v[1] > 0.0).ok_or_else(|| log.error_at(i, expected))?;
                p.exponents.push(v[1]);
                p.coefficients.push(v[2]);
            }
            shells.push(p);
            i += 1;
        }
        out.insert(element, shells);
    }
    if out.is_empty() {
        return Err(log.error_at(i, "`NewGTO ELEMENT` opening the basis set"));
    }
    Ok((out, i))
}

/// A block's header: the orbitals' numbers (from 0), one after another.
fn column_numbers(line: &str) -> Option<Vec<usize>> {
    let n: Option<Vec<usize>> = line.split_whitespace().map(|t| t.parse().ok()).collect();
    n.filter(|n| !n.is_empty() && n.windows(2).all(|w| w[1] == w[0] + 1))
}

/// Width of ORCA's orbital columns.
const COLUMN: usize = 10;

/// `MOLECULAR ORBITALS` at line `header`: blocks of up to 6 orbitals; numbering from 0 again
/// starts the beta orbitals.
fn mo_section(log: &LogLines, header: usize) -> Result<(MoSection, usize), ParseError> {
    let mut section = MoSection { line: header, ..Default::default() };
    let mut i = header + 1;
    while log.lines.get(i).is_some_and(|l| l.trim().starts_with("---")) {
        i += 1;
    }
    let mut spin = Spin::Alpha;
    let mut first_decimals = None;
    let mut in_spin = 0;
    while let Some(numbers) = log.lines.get(i).and_then(|l| column_numbers(l)) {
        let block = i;
        let k = numbers.len();
        if numbers[0] == 0 && in_spin > 0 {
            if spin == Spin::Beta {
                break;
            }
            spin = Spin::Beta;
            in_spin = 0;
        } else if numbers[0] != in_spin {
            break;
        }
        let numbers_of = |i: usize, what: &str| -> Result<Vec<f64>, ParseError> {
            let l = log.get(i, what)?;
            let v: Option<Vec<f64>> = l.split_whitespace().map(parse_real).collect();
            v.filter(|v| v.len() == k).ok_or_else(|| log.error_at(i, format!("{k} {what}")))
        };
        let energies = numbers_of(i + 1, "orbital energies")?;
        let occupations = numbers_of(i + 2, "occupations")?;
        if !log.get(i + 3, "a line of dashes")?.trim().starts_with("---") {
            return Err(log.error_at(i + 3, "a line of dashes under the occupations"));
        }
        i += 4;
        let rows_before = section.rows.len();
        let first_block = section.orbitals.is_empty();
        let mut columns: Vec<Vec<f64>> = vec![Vec::new(); k];
        let mut row = 0;
        while let Some(l) = log.lines.get(i) {
            let Some((values, head)) = trailing_numbers(l, k, COLUMN) else { break };
            let head: Vec<&str> = head.split_whitespace().collect();
            let [atom, label] = head[..] else { break };
            let digits = atom.chars().take_while(char::is_ascii_digit).count();
            let Ok(atom) = atom[..digits].parse::<usize>() else { break };
            if first_decimals.is_none() {
                first_decimals = l.split_whitespace().last().and_then(decimals);
            }
            if first_block {
                section.rows.push((i, atom, label.to_ascii_lowercase()));
            } else if section.rows.get(row).is_none_or(|r| r.1 != atom || r.2 != label.to_ascii_lowercase()) {
                return Err(log.error_at(i, format!("row {} as in the first block (line {})", row + 1, header + 1)));
            }
            for (c, v) in values.into_iter().enumerate() {
                columns[c].push(v);
            }
            row += 1;
            i += 1;
        }
        log.block_rows(i, row, (!first_block).then_some(rows_before), (numbers[0], numbers[k - 1]), block)?;
        for (c, coefficients) in columns.into_iter().enumerate() {
            section.orbitals.push((energies[c], occupations[c], spin, coefficients));
        }
        in_spin += k;
    }
    if section.orbitals.is_empty() {
        return Err(log.error_at(i, "a block of orbitals: their numbers `0 1 2 3 4 5`"));
    }
    section.decimals = first_decimals.unwrap_or(6);
    Ok((section, i))
}

/// Letters of shells by l, as ORCA names its functions.
const LETTERS: &str = "spdfgh";

fn wavefunction_document(
    log: &LogLines,
    geometry: &Geometry,
    printed: &HashMap<String, Vec<PrintedShell>>,
    section: &MoSection,
    overlap: Option<OverlapFn>,
) -> Result<Document, ParseError> {
    let atoms: Vec<Atom> = geometry
        .z
        .iter()
        .zip(&geometry.positions)
        .map(|(&z, &position)| Atom { z, charge: z as f64, position, ghost: z == 0 })
        .collect();
    let mut shells = Vec::new();
    // For each printed row, its function in the model's order, and its sign.
    let mut file_to_model = Vec::new();
    let mut signs = Vec::new();
    for (a, atom) in atoms.iter().enumerate() {
        let symbol = atom.element().symbol.to_ascii_lowercase();
        let Some(element) = printed.get(&symbol) else {
            return Err(log.error_at(
                geometry.line,
                format!("a basis set for {} (atom {a}) in the printed basis", atom.element().symbol),
            ));
        };
        for p in element {
            let kind = if p.l < 2 { ShellKind::Cartesian } else { ShellKind::Pure };
            let shell = Shell {
                atom: a,
                center: atom.position,
                l: p.l,
                kind,
                exponents: p.exponents.clone(),
                coefficients: p.coefficients.clone(),
            };
            let first = file_to_model.len();
            let n = shell.n_functions();
            if p.l == 1 {
                // z, x, y → x, y, z.
                file_to_model.extend([first + 2, first, first + 1]);
            } else {
                file_to_model.extend(first..first + n);
            }
            let flipped = if kind == ShellKind::Pure { orca_flipped(p.l) } else { 0..0 };
            signs.extend((0..n).map(|k| if flipped.contains(&k) { -1.0 } else { 1.0 }));
            // Each row names the atom and the shell's letter.
            for k in 0..n {
                let Some((line, row_atom, label)) = section.rows.get(first + k) else {
                    return Err(log.error_at(
                        section.line,
                        format!("{} rows of coefficients or more (the printed basis set's functions)", first + k + 1),
                    ));
                };
                let letter = label.trim_start_matches(|c: char| c.is_ascii_digit()).chars().next();
                if *row_atom != a || letter != LETTERS.chars().nth(p.l as usize) {
                    let letter = LETTERS.chars().nth(p.l as usize).unwrap_or('?');
                    return Err(
                        log.error_at(*line, format!("a {letter} function of atom {a}, as the printed basis set says"))
                    );
                }
            }
            shells.push(shell);
        }
    }
    let n = file_to_model.len();
    if section.rows.len() != n {
        return Err(log.error_at(section.line, format!("{n} rows of coefficients (the printed basis set's functions)")));
    }
    let orbitals = section
        .orbitals
        .iter()
        .map(|(energy, occupation, spin, c)| {
            let mut coefficients = vec![0.0; n];
            for (k, &v) in c.iter().enumerate() {
                coefficients[file_to_model[k]] = v * signs[k];
            }
            MolecularOrbital {
                energy: *energy,
                occupation: *occupation,
                spin: *spin,
                symmetry: String::new(),
                coefficients,
            }
        })
        .collect();
    Ok(super::printed::log_document(log, "ORCA", atoms, Basis { shells }, orbitals, overlap, section.decimals))
}

/// A frequency job's normal modes (see the module's documentation); `None` without
/// `VIBRATIONAL FREQUENCIES` and `NORMAL MODES`.
fn vibrations(log: &LogLines) -> Result<Option<Vibrations>, ParseError> {
    let find = |title: &str| log.lines.iter().rposition(|l| l.trim() == title);
    let (Some(freq_at), Some(modes_at)) = (find("VIBRATIONAL FREQUENCIES"), find("NORMAL MODES")) else {
        return Ok(None);
    };
    // `  k:   wavenumber cm**-1 …`, from 0, after the title.
    let mut frequencies: Vec<f64> = Vec::new();
    let mut i = freq_at + 1;
    while let Some(l) = log.lines.get(i) {
        let t: Vec<&str> = l.split_whitespace().collect();
        if let Some(k) = t.first().and_then(|k| k.strip_suffix(':')).and_then(|k| k.parse::<usize>().ok()) {
            let row = format!("a frequency `{k}:  wavenumber cm**-1`");
            if k != frequencies.len() || t.get(2) != Some(&"cm**-1") {
                return Err(log.error_at(i, row));
            }
            frequencies.push(t.get(1).and_then(|v| parse_real(v)).ok_or_else(|| log.error_at(i, row))?);
        } else if !frequencies.is_empty() && (t.is_empty() || l.trim().starts_with("---")) {
            break;
        }
        i += 1;
    }
    if frequencies.is_empty() {
        return Err(log.error_at(freq_at, "frequencies `0:  0.00 cm**-1` after `VIBRATIONAL FREQUENCIES`"));
    }
    let n = frequencies.len();
    if !n.is_multiple_of(3) {
        return Err(log.error_at(freq_at, format!("three frequencies per atom ({n} found)")));
    }
    // The blocks of columns: numbers, (irreps), rows `coordinate  values`.
    let mut columns: Vec<Vec<f64>> = Vec::new();
    let mut i = modes_at + 1;
    while columns.len() < n {
        let Some(l) = log.lines.get(i) else {
            return Err(
                log.error_at(i, format!("the modes' columns up to {} (NORMAL MODES at line {})", n - 1, modes_at + 1))
            );
        };
        let Some(numbers) = super::printed::column_numbers(l).filter(|c| c[0] == columns.len()) else {
            if columns.is_empty() || l.trim().is_empty() {
                i += 1;
                if i > modes_at + 40 && columns.is_empty() {
                    return Err(log.error_at(modes_at, "a block of modes: their numbers `0 1 2 …`"));
                }
                continue;
            }
            return Err(log.error_at(
                i,
                format!("the block of modes from {} (NORMAL MODES at line {})", columns.len(), modes_at + 1),
            ));
        };
        let block = i;
        let k = numbers.len();
        i += 1;
        // The irreps' line, when the point group has them.
        if log.lines.get(i).is_some_and(|l| l.split_whitespace().next().is_some_and(|t| t.parse::<usize>().is_err())) {
            i += 1;
        }
        let mut block_columns = vec![Vec::with_capacity(n); k];
        for row in 0..n {
            let expected =
                format!("row {row} of the block at line {}: the coordinate's number and {k} displacements", block + 1);
            let l = log.get(i, &expected)?;
            let t: Vec<&str> = l.split_whitespace().collect();
            let values: Option<Vec<f64>> =
                t.get(1..).filter(|v| v.len() == k).and_then(|v| v.iter().map(|x| parse_real(x)).collect());
            let values =
                values.filter(|_| t[0].parse::<usize>().ok() == Some(row)).ok_or_else(|| log.error_at(i, expected))?;
            for (c, v) in values.into_iter().enumerate() {
                block_columns[c].push(v);
            }
            i += 1;
        }
        columns.extend(block_columns);
    }
    // `  k:  wavenumber  eps  Int  …` under the `IR SPECTRUM` heading's `Int` column.
    let mut intensities: Vec<Option<f64>> = vec![None; n];
    if let Some(ir_at) = find("IR SPECTRUM") {
        let heading =
            (ir_at + 1..(ir_at + 6).min(log.lines.len())).find(|&k| log.lines[k].trim_start().starts_with("Mode"));
        let column = heading.and_then(|k| log.lines[k].split_whitespace().position(|w| w == "Int"));
        if let (Some(heading), Some(column)) = (heading, column) {
            let mut i = heading + 1;
            while let Some(l) = log.lines.get(i) {
                let t: Vec<&str> = l.split_whitespace().collect();
                let Some(k) = t.first().and_then(|k| k.strip_suffix(':')).and_then(|k| k.parse::<usize>().ok()) else {
                    // The units' line and the dashes under the heading; the table ends at the
                    // first other line after its rows.
                    if i <= heading + 3 {
                        i += 1;
                        continue;
                    }
                    break;
                };
                let value = t.get(column).and_then(|v| parse_real(v));
                match (intensities.get_mut(k), value) {
                    (Some(slot), Some(v)) => *slot = Some(v),
                    _ => return Err(log.error_at(i, format!("a mode below {n} and its intensity in the `Int` column"))),
                }
                i += 1;
            }
        }
    }
    let atoms = n / 3;
    let geometry_at = (0..modes_at).rev().find(|&k| log.lines[k].trim() == "CARTESIAN COORDINATES (A.U.)");
    let Some(geometry_at) = geometry_at else {
        return Err(log.error_at(modes_at, "a `CARTESIAN COORDINATES (A.U.)` table before the normal modes"));
    };
    let (geometry, _) = coordinates(log, geometry_at)?;
    if geometry.z.len() != atoms {
        return Err(log.error_at(
            freq_at,
            format!(
                "three frequencies for each of the {} atoms of the geometry at line {}",
                geometry.z.len(),
                geometry_at + 1
            ),
        ));
    }
    // Translations and rotations: the leading modes ORCA sets to exactly zero.
    let skip = frequencies.iter().take(6).take_while(|&&f| f == 0.0).count();
    let modes = (skip..n)
        .map(|m| NormalMode {
            frequency_cm1: frequencies[m],
            ir_intensity: intensities[m],
            displacement: columns[m].chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect(),
        })
        .collect();
    Ok(Some(Vibrations {
        modes,
        geometry: geometry.positions,
        geometry_from: format!("the coordinates at line {}", geometry_at + 1),
    }))
}

#[cfg(test)]
#[path = "orca_log_tests.rs"]
mod tests;
