//! The electrostatic potential from wavefunction files against PySCF's (`int1e_rinv` per point,
//! scripts/make_esp_fixtures.py): cartesian and pure bases, d to h functions, restricted and
//! unrestricted, cations, a pseudopotential's core charge; Molden and fchk files of the same
//! calculations give the same potential; far away the potential is the net charge over the
//! distance.

use std::path::Path;

use glam::DVec3;
use orbcloud::formats;
use orbcloud::model::esp::{Potential, Scratch};
use serde::Deserialize;

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures");
/// Agreement with PySCF (a.u.): the bound.
const TOL: f64 = 1e-6;

#[derive(Deserialize)]
struct Reference {
    source: String,
    charge: i32,
    points: Vec<[f64; 3]>,
    esp: Vec<f64>,
}

fn reference(name: &str) -> Reference {
    let path = format!("{FIXTURES}/esp/{name}.json");
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

fn potential(path: &Path) -> Potential {
    let doc = formats::load(path).unwrap_or_else(|e| panic!("{e}"));
    let wf = doc.wavefunction.as_ref().expect("a wavefunction");
    Potential::new(&doc.molecule, wf)
}

fn check(name: &str, file: &str) {
    let r = reference(name);
    let v = potential(&Path::new(FIXTURES).join(file));
    let points: Vec<DVec3> = r.points.iter().map(|p| DVec3::from_array(*p)).collect();
    let got = v.at_points(&points);
    let worst = got.iter().zip(&r.esp).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(worst < TOL, "{file}: largest difference from PySCF {worst:.2e} a.u.");
    assert!((v.total_charge() - r.charge as f64).abs() < 1e-6, "{file}: charge {}", v.total_charge());
}

#[test]
fn molden_files_match_pyscf() {
    for name in ["h2o_cart_631gs", "h2o_ccpvtz", "h2o_cation_uhf_631gs", "h3o_cation_631gss", "benzene_631gs"] {
        let r = reference(name);
        check(name, &r.source);
    }
}

#[test]
fn fchk_files_match_pyscf() {
    for name in ["h2o_cart_631gs", "h2o_ccpvtz", "h2o_cation_uhf_631gs", "h3o_cation_631gss"] {
        check(name, &format!("wavefunctions/{name}.fchk"));
    }
}

#[test]
fn d_to_h_functions_match_pyscf() {
    check("h2_spdfgh", "wavefunctions/h2_spdfgh.molden");
}

#[test]
fn a_pseudopotential_uses_the_core_charge() {
    // Iodine's nucleus counts as +25 (fchk "Nuclear charges"), not +53: the molecule is neutral.
    check("hi_def2svp_ecp", "esp/hi_def2svp_ecp.fchk");
}

#[test]
fn far_away_the_potential_is_the_net_charge_over_the_distance() {
    for (file, charge) in [("wavefunctions/h2o_cation_uhf_631gs.molden", 1.0), ("wavefunctions/h2o_ccpvtz.fchk", 0.0)] {
        let v = potential(&Path::new(FIXTURES).join(file));
        let mut s = Scratch::default();
        for r in [200.0, 2000.0] {
            let at = v.at(DVec3::new(0.3, -0.2, 0.9).normalize() * r, &mut s);
            // The dipole term falls off as 1/r², so r·V → q to within |μ|/r.
            assert!((at * r - charge).abs() < 2.0 / r, "{file}: r·V = {} at r = {r}", at * r);
        }
    }
}

#[test]
fn far_fields_agree_with_the_exact_sum_on_a_grid() {
    // Every point of a grid around the molecule, from inside the nuclei's cusps to the box's
    // corners: the far fields change the potential by less than their stated bound.
    use orbcloud::model::GridSpec;
    use orbcloud::model::esp::FAR_FIELD_ERROR;
    for file in ["wavefunctions/benzene_631gs.molden", "wavefunctions/h2_spdfgh.molden", "esp/hi_def2svp_ecp.fchk"] {
        let doc = formats::load(&Path::new(FIXTURES).join(file)).unwrap();
        let v = Potential::new(&doc.molecule, doc.wavefunction.as_ref().unwrap());
        let (lo, hi) = doc.molecule.bounds().unwrap();
        let grid = GridSpec::cube(lo - DVec3::splat(5.0), hi + DVec3::splat(5.0), 17);
        let fast = v.on_grid(&grid);
        let mut s = Scratch::default();
        let mut worst: f64 = 0.0;
        for i in 0..17 {
            for j in 0..17 {
                for k in 0..17 {
                    let exact = v.exact_at(grid.point(i, j, k), &mut s);
                    worst = worst.max((fast[(i * 17 + j) * 17 + k] - exact).abs());
                }
            }
        }
        assert!(worst <= FAR_FIELD_ERROR, "{file}: far fields off by {worst:.2e}");
        eprintln!("{file}: far fields within {worst:.1e} of the exact sum");
    }
}
