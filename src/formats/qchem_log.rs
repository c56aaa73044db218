//! Q-Chem outputs: the geometries (`Standard Nuclear Orientation (Angstroms)`, one per step) as
//! frames, the basis (`print_general_basis = true`) and the orbitals (`print_orbitals = true`),
//! and the excited states of a TDDFT, TDA or CIS job ([`super::excited_logs::qchem`]).
//!
//! ```text
//! Basis set in general basis input format:
//! $basis
//! C    0                                                  one block per atom, in order
//! SP   3    1.000000                                      shell, primitives, scale
//!    2.94124940E+00   -9.99672300E-02   1.55916270E-01    exponent, s (and p) coefficients
//! ****
//!                         RESTRICTED (RHF) MOLECULAR ORBITAL COEFFICIENTS   (ALPHA …, BETA …)
//!                          1         2                      6 a block
//!  eigenvalues:        -10.018   -10.018                    energies (3 decimals)
//!    1  C 1   s       -0.69896   0.69891                    function, element and its count
//! ```
//! Rows name their atom by element and count within it (`H 1` is the first hydrogen), and their
//! function by its letters (`s`, `px`, `dxy`): cartesian functions in any order, mapped by their
//! letters. The contraction coefficients are for normalised primitives. Occupations follow the
//! numbers of alpha and beta electrons; Q-Chem prints the occupied and a few virtual orbitals.
//! Coefficients are printed to 5 decimals: the residual is measured and reported, never repaired.
//! Without the printed basis and orbitals a log opens as its atoms; the job's fchk file
//! (`GUI=2`) holds the orbitals.

use glam::DVec3;

use super::logs::{Geometry, LogLines, decimals, frames, trailing_numbers, trajectory};
use super::printed::column_numbers;
use super::printed::{self, Orbital, PrintedShell, Row, Section, aufbau, cartesian_index, pure_index};
use super::text::parse_real;
use super::wavefunction::OverlapFn;
use super::{MAX_Z, ParseError};
use crate::model::Document;
use crate::model::basis::{MAX_L, ShellKind};
use crate::model::elements::atomic_number;
use crate::model::orbitals::Spin;
use crate::model::units::BOHR_PER_ANGSTROM;

/// The `$rem` keywords that make Q-Chem print what the viewer needs to draw orbitals.
pub const ORBITAL_KEYWORDS: &str = "print_general_basis = true  print_orbitals = true";

/// Width of Q-Chem's coefficient columns.
const COLUMN: usize = 10;

/// Parses a Q-Chem output: its geometries as frames (with their `Total energy in the final
/// basis set`) or, when printed, its basis and orbitals (checked with `overlap`), and its excited
/// states.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    let log = LogLines::new(file, text);
    let mut geometries = Vec::new();
    let mut doc = read(&log, overlap, &mut geometries)?;
    super::log_modes::attach(&mut doc, super::log_modes::qchem(&log, &geometries));
    Ok(doc)
}

