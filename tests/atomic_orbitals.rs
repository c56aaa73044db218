//! Jang and Varetto's atomic-orbital selector: single basis functions named as chemists write them and
//! shown bare, and orbitals restricted to chosen functions, against PySCF
//! (tests/fixtures/wavefunctions/*.ao.json, written by scripts/make_ao_fixtures.py from the
//! Molden fixtures), read from Molden and from fchk files.

mod common;

use std::path::Path;

use glam::DVec3;
use orbcloud::evaluate::{WavefunctionView, evaluate_wavefunction, restricted};
use orbcloud::gpu::gto::GtoFillPass;
use orbcloud::model::basis_labels::{find_function, function_name};
use orbcloud::model::orbitals::Quantity;
use orbcloud::model::{Document, PreparedBasis};

struct Reference {
    points: Vec<DVec3>,
    /// PySCF's label ("O1 3dz^2", "O1 4f-3") and the unit-normalised function's values.
    functions: Vec<(String, Vec<f64>)>,
    /// (orbital, PySCF's labels of the functions kept, values).
    restricted: Vec<(usize, Vec<String>, Vec<f64>)>,
}

fn reference(name: &str) -> Reference {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions").join(format!("{name}.ao.json"));
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let floats = |v: &serde_json::Value| v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect::<Vec<_>>();
    let strings =
        |v: &serde_json::Value| v.as_array().unwrap().iter().map(|x| x.as_str().unwrap().to_string()).collect();
    Reference {
        points: json["points"].as_array().unwrap().iter().map(|p| DVec3::from_slice(&floats(p))).collect(),
        functions: json["functions"].as_object().unwrap().iter().map(|(k, v)| (k.clone(), floats(v))).collect(),
        restricted: json["restricted"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| (r["orbital"].as_u64().unwrap() as usize, strings(&r["functions"]), floats(&r["values"])))
            .collect(),
    }
}

fn load(file: &str) -> Document {
    orbcloud::formats::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions").join(file))
        .unwrap()
}

/// PySCF's label in orbcloud's words: d components read as they are ("3dz^2", "3dx2-y2"), f ones
/// by m become their polynomials (real solid harmonics, m > 0 the cosine-like ones).
fn ours(pyscf: &str) -> String {
    const F: [(&str, &str); 7] = [
        ("f+0", "fz³"),
        ("f+1", "fxz²"),
        ("f-1", "fyz²"),
        ("f+2", "fz(x²−y²)"),
        ("f-2", "fxyz"),
        ("f+3", "fx(x²−3y²)"),
        ("f-3", "fy(3x²−y²)"),
    ];
    F.iter().find(|(m, _)| pyscf.ends_with(m)).map_or(pyscf.to_string(), |(m, poly)| pyscf.replace(m, poly))
}

fn assert_close(what: &str, got: f64, want: f64, tolerance: f64) {
    assert!((got - want).abs() <= tolerance * want.abs().max(1.0), "{what}: {got} vs PySCF {want}");
}

const CASES: [(&str, [&str; 2]); 2] = [
    ("h2o_ccpvtz", ["h2o_ccpvtz.molden", "h2o_ccpvtz.fchk"]),
    ("h2o_cart_631gs", ["h2o_cart_631gs.molden", "h2o_cart_631gs.fchk"]),
];

#[test]
fn every_basis_function_is_named_and_shown_bare_as_pyscf_evaluates_it() {
    for (name, files) in CASES {
        let r = reference(name);
        let mut names_of_files = Vec::new();
        for file in files {
            let doc = load(file);
            let wf = doc.wavefunction.as_ref().unwrap();
            let n = wf.basis.n_functions();
            assert_eq!(n, r.functions.len(), "{file}");
            let prepared = PreparedBasis::new(&wf.basis);
            let mut found = vec![false; n];
            for (label, values) in &r.functions {
                let k = find_function(&doc.molecule, &wf.basis, &ours(label))
                    .unwrap_or_else(|| panic!("{file}: no function named {:?}", ours(label)));
                assert!(!found[k], "{file}: two labels name function {k}");
                found[k] = true;
                // The bare function: coefficient 1 on it, 0 elsewhere.
                let bare = prepared.unit_coefficients(k);
                for (p, &want) in r.points.iter().zip(values) {
                    assert_close(&format!("{file} {label} at {p}"), prepared.orbital_value(&bare, *p), want, 1e-8);
                }
            }
            names_of_files
                .push((0..n).map(|k| function_name(&doc.molecule, &wf.basis, k).unwrap()).collect::<Vec<_>>());
        }
        assert_eq!(names_of_files[0], names_of_files[1], "{name}: Molden and fchk name their functions alike");
        eprintln!("{name}: {} functions named and evaluated as PySCF does", r.functions.len());
    }
}

