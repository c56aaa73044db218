//! NCI quantities against PySCF (in the Python `ORBCLOUD_PYTHON` names, which `scripts/test`
//! sets up): a water dimer's density, gradient and Hessian from `eval_ao(deriv=2)` against
//! the model's and `orbcloud eval`'s, in a pure (cc-pVDZ) and a cartesian (6-31G*) basis; then
//! the cubes `orbcloud nci` writes, for one file, for two fragments and promolecular.

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::DVec3;
use orbcloud::formats;
use orbcloud::model::nci::{DensityDerivatives, DensitySource, WavefunctionDensity};
use orbcloud::model::promolecular::Promolecule;
use orbcloud::model::units::BOHR_PER_ANGSTROM;
use serde::Deserialize;

/// The dimer (Å): the donor's O–H points at the acceptor's O.
const DONOR: &str = "O -1.551007 -0.114520 0.000000; H -1.934259 0.762503 0.000000; H -0.599677 0.040712 0.000000";
const ACCEPTOR: &str = "O 1.350625 0.111469 0.000000; H 1.680398 -0.373741 -0.758561; H 1.680398 -0.373741 0.758561";

const SCRIPT: &str = r#"
import json, sys
import numpy as np
from pyscf import gto, scf
from pyscf.tools import molden
atom, basis, cart, out = sys.argv[1], sys.argv[2], sys.argv[3] == "cart", sys.argv[4]
mol = gto.M(atom=atom, basis=basis, cart=cart, unit="Angstrom", verbose=0)
mf = scf.RHF(mol).run(conv_tol=1e-11)
molden.from_scf(mf, out)
rng = np.random.default_rng(7)
xyz = mol.atom_coords()
lo, hi = xyz.min(axis=0) - 2.0, xyz.max(axis=0) + 2.0
points = np.vstack([lo + (hi - lo) * rng.random((300, 3)),
                    xyz[2] + (xyz[-1] - xyz[2]) * np.linspace(0.05, 0.95, 40)[:, None] + 0.05])
dm = mf.make_rdm1()
ao = mol.eval_ao("GTOval_cart_deriv2" if cart else "GTOval_sph_deriv2", points)
v, g = ao[0], ao[1:4]
xx, xy, xz, yy, yz, zz = ao[4:10]
rho = np.einsum("pi,ij,pj->p", v, dm, v)
grad = 2 * np.einsum("api,ij,pj->pa", g, dm, v)
second = {"xx": xx, "xy": xy, "xz": xz, "yy": yy, "yz": yz, "zz": zz}
names = [["xx", "xy", "xz"], ["xy", "yy", "yz"], ["xz", "yz", "zz"]]
hess = np.zeros((len(points), 3, 3))
for a in range(3):
    for b in range(3):
        hess[:, a, b] = 2 * (np.einsum("pi,ij,pj->p", second[names[a][b]], dm, v)
                             + np.einsum("pi,ij,pj->p", g[a], dm, g[b]))
json.dump({"points": points.tolist(), "rho": rho.tolist(), "grad": grad.tolist(), "hess": hess.tolist()}, sys.stdout)
"#;

#[derive(Deserialize)]
struct Reference {
    points: Vec<[f64; 3]>,
    rho: Vec<f64>,
    grad: Vec<[f64; 3]>,
    hess: Vec<[[f64; 3]; 3]>,
}

fn python() -> String {
    orbcloud::sources::compute::python()
}

/// A Molden file of `atom` in `basis` written by PySCF into `dir`, with PySCF's density and
/// its derivatives at points.
fn pyscf(dir: &Path, name: &str, atom: &str, basis: &str, cart: bool) -> (PathBuf, Reference) {
    let molden = dir.join(format!("{name}.molden"));
    let script = dir.join("reference.py");
    std::fs::write(&script, SCRIPT).unwrap();
    let kind = if cart { "cart" } else { "pure" };
    let out = Command::new(python())
        .arg(&script)
        .args([atom, basis, kind])
        .arg(&molden)
        .output()
        .unwrap_or_else(|e| panic!("running `{}`: {e} (scripts/test sets ORBCLOUD_PYTHON)", python()));
    assert!(out.status.success(), "PySCF failed: {}", String::from_utf8_lossy(&out.stderr));
    (molden, serde_json::from_slice(&out.stdout).expect("the script's JSON"))
}

