//! Molekel files (`.mkl`) as ORCA's `orca_2mkl -mkl` (and MOKIT) write them (GUIDE §9).
//!
//! ```text
//! $MKL
//! # comments                       ORCA names itself here
//! $CHAR_MULT                       charge multiplicity
//! $COORD                           `Z x y z` per atom, Å
//! $CHARGES                         (skipped)
//! $BASIS                           per atom its shells, atoms separated by `$$`; a shell is a
//!  5 D 1.0                         header `nfunctions L scale` (1 S, 3 P, 5 D, 7 F, 9 G, 11 H pure;
//!   exponent coefficient           6 D, 10 F, 15 G cartesian), then its primitives
//! $COEFF_ALPHA                     blocks of up to 5 orbitals: a line of symmetry labels, a line
//!  a1g a1g …                       of energies, then one row per basis function
//! $OCC_ALPHA                       one occupation per orbital
//! $COEFF_BETA, $OCC_BETA           unrestricted files only
//! ```
//! every section closed by `$END` (ORCA indents some: ` $END`). The file is Molden's data in
//! another layout, with Molden's conventions (pure functions m = 0, +1, −1, …, cartesian ones in
//! Molden's order) and ORCA's quirks (the primitive normalisation of the s, x, xy, xyz, xxyz
//! component folded into the contraction coefficients, opposite signs for f±3, g±3, g±4, as
//! MOKIT's `fch2mkl` and IOData's reader have it), so it is read into a [`MoldenFile`] and built
//! and repaired like one (see [`super::wavefunction`]).

use super::molden::{MoldenAtom, MoldenFile, MoldenOrbital, MoldenShell, PureTags};
use super::text::{excerpt, fortran_fields, parse_real};
use super::wavefunction::OverlapFn;
use super::{MAX_Z, ParseError};
use crate::model::Document;
use crate::model::basis::{MAX_L, n_cartesian};
use crate::model::elements::element;
use crate::model::orbitals::Spin;

/// Parses MKL text into a document, checking and repairing the orbitals with `overlap`.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    read(file, text)?.into_document(file, overlap)
}

fn error(file: &str, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
    ParseError { file: file.to_string(), line, expected: expected.into(), found: found.into() }
}

/// One `$NAME … $END` section: the line of its name and its lines with their numbers.
struct Section<'a> {
    name: String,
    line: usize,
    end: usize,
    body: Vec<(usize, &'a str)>,
}

/// The sections of the file and its comment text.
fn sections<'a>(file: &str, text: &'a str) -> Result<(Vec<Section<'a>>, String), ParseError> {
    let lines: Vec<&str> = text.lines().collect();
    let mut comments = Vec::new();
    let mut out = Vec::new();
    let mut seen_mkl = false;
    let mut open: Option<Section> = None;
    for (i, l) in lines.iter().enumerate() {
        let t = l.trim();
        let line = i + 1;
        if let Some(c) = t.strip_prefix('#') {
            comments.push(c.trim());
            continue;
        }
        if t.is_empty() {
            continue;
        }
        if !seen_mkl {
            if !t.eq_ignore_ascii_case("$MKL") {
                return Err(error(file, line, "an MKL file (a `$MKL` first line)", excerpt(t)));
            }
            seen_mkl = true;
            continue;
        }
        let is_end = t.eq_ignore_ascii_case("$END");
        match &mut open {
            Some(s) if is_end => {
                s.end = line;
                out.extend(open.take());
            }
            Some(s) if t.starts_with('$') && t != "$$" => {
                let expected = format!("the $END of ${} (line {})", s.name, s.line);
                return Err(error(file, line, expected, excerpt(t)));
            }
            Some(s) => s.body.push((line, *l)),
            None if t.starts_with('$') && !is_end && t != "$$" => {
                let name = t[1..].trim().to_ascii_uppercase();
                open = Some(Section { name, line, end: 0, body: Vec::new() });
            }
            None => return Err(error(file, line, "a section `$NAME`", excerpt(t))),
        }
    }
    if let Some(s) = open {
        return Err(error(
            file,
            lines.len().max(1),
            format!("the $END of ${} (line {})", s.name, s.line),
            "end of file",
        ));
    }
    if !seen_mkl {
        let found = if text.trim().is_empty() { "an empty file" } else { "no `$MKL` line" };
        return Err(error(file, lines.len().max(1), "an MKL file (a `$MKL` first line)", found));
    }
    let title = comments.into_iter().filter(|c| !c.is_empty()).collect::<Vec<_>>().join(" ");
    Ok((out, title))
}

