//! NWChem outputs: H₂ in NWChem 6.5's layout (tests/fixtures/logs/h2_nwchem.out), cut, altered
//! and without orbitals.

use super::super::ref_overlap::reference_overlap;
use super::*;

const H2: &str = include_str!("../../tests/fixtures/logs/h2_nwchem.out");

fn read(text: &str) -> Result<Document, ParseError> {
    parse("h2.out", text, Some(&reference_overlap))
}

#[test]
fn the_final_vectors_open_with_the_analysis_energies() {
    let doc = read(H2).unwrap();
    let wf = doc.wavefunction.as_ref().expect("orbitals");
    assert_eq!(doc.molecule.atoms[0].position.z, 0.37 * BOHR_PER_ANGSTROM);
    assert_eq!((wf.basis.shells.len(), wf.orbitals.len()), (2, 2));
    assert_eq!([wf.orbitals[0].occupation, wf.orbitals[1].occupation], [2.0, 0.0]);
    assert_eq!((wf.orbitals[0].energy, wf.orbitals[1].symmetry.as_str()), (-0.5785538, "b1u"));
    assert_eq!(wf.orbitals[1].coefficients, vec![1.21245, -1.21245]);
    let n = &wf.normalization;
    assert_eq!((n.program.as_str(), n.printed_decimals), ("NWChem", Some(5)));
    assert!(n.residual < n.expected_residual(), "{n:?}");
    assert!(doc.problems.is_empty(), "{:?}", doc.problems);
}

#[test]
fn orbitals_the_analysis_leaves_out_take_the_shells_occupations() {
    let text = H2.replacen(" Vector    2  Occ=0.000000D+00  E= 6.711370D-01  Symmetry=b1u\n", "", 1);
    let doc = read(&text).unwrap();
    let wf = doc.wavefunction.as_ref().unwrap();
    assert!(wf.orbitals[1].energy.is_nan() && wf.orbitals[1].occupation == 0.0);
    assert!(doc.problems.iter().any(|p| p.contains("1 orbitals have no energy")), "{:?}", doc.problems);
}

#[test]
fn a_vector_block_cut_short_is_refused_at_its_line() {
    let rows = H2.find("       ----------- -----------\n").unwrap() + 31;
    let end = rows + H2[rows..].find('\n').unwrap() + 1;
    let cut = format!("{}\n center of mass\n", &H2[..end]);
    let e = read(&cut).unwrap_err();
    assert!(e.expected.contains("2 rows of coefficients"), "{e}");
    assert_eq!(e.line, cut.lines().position(|l| l.contains("Final MO vectors")).unwrap() + 1, "{e}");
    // A basis that gives the atoms more functions than the vectors have rows.
    let more =
        H2.replacen("  1 S  1.68855400E-01  0.444635\n", "  1 S  1.68855400E-01  0.444635\n\n  2 P  1.0E+00  1.0\n", 1);
    let e = read(&more).unwrap_err();
    assert!(e.expected.contains("8 rows of coefficients"), "{e}");
}

#[test]
fn without_printed_vectors_the_atoms_open_naming_the_keyword() {
    let cut = &H2[..H2.find("                                 Final MO vectors").unwrap()];
    let doc = read(cut).unwrap();
    assert!(doc.wavefunction.is_none());
    assert!(doc.problems.iter().any(|p| p.contains("print \"final vectors\"")), "{:?}", doc.problems);
}

/// H₂⁺-like occupations in an unrestricted job's layout (NWChem 6.5's DFT module): the alpha and
/// beta analyses, then `global array: alpha evecs…` and `… beta evecs…` blocks.
#[test]
fn an_unrestricted_jobs_alpha_and_beta_vectors_open() {
    let vectors = H2.find(" global array: scf_init").unwrap();
    let blocks_end = H2.find(" center of mass").unwrap();
    let blocks = &H2[H2[vectors..].find('\n').unwrap() + vectors + 1..blocks_end];
    let text = format!(
        "{}{}{}{}{}",
        &H2[..vectors],
        " global array: alpha evecs[1:2,1:2],  handle: -995 \n",
        blocks,
        " global array: beta evecs[1:2,1:2],  handle: -990 \n",
        &H2[vectors + H2[vectors..].find('\n').unwrap() + 1..]
    )
    .replacen("ROHF Final Molecular Orbital Analysis", "DFT Final Alpha Molecular Orbital Analysis", 1)
    .replacen(
        "\n\n                                 Final MO vectors",
        "\n                       DFT Final Beta Molecular Orbital Analysis\n\n Vector    1  Occ=0.000000D+00  E=-4.000000D-01  Symmetry=ag\n Vector    2  Occ=0.000000D+00  E= 7.000000D-01  Symmetry=b1u\n\n                                 Final MO vectors",
        1,
    )
    .replacen("Occ=2.000000D+00", "Occ=1.000000D+00", 1);
    let doc = read(&text).unwrap_or_else(|e| panic!("{e}"));
    let wf = doc.wavefunction.as_ref().expect("orbitals");
    assert!(!wf.restricted);
    let spins: Vec<(Spin, f64, f64)> = wf.orbitals.iter().map(|o| (o.spin, o.occupation, o.energy)).collect();
    assert_eq!(
        spins,
        vec![
            (Spin::Alpha, 1.0, -0.5785538),
            (Spin::Alpha, 0.0, 0.671137),
            (Spin::Beta, 0.0, -0.4),
            (Spin::Beta, 0.0, 0.7)
        ]
    );
    assert!(wf.normalization.residual < wf.normalization.expected_residual());
    // The beta vectors cut short.
    let cut = &text[..text.rfind("   2  ").unwrap()];
    let e = read(cut).unwrap_err();
    assert!(e.expected.contains("rows of coefficients"), "{e}");
}
