//! Program logs (`.log`, `.out`): many programs write files with these endings, so the program
//! is told from the text, not the name. Gaussian prints "Entering Gaussian System" and its
//! copyright ("Gaussian, Inc.") at the top; ORCA its banner "O   R   C   A"; Q-Chem "Welcome to
//! Q-Chem" and "Q-Chem, Inc."; GAMESS-US "GAMESS VERSION"; NWChem "Northwest Computational
//! Chemistry Package"; Psi4 "Psi4: An Open-Source Ab Initio Electronic Structure Package".
//!
//! What the readers of logs share: the lines with their numbers, numbers in fixed-width
//! columns, and the errors they raise.

use glam::DVec3;

use super::text::{excerpt, parse_real};
use super::wavefunction::OverlapFn;
use super::{ParseError, gamess_log, gaussian_log, nwchem_log, orca_log, psi4_log, qchem_log};
use crate::model::scan::{Coordinate, JobScan};
use crate::model::{Atom, Document, Molecule};

/// Lines of the file's top in which the program's banner is looked for: a job scheduler may
/// write a few lines first, and the banners sit within the first hundred lines.
const BANNER_LINES: usize = 500;

/// The programs whose logs orbcloud reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Program {
    Gaussian,
    Orca,
    QChem,
    Gamess,
    NwChem,
    Psi4,
}

/// The program that wrote `text`, from its banner.
pub fn program(text: &str) -> Option<Program> {
    for line in text.lines().take(BANNER_LINES) {
        if line.contains("Entering Gaussian System") || line.contains("Gaussian, Inc.") {
            return Some(Program::Gaussian);
        }
        if line.contains("O   R   C   A") {
            return Some(Program::Orca);
        }
        if line.contains("Welcome to Q-Chem") || line.contains("Q-Chem, Inc.") {
            return Some(Program::QChem);
        }
        if line.contains("GAMESS VERSION =") {
            return Some(Program::Gamess);
        }
        if line.contains("Northwest Computational Chemistry Package") {
            return Some(Program::NwChem);
        }
        if line.contains("Psi4: An Open-Source Ab Initio Electronic Structure Package") {
            return Some(Program::Psi4);
        }
    }
    None
}

/// What the banner check looks for, in words.
pub const BANNERS: &str = "a Gaussian log (\"Entering Gaussian System\" or \"Gaussian, Inc.\"), an ORCA output (\"O   R   C   A\"), a Q-Chem output (\"Welcome to Q-Chem\"), a GAMESS-US output (\"GAMESS VERSION =\"), an NWChem output (\"Northwest Computational Chemistry Package\") or a Psi4 output (\"Psi4: An Open-Source Ab Initio Electronic Structure Package\")";

/// Parses a program's log into a document, the program told by its banner.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    if text.trim().is_empty() {
        return Err(error(file, 1, BANNERS, "an empty file"));
    }
    match program(text) {
        Some(Program::Gaussian) => gaussian_log::parse(file, text, overlap),
        Some(Program::Orca) => orca_log::parse(file, text, overlap),
        Some(Program::QChem) => qchem_log::parse(file, text, overlap),
        Some(Program::Gamess) => gamess_log::parse(file, text, overlap),
        Some(Program::NwChem) => nwchem_log::parse(file, text, overlap),
        Some(Program::Psi4) => psi4_log::parse(file, text, overlap),
        None => Err(error(
            file,
            1,
            BANNERS,
            format!("no banner in the first {BANNER_LINES} lines (another program's output?)"),
        )),
    }
}

pub(crate) fn error(file: &str, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
    ParseError { file: file.to_string(), line, expected: expected.into(), found: found.into() }
}

/// The lines of a log, each with its 1-based number, for readers that look back and forth.
pub(crate) struct LogLines<'a> {
    pub file: &'a str,
    pub lines: Vec<&'a str>,
}

impl<'a> LogLines<'a> {
    pub fn new(file: &'a str, text: &'a str) -> Self {
        Self { file, lines: text.lines().collect() }
    }

    /// Line `i` (0-based), or an error at the end of the file saying what was expected.
    pub fn get(&self, i: usize, expected: &str) -> Result<&'a str, ParseError> {
        self.lines.get(i).copied().ok_or_else(|| error(self.file, self.lines.len().max(1), expected, "end of file"))
    }

    /// An error at line `i` (0-based), quoting it.
    pub fn error_at(&self, i: usize, expected: impl Into<String>) -> ParseError {
        let found = self.lines.get(i).map_or_else(|| "end of file".to_string(), |l| excerpt(l));
        error(self.file, (i + 1).min(self.lines.len().max(1)), expected, found)
    }

    /// Checks that an orbital block (orbitals `first`–`last`, its header at line index
    /// `block`) read `rows` rows of coefficients, as many as the first block when `before` is
    /// its count; the error names line index `i`, where the block stopped.
    pub fn block_rows(
        &self,
        i: usize,
        rows: usize,
        before: Option<usize>,
        (first, last): (impl std::fmt::Display, impl std::fmt::Display),
        block: usize,
    ) -> Result<(), ParseError> {
        if rows > 0 && before.is_none_or(|n| rows == n) {
            return Ok(());
        }
        let want = before.map_or_else(|| "one or more".to_string(), |n| n.to_string());
        Err(self.error_at(
            i,
            format!("{want} rows of coefficients for orbitals {first}–{last} (block at line {})", block + 1),
        ))
    }
}