/// The file as a [`MoldenFile`]: atoms (Å), shells, orbitals with their occupations.
pub fn read(file: &str, text: &str) -> Result<MoldenFile, ParseError> {
    let (sections, title) = sections(file, text)?;
    let find = |name: &str| sections.iter().find(|s| s.name == name);
    let eof = text.lines().count().max(1);
    let missing = |name: &str| error(file, eof, format!("a ${name} section"), "none in the file");
    for (i, s) in sections.iter().enumerate() {
        if let Some(first) = sections[..i].iter().find(|f| f.name == s.name) {
            return Err(error(
                file,
                s.line,
                format!("one ${} section", s.name),
                format!("a second (the first on line {})", first.line),
            ));
        }
    }
    if let Some(s) = find("CHAR_MULT") {
        let values: Vec<&str> = s.body.iter().flat_map(|(_, l)| l.split_whitespace()).collect();
        if values.len() != 2 || values.iter().any(|v| v.parse::<i64>().is_err()) {
            return Err(error(file, s.line, "`charge multiplicity` in $CHAR_MULT", values.join(" ")));
        }
    }
    let atoms = read_atoms(file, find("COORD").ok_or_else(|| missing("COORD"))?)?;
    let basis = find("BASIS").ok_or_else(|| missing("BASIS"))?;
    let (shells, pure, n_functions) = read_basis(file, basis)?;
    let alpha = find("COEFF_ALPHA").ok_or_else(|| missing("COEFF_ALPHA"))?;
    let mut orbitals = read_orbitals(file, alpha, n_functions, Spin::Alpha)?;
    set_occupations(file, find("OCC_ALPHA").ok_or_else(|| missing("OCC_ALPHA"))?, &mut orbitals)?;
    if let Some(beta) = find("COEFF_BETA") {
        let mut b = read_orbitals(file, beta, n_functions, Spin::Beta)?;
        set_occupations(file, find("OCC_BETA").ok_or_else(|| missing("OCC_BETA"))?, &mut b)?;
        orbitals.extend(b);
    }
    // ORCA writes "a1g" for every orbital of a calculation run without symmetry: one label
    // for all of them names nothing, and shown on each orbital it misleads.
    if orbitals.len() > 1 && orbitals.iter().all(|o| o.symmetry == orbitals[0].symmetry) {
        orbitals.iter_mut().for_each(|o| o.symmetry.clear());
    }
    Ok(MoldenFile { title, atoms, angstrom: true, shells, pure, orbitals, mo_line: alpha.line, ..Default::default() })
}

fn read_atoms(file: &str, s: &Section) -> Result<Vec<MoldenAtom>, ParseError> {
    let mut atoms = Vec::new();
    for &(line, l) in &s.body {
        let t = fortran_fields(l);
        let bad = || error(file, line, "an atom `Z x y z` (Å)", excerpt(l));
        if t.len() != 4 {
            return Err(bad());
        }
        let z: u32 = t[0].parse().map_err(|_| bad())?;
        if z > MAX_Z {
            return Err(error(file, line, format!("an atomic number 0..={MAX_Z} (0 for a ghost)"), t[0]));
        }
        let xyz: Vec<f64> = t[1..].iter().map(|v| parse_real(v)).collect::<Option<_>>().ok_or_else(bad)?;
        let name = if z == 0 { "X".to_string() } else { element(z).symbol.to_string() };
        atoms.push(MoldenAtom {
            name,
            index: atoms.len() as i64 + 1,
            charge: z as f64,
            position: [xyz[0], xyz[1], xyz[2]],
        });
    }
    if atoms.is_empty() {
        return Err(error(file, s.line, "at least one atom in $COORD", "none"));
    }
    Ok(atoms)
}

