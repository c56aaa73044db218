//! The wavefunction fixtures of tests/fixtures/wavefunctions, written by
//! scripts/make_wavefunction_fixtures.py with PySCF (Molden files by PySCF's own writer, fchk
//! files in Gaussian's conventions), load through `formats::load` and reproduce PySCF's values:
//! the alpha HOMO and LUMO (signs included), the total density and the spin density at 50
//! random points, the electron count, restricted/unrestricted and the frontier energies. The
//! files need no normalisation repair.

use std::path::PathBuf;

use glam::DVec3;
use orbcloud::formats;
use orbcloud::model::gto::PreparedBasis;
use orbcloud::model::orbitals::{Spin, Wavefunction};
use serde::Deserialize;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions");

/// Orbital and spin-density values: absolute tolerance.
const VALUE_TOL: f64 = 1e-8;
/// Density: relative tolerance, or this absolute one where the density is tiny.
const DENSITY_REL_TOL: f64 = 1e-8;
const DENSITY_ABS_TOL: f64 = 1e-10;
/// Largest max |CᵀSC − I| accepted as read. fchk writes coefficients with 9 significant digits
/// (`%16.8E`), which alone leaves residuals near 1e-8 (1.04e-8 for H2O/cc-pVTZ, the same with
/// an independent overlap); Molden's 14 digits leave ~1e-13.
fn residual_tol(ext: &str) -> f64 {
    if ext == "fchk" { 5e-8 } else { 1e-8 }
}

/// Orbital energies: Molden writes 10 significant digits, fchk 9.
const ENERGY_TOL: f64 = 1e-7;

#[derive(Deserialize)]
struct Expected {
    restricted: bool,
    n_electrons: usize,
    n_basis: usize,
    n_orbitals_per_spin: usize,
    homo_energy: f64,
    lumo_energy: f64,
    points: Vec<[f64; 3]>,
    homo: Vec<f64>,
    lumo: Vec<f64>,
    density: Vec<f64>,
    spin_density: Option<Vec<f64>>,
}

fn path(name: &str, ext: &str) -> PathBuf {
    let path = PathBuf::from(DIR).join(format!("{name}.{ext}"));
    assert!(
        path.is_file(),
        "fixture missing: {} (regenerate with python scripts/make_wavefunction_fixtures.py)",
        path.display()
    );
    path
}

