//! The JSON wavefunctions of tests/fixtures/json, written by
//! scripts/make_json_wavefunction_fixtures.py from PySCF wavefunctions in ORCA's `orca_2json`
//! layout (ORCA 5 and 6.1) and in Psi4's QCSchema layout, open with the orbitals of the same
//! wavefunction's Molden file (PySCF's writer, itself checked against PySCF in
//! tests/fixture_wavefunctions.rs): every orbital's value at 300 points (signs included), the
//! density and spin density there, energies, occupations, spins, and CᵀSC = I to the files'
//! full double precision. Restricted and unrestricted; pure functions to g (ORCA's order and
//! f/g signs, Psi4's m = +l … −l) and cartesian d (QCSchema's x^l normalisation). A QCSchema file
//! in the specification's own order, and one that does not name its writer, open the same.

mod common;

use std::path::{Path, PathBuf};

use glam::DVec3;
use orbcloud::formats;
use orbcloud::model::Document;
use orbcloud::model::gto::PreparedBasis;
use orbcloud::model::orbitals::{Spin, Wavefunction};
use serde_json::Value;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/json");
const POINTS: usize = 300;

/// One fixture: the file, its Molden file, the program its check names.
const CASES: [(&str, &str, &str); 6] = [
    ("h2o_rhf.orca.json", "h2o_rhf.molden", "ORCA 5.0 - current"),
    ("h2o_rhf.qcschema.json", "h2o_rhf.molden", "Psi4"),
    ("h2o_cation.orca.json", "h2o_cation.molden", "ORCA 6.1.x"),
    ("h2o_cation.qcschema.json", "h2o_cation.molden", "Psi4"),
    ("h2o_cart.qcschema.json", "h2o_cart.molden", "Psi4"),
    // Gzipped in memory.
    ("h2o_cation.orca.json.gz", "h2o_cation.molden", "ORCA 6.1.x"),
];

fn read(name: &str) -> Vec<u8> {
    std::fs::read(PathBuf::from(DIR).join(name))
        .unwrap_or_else(|e| panic!("{name}: {e} (run scripts/make_json_wavefunction_fixtures.py)"))
}

fn load(name: &str) -> Document {
    let path = PathBuf::from(DIR).join(name);
    if let Some(plain) = name.strip_suffix(".gz") {
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        std::io::Write::write_all(&mut gz, &read(plain)).expect("gzip");
        return formats::load_bytes(&path, &gz.finish().expect("gzip")).unwrap_or_else(|e| panic!("{e}"));
    }
    formats::load_bytes(&path, &read(name)).unwrap_or_else(|e| panic!("{e}"))
}

fn points(doc: &Document) -> Vec<DVec3> {
    common::points_around(doc, POINTS)
}

/// Compares `doc` with the Molden file's wavefunction; returns what is off, and the worst
/// orbital value difference.
fn compare(file: &str, doc: &Document, molden: &str) -> (Vec<String>, f64) {
    let reference = load(molden);
    let wf = doc.wavefunction.as_ref().unwrap_or_else(|| panic!("{file}: no wavefunction"));
    let want = reference.wavefunction.as_ref().expect("the Molden file's wavefunction");
    assert_eq!(doc.molecule.atoms.len(), reference.molecule.atoms.len(), "{file}: atoms");
    for (a, b) in doc.molecule.atoms.iter().zip(&reference.molecule.atoms) {
        assert_eq!((a.z, a.charge, a.ghost), (b.z, b.charge, b.ghost), "{file}: atom");
        assert!((a.position - b.position).length() < 1e-9, "{file}: atom at {} vs {}", a.position, b.position);
    }
    assert_eq!(wf.restricted, want.restricted, "{file}: restricted");
    assert_eq!(wf.basis.n_functions(), want.basis.n_functions(), "{file}: functions");
    let pa = PreparedBasis::new(&wf.basis);
    let pb = PreparedBasis::new(&want.basis);
    let pts = points(doc);
    let mut failures = Vec::new();
    let mut worst = 0.0f64;
    for spin in [Spin::Alpha, Spin::Beta] {
        let got: Vec<_> = wf.of_spin(spin).map(|(_, o)| o).collect();
        let exp: Vec<_> = want.of_spin(spin).map(|(_, o)| o).collect();
        assert_eq!(got.len(), exp.len(), "{file}: {spin:?} orbitals");
        for (k, (a, b)) in got.iter().zip(&exp).enumerate() {
            // Molden writes energies to 10 significant digits.
            if (a.energy - b.energy).abs() > 1e-9 * b.energy.abs().max(1.0) {
                failures.push(format!("{spin:?} orbital {}: energy {} vs {}", k + 1, a.energy, b.energy));
            }
            if (a.occupation - b.occupation).abs() > 1e-12 {
                failures.push(format!("{spin:?} orbital {}: occupation {} vs {}", k + 1, a.occupation, b.occupation));
            }
            for &p in &pts {
                let (va, vb) = (pa.orbital_value(&a.coefficients, p), pb.orbital_value(&b.coefficients, p));
                let d = (va - vb).abs() / vb.abs().max(1.0);
                worst = worst.max(d);
                if d > 1e-8 {
                    failures.push(format!("{spin:?} orbital {} at {p}: {va:e} vs {vb:e}", k + 1));
                }
            }
        }
        if spin == Spin::Alpha || !want.restricted {
            let e = |w: &Wavefunction, i: Option<usize>| i.map(|i| w.orbitals[i].energy);
            for (got, exp) in
                [(e(wf, wf.homo(spin)), e(want, want.homo(spin))), (e(wf, wf.lumo(spin)), e(want, want.lumo(spin)))]
            {
                assert!(
                    matches!((got, exp), (Some(x), Some(y)) if (x - y).abs() < 1e-9),
                    "{file}: {spin:?} frontier {got:?} vs {exp:?}"
                );
            }
        }
    }
    for &p in &pts {
        for (label, a, b) in [
            ("density", pa.density(wf, p), pb.density(want, p)),
            ("spin density", pa.spin_density(wf, p), pb.spin_density(want, p)),
        ] {
            if (a - b).abs() > 1e-8 * b.abs().max(1.0) {
                failures.push(format!("{label} at {p}: {a:e} vs {b:e}"));
            }
        }
    }
    (failures.into_iter().map(|f| format!("{file}: {f}")).collect(), worst)
}

