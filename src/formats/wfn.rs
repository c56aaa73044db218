//! AIM wavefunction files (`.wfn`: AIMPAC's format, written by Gaussian, GAMESS, PySCF, ORCA,
//! Molden2AIM, Multiwfn; GUIDE §9).
//!
//! ```text
//! title
//! GAUSSIAN      n MOL ORBITALS      p PRIMITIVES      a NUCLEI      (GTO also for GAUSSIAN)
//!   O    1    (CENTRE  1)   x y z (bohr)  CHARGE =  8.0             one line per nucleus
//! CENTRE ASSIGNMENTS    1  1  1 …     p centre numbers, 20 I3 fields from column 21 a line
//! TYPE ASSIGNMENTS      1  1  2 …     p types (see `primitives`), the same layout
//! EXPONENTS  0.1172000D+05 …          p exponents, 5 a line, D or E exponents
//! MO    1     MO 0.0        OCC NO =    2.0000000  ORB. ENERGY =  -20.550000
//!   0.57031692D+00 …                  per orbital: the header, then p coefficients over the
//!                                     unnormalised primitives, 5 a line
//! END DATA
//!  THE  HF ENERGY =   -76.02876 THE VIRIAL(-V/T)=   2.0021    (not needed)
//! [$MOSPIN $END, then one code per orbital: 1 alpha, 2 beta, 3 both]   Multiwfn's extension
//! ```
//!
//! The fields are Fortran's fixed columns, but writers differ in spacing (PySCF's `MO  1   OCC NO
//! =`), so lines are read by field: numbers are split at whitespace and where a negative number
//! fills its field (`fortran_fields`), and the assignments are read as I3 columns from column 21
//! when a centre or type above 99 runs into its neighbour.
//!
//! The format has no spin field. As IOData reads it: Multiwfn's `$MOSPIN` section when there is
//! one; otherwise an occupation above 1 means a restricted wavefunction (ROHF included), and with
//! none the orbitals are alpha while energies do not fall, occupations do not rise and numbers
//! run on, beta from there (Gaussian writes UHF orbitals so, alpha first). What was inferred is
//! said in `Document::problems`.

use glam::DVec3;

use super::molden::MAX_MO_VALUES;
use super::primitives::{MAX_TYPE, PrimitiveBasis, TYPE_RANGE};
use super::text::{Lines, excerpt, fortran_fields, parse_fortran_real};
use super::wavefunction::{OverlapFn, program_named_in, wavefunction_document};
use super::{MAX_Z, ParseError};
use crate::model::elements::atomic_number;
use crate::model::orbitals::{MolecularOrbital, Spin, Wavefunction};
use crate::model::{Atom, Document};

