//! A wavefunction moved rigidly (`model::rigid::moved`, what aligns a path's frames) keeps
//! every orbital's values at the moved points, ψ′(R·r + t) = ψ(r), for s to h functions,
//! cartesian and pure: checked with the evaluator that tests/gto_pyscf.rs holds to PySCF.

use glam::{DQuat, DVec3};
use orbcloud::model::PreparedBasis;
use orbcloud::model::rigid::moved;

fn check(file: &str) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions").join(file);
    let doc = orbcloud::formats::load(&path).unwrap();
    let wf = doc.wavefunction.as_ref().unwrap();
    let rotation = DQuat::from_euler(glam::EulerRot::ZYX, 0.83, -0.41, 2.2);
    let shift = DVec3::new(1.5, -0.7, 2.9);
    let turned = moved(wf, rotation, shift);
    let (before, after) = (PreparedBasis::new(&wf.basis), PreparedBasis::new(&turned.basis));
    let highest = wf.basis.shells.iter().map(|s| s.l).max().unwrap();
    let mut worst: f64 = 0.0;
    for (i, o) in wf.orbitals.iter().enumerate() {
        for k in 0..12 {
            let t = k as f64;
            let p = DVec3::new((0.7 * t).sin() * 1.3, (1.1 * t).cos() * 0.9, 0.2 * t - 1.0);
            let want = before.orbital_value(&o.coefficients, p);
            let got = after.orbital_value(&turned.orbitals[i].coefficients, rotation * p + shift);
            worst = worst.max((got - want).abs());
        }
    }
    eprintln!("{file}: l up to {highest}, worst |ψ′(Rr+t) − ψ(r)| = {worst:.2e}");
    assert!(worst < 1e-9, "{file}: {worst}");
}

#[test]
fn orbitals_turn_with_their_atoms_for_every_angular_momentum() {
    check("h2_spdfgh.molden");
    check("h2o_cart_631gs.molden");
    check("benzene_631gs.fchk");
}
