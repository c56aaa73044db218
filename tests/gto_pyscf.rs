//! Basis functions, orbitals, densities and overlaps against PySCF
//! (fixtures from scripts/make_gto_fixtures.py).

use glam::DVec3;
use orbcloud::model::basis::{Basis, Shell, ShellKind, cartesian_powers, n_cartesian};
use orbcloud::model::gto::PreparedBasis;
use orbcloud::model::orbitals::{MolecularOrbital, Spin, Wavefunction};
use orbcloud::model::overlap::{orthonormality_error, orthonormality_residual, overlap_matrix};
use orbcloud::model::solid_harmonics::cart_to_pure;
use serde::Deserialize;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/gto");

#[derive(Deserialize)]
struct FixAtom {
    xyz: [f64; 3],
}

#[derive(Deserialize)]
struct FixShell {
    atom: usize,
    l: u32,
    pure: bool,
    exponents: Vec<f64>,
    coefficients: Vec<f64>,
}

#[derive(Deserialize)]
struct FixOrbital {
    index: usize,
    spin: String,
    energy: f64,
    occupation: f64,
    coefficients: Vec<f64>,
}

#[derive(Deserialize)]
struct Fixture {
    name: String,
    atoms: Vec<FixAtom>,
    shells: Vec<FixShell>,
    n_ao: usize,
    restricted: bool,
    orbitals: Vec<FixOrbital>,
    homo: usize,
    lumo: usize,
    points: Vec<[f64; 3]>,
    ao_values: Vec<Vec<f64>>,
    homo_values: Vec<f64>,
    lumo_values: Vec<f64>,
    density: Vec<f64>,
    spin_density: Vec<f64>,
    overlap_diagonal: Vec<f64>,
    overlap_elements: Vec<(usize, usize, f64)>,
}

const MOLECULES: &[&str] =
    &["h2o_cart_631gs", "h2o_pure_ccpvtz", "n2_ccpvqz", "ne_ccpv5z", "benzene_631gs", "h2o_cation_uhf"];

fn load(name: &str) -> (Fixture, Wavefunction) {
    let text = std::fs::read_to_string(format!("{DIR}/{name}.json")).expect("fixture");
    let fx: Fixture = serde_json::from_str(&text).expect("fixture json");
    let shells = fx
        .shells
        .iter()
        .map(|s| Shell {
            atom: s.atom,
            center: DVec3::from_array(fx.atoms[s.atom].xyz),
            l: s.l,
            kind: if s.pure { ShellKind::Pure } else { ShellKind::Cartesian },
            exponents: s.exponents.clone(),
            coefficients: s.coefficients.clone(),
        })
        .collect();
    let wf = Wavefunction {
        basis: Basis { shells },
        orbitals: fx
            .orbitals
            .iter()
            .map(|o| MolecularOrbital {
                energy: o.energy,
                occupation: o.occupation,
                spin: if o.spin == "beta" { Spin::Beta } else { Spin::Alpha },
                symmetry: String::new(),
                coefficients: o.coefficients.clone(),
            })
            .collect(),
        restricted: fx.restricted,
        ..Default::default()
    };
    assert_eq!(fx.name, name);
    assert_eq!(wf.basis.n_functions(), fx.n_ao, "{name}");
    (fx, wf)
}

fn alpha_orbital(fx: &Fixture, index: usize) -> &[f64] {
    &fx.orbitals.iter().find(|o| o.spin == "alpha" && o.index == index).expect("orbital in fixture").coefficients
}

#[test]
fn cart_to_pure_matches_pyscf() {
    let text = std::fs::read_to_string(format!("{DIR}/cart2sph.json")).unwrap();
    let fx: std::collections::BTreeMap<String, Vec<Vec<f64>>> = serde_json::from_str(&text).unwrap();
    for l in 0..=5u32 {
        let rows = &fx[&l.to_string()];
        let t = cart_to_pure(l);
        let nc = n_cartesian(l);
        assert_eq!(rows.len(), 2 * l as usize + 1);
        for (k, row) in rows.iter().enumerate() {
            for i in 0..nc {
                let (ours, theirs) = (t[k * nc + i], row[i]);
                assert!(
                    (ours - theirs).abs() < 1e-12,
                    "l={l} m-row {k} {:?}: {ours} vs PySCF {theirs}",
                    cartesian_powers(l)[i]
                );
            }
        }
    }
}

