//! The structure readers (PDB, mmCIF, XYZ) against what gemmi reads from the same files
//! (tests/fixtures/structures/expected.json, written by scripts/make_structure_fixtures.py
//! from public-domain PDB entries), and their handling of broken input.

use std::path::Path;

use orbcloud::formats;
use orbcloud::model::Document;
use orbcloud::model::units::BOHR_PER_ANGSTROM;
use serde_json::Value;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/structures");

fn load(name: &str) -> Document {
    formats::load(&Path::new(DIR).join(name)).unwrap_or_else(|e| panic!("{e}"))
}

fn expected() -> Value {
    serde_json::from_str(&std::fs::read_to_string(Path::new(DIR).join("expected.json")).unwrap()).unwrap()
}

fn close(a: &[f64], b: &Value) -> bool {
    a.iter().zip(b.as_array().unwrap()).all(|(x, y)| (x - y.as_f64().unwrap()).abs() < 1e-6)
}

#[test]
fn readers_agree_with_gemmi() {
    let expected = expected();
    let files = ["4e43_excerpt.pdb", "4e43_excerpt.cif", "4e43_shuffled.cif.gz", "nmr_excerpt.pdb", "hybrid36.pdb"];
    for name in files {
        let doc = load(name);
        let s = &doc.structure.as_ref().expect("a structure").structure;
        let models = expected[name]["models"].as_array().unwrap();
        assert_eq!(s.models.len(), models.len(), "{name}: models");
        for (m, want) in s.models.iter().zip(models) {
            let atoms: Vec<usize> = (m.atoms.start as usize..m.atoms.end as usize).collect();
            let n = |key: &str| want[key].as_u64().unwrap() as usize;
            assert_eq!(atoms.len(), n("atoms"), "{name}: atoms");
            assert_eq!(atoms.iter().filter(|&&i| s.altloc[i] != 0).count(), n("altloc_atoms"), "{name}: altlocs");
            let residues: std::collections::BTreeSet<u32> = atoms.iter().map(|&i| s.residue[i]).collect();
            assert_eq!(residues.len(), n("residues"), "{name}: residues");
            let chains: std::collections::BTreeSet<String> =
                residues.iter().map(|&r| s.chains[s.residues[r as usize].chain as usize].name.to_string()).collect();
            let want_chains: std::collections::BTreeSet<String> =
                want["chains"].as_array().unwrap().iter().map(|c| c.as_str().unwrap().to_string()).collect();
            assert_eq!(chains, want_chains, "{name}: chains");
            let at = |i: usize| (s.position[i] / BOHR_PER_ANGSTROM).to_array();
            assert!(close(&at(atoms[0]), &want["first"]), "{name}: first atom {:?}", at(atoms[0]));
            let last = *atoms.last().unwrap();
            assert!(close(&at(last), &want["last"]), "{name}: last atom");
            assert_eq!(s.serial[last] as i64, want["last_serial"].as_i64().unwrap(), "{name}: serial");
            assert_eq!(s.residues[s.residue[last] as usize].number as i64, want["last_residue"].as_i64().unwrap());
            let sum = |v: &[f32]| atoms.iter().map(|&i| v[i] as f64).sum::<f64>();
            assert!((sum(&s.b_factor) - want["b_factors_sum"].as_f64().unwrap()).abs() < 0.01, "{name}: B");
            assert!((sum(&s.occupancy) - want["occupancy_sum"].as_f64().unwrap()).abs() < 0.01, "{name}: occ");
            assert_eq!(atoms.iter().filter(|&&i| s.z[i] == 1).count(), n("hydrogens"), "{name}: hydrogens");
        }
    }
}

#[test]
fn first_altloc_is_shown_and_all_are_kept() {
    let doc = load("4e43_excerpt.pdb");
    let view = doc.structure.as_ref().unwrap();
    let s = &view.structure;
    assert_eq!(doc.molecule.atoms.len(), view.atoms.len());
    // Altloc B atoms are kept in the structure, not shown.
    assert!(view.atoms.iter().all(|&i| s.altloc[i as usize] != b'B'));
    assert_eq!(s.len() - view.atoms.len(), s.altloc.iter().filter(|&&a| a == b'B').count());
    // The helix and the strands the file declares mark their residues.
    use orbcloud::model::structure::Secondary;
    assert!(s.residues.iter().any(|r| r.secondary == Secondary::Sheet));
    // Every peptide bond of chain A 30–50 is there: one C–N bond per consecutive residue pair.
    let peptide = doc
        .molecule
        .bonds
        .iter()
        .filter(|b| {
            let (i, j) = (view.atoms[b.a as usize] as usize, view.atoms[b.b as usize] as usize);
            s.residue[i] != s.residue[j] && s.residues[s.residue[i] as usize].name.as_str() != "HOH"
        })
        .count();
    assert!(peptide >= 20, "{peptide} bonds between residues");
}

