//! Outputs written here in ORCA 6's layout (checked against its own): orthonormal orbitals over
//! s, p, d and f shells, printed in ORCA's order and signs to 6 decimals, and read back.

use super::super::ref_overlap::reference_overlap;
use super::*;
use crate::model::gto::PreparedBasis;
use crate::model::orbitals::Wavefunction;

/// Water (bohr): O with s, s, p, d and f shells, H with s.
const ATOMS: [(&str, [f64; 3]); 3] = [("O", [0.0, 0.0, 0.22]), ("H", [0.0, 1.43, -0.89]), ("H", [0.0, -1.43, -0.89])];

fn element_shells(symbol: &str) -> Vec<PrintedShell> {
    let s = |l, e: &[f64], c: &[f64]| PrintedShell { l, exponents: e.to_vec(), coefficients: c.to_vec() };
    match symbol {
        "O" => vec![
            s(0, &[130.7, 23.81, 6.444], &[0.1543, 0.5353, 0.4446]),
            s(0, &[5.033, 1.170], &[-0.0999, 0.3995]),
            s(1, &[5.033, 1.170], &[0.1559, 0.6077]),
            s(2, &[1.2], &[1.0]),
            s(3, &[0.9], &[1.0]),
        ],
        _ => vec![s(0, &[3.425, 0.6239], &[0.4, 0.7])],
    }
}

fn model_basis() -> Basis {
    let mut shells = Vec::new();
    for (atom, (symbol, p)) in ATOMS.iter().enumerate() {
        for ps in element_shells(symbol) {
            let kind = if ps.l >= 2 { ShellKind::Pure } else { ShellKind::Cartesian };
            shells.push(Shell {
                atom,
                center: DVec3::from_array(*p),
                l: ps.l,
                kind,
                exponents: ps.exponents,
                coefficients: ps.coefficients,
            });
        }
    }
    Basis { shells }
}

/// Orthonormal orbitals (Gram–Schmidt in the overlap) over the normalised `basis`.
fn orbitals(basis: &Basis, seed: f64) -> Vec<Vec<f64>> {
    super::super::orthonormal_orbitals(&normalized(basis), |i, k| {
        if i == k { 1.0 } else { 0.2 * ((i * 5 + k) as f64 + seed).cos() }
    })
}

/// ORCA's function labels of a shell and, for each, the model's function and sign.
fn rows_of(l: u32, n: u32) -> Vec<(String, usize, f64)> {
    let names: Vec<String> = match l {
        0 => vec!["s".into()],
        1 => vec!["pz".into(), "px".into(), "py".into()],
        2 => ["dz2", "dxz", "dyz", "dx2y2", "dxy"].iter().map(ToString::to_string).collect(),
        _ => {
            let mut v = vec![format!("{}0", LETTERS.chars().nth(l as usize).unwrap())];
            for m in 1..=l {
                v.push(format!("{}+{m}", LETTERS.chars().nth(l as usize).unwrap()));
                v.push(format!("{}-{m}", LETTERS.chars().nth(l as usize).unwrap()));
            }
            v
        }
    };
    let flipped = orca_flipped(l);
    names
        .into_iter()
        .enumerate()
        .map(|(k, name)| {
            let model = if l == 1 { [2, 0, 1][k] } else { k };
            (format!("{n}{name}"), model, if l >= 2 && flipped.contains(&k) { -1.0 } else { 1.0 })
        })
        .collect()
}