/// The last `count` numbers of `line`, printed in fields `width` characters wide (Fortran's
/// `F10.5`, which may run two numbers together) or, where the fields do not parse, separated by
/// blanks. `None` when the line does not end in that many numbers.
pub(crate) fn trailing_numbers(line: &str, count: usize, width: usize) -> Option<(Vec<f64>, &str)> {
    let line = line.trim_end();
    let span = count.checked_mul(width)?;
    if line.len() >= span && line.is_char_boundary(line.len() - span) {
        let (head, fields) = line.split_at(line.len() - span);
        let parsed: Option<Vec<f64>> =
            (0..count).map(|k| fields.get(k * width..(k + 1) * width).and_then(|f| parse_real(f.trim()))).collect();
        if let Some(values) = parsed {
            return Some((values, head));
        }
    }
    let tokens: Vec<&str> = line.split_whitespace().collect();
    let first = tokens.len().checked_sub(count)?;
    let values: Option<Vec<f64>> = tokens[first..].iter().map(|t| parse_real(t)).collect();
    let head_len = tokens[first..].first().map_or(line.len(), |t| t.as_ptr() as usize - line.as_ptr() as usize);
    Some((values?, &line[..head_len]))
}

/// One geometry a log prints: its header's 0-based line, atomic numbers and positions (bohr).
#[derive(Debug, Clone)]
pub(crate) struct Geometry {
    pub line: usize,
    pub z: Vec<u32>,
    pub positions: Vec<DVec3>,
}

fn same_geometry(a: &Geometry, b: &Geometry) -> bool {
    a.z == b.z && a.positions.iter().zip(&b.positions).all(|(p, q)| p.distance(*q) < 1e-5)
}

/// The frames of a series (an optimisation's, a scan's, an IRC's steps): each geometry with the
/// first energy printed after it and before the next; a geometry printed again unchanged, without
/// an energy or with the same one (the converged one, printed or evaluated once more at the end),
/// is no new frame, nor is one printed first without its energy and then again with it.
pub(crate) fn frames<'a>(all: &'a [Geometry], energies: &[(usize, f64)]) -> Vec<(&'a Geometry, Option<f64>)> {
    let mut out: Vec<(&Geometry, Option<f64>)> = Vec::new();
    for (k, g) in all.iter().enumerate() {
        let end = all.get(k + 1).map_or(usize::MAX, |n| n.line);
        let energy = energies.iter().find(|(l, _)| *l > g.line && *l < end).map(|e| e.1);
        if let Some((last, last_energy)) = out.last_mut()
            && same_geometry(last, g)
        {
            if energy.is_none() || energy == *last_energy {
                continue;
            }
            if last_energy.is_none() {
                // Printed first without its energy (an optimiser's next step, the input echo).
                *last_energy = energy;
                continue;
            }
        }
        out.push((g, energy));
    }
    out
}

/// The document of a log without orbitals: every frame as a model, its energy kept with it.
pub(crate) fn trajectory(file: &str, title: &str, frames: &[(&Geometry, Option<f64>)]) -> Document {
    let z: Vec<u8> = frames.first().map(|f| f.0.z.iter().map(|&z| z as u8).collect()).unwrap_or_default();
    let named: Vec<(String, Vec<DVec3>)> = frames
        .iter()
        .enumerate()
        .map(|(k, (g, e))| {
            let name = match e {
                Some(e) => format!("step {}: E = {e:.9} Eh (line {})", k + 1, g.line + 1),
                None => format!("step {} (line {})", k + 1, g.line + 1),
            };
            (name, g.positions.clone())
        })
        .collect();
    let mut doc = super::structure::trajectory(file, title, &z, &named);
    if let Some(view) = doc.structure.as_mut() {
        for (model, (_, e)) in view.structure.models.iter_mut().zip(frames) {
            model.energy = *e;
        }
    }
    doc
}