#[test]
fn pdb_and_mmcif_give_the_same_molecule() {
    let pdb = load("4e43_excerpt.pdb");
    let cif = load("4e43_shuffled.cif.gz");
    assert_eq!(pdb.molecule.atoms.len(), cif.molecule.atoms.len());
    for (a, b) in pdb.molecule.atoms.iter().zip(&cif.molecule.atoms) {
        assert_eq!(a.z, b.z);
        assert!(a.position.distance(b.position) < 1e-9);
    }
    // CONECT (PDB) adds the acetates' bonds that distances find anyway: same bond count.
    assert_eq!(pdb.molecule.bonds.len(), cif.molecule.bonds.len());
}

#[test]
fn models_and_frames_are_selectable() {
    let mut doc = load("nmr_excerpt.pdb");
    let view = doc.structure.as_mut().unwrap();
    let first = doc.molecule.atoms[0].position;
    let third = view.show(2);
    assert_eq!(view.model, 2);
    assert_eq!(third.atoms.len(), doc.molecule.atoms.len());
    assert!(third.atoms[0].position.distance(first) > 1e-3, "model 3 has its own coordinates");

    let mut traj = load("ethane_trajectory.xyz");
    let view = traj.structure.as_mut().unwrap();
    assert_eq!(view.structure.models.len(), 3);
    let dihedral = |m: &orbcloud::model::Molecule| {
        let p = |i: usize| m.atoms[i].position;
        orbcloud::model::measure::dihedral([p(2), p(0), p(1), p(3)])
    };
    let angles: Vec<f64> = (0..3).map(|k| dihedral(&view.show(k))).collect();
    for (a, want) in angles.iter().zip([60.0, 90.0, 120.0]) {
        assert!((a.abs() - want).abs() < 1e-5, "{angles:?}");
    }
    assert_eq!(view.structure.models[1].title, "ethane, H-C-C-H turned 30 degrees");
}

#[test]
fn hybrid36_conect_bonds_resolve() {
    let doc = load("hybrid36.pdb");
    let s = &doc.structure.as_ref().unwrap().structure;
    assert_eq!(s.serial[6], 100_000);
    assert_eq!(s.explicit_bonds.len(), 2);
    // Twelve waters: two O–H bonds each, no bonds between waters.
    assert_eq!(doc.molecule.bonds.len(), 24);
}

/// Broken structure files: each refused with the line and what was expected.
#[test]
fn broken_structures_name_file_and_line() {
    let atom = "ATOM      1  N   GLY A   1      11.104   6.134  -6.504  1.00  0.00           N";
    let cases: [(&str, String, usize, &str); 8] = [
        ("nan.pdb", atom.replace("  11.104", "     nan"), 1, "x coordinate"),
        ("element.pdb", atom.replace("           N", "          QQ"), 1, "element"),
        ("resseq.pdb", atom.replace("A   1 ", "A 1x1 "), 1, "residue number"),
        ("empty.pdb", "HEADER    NOTHING\nEND\n".into(), 2, "ATOM or HETATM"),
        ("model.pdb", format!("MODEL     one\n{atom}\n"), 1, "model number"),
        ("noxyz.cif", "data_x\nloop_\n_atom_site.id\n_atom_site.type_symbol\n1 C\n".into(), 2, "Cartn_x"),
        ("quote.cif", "data_x\n_struct.title 'unclosed\n".into(), 2, "closing '"),
        ("count.xyz", "2\nwater\nO 0 0 0\n".into(), 3, "2 atom lines"),
    ];
    for (name, text, line, expected) in cases {
        let e = formats::load_bytes(Path::new(name), text.as_bytes()).unwrap_err();
        let formats::LoadError::Parse(p) = &e else { panic!("{name}: {e}") };
        assert_eq!((p.file.as_str(), p.line), (name, line), "{name}: {e}");
        assert!(p.expected.contains(expected), "{name}: {e}");
    }
}
