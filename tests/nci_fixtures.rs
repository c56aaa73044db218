//! The density's Hessian from real files' bases (pure d and f from an fchk, d–h from a Molden
//! file, an unrestricted cation) against finite differences of its gradient; the same
//! wavefunction read from fchk and from Molden gives the same NCI quantities.

use glam::DVec3;
use orbcloud::formats;
use orbcloud::model::nci::{DensityDerivatives, DensitySource, WavefunctionDensity};

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions");

fn at(source: &WavefunctionDensity, p: DVec3) -> DensityDerivatives {
    let mut d = [DensityDerivatives::default()];
    source.derivatives_at(&[p], &mut d);
    d[0]
}

/// Points around the atoms, 0.3–3 bohr out.
fn points(doc: &orbcloud::model::Document) -> Vec<DVec3> {
    let mut out = Vec::new();
    for (i, a) in doc.molecule.atoms.iter().enumerate() {
        for k in 0..8 {
            let t = (i * 8 + k) as f64 * 0.77;
            let dir = DVec3::new(t.sin(), (1.3 * t).cos(), (0.7 * t).sin()).normalize();
            out.push(a.position + dir * (0.3 + 0.35 * k as f64));
        }
    }
    out
}

#[test]
fn hessians_of_real_files_match_finite_differences() {
    for name in ["h2o_ccpvtz.fchk", "h2_spdfgh.molden", "h2o_cation_uhf_631gs.fchk", "h2o_cart_631gs.molden"] {
        let doc = formats::load(std::path::Path::new(&format!("{DIR}/{name}"))).unwrap();
        let wf = doc.wavefunction.as_ref().unwrap();
        let source = WavefunctionDensity::new(wf);
        let h = 1e-4;
        let mut worst = 0.0f64;
        for p in points(&doc) {
            let d = at(&source, p);
            assert!((d.rho - source.basis.density(wf, p)).abs() < 1e-12 * (1.0 + d.rho), "{name}: ρ at {p}");
            for a in 0..3 {
                let mut e = DVec3::ZERO;
                e[a] = h;
                let (up, down) = (at(&source, p + e), at(&source, p - e));
                let fd = (up.rho - down.rho) / (2.0 * h);
                worst = worst.max((fd - d.gradient[a]).abs() / (1.0 + fd.abs()));
                for b in 0..3 {
                    let fd = (up.gradient[b] - down.gradient[b]) / (2.0 * h);
                    worst = worst.max((fd - d.hessian[a][b]).abs() / (1.0 + fd.abs()));
                }
            }
        }
        assert!(worst < 1e-5, "{name}: worst relative difference {worst}");
    }
}

#[test]
fn fchk_and_molden_of_one_wavefunction_agree() {
    let load = |f: &str| formats::load(std::path::Path::new(&format!("{DIR}/{f}"))).unwrap();
    let (fchk, molden) = (load("h2o_ccpvtz.fchk"), load("h2o_ccpvtz.molden"));
    let (a, b) = (
        WavefunctionDensity::new(fchk.wavefunction.as_ref().unwrap()),
        WavefunctionDensity::new(molden.wavefunction.as_ref().unwrap()),
    );
    for p in points(&fchk) {
        let (x, y) = (at(&a, p), at(&b, p));
        assert!((x.sign_lambda2_rho() - y.sign_lambda2_rho()).abs() < 1e-6 * (1.0 + x.rho), "at {p}");
        assert!((x.reduced_gradient() / y.reduced_gradient() - 1.0).abs() < 1e-4, "at {p}");
        assert!((x.laplacian() - y.laplacian()).abs() < 1e-5 * (1.0 + x.laplacian().abs()), "at {p}");
    }
}
