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

fn orbcloud(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).output().expect("run orbcloud")
}

const DIMER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/nci/water_dimer_631gs.molden");

/// Pixels of `png` that are blue-green (the NCI surface's colours around sign(λ₂)ρ ≈ −0.01),
/// left of the colour bar: their x coordinates.
fn blue_green_columns(png: &std::path::Path) -> (Vec<u32>, u32) {
    let img = image::open(png).unwrap().to_rgb8();
    let width = img.width();
    let xs = img
        .enumerate_pixels()
        .filter(|(x, _, p)| {
            let [r, g, b] = p.0.map(i32::from);
            *x < width * 7 / 10 && g > r + 30 && b > r + 30
        })
        .map(|(x, _, _)| x)
        .collect();
    (xs, width)
}

#[test]
fn render_nci_draws_the_water_dimers_hydrogen_bond_blue_green_between_the_molecules() {
    let dir = tempfile::tempdir().unwrap();
    let draw = |name: &str, quantity: &[&str]| {
        let png = dir.path().join(name);
        let mut args = vec!["render", DIMER, "--lavapipe", "--size", "320x240", "--grid-points", "56"];
        args.extend(quantity);
        args.extend(["-o", png.to_str().unwrap()]);
        let out = orbcloud(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        png
    };
    let (xs, width) = blue_green_columns(&draw("nci.png", &["--nci"]));
    assert!(xs.len() >= 10, "{} blue-green pixels", xs.len());
    // The hydrogen bond's disc lies between the two waters, in the middle of the part of the
    // picture its colour bar leaves free.
    let mean = xs.iter().map(|&x| x as f64).sum::<f64>() / xs.len() as f64;
    assert!((0.2..0.55).contains(&(mean / width as f64)), "blue-green around x = {mean} of {width}");
    // Its colour bar, right of it: red at the top, blue at the bottom.
    let img = image::open(dir.path().join("nci.png")).unwrap().to_rgb8();
    let bar = img.enumerate_pixels().filter(|(x, ..)| *x >= width * 7 / 10);
    let (mut red, mut blue) = (0, 0);
    for (_, _, p) in bar {
        let [r, g, b] = p.0.map(i32::from);
        red += (r > 180 && g < 120 && b < 120) as usize;
        blue += (b > 180 && r < 120 && g < 160) as usize;
    }
    assert!(red > 0 && blue > 0, "no colour bar: {red} red and {blue} blue pixels");
    // The density's cloud has none of those colours.
    let (xs, _) = blue_green_columns(&draw("density.png", &["--density"]));
    assert!(xs.is_empty(), "{} blue-green pixels in the density's picture", xs.len());
}

const DIMER_PDB: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/nci/water_dimer.pdb");

#[test]
fn render_nci_of_a_structure_draws_its_spherical_atoms_hydrogen_bond_between_a_selection_and_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("pdb.png");
    let out = orbcloud(&[
        "render",
        DIMER_PDB,
        "--nci",
        "--nci-between",
        "resn LIG",
        "--lavapipe",
        "--size",
        "320x240",
        "-o",
        png.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("NCI of spherical atoms"), "{err}");
    let (xs, width) = blue_green_columns(&png);
    assert!(xs.len() >= 10, "{} blue-green pixels", xs.len());
    let mean = xs.iter().map(|&x| x as f64).sum::<f64>() / xs.len() as f64;
    assert!((0.2..0.55).contains(&(mean / width as f64)), "blue-green around x = {mean} of {width}");
}

#[test]
fn render_nci_refusals_say_why() {
    // A structure's NCI between a selection and the rest needs atoms on both sides, and a
    // wavefunction's fragments are files of their own.
    for (file, between, said) in [
        (DIMER_PDB, "resn XYZ", "picks 0 of 6 atoms"),
        (DIMER_PDB, "resn LIG HOH", "picks 6 of 6 atoms"),
        (DIMER_PDB, "resi one", "residue numbers"),
        (DIMER, "resn LIG", "--intermolecular"),
    ] {
        let out = orbcloud(&["render", file, "--nci", "--nci-between", between, "--lavapipe", "-o", "/dev/null"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(err.contains(file) || err.contains(between), "{err}");
        assert!(err.contains(said), "{between}: {err}");
    }
    for (args, said) in [
        (&["--nci", "--rdg"][..], "cannot be used with"),
        (&["--nci", "--iso", "0.3"][..], "cannot be used with"),
        (&["--nci-level", "0.3"][..], "--nci"),
        (&["--nci", "--nci-range", "0"][..], "0.001"),
        (&["--nci", "--pick", "10,10"][..], "--pick"),
    ] {
        let out = orbcloud(&[&["render", DIMER, "--lavapipe", "-o", "/dev/null"][..], args].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(said), "{args:?}: {err}");
    }
}

/// `eval`'s output values.
fn eval(args: &[&str]) -> Vec<f64> {
    let out = orbcloud(&[&["eval"][..], args].concat());
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().nth(3).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn eval_of_several_files_is_of_their_summed_density() {
    let a = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions/h2o_cart_631gs.molden");
    let b = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions/benzene_631gs.molden");
    let dir = tempfile::tempdir().unwrap();
    let pts = dir.path().join("points.xyz");
    let points: Vec<DVec3> = (0..40)
        .map(|i| DVec3::new(0.21 * i as f64 - 4.0, 1.5 * (0.3 * i as f64).sin(), 0.8 + 0.05 * i as f64))
        .collect();
    std::fs::write(&pts, points.iter().map(|p| format!("{} {} {}\n", p.x, p.y, p.z)).collect::<String>()).unwrap();
    let pts = pts.to_str().unwrap();
    // ρ adds: the pair's density is each file's (one file's own evaluation) summed.
    let (da, db) = (eval(&[a, "--density", "--points", pts]), eval(&[b, "--density", "--points", pts]));
    let dab = eval(&[a, b, "--density", "--points", pts]);
    for ((x, y), z) in da.iter().zip(&db).zip(&dab) {
        assert!((x + y - z).abs() < 1e-10 * (1.0 + z.abs()), "{x} + {y} vs {z}");
    }
    // One file twice: s = |2∇ρ| / (c (2ρ)^{4/3}) = 2^{-1/3} s of the file alone.
    let (sa, saa) = (eval(&[a, "--rdg", "--points", pts]), eval(&[a, a, "--rdg", "--points", pts]));
    for (x, y) in sa.iter().zip(&saa) {
        let want = x * 2f64.powf(-1.0 / 3.0);
        assert!((y - want).abs() < 1e-8 * (1.0 + want), "{y} vs {want}");
    }
    // The pair's s and sign(λ₂)ρ from the two densities' derivatives summed by hand.
    let (doc_a, doc_b) = (formats::load(a.as_ref()).unwrap(), formats::load(b.as_ref()).unwrap());
    let (wa, wb) = (doc_a.wavefunction.as_ref().unwrap(), doc_b.wavefunction.as_ref().unwrap());
    let (fa, fb) = (WavefunctionDensity::new(wa), WavefunctionDensity::new(wb));
    let sab = eval(&[a, b, "--rdg", "--points", pts]);
    let lab = eval(&[a, b, "--sign-lambda2-rho", "--points", pts]);
    for ((p, s), l) in points.iter().zip(&sab).zip(&lab) {
        let (x, y) = (at(&fa, *p), at(&fb, *p));
        let rho = x.rho + y.rho;
        let grad = (x.gradient + y.gradient).length();
        let want = grad / (2.0 * (3.0 * std::f64::consts::PI.powi(2)).cbrt() * rho.powf(4.0 / 3.0));
        assert!((s - want).abs() < 1e-8 * (1.0 + want), "s at {p}: {s} vs {want}");
        assert!((l.abs() - rho).abs() < 1e-10 * (1.0 + rho), "|sign(λ₂)ρ| at {p}: {l} vs {rho}");
    }
    // What a sum of densities cannot give, and a file without a wavefunction, are refused.
    let xyz = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/structures/ethane_trajectory.xyz");
    for (args, said) in [
        (vec![a, b, "--orbital", "homo", "--points", pts], "fragments whose densities add"),
        (vec![a, b, "--esp", "--points", pts], "fragments whose densities add"),
        (vec![a, b, "--rdg", "--minus", a, "--points", pts], "--minus"),
        (vec![a, xyz, "--rdg", "--points", pts], xyz),
    ] {
        let out = orbcloud(&[&["eval"][..], &args].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(said), "{args:?}: {err}");
    }
}

#[test]
fn bench_nci_times_both_paths_and_they_agree() {
    let out = orbcloud(&["bench", "nci", DIMER, "--points", "16", "--runs", "1", "--lavapipe"]);
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(said.contains("grid [16, 16, 16]") && said.contains("cpu_ms=") && said.contains("gpu_ms="), "{said}");
    assert!(said.contains("points cut by one and not the other: 0"), "{said}");
}
