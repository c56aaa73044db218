//! A structure's NCI from its spherical atoms, as the window and `render --nci` make it: of all
//! its atoms, or between a selection (a ligand) and the rest (its pocket). Checked against
//! `orbcloud nci --promolecular --intermolecular` of the same atoms given as two files.

use orbcloud::cli::{NciOptions, nci_of};
use orbcloud::evaluate::promolecular;
use orbcloud::model::nci::CUT_VALUE;
use orbcloud::model::orbitals::Quantity;
use orbcloud::model::{Document, Molecule};

const DIMER_PDB: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/nci/water_dimer.pdb");

/// The document's atoms `range` as a document of their own (a fragment's file).
fn part(doc: &Document, range: std::ops::Range<usize>) -> Document {
    let molecule = Molecule::new(doc.molecule.atoms[range].to_vec());
    Document { source: "part".into(), molecule, ..Document::default() }
}

#[test]
fn a_selections_interaction_with_the_rest_is_that_of_two_fragments_files() {
    let doc = orbcloud::formats::load(std::path::Path::new(DIMER_PDB)).unwrap();
    let window = promolecular::grid(&doc, Quantity::NciGradient, Some("resn LIG"), 40).unwrap();
    // The donor (HOH 1) and the acceptor (LIG 2), as `orbcloud nci A B` reads two files.
    let (donor, acceptor) = (part(&doc, 0..3), part(&doc, 3..6));
    let spec = orbcloud::model::GridSpec::new(
        window.origin(),
        [window.step(0), window.step(1), window.step(2)],
        window.dims,
    );
    let options = NciOptions {
        promolecular: true,
        grid: Some(spec),
        rdg_cut: Some(f64::from(CUT_VALUE)),
        intermolecular: true,
        ..NciOptions::default()
    };
    let cubes = nci_of(&[&acceptor, &donor], &["acceptor".into(), "donor".into()], &options).unwrap();
    assert_eq!(window.values.len(), cubes.grids.grad.len());
    let differ = window.values.iter().zip(&cubes.grids.grad).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "points where the window's field and `nci`'s differ");
    // The hydrogen bond: points of low s, kept only between the molecules, attractive.
    let low: Vec<usize> = (0..window.values.len()).filter(|&k| window.values[k] < 0.3).collect();
    assert!(low.len() >= 5, "{} points with s < 0.3", low.len());
    let [_, ny, nz] = window.dims;
    let (h, o) = (doc.molecule.atoms[2].position, doc.molecule.atoms[3].position);
    for &k in &low {
        let p = window.point(k / (ny * nz), k / nz % ny, k % nz);
        let along = (p - h).dot(o - h) / (o - h).length_squared();
        assert!((0.0..1.0).contains(&along), "a point of low s at {p} lies off the bond H···O ({along:.2})");
        assert!(cubes.grids.dens[k] < 0.0, "100·sign(λ₂)ρ there: {}", cubes.grids.dens[k]);
    }
    // All the atoms, no selection: the same disc is there, with more kept around it.
    let whole = promolecular::grid(&doc, Quantity::NciGradient, None, 40).unwrap();
    let kept = |v: &[f32]| v.iter().filter(|&&s| s < CUT_VALUE).count();
    assert!(whole.values.iter().any(|&s| s < 0.3), "no disc without a selection");
    assert!(kept(&whole.values) > 0 && kept(&window.values) > 0);
}

#[test]
fn a_structure_without_hydrogens_is_told_its_surfaces_are_small() {
    let pdb = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/structures/4e43_excerpt.pdb");
    let doc = orbcloud::formats::load(std::path::Path::new(pdb)).unwrap();
    let note = promolecular::note(&doc).expect("a note");
    assert!(note.contains("no hydrogens"), "{note}");
    let dimer = orbcloud::formats::load(std::path::Path::new(DIMER_PDB)).unwrap();
    assert_eq!(promolecular::note(&dimer), None);
}