#[test]
fn json_wavefunctions_match_their_molden_files() {
    let mut failures = Vec::new();
    for (file, molden, program) in CASES {
        let doc = load(file);
        let n = &doc.wavefunction.as_ref().expect("wavefunction").normalization;
        assert_eq!(n.program, program, "{file}: {n:?}");
        assert_eq!(n.repair, "none", "{file}: {n:?}");
        // The files write every number in full: CᵀSC = I to double precision.
        assert!(n.residual < 1e-9, "{file}: residual {:e}", n.residual);
        assert!(doc.problems.is_empty(), "{file}: {:?}", doc.problems);
        let (f, worst) = compare(file, &doc, molden);
        eprintln!("{file}: residual {:.1e}, worst orbital value {worst:.1e}", n.residual);
        failures.extend(f);
    }
    assert!(failures.is_empty(), "{} checks off:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn every_fixture_is_checked() {
    let mut names: Vec<String> = std::fs::read_dir(DIR)
        .unwrap_or_else(|e| panic!("{DIR}: {e}"))
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".json"))
        .collect();
    names.sort();
    let mut listed: Vec<String> = CASES.iter().map(|c| c.0.to_string()).filter(|f| !f.ends_with(".gz")).collect();
    listed.sort();
    assert_eq!(names, listed);
}

/// The electrons the orbitals hold, from the occupations (the QCSchema file of the restricted
/// water has none: they come from calcinfo_nalpha and calcinfo_nbeta).
#[test]
fn occupations_count_the_electrons() {
    for (file, electrons, restricted) in [
        ("h2o_rhf.orca.json", 10.0, true),
        ("h2o_rhf.qcschema.json", 10.0, true),
        ("h2o_cation.orca.json", 9.0, false),
        ("h2o_cation.qcschema.json", 9.0, false),
        ("h2o_cart.qcschema.json", 10.0, true),
    ] {
        let wf = load(file).wavefunction.expect("wavefunction");
        let total: f64 = wf.orbitals.iter().map(|o| o.occupation).sum();
        assert_eq!((total, wf.restricted), (electrons, restricted), "{file}");
        let alpha: f64 = wf.of_spin(Spin::Alpha).map(|(_, o)| o.occupation).sum();
        if !restricted {
            assert_eq!(alpha, 5.0, "{file}");
        }
    }
}

