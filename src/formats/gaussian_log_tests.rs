//! Logs written here in Gaussian's layout (checked against Gaussian 09's own): orbitals made
//! orthonormal, printed to 5 decimals as Gaussian prints them, and read back.

use glam::DVec3;

use super::super::ref_overlap::reference_overlap;
use super::*;
use crate::formats::wavefunction::normalize_contractions;
use crate::model::basis::cartesian_powers;
use crate::model::gto::PreparedBasis;

/// Water with an s, sp, d and f shell on O and two s primitives on each H (Å).
const ATOMS: [(u32, &str, [f64; 3]); 3] =
    [(8, "O", [0.0, 0.0, 0.1173]), (1, "H", [0.0, 0.7572, -0.4692]), (1, "H", [0.0, -0.7572, -0.4692])];

/// A printed shell: letters, exponents, coefficient columns.
type Printed = (&'static str, Vec<f64>, Vec<Vec<f64>>);

/// Printed shells per atom: letters, exponents, coefficient columns, each column's contraction
/// normalised (as Gaussian prints them).
fn printed_shells(atom: usize) -> Vec<Printed> {
    let mut shells = raw_shells(atom);
    for (letters, exponents, columns) in &mut shells {
        for (c, column) in columns.iter_mut().enumerate() {
            let l = if *letters == "SP" { c as u32 } else { shell_l(letters).unwrap() };
            let n = crate::formats::wavefunction::contraction_norm(l, exponents, column);
            column.iter_mut().for_each(|v| *v /= n);
        }
    }
    shells
}

fn raw_shells(atom: usize) -> Vec<Printed> {
    if atom == 0 {
        vec![
            ("S", vec![130.7, 23.81, 6.444], vec![vec![0.1543, 0.5353, 0.4446]]),
            ("SP", vec![5.033, 1.170], vec![vec![-0.0999, 0.3995], vec![0.1559, 0.6077]]),
            ("D", vec![1.2], vec![vec![1.0]]),
            ("F", vec![0.9], vec![vec![1.0]]),
        ]
    } else {
        vec![("S", vec![3.425, 0.6239], vec![vec![0.4, 0.7]])]
    }
}

/// The model's basis of [`printed_shells`] at [`ATOMS`], pure or cartesian d and f.
fn model_basis(pure: bool) -> Basis {
    let mut shells = Vec::new();
    for (atom, (_, _, p)) in ATOMS.iter().enumerate() {
        let center = DVec3::from_array(*p) * BOHR_PER_ANGSTROM;
        for (letters, exponents, columns) in printed_shells(atom) {
            let ls: Vec<u32> = if letters == "SP" { vec![0, 1] } else { vec![shell_l(letters).unwrap()] };
            for (l, coefficients) in ls.into_iter().zip(columns) {
                let kind = if l >= 2 && pure { ShellKind::Pure } else { ShellKind::Cartesian };
                shells.push(Shell { atom, center, l, kind, exponents: exponents.clone(), coefficients });
            }
        }
    }
    Basis { shells }
}

/// Orthonormal orbitals over `basis` (Gram–Schmidt in its overlap), started from `seed`.
fn orbitals(basis: &Basis, seed: f64) -> Vec<Vec<f64>> {
    let mut wf = Wavefunction { basis: basis.clone(), ..Default::default() };
    normalize_contractions(&mut wf);
    super::super::orthonormal_orbitals(
        &wf.basis,
        |i, k| if i == k { 1.0 } else { 0.2 * ((i * 7 + k) as f64 + seed).sin() },
    )
}

/// Gaussian's AO labels of a shell, in its order.
fn labels(l: u32, pure: bool, n: u32) -> Vec<String> {
    let letters = |p: [u32; 3]| -> String {
        [('X', p[0]), ('Y', p[1]), ('Z', p[2])].iter().flat_map(|&(c, k)| std::iter::repeat_n(c, k as usize)).collect()
    };
    match (l, pure) {
        (0, _) => vec![format!("{n}S")],
        (1, _) => ["PX", "PY", "PZ"].iter().map(|c| format!("{n}{c}")).collect(),
        (_, true) => {
            let c = shell_letter(l);
            let mut v = vec![format!("{n}{c} 0")];
            for m in 1..=l {
                v.push(format!("{n}{c}+{m}"));
                v.push(format!("{n}{c}-{m}"));
            }
            v
        }
        (_, false) => {
            super::super::fchk::gaussian_cartesian_order(l).into_iter().map(|p| format!("{n}{}", letters(p))).collect()
        }
    }
}

fn orientation_table(title: &str, scale: f64) -> String {
    let dashes = " ---------------------------------------------------------------------\n";
    let mut s = format!("                         {title}                         \n{dashes}");
    s += " Center     Atomic      Atomic             Coordinates (Angstroms)\n";
    s += " Number     Number       Type             X           Y           Z\n";
    s += dashes;
    for (k, (z, _, p)) in ATOMS.iter().enumerate() {
        s += &format!(
            "{:>7}{:>11}{:>12}    {:>12.6}{:>12.6}{:>12.6}\n",
            k + 1,
            z,
            0,
            p[0] * scale,
            p[1] * scale,
            p[2] * scale
        );
    }
    s + dashes
}

const HEADER: &str = " Entering Gaussian System, Link 0=g09\n Copyright (c) 1988,1990,1992,1993,1995,1998,2003,2009,2013,\n            Gaussian, Inc.  All Rights Reserved.\n";

fn route(keywords: &str) -> String {
    format!(
        " ----------------------------------------------------------------------\n #p b3lyp/sto-3g {keywords}\n ----------------------------------------------------------------------\n"
    )
}

fn gfinput() -> String {
    let mut s = " AO basis set in the form of general basis input (Overlap normalization):\n".to_string();
    for atom in 0..ATOMS.len() {
        s += &format!("{:>7} 0\n", atom + 1);
        for (letters, exponents, columns) in printed_shells(atom) {
            s += &format!(" {:<3}{:>2} 1.00       0.000000000000\n", letters, exponents.len());
            for (k, e) in exponents.iter().enumerate() {
                s += &format!("      {e:.10E}").replace('E', "D");
                for c in &columns {
                    s += &format!(" {:>17.10E}", c[k]).replace('E', "D");
                }
                s.push('\n');
            }
        }
        s += " ****\n";
    }
    s + " \n"
}

/// A section of orbitals in Gaussian's layout: coefficients given in the model's order, printed
/// in Gaussian's, 5 decimals, 5 columns a block.
fn mo_section_text(header: &str, basis: &Basis, orbitals: &[Vec<f64>], occupied: usize) -> String {
    let pure = basis.shells.iter().any(|s| s.kind == ShellKind::Pure);
    // Rows: (atom on first row, label, model index).
    let mut rows = Vec::new();
    let mut first = 0;
    let mut last_atom = usize::MAX;
    for s in &basis.shells {
        let n = s.l + 1;
        let order: Vec<usize> = if s.kind == ShellKind::Cartesian && s.l >= 2 {
            let model = cartesian_powers(s.l);
            super::super::fchk::gaussian_cartesian_order(s.l)
                .iter()
                .map(|p| model.iter().position(|q| q == p).unwrap())
                .collect()
        } else {
            (0..s.n_functions()).collect()
        };
        for (label, k) in labels(s.l, pure, n).into_iter().zip(order) {
            let atom = (s.atom != last_atom).then_some(s.atom);
            last_atom = s.atom;
            rows.push((atom, label, first + k));
        }
        first += s.n_functions();
    }
    let mut t = format!("     {header}\n");
    for (b, block) in orbitals.chunks(5).enumerate() {
        let numbers: String = (0..block.len()).map(|c| format!("{:>10}", b * 5 + c + 1)).collect();
        t += &format!("{:>21}{numbers}\n", "");
        let occ: String = (0..block.len())
            .map(|c| format!("{:>10}", if b * 5 + c < occupied { "(A1)--O" } else { "(B2)--V" }))
            .collect();
        t += &format!("{:>21}{occ}\n", "");
        let e: String = (0..block.len()).map(|c| format!("{:>10.5}", -1.0 + 0.1 * (b * 5 + c) as f64)).collect();
        t += &format!("     Eigenvalues --{e}\n");
        for (r, (atom, label, k)) in rows.iter().enumerate() {
            let head = match atom {
                Some(a) => format!("{:>4} {:<3} {:<2} {:<9}", r + 1, a + 1, ATOMS[*a].1, label),
                None => format!("{:>4}        {:<9}", r + 1, label),
            };
            let v: String = block.iter().map(|o| format!("{:>10.5}", o[*k])).collect();
            t += &format!("{head}{v}\n");
        }
    }
    t
}

struct Written {
    text: String,
    basis: Basis,
    alpha: Vec<Vec<f64>>,
    beta: Vec<Vec<f64>>,
}

/// A single point: `pop=full gfinput`, restricted or unrestricted, pure or cartesian.
fn single_point(pure: bool, unrestricted: bool) -> Written {
    let basis = model_basis(pure);
    let alpha = orbitals(&basis, 0.3);
    let beta = orbitals(&basis, 1.7);
    let kinds = if pure { "(5D, 7F)" } else { "(6D, 10F)" };
    let mut text = format!("{HEADER}{}", route("pop=full gfinput"));
    text += &orientation_table("Input orientation:", 1.0);
    text += &orientation_table("Standard orientation:", 1.0);
    text += &format!(" Standard basis: STO-3G {kinds}\n");
    text += &gfinput();
    text += "     5 alpha electrons        5 beta electrons\n";
    text += " SCF Done:  E(RB3LYP) =  -76.0123456789     A.U. after    9 cycles\n";
    if unrestricted {
        text += &mo_section_text("Alpha Molecular Orbital Coefficients:", &basis, &alpha, 5);
        text += &mo_section_text("Beta Molecular Orbital Coefficients:", &basis, &beta, 4);
        text += "     Alpha Density Matrix:\n";
    } else {
        text += &mo_section_text("Molecular Orbital Coefficients:", &basis, &alpha, 5);
        text += "     Density Matrix:\n";
    }
    text += " Normal termination of Gaussian 09\n";
    Written { text, basis, alpha, beta }
}

fn read(text: &str) -> Result<Document, ParseError> {
    parse("t.log", text, Some(&reference_overlap))
}

/// Values of each orbital at a few points, through the model's evaluator.
fn values(basis: &Basis, orbitals: &[&[f64]]) -> Vec<f64> {
    let mut wf = Wavefunction { basis: basis.clone(), ..Default::default() };
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
    normalize_contractions(&mut wf);
    let pb = PreparedBasis::new(&wf.basis);
    let points: Vec<DVec3> =
        (0..12).map(|k| DVec3::new((k as f64).sin(), (1.3 * k as f64).cos(), 0.2 * k as f64 - 1.0) * 1.5).collect();
    wf.orbitals
        .iter()
        .flat_map(|o| points.iter().map(|&p| pb.orbital_value(&o.coefficients, p)).collect::<Vec<_>>())
        .collect()
}

fn check_same_orbitals(w: &Written, doc: &Document) {
    let wf = doc.wavefunction.as_ref().expect("orbitals");
    assert_eq!(wf.basis.n_functions(), w.basis.n_functions());
    for spin in [Spin::Alpha, Spin::Beta] {
        let expected = if spin == Spin::Alpha { &w.alpha } else { &w.beta };
        let read: Vec<&[f64]> = wf.of_spin(spin).map(|(_, o)| o.coefficients.as_slice()).collect();
        if spin == Spin::Beta && wf.restricted {
            assert!(read.is_empty());
            continue;
        }
        let want: Vec<&[f64]> = expected.iter().map(Vec::as_slice).collect();
        let (a, b) = (values(&wf.basis, &read), values(&w.basis, &want));
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(
            worst < 1e-4 * scale,
            "{spin:?} (pure {}): orbital values differ by {worst:e} (largest {scale:e})",
            w.basis.shells.iter().any(|s| s.kind == ShellKind::Pure)
        );
    }
}

#[test]
fn restricted_orbitals_read_back_pure_and_cartesian() {
    for pure in [true, false] {
        let w = single_point(pure, false);
        let doc = read(&w.text).unwrap_or_else(|e| panic!("{e}"));
        let wf = doc.wavefunction.as_ref().unwrap();
        assert!(wf.restricted);
        assert_eq!(wf.basis.n_functions(), if pure { 19 } else { 23 });
        let kinds: Vec<ShellKind> = wf.basis.shells.iter().filter(|s| s.l >= 2).map(|s| s.kind).collect();
        let want = if pure { ShellKind::Pure } else { ShellKind::Cartesian };
        assert!(kinds.iter().all(|&k| k == want), "{kinds:?}");
        check_same_orbitals(&w, &doc);
        let n = &wf.normalization;
        assert_eq!((n.program.as_str(), n.repair.as_str(), n.printed_decimals), ("Gaussian", "none", Some(5)));
        assert!(n.residual > 1e-7 && n.residual < n.expected_residual(), "{n:?}");
        assert_eq!(wf.orbitals.iter().filter(|o| o.occupation == 2.0).count(), 5);
        assert_eq!(wf.orbitals[0].symmetry, "A1");
        assert!((wf.orbitals[1].energy + 0.9).abs() < 1e-12);
        assert_eq!(doc.molecule.atoms.len(), 3);
        let o = DVec3::from_array(ATOMS[1].2) * BOHR_PER_ANGSTROM;
        assert!(doc.molecule.atoms[1].position.distance(o) < 1e-9);
        assert!(doc.title.contains("pop=full gfinput"), "{}", doc.title);
    }
}

#[test]
fn unrestricted_orbitals_keep_both_spins() {
    let w = single_point(true, true);
    let doc = read(&w.text).unwrap_or_else(|e| panic!("{e}"));
    let wf = doc.wavefunction.as_ref().unwrap();
    assert!(!wf.restricted);
    check_same_orbitals(&w, &doc);
    let occupied = |spin| wf.of_spin(spin).filter(|(_, o)| o.occupation == 1.0).count();
    assert_eq!((occupied(Spin::Alpha), occupied(Spin::Beta)), (5, 4));
}

#[test]
fn a_basis_line_that_contradicts_the_labels_is_refused() {
    let w = single_point(true, false);
    let text = w.text.replace("(5D, 7F)", "(6D, 10F)");
    let e = read(&text).unwrap_err();
    let line = text.lines().position(|l| l.contains("3D 0")).unwrap() + 1;
    assert_eq!(e.line, line, "{e}");
    assert!(e.expected.contains("cartesian D"), "{e}");
}

#[test]
fn a_truncated_orbital_block_names_its_file_and_line() {
    let w = single_point(false, false);
    // Cut the third block after its tenth row.
    let lines: Vec<&str> = w.text.lines().collect();
    let block = lines.iter().position(|l| column_numbers(l).is_some_and(|n| n[0] == 11)).unwrap();
    let cut = block + 3 + 10;
    let text = lines[..cut].join("\n") + "\n     Density Matrix:\n";
    let e = read(&text).unwrap_err();
    assert_eq!(e.file, "t.log");
    assert_eq!(e.line, cut + 1, "{e}");
    assert!(e.expected.contains("23 rows of coefficients for orbitals 11–15"), "{e}");
    assert!(e.to_string().starts_with(&format!("t.log:{}:", cut + 1)), "{e}");
}

#[test]
fn a_log_without_orbitals_opens_its_frames_and_says_what_prints_them() {
    let mut text = format!("{HEADER}{}", route("opt"));
    for (k, scale) in [1.0, 1.01, 1.02].iter().enumerate() {
        text += &orientation_table("Standard orientation:", *scale);
        text += &format!(" SCF Done:  E(RB3LYP) =  -76.01{k}000000     A.U. after    9 cycles\n");
    }
    text += " Optimization completed.\n";
    text += &orientation_table("Standard orientation:", 1.02);
    let doc = read(&text).unwrap_or_else(|e| panic!("{e}"));
    assert!(doc.wavefunction.is_none());
    let s = &doc.structure.as_ref().expect("frames").structure;
    assert_eq!(s.models.len(), 3, "the repeated final geometry is no new frame");
    let energies: Vec<Option<f64>> = s.models.iter().map(|m| m.energy).collect();
    assert_eq!(energies, vec![Some(-76.01), Some(-76.011), Some(-76.012)]);
    assert!(doc.problems.iter().any(|p| p.contains("pop=full gfinput")), "{:?}", doc.problems);
    let z2 = s.position[s.models[2].atoms.start as usize + 1].y;
    assert!((z2 - ATOMS[1].2[1] * 1.02 * BOHR_PER_ANGSTROM).abs() < 1e-5);

    // The basis printed, the orbitals not: the keyword that prints them is named.
    let with_basis = text.replace(" Optimization completed.\n", &gfinput());
    let doc = read(&with_basis).unwrap();
    assert!(doc.problems.iter().any(|p| p.contains("add `pop=full`")), "{:?}", doc.problems);
}

#[test]
fn a_log_without_geometry_is_refused() {
    let e = read(&format!("{HEADER}{}", route("sp"))).unwrap_err();
    assert!(e.expected.contains("Standard orientation"), "{e}");
}

/// Frequencies as Gaussian prints them: the hpmodes blocks (5 a block, `---`) and the usual
/// ones (3 a block, 2 decimals).
fn frequency_text(hp: bool) -> String {
    let freqs = [-120.5, 1598.42, 3657.1, 3756.2];
    let intensities = [3.5, 63.8, 4.1, 45.0];
    let disp = |m: usize, a: usize, c: usize| ((m * 9 + a * 3 + c) as f64 * 0.37).sin() * 0.5;
    let mut s = " Harmonic frequencies (cm**-1), IR intensities (KM/Mole), Raman scattering\n activities (A**4/AMU), depolarization ratios for plane and unpolarized\n incident light, reduced masses (AMU), force constants (mDyne/A),\n and normal coordinates:\n".to_string();
    let per = if hp { 5 } else { 3 };
    for start in (0..freqs.len()).step_by(per) {
        let ms: Vec<usize> = (start..freqs.len().min(start + per)).collect();
        let w = if hp { 10 } else { 23 };
        s += &format!("{:>17}", "");
        s += &ms.iter().map(|m| format!("{:>w$}", m + 1)).collect::<String>();
        s += "\n";
        s += &format!("{:>17}{}\n", "", ms.iter().map(|_| format!("{:>w$}", "A1")).collect::<String>());
        if hp {
            s += &format!(
                "       Frequencies ---{}\n",
                ms.iter().map(|&m| format!("{:>10.4}", freqs[m])).collect::<String>()
            );
            s += &format!(
                "    IR Intensities ---{}\n",
                ms.iter().map(|&m| format!("{:>10.4}", intensities[m])).collect::<String>()
            );
            s += " Coord Atom Element:\n";
            for (a, atom) in ATOMS.iter().enumerate() {
                for c in 0..3 {
                    let v: String = ms.iter().map(|&m| format!("{:>10.5}", disp(m, a, c))).collect();
                    s += &format!("{:>4}{:>6}{:>6}      {v}\n", c + 1, a + 1, atom.0);
                }
            }
        } else {
            s += &format!(
                " Frequencies --{}\n",
                ms.iter().map(|&m| format!("{:>12.4}{:>11}", freqs[m], "")).collect::<String>()
            );
            s += &format!(
                " IR Inten    --{}\n",
                ms.iter().map(|&m| format!("{:>12.4}{:>11}", intensities[m], "")).collect::<String>()
            );
            s += "  Atom  AN      X      Y      Z        X      Y      Z        X      Y      Z\n";
            for (a, atom) in ATOMS.iter().enumerate() {
                let v: String = ms
                    .iter()
                    .map(|&m| (0..3).map(|c| format!("{:>7.2}", disp(m, a, c))).collect::<String>() + "  ")
                    .collect();
                s += &format!("{:>6}{:>4}  {v}\n", a + 1, atom.0);
            }
        }
    }
    s
}

#[test]
fn normal_modes_are_read_from_either_layout_hpmodes_first() {
    let base = format!("{HEADER}{}{}", route("freq"), orientation_table("Standard orientation:", 1.0))
        + " SCF Done:  E(RB3LYP) =  -76.0123456789     A.U. after    9 cycles\n";
    let low =
        read(&(base.clone() + &frequency_text(false) + " - Thermochemistry -\n")).unwrap_or_else(|e| panic!("{e}"));
    let both = read(&(base + &frequency_text(true) + &frequency_text(false))).unwrap_or_else(|e| panic!("{e}"));
    for (doc, digits) in [(&low, 0.005), (&both, 5e-6)] {
        let v = doc.vibrations.as_ref().expect("modes");
        assert_eq!(v.modes.len(), 4);
        assert_eq!(v.modes[0].frequency_cm1, -120.5);
        assert_eq!(v.modes[3].ir_intensity, Some(45.0));
        let want = ((3 * 9 + 2 * 3 + 1) as f64 * 0.37).sin() * 0.5;
        assert!((v.modes[3].displacement[2].y - want).abs() <= digits, "{:?}", v.modes[3].displacement[2]);
        assert_eq!(v.geometry.len(), 3);
    }
    // The hpmodes' five decimals, not the two of the blocks after them.
    let d = both.vibrations.as_ref().unwrap().modes[1].displacement[1].x;
    assert!((d * 100.0 - (d * 100.0).round()).abs() > 1e-6, "{d}");
}

#[test]
fn a_relaxed_scan_keeps_the_converged_geometry_of_each_point() {
    let mut text = format!("{HEADER}{}", route("opt=modredundant"));
    // Two points of two optimisation steps each; each point ends with its converged geometry.
    let mut k = 0;
    for point in 0..2 {
        for step in 0..2 {
            let scale = 1.0 + 0.01 * (2 * point + step) as f64;
            text += &orientation_table("Standard orientation:", scale);
            text += &format!(" SCF Done:  E(RB3LYP) =  -76.0{k}0000000     A.U. after    9 cycles\n");
            k += 1;
        }
        text += " Optimization completed.\n    -- Stationary point found.\n";
        text += &orientation_table("Standard orientation:", 1.0 + 0.01 * (2 * point + 1) as f64);
    }
    let doc = read(&text).unwrap_or_else(|e| panic!("{e}"));
    let s = &doc.structure.as_ref().expect("frames").structure;
    let energies: Vec<Option<f64>> = s.models.iter().map(|m| m.energy).collect();
    assert_eq!(energies, vec![Some(-76.01), Some(-76.03)], "{:?}", s.models);
    // Without a second "Optimization completed" every step is a frame.
    let one = text.replacen(" Optimization completed.", " Optimization stopped.", 1);
    let doc = read(&one).unwrap();
    assert_eq!(doc.structure.as_ref().unwrap().structure.models.len(), 4);
}

#[test]
fn a_td_table_opens_with_the_log_and_a_malformed_one_is_left_out() {
    let mut text = format!("{HEADER}{}", route("td(nstates=2)"));
    text += &orientation_table("Standard orientation:", 1.0);
    text += " Excitation energies and oscillator strengths:\n\n";
    text += " Excited State   1:      Singlet-B2     7.1234 eV  174.05 nm  f=0.0312  <S**2>=0.000\n";
    text += "       5 ->  6         0.70123\n\n";
    text += " Excited State   2:      Triplet-A1     8.0000 eV  154.98 nm  f=0.0000  <S**2>=2.000\n";
    text += "       4 ->  6         0.69000\n";
    let doc = read(&text).unwrap_or_else(|e| panic!("{e}"));
    let states = doc.excited.as_ref().expect("states");
    assert_eq!(states.states.len(), 2);
    assert_eq!((states.states[0].symmetry.as_str(), states.states[1].spin.as_str()), ("B2", "Triplet"));
    assert_eq!(states.states[1].transitions[0].from, 4);
    // An energy that is no number: the states are left out, saying where; the atoms open.
    let broken = text.replace("8.0000 eV", "8.00x0 eV");
    let doc = read(&broken).unwrap_or_else(|e| panic!("{e}"));
    assert!(doc.excited.is_none() && doc.molecule.atoms.len() == ATOMS.len());
    assert!(
        doc.problems.iter().any(|p| p.contains("excited states left out") && p.contains(":")),
        "{:?}",
        doc.problems
    );
}
