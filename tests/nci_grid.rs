//! `orbcloud nci`'s grid: NCIPLOT's automatic box by default (the atoms' box plus 0.75 Å,
//! 0.1 Å apart, ⌈extent/step⌉ points per axis), or a cube's grid exactly with --grid-like; and
//! an AIM file's primitives, contracted again for the density, give what they gave apart.

use std::path::Path;
use std::process::Command;

use glam::DVec3;
use orbcloud::formats;
use orbcloud::model::nci::{DensityDerivatives, DensitySource, WavefunctionDensity};
use orbcloud::model::units::BOHR_PER_ANGSTROM;

const WFN: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wfn_wfx_mkl/h2o_rhf.wfn");

fn orbcloud(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).output().unwrap()
}

fn cube(path: &Path) -> orbcloud::model::Document {
    formats::load(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_default_grid_is_nciplots_and_grid_like_copies_a_cube_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let prefix = dir.path().join("auto");
    let out = orbcloud(&["nci", WFN, "-o", prefix.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc = cube(&dir.path().join("auto-dens.cube"));
    let grid = &doc.volumes[0];
    let (lo, hi) = doc.molecule.bounds().unwrap();
    let (step, margin) = (0.1 * BOHR_PER_ANGSTROM, 0.75 * BOHR_PER_ANGSTROM);
    let origin = grid.world_from_grid.transform_point3(DVec3::ZERO);
    assert!((origin - (lo - DVec3::splat(margin))).length() < 1e-5, "{origin}");
    let want = ((hi - lo + DVec3::splat(2.0 * margin)) / step).ceil();
    assert_eq!(grid.dims, [want.x as usize, want.y as usize, want.z as usize]);
    assert!((grid.world_from_grid.transform_vector3(DVec3::X).length() - step).abs() < 1e-6);

    // A grid no box around the atoms gives: an odd origin, unequal steps, a sheared axis.
    let like = dir.path().join("like.cube");
    let mut text = String::from("a grid\nto copy\n    1   -3.123457    0.250000   -1.000001\n");
    text += "    7    0.210000    0.000000    0.000000\n";
    text += "    5    0.000000    0.330000    0.000000\n";
    text += "    3    0.000000    0.050000    0.170000\n";
    text += "    8    8.000000    0.000000    0.000000    0.000000\n";
    for i in 0..7 * 5 * 3 {
        text += &format!(" {:12.5E}{}", i as f64, if i % 6 == 5 { "\n" } else { "" });
    }
    text += "\n";
    std::fs::write(&like, text).unwrap();
    let copied = dir.path().join("copied");
    let out = orbcloud(&["nci", WFN, "--grid-like", like.to_str().unwrap(), "-o", copied.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (want, got) = (cube(&like), cube(&dir.path().join("copied-grad.cube")));
    assert_eq!(got.volumes[0].dims, [7, 5, 3]);
    let (a, b) = (want.volumes[0].world_from_grid, got.volumes[0].world_from_grid);
    assert!(a.abs_diff_eq(b, 1e-6), "{a} vs {b}");
    assert_eq!(cube(&dir.path().join("copied-dens.cube")).volumes[0].dims, [7, 5, 3]);

    // --grid-like says everything --step and --margin would.
    let out = orbcloud(&["nci", WFN, "--grid-like", like.to_str().unwrap(), "--step", "0.2", "-o", "x"]);
    assert!(!out.status.success());
}

#[test]
fn grad_cube_cuts_above_the_rdg_cutoff_as_nciplot_does() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("cut"), dir.path().join("all"));
    for (p, extra) in [(&a, None), (&b, Some("100"))] {
        // Every ρ kept: near the nuclei s is small.
        let mut args = vec!["nci", WFN, "--step", "0.2", "--cut", "10", "-o", p.to_str().unwrap()];
        if let Some(s) = extra {
            args.extend(["--rdg-cut", s]);
        }
        let out = orbcloud(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    let cut = cube(&dir.path().join("cut-grad.cube"));
    let all = cube(&dir.path().join("all-grad.cube"));
    let (mut above, mut below) = (0, 0);
    for (&c, &s) in cut.volumes[0].values.iter().zip(&all.volumes[0].values) {
        if s > 1.0 {
            assert_eq!(c, 100.0);
            above += 1;
        } else {
            assert_eq!(c, s);
            below += 1;
        }
    }
    assert!(above > 100 && below > 10, "{above} above s = 1, {below} below");
}

#[test]
fn a_wfn_files_primitives_are_contracted_again_without_changing_the_density() {
    let doc = formats::load(Path::new(WFN)).unwrap();
    let wf = doc.wavefunction.as_ref().unwrap();
    let source = WavefunctionDensity::new(wf);
    // cc-pVDZ's oxygen s shells share primitives (general contraction): those stay apart.
    assert!(
        source.contracted_functions() < source.basis.n_functions(),
        "{} of {} functions",
        source.contracted_functions(),
        source.basis.n_functions()
    );
    let points: Vec<DVec3> = (0..200)
        .map(|i| {
            let t = i as f64 * 0.31;
            DVec3::new(2.5 * t.sin(), 2.0 * (0.7 * t).cos(), 1.5 * (1.3 * t).sin())
        })
        .collect();
    let mut fast = vec![DensityDerivatives::default(); points.len()];
    source.derivatives_at(&points, &mut fast);
    let direct = source.basis.density_derivatives(wf, &points);
    for ((f, d), p) in fast.iter().zip(&direct).zip(&points) {
        // The file prints its coefficients to about 1e-8: contracting within 1e-7 of the
        // largest keeps the density to that.
        assert!((f.rho - d.rho).abs() < 1e-7 * d.rho + 1e-12, "ρ at {p}: {} vs {}", f.rho, d.rho);
        assert!((f.gradient - d.gradient).length() < 1e-7 * (1.0 + d.gradient.length()), "∇ρ at {p}");
        assert!((f.sign_lambda2_rho() - d.sign_lambda2_rho()).abs() < 1e-7 * (1.0 + d.rho), "at {p}");
    }
}