/// Parses `.wfn` text into a document, checking the orbitals with `overlap`.
pub fn parse(file: &str, text: &str, overlap: Option<OverlapFn>) -> Result<Document, ParseError> {
    if text.trim().is_empty() {
        return Err(ParseError {
            file: file.to_string(),
            line: 1,
            expected: "a .wfn file: a title line, then `GAUSSIAN … NUCLEI`".into(),
            found: "an empty file".into(),
        });
    }
    let mut lines = Lines::new(file, text);
    let title = lines.next_line("a title line")?.trim().to_string();
    let header_line = next_nonblank(&mut lines, HEADER)?;
    let (n_mo, n_prim, n_atoms) =
        header_counts(header_line).ok_or_else(|| lines.error(HEADER, &excerpt(header_line)))?;
    check_counts(&mut lines, n_mo, n_prim, n_atoms)?;

    let mut atoms = Vec::with_capacity(n_atoms);
    for k in 0..n_atoms {
        let l = lines.next_line(&format!("the line of nucleus {} of {n_atoms}", k + 1))?;
        atoms.push(parse_atom(l).map_err(|expected| lines.error(&expected, &excerpt(l)))?);
    }
    let centres = read_assignments(&mut lines, "CENTRE ASSIGNMENTS", n_prim, |c| {
        (1..=n_atoms as u32).contains(&c).then_some(()).ok_or(format!("a centre 1..={n_atoms}"))
    })?;
    let types = read_assignments(&mut lines, "TYPE ASSIGNMENTS", n_prim, |t| {
        (1..=MAX_TYPE).contains(&t).then_some(()).ok_or(TYPE_RANGE.to_string())
    })?;
    let exponents = read_exponents(&mut lines, n_prim)?;
    let positions: Vec<DVec3> = atoms.iter().map(|a| a.position).collect();
    let centres: Vec<usize> = centres.iter().map(|&c| c as usize - 1).collect();
    let primitives = PrimitiveBasis::new(&positions, &centres, &types, &exponents);

    let mut orbitals = Vec::new();
    let mut numbers = Vec::new();
    let mut buffer = Vec::with_capacity(n_prim);
    for k in 0..n_mo {
        let expected = format!("the header of orbital {} of {n_mo} (`MO n … OCC NO = … ORB. ENERGY = …`)", k + 1);
        let l = next_nonblank(&mut lines, &expected)?;
        let (number, occupation, energy) = parse_mo_header(l).ok_or_else(|| lines.error(&expected, &excerpt(l)))?;
        let start = lines.line;
        buffer.clear();
        while buffer.len() < n_prim {
            let what = format!("{n_prim} coefficients of orbital {} (line {start})", k + 1);
            let l = lines
                .next_line(&what)
                .map_err(|_| lines.error(&what, &format!("end of file after {}", buffer.len())))?;
            if parse_mo_header(l).is_some() || is_end(l) {
                return Err(lines.error(&what, &format!("{} after {}", excerpt(l), buffer.len())));
            }
            for field in fortran_fields(l) {
                if buffer.len() == n_prim {
                    return Err(lines.error(&what, "more values on the line"));
                }
                let v = parse_fortran_real(field).ok_or_else(|| {
                    lines.error(
                        &format!("coefficient {} of orbital {} as a number", buffer.len() + 1, k + 1),
                        &excerpt(field),
                    )
                })?;
                buffer.push(v);
            }
        }
        numbers.push(number);
        orbitals.push(MolecularOrbital {
            energy,
            occupation,
            spin: Spin::Alpha,
            symmetry: String::new(),
            coefficients: primitives.orbital(&buffer),
        });
    }
    let expected = format!("END DATA after the {n_mo} orbitals the header declares");
    let l = next_nonblank(&mut lines, &expected)?;
    if !is_end(l) {
        return Err(lines.error(&expected, &excerpt(l)));
    }
    let codes = read_mospin(&mut lines, n_mo)?;

    let (restricted, inferred) = assign_spins(&mut orbitals, &numbers, codes.as_deref()).map_err(|found| {
        lines.error("spin codes 1 and 3 (restricted) or 1 and 2 (unrestricted) after $MOSPIN", &found)
    })?;
    orbitals.sort_by_key(|o| o.spin == Spin::Beta);
    let wf = Wavefunction {
        basis: primitives.basis,
        orbitals,
        restricted,
        normalization: Default::default(),
        excited: None,
    };
    let mut doc = wavefunction_document(file, &title, atoms, wf, program_named_in(&title), overlap);
    if let Some(note) = inferred {
        doc.problems.push(format!("{file}: {note}"));
    }
    Ok(doc)
}

const HEADER: &str = "a header `GAUSSIAN  n MOL ORBITALS  n PRIMITIVES  n NUCLEI`";

fn next_nonblank<'a>(lines: &mut Lines<'a>, expected: &str) -> Result<&'a str, ParseError> {
    loop {
        let l = lines.next_line(expected)?;
        if !l.trim().is_empty() {
            return Ok(l);
        }
    }
}

fn is_end(line: &str) -> bool {
    line.trim_start().to_ascii_uppercase().starts_with("END DATA")
}

/// (orbitals, primitives, nuclei) of the header line; the numbers may touch the words around
/// them (`MOL ORBITALS1234567`), so each is the text between two keywords.
fn header_counts(line: &str) -> Option<(usize, usize, usize)> {
    let first = line.split_whitespace().next()?;
    if !first.to_ascii_uppercase().starts_with('G') {
        return None;
    }
    let start = line.find(first)? + first.len();
    let mut from = start;
    let mut counts = [0usize; 3];
    for (k, keyword) in ["MOL ORBITALS", "PRIMITIVES", "NUCLEI"].iter().enumerate() {
        let at = from + line[from..].find(keyword)?;
        counts[k] = line[from..at].trim().parse().ok()?;
        from = at + keyword.len();
    }
    Some((counts[0], counts[1], counts[2]))
}