#[test]
fn basis_values_match_pyscf() {
    for name in MOLECULES {
        let (fx, wf) = load(name);
        let pb = PreparedBasis::new(&wf.basis);
        let mut worst: f64 = 0.0;
        for (p, want) in fx.points.iter().zip(&fx.ao_values) {
            let got = pb.basis_values(DVec3::from_array(*p));
            for (i, (a, b)) in got.iter().zip(want).enumerate() {
                assert!((a - b).abs() <= 1e-8, "{name} AO {i}: {a} vs {b}");
                worst = worst.max((a - b).abs());
            }
        }
        println!("{name}: max |AO − PySCF| = {worst:.2e}");
    }
}

#[test]
fn orbitals_and_densities_match_pyscf() {
    for name in MOLECULES {
        let (fx, wf) = load(name);
        let pb = PreparedBasis::new(&wf.basis);
        let (homo, lumo) = (alpha_orbital(&fx, fx.homo), alpha_orbital(&fx, fx.lumo));
        let (mut w_orb, mut w_rho): (f64, f64) = (0.0, 0.0);
        for (i, p) in fx.points.iter().enumerate() {
            let p = DVec3::from_array(*p);
            for (c, want) in [(homo, fx.homo_values[i]), (lumo, fx.lumo_values[i])] {
                let got = pb.orbital_value(c, p);
                assert!((got - want).abs() <= 1e-8, "{name} point {i}: {got} vs {want}");
                w_orb = w_orb.max((got - want).abs());
            }
            let rho = pb.density(&wf, p);
            let want = fx.density[i];
            let rel = (rho - want).abs() / want.abs().max(1e-300);
            assert!(rel <= 1e-8, "{name} density at {i}: {rho} vs {want}");
            w_rho = w_rho.max(rel);
            let spin = pb.spin_density(&wf, p);
            let want = fx.spin_density[i];
            assert!(
                (spin - want).abs() <= 1e-8 * fx.density[i].abs().max(1e-12),
                "{name} spin density at {i}: {spin} vs {want}"
            );
        }
        println!("{name}: max |ψ − PySCF| = {w_orb:.2e}, max density rel. error = {w_rho:.2e}");
    }
}

#[test]
fn overlap_matches_pyscf_and_orbitals_are_orthonormal() {
    for name in MOLECULES {
        let (fx, wf) = load(name);
        let n = fx.n_ao;
        let s = overlap_matrix(&wf.basis);
        for (i, d) in fx.overlap_diagonal.iter().enumerate() {
            assert!((s[i * n + i] - d).abs() < 1e-10, "{name} S[{i},{i}]");
        }
        for &(i, j, v) in &fx.overlap_elements {
            assert!((s[i * n + j] - v).abs() < 1e-10, "{name} S[{i},{j}] = {} vs {v}", s[i * n + j]);
        }
        let residual = orthonormality_residual(&wf);
        println!("{name}: max |CᵀSC − I| = {residual:.2e}");
        assert!(residual <= 1e-8, "{name}: {residual}");
        // A deliberately wrong normalisation is caught.
        let broken: Vec<Vec<f64>> = wf
            .orbitals
            .iter()
            .filter(|o| o.spin == Spin::Alpha)
            .map(|o| o.coefficients.iter().map(|c| c * 1.1).collect())
            .collect();
        let refs: Vec<&[f64]> = broken.iter().map(std::vec::Vec::as_slice).collect();
        assert!(orthonormality_error(&s, n, &refs) > 0.1);
    }
}

#[test]
fn grid_matches_points_on_benzene() {
    let (fx, wf) = load("benzene_631gs");
    let pb = PreparedBasis::new(&wf.basis);
    let homo = alpha_orbital(&fx, fx.homo);
    let grid = orbcloud::model::GridSpec::new(
        DVec3::new(-7.0, -7.5, -4.0),
        [DVec3::X * 0.7, DVec3::Y * 0.75, DVec3::Z * 0.2],
        [21, 21, 41],
    );
    let values = pb.eval_grid(homo, &grid);
    for (idx, v) in values.iter().enumerate() {
        let (i, j, k) = (idx / (21 * 41), idx / 41 % 21, idx % 41);
        let want = pb.orbital_value(homo, grid.point(i, j, k));
        assert!((v - want).abs() < 1e-10, "{v} vs {want}");
    }
}