/// Psi4's QCSchema file rewritten as the specification orders a shell (pure m = −l … +l) with
/// the coefficients of normalised primitives: `psi4 = false` does that; the other rewrite keeps
/// Psi4's layout and drops the file's `provenance` (so the reader no longer knows the writer).
fn rewritten(name: &str, as_spec: bool) -> Vec<u8> {
    let mut v: Value = serde_json::from_slice(&read(name)).expect("JSON");
    v.as_object_mut().expect("object").remove("provenance");
    if as_spec {
        // Shell sizes in file order, reversing each pure shell's rows.
        let wfn = &v["wavefunction"];
        let mut blocks = Vec::new();
        for center in wfn["basis"]["atom_map"].as_array().expect("atom_map") {
            let shells = &wfn["basis"]["center_data"][center.as_str().expect("name")]["electron_shells"];
            for s in shells.as_array().expect("shells") {
                let l = s["angular_momentum"][0].as_u64().expect("l") as usize;
                let pure = s["harmonic_type"] == "spherical";
                blocks.push(if pure { (2 * l + 1, true) } else { ((l + 1) * (l + 2) / 2, false) });
            }
        }
        let nao: usize = blocks.iter().map(|b| b.0).sum();
        let mut order = Vec::with_capacity(nao);
        for (n, pure) in blocks {
            let first = order.len();
            if pure {
                order.extend((first..first + n).rev());
            } else {
                order.extend(first..first + n);
            }
        }
        let wfn = v["wavefunction"].as_object_mut().expect("wavefunction");
        for key in ["scf_orbitals_a", "scf_orbitals_b"] {
            let Some(Value::Array(c)) = wfn.get(key).cloned() else { continue };
            let nmo = c.len() / nao;
            let rows: Vec<Value> = order.iter().flat_map(|&i| c[i * nmo..(i + 1) * nmo].to_vec()).collect();
            wfn.insert(key.into(), Value::Array(rows));
        }
        // Coefficients of normalised primitives: the x^l normalisation taken out again.
        let centers = wfn.get_mut("basis").and_then(|b| b.get_mut("center_data")).expect("center_data");
        for (_, center) in centers.as_object_mut().expect("centres").iter_mut() {
            for s in center["electron_shells"].as_array_mut().expect("shells") {
                let l = s["angular_momentum"][0].as_u64().expect("l") as i32;
                let exps: Vec<f64> =
                    s["exponents"].as_array().expect("exps").iter().map(|e| e.as_f64().unwrap()).collect();
                let df: f64 = (1..=(2 * l - 1).max(0)).rev().step_by(2).map(f64::from).product();
                for row in s["coefficients"].as_array_mut().expect("rows") {
                    for (c, a) in row.as_array_mut().expect("row").iter_mut().zip(&exps) {
                        let n = ((2.0 * a / std::f64::consts::PI).powf(1.5) * (4.0 * a).powi(l) / df).sqrt();
                        *c = Value::from(c.as_f64().unwrap() / n);
                    }
                }
            }
        }
    }
    serde_json::to_vec(&v).expect("JSON")
}

#[test]
fn qcschema_readings_are_told_apart_by_the_orbitals() {
    for name in ["h2o_rhf.qcschema.json", "h2o_cation.qcschema.json", "h2o_cart.qcschema.json"] {
        let molden = format!("{}.molden", name.split('.').next().unwrap());
        for as_spec in [true, false] {
            let bytes = rewritten(name, as_spec);
            let doc = formats::load_bytes(Path::new(name), &bytes).unwrap_or_else(|e| panic!("{e}"));
            let n = doc.wavefunction.as_ref().expect("wf").normalization.clone();
            assert!(n.residual < 1e-9, "{name} {as_spec}: {n:?}");
            assert_eq!(n.program, "unknown", "{name}: {n:?}");
            // Without a writer the specification's reading comes first; Psi4's order and
            // coefficients are found by measuring, and said (a cartesian file has no pure order
            // to tell: only its coefficients differ).
            let pure = !name.contains("cart");
            match (as_spec, pure) {
                (true, _) => assert_eq!(n.repair, "none", "{name} {as_spec}: {n:?}"),
                (false, true) => assert!(n.repair.contains("m = +l … −l (Psi4's)"), "{name}: {n:?}"),
                (false, false) => assert!(n.repair.contains("normalisation folded in"), "{name}: {n:?}"),
            }
            let (failures, _) = compare(name, &doc, &molden);
            assert!(failures.is_empty(), "{name} as_spec={as_spec}:\n{}", failures.join("\n"));
        }
    }
}

