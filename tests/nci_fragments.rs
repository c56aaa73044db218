//! Non-covalent interactions of several densities as the window and `render --nci` make them:
//! a structure's spherical atoms between a selection (a ligand) and the rest (its pocket), and
//! two files' wavefunctions as fragments. Checked against `orbcloud nci` (`nci_of`) of the same
//! densities given as two files, on the same grid.

use std::sync::Arc;

use orbcloud::cli::{NciOptions, nci_of};
use orbcloud::evaluate::interaction::{self, Kind};
use orbcloud::evaluate::meshes::{Evaluating, values_at};
use orbcloud::model::nci::CUT_VALUE;
use orbcloud::model::orbitals::Quantity;
use orbcloud::model::{Document, GridSpec, Molecule, VolumeGrid};
use orbcloud::scene::Fragments;

const DIMER_PDB: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/nci/water_dimer.pdb");

fn load(path: &str) -> Document {
    orbcloud::formats::load(std::path::Path::new(path)).unwrap()
}

fn fixture(name: &str) -> String {
    format!("{}/tests/fixtures/nci/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// The document's atoms `range` as a document of their own (a fragment's file).
fn part(doc: &Document, range: std::ops::Range<usize>) -> Document {
    let molecule = Molecule::new(doc.molecule.atoms[range].to_vec());
    Document { source: "part".into(), molecule, ..Document::default() }
}

/// `orbcloud nci`'s `-grad` grid of `docs` on `field`'s grid, every s kept, only between them.
fn nci_between(docs: &[&Document], promolecular: bool, field: &VolumeGrid) -> (Vec<f32>, Vec<f32>) {
    let spec = GridSpec::new(field.origin(), [field.step(0), field.step(1), field.step(2)], field.dims);
    let options = NciOptions {
        promolecular,
        grid: Some(spec),
        rdg_cut: Some(f64::from(CUT_VALUE)),
        intermolecular: true,
        ..NciOptions::default()
    };
    let names: Vec<String> = (0..docs.len()).map(|k| format!("fragment {k}")).collect();
    let cubes = nci_of(docs, &names, &options).unwrap();
    (cubes.grids.grad, cubes.grids.dens)
}

/// The points of `field` with s below `level`, each checked to lie across the hydrogen bond
/// from the donor's H (`h`) to the acceptor's O (`o`) where sign(λ₂)ρ < 0.
fn check_disc(field: &VolumeGrid, dens: &[f32], level: f32, h: glam::DVec3, o: glam::DVec3) {
    let low: Vec<usize> = (0..field.values.len()).filter(|&k| field.values[k] < level).collect();
    assert!(low.len() >= 5, "{} points with s < {level}", low.len());
    let [_, ny, nz] = field.dims;
    for &k in &low {
        let p = field.point(k / (ny * nz), k / nz % ny, k % nz);
        let along = (p - h).dot(o - h) / (o - h).length_squared();
        assert!((0.0..1.0).contains(&along), "a point of low s at {p} lies off the bond H···O ({along:.2})");
        assert!(dens[k] < 0.0, "100·sign(λ₂)ρ there: {}", dens[k]);
    }
}

#[test]
fn a_selections_interaction_with_the_rest_is_that_of_two_fragments_files() {
    let doc = load(DIMER_PDB);
    let between = Fragments { selection: Some("resn LIG".into()), ..Fragments::default() };
    let field = interaction::grid(&doc, Kind::Spherical, &between, &[], Quantity::NciGradient, 40).unwrap();
    // The acceptor (LIG 2, the selection) and the donor (HOH 1), as `orbcloud nci A B` reads
    // two files, summed in the same order.
    let (acceptor, donor) = (part(&doc, 3..6), part(&doc, 0..3));
    let (grad, dens) = nci_between(&[&acceptor, &donor], true, &field);
    let differ = field.values.iter().zip(&grad).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "points where the window's field and `nci`'s differ");
    let atoms = &doc.molecule.atoms;
    check_disc(&field, &dens, 0.3, atoms[2].position, atoms[3].position);
    // All the atoms, no selection: the same disc is there.
    let whole = interaction::grid(&doc, Kind::Spherical, &Fragments::default(), &[], Quantity::NciGradient, 40);
    assert!(whole.unwrap().values.iter().any(|&s| s < 0.3), "no disc without a selection");
}

#[test]
fn two_files_wavefunctions_add_as_fragments_and_their_hydrogen_bond_lies_between_them() {
    let (donor, acceptor) =
        (Arc::new(load(&fixture("water_donor_631gs.molden"))), load(&fixture("water_acceptor_631gs.molden")));
    let acceptor = Arc::new(acceptor);
    let with = Fragments { files: vec![donor.source.clone()], between_only: true, ..Fragments::default() };
    let open = [donor.clone(), acceptor.clone()];
    let field = interaction::grid(&acceptor, Kind::Wavefunction, &with, &open, Quantity::NciGradient, 64).unwrap();
    let (grad, dens) = nci_between(&[&acceptor, &donor], false, &field);
    let differ = field.values.iter().zip(&grad).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "points where the window's field and `nci`'s differ");
    check_disc(&field, &dens, 0.5, donor.molecule.atoms[2].position, acceptor.molecule.atoms[0].position);
    // Coloured by the sum's sign(λ₂)ρ (what `nci` writes there), not the acceptor's own.
    let [_, ny, nz] = field.dims;
    let k = (0..field.values.len()).min_by(|&a, &b| field.values[a].total_cmp(&field.values[b])).unwrap();
    let p = field.point(k / (ny * nz), k / nz % ny, k % nz).as_vec3();
    let of = Evaluating { doc: &acceptor, fragments: &with, others: &open };
    let source = orbcloud::scene::Source::Wavefunction(Quantity::SignLambda2Rho);
    let summed = values_at(of, source, &[p])[0].unwrap();
    let alone = values_at(Evaluating::alone(&acceptor), source, &[p])[0].unwrap();
    assert!((summed - f64::from(dens[k]) / 100.0).abs() < 1e-6, "sign(λ₂)ρ {summed} against nci's {}", dens[k]);
    assert!(summed < -0.01 && (summed - alone).abs() > 0.005, "sign(λ₂)ρ: {summed:.4} summed, {alone:.4} alone");
    // A fragment not open, or without a wavefunction, is named.
    let missing = Fragments { files: vec!["elsewhere.molden".into()], ..Fragments::default() };
    let err = interaction::grid(&acceptor, Kind::Wavefunction, &missing, &open, Quantity::NciGradient, 20).unwrap_err();
    assert!(err.contains("elsewhere.molden") && err.contains("not open"), "{err}");
    let structure = Arc::new(load(DIMER_PDB));
    let mixed = Fragments { files: vec![structure.source.clone()], ..Fragments::default() };
    let err =
        interaction::grid(&acceptor, Kind::Wavefunction, &mixed, &[structure], Quantity::NciGradient, 20).unwrap_err();
    assert!(err.contains("no wavefunction"), "{err}");
}

#[test]
fn a_structure_without_hydrogens_is_told_its_surfaces_are_small() {
    let pdb = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/structures/4e43_excerpt.pdb");
    let note = interaction::note(&load(pdb)).expect("a note");
    assert!(note.contains("no hydrogens"), "{note}");
    assert_eq!(interaction::note(&load(DIMER_PDB)), None);
}
