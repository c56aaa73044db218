//! GAMESS-US outputs: H₂ in GAMESS 2017's layout (tests/fixtures/logs/h2_gamess.out: one
//! symmetry-unique atom printed in the basis for two atoms), cut, altered and without orbitals.

use super::super::ref_overlap::reference_overlap;
use super::*;

const H2: &str = include_str!("../../tests/fixtures/logs/h2_gamess.out");

fn read(text: &str) -> Result<Document, ParseError> {
    parse("h2.out", text, Some(&reference_overlap))
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn every_atom_takes_the_shells_of_its_unique_atom() {
    let doc = read(H2).unwrap();
    let wf = doc.wavefunction.as_ref().expect("orbitals");
    assert_eq!((doc.molecule.atoms.len(), wf.basis.shells.len(), wf.orbitals.len()), (2, 2, 2));
    assert_eq!(wf.basis.shells[1].atom, 1);
    assert_eq!(wf.basis.shells[1].center.z, -0.699199);
    assert_eq!([wf.orbitals[0].occupation, wf.orbitals[1].occupation], [2.0, 0.0]);
    assert_eq!((wf.orbitals[0].energy, wf.orbitals[1].symmetry.as_str()), (-0.5786, "A2U"));
    assert_eq!(wf.orbitals[1].coefficients, vec![1.212452, -1.212452]);
    let n = &wf.normalization;
    assert_eq!((n.program.as_str(), n.printed_decimals), ("GAMESS", Some(6)));
    assert!(n.residual < n.expected_residual(), "{n:?}");
}

#[test]
fn an_orbital_block_cut_short_is_refused_at_its_line() {
    let cut = H2.replacen("    2  H  2  S", " ...... END OF RHF", 1);
    let e = read(&cut).unwrap_err();
    assert_eq!(e.line, line_of(&cut, "    1  H  1  S") + 1, "{e}");
    assert!(e.to_string().starts_with("h2.out:"), "{e}");
    // Cut inside the block (the file ends there): refused, naming the line where it stopped.
    let end = H2.find("    2  H  2  S").unwrap();
    let e = read(&H2[..end]).unwrap_err();
    assert!(e.expected.contains("rows of coefficients") || e.expected.contains("functions"), "{e}");
    // A row naming an atom whose functions the basis does not give it.
    let bad = H2.replacen("    2  H  2  S", "    2  H  1  S", 1);
    let e = read(&bad).unwrap_err();
    assert!(e.expected.contains("atom 2") || e.expected.contains("atom named H"), "{e}");
}

#[test]
fn a_shell_claiming_an_unknown_type_is_refused_at_its_line() {
    let bad = H2.replacen("      1   S       2", "      1   Q       2", 1);
    let e = read(&bad).unwrap_err();
    assert_eq!(e.line, line_of(&bad, "      1   Q       2"), "{e}");
}

#[test]
fn without_printed_orbitals_the_atoms_open_naming_the_keyword() {
    let cut = &H2[..H2.find("          ------------\n          EIGENVECTORS").unwrap()];
    let doc = read(cut).unwrap();
    assert!(doc.wavefunction.is_none());
    assert_eq!(doc.molecule.atoms.len(), 2);
    assert!(doc.problems.iter().any(|p| p.contains("NPRINT")), "{:?}", doc.problems);
}

#[test]
fn row_heads_split_where_the_label_fills_its_field() {
    assert_eq!(row_head("    1  C  1  S  "), Some((1, 1, "S")));
    assert_eq!(row_head("   56  C  1XXXX"), Some((56, 1, "XXXX")));
    assert_eq!(row_head("  120  CL 12 XYZ"), Some((120, 12, "XYZ")));
    assert_eq!(row_head("  NUMBER OF"), None);
}
