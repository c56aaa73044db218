//! `orbcloud plane` end to end: the numbers it writes are PySCF's (`eval_ao`) orbital and
//! density at the same points, the points lie on the plane asked for, the SVG holds the contour
//! lines, and bad planes fail with a message, not a panic. PySCF runs in the Python
//! `ORBCLOUD_PYTHON` names (`scripts/test` sets it up).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use glam::DVec3;
use orbcloud::model::units::BOHR_PER_ANGSTROM;

mod common;

fn orbcloud(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).output().expect("run orbcloud")
}

fn fixture(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions").join(name).display().to_string()
}

/// Water at RHF/6-31G*, written by PySCF's Molden writer; `compare` evaluates the same SCF's
/// LUMO and density with `eval_ao` at a CSV's points and prints the largest differences.
const SCRIPT: &str = r#"
import json, sys
import numpy as np
from pyscf import gto, scf
from pyscf.tools import molden

mol = gto.M(atom="O 0 0 0.1173; H 0 0.7572 -0.4692; H 0 -0.7572 -0.4692", basis="6-31g*", verbose=0)
mf = scf.RHF(mol)
mf.conv_tol = 1e-11
mf.kernel()
if sys.argv[1] == "make":
    molden.from_scf(mf, sys.argv[2])
    sys.exit(0)
lumo = int(np.max(np.nonzero(mf.mo_occ > 0))) + 1
out = {}
for name, path in (("orbital", sys.argv[2]), ("density", sys.argv[3])):
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    ao = mol.eval_gto("GTOval_sph", table[:, :3])
    if name == "orbital":
        ref = ao @ mf.mo_coeff[:, lumo]
    else:
        occupied = mf.mo_coeff[:, mf.mo_occ > 0]
        ref = np.einsum("pi,i,pi->p", ao @ occupied, mf.mo_occ[mf.mo_occ > 0], ao @ occupied)
    out[name] = {"max_diff": float(np.max(np.abs(table[:, 3] - ref))), "max_abs": float(np.max(np.abs(ref))), "n": len(ref)}
print(json.dumps(out))
"#;

fn python(script: &Path, args: &[&str]) -> String {
    let python = orbcloud::sources::compute::python();
    let out = Command::new(&python).arg(script).args(args).output().expect("run python");
    assert!(
        out.status.success(),
        "`{python}` failed (is PySCF installed? scripts/test sets ORBCLOUD_PYTHON): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The CSV's points (bohr) and values, checking its header.
fn read_csv(path: &Path) -> Vec<(DVec3, f64)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("x,y,z,value"));
    lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|t| t.parse().unwrap()).collect();
            (DVec3::new(v[0], v[1], v[2]), v[3])
        })
        .collect()
}

fn path(dir: &Path, name: &str) -> (PathBuf, String) {
    let p = dir.join(name);
    let s = p.display().to_string();
    (p, s)
}

