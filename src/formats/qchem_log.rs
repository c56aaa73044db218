//! Q-Chem outputs: the geometries (`Standard Nuclear Orientation (Angstroms)`, one per step) as
//! frames, and the excited states of a TDDFT, TDA or CIS job ([`super::excited_logs::qchem`]).
//! Q-Chem prints neither the basis nor the orbitals by default (and this reader reads neither), so a
//! log opens as its atoms; the job's fchk file holds the orbitals.

use glam::DVec3;

use super::logs::{Geometry, LogLines, frames, trajectory};
use super::text::parse_real;
use super::{MAX_Z, ParseError};
use crate::model::Document;
use crate::model::elements::atomic_number;
use crate::model::units::BOHR_PER_ANGSTROM;

/// Parses a Q-Chem output: its geometries as frames (with their `Total energy in the final
/// basis set`), and its excited states.
pub fn parse(file: &str, text: &str) -> Result<Document, ParseError> {
    let log = LogLines::new(file, text);
    let mut geometries = Vec::new();
    let mut energies = Vec::new();
    let mut electrons = None;
    let mut i = 0;
    while i < log.lines.len() {
        let t = log.lines[i].trim();
        if t.starts_with("Standard Nuclear Orientation") {
            let (g, next) = orientation(&log, i)?;
            geometries.push(g);
            i = next;
            continue;
        }
        if t.starts_with("Total energy in the final basis set")
            && let Some(e) = t.rsplit('=').next().and_then(|v| parse_real(v.trim()))
        {
            energies.push((i, e));
        }
        if let Some(rest) = t.strip_prefix("There are")
            && t.contains("alpha and")
            && t.ends_with("beta electrons")
        {
            let n: Vec<usize> = rest.split_whitespace().filter_map(|w| w.parse().ok()).collect();
            if let [a, b] = n[..] {
                electrons = Some((a, b));
            }
        }
        i += 1;
    }
    let frames = frames(&geometries, &energies);
    if frames.is_empty() {
        return Err(log.error_at(log.lines.len(), "a `Standard Nuclear Orientation (Angstroms)` table"));
    }
    let mut doc = trajectory(file, file, &frames);
    doc.problems.push(format!(
        "{file}: no orbitals to draw: a Q-Chem output is read for its geometries and excited states only (the job's fchk file, `GUI=2`, holds the orbitals)"
    ));
    if let Some(occupied) = electrons {
        // A malformed table leaves the states out, not the file.
        match super::excited_logs::qchem(&log, occupied) {
            Ok(states) => doc.excited = states,
            Err(e) => doc.problems.push(format!("excited states left out: {e}")),
        }
    }
    Ok(doc)
}

/// `Standard Nuclear Orientation (Angstroms)` at `header`: a heading `I Atom X Y Z`, dashes,
/// rows `n symbol x y z` (Å), dashes.
fn orientation(log: &LogLines, header: usize) -> Result<(Geometry, usize), ParseError> {
    let mut i = header + 1;
    let heading = "the heading `I  Atom  X  Y  Z`";
    if !log.get(i, heading)?.trim_start().starts_with('I') {
        return Err(log.error_at(i, heading));
    }
    i += 1;
    while log.get(i, "the atom rows")?.trim().starts_with("---") {
        i += 1;
    }
    let mut g = Geometry { line: header, z: Vec::new(), positions: Vec::new() };
    while let Some(l) = log.lines.get(i).filter(|l| !l.trim().starts_with("---") && !l.trim().is_empty()) {
        let t: Vec<&str> = l.split_whitespace().collect();
        let row = "an atom row `n symbol x y z` (Å)";
        if t.len() != 5 {
            return Err(log.error_at(i, row));
        }
        let symbol = t[1].trim_end_matches(|c: char| !c.is_ascii_alphabetic());
        let z = atomic_number(symbol)
            .filter(|&z| z <= MAX_Z)
            .ok_or_else(|| log.error_at(i, "an element symbol in the Atom column"))?;
        let xyz: Option<Vec<f64>> = t[2..].iter().map(|v| parse_real(v)).collect();
        let xyz = xyz.ok_or_else(|| log.error_at(i, row))?;
        g.z.push(z);
        g.positions.push(DVec3::new(xyz[0], xyz[1], xyz[2]) * BOHR_PER_ANGSTROM);
        i += 1;
    }
    if g.z.is_empty() {
        return Err(log.error_at(i, "at least one atom row in the orientation table"));
    }
    Ok((g, i))
}