#[test]
fn a_restricted_orbital_is_the_sum_over_the_chosen_functions() {
    for (name, files) in CASES {
        let r = reference(name);
        for file in files {
            let doc = load(file);
            let wf = doc.wavefunction.as_ref().unwrap();
            let prepared = PreparedBasis::new(&wf.basis);
            for (orbital, chosen, values) in &r.restricted {
                let mut keep = vec![false; wf.basis.n_functions()];
                for label in chosen {
                    keep[find_function(&doc.molecule, &wf.basis, &ours(label)).unwrap()] = true;
                }
                let c = restricted(&wf.orbitals[*orbital].coefficients, Some(&keep));
                for (p, &want) in r.points.iter().zip(values) {
                    let what = format!("{file} MO {} on {chosen:?} at {p}", orbital + 1);
                    assert_close(&what, prepared.orbital_value(&c, *p), want, 1e-8);
                }
            }
        }
    }
}

/// What the viewer evaluates (the GPU fill, read back) for a restricted orbital and a bare d
/// function, against Σ over the chosen functions of coefficient × function value, computed
/// here from the CPU evaluator's values of each basis function.
#[test]
fn the_gpu_shows_the_restricted_orbital_and_the_bare_function() {
    let ctx = common::lavapipe();
    let fill = GtoFillPass::new(&ctx);
    let doc = load("h2o_ccpvtz.molden");
    let wf = doc.wavefunction.as_ref().unwrap();
    let prepared = PreparedBasis::new(&wf.basis);
    let index = |name: &str| find_function(&doc.molecule, &wf.basis, name).unwrap();
    let homo = wf.homo(orbcloud::model::Spin::Alpha).unwrap();
    let chosen = [index("O1 2px"), index("O1 3dxz")];
    let mut keep = vec![false; wf.basis.n_functions()];
    chosen.iter().for_each(|&k| keep[k] = true);
    let cases = [
        (Quantity::Orbital(homo), Some(keep), chosen.iter().map(|&k| (k, wf.orbitals[homo].coefficients[k])).collect()),
        (Quantity::BasisFunction(index("O1 3dxy")), None, vec![(index("O1 3dxy"), 1.0)]),
    ];
    for (quantity, functions, terms) in cases {
        let view = WavefunctionView { quantity, direct: false, points: 24, functions, grid: true };
        let grid = evaluate_wavefunction(&ctx, &fill, &doc, &view).unwrap().unwrap().values.grid.unwrap();
        let [nx, ny, nz] = grid.dims;
        let (mut worst, mut max) = (0f64, 0f64);
        for i in 0..nx {
            for j in 0..ny {
                for k in 0..nz {
                    let chi = prepared.basis_values(grid.point(i, j, k));
                    let want: f64 = terms.iter().map(|&(f, c): &(usize, f64)| c * chi[f]).sum();
                    let got = grid.values[(i * ny + j) * nz + k] as f64;
                    worst = worst.max((got - want).abs());
                    max = max.max(want.abs());
                }
            }
        }
        eprintln!("{quantity:?}: max |ψ| {max:.4}, worst |GPU − Σ c χ| {worst:.2e}");
        assert!(max > 0.05, "{quantity:?}: the grid holds the function ({max})");
        assert!(worst < 1e-5 * max.max(1.0), "{quantity:?}: worst difference {worst}");
    }
}

/// Sessions saved when the selector ticked whole shells still open: each shell's ticks spread
/// over its functions.
#[test]
fn a_selection_of_shells_from_an_older_session_ticks_their_functions() {
    use orbcloud::model::basis_labels::function_labels;
    let doc = load("h2o_cart_631gs.molden");
    let basis = &doc.wavefunction.as_ref().unwrap().basis;
    let p_shells: Vec<bool> = basis.shells.iter().map(|s| s.l == 1).collect();
    let stored = format!("ao_filter = true\nshell_mask = {p_shells:?}\n");
    let evaluation: orbcloud::scene::Evaluation = toml::from_str(&stored).unwrap();
    let ticked = evaluation.restriction(basis).expect("the filter is on");
    let labels = function_labels(basis);
    assert_eq!(ticked.len(), labels.len());
    for (on, label) in ticked.iter().zip(&labels) {
        assert_eq!(*on, label.shell_name.ends_with('p'), "{label:?}");
    }
}