fn orbcloud(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).output().unwrap();
    assert!(out.status.success(), "orbcloud {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

fn derived(rho: f64, grad: [f64; 3], hessian: [[f64; 3]; 3]) -> DensityDerivatives {
    DensityDerivatives { rho, gradient: DVec3::from_array(grad), hessian }
}

#[test]
fn density_gradient_and_hessian_match_pyscf_in_pure_and_cartesian_bases() {
    let dir = tempfile::tempdir().unwrap();
    let atom = format!("{DONOR}; {ACCEPTOR}");
    for (name, basis, cart) in [("dimer_ccpvdz", "cc-pvdz", false), ("dimer_631gs_cart", "6-31g*", true)] {
        let (molden, r) = pyscf(dir.path(), name, &atom, basis, cart);
        let doc = formats::load(&molden).unwrap();
        let wf = doc.wavefunction.as_ref().unwrap();
        assert_eq!(
            wf.basis.shells.iter().any(|s| s.l == 2 && s.kind == orbcloud::model::basis::ShellKind::Pure),
            !cart
        );
        let source = WavefunctionDensity::new(wf);
        let points: Vec<DVec3> = r.points.iter().map(|p| DVec3::from_array(*p)).collect();
        let mut ours = vec![DensityDerivatives::default(); points.len()];
        source.derivatives_at(&points, &mut ours);
        let (mut worst_hessian, mut worst_sl2r, mut worst_s) = (0.0f64, 0.0f64, 0.0f64);
        let mut compared = 0;
        for (i, o) in ours.iter().enumerate() {
            let want = derived(r.rho[i], r.grad[i], r.hess[i]);
            let scale = 1.0 + want.hessian.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            for a in 0..3 {
                assert!(
                    (o.gradient[a] - want.gradient[a]).abs() < 1e-8 * (1.0 + want.gradient[a].abs()),
                    "{name} ∇ρ at {i}"
                );
                for b in 0..3 {
                    worst_hessian = worst_hessian.max((o.hessian[a][b] - want.hessian[a][b]).abs() / scale);
                }
            }
            if want.rho < 1e-10 {
                continue;
            }
            compared += 1;
            worst_sl2r = worst_sl2r.max((o.sign_lambda2_rho() - want.sign_lambda2_rho()).abs());
            worst_s = worst_s.max((o.reduced_gradient() / want.reduced_gradient() - 1.0).abs());
        }
        eprintln!(
            "{name}: {compared} points, max |ΔH|/(1+|H|) {worst_hessian:.2e}, max |Δ sign(λ₂)ρ| {worst_sl2r:.2e}, max relative Δs {worst_s:.2e}"
        );
        assert!(compared > 200, "{name}: most points have a density");
        assert!(worst_hessian < 1e-8, "{name}: Hessian {worst_hessian}");
        assert!(worst_sl2r < 1e-8, "{name}: sign(λ₂)ρ {worst_sl2r}");
        assert!(worst_s < 1e-5, "{name}: s {worst_s}");

        // The command line prints the same values.
        let list: String = points.iter().map(|p| format!("{:.17e} {:.17e} {:.17e}\n", p.x, p.y, p.z)).collect();
        let file = dir.path().join("points.txt");
        std::fs::write(&file, list).unwrap();
        for (flag, f) in [("--sign-lambda2-rho", 0), ("--rdg", 1), ("--laplacian", 2)] {
            let text = orbcloud(&["eval", molden.to_str().unwrap(), flag, "--points", file.to_str().unwrap()]);
            let values: Vec<f64> =
                text.lines().map(|l| l.split_whitespace().nth(3).unwrap().parse().unwrap()).collect();
            assert_eq!(values.len(), points.len());
            for (i, v) in values.iter().enumerate() {
                let want = derived(r.rho[i], r.grad[i], r.hess[i]);
                if want.rho < 1e-10 {
                    continue;
                }
                match f {
                    0 => assert!((v - want.sign_lambda2_rho()).abs() < 1e-8, "{flag} at {i}: {v}"),
                    1 => assert!((v / want.reduced_gradient() - 1.0).abs() < 1e-5, "{flag} at {i}: {v}"),
                    _ => assert!(
                        (v - want.laplacian()).abs() < 1e-7 * (1.0 + want.laplacian().abs()),
                        "{flag} at {i}: {v}"
                    ),
                }
            }
        }
    }
}

/// A cube's values (x slowest) and its grid, read back.
fn cube(path: &Path) -> orbcloud::model::Document {
    formats::load(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn nci_cubes_follow_nciplot_conventions_for_one_file_two_fragments_and_promolecules() {
    let dir = tempfile::tempdir().unwrap();
    let (dimer, _) = pyscf(dir.path(), "dimer", &format!("{DONOR}; {ACCEPTOR}"), "6-31g*", false);
    let (donor, _) = pyscf(dir.path(), "donor", DONOR, "6-31g*", false);
    let (acceptor, _) = pyscf(dir.path(), "acceptor", ACCEPTOR, "6-31g*", false);
    let prefix = dir.path().join("dimer");
    let p = prefix.to_str().unwrap();
    orbcloud(&["nci", dimer.to_str().unwrap(), "--step", "0.15", "--margin", "1.0", "-o", p]);
    let (dens, grad) = (cube(&dir.path().join("dimer-dens.cube")), cube(&dir.path().join("dimer-grad.cube")));
    let (d, g) = (&dens.volumes[0], &grad.volumes[0]);
    assert_eq!(dens.molecule.atoms.len(), 6);
    assert_eq!((d.dims, d.world_from_grid), (g.dims, g.world_from_grid));
    // The box: the atoms' extent plus the margin, at the step asked for.
    let (lo, _) = dens.molecule.bounds().unwrap();
    let origin = d.world_from_grid.transform_point3(DVec3::ZERO);
    assert!((origin - (lo - DVec3::splat(BOHR_PER_ANGSTROM))).length() < 1e-4, "{origin}");
    let step = d.world_from_grid.transform_vector3(DVec3::X).length();
    assert!((step - 0.15 * BOHR_PER_ANGSTROM).abs() < 1e-5);

    let doc = formats::load(&dimer).unwrap();
    let source = WavefunctionDensity::new(doc.wavefunction.as_ref().unwrap());
    let [nx, ny, nz] = d.dims;
    let (mut cut, mut kept) = (0, 0);
    for i in (0..nx).step_by(3) {
        for j in (0..ny).step_by(3) {
            for k in (0..nz).step_by(3) {
                let at = (i * ny + j) * nz + k;
                let point = d.world_from_grid.transform_point3(DVec3::new(i as f64, j as f64, k as f64));
                let mut e = [DensityDerivatives::default()];
                source.derivatives_at(&[point], &mut e);
                let e = e[0];
                let (dv, gv) = (d.values[at] as f64, g.values[at] as f64);
                if e.rho > 0.05 {
                    assert_eq!((dv, gv), (100.0, 100.0), "a point above the cut at {point}");
                    cut += 1;
                } else {
                    // Cube files hold 5 significant digits.
                    assert!(
                        (dv - 100.0 * e.sign_lambda2_rho()).abs() < 1e-4 * (1.0 + dv.abs()),
                        "dens at {point}: {dv}"
                    );
                    // Above s = 1 (NCIPLOT's RDG cutoff) the -grad cube holds 100.
                    let s = e.reduced_gradient();
                    let s = if s > 1.0 { 100.0 } else { s };
                    assert!((gv - s).abs() < 1e-4 * (1.0 + s), "grad at {point}: {gv} vs {s}");
                    kept += 1;
                }
            }
        }
    }
    assert!(cut > 10 && kept > 500, "{cut} cut, {kept} kept");
    let bonding = d.values.iter().zip(&g.values).filter(|(dv, gv)| **dv < -1.0 && **gv < 0.5).count();
    assert!(bonding > 0, "the hydrogen bond shows as s < 0.5 with sign(λ₂)ρ < −0.01");

    // Two fragments add: their sum is close to the dimer's own density (polarisation apart),
    // and between them the hydrogen bond stays while each monomer's inside is dropped.
    let frag = dir.path().join("frag");
    let (a, b, f) = (donor.to_str().unwrap(), acceptor.to_str().unwrap(), frag.to_str().unwrap());
    orbcloud(&["nci", a, b, "--step", "0.15", "--margin", "1.0", "-o", f]);
    orbcloud(&["nci", a, b, "--step", "0.15", "--margin", "1.0", "--intermolecular", "-o", &format!("{f}-inter")]);
    let sum = cube(&dir.path().join("frag-dens.cube"));
    let inter = cube(&dir.path().join("frag-inter-dens.cube"));
    let inter_grad = cube(&dir.path().join("frag-inter-grad.cube"));
    let (s, n, ng) = (&sum.volumes[0], &inter.volumes[0], &inter_grad.volumes[0]);
    assert_eq!(s.dims, d.dims, "the same atoms make the same box");
    let fragments = [formats::load(&donor).unwrap(), formats::load(&acceptor).unwrap()];
    let sources: Vec<WavefunctionDensity> =
        fragments.iter().map(|d| WavefunctionDensity::new(d.wavefunction.as_ref().unwrap())).collect();
    let (mut between, mut dropped) = (0, 0);
    for (at, (&sv, &nv)) in s.values.iter().zip(&n.values).enumerate().step_by(7) {
        let (i, j, k) = (at / (ny * nz), (at / nz) % ny, at % nz);
        let point = d.world_from_grid.transform_point3(DVec3::new(i as f64, j as f64, k as f64));
        let parts: Vec<DensityDerivatives> = sources
            .iter()
            .map(|src| {
                let mut e = [DensityDerivatives::default()];
                src.derivatives_at(&[point], &mut e);
                e[0]
            })
            .collect();
        let mut total = parts[0];
        total.add(&parts[1]);
        if total.rho > 0.05 {
            assert_eq!(sv, 100.0);
            continue;
        }
        assert!((sv as f64 - 100.0 * total.sign_lambda2_rho()).abs() < 1e-4 * (1.0 + sv.abs() as f64));
        let share = parts[0].rho.max(parts[1].rho) / total.rho;
        if share > 0.95 {
            assert_eq!((nv, ng.values[at]), (100.0, 100.0), "owned by one fragment at {point}");
            dropped += 1;
        } else {
            assert_eq!(nv, sv, "between the fragments at {point}");
            between += 1;
        }
    }
    assert!(between > 10 && dropped > 100, "{between} between, {dropped} dropped");

    // Promolecular: any structure file, cut at 0.07.
    let xyz = dir.path().join("dimer.xyz");
    let lines: Vec<String> = format!("{DONOR}; {ACCEPTOR}").split(';').map(|a| a.trim().to_string()).collect();
    std::fs::write(&xyz, format!("6\nwater dimer\n{}\n", lines.join("\n"))).unwrap();
    let pro = dir.path().join("pro");
    orbcloud(&["nci", xyz.to_str().unwrap(), "--promolecular", "--step", "0.15", "-o", pro.to_str().unwrap()]);
    let pd = cube(&dir.path().join("pro-dens.cube"));
    let pg = cube(&dir.path().join("pro-grad.cube"));
    let promolecule = Promolecule::new(&pd.molecule).unwrap();
    let (v, w) = (&pd.volumes[0], &pg.volumes[0]);
    let [_, ny, nz] = v.dims;
    let (mut cut, mut kept) = (0, 0);
    for (at, (&dv, &gv)) in v.values.iter().zip(&w.values).enumerate().step_by(5) {
        let (i, j, k) = (at / (ny * nz), (at / nz) % ny, at % nz);
        let point = v.world_from_grid.transform_point3(DVec3::new(i as f64, j as f64, k as f64));
        let mut e = [DensityDerivatives::default()];
        promolecule.derivatives_at(&[point], &mut e);
        if e[0].rho > 0.07 {
            assert_eq!((dv, gv), (100.0, 100.0));
            cut += 1;
        } else {
            assert!((dv as f64 - 100.0 * e[0].sign_lambda2_rho()).abs() < 1e-4 * (1.0 + dv.abs() as f64));
            kept += 1;
        }
    }
    assert!(cut > 0 && kept > 1000);

    // Refusals name the file and what was expected.
    let out = Command::new(env!("CARGO_BIN_EXE_orbcloud"))
        .args(["nci", xyz.to_str().unwrap(), "-o", pro.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("dimer.xyz") && err.contains("--promolecular"), "{err}");
    let out = Command::new(env!("CARGO_BIN_EXE_orbcloud"))
        .args(["nci", dimer.to_str().unwrap(), "--intermolecular", "-o", p])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("two files"));
    let out = Command::new(env!("CARGO_BIN_EXE_orbcloud"))
        .args(["nci", xyz.to_str().unwrap(), "--promolecular", "--step", "0.001", "-o", p])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--step"), "{err}");
}