/// The document of `log` without its normal modes; `geometries` receives every geometry printed.
fn read(log: &LogLines, overlap: Option<OverlapFn>, geometries: &mut Vec<Geometry>) -> Result<Document, ParseError> {
    let file = log.file;
    let mut energies = Vec::new();
    let mut electrons = None;
    let mut basis: Option<(usize, Vec<Vec<PrintedShell>>)> = None;
    let mut sections: Vec<(Spin, Section)> = Vec::new();
    let mut i = 0;
    while i < log.lines.len() {
        let t = log.lines[i].trim();
        if t.starts_with("Standard Nuclear Orientation") {
            let (g, next) = orientation(log, i)?;
            geometries.push(g);
            i = next;
            continue;
        }
        if t.starts_with("Basis set in general basis input format") {
            let (b, next) = general_basis(log, i)?;
            basis = Some((i, b));
            i = next;
            continue;
        }
        if t.ends_with("MOLECULAR ORBITAL COEFFICIENTS") {
            let spin = if t.starts_with("BETA") { Spin::Beta } else { Spin::Alpha };
            let (section, next) = coefficients(log, i)?;
            if spin == Spin::Alpha {
                sections.clear();
            }
            sections.retain(|s| s.0 != spin);
            sections.push((spin, section));
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
    let frames = frames(geometries, &energies);
    if frames.is_empty() {
        return Err(log.error_at(log.lines.len(), "a `Standard Nuclear Orientation (Angstroms)` table"));
    }
    let mut doc = match (sections.first(), &basis) {
        (Some((_, first)), Some((_, shells))) => {
            let k = geometries.iter().rposition(|g| g.line < first.line).unwrap_or(geometries.len() - 1);
            let geometry = &geometries[k];
            let Some(counts) = electrons else {
                return Err(log.error_at(first.line, "`There are n alpha and m beta electrons` before the orbitals"));
            };
            let restricted = sections.len() == 1;
            let mut section = Section { line: first.line, decimals: first.decimals, ..Default::default() };
            for (spin, s) in &sections {
                if !section.rows.is_empty() && s.rows.len() != section.rows.len() {
                    return Err(log.error_at(
                        s.line,
                        format!("{} rows of coefficients, as the alpha orbitals", section.rows.len()),
                    ));
                }
                section.rows.clone_from(&s.rows);
                for (k, o) in s.orbitals.iter().enumerate() {
                    section.orbitals.push(Orbital {
                        occupation: aufbau(k, *spin, restricted, counts),
                        spin: *spin,
                        ..o.clone()
                    });
                }
            }
            // Rows name atoms by element and count: `H 2` is the second hydrogen.
            let mut seen = std::collections::HashMap::new();
            let names: Vec<String> = geometry
                .z
                .iter()
                .map(|&z| {
                    let n = seen.entry(z).or_insert(0);
                    *n += 1;
                    format!(
                        "{}{}",
                        crate::model::elements::ELEMENTS.get(z as usize).map_or("X", |e| e.symbol).to_ascii_uppercase(),
                        n
                    )
                })
                .collect();
            for row in &mut section.rows {
                let (name, label) = row.label.split_once(' ').unwrap_or_default();
                let Some(a) = names.iter().position(|n| n == name) else {
                    return Err(
                        log.error_at(row.line, format!("an atom of the orientation (element and count), not {name}"))
                    );
                };
                row.atom = a;
                row.label = label.to_string();
            }
            if shells.len() != geometry.z.len() {
                let line = basis.as_ref().map_or(first.line, |b| b.0);
                return Err(log.error_at(
                    line,
                    format!("{} atoms in the printed basis set, as in the orientation", geometry.z.len()),
                ));
            }
            let mut doc = printed::document(log, "Q-Chem", geometry, shells, &section, &function_of, overlap)?;
            super::logs::note_one_geometry(&mut doc, file, frames.len(), geometry.line);
            doc
        }
        (first, basis) => {
            let why = match (first, basis) {
                (None, None) => format!(
                    "the output prints neither the basis set nor the orbitals (add `{ORBITAL_KEYWORDS}` to $rem, or open the job's fchk file, `GUI=2`)"
                ),
                (None, Some(_)) => {
                    "the output prints the basis set but not the orbitals (add `print_orbitals = true` to $rem)"
                        .to_string()
                }
                _ => "the output prints the orbitals but not the basis set (add `print_general_basis = true` to $rem)"
                    .to_string(),
            };
            let mut doc = trajectory(file, file, &frames);
            doc.problems.push(format!("{file}: no orbitals to draw: {why}"));
            doc
        }
    };
    if let Some(occupied) = electrons {
        // A malformed table leaves the states out, not the file.
        match super::excited_logs::qchem(log, occupied) {
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

/// A row's function label: `s`, `px`, cartesian `dxy`, `fxyz` by their letters, pure `d 1` …
/// `d 5` (read `d1`) in Q-Chem's order m = −l … +l.
fn function_of(label: &str, l: u32) -> Option<(ShellKind, usize)> {
    let label = label.to_ascii_lowercase();
    let rest = label.strip_prefix(printed::letter(l))?;
    if l == 0 {
        return rest.is_empty().then_some((ShellKind::Cartesian, 0));
    }
    if let Some(i) = cartesian_index(rest, l) {
        return Some((ShellKind::Cartesian, i));
    }
    let k: usize = rest.parse().ok()?;
    (l >= 2 && (1..=2 * l as usize + 1).contains(&k)).then(|| (ShellKind::Pure, pure_index(k as i32 - 1 - l as i32)))
}

/// `Basis set in general basis input format:` at `header`: dashes, `$basis`, per atom in order
/// `C    0`, shells `S|SP|P|D…  primitives  scale` with their primitives, `****`; `$end`.
fn general_basis(log: &LogLines, header: usize) -> Result<(Vec<Vec<PrintedShell>>, usize), ParseError> {
    let mut i = header + 1;
    while log.get(i, "`$basis`")?.trim().starts_with("---") {
        i += 1;
    }
    if !log.lines[i].trim().eq_ignore_ascii_case("$basis") {
        return Err(log.error_at(i, "`$basis`"));
    }
    i += 1;
    let mut atoms = Vec::new();
    loop {
        let l = log.get(i, "an atom `C    0` or `$end`")?;
        let t: Vec<&str> = l.split_whitespace().collect();
        if t.first().is_some_and(|w| w.eq_ignore_ascii_case("$end")) {
            i += 1;
            break;
        }
        if t.len() != 2 || t[1] != "0" {
            return Err(log.error_at(i, "an atom `C    0` or `$end`"));
        }
        i += 1;
        let mut shells = Vec::new();
        loop {
            let l = log.get(i, "a shell `S 3 1.000000` or `****`")?;
            let t: Vec<&str> = l.split_whitespace().collect();
            if t.first() == Some(&"****") {
                i += 1;
                break;
            }
            let shell = "a shell `S|SP|P|D|F|G|H  primitives  scale` or `****`";
            let kind = t.first().map(|k| k.to_ascii_uppercase()).unwrap_or_default();
            let ls: Vec<u32> = if kind == "SP" {
                vec![0, 1]
            } else {
                let l = (kind.len() == 1).then(|| "SPDFGH".find(kind.as_str())).flatten().map(|l| l as u32);
                vec![l.filter(|&l| l <= MAX_L).ok_or_else(|| log.error_at(i, shell))?]
            };
            let count: usize =
                t.get(1).and_then(|n| n.parse().ok()).filter(|&n| n > 0).ok_or_else(|| log.error_at(i, shell))?;
            let scale = t.get(2).and_then(|s| parse_real(s)).unwrap_or(1.0);
            let mut printed: Vec<PrintedShell> =
                ls.iter().map(|&l| PrintedShell { l, exponents: Vec::new(), coefficients: Vec::new() }).collect();
            for _ in 0..count {
                i += 1;
                let expected = "a primitive `exponent coefficient(s)`";
                let v: Option<Vec<f64>> = log.get(i, expected)?.split_whitespace().map(parse_real).collect();
                let v = v.filter(|v| v.len() == 1 + ls.len() && v[0] > 0.0).ok_or_else(|| log.error_at(i, expected))?;
                for (k, p) in printed.iter_mut().enumerate() {
                    p.exponents.push(v[0] * scale * scale);
                    p.coefficients.push(v[1 + k]);
                }
            }
            shells.extend(printed);
            i += 1;
        }
        atoms.push(shells);
    }
    if atoms.is_empty() {
        return Err(log.error_at(i, "an atom's shells in the basis set"));
    }
    Ok((atoms, i))
}

/// `… MOLECULAR ORBITAL COEFFICIENTS` at `header`: blocks of up to 6 orbitals — their numbers,
/// `eigenvalues:`, rows `n  C 1   px  coefficients` — until a line that opens no block. Each
/// row's label is kept as `C1 px` (element and count, function) until the atoms are known.
fn coefficients(log: &LogLines, header: usize) -> Result<(Section, usize), ParseError> {
    let mut section = Section { line: header, ..Default::default() };
    let mut first_decimals = None;
    let mut i = header + 1;
    while let Some(numbers) = log.lines.get(i).and_then(|l| column_numbers(l)) {
        if numbers[0] != section.orbitals.len() + 1 {
            break;
        }
        let block = i;
        let k = numbers.len();
        let l = log.get(i + 1, "`eigenvalues:` and the orbitals' energies")?;
        let energies: Option<Vec<f64>> =
            l.trim_start().strip_prefix("eigenvalues:").and_then(|r| r.split_whitespace().map(parse_real).collect());
        let energies = energies
            .filter(|e| e.len() == k)
            .ok_or_else(|| log.error_at(i + 1, format!("`eigenvalues:` and {k} orbital energies")))?;
        i += 2;
        let first_block = section.orbitals.is_empty();
        let mut columns: Vec<Vec<f64>> = vec![Vec::new(); k];
        let mut row = 0;
        while let Some(l) = log.lines.get(i) {
            let Some((values, head)) = trailing_numbers(l, k, COLUMN) else { break };
            let t: Vec<&str> = head.split_whitespace().collect();
            if t.first().and_then(|n| n.parse::<usize>().ok()) != Some(row + 1) || t.len() < 3 {
                break;
            }
            // `C 1 px`, `C 12 dxy`, `C12 dxy`, `C  d 1` (a pure function, the element's only
            // atom): the element and its count, then the function from its lower-case letter.
            let function = t[2..].iter().position(|w| w.starts_with(|c: char| c.is_ascii_lowercase())).map(|k| k + 2);
            let Some(function) = function else { break };
            let mut name: String = t[1..function].concat().to_ascii_uppercase();
            if !name.ends_with(|c: char| c.is_ascii_digit()) {
                name.push('1');
            }
            let label = format!("{name} {}", t[function..].concat());
            if first_decimals.is_none() {
                first_decimals = l.split_whitespace().last().and_then(decimals);
            }
            section.take_row(log, (header, row, first_block), Row { line: i, atom: 0, label }, values, &mut columns)?;
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
                symmetry: String::new(),
                coefficients,
            });
        }
    }
    if section.orbitals.is_empty() {
        return Err(log.error_at(i, "a block of orbitals: their numbers `1 2 3 4 5 6`"));
    }
    section.decimals = first_decimals.unwrap_or(5);
    Ok((section, i))
}

#[cfg(test)]
mod tests {
    use super::super::ref_overlap::reference_overlap;
    use super::*;

    const H2: &str = include_str!("../../tests/fixtures/logs/h2_qchem.out");

    fn read(text: &str) -> Result<Document, ParseError> {
        parse("h2.out", text, Some(&reference_overlap))
    }

    #[test]
    fn the_printed_basis_and_orbitals_open_with_occupations_from_the_electrons() {
        let doc = read(H2).unwrap();
        let wf = doc.wavefunction.as_ref().expect("orbitals");
        assert_eq!((wf.basis.shells.len(), wf.orbitals.len()), (2, 2));
        assert_eq!([wf.orbitals[0].occupation, wf.orbitals[1].occupation], [2.0, 0.0]);
        assert_eq!([wf.orbitals[0].energy, wf.orbitals[1].energy], [-0.579, 0.671]);
        let n = &wf.normalization;
        assert_eq!((n.program.as_str(), n.printed_decimals), ("Q-Chem", Some(5)));
        assert!(n.residual < n.expected_residual(), "{n:?}");
    }

    #[test]
    fn labels_name_cartesian_functions_by_their_letters() {
        assert_eq!(function_of("s", 0), Some((ShellKind::Cartesian, 0)));
        assert_eq!(function_of("pz", 1), Some((ShellKind::Cartesian, 2)));
        assert_eq!(function_of("dyy", 2), Some((ShellKind::Cartesian, 3)));
        assert_eq!(function_of("dxz", 2), Some((ShellKind::Cartesian, 2)));
        assert_eq!(function_of("px", 2), None);
        // Pure `d 1` … `d 5`: m = −2 … +2.
        assert_eq!(function_of("d1", 2), Some((ShellKind::Pure, 4)));
        assert_eq!(function_of("d3", 2), Some((ShellKind::Pure, 0)));
        assert_eq!(function_of("f7", 3), Some((ShellKind::Pure, 5)));
        assert_eq!(function_of("d6", 2), None);
    }

    #[test]
    fn an_orbital_block_cut_short_is_refused_at_its_line() {
        let end = H2.find("   2  H 2   s").unwrap();
        let e = read(&H2[..end]).unwrap_err();
        assert!(e.expected.contains("rows of coefficients"), "{e}");
        assert!(e.to_string().starts_with("h2.out:"), "{e}");
        let bad = H2.replacen("   2  H 2   s", "   2  H 3   s", 1);
        let e = read(&bad).unwrap_err();
        assert_eq!(e.line, bad.lines().position(|l| l.starts_with("   2  H 3   s")).unwrap() + 1, "{e}");
        assert!(e.expected.contains("an atom of the orientation"), "{e}");
        let bad = H2.replacen("****\n$end", "****\nH    0\nS    3    1.000000\n   3.4E+00    1.5E-01 \n", 1);
        let e = read(&bad).unwrap_err();
        assert!(e.expected.contains("primitive"), "{e}");
    }

    #[test]
    fn without_printed_orbitals_the_atoms_open_naming_the_keywords() {
        let cut = &H2[..H2.find("                        RESTRICTED (RHF)").unwrap()];
        let doc = read(cut).unwrap();
        assert!(doc.wavefunction.is_none());
        assert!(doc.problems.iter().any(|p| p.contains("print_orbitals = true")), "{:?}", doc.problems);
    }
}
