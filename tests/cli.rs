//! The command line end to end: `eval` reproduces the corpus's expected values, `cube` writes a
//! file the cube reader reads back with the same numbers, `info --json` describes wavefunctions,
//! and bad input fails with a message, not a panic.

use std::path::Path;
use std::process::Command;

mod common;

fn orbcloud(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).output().expect("run orbcloud")
}

fn refdata(name: &str) -> String {
    let p = common::refdata_dir().join(name);
    assert!(p.exists(), "reference corpus missing: {}", p.display());
    p.display().to_string()
}

#[test]
fn eval_reproduces_expected_values() {
    if common::refdata("cli::eval_reproduces_expected_values").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for (file, kind, flags, tolerance) in [
        ("nh3_orca.molden", "homo", &["--orbital", "homo"][..], 1e-6),
        ("o2_cc_pvtz_cart.fchk", "lumo", &["--orbital", "lumo"][..], 1e-6),
        ("h2o_ccpvdz_cfour.molden", "density", &["--density"][..], 1e-5),
    ] {
        let table = std::fs::read_to_string(common::refdata_dir().join("expected").join(format!("{file}.{kind}.tsv")))
            .expect("expected table");
        let points = dir.path().join("points.txt");
        let expected: Vec<[f64; 4]> = table
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| {
                let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
                [v[0], v[1], v[2], v[3]]
            })
            .collect();
        let text: String = expected.iter().map(|v| format!("{} {} {}\n", v[0], v[1], v[2])).collect();
        std::fs::write(&points, text).unwrap();
        let mut args = vec!["eval", &refdata(file)].into_iter().map(String::from).collect::<Vec<_>>();
        args.extend(flags.iter().map(std::string::ToString::to_string));
        args.extend(["--points".to_string(), points.display().to_string()]);
        let out = orbcloud(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let stdout = String::from_utf8(out.stdout).unwrap();
        let got: Vec<f64> = stdout.lines().map(|l| l.split_whitespace().nth(3).unwrap().parse().unwrap()).collect();
        assert_eq!(got.len(), expected.len());
        for (g, e) in got.iter().zip(&expected) {
            let err = if kind == "density" { (g - e[3]).abs() / e[3].abs().max(1e-12) } else { (g - e[3]).abs() };
            assert!(err <= tolerance, "{file} {kind}: {g} vs {}", e[3]);
        }
    }
}

#[test]
fn eval_shows_a_bare_basis_function_as_pyscf_evaluates_it() {
    let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixtures.join("h2o_ccpvtz.ao.json")).unwrap()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let points = dir.path().join("points.txt");
    let text: String = json["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| format!("{} {} {}\n", p[0].as_f64().unwrap(), p[1].as_f64().unwrap(), p[2].as_f64().unwrap()))
        .collect();
    std::fs::write(&points, text).unwrap();
    let molden = fixtures.join("h2o_ccpvtz.molden").display().to_string();
    let args = ["eval", &molden, "--basis-function", "O1 3dz2", "--points", &points.display().to_string()];
    let out = orbcloud(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let got: Vec<f64> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().nth(3).unwrap().parse().unwrap())
        .collect();
    let want = json["functions"]["O1 3dz^2"].as_array().unwrap();
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(want) {
        assert!((g - w.as_f64().unwrap()).abs() < 1e-9, "{g} vs PySCF {w}");
    }
    let out = orbcloud(&["eval", &molden, "--basis-function", "O1 9dz2", "--points", &points.display().to_string()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no basis function \"O1 9dz2\""));
}