/// An output with the coordinates, the basis and the orbitals (alpha, then beta when given).
fn output(alpha: &[Vec<f64>], beta: Option<&[Vec<f64>]>) -> String {
    let mut t = "                                 *****************\n                                 * O   R   C   A *\n                                 *****************\n".to_string();
    t += "|  1> ! uks hf def2-svp\n\n----------------------------\nCARTESIAN COORDINATES (A.U.)\n----------------------------\n";
    t += "  NO LB      ZA    FRAG     MASS         X           Y           Z\n";
    for (k, (symbol, p)) in ATOMS.iter().enumerate() {
        let (za, mass) = if *symbol == "O" { (8.0, 15.999) } else { (1.0, 1.008) };
        t += &format!("{k:>4} {symbol:<2} {za:>9.4}{:>5}{mass:>11.3}{:>12.6}{:>12.6}{:>12.6}\n", 0, p[0], p[1], p[2]);
    }
    t += "\n-------------------------\nBASIS SET IN INPUT FORMAT\n-------------------------\n\n";
    for symbol in ["H", "O"] {
        t += &format!(" # Basis set for element : {symbol} \n NewGTO {symbol} \n");
        for s in element_shells(symbol) {
            t += &format!(
                " {} {} \n",
                LETTERS.chars().nth(s.l as usize).unwrap().to_ascii_uppercase(),
                s.exponents.len()
            );
            for (k, (e, c)) in s.exponents.iter().zip(&s.coefficients).enumerate() {
                t += &format!("  {:>2} {e:>18.10} {c:>16.10}\n", k + 1);
            }
        }
        t += "  end;\n\n";
    }
    t += "FINAL SINGLE POINT ENERGY       -76.012345678901\n\n";
    // Rows: (atom, label, model index, sign).
    let basis = model_basis();
    let offsets = basis.shell_offsets();
    let mut rows = Vec::new();
    for (s, first) in basis.shells.iter().zip(offsets) {
        for (label, k, sign) in rows_of(s.l, s.l + 1) {
            rows.push((s.atom, label, first + k, sign));
        }
    }
    t += "------------------\nMOLECULAR ORBITALS\n------------------\n";
    for set in std::iter::once(alpha).chain(beta) {
        for (b, block) in set.chunks(6).enumerate() {
            t += &format!("{:>16}{}\n", "", (0..block.len()).map(|c| format!("{:>10}", b * 6 + c)).collect::<String>());
            t += &format!(
                "{:>16}{}\n",
                "",
                (0..block.len()).map(|c| format!("{:>10.5}", -1.0 + 0.1 * (b * 6 + c) as f64)).collect::<String>()
            );
            let occupied = if beta.is_some() { 1.0 } else { 2.0 };
            t += &format!(
                "{:>16}{}\n",
                "",
                (0..block.len())
                    .map(|c| format!("{:>10.5}", if b * 6 + c < 5 { occupied } else { 0.0 }))
                    .collect::<String>()
            );
            t += &format!("{:>16}{}\n", "", (0..block.len()).map(|_| "  --------").collect::<String>());
            for (atom, label, k, sign) in &rows {
                let head = format!("{:>3}{:<2}  {label:<6}", atom, ATOMS[*atom].0);
                let values: String = block.iter().map(|o| format!("{:>10.6}", sign * o[*k])).collect();
                t += &format!("{head:<16}{values}\n");
            }
        }
    }
    t + "\n------------------------\nMULLIKEN POPULATION ANALYSIS\n"
}

/// `basis` with every contraction scaled to unit norm (the orbitals are over those).
fn normalized(basis: &Basis) -> Basis {
    let mut b = basis.clone();
    for s in &mut b.shells {
        let n = crate::formats::wavefunction::contraction_norm(s.l, &s.exponents, &s.coefficients);
        s.coefficients.iter_mut().for_each(|c| *c /= n);
    }
    b
}

fn values(basis: &Basis, orbitals: &[&[f64]]) -> Vec<f64> {
    let mut wf = Wavefunction { basis: normalized(basis), ..Default::default() };
    wf.orbitals = orbitals
        .iter()
        .map(|c| MolecularOrbital {
            energy: 0.0,
            occupation: 0.0,
            spin: Spin::Alpha,
            symmetry: String::new(),
            coefficients: c.to_vec(),
        })
        .collect();
    let pb = PreparedBasis::new(&wf.basis);
    let points: Vec<DVec3> =
        (0..12).map(|k| DVec3::new((k as f64).sin(), (1.7 * k as f64).cos(), 0.2 * k as f64 - 1.0) * 1.5).collect();
    wf.orbitals
        .iter()
        .flat_map(|o| points.iter().map(|&p| pb.orbital_value(&o.coefficients, p)).collect::<Vec<_>>())
        .collect()
}