/// The shapes of QCSchema shells no fixture writes as Psi4 does: sp shells
/// (`angular_momentum: [0, 1]`, a row of coefficients per l), general contractions (several rows
/// of one l over shared exponents) and numbers written as strings, as the schema's own examples
/// have them. The same wavefunctions rewritten so (the orbitals' rows moved with their
/// functions) open with the same orbitals.
#[test]
fn qcschema_sp_shells_general_contractions_and_string_numbers() {
    for (name, sp) in [("h2o_cart.qcschema.json", true), ("h2o_rhf.qcschema.json", false)] {
        let mut v: Value = serde_json::from_slice(&read(name)).expect("JSON");
        let cartesian = name.contains("cart");
        let size = |l: usize| if cartesian { (l + 1) * (l + 2) / 2 } else { 2 * l + 1 };
        // Per centre: the new shells, each the old shells (index, functions) whose rows it takes.
        let mut groups: std::collections::BTreeMap<String, Vec<Vec<(usize, usize)>>> = Default::default();
        let mut merged = 0;
        let centers = v["wavefunction"]["basis"]["center_data"].as_object_mut().expect("centres");
        for (key, center) in centers.iter_mut() {
            let shells = center["electron_shells"].as_array().expect("shells").clone();
            let l_of = |s: &Value| s["angular_momentum"][0].as_u64().unwrap() as usize;
            let mut out: Vec<Value> = Vec::new();
            let mut group: Vec<Vec<usize>> = Vec::new();
            for (i, s) in shells.iter().enumerate() {
                // An sp partner: the earlier s shell of the same exponents; a general
                // contraction: the previous shell of the same l and exponents.
                let partner = if sp && l_of(s) == 1 {
                    group.iter().position(|g| {
                        g.len() == 1 && l_of(&shells[g[0]]) == 0 && shells[g[0]]["exponents"] == s["exponents"]
                    })
                } else if !sp
                    && i > 0
                    && l_of(&shells[i - 1]) == l_of(s)
                    && shells[i - 1]["exponents"] == s["exponents"]
                {
                    Some(group.len() - 1)
                } else {
                    None
                };
                match partner {
                    Some(k) => {
                        if sp {
                            out[k]["angular_momentum"] = serde_json::json!([0, 1]);
                        }
                        let row = s["coefficients"][0].clone();
                        out[k]["coefficients"].as_array_mut().unwrap().push(row);
                        group[k].push(i);
                        merged += 1;
                    }
                    None => {
                        out.push(s.clone());
                        group.push(vec![i]);
                    }
                }
            }
            // Numbers as strings.
            for s in &mut out {
                let text = |x: &Value| Value::String(format!("{}", x.as_f64().unwrap()));
                s["exponents"] = Value::Array(s["exponents"].as_array().unwrap().iter().map(text).collect());
                for row in s["coefficients"].as_array_mut().unwrap() {
                    *row = Value::Array(row.as_array().unwrap().iter().map(text).collect());
                }
            }
            let with_sizes = group.into_iter().map(|g| g.into_iter().map(|i| (i, size(l_of(&shells[i])))).collect());
            groups.insert(key.clone(), with_sizes.collect());
            center["electron_shells"] = Value::Array(out);
        }
        assert!(merged >= 1, "{name}: {merged} shells merged");
        // The functions' new order: atom by atom, new shell by new shell, its rows' old shells.
        let atom_map: Vec<String> = v["wavefunction"]["basis"]["atom_map"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a.as_str().unwrap().to_string())
            .collect();
        let mut order = Vec::new();
        let mut first = 0;
        for key in &atom_map {
            // Where each old shell's functions started in the file: old shells in index order.
            let mut old: Vec<(usize, usize)> = groups[key].iter().flatten().copied().collect();
            old.sort();
            let mut offsets = std::collections::BTreeMap::new();
            for (i, n) in old {
                offsets.insert(i, first);
                first += n;
            }
            for &(i, n) in groups[key].iter().flatten() {
                order.extend(offsets[&i]..offsets[&i] + n);
            }
        }
        let wfn = v["wavefunction"].as_object_mut().unwrap();
        let c = wfn["scf_orbitals_a"].as_array().unwrap().clone();
        let nmo = c.len() / order.len();
        wfn.insert(
            "scf_orbitals_a".into(),
            Value::Array(order.iter().flat_map(|&i| c[i * nmo..(i + 1) * nmo].to_vec()).collect()),
        );
        let bytes = serde_json::to_vec(&v).expect("JSON");
        let doc = formats::load_bytes(Path::new(name), &bytes).unwrap_or_else(|e| panic!("{e}"));
        let n = &doc.wavefunction.as_ref().expect("wf").normalization;
        assert!(n.residual < 1e-9 && n.repair == "none", "{name}: {n:?}");
        let molden = format!("{}.molden", name.split('.').next().unwrap());
        let (failures, _) = compare(name, &doc, &molden);
        assert!(failures.is_empty(), "{name}:\n{}", failures.join("\n"));
    }
}