fn expected(name: &str) -> Expected {
    let path = path(name, "expected.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let exp: Expected = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let n = exp.points.len();
    assert!(n > 0 && exp.homo.len() == n && exp.lumo.len() == n && exp.density.len() == n, "{name}: value counts");
    assert_eq!(exp.spin_density.is_none(), exp.restricted, "{name}: spin density given for unrestricted only");
    exp
}

fn wavefunction(name: &str, ext: &str) -> Wavefunction {
    let path = path(name, ext);
    let doc = formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    doc.wavefunction.unwrap_or_else(|| panic!("{}: no wavefunction", path.display()))
}

/// Worst deviations of one file from the expected values.
#[derive(Default)]
struct Worst {
    homo: f64,
    lumo: f64,
    density_rel: f64,
    density_abs: f64,
    spin_density: f64,
}

fn check(name: &str, ext: &str) {
    let exp = expected(name);
    let wf = wavefunction(name, ext);
    let file = format!("{name}.{ext}");

    assert_eq!(wf.restricted, exp.restricted, "{file}: restricted");
    assert_eq!(wf.normalization.repair, "none", "{file}: repair applied ({:?})", wf.normalization);
    assert!(
        wf.normalization.residual <= residual_tol(ext),
        "{file}: orthonormality residual {:e} > {:e}",
        wf.normalization.residual,
        residual_tol(ext)
    );

    let basis = PreparedBasis::new(&wf.basis);
    assert_eq!(basis.n_functions(), exp.n_basis, "{file}: basis functions");
    for spin in [Spin::Alpha, Spin::Beta] {
        let n = wf.of_spin(spin).count();
        let want = if spin == Spin::Beta && exp.restricted { 0 } else { exp.n_orbitals_per_spin };
        assert_eq!(n, want, "{file}: {spin:?} orbitals");
    }
    let electrons: f64 = wf.orbitals.iter().map(|o| o.occupation).sum();
    assert!(
        (electrons - exp.n_electrons as f64).abs() < 1e-9,
        "{file}: {electrons} electrons, want {}",
        exp.n_electrons
    );

    let homo = wf.homo(Spin::Alpha).unwrap_or_else(|| panic!("{file}: no HOMO"));
    let lumo = wf.lumo(Spin::Alpha).unwrap_or_else(|| panic!("{file}: no LUMO"));
    let (e_homo, e_lumo) = (wf.orbitals[homo].energy, wf.orbitals[lumo].energy);
    assert!((e_homo - exp.homo_energy).abs() <= ENERGY_TOL, "{file}: HOMO energy {e_homo}, want {}", exp.homo_energy);
    assert!((e_lumo - exp.lumo_energy).abs() <= ENERGY_TOL, "{file}: LUMO energy {e_lumo}, want {}", exp.lumo_energy);

    let mut worst = Worst::default();
    let mut failures = Vec::new();
    for (i, p) in exp.points.iter().enumerate() {
        let p = DVec3::from(*p);
        for (label, index, want, worst) in
            [("HOMO", homo, exp.homo[i], &mut worst.homo), ("LUMO", lumo, exp.lumo[i], &mut worst.lumo)]
        {
            let got = basis.orbital_value(&wf.orbitals[index].coefficients, p);
            let d = (got - want).abs();
            *worst = worst.max(d);
            if d > VALUE_TOL {
                failures.push(format!("{label} at {p}: {got:e}, want {want:e}"));
            }
        }

        let (got, want) = (basis.density(&wf, p), exp.density[i]);
        let d = (got - want).abs();
        worst.density_abs = worst.density_abs.max(d);
        if want.abs() > DENSITY_ABS_TOL {
            worst.density_rel = worst.density_rel.max(d / want.abs());
        }
        if d > (DENSITY_REL_TOL * want.abs()).max(DENSITY_ABS_TOL) {
            failures.push(format!("density at {p}: {got:e}, want {want:e}"));
        }

        if let Some(spin) = &exp.spin_density {
            let (got, want) = (basis.spin_density(&wf, p), spin[i]);
            let d = (got - want).abs();
            worst.spin_density = worst.spin_density.max(d);
            if d > VALUE_TOL {
                failures.push(format!("spin density at {p}: {got:e}, want {want:e}"));
            }
        }
    }
    eprintln!(
        "{file}: residual {:.1e}; worst |diff| HOMO {:.1e}, LUMO {:.1e}, density {:.1e} (relative {:.1e}), spin density {:.1e}",
        wf.normalization.residual, worst.homo, worst.lumo, worst.density_abs, worst.density_rel, worst.spin_density
    );
    assert!(
        failures.is_empty(),
        "{file}: {} of {} checks off:\n{}",
        failures.len(),
        exp.points.len(),
        failures.join("\n")
    );
}

macro_rules! fixtures {
    ($($test:ident: $name:literal, $ext:literal;)*) => {
        $(
            #[test]
            fn $test() {
                check($name, $ext);
            }
        )*
    };
}

fixtures! {
    h2o_cart_631gs_molden: "h2o_cart_631gs", "molden";
    h2o_cart_631gs_fchk: "h2o_cart_631gs", "fchk";
    h2o_ccpvtz_molden: "h2o_ccpvtz", "molden";
    h2o_ccpvtz_fchk: "h2o_ccpvtz", "fchk";
    benzene_631gs_molden: "benzene_631gs", "molden";
    benzene_631gs_fchk: "benzene_631gs", "fchk";
    h3o_cation_631gss_molden: "h3o_cation_631gss", "molden";
    h3o_cation_631gss_fchk: "h3o_cation_631gss", "fchk";
    h2o_cation_uhf_631gs_molden: "h2o_cation_uhf_631gs", "molden";
    h2o_cation_uhf_631gs_fchk: "h2o_cation_uhf_631gs", "fchk";
}

/// Every fixture in the directory is covered by a test above.
#[test]
fn every_fixture_is_listed() {
    let mut names: Vec<String> = std::fs::read_dir(DIR)
        .unwrap_or_else(|e| panic!("{DIR}: {e}"))
        .filter_map(|e| e.ok()?.file_name().into_string().ok()?.strip_suffix(".expected.json").map(String::from))
        .collect();
    names.sort();
    let mut listed = ["benzene_631gs", "h2o_cart_631gs", "h2o_cation_uhf_631gs", "h2o_ccpvtz", "h3o_cation_631gss"]
        .map(String::from);
    listed.sort();
    assert_eq!(names, listed, "fixtures in {DIR} vs the tests above");
}