fn read(text: &str) -> Result<Document, ParseError> {
    parse("t.out", text, Some(&reference_overlap))
}

#[test]
fn orbitals_over_d_and_f_shells_read_back_in_orcas_order_and_signs() {
    let basis = model_basis();
    let (alpha, beta) = (orbitals(&basis, 0.4), orbitals(&basis, 2.1));
    for unrestricted in [false, true] {
        let text = output(&alpha, unrestricted.then_some(&beta[..]));
        let doc = read(&text).unwrap_or_else(|e| panic!("{e}"));
        let wf = doc.wavefunction.as_ref().expect("orbitals");
        assert_eq!(wf.basis.n_functions(), 1 + 1 + 3 + 5 + 7 + 2);
        assert_eq!(wf.restricted, !unrestricted);
        let n = &wf.normalization;
        assert_eq!((n.program.as_str(), n.repair.as_str(), n.printed_decimals), ("ORCA", "none", Some(6)));
        assert!(n.residual < n.expected_residual(), "{n:?}");
        for (spin, want) in [(Spin::Alpha, &alpha), (Spin::Beta, &beta)] {
            let got: Vec<&[f64]> = wf.of_spin(spin).map(|(_, o)| o.coefficients.as_slice()).collect();
            if spin == Spin::Beta && !unrestricted {
                assert!(got.is_empty());
                continue;
            }
            let want: Vec<&[f64]> = want.iter().map(Vec::as_slice).collect();
            let (a, b) = (values(&wf.basis, &got), values(&basis, &want));
            let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            assert!(worst < 1e-5 * scale, "{spin:?}: values differ by {worst:e} of {scale:e}");
        }
        assert_eq!(doc.title, "! uks hf def2-svp");
    }
}

#[test]
fn a_cut_orbital_block_and_a_missing_basis_are_reported() {
    let basis = model_basis();
    let text = output(&orbitals(&basis, 0.4), None);
    let lines: Vec<&str> = text.lines().collect();
    let block = lines.iter().position(|l| column_numbers(l).is_some_and(|n| n[0] == 6)).unwrap();
    let cut = block + 4 + 9;
    let e = read(&(lines[..cut].join("\n") + "\n\nMULLIKEN\n")).unwrap_err();
    assert_eq!((e.file.as_str(), e.line), ("t.out", cut + 1), "{e}");
    assert!(e.expected.contains("19 rows of coefficients for orbitals 6–11"), "{e}");

    let start = text.find("-------------------------\nBASIS SET").unwrap();
    let end = text.find("FINAL SINGLE POINT").unwrap();
    let doc = read(&format!("{}{}", &text[..start], &text[end..])).unwrap();
    assert!(doc.wavefunction.is_none());
    assert_eq!(doc.structure.as_ref().unwrap().structure.models[0].energy, Some(-76.012345678901));
    assert!(doc.problems.iter().any(|p| p.contains("print[p_basis] 2")), "{:?}", doc.problems);
}