#[test]
fn plane_values_are_pyscf_s_on_the_plane_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("water.py");
    std::fs::write(&script, SCRIPT).unwrap();
    let (molden, molden_s) = path(dir.path(), "water.molden");
    python(&script, &["make", &molden_s]);
    assert!(molden.exists());
    let (lumo_csv, lumo_s) = path(dir.path(), "lumo.csv");
    let (rho_csv, rho_s) = path(dir.path(), "rho.csv");
    let (svg, svg_s) = path(dir.path(), "lumo.svg");
    let (png, png_s) = path(dir.path(), "rho.png");
    // The LUMO (σ*, of both signs) and the density 0.3 Å off the molecular plane.
    let offset = 0.3;
    for (what, out, csv) in [("--orbital=lumo", &svg_s, &lumo_s), ("--density", &png_s, &rho_s)] {
        let o = orbcloud(&[
            "plane",
            &molden_s,
            what,
            "--through",
            "1,2,3",
            "--offset",
            "0.3",
            "--points",
            "61",
            "-o",
            out,
            "--values",
            csv,
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert!(png.exists());

    // On the plane through the three atoms, `offset` along (H1 − O) × (H2 − O).
    let doc = orbcloud::formats::load(&molden).unwrap();
    let [o, h1, h2] = [0, 1, 2].map(|i| doc.molecule.atoms[i].position);
    let normal = (h1 - o).cross(h2 - o).normalize();
    for csv in [&lumo_csv, &rho_csv] {
        let rows = read_csv(csv);
        assert_eq!(rows.len(), 61 * 61);
        for (p, _) in &rows {
            let d = (*p - o).dot(normal);
            assert!((d - offset * BOHR_PER_ANGSTROM).abs() < 1e-10, "{p} lies {d} bohr from the plane");
        }
    }

    // PySCF's values at the same points.
    let json = python(&script, &["compare", &lumo_s, &rho_s]);
    let result: serde_json::Value = serde_json::from_str(json.trim()).unwrap();
    for name in ["orbital", "density"] {
        let r = &result[name];
        let (diff, max) = (r["max_diff"].as_f64().unwrap(), r["max_abs"].as_f64().unwrap());
        assert_eq!(r["n"].as_u64(), Some(61 * 61));
        assert!(max > 0.01, "{name}: the plane meets the quantity ({max})");
        assert!(diff <= 1e-8 * max, "{name}: max |orbcloud − PySCF| = {diff:e}, max |value| = {max}");
    }

    // The SVG draws each contour as a polyline, the negative lobes' dashed.
    let text = std::fs::read_to_string(&svg).unwrap();
    let contours: Vec<&str> = text.lines().filter(|l| l.starts_with(r#"<polyline class="contour""#)).collect();
    assert!(contours.len() >= 10, "{} contour lines", contours.len());
    assert!(contours.iter().any(|l| l.contains("stroke-dasharray")), "negative levels are dashed");
    assert!(contours.iter().any(|l| !l.contains("stroke-dasharray")));
}

#[test]
fn bad_planes_fail_with_a_message() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("map.png").display().to_string();
    let water = fixture("h2o_cart_631gs.molden");
    for (args, expected) in [
        (&["--through", "1,2,4"][..], "atom 4 does not exist"),
        (&["--through", "1,2,2"][..], "repeat an atom"),
        (&["--origin", "0,0,0", "--normal", "0,0,0"][..], "normal is zero"),
        (&["--through", "1,2,3", "--points", "4001"][..], "4001 points per side"),
        (&["--through", "1,2,3", "--extent=0"][..], "positive side"),
        (&["--bond", "1,2", "--toward", "0,0,0"][..], "runs along the bond"),
        (&[][..], "which plane?"),
    ] {
        let mut line = vec!["plane", water.as_str(), "-o", out.as_str()];
        line.extend(args);
        let o = orbcloud(&line);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    let svg_out = dir.path().join("map.txt").display().to_string();
    let o = orbcloud(&["plane", &water, "--through", "1,2,3", "-o", &svg_out]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("PNG or SVG"));
}

#[test]
fn a_cube_file_is_interpolated_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let water = fixture("h2o_cart_631gs.molden");
    let cube = dir.path().join("rho.cube").display().to_string();
    let o = orbcloud(&["cube", &water, "--density", "--grid", "40", "-o", &cube]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (exact_csv, exact_s) = path(dir.path(), "exact.csv");
    let (cube_csv, cube_s) = path(dir.path(), "cube.csv");
    let (svg, svg_s) = path(dir.path(), "cube.svg");
    let png = dir.path().join("exact.png").display().to_string();
    let plane = ["--through", "1,2,3", "--points", "41", "--extent", "3"];
    let run = |file: &str, out: &str, csv: &str| {
        let mut line = vec!["plane", file, "--density", "-o", out, "--values", csv];
        line.extend(plane);
        if file.ends_with(".cube") {
            line.retain(|w| *w != "--density");
        }
        orbcloud(&line)
    };
    let exact = run(&water, &png, &exact_s);
    assert!(exact.status.success(), "{}", String::from_utf8_lossy(&exact.stderr));
    assert!(!String::from_utf8_lossy(&exact.stderr).contains("interpolated"));
    let interpolated = run(&cube, &svg_s, &cube_s);
    assert!(interpolated.status.success(), "{}", String::from_utf8_lossy(&interpolated.stderr));
    assert!(String::from_utf8_lossy(&interpolated.stderr).contains("interpolated trilinearly"));
    assert!(std::fs::read_to_string(&svg).unwrap().contains("interpolated trilinearly"), "the caption says so");
    // Interpolated values follow the exact ones where the density is smooth (away from the
    // nuclei's cusps), and are not them.
    let (exact, cube) = (read_csv(&exact_csv), read_csv(&cube_csv));
    assert_eq!(exact.len(), cube.len());
    let smooth: Vec<(f64, f64)> =
        exact.iter().zip(&cube).map(|(e, c)| (e.1, c.1)).filter(|(e, c)| *e < 0.05 && c.is_finite()).collect();
    assert!(smooth.len() > 500);
    let worst = smooth.iter().map(|(e, c)| (e - c).abs() / 0.05).fold(0.0, f64::max);
    assert!(worst < 0.1, "interpolation error {worst} of 0.05");
    assert!(smooth.iter().any(|(e, c)| e != c));
}

/// The Laplacian and the NCI quantities on a plane are what `eval` gives at the same points
/// (itself checked against PySCF's second derivatives in tests/nci_pyscf.rs), and gradient
/// lines reach the SVG.
#[test]
fn second_derivative_quantities_map_as_eval_gives_them() {
    let dir = tempfile::tempdir().unwrap();
    let water = fixture("h2o_cart_631gs.molden");
    for flag in ["--laplacian", "--rdg", "--sign-lambda2-rho"] {
        let (csv, csv_s) = path(dir.path(), "map.csv");
        let (svg, svg_s) = path(dir.path(), "map.svg");
        let o = orbcloud(&[
            "plane",
            &water,
            flag,
            "--through",
            "1,2,3",
            "--offset",
            "0.2",
            "--points",
            "12",
            "--gradient-lines",
            "--bohr",
            "-o",
            &svg_s,
            "--values",
            &csv_s,
        ]);
        assert!(o.status.success(), "{flag}: {}", String::from_utf8_lossy(&o.stderr));
        let map = read_csv(&csv);
        let points: String = map.iter().map(|(p, _)| format!("{} {} {}\n", p.x, p.y, p.z)).collect();
        let (pts, pts_s) = path(dir.path(), "points.txt");
        std::fs::write(&pts, points).unwrap();
        let o = orbcloud(&["eval", &water, flag, "--points", &pts_s]);
        assert!(o.status.success(), "{flag}: {}", String::from_utf8_lossy(&o.stderr));
        let eval: Vec<f64> = String::from_utf8_lossy(&o.stdout)
            .lines()
            .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
            .filter_map(|l| l.split_whitespace().nth(3)?.parse().ok())
            .collect();
        assert_eq!(eval.len(), map.len(), "{flag}");
        let largest = map.iter().map(|(_, v)| v.abs()).fold(0.0, f64::max);
        let worst = map.iter().zip(&eval).map(|((_, a), b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(worst <= 1e-9 * largest.max(1.0), "{flag}: worst {worst:e} of {largest:e}");
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("u (bohr)"), "{flag}: axes in bohr");
        if flag == "--laplacian" {
            assert!(text.contains(r#"class="gradient""#), "gradient lines drawn");
        }
    }
}

/// The plane map's frame in the view is a representation of its own (`gpu::plane_frame`): lines
/// of a constant width on screen where the plane lies, hidden where an atom stands in front.
#[test]
fn the_plane_frame_is_drawn_where_the_plane_lies_and_atoms_in_front_hide_it() {
    use glam::Vec3;
    use orbcloud::gpu::{FrameInput, OffscreenTarget, Renderer};
    use orbcloud::model::Molecule;
    use orbcloud::model::atom::Atom;
    use orbcloud::scene::{AtomStyle, Camera, RenderSettings, VolumeSettings};
    let ctx = common::lavapipe();
    let size = [200u32, 200];
    // A carbon at the origin, space filling (radius about 3 bohr), in front of the plane z = −1.
    let carbon = Atom { z: 6, charge: 6.0, position: DVec3::ZERO, ghost: false };
    let mut renderer = Renderer::new(&ctx);
    renderer.main().set_molecule(&ctx, &Molecule::new(vec![carbon]), AtomStyle::SpaceFilling);
    let c = |x: f32, y: f32| Vec3::new(x, y, -1.0);
    let square = [c(-6.0, -6.0), c(6.0, -6.0), c(6.0, 6.0), c(-6.0, 6.0)];
    let mut lines: Vec<[Vec3; 2]> = (0..4).map(|k| [square[k], square[(k + 1) % 4]]).collect();
    lines.push([square[0], square[2]]);
    let amber = [1.0, 0.72, 0.19];
    renderer.main().plane_frame.set_lines(&ctx, &lines, amber);
    assert_eq!(renderer.main().plane_frame.count(), 5);
    let camera = Camera::framing(Vec3::splat(-8.0), Vec3::splat(8.0));
    let hidden = [VolumeSettings { visible: false, ..Default::default() }];
    let target = OffscreenTarget::new(&ctx.device, size);
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let frame = FrameInput {
        camera: &camera,
        background: RenderSettings::default().background,
        clouds: &hidden,
        size,
        tile: None,
    };
    renderer.render(&ctx, &mut encoder, &target.color_view, &frame);
    ctx.queue.submit([encoder.finish()]);
    let picture = target.read_rgba(&ctx.device, &ctx.queue).unwrap();
    let is_amber = |p: &image::Rgba<u8>| p[0] > 200 && (120..230).contains(&p[1]) && p[2] < 140;
    let clip = renderer.clip_from_world(&camera, size);
    let pixel = |p: Vec3| {
        let q = clip * p.extend(1.0);
        let ndc = q.truncate() / q.w;
        [((ndc.x * 0.5 + 0.5) * size[0] as f32) as u32, ((0.5 - ndc.y * 0.5) * size[1] as f32) as u32]
    };
    // Along each edge of the square (nothing in front), the frame's colour within a pixel.
    for [a, b] in &lines[..4] {
        for t in [0.25f32, 0.5, 0.75] {
            let [x, y] = pixel(a.lerp(*b, t));
            let near = (x.saturating_sub(1)..=x + 1).flat_map(|x| (y.saturating_sub(1)..=y + 1).map(move |y| (x, y)));
            assert!(near.into_iter().any(|(x, y)| is_amber(picture.get_pixel(x, y))), "edge at {x},{y}");
        }
    }
    // The diagonal runs behind the carbon: hidden at its middle, seen near the corners.
    let [x, y] = pixel(c(0.0, 0.0));
    assert!(!is_amber(picture.get_pixel(x, y)), "the atom hides the frame behind it");
    let drawn = picture.pixels().filter(|p| is_amber(p)).count();
    eprintln!("plane frame: {drawn} pixels");
    // Five segments of some 50–70 pixels, two pixels wide, less what the atom covers.
    assert!((300..1200).contains(&drawn), "{drawn} pixels of the frame's colour");
}