#[test]
fn cube_output_reads_back() {
    if common::refdata("cli::cube_output_reads_back").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("homo.cube");
    let out = orbcloud(&[
        "cube",
        &refdata("water_hf_sto3g_qchem5.2.fchk"),
        "--orbital",
        "homo",
        "--grid",
        "24",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let cube = orbcloud::formats::load(&out_path).expect("the cube reader reads it");
    let grid = &cube.volumes[0];
    assert_eq!(grid.dims, [24, 24, 24]);
    assert_eq!(cube.molecule.atoms.len(), 3);
    let doc = orbcloud::formats::load(std::path::Path::new(&refdata("water_hf_sto3g_qchem5.2.fchk"))).unwrap();
    let wf = doc.wavefunction.as_ref().unwrap();
    let homo = &wf.orbitals[wf.homo(orbcloud::model::Spin::Alpha).unwrap()].coefficients;
    let prepared = orbcloud::model::gto::PreparedBasis::new(&wf.basis);
    for (i, j, k) in [(3, 5, 7), (12, 12, 12), (20, 2, 17), (0, 0, 0)] {
        let want = prepared.orbital_value(homo, grid.point(i, j, k));
        let got = grid.value(i, j, k) as f64;
        // The file holds 6 significant digits.
        assert!((got - want).abs() <= 1e-5 * want.abs() + 1e-12, "({i},{j},{k}): {got} vs {want}");
    }
}

#[test]
fn info_json_describes_the_wavefunction() {
    if common::refdata("cli::info_json_describes_the_wavefunction").is_none() {
        return;
    }
    let out = orbcloud(&["info", &refdata("nh3_turbomole.molden"), "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let wf = &v["wavefunction"];
    assert_eq!(wf["normalization"]["program"], "Turbomole");
    assert!(wf["normalization"]["residual"].as_f64().unwrap() < 1e-6);
    assert_eq!(wf["basis_functions"], 52);
    assert!(wf["homo"].is_object() && wf["lumo"].is_object());
}

#[test]
fn bad_input_fails_cleanly() {
    if common::refdata("cli::bad_input_fails_cleanly").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.molden");
    std::fs::write(&bad, "[Molden Format]\n[Atoms] AU\nO 1 8 0.0 zero 0.0\n").unwrap();
    for args in [
        vec!["info", bad.to_str().unwrap()],
        vec!["eval", &refdata("nh3_orca.molden"), "--orbital", "homo-99", "--points", "-"],
        vec!["cube", &refdata("aelta.cube"), "-o", "/dev/null"],
        vec!["render", "/nonexistent.cube", "-o", "/dev/null"],
    ] {
        let out = orbcloud(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
        assert!(!err.trim().is_empty(), "{args:?} gave no message");
    }
}

#[test]
fn scan_export_writes_the_interpolated_orbital_and_render_writes_both_views() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/psb3/psb3.scan.toml");
    let cube = dir.path().join("homo.cube");
    let out = orbcloud(&[
        "scan",
        "export",
        manifest,
        "--angle",
        "-97.5",
        "--orbital",
        "homo",
        "--points",
        "24",
        "-o",
        cube.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc = orbcloud::formats::load(&cube).unwrap();
    let file = orbcloud::formats::scan::load_scan(std::path::Path::new(manifest)).unwrap();
    let tracks = file.scan.track(orbcloud::model::scan::Follow::Index).unwrap();
    let grid = file.scan.key_grid(&tracks, orbcloud::scene::framing::ORBITAL_MARGIN, 24);
    let want = file.scan.interpolated_values(&tracks, 0, -97.5, &grid);
    let got = &doc.volumes[0];
    assert_eq!(got.dims, grid.dims);
    let scale = want.iter().fold(0f32, |m, v| m.max(v.abs()));
    let worst = got.values.iter().zip(&want).fold(0f32, |m, (a, b)| m.max((a - b).abs()));
    assert!(worst <= 1e-4 * scale, "exported values differ by {worst} (max |ψ| {scale})");
    // The skeleton in the file is the one at θ.
    let d = file.scan.coordinate.measure(&doc.molecule).unwrap();
    assert!((d + 97.5).abs() < 1e-3, "dihedral in the cube: {d}");

    let png = dir.path().join("scan.png");
    let out = orbcloud(&[
        "scan",
        "render",
        manifest,
        "--angle",
        "-90",
        "--interpolation",
        "three-pass",
        "--points",
        "24",
        "--size",
        "96x64",
        "--lavapipe",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (192, 64), "two views side by side");

    // Wrong arguments are refused before the key volumes are made (seconds of GPU work).
    for (args, says) in [
        (["--angle", "-90", "--orbital", "homo-7"], "--orbital homo-7: the scan shows homo, lumo"),
        (["--angle", "30", "--orbital", "homo"], "--at 30 is outside the scan's -180°..0°"),
    ] {
        let start = std::time::Instant::now();
        let out = orbcloud(&[&["scan", "render", manifest][..], &args[..], &["-o", "x.png"][..]].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{args:?}: {err}");
        assert!(!err.contains("key volumes"), "{args:?}: checked only after building: {err}");
        assert!(start.elapsed().as_secs_f64() < 15.0, "{args:?} took {:?}", start.elapsed());
    }
}

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions");

#[test]
fn mesh_writes_both_signs_of_an_orbital_and_refuses_unknown_formats() {
    let dir = tempfile::tempdir().unwrap();
    let molden = format!("{FIXTURES}/h2o_cart_631gs.molden");
    for ext in ["obj", "ply", "glb"] {
        let out = dir.path().join(format!("homo.{ext}"));
        let run = orbcloud(&["mesh", &molden, "--iso", "0.05", "--grid-points", "40", "-o", out.to_str().unwrap()]);
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        let said = String::from_utf8_lossy(&run.stderr);
        assert!(said.contains("psi_plus_0.05") && said.contains("psi_minus_0.05"), "{said}");
        assert!(std::fs::metadata(&out).unwrap().len() > 10_000);
    }
    let obj = std::fs::read_to_string(dir.path().join("homo.obj")).unwrap();
    assert_eq!(obj.lines().filter(|l| l.starts_with("o ")).count(), 2);
    let density = dir.path().join("rho.obj");
    let run = orbcloud(&[
        "mesh",
        &molden,
        "--density",
        "--iso",
        "0.05",
        "--grid-points",
        "40",
        "-o",
        density.to_str().unwrap(),
    ]);
    assert!(run.status.success());
    assert_eq!(std::fs::read_to_string(density).unwrap().lines().filter(|l| l.starts_with("o ")).count(), 1);
    let bad = orbcloud(&["mesh", &molden, "--iso", "0.05", "-o", dir.path().join("x.stl").to_str().unwrap()]);
    assert!(!bad.status.success() && String::from_utf8_lossy(&bad.stderr).contains(".obj, .ply or .glb"));
    let none = orbcloud(&["mesh", &molden, "-o", dir.path().join("x.obj").to_str().unwrap()]);
    assert!(!none.status.success() && String::from_utf8_lossy(&none.stderr).contains("--iso"));
}

#[test]
fn render_with_isosurfaces_and_a_pick() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("iso.png");
    let molden = format!("{FIXTURES}/h2o_cart_631gs.molden");
    let args = ["render", &molden, "--lavapipe", "--size", "160x120", "--grid-points", "40", "--no-volume"];
    let run = orbcloud(
        &[&args[..], &["--iso", "0.05", "--iso-sigma", "4", "-o", png.to_str().unwrap(), "--pick", "80,60"]].concat(),
    );
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let said = String::from_utf8_lossy(&run.stderr);
    assert!(said.contains("isosurfaces: 4 surface(s)"), "{said}");
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.starts_with("pick 80,60: "), "{stdout}");
    // The view's centre is the molecule's: an atom or a lobe is there, not background.
    assert!(!stdout.contains("nothing"), "{stdout}");
    let corner = orbcloud(&[&args[..], &["-o", png.to_str().unwrap(), "--pick", "0,0"]].concat());
    assert!(String::from_utf8_lossy(&corner.stdout).contains("pick 0,0: nothing"));
    assert!(!orbcloud(&[&args[..], &["-o", png.to_str().unwrap(), "--pick", "3"]].concat()).status.success());
}

#[test]
fn the_translucent_demo_renders_the_same_whatever_order_the_values_come_in() {
    let dir = tempfile::tempdir().unwrap();
    let render = |name: &str, values: [&str; 2]| {
        let png = dir.path().join(name);
        let args =
            ["render", "--demo", "cycloaddition", "--lavapipe", "--size", "160x120", "-o", png.to_str().unwrap()];
        let run = orbcloud(&[&args[..], &["--iso", values[0], "--iso", values[1]]].concat());
        let said = String::from_utf8_lossy(&run.stderr).into_owned();
        assert!(run.status.success(), "{said}");
        assert!(said.contains("exact order"), "{said}");
        image::open(&png).unwrap().to_rgba8()
    };
    let a = render("a.png", ["0.02", "0.05"]);
    // Coefficients edited per channel change the picture; a name that is none is refused.
    let png = dir.path().join("tuned.png");
    let tuned = orbcloud(&[
        "render",
        "--demo",
        "cycloaddition",
        "--lavapipe",
        "--size",
        "160x120",
        "--iso",
        "0.02",
        "--iso",
        "0.05",
        "--optics-scale",
        "g=3",
        "--optics-scale",
        "d=1,0.2,0.2",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(tuned.status.success(), "{}", String::from_utf8_lossy(&tuned.stderr));
    assert_ne!(image::open(&png).unwrap().to_rgba8(), a, "--optics-scale changes the image");
    let bad = orbcloud(&["render", "--demo", "cycloaddition", "--optics-scale", "q=1", "-o", "x.png"]);
    assert!(!bad.status.success() && String::from_utf8_lossy(&bad.stderr).contains("not a coefficient"));
    let b = render("b.png", ["0.05", "0.02"]);
    assert_eq!(a, b, "the order of --iso values changes nothing");
    // Translucent surfaces of two molecules in colour, not a blank frame.
    let coloured = a.pixels().filter(|p| p[0].abs_diff(p[2]) > 40 || p[1].abs_diff(p[2]) > 40).count();
    assert!(coloured > 2_000, "{coloured} coloured pixels");
}

#[test]
fn help_names_every_format_read() {
    let text = |args: &[&str]| {
        let out = orbcloud(args);
        assert!(out.status.success(), "{args:?}");
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let one: Vec<&str> = orbcloud::formats::extensions().chain([".gz"]).collect();
    for args in [&["--help"][..], &["viewer", "--help"], &["info", "--help"], &["render", "--help"]] {
        let help = text(args);
        for &ext in &one {
            assert!(help.contains(ext), "`orbcloud {}` does not name {ext}:\n{help}", args.join(" "));
        }
        let viewer = args.len() == 1 || args[0] == "viewer";
        assert_eq!(help.contains(".scan.toml"), viewer, "`orbcloud {}`:\n{help}", args.join(" "));
    }
}

#[test]
fn render_views_along_presets_and_refuses_bad_ones_before_any_gpu_work() {
    let dir = tempfile::tempdir().unwrap();
    // The bundled formaldehyde: atoms 1 (C) and 2 (O) make the C=O bond.
    let along_bond = dir.path().join("bond.png");
    let out = orbcloud(&[
        "render",
        "--view",
        "bond:1,2",
        "--size",
        "96x64",
        "--lavapipe",
        "-o",
        along_bond.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let side = dir.path().join("auto.png");
    let out = orbcloud(&["render", "--size", "96x64", "--lavapipe", "-o", side.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (a, b) = (image::open(&along_bond).unwrap().to_rgba8(), image::open(&side).unwrap().to_rgba8());
    assert_ne!(a.as_raw(), b.as_raw(), "down the bond differs from the first view");
    for (view, says) in [("bond:1,99", "atom 99"), ("plane:1,2", "3 atom numbers"), ("sideways", "expected auto")] {
        let start = std::time::Instant::now();
        let out = orbcloud(&["render", "--view", view, "--lavapipe", "-o", "/dev/null"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "--view {view}: {err}");
        assert!(start.elapsed().as_secs_f64() < 15.0, "--view {view} took {:?}", start.elapsed());
    }
}

#[test]
fn structures_through_info_render_and_bench() {
    let pdb = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/structures/4e43_excerpt.pdb");
    let out = orbcloud(&["info", pdb, "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let st = &v["structure"];
    assert_eq!(st["models"].as_array().unwrap().len(), 1);
    assert_eq!(st["all_atoms"], 197);
    assert_eq!(st["chains"][0]["name"], "A");
    assert_eq!(st["residues"][4]["name"], "GLU");
    assert_eq!(st["residues"][4]["number"], 34);
    // The shown atoms: the first alternate location only.
    assert_eq!(v["atoms"].as_array().unwrap().len(), 197 - 16);
    assert!(v["atoms"][0]["position_bohr"][0].as_f64().unwrap() > 30.0);

    let png = std::env::temp_dir().join(format!("orbcloud-cli-structure-{}.png", std::process::id()));
    let out = orbcloud(&[
        "render",
        pdb,
        "-o",
        png.to_str().unwrap(),
        "--size",
        "96x72",
        "--atoms",
        "licorice",
        "--color",
        "chain",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(image::open(&png).unwrap().width(), 96);
    std::fs::remove_file(&png).ok();

    let out = orbcloud(&["bench", "load", pdb, "--repeat", "1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("atoms=197") && text.contains("bonds_ms="), "{text}");
    let out = orbcloud(&["bench", "spheres", "--atoms", "2000", "--size", "64x48", "--frames", "1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("ms_per_frame_median=") && text.contains("gpu_bytes_per_atom="),
        "{text}"
    );
}

#[test]
fn molecular_surfaces_are_written_and_rendered() {
    let pdb = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/structures/4e43_excerpt.pdb");
    let dir = tempfile::tempdir().unwrap();
    let mut areas = Vec::new();
    for (kind, name) in [("ses", "solvent_excluded_surface"), ("gaussian", "gaussian_surface")] {
        let out = dir.path().join(format!("{kind}.obj"));
        let run =
            orbcloud(&["mesh", pdb, "--surface", kind, "--surface-resolution", "0.5", "-o", out.to_str().unwrap()]);
        let said = String::from_utf8_lossy(&run.stderr).to_string();
        assert!(run.status.success(), "{said}");
        let obj = std::fs::read_to_string(&out).unwrap();
        assert_eq!(obj.lines().filter(|l| l.starts_with("o ")).collect::<Vec<_>>(), [format!("o {name}")]);
        assert!(obj.lines().filter(|l| l.starts_with("f ")).count() > 10_000, "{kind}: a protein's surface");
        let area: f64 = said.split("area ").nth(1).and_then(|t| t.split(' ').next()).unwrap().parse().unwrap();
        areas.push(area);
    }
    // 181 atoms shown: each kind's area is of the order of the atoms' own (≈ 10–20 Å² each).
    assert!(areas.iter().all(|a| (1000.0..4000.0).contains(a)), "{areas:?}");
    let png = dir.path().join("ses.png");
    let run = orbcloud(&[
        "render",
        pdb,
        "--surface",
        "ses",
        "--surface-resolution",
        "0.6",
        "--atoms",
        "hidden",
        "--lavapipe",
        "--size",
        "120x90",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let img = image::open(&png).unwrap().to_rgba8();
    let bg = *img.get_pixel(0, 0);
    let drawn = img.pixels().filter(|p| p.0.iter().zip(bg.0).any(|(a, b)| a.abs_diff(b) > 8)).count();
    assert!(drawn > 120 * 90 / 10, "the surface covers the middle of the picture: {drawn} pixels");
    let bench = orbcloud(&[
        "bench",
        "surface",
        pdb,
        "--surface",
        "ses",
        "--surface-resolution",
        "0.6",
        "--runs",
        "1",
        "--frames",
        "1",
        "--lavapipe",
        "--size",
        "120x90",
    ]);
    let said = String::from_utf8_lossy(&bench.stdout);
    assert!(bench.status.success(), "{}", String::from_utf8_lossy(&bench.stderr));
    for key in ["build_ms_median=", "frame_ms_all_triangles=", "frame_ms_lod=", "lod_error_mean=", "phases (ms"] {
        assert!(said.contains(key), "{key} missing from {said}");
    }
    let bad = orbcloud(&["mesh", pdb, "--surface", "ses", "--surface-resolution", "0.0001", "-o", "x.obj"]);
    let said = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && said.contains("coarser resolution") && said.contains("4e43_excerpt.pdb"),
        "{said}"
    );
}

/// Benzene's RHF/6-31G* wavefunction (tests/fixtures/wavefunctions).
fn benzene() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions/benzene_631gs.molden").to_string()
}

fn render_png(args: &[&str]) -> (image::RgbaImage, String) {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("out.png");
    let mut all = vec!["render", "--lavapipe", "-o", png.to_str().unwrap()];
    all.extend_from_slice(args);
    let out = orbcloud(&all);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{args:?}: {stderr}");
    (image::open(&png).unwrap().to_rgba8(), stderr)
}

#[test]
fn render_draws_several_quantities_of_one_file_and_panes_side_by_side() {
    let file = benzene();
    let size = ["--size", "160x120"];
    let one = |q: &[&str]| render_png(&[&[file.as_str()][..], &size, q].concat()).0;
    // The density's translucent surface with the HOMO's inside it: both quantities are drawn.
    let surfaces = ["--iso", "0.05", "--translucent", "--no-volume"];
    let density = one(&[&["--density"][..], &surfaces].concat());
    let homo = one(&[&["--orbital", "homo"][..], &surfaces].concat());
    let (both, said) = render_png(
        &[&[file.as_str()][..], &size, &["--density"], &surfaces, &["--orbital", "homo"], &surfaces].concat(),
    );
    assert!(said.contains("pane 1: total density + HOMO"), "{said}");
    assert!(
        common::mean_difference(&both, &density) > 1.0,
        "the HOMO shows: {}",
        common::mean_difference(&both, &density)
    );
    assert!(
        common::mean_difference(&both, &homo) > 1.0,
        "the density shows: {}",
        common::mean_difference(&both, &homo)
    );
    // Clouds of both: each quantity's own options (here the HOMO's colours) are its own.
    let (clouds, _) = render_png(&[&[file.as_str()][..], &size, &["--density", "--orbital", "homo"]].concat());
    let (recoloured, _) =
        render_png(&[&[file.as_str()][..], &size, &["--density", "--orbital", "homo", "--colors", "gold"]].concat());
    assert!(common::mean_difference(&clouds, &recoloured) > 0.5, "the second quantity's colours apply to it");
    // HOMO | LUMO side by side, one camera: each pane is what its quantity alone draws.
    let (beside, said) =
        render_png(&[file.as_str(), "--size", "320x120", "--orbital", "homo", "--beside", "--orbital", "lumo"]);
    assert!(said.contains("pane 1: HOMO") && said.contains("pane 2: LUMO"), "{said}");
    assert_eq!(beside.dimensions(), (320, 120));
    // Each pane is captioned with its quantity at its top left; without captions each pane is
    // what its quantity alone draws.
    let (bare, _) = render_png(&[
        file.as_str(),
        "--size",
        "320x120",
        "--orbital",
        "homo",
        "--beside",
        "--orbital",
        "lumo",
        "--no-captions",
    ]);
    let corner = |img: &image::RgbaImage, x| image::imageops::crop_imm(img, x, 0, 40, 12).to_image();
    for x in [0, 160] {
        let d = common::mean_difference(&corner(&beside, x), &corner(&bare, x));
        assert!(d > 3.0, "a caption at the top left of the pane at x = {x}: {d}");
    }
    let below = |img: &image::RgbaImage, x| image::imageops::crop_imm(img, x, 40, 160, 80).to_image();
    assert_eq!(common::mean_difference(&below(&beside, 0), &below(&bare, 0)), 0.0, "only the caption differs");
    let beside = bare;
    let left = image::imageops::crop_imm(&beside, 0, 0, 160, 120).to_image();
    let right = image::imageops::crop_imm(&beside, 160, 0, 160, 120).to_image();
    let (lumo, homo) = (one(&["--orbital", "lumo"]), one(&["--orbital", "homo"]));
    assert!(common::mean_difference(&left, &homo) < 0.5, "left pane: {}", common::mean_difference(&left, &homo));
    assert!(common::mean_difference(&right, &lumo) < 0.5, "right pane: {}", common::mean_difference(&right, &lumo));
    assert!(common::mean_difference(&left, &right) > 2.0, "HOMO and LUMO differ");
    // Options of the whole picture may come after the second quantity too.
    let (late, _) = render_png(&[
        file.as_str(),
        "--orbital",
        "homo",
        "--beside",
        "--orbital",
        "lumo",
        "--size",
        "320x120",
        "--no-captions",
    ]);
    assert_eq!(common::mean_difference(&late, &beside), 0.0, "--size after the quantities");
}

#[test]
fn listing_two_quantities_of_one_file_the_other_way_round_changes_nothing() {
    let file = benzene();
    let size = ["--size", "160x120"];
    let surfaces = ["--iso", "0.05", "--translucent", "--no-volume"];
    let render = |first: &[&str], second: &[&str]| render_png(&[&[file.as_str()][..], &size, first, second].concat()).0;
    let max_difference = |a: &image::RgbaImage, b: &image::RgbaImage| {
        a.pixels().zip(b.pixels()).flat_map(|(p, q)| (0..3).map(move |k| p[k].abs_diff(q[k]))).max().unwrap_or(0)
    };
    let density: Vec<&str> = [&["--density"][..], &surfaces].concat();
    let homo: Vec<&str> = [&["--orbital", "homo"][..], &surfaces].concat();
    let (a, b) = (render(&density, &homo), render(&homo, &density));
    // A knife-edge pixel may differ: one whose centre an outline passes through, or whose two
    // surfaces' fragments lie at one depth (ties go by the surfaces' order,
    // scene::translucency::sort_fragments), where the last bit of a vertex decides. Seen: one
    // pixel of 19,200, on the density's outline. Nothing else may.
    let differing = a.pixels().zip(b.pixels()).filter(|(p, q)| (0..3).any(|k| p[k].abs_diff(q[k]) > 1)).count();
    assert!(differing <= 2, "translucent surfaces: {differing} pixels differ, by up to {}/255", max_difference(&a, &b));
    assert!(common::mean_difference(&a, &b) < 0.05, "translucent surfaces: {}", common::mean_difference(&a, &b));
    // Overlapping clouds: one depth order, whichever is listed first.
    let (a, b) = (render(&["--density"], &["--orbital", "homo"]), render(&["--orbital", "homo"], &["--density"]));
    assert!(max_difference(&a, &b) <= 1, "clouds: {}/255", max_difference(&a, &b));
    let homo_alone = render(&["--orbital", "homo"], &[]);
    assert!(common::mean_difference(&a, &homo_alone) > 1.0, "both clouds are drawn");
}

#[test]
fn mesh_writes_each_quantitys_surfaces_named_after_it() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("both.obj");
    let file = benzene();
    let out = orbcloud(&[
        "mesh",
        &file,
        "--grid-points",
        "40",
        "--density",
        "--iso",
        "0.1",
        "--orbital",
        "homo",
        "--iso",
        "0.05",
        "--iso",
        "0.02",
        "-o",
        obj.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&obj).unwrap();
    let objects: Vec<&str> = text.lines().filter_map(|l| l.strip_prefix("o ")).collect();
    assert_eq!(
        objects,
        ["density_0.1", "homo_plus_0.02", "homo_minus_0.02", "homo_plus_0.05", "homo_minus_0.05"],
        "each quantity's surfaces, its levels in increasing order"
    );
    // A quantity without levels of its own, or --beside, is refused with the reason.
    let out = orbcloud(&["mesh", &file, "--density", "--iso", "0.1", "--orbital", "homo", "-o", obj.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("--orbital homo: each quantity needs its own --iso"));
    let out =
        orbcloud(&["mesh", &file, "--iso", "0.1", "--beside", "--orbital", "lumo", "--iso", "0.1", "-o", "x.obj"]);
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("`mesh` does not"));
}

#[test]
fn a_closed_output_ends_a_command_quietly() {
    use std::io::Read;
    // `orbcloud info FILE | head -1` of a file whose description is far longer than a pipe holds:
    // the reader goes away after the first bytes.
    let dir = tempfile::tempdir().unwrap();
    let xyz = dir.path().join("many.xyz");
    let atoms: String =
        (0..5000).map(|k| format!("C {} {} 0.0\n", (k % 70) as f64 * 1.5, (k / 70) as f64 * 1.5)).collect();
    std::fs::write(&xyz, format!("5000\nmany carbons\n{atoms}")).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_orbcloud"))
        .args(["info", xyz.to_str().unwrap()])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("run orbcloud");
    let mut first = [0u8; 16];
    child.stdout.as_mut().unwrap().read_exact(&mut first).unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked") && !stderr.contains("Broken pipe"), "{stderr}");
}

#[test]
fn natural_orbitals_have_their_frontier_by_occupation_and_no_energies() {
    // Water's orbitals written as natural orbitals: fractional occupations, and (as some writers
    // do) the occupations in place of the energies.
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/wavefunctions/h2o_cart_631gs.molden"
    ))
    .unwrap();
    let occupations = [1.9998, 1.993, 1.98, 1.97, 1.96, 0.045, 0.03, 0.012];
    let mut k = 0;
    let natural: String = text
        .lines()
        .map(|l| {
            let t = l.trim_start();
            if t.starts_with("Ene=") || t.starts_with("Occup=") {
                let occ = occupations.get(k / 2).copied().unwrap_or(0.0);
                k += 1;
                format!("{} {occ}", if t.starts_with("Ene=") { "Ene=" } else { "Occup=" })
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no.molden");
    std::fs::write(&path, natural).unwrap();
    let out = orbcloud(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("natural orbitals: HOMO and LUMO by occupation; the file's energies are its occupations"),
        "{text}"
    );
    assert!(text.contains("HOMO: MO 5 Alpha A no energy, occupation 1.960"), "{text}");
    assert!(text.contains("LUMO: MO 6 Alpha A no energy, occupation 0.045"), "{text}");
}

/// Numbers out of range, NaN or infinite are refused by name before anything is read or
/// drawn: four billion slices would otherwise be an allocation that aborts the process.
#[test]
fn numeric_options_out_of_range_are_refused_by_name() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions/h2o_cart_631gs.molden");
    let cases: &[(&[&str], &str, &str)] = &[
        (&["render", file, "-o", "x.png", "--slices", "4000000000"], "--slices", "1..=4096"),
        (&["render", file, "-o", "x.png", "--zoom", "nan"], "--zoom", "0.001..=1000"),
        (&["render", file, "-o", "x.png", "--yaw", "inf"], "--yaw", "outside"),
        (&["render", file, "-o", "x.png", "--k1=-1"], "--k1", "0..=1000"),
        (&["render", file, "-o", "x.png", "--iso", "NaN"], "--iso", "outside"),
        (&["render", file, "-o", "x.png", "--grid-points", "100000"], "--grid-points", "8..=512"),
        (&["render", file, "-o", "x.png", "--ball-scale", "30"], "--ball-scale", "0.3..=3"),
        (&["render", file, "-o", "x.png", "--clip", "0,0,0"], "--clip", "not zero"),
        (&["render", file, "-o", "x.png", "--clip", "0,0,1,nan"], "--clip", "outside"),
        (&["cube", file, "-o", "x.cube", "--grid", "100000"], "--grid", "8..=512"),
        (&["cube", file, "-o", "x.cube", "--spacing", "0"], "--spacing", "0.001..=10"),
        (&["modes", file, "--mode", "1", "-o", "x.xyz", "--frames", "0"], "--frames", "1..=100000"),
        (&["mesh", file, "-o", "x.obj", "--iso-sigma=-2"], "--iso-sigma", "0..=1000"),
    ];
    for (args, option, expected) in cases {
        let out = orbcloud(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} ran");
        assert_eq!(out.status.code(), Some(2), "a usage error, not a crash: {args:?}\n{stderr}");
        assert!(stderr.contains(&format!("'{option} <")) && stderr.contains(expected), "{args:?}: {stderr}");
    }
}

/// `x` as C's `% .17e` writes it, as Psi4's Molden writer does: a space for the sign of a
/// positive number, an exponent of at least two digits with its sign.
fn c_exponent(x: f64) -> String {
    let s = format!("{x:.17e}");
    let (mantissa, exponent) = s.split_once('e').unwrap();
    let exponent: i32 = exponent.parse().unwrap();
    let sign = if exponent < 0 { '-' } else { '+' };
    format!("{}{mantissa}e{sign}{:02}", if x < 0.0 { "" } else { " " }, exponent.abs())
}

#[test]
fn psi4_natural_orbitals_write_each_spin_s_occupation_as_their_energy() {
    // Water's orbitals rewritten in the layout of Psi4's Molden writer for natural orbitals of a
    // restricted density: `Ene=` the occupation of one spin, `Occup=` that of both.
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/wavefunctions/h2o_cart_631gs.molden"
    ))
    .unwrap();
    let (head, mo) = text.split_once("[MO]\n").unwrap();
    let per_spin = [0.99991, 0.9965, 0.99, 0.985, 0.98, 0.0225, 0.015, 0.006];
    let mut psi4 = format!("{head}[MO]\n");
    let mut k = 0;
    for line in mo.lines() {
        let t = line.trim();
        if t.starts_with("Sym=") {
            let occ = per_spin.get(k).copied().unwrap_or(0.0);
            k += 1;
            psi4 += &format!(" Sym= A\n Ene= {}\n Spin= Alpha\n Occup= {}\n", c_exponent(occ), c_exponent(2.0 * occ));
        } else if let (false, Some((index, value))) = (t.contains('='), t.split_once(char::is_whitespace)) {
            let value: f64 = value.trim().parse().unwrap();
            psi4 += &format!("{:>3} {}\n", index, c_exponent(value));
        }
    }
    assert!(
        psi4.contains(" Ene=  9.99909999999999966e-01\n Spin= Alpha\n Occup=  1.99981999999999993e+00\n"),
        "{}",
        &psi4[head.len()..head.len() + 300]
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no.molden");
    std::fs::write(&path, psi4).unwrap();
    let out = orbcloud(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(
            "natural orbitals: HOMO and LUMO by occupation; the file's energies are its occupations per spin (half of Occup=)"
        ),
        "{text}"
    );
    assert!(text.contains("HOMO: MO 5 Alpha A no energy, occupation 1.960"), "{text}");
    assert!(text.contains("LUMO: MO 6 Alpha A no energy, occupation 0.045"), "{text}");
    let out = orbcloud(&["info", path.to_str().unwrap(), "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let wf = &json["wavefunction"];
    assert_eq!(wf["energies_as_occupations"], "per_spin", "{wf}");
    assert_eq!(wf["energies_are_occupations"], true);
}

#[test]
fn ball_and_stick_sizes_change_the_picture() {
    let file = benzene();
    let base = [file.as_str(), "--size", "160x120", "--no-volume"];
    let (plain, _) = render_png(&base);
    let (balls, _) = render_png(&[&base[..], &["--ball-scale", "2"]].concat());
    let (sticks, _) = render_png(&[&base[..], &["--stick-scale", "2.5"]].concat());
    let lit = |img: &image::RgbaImage| {
        common::coverage(img, [img.get_pixel(0, 0)[0], img.get_pixel(0, 0)[1], img.get_pixel(0, 0)[2]])
    };
    assert!(lit(&balls) > 1.3 * lit(&plain), "bigger balls cover more: {} vs {}", lit(&balls), lit(&plain));
    assert!(lit(&sticks) > lit(&plain), "thicker sticks cover more: {} vs {}", lit(&sticks), lit(&plain));
    assert!(common::mean_difference(&sticks, &balls) > 0.5);
}

#[test]
fn the_clipping_plane_cuts_what_render_draws_and_atoms_only_when_asked() {
    let size = ["--size", "96x64", "--no-volume"];
    let whole = render_png(&size).0;
    // The bundled formaldehyde's atoms stay whole under a plane that cuts no atoms.
    let spared = render_png(&[&size[..], &["--clip", "1,0,0"]].concat()).0;
    assert_eq!(whole.as_raw(), spared.as_raw(), "--clip alone leaves atoms whole");
    let cut = render_png(&[&size[..], &["--clip", "1,0,0", "--clip-atoms"]].concat()).0;
    assert_ne!(whole.as_raw(), cut.as_raw(), "--clip-atoms cuts them");
    let out = orbcloud(&["render", "--clip-atoms", "--lavapipe", "-o", "/dev/null"]);
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("--clip"));
    // Several quantities of one file: the plane (the object's, wherever it is given) cuts
    // every one of them.
    let file = benzene();
    let density = [file.as_str(), "--size", "96x64", "--atoms", "hidden", "--density", "--iso", "0.05", "--no-volume"];
    let homo = ["--orbital", "homo", "--iso", "0.05", "--no-volume"];
    let whole = render_png(&[&density[..], &homo].concat()).0;
    let cut = render_png(&[&density[..], &homo, &["--clip", "0,0,1,-0.5"]].concat()).0;
    let only_density = render_png(&[&density[..], &["--clip", "0,0,1,-0.5"], &homo].concat()).0;
    assert_ne!(whole.as_raw(), cut.as_raw());
    assert_eq!(cut.as_raw(), only_density.as_raw(), "--clip belongs to the picture, not a quantity");
}

/// What a newcomer types wrong gets a message that says what there is: an orbital past the
/// last, a directory with no frames (no "line 0"), an empty points file, a density asked of
/// atoms alone; and no display is needed for `render` to stay quiet.
#[test]
fn first_hour_mistakes_get_messages_that_say_what_there_is() {
    let dir = tempfile::tempdir().unwrap();
    let molden = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions/h2o_cart_631gs.molden");
    let molden = molden.to_str().unwrap();
    let fails = |args: &[&str]| {
        let out = orbcloud(args);
        assert!(!out.status.success(), "{args:?} succeeded");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let err = fails(&["render", molden, "--orbital", "999", "-o", "/dev/null", "--lavapipe"]);
    assert!(err.contains("--orbital 999: the file has 19 orbitals (1–19), the HOMO is 5"), "{err}");
    assert!(!err.contains("Index(") && !err.contains("Alpha"), "no debug text: {err}");

    let empty = dir.path().join("frames");
    std::fs::create_dir(&empty).unwrap();
    let err = fails(&["scan", "init", empty.to_str().unwrap()]);
    assert!(err.contains("frames: expected a directory with at least two"), "{err}");
    assert!(!err.contains(":0:"), "no line 0: {err}");

    let points = dir.path().join("points.txt");
    std::fs::write(&points, "# nothing yet\n").unwrap();
    let err = fails(&["eval", molden, "--points", points.to_str().unwrap()]);
    assert!(err.contains("points.txt: expected lines of `x y z` in bohr, found none"), "{err}");

    let xyz = dir.path().join("water.xyz");
    std::fs::write(&xyz, "3\nwater\nO 0 0 0\nH 0.96 0 0\nH -0.24 0.93 0\n").unwrap();
    let err = fails(&["render", xyz.to_str().unwrap(), "--density", "-o", "/dev/null", "--lavapipe"]);
    assert!(err.contains("--density needs a wavefunction") && err.contains("orbcloud compute"), "{err}");

    // Without XDG_RUNTIME_DIR (ssh, cron, CI) nothing is printed about it.
    let png = dir.path().join("w.png");
    let out = Command::new(env!("CARGO_BIN_EXE_orbcloud"))
        .args(["render", molden, "--size", "64x48", "-o", png.to_str().unwrap()])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("XDG_RUNTIME_DIR"), "{err}");
}