/// A shell header `nfunctions L [scale]` (the count and the letter in either order): (l, pure).
fn shell_header(tokens: &[&str]) -> Option<(u32, bool, f64)> {
    if !(2..=3).contains(&tokens.len()) {
        return None;
    }
    let letter = |t: &str| "SPDFGH".find(&t.to_ascii_uppercase()).filter(|_| t.len() == 1).map(|l| l as u32);
    let (l, n) = match (letter(tokens[0]), letter(tokens[1])) {
        (None, Some(l)) => (l, tokens[0].parse::<usize>().ok()?),
        (Some(l), None) => (l, tokens[1].parse::<usize>().ok()?),
        _ => return None,
    };
    let scale = match tokens.get(2) {
        Some(s) => parse_real(s).filter(|&v| v > 0.0)?,
        None => 1.0,
    };
    debug_assert!(l <= MAX_L);
    if n == 2 * l as usize + 1 {
        Some((l, l >= 2, scale))
    } else if n == n_cartesian(l) {
        Some((l, false, scale))
    } else {
        None
    }
}

const SHELL: &str = "a shell header `N L 1.0` (N functions: 1 S, 3 P, 5 or 6 D, 7 or 10 F, 9 or 15 G, 11 or 21 H), `$$` or a primitive `exponent coefficient`";

fn read_basis(file: &str, s: &Section) -> Result<(Vec<MoldenShell>, PureTags, usize), ParseError> {
    let mut shells: Vec<MoldenShell> = Vec::new();
    let mut atom = 1i64;
    let mut pure = PureTags::default();
    let mut kinds: [Option<(bool, usize)>; 3] = [None; 3];
    let mut n_functions = 0usize;
    // The header's scale multiplies the exponents' square roots, as in Molden.
    let mut scale = 1.0;
    for &(line, l) in &s.body {
        let t: Vec<&str> = l.split_whitespace().collect();
        if t == ["$$"] {
            atom += 1;
            continue;
        }
        if let Some((l_value, is_pure, shell_scale)) = shell_header(&t) {
            scale = shell_scale;
            // Molden's tags say pure or cartesian per l (g and h share one).
            if l_value >= 2 {
                let slot = (l_value as usize - 2).min(2);
                match kinds[slot] {
                    Some((p, first)) if p != is_pure => {
                        let expected = format!(
                            "shells of one kind per l (the first on line {first} is {})",
                            if p { "pure" } else { "cartesian" }
                        );
                        return Err(error(file, line, expected, excerpt(l)));
                    }
                    _ => kinds[slot] = Some((is_pure, line)),
                }
                match slot {
                    0 => pure.d = is_pure,
                    1 => pure.f = is_pure,
                    _ => pure.g = is_pure,
                }
            }
            n_functions += if is_pure || l_value < 2 { 2 * l_value as usize + 1 } else { n_cartesian(l_value) };
            shells.push(MoldenShell {
                atom,
                l: l_value,
                exponents: Vec::new(),
                coefficients: Vec::new(),
                sp_coefficients: None,
                line,
            });
            continue;
        }
        let numbers: Option<Vec<f64>> = (t.len() == 2).then(|| t.iter().map(|v| parse_real(v)).collect()).flatten();
        match (numbers, shells.last_mut()) {
            (Some(v), Some(shell)) if v[0] > 0.0 => {
                shell.exponents.push(v[0] * scale * scale);
                shell.coefficients.push(v[1]);
            }
            (Some(_), Some(_)) => return Err(error(file, line, "a positive exponent", excerpt(l))),
            _ => return Err(error(file, line, SHELL, excerpt(l))),
        }
    }
    if let Some(empty) = shells.iter().find(|s| s.exponents.is_empty()) {
        return Err(error(file, empty.line, "a shell with at least one primitive `exponent coefficient`", "none"));
    }
    if shells.is_empty() {
        return Err(error(file, s.line, "at least one shell in $BASIS", "none"));
    }
    Ok((shells, pure, n_functions))
}