/// Refuses counts the rest of the file cannot hold before anything is sized by them: a nucleus
/// takes a line, a primitive at least three bytes (its centre), an orbital coefficient two.
fn check_counts(lines: &mut Lines, n_mo: usize, n_prim: usize, n_atoms: usize) -> Result<(), ParseError> {
    let rest = lines.rest();
    let bytes = rest.len() as u64;
    let lines_left = rest.lines().count() as u64;
    let (mo, prim, atoms) = (n_mo as u64, n_prim as u64, n_atoms as u64);
    let found = format!("{n_mo} orbitals, {n_prim} primitives, {n_atoms} nuclei");
    if mo == 0 || prim == 0 || atoms == 0 {
        return Err(lines.error("at least one orbital, one primitive and one nucleus", &found));
    }
    if atoms > lines_left || prim.saturating_mul(3) > bytes || mo.saturating_mul(prim).saturating_mul(2) > bytes {
        return Err(
            lines.error(&format!("counts the {bytes} bytes and {lines_left} lines after the header can hold"), &found)
        );
    }
    if mo.saturating_mul(prim) > MAX_MO_VALUES {
        return Err(lines.error(&format!("at most {MAX_MO_VALUES} orbital coefficients"), &found));
    }
    Ok(())
}

/// An atom line `  O    1    (CENTRE  1)   x y z  CHARGE =  8.0`; the element is the name's
/// leading letters (`Li1`, `H2` as AIMAll writes them), else the charge.
fn parse_atom(line: &str) -> Result<Atom, String> {
    const EXPECTED: &str = "a nucleus `name  (CENTRE n)  x y z  CHARGE = z`";
    let bad = || EXPECTED.to_string();
    let open = line.find("(CENT").ok_or_else(bad)?;
    let close = open + line[open..].find(')').ok_or_else(bad)?;
    let charge_at = close + line[close..].find("CHARGE").ok_or_else(bad)?;
    let xyz: Vec<f64> = fortran_fields(&line[close + 1..charge_at])
        .into_iter()
        .map(parse_fortran_real)
        .collect::<Option<_>>()
        .ok_or_else(bad)?;
    if xyz.len() != 3 {
        return Err(bad());
    }
    let charge_text = line[charge_at + "CHARGE".len()..].trim_start().trim_start_matches('=');
    let charge = fortran_fields(charge_text).first().and_then(|f| parse_fortran_real(f)).ok_or_else(bad)?;
    let name = line[..open].split_whitespace().next().unwrap_or("");
    let letters: String = name.chars().take_while(char::is_ascii_alphabetic).collect();
    let z = atomic_number(&letters)
        .or_else(|| (0.0..=f64::from(MAX_Z)).contains(&charge.round()).then_some(charge.round() as u32))
        .ok_or_else(|| format!("an element name or a nuclear charge 0..={MAX_Z}"))?;
    Ok(Atom { z, charge, position: DVec3::new(xyz[0], xyz[1], xyz[2]), ghost: charge == 0.0 })
}

/// `n` integers from lines starting with `label`, each checked by `valid` (an error names the
/// line of the value).
fn read_assignments(
    lines: &mut Lines,
    label: &str,
    n: usize,
    valid: impl Fn(u32) -> Result<(), String>,
) -> Result<Vec<u32>, ParseError> {
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let expected = format!("{label} lines with {n} values");
        let l = lines
            .next_line(&expected)
            .map_err(|_| lines.error(&expected, &format!("end of file after {}", out.len())))?;
        let Some(rest) = l.trim_start().strip_prefix(label) else {
            return Err(lines.error(&expected, &format!("{} after {}", excerpt(l), out.len())));
        };
        // I3 columns from column 21 when a value runs into its neighbour (`100101`).
        let fields: Vec<&str> = if rest.split_whitespace().all(|t| t.len() <= 3) {
            rest.split_whitespace().collect()
        } else if l.starts_with(label) && l.len() > 20 && l.is_ascii() {
            l.as_bytes()[20..].chunks(3).filter_map(|c| std::str::from_utf8(c).ok()).map(str::trim).collect()
        } else {
            return Err(lines.error(&format!("{label} as I3 fields from column 21"), &excerpt(l)));
        };
        for field in fields.into_iter().filter(|f| !f.is_empty()) {
            if out.len() == n {
                return Err(lines.error(&format!("{n} values in {label} (the header's primitives)"), "more"));
            }
            let v: u32 = field.parse().map_err(|_| lines.error(&format!("an integer in {label}"), &excerpt(field)))?;
            valid(v).map_err(|expected| lines.error(&expected, field))?;
            out.push(v);
        }
    }
    Ok(out)
}

