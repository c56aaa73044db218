//! Psi4 outputs: H₂ in Psi4 1.3's layout (tests/fixtures/logs/h2_psi4.out), cut, altered and
//! without orbitals; the labels of pure and cartesian functions.

use super::super::ref_overlap::reference_overlap;
use super::*;

const H2: &str = include_str!("../../tests/fixtures/logs/h2_psi4.out");

fn read(text: &str) -> Result<Document, ParseError> {
    parse("h2.out", text, Some(&reference_overlap))
}

#[test]
fn the_printed_orbitals_open_with_their_energies_and_occupations() {
    let doc = read(H2).unwrap();
    let wf = doc.wavefunction.as_ref().expect("orbitals");
    assert_eq!((wf.basis.shells.len(), wf.orbitals.len()), (2, 2));
    assert_eq!([wf.orbitals[0].occupation, wf.orbitals[1].occupation], [2.0, 0.0]);
    assert_eq!((wf.orbitals[0].energy, wf.orbitals[1].symmetry.as_str()), (-0.5785538, "B1u"));
    let n = &wf.normalization;
    assert_eq!((n.program.as_str(), n.printed_decimals), ("Psi4", Some(7)));
    assert!(n.residual < n.expected_residual(), "{n:?}");
}

#[test]
fn labels_name_pure_and_cartesian_functions() {
    assert_eq!(function_of("p0", 1, true), Some((ShellKind::Cartesian, 2)));
    assert_eq!(function_of("p+1", 1, true), Some((ShellKind::Cartesian, 0)));
    assert_eq!(function_of("p-1", 1, true), Some((ShellKind::Cartesian, 1)));
    assert_eq!(function_of("d-2", 2, true), Some((ShellKind::Pure, 4)));
    assert_eq!(function_of("d+1", 2, true), Some((ShellKind::Pure, 1)));
    assert_eq!(function_of("dxy", 2, false), Some((ShellKind::Cartesian, 1)));
    assert_eq!(function_of("d+3", 2, true), None);
    assert_eq!(function_of("s0", 1, true), None);
}

#[test]
fn an_orbital_block_cut_short_is_refused_at_its_line() {
    let bad = H2.replacen(" 2    H2 s0", "", 1);
    let e = read(&bad).unwrap_err();
    assert!(e.expected.contains("Ene"), "{e}");
    let end = H2.find(" 2    H2 s0").unwrap();
    let e = read(&H2[..end]).unwrap_err();
    assert!(e.expected.contains("Ene"), "{e}");
    assert!(e.to_string().starts_with("h2.out:"), "{e}");
    let bad = H2.replacen(" 2    H2 s0", " 2    H1 s0", 1);
    let e = read(&bad).unwrap_err();
    assert_eq!(e.line, bad.lines().position(|l| l.starts_with(" 2    H1 s0")).unwrap() + 1, "{e}");
    assert!(e.expected.contains("function of atom 2"), "{e}");
}

#[test]
fn without_printed_orbitals_the_atoms_open_naming_the_option() {
    let cut = &H2[..H2.find("  ==> Molecular Orbitals <==").unwrap()];
    let doc = read(cut).unwrap();
    assert!(doc.wavefunction.is_none());
    assert!(doc.problems.iter().any(|p| p.contains("print_mos true")), "{:?}", doc.problems);
}