/// The orbitals of a `$COEFF_…` section: blocks of a label line, an energy line and one row
/// per basis function, as many columns as labels.
fn read_orbitals(file: &str, s: &Section, n_functions: usize, spin: Spin) -> Result<Vec<MoldenOrbital>, ParseError> {
    let mut out: Vec<MoldenOrbital> = Vec::new();
    let mut rows = s.body.iter().filter(|(_, l)| !l.trim().is_empty());
    while let Some(&(label_line, labels)) = rows.next() {
        let labels: Vec<&str> = labels.split_whitespace().collect();
        let m = labels.len();
        let first = out.len();
        let block = format!("the orbitals {}–{} of the block on line {label_line}", first + 1, first + m);
        let Some(&(line, energies)) = rows.next() else {
            return Err(error(file, s.end, format!("a line of {m} energies for {block}"), "$END"));
        };
        let energies: Vec<f64> = fortran_fields(energies)
            .iter()
            .map(|v| parse_real(v))
            .collect::<Option<_>>()
            .filter(|v: &Vec<f64>| v.len() == m)
            .ok_or_else(|| error(file, line, format!("{m} energies for {block}"), excerpt(energies)))?;
        for (label, energy) in labels.iter().zip(energies) {
            out.push(MoldenOrbital {
                symmetry: label.to_string(),
                energy: Some(energy),
                spin,
                occupation: None,
                coefficients: Vec::new(),
                line: label_line,
            });
        }
        for row in 1..=n_functions {
            let Some(&(line, values)) = rows.next() else {
                return Err(error(
                    file,
                    s.end,
                    format!("{n_functions} coefficient rows for {block}"),
                    format!("$END after {}", row - 1),
                ));
            };
            let fields = fortran_fields(values);
            let parsed: Option<Vec<f64>> = fields.iter().map(|v| parse_real(v)).collect();
            match parsed {
                Some(v) if v.len() == m => {
                    for (o, c) in out[first..].iter_mut().zip(v) {
                        o.coefficients.push((row, c));
                    }
                }
                _ => {
                    let expected = format!("{m} coefficients of basis function {row} for {block}");
                    return Err(error(file, line, expected, excerpt(values)));
                }
            }
        }
    }
    if out.is_empty() {
        return Err(error(file, s.line, format!("orbitals in ${}", s.name), "none"));
    }
    Ok(out)
}