/// Water's frequency job as ORCA 6 prints it: 9 frequencies (six zeros), the `NORMAL MODES`
/// columns in blocks, the `IR SPECTRUM` table.
fn frequency_output() -> String {
    let mut t = "                                 * O   R   C   A *\n\n----------------------------\nCARTESIAN COORDINATES (A.U.)\n----------------------------\n".to_string();
    t += "  NO LB      ZA    FRAG     MASS         X           Y           Z\n";
    for (k, (symbol, p)) in ATOMS.iter().enumerate() {
        let (za, mass) = if *symbol == "O" { (8.0, 15.999) } else { (1.0, 1.008) };
        t += &format!("{k:>4} {symbol:<2} {za:>9.4}{:>5}{mass:>11.3}{:>12.6}{:>12.6}{:>12.6}\n", 0, p[0], p[1], p[2]);
    }
    t += "\nFINAL SINGLE POINT ENERGY       -75.012345678901\n\n-----------------------\nVIBRATIONAL FREQUENCIES\n-----------------------\n\n";
    t += "Scaling factor for frequencies =  1.000000000  (already applied!)\n\n";
    let freqs = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1600.5, 3650.25, 3755.75];
    for (k, f) in freqs.iter().enumerate() {
        t += &format!("{k:>6}:{f:>11.2} cm**-1\n");
    }
    t += "\n\n------------\nNORMAL MODES\n------------\n\nThese modes are the Cartesian displacements weighted by the diagonal matrix\n\n";
    let value = |row: usize, col: usize| ((row * 7 + col * 3) as f64 * 0.37).sin() * 0.5;
    for first in [0, 6] {
        let cols: Vec<usize> = (first..(first + 6).min(9)).collect();
        t += &format!("      {}\n", cols.iter().map(|c| format!("{c:>11}")).collect::<String>());
        for row in 0..9 {
            t += &format!("{row:>6}{}\n", cols.iter().map(|&c| format!("{:>11.6}", value(row, c))).collect::<String>());
        }
        t += "\n";
    }
    t += "\n-----------\nIR SPECTRUM\n-----------\n\n Mode   freq       eps      Int      T**2         TX        TY        TZ\n";
    t += "       cm**-1   L/(mol*cm) km/mol    a.u.\n----------------------------------------------------------------------------\n";
    for (k, (f, int)) in
        [(6, 1600.5, 70.25), (7, 3650.25, 5.5), (8, 3755.75, 48.0)].iter().map(|(k, f, i)| (*k, (*f, *i)))
    {
        t += &format!("{k:>3}:{f:>10.2}   0.001000{int:>8.2}  0.000100  ( 0.000000  0.000000  0.010000)\n");
    }
    t + "\n* The epsilon (eps) is given for a Dirac delta lineshape.\n"
}

#[test]
fn a_frequency_jobs_modes_open_without_translations_and_rotations() {
    let text = frequency_output();
    let doc = read(&text).unwrap_or_else(|e| panic!("{e}"));
    let v = doc.vibrations.as_ref().unwrap_or_else(|| panic!("modes: {:?}", doc.problems));
    assert_eq!(v.modes.len(), 3);
    assert_eq!(v.geometry.len(), 3);
    assert_eq!(v.geometry[1], DVec3::from_array(ATOMS[1].1));
    let value = |row: usize, col: usize| ((row * 7 + col * 3) as f64 * 0.37).sin() * 0.5;
    for (m, (f, int)) in v.modes.iter().zip([(1600.5, 70.25), (3650.25, 5.5), (3755.75, 48.0)]) {
        assert_eq!((m.frequency_cm1, m.ir_intensity), (f, Some(int)));
    }
    // Mode 8 (the third kept), atom 2 (rows 6, 7, 8): x, y, z as printed, to 6 decimals.
    let d = v.modes[2].displacement[2];
    for (got, row) in [d.x, d.y, d.z].into_iter().zip(6..9) {
        assert!((got - value(row, 8)).abs() < 1e-6, "{got} {}", value(row, 8));
    }
}

#[test]
fn a_malformed_mode_section_leaves_the_modes_out_not_the_file() {
    let text = frequency_output();
    // A block cut after its first rows.
    let cut = text.replacen("\n     4  ", "\n  four  ", 1);
    let doc = read(&cut).unwrap();
    assert!(doc.vibrations.is_none());
    assert!(
        doc.problems.iter().any(|p| p.contains("normal modes left out") && p.contains("row 4")),
        "{:?}",
        doc.problems
    );
    // Frequencies for another molecule.
    let more = text.replacen(
        "     8:",
        "     8:  3755.75 cm**-1\n     9:    100.00 cm**-1\n    10:    100.00 cm**-1\n    11:",
        1,
    );
    let doc = read(&more).unwrap();
    assert!(doc.vibrations.is_none());
    assert!(!doc.problems.is_empty());
}