fn read_exponents(lines: &mut Lines, n: usize) -> Result<Vec<f64>, ParseError> {
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let expected = format!("EXPONENTS lines with {n} values");
        let l = lines
            .next_line(&expected)
            .map_err(|_| lines.error(&expected, &format!("end of file after {}", out.len())))?;
        let Some(rest) = l.trim_start().strip_prefix("EXPONENTS") else {
            return Err(lines.error(&expected, &format!("{} after {}", excerpt(l), out.len())));
        };
        for field in fortran_fields(rest) {
            if out.len() == n {
                return Err(lines.error(&format!("{n} EXPONENTS (the header's primitives)"), "more"));
            }
            match parse_fortran_real(field) {
                Some(v) if v > 0.0 => out.push(v),
                _ => return Err(lines.error("a positive exponent", &excerpt(field))),
            }
        }
    }
    Ok(out)
}

/// (number, occupation, energy) of `MO n … OCC NO = x  ORB. ENERGY = e` (or PySCF's `CANMO n`
/// for orbitals without either); `None` when the line is no orbital header.
fn parse_mo_header(line: &str) -> Option<(usize, f64, f64)> {
    let t = line.trim_start();
    let (rest, canonical) = match t.strip_prefix("CANMO") {
        Some(r) => (r, true),
        None => (t.strip_prefix("MO")?, false),
    };
    let number = rest.split_whitespace().next()?.parse().ok()?;
    let value_after = |key: &str| -> Option<Option<f64>> {
        let Some(at) = line.find(key) else { return Some(None) };
        let text = line[at + key.len()..].trim_start().trim_start_matches('=');
        Some(Some(fortran_fields(text).first().and_then(|f| parse_fortran_real(f))?))
    };
    let occupation = value_after("OCC NO")?;
    let energy = value_after("ENERGY")?;
    if occupation.is_none() && !canonical {
        return None;
    }
    Some((number, occupation.unwrap_or(0.0), energy.unwrap_or(f64::NAN)))
}

/// Multiwfn's `$MOSPIN $END` section after `END DATA`: one code per orbital.
fn read_mospin(lines: &mut Lines, n_mo: usize) -> Result<Option<Vec<u8>>, ParseError> {
    loop {
        let Ok(l) = lines.next_line("") else { return Ok(None) };
        if l.trim().eq_ignore_ascii_case("$MOSPIN $END") {
            break;
        }
    }
    let mut codes = Vec::with_capacity(n_mo);
    while codes.len() < n_mo {
        let expected = format!("{n_mo} spin codes after $MOSPIN $END");
        let l = lines
            .next_line(&expected)
            .map_err(|_| lines.error(&expected, &format!("end of file after {}", codes.len())))?;
        for field in l.split_whitespace() {
            match field.parse::<u8>() {
                Ok(c @ 1..=3) if codes.len() < n_mo => codes.push(c),
                Ok(1..=3) => return Err(lines.error(&expected, "more")),
                _ => return Err(lines.error("a spin code 1 (alpha), 2 (beta) or 3 (both)", &excerpt(field))),
            }
        }
    }
    Ok(Some(codes))
}