/// The occupations of a `$OCC_…` section, one per orbital read.
fn set_occupations(file: &str, s: &Section, orbitals: &mut [MoldenOrbital]) -> Result<(), ParseError> {
    let n = orbitals.len();
    let mut k = 0;
    for &(line, l) in &s.body {
        for v in fortran_fields(l) {
            let occupation =
                parse_real(v).ok_or_else(|| error(file, line, format!("an occupation in ${}", s.name), excerpt(v)))?;
            let o = orbitals
                .get_mut(k)
                .ok_or_else(|| error(file, line, format!("{n} occupations (one per orbital)"), "more"))?;
            o.occupation = Some(occupation);
            k += 1;
        }
    }
    if k != n {
        return Err(error(file, s.end, format!("{n} occupations in ${} (one per orbital)", s.name), format!("{k}")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::basis::ShellKind;

    /// H2 with an s shell per atom and a pure d shell on atom 1; 2 alpha orbitals, 2 beta.
    const H2: &str = "$MKL
#
# MKL format file produced by ORCA
#
$CHAR_MULT
  0 1
$END

$COORD
   1    0.000000   0.000000   0.000000
   1    0.000000   0.000000   0.740000
$END

$BASIS
 1 S 1.0
        3.425250910      0.276934361
        0.623913730      0.267838852
 5 D 1.0
        0.800000000      1.000000000
$$
 1 S 1.0
        3.425250910      0.276934361
        0.623913730      0.267838852
$END

$COEFF_ALPHA
 a1g  a1g
   -0.5902189     0.7006479
   0.5458586   -1.2462451
   0.0000000    0.0000000
   0.0000000    0.0000000
   0.0000000    0.0000000
   0.0000000    0.0000000
   0.0100000    0.0000000
   0.5458586    1.2462451
 $END

$OCC_ALPHA
   1.0000000    0.0000000
 $END
";

    fn doc(text: &str) -> Document {
        parse("t.mkl", text, None).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn restricted_and_unrestricted_files_read() {
        let d = doc(H2);
        assert!(d.title.contains("ORCA"));
        assert!((d.molecule.atoms[1].position.z - 0.74 * crate::model::units::BOHR_PER_ANGSTROM).abs() < 1e-12);
        let wf = d.wavefunction.expect("wf");
        assert!(wf.restricted);
        let kinds: Vec<(u32, ShellKind)> = wf.basis.shells.iter().map(|s| (s.l, s.kind)).collect();
        assert_eq!(kinds, [(0, ShellKind::Cartesian), (2, ShellKind::Pure), (0, ShellKind::Cartesian)]);
        assert_eq!(wf.orbitals.len(), 2);
        assert_eq!((wf.orbitals[0].energy, wf.orbitals[0].occupation), (-0.5902189, 1.0));
        assert_eq!(wf.normalization.program, "ORCA");
        let beta = H2.replace(" $END\n\n$OCC_ALPHA", " $END\n\n$COEFF_BETA\n a1g\n -0.5\n 0.5\n 0\n 0\n 0\n 0\n 0\n 0.5\n $END\n$OCC_BETA\n 1.0\n$END\n$OCC_ALPHA");
        let wf = doc(&beta).wavefunction.expect("wf");
        assert!(!wf.restricted);
        assert_eq!(wf.of_spin(Spin::Beta).count(), 1);
    }

    #[test]
    fn one_label_on_every_orbital_is_dropped_and_real_labels_kept() {
        let wf = doc(H2).wavefunction.expect("wf");
        assert!(wf.orbitals.iter().all(|o| o.symmetry.is_empty()), "ORCA's a1g on every orbital names nothing");
        let labelled = H2.replacen(" a1g  a1g", " ag  b1u", 1);
        let wf = doc(&labelled).wavefunction.expect("wf");
        assert_eq!(wf.orbitals.iter().map(|o| o.symmetry.as_str()).collect::<Vec<_>>(), ["ag", "b1u"]);
    }

    #[test]
    fn malformed_files_name_their_line() {
        let cases: Vec<(String, usize, &str)> = vec![
            (String::new(), 1, "an MKL file"),
            ("hello\n".into(), 1, "an MKL file"),
            (H2.replace("  0 1\n", "  0 one\n"), 5, "charge multiplicity"),
            (H2.replace("   1    0.000000   0.000000   0.740000", "   1    0.000000   0.740000"), 11, "Z x y z"),
            (
                H2.replace("   1    0.000000   0.000000   0.740000", " 200    0.000000   0.000000   0.740000"),
                11,
                "atomic number",
            ),
            (H2.replace(" 5 D 1.0", " 4 D 1.0"), 18, "shell header"),
            (H2.replace(" 5 D 1.0", " 5 Q 1.0"), 18, "shell header"),
            (
                H2.replace("        0.800000000      1.000000000", "       -0.800000000      1.000000000"),
                19,
                "positive exponent",
            ),
            (H2.replace("$$\n", "$$\n 6 D 1.0\n 0.5 1.0\n"), 21, "one kind per l"),
            (H2.replace("$$\n", "$$\n$$\n"), 22, "atoms"),
            (H2.replace("   -0.5902189     0.7006479", "   -0.5902189"), 28, "2 energies"),
            (H2.replace("   0.0100000    0.0000000", "   0.0100000    zero"), 34, "2 coefficients of basis function 6"),
            (H2.replace("   0.5458586    1.2462451\n $END", " $END"), 35, "7 coefficient rows"),
            (H2.replace("   1.0000000    0.0000000", "   1.0000000"), 40, "2 occupations"),
            (H2.replace(" $END\n\n$OCC_ALPHA", "\n$OCC_ALPHA"), 37, "the $END of $COEFF_ALPHA"),
            (H2.replace("$OCC_ALPHA\n   1.0000000    0.0000000\n $END\n", ""), 37, "a $OCC_ALPHA section"),
            (format!("{H2}$COORD\n 1 0 0 0\n$END\n"), 41, "one $COORD"),
        ];
        let mut wrong = Vec::new();
        for (text, line, expected) in cases {
            match parse("t.mkl", &text, None) {
                Ok(_) => wrong.push(format!("wanted line {line} \"{expected}\", but it parsed")),
                Err(e) if e.line != line || !e.expected.contains(expected) || e.file != "t.mkl" => {
                    wrong.push(format!("wanted line {line} \"{expected}\", got {e}"));
                }
                Err(_) => {}
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    }
}