/// A scan job's coordinate measured at each of its `frames` (one per point, the point's converged
/// geometry), the coordinate named at 0-based line `line` of the job's echoed input (`text`, as
/// the job wrote it): what the Gaussian and ORCA readers share. `points` is the number of points the job asked for; a log cut
/// off before its last says how many it holds. An error when the coordinate names an atom
/// beyond the molecule's.
pub(crate) fn job_scan(
    log: &LogLines,
    line: usize,
    text: &str,
    coordinate: Coordinate,
    points: usize,
    frames: &[(&Geometry, Option<f64>)],
) -> Result<JobScan, ParseError> {
    let molecules: Vec<Molecule> = frames
        .iter()
        .map(|(g, _)| Molecule {
            atoms: g
                .z
                .iter()
                .zip(&g.positions)
                .map(|(&z, &position)| Atom { z, charge: z as f64, position, ghost: false })
                .collect(),
            bonds: Vec::new(),
        })
        .collect();
    let from = format!("line {}: {}", line + 1, text.split_whitespace().collect::<Vec<_>>().join(" "));
    let atoms = frames.first().map_or(0, |f| f.0.z.len());
    let mut scan = JobScan::measured(coordinate, &molecules, from)
        .ok_or_else(|| log.error_at(line, format!("atoms among the {atoms} of the molecule")))?;
    if scan.values.len() < points {
        scan.from += &format!(" ({} of its {} points)", scan.values.len(), points);
    }
    Ok(scan)
}

/// Digits after the decimal point of a printed number ("-0.02805" → 5).
pub(crate) fn decimals(token: &str) -> Option<u32> {
    let (_, frac) = token.split_once('.')?;
    let digits = frac.chars().take_while(char::is_ascii_digit).count();
    u32::try_from(digits).ok()
}

/// Notes in `doc`'s problems that a log of `frames` geometries opens at one: a document with
/// orbitals shows the geometry they belong to (printed at 0-based `line`).
pub(crate) fn note_one_geometry(doc: &mut Document, file: &str, frames: usize, line: usize) {
    if frames > 1 {
        doc.problems.push(format!(
            "{file}: its {frames} geometries are not shown: the orbitals open at the one they belong to (line {})",
            line + 1
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_geometry_repeated_without_a_new_energy_is_no_new_frame() {
        let g = |line, x| Geometry { line, z: vec![1], positions: vec![DVec3::new(x, 0.0, 0.0)] };
        let all = [g(0, 0.0), g(10, 0.5), g(20, 0.5), g(30, 0.5), g(40, 0.5)];
        // Energies after lines 0, 10 and 20 (the same value twice), then 40 (a new one).
        let energies = [(5, -1.0), (15, -1.5), (25, -1.5), (45, -1.6)];
        let kept: Vec<(usize, Option<f64>)> = frames(&all, &energies).iter().map(|(g, e)| (g.line, *e)).collect();
        assert_eq!(kept, vec![(0, Some(-1.0)), (10, Some(-1.5)), (40, Some(-1.6))]);
        // An optimiser's next geometry, printed again by the SCF that gives its energy.
        let all = [g(0, 0.0), g(10, 0.5), g(20, 0.5)];
        let energies = [(5, -1.0), (25, -1.5)];
        let kept: Vec<(usize, Option<f64>)> = frames(&all, &energies).iter().map(|(g, e)| (g.line, *e)).collect();
        assert_eq!(kept, vec![(0, Some(-1.0)), (10, Some(-1.5))]);
    }

    #[test]
    fn programs_are_told_by_their_banner() {
        assert_eq!(program(" Entering Gaussian System, Link 0=g16\n"), Some(Program::Gaussian));
        assert_eq!(program("\n  * O   R   C   A *\n"), Some(Program::Orca));
        assert_eq!(program(" *  GAMESS VERSION = 30 SEP 2017 (R1)  *\n"), Some(Program::Gamess));
        assert_eq!(program(" Northwest Computational Chemistry Package (NWChem) 6.5\n"), Some(Program::NwChem));
        assert_eq!(program("  Psi4: An Open-Source Ab Initio Electronic Structure Package\n"), Some(Program::Psi4));
        assert_eq!(program(" Molpro calculation\n"), None);
        let e = parse("x.out", " NWChem Input Module\n", None).unwrap_err();
        assert_eq!(e.line, 1);
        assert!(e.expected.contains("Entering Gaussian System") && e.expected.contains("O   R   C   A"), "{e}");
        assert!(e.to_string().starts_with("x.out:1:"), "{e}");
    }

    #[test]
    fn fixed_width_numbers_run_together_or_stand_apart() {
        let (v, head) = trailing_numbers("   1 1   C  1S        -10.12345-100.12345", 2, 10).unwrap();
        assert_eq!(v, vec![-10.12345, -100.12345]);
        assert_eq!(head.trim(), "1 1   C  1S");
        let (v, head) = trailing_numbers("  2  2S  0.5 -0.25", 2, 10).unwrap();
        assert_eq!(v, vec![0.5, -0.25]);
        assert_eq!(head.trim(), "2  2S");
        assert!(trailing_numbers("  2  2S  0.5", 2, 10).is_none());
        assert_eq!(decimals("-0.02805"), Some(5));
    }
}