/// Sets each orbital's spin; returns whether the wavefunction is restricted and, when the
/// file does not say, what was inferred. `Err` carries the codes that mix the two kinds.
fn assign_spins(
    orbitals: &mut [MolecularOrbital],
    numbers: &[usize],
    codes: Option<&[u8]>,
) -> Result<(bool, Option<String>), String> {
    if let Some(codes) = codes {
        let both = codes.contains(&3);
        if both && codes.contains(&2) {
            return Err("codes 2 and 3 together".into());
        }
        for (o, &c) in orbitals.iter_mut().zip(codes) {
            o.spin = if c == 2 { Spin::Beta } else { Spin::Alpha };
        }
        return Ok((both, None));
    }
    if orbitals.iter().any(|o| o.occupation > 1.0 + 1e-6) {
        return Ok((true, None));
    }
    // Alpha while energies do not fall, occupations do not rise and numbers run on.
    let alpha = (1..orbitals.len())
        .find(|&i| {
            let (a, b) = (&orbitals[i - 1], &orbitals[i]);
            b.energy < a.energy || b.occupation > a.occupation + 1e-9 || numbers[i] != numbers[i - 1] + 1
        })
        .unwrap_or(orbitals.len());
    let n = orbitals.len();
    for o in &mut orbitals[alpha..] {
        o.spin = Spin::Beta;
    }
    let note = if alpha == n {
        "every orbital read as an alpha spin orbital: occupations of at most 1 and no second set (the format has no spin field)".to_string()
    } else {
        format!(
            "orbitals 1–{alpha} read as alpha and {}–{n} as beta: the format has no spin field; occupations of at most 1 mean spin orbitals, and the beta set starts where the energies fall or the occupations rise again",
            alpha + 1
        )
    };
    Ok((false, Some(note)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// H2 with one s primitive per atom and a p primitive on atom 1; 2 orbitals.
    const H2: &str = " H2 test
GAUSSIAN              2 MOL ORBITALS      5 PRIMITIVES        2 NUCLEI
  H    1    (CENTRE  1)   0.00000000  0.00000000  0.00000000  CHARGE =  1.0
  H    2    (CENTRE  2)   0.00000000  0.00000000  1.40000000  CHARGE =  1.0
CENTRE ASSIGNMENTS    1  2  1  1  1
TYPE ASSIGNMENTS      1  1  2  3  4
EXPONENTS  0.1000000D+01 0.1000000D+01 0.8000000D+00 0.8000000D+00 0.8000000D+00
MO    1     MO 0.0        OCC NO =    2.0000000  ORB. ENERGY =   -0.600000
  0.40000000D+00  0.40000000D+00  0.00000000D+00  0.00000000D+00  0.10000000D+00
MO    2     MO 0.0        OCC NO =    0.0000000  ORB. ENERGY =    0.700000
  0.50000000D+00 -0.50000000D+00  0.00000000D+00  0.00000000D+00  0.00000000D+00
END DATA
 THE  HF ENERGY =     -1.100000000000 THE VIRIAL(-V/T)=   2.00000000
";

    fn doc(text: &str) -> Document {
        parse("t.wfn", text, None).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn a_restricted_file_reads() {
        let d = doc(H2);
        assert_eq!(d.title, "H2 test");
        assert_eq!(d.molecule.atoms.len(), 2);
        assert_eq!(d.molecule.atoms[1].position.z, 1.4);
        let wf = d.wavefunction.expect("wf");
        assert!(wf.restricted);
        assert_eq!(wf.basis.shells.len(), 3);
        assert_eq!(wf.basis.n_functions(), 5);
        assert_eq!(wf.orbitals.len(), 2);
        assert_eq!((wf.orbitals[0].occupation, wf.orbitals[0].energy), (2.0, -0.6));
        assert!(d.problems.is_empty(), "{:?}", d.problems);
    }

    #[test]
    fn spins_are_inferred_as_iodata_does() {
        let uhf = H2
            .replace(
                "OCC NO =    2.0000000  ORB. ENERGY =   -0.600000",
                "OCC NO =    1.0000000  ORB. ENERGY =   -0.600000",
            )
            .replace(
                "OCC NO =    0.0000000  ORB. ENERGY =    0.700000",
                "OCC NO =    1.0000000  ORB. ENERGY =   -0.500000",
            );
        let d = doc(&uhf);
        let wf = d.wavefunction.expect("wf");
        assert!(!wf.restricted);
        assert_eq!(wf.orbitals.iter().map(|o| o.spin).collect::<Vec<_>>(), [Spin::Alpha, Spin::Alpha]);
        assert!(d.problems[0].contains("every orbital read as an alpha"), "{:?}", d.problems);
        // Energies falling again start the beta set.
        let split = uhf.replace("ORB. ENERGY =   -0.500000", "ORB. ENERGY =   -0.700000");
        let d = doc(&split);
        let wf = d.wavefunction.expect("wf");
        assert_eq!(wf.orbitals.iter().map(|o| o.spin).collect::<Vec<_>>(), [Spin::Alpha, Spin::Beta]);
        assert!(d.problems[0].contains("1–1 read as alpha and 2–2 as beta"), "{:?}", d.problems);
        // Multiwfn's $MOSPIN section says so itself.
        let d = doc(&format!("{split} $MOSPIN $END\n\n 1 1\n"));
        assert_eq!(d.wavefunction.expect("wf").of_spin(Spin::Beta).count(), 0);
        assert!(d.problems.is_empty());
        let d = doc(&format!("{H2} $MOSPIN $END\n 3 3\n"));
        assert!(d.wavefunction.expect("wf").restricted);
    }

    #[test]
    fn fixed_columns_that_run_together_are_split() {
        let text = H2
            .replace(
                "  H    2    (CENTRE  2)   0.00000000  0.00000000  1.40000000",
                "H2          (CENTRE  2) -10.00000000-11.00000000  1.40000000",
            )
            .replace("MO    2     MO 0.0        OCC NO =    0.0000000  ORB. ENERGY =    0.700000", "CANMO 2")
            .replace("  0.50000000D+00 -0.50000000D+00", "  0.50000000D+00-0.50000000D+00");
        let d = doc(&text);
        let h = &d.molecule.atoms[1];
        assert_eq!((h.z, h.position.x, h.position.y), (1, -10.0, -11.0));
        let wf = d.wavefunction.expect("wf");
        assert!(wf.orbitals[1].energy.is_nan());
        // Centres above 99 touch: I3 columns from column 21.
        let fields = "CENTRE ASSIGNMENTS  100101  7";
        let mut lines = Lines::new("t.wfn", fields);
        let v = read_assignments(&mut lines, "CENTRE ASSIGNMENTS", 3, |_| Ok(())).expect("fields");
        assert_eq!(v, [100, 101, 7]);
    }

    #[test]
    fn malformed_files_name_their_line() {
        let cases: Vec<(String, usize, &str)> = vec![
            (String::new(), 1, "a .wfn file"),
            (H2.replace("GAUSSIAN ", "SLATER   "), 2, "GAUSSIAN"),
            (H2.replace("      5 PRIMITIVES", "    5x PRIMITIVES"), 2, "GAUSSIAN"),
            (H2.replace("      5 PRIMITIVES", "99999999999 PRIMITIVES"), 2, "can hold"),
            (H2.replace("     2 MOL ORBITALS", "999999 MOL ORBITALS"), 2, "can hold"),
            (H2.replace("      2 NUCLEI", "      0 NUCLEI"), 2, "at least one"),
            (H2.replace("(CENTRE  2)", "(CENTER 2"), 4, "nucleus"),
            (H2.replace("1.40000000  CHARGE", "1.4x  CHARGE"), 4, "nucleus"),
            (H2.replace("CENTRE ASSIGNMENTS    1  2", "CENTRE ASSIGNMENTS    1  3"), 5, "a centre 1..=2"),
            (
                H2.replace("TYPE ASSIGNMENTS      1  1  2  3  4", "TYPE ASSIGNMENTS      1  1  2  3 57"),
                6,
                "primitive type 1..=56",
            ),
            (
                H2.replace("TYPE ASSIGNMENTS      1  1  2  3  4", "TYPE ASSIGNMENTS      1  1  2  3  4  1"),
                6,
                "5 values",
            ),
            (H2.replace("TYPE ASSIGNMENTS", "TYPE ASSIGNMENTZ"), 6, "TYPE ASSIGNMENTS lines"),
            (H2.replace("0.8000000D+00 0.8000000D+00\n", "-0.8000000D+00 0.8000000D+00\n"), 7, "positive exponent"),
            (H2.replace("0.8000000D+00 0.8000000D+00\n", "0.8000000D+00 x\n"), 7, "positive exponent"),
            (H2.replace("MO    2     MO 0.0", "XO    2     MO 0.0"), 10, "the header of orbital 2"),
            (H2.replace("OCC NO =    0.0000000", "OCC NO =    zero"), 10, "the header of orbital 2"),
            (
                H2.replace(
                    "  0.50000000D+00 -0.50000000D+00  0.00000000D+00  0.00000000D+00  0.00000000D+00\n",
                    "  0.50000000D+00 -0.5000000QD+00  0.0  0.0  0.0\n",
                ),
                11,
                "coefficient 2 of orbital 2",
            ),
            (H2.replace("  0.10000000D+00\nMO", "\nMO"), 10, "5 coefficients of orbital 1"),
            (
                H2.replace("END DATA\n", "MO    3     MO 0.0        OCC NO =    0.0000000  ORB. ENERGY =    0.7\n"),
                12,
                "END DATA after the 2 orbitals",
            ),
            (H2.split("MO    2").next().unwrap_or("").to_string(), 9, "the header of orbital 2"),
            (format!("{H2} $MOSPIN $END\n 1 4\n"), 15, "spin code"),
            (format!("{H2} $MOSPIN $END\n 3 2\n"), 15, "restricted"),
        ];
        let mut wrong = Vec::new();
        for (text, line, expected) in cases {
            match parse("t.wfn", &text, None) {
                Ok(_) => wrong.push(format!("wanted line {line} \"{expected}\", but it parsed")),
                Err(e) if e.line != line || !e.expected.contains(expected) || e.file != "t.wfn" => {
                    wrong.push(format!("wanted line {line} \"{expected}\", got {e}"));
                }
                Err(_) => {}
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    }
}
