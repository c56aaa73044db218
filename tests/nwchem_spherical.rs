//! NWChem's pure functions: water RHF/cc-pVDZ (pure d on oxygen) written by PySCF in NWChem's
//! layout and sign convention (scripts/make_nwchem_spherical_fixture.py: its m = +1, +3 functions
//! carry the Condon–Shortley phase) reads back orbitals that equal PySCF's at points and are
//! orthonormal to the printed precision; read with the model's signs they were not (|CᵀSC − I|
//! 0.65).

use std::path::Path;

use glam::DVec3;
use orbcloud::model::gto::PreparedBasis;

const LOGS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/logs");

#[test]
fn nwchem_pure_d_orbitals_equal_pyscfs() {
    let doc =
        orbcloud::formats::load(Path::new(&format!("{LOGS}/h2o_nwchem_ccpvdz.out"))).unwrap_or_else(|e| panic!("{e}"));
    let wf = doc.wavefunction.as_ref().unwrap_or_else(|| panic!("orbitals: {:?}", doc.problems));
    assert_eq!((wf.basis.n_functions(), wf.orbitals.len()), (24, 24));
    let n = &wf.normalization;
    assert!(n.residual < n.expected_residual(), "{n:?}");
    let text = std::fs::read_to_string(format!("{LOGS}/h2o_nwchem_ccpvdz.expected.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let floats = |x: &serde_json::Value| x.as_array().unwrap().iter().map(|c| c.as_f64().unwrap()).collect::<Vec<_>>();
    let points: Vec<DVec3> =
        v["points_bohr"].as_array().unwrap().iter().map(|p| DVec3::from_slice(&floats(p))).collect();
    let pb = PreparedBasis::new(&wf.basis);
    let mut worst: f64 = 0.0;
    for (o, want) in wf.orbitals.iter().zip(v["orbital_values"].as_array().unwrap()) {
        for (p, w) in points.iter().zip(floats(want)) {
            worst = worst.max((pb.orbital_value(&o.coefficients, *p) - w).abs());
        }
    }
    // Coefficients printed to 5 decimals, 24 of them, basis functions below ~2 in value.
    assert!(worst < 2e-4, "orbital values differ from PySCF's by {worst:e}");
}
