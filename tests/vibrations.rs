//! Normal modes: Molden's `[FREQ]`… sections and fchk's `Vib-*` records read back what PySCF
//! computed (scripts/make_mode_fixtures.py) to the printed precision; malformed sections are
//! refused with their line while the orbitals still open; `info`, `modes` and
//! `render --normal-mode` show them.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/modes").join(name)
}

fn orbcloud(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).output().expect("run orbcloud")
}

struct Expected {
    frequency: Vec<f64>,
    intensity: Vec<f64>,
    displacement: Vec<Vec<[f64; 3]>>,
    geometry: Vec<[f64; 3]>,
}

fn expected(name: &str) -> Expected {
    let text = std::fs::read_to_string(fixture(&format!("{name}.expected.json"))).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let list = |k: &str| v[k].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect::<Vec<_>>();
    let triple = |x: &serde_json::Value| {
        let a = x.as_array().unwrap();
        [a[0].as_f64().unwrap(), a[1].as_f64().unwrap(), a[2].as_f64().unwrap()]
    };
    Expected {
        frequency: list("frequency_cm1"),
        intensity: list("ir_intensity"),
        displacement: v["displacement"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m.as_array().unwrap().iter().map(triple).collect())
            .collect(),
        geometry: v["geometry_bohr"].as_array().unwrap().iter().map(triple).collect(),
    }
}

/// Reads `file` and checks its modes against `name`'s expected values within `tolerance` of
/// each printed number (absolute for Molden's fixed decimals, relative for fchk's exponents).
fn check(name: &str, ext: &str, tolerance: impl Fn(f64) -> f64) {
    let doc = orbcloud::formats::load(&fixture(&format!("{name}.{ext}"))).expect("the file opens");
    assert!(doc.wavefunction.is_some() && doc.problems.is_empty(), "{:?}", doc.problems);
    let v = doc.vibrations.as_ref().expect("modes read");
    let e = expected(name);
    assert_eq!(v.modes.len(), e.frequency.len());
    let close = |a: f64, b: f64, what: &str| assert!((a - b).abs() <= tolerance(b), "{name}.{ext} {what}: {a} vs {b}");
    for (k, m) in v.modes.iter().enumerate() {
        close(m.frequency_cm1, e.frequency[k], "frequency");
        assert_eq!(m.is_imaginary(), e.frequency[k] < 0.0);
        close(m.ir_intensity.expect("an intensity"), e.intensity[k], "intensity");
        for (d, x) in m.displacement.iter().zip(&e.displacement[k]) {
            for c in 0..3 {
                close(d[c], x[c], "displacement");
            }
        }
    }
    for (p, x) in v.geometry.iter().zip(&e.geometry) {
        for c in 0..3 {
            close(p[c], x[c], "geometry");
        }
    }
}

#[test]
fn molden_and_fchk_modes_agree_with_pyscf_to_the_printed_precision() {
    for name in ["water_rhf_631g", "nh3_planar_rhf_sto3g"] {
        // Molden: %12.4f frequencies and intensities, %12.6f displacements, %14.6f geometry.
        check(name, "molden", |_| 5.1e-5);
        // fchk: %16.8E everywhere.
        check(name, "fchk", |x| 5.1e-9 * x.abs().max(1e-300) + 1e-300);
    }
    let ts = orbcloud::formats::load(&fixture("nh3_planar_rhf_sto3g.molden")).unwrap();
    let imaginary = ts.vibrations.unwrap().modes.iter().filter(|m| m.is_imaginary()).count();
    assert_eq!(imaginary, 1, "planar ammonia is the inversion's transition state");
}

#[test]
fn a_malformed_mode_section_is_refused_with_its_line_and_the_orbitals_still_open() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(fixture("water_rhf_631g.molden")).unwrap();
    let line = text.lines().position(|l| l.starts_with("vibration      2")).unwrap() + 2;
    let broken: String = text
        .lines()
        .enumerate()
        .map(|(k, l)| if k + 1 == line { "   0.1  zero  0.3".to_string() } else { l.to_string() })
        .collect::<Vec<_>>()
        .join("\n");
    let path = dir.path().join("broken.molden");
    std::fs::write(&path, broken).unwrap();
    let doc = orbcloud::formats::load(&path).expect("the orbitals still open");
    assert!(doc.wavefunction.is_some() && doc.vibrations.is_none());
    assert_eq!(doc.problems.len(), 1);
    assert!(doc.problems[0].contains(&format!("broken.molden:{line}")), "{:?}", doc.problems);
    // A count that does not match: a vibration block one atom short.
    let cut = text.lines().position(|l| l.starts_with("vibration      1")).unwrap() + 1;
    let short: String =
        text.lines().enumerate().filter(|(k, _)| *k != cut).map(|(_, l)| l).collect::<Vec<_>>().join("\n");
    std::fs::write(&path, short).unwrap();
    let doc = orbcloud::formats::load(&path).unwrap();
    assert!(
        doc.problems[0].contains(&format!(":{cut}:")) && doc.problems[0].contains("3 displacement lines"),
        "{:?}",
        doc.problems
    );
    // `info` says what was left out.
    let out = orbcloud(&["info", path.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("normal modes left out"));
}

#[test]
fn info_lists_the_modes_and_modes_writes_a_period_as_xyz_frames() {
    let ts = fixture("nh3_planar_rhf_sto3g.fchk");
    let out = orbcloud(&["info", ts.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let modes = v["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 6);
    assert!(modes[0]["frequency_cm1"].as_f64().unwrap() < -1000.0);
    assert!(modes[0]["ir_intensity"].as_f64().unwrap() > 100.0);
    assert_eq!(modes[0]["displacement"].as_array().unwrap().len(), 4, "one [x, y, z] per atom");
    let text = String::from_utf8(orbcloud(&["info", ts.to_str().unwrap()]).stdout).unwrap();
    assert!(text.contains("6 normal modes (1 imaginary: a transition state)") && text.contains("1117.82i"), "{text}");

    let dir = tempfile::tempdir().unwrap();
    let xyz = dir.path().join("umbrella.xyz");
    let out = orbcloud(&["modes", ts.to_str().unwrap(), "--mode", "1", "--frames", "8", "-o", xyz.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc = orbcloud::formats::load(&xyz).expect("the XYZ reader takes the frames back");
    let frames = &doc.structure.as_ref().unwrap().structure.models;
    assert_eq!(frames.len(), 8);
    // Frame 1 is the geometry itself; frame 3 (a quarter period) the largest displacement.
    let fchk = orbcloud::formats::load(&ts).unwrap();
    let first = doc.molecule.atoms.iter().zip(&fchk.molecule.atoms).map(|(a, b)| (a.position - b.position).length());
    assert!(first.fold(0.0, f64::max) < 1e-6);
    let bad = orbcloud(&["modes", ts.to_str().unwrap(), "--mode", "7", "-o", xyz.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&bad.stderr).contains("modes 1 to 6"));
    let none = orbcloud(&[
        "modes",
        fixture("../wavefunctions/h2o_cart_631gs.molden").to_str().unwrap(),
        "--mode",
        "1",
        "-o",
        "x.xyz",
    ]);
    assert!(String::from_utf8_lossy(&none.stderr).contains("no normal modes"));
}

#[test]
fn render_draws_the_displaced_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let ts = fixture("nh3_planar_rhf_sto3g.molden");
    let draw = |phase: &str| {
        let png = dir.path().join(format!("p{phase}.png"));
        let args = ["render", ts.to_str().unwrap(), "--lavapipe", "--no-volume", "--size", "160x120", "--view", "y"];
        let out = orbcloud(
            &[&args[..], &["--normal-mode", "1", "--phase", phase, "--amplitude", "0.8", "-o", png.to_str().unwrap()]]
                .concat(),
        );
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        image::open(&png).unwrap().to_rgba8()
    };
    let (rest, up, down) = (draw("0"), draw("90"), draw("270"));
    assert!(common::mean_difference(&rest, &up) > 0.2, "the atoms moved: {}", common::mean_difference(&rest, &up));
    assert!(common::mean_difference(&up, &down) > 0.2, "the other way: {}", common::mean_difference(&up, &down));
}

#[test]
fn a_modes_arrows_match_their_golden_image() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("arrows.png");
    let ts = fixture("nh3_planar_rhf_sto3g.molden");
    let args = [
        "render",
        ts.to_str().unwrap(),
        "--lavapipe",
        "--no-volume",
        "--size",
        "200x150",
        "--view",
        "y",
        "--yaw",
        "70",
        "--normal-mode",
        "1",
        "--phase",
        "0",
        "--amplitude",
        "0.5",
        "--arrows",
        "-o",
        png.to_str().unwrap(),
    ];
    let out = orbcloud(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    common::assert_golden("mode_arrows", &image::open(&png).unwrap().to_rgba8());
    let bad = orbcloud(&["render", ts.to_str().unwrap(), "--arrows", "-o", "x.png"]);
    assert!(!bad.status.success(), "--arrows needs a mode");
}

/// Pixels of the arrows' yellow in `img`: red and green high, blue low.
fn arrow_pixels(img: &image::RgbaImage) -> usize {
    img.pixels().filter(|p| p[0] > 170 && p[1] > 120 && p[2] < 90 && p[0].abs_diff(p[1]) < 90).count()
}

#[test]
fn a_modes_arrows_are_seen_through_the_cloud_and_the_translucent_surfaces() {
    let dir = tempfile::tempdir().unwrap();
    let water = fixture("water_rhf_631g.fchk");
    let draw = |name: &str, extra: &[&str]| {
        let png = dir.path().join(name);
        let mut args = vec![
            "render",
            water.to_str().unwrap(),
            "--lavapipe",
            "--size",
            "240x180",
            "--view",
            "x",
            "--normal-mode",
            "1",
            "--phase",
            "0",
            "--arrows",
            "-o",
            png.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let out = orbcloud(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        image::open(&png).unwrap().to_rgba8()
    };
    let bare = arrow_pixels(&draw("bare.png", &["--no-volume"]));
    let veiled = arrow_pixels(&draw("veiled.png", &["--iso", "0.05", "--translucent"]));
    eprintln!("arrow pixels: {bare} over the atoms alone, {veiled} inside the HOMO's cloud and surfaces");
    assert!(bare > 100, "the arrows are drawn: {bare} pixels");
    assert!(veiled * 10 >= bare * 9, "the cloud and the surfaces hide the arrows: {veiled} of {bare} pixels");
}

#[test]
fn arrow_impostors_cover_what_the_cpu_ray_cast_covers() {
    use glam::{DVec3, Vec3, Vec4};
    use orbcloud::gpu::{FrameInput, OffscreenTarget, Renderer};
    use orbcloud::model::arrow::Arrow;
    use orbcloud::scene::{Camera, RenderSettings, VolumeSettings};
    let ctx = common::lavapipe();
    let size = [160u32, 120];
    // Thick arrows, so that their edges are a small part of what they cover.
    let thick = |from: DVec3, v: DVec3| Arrow {
        shaft_radius: 0.25,
        head_radius: 0.5,
        head_length: 0.8,
        ..Arrow::along(from, v)
    };
    let arrows = [
        thick(DVec3::new(-2.0, 0.0, 0.0), DVec3::new(0.0, 2.5, 0.5)),
        thick(DVec3::new(1.0, -1.0, 0.5), DVec3::new(2.0, 0.5, -1.0)),
        thick(DVec3::new(0.0, 0.0, -1.0), DVec3::new(-0.3, -0.4, 2.2)),
    ];
    let mut renderer = Renderer::new(&ctx);
    renderer.main().arrows.set_arrows(&ctx, &arrows, [0.9, 0.7, 0.1]);
    let mut camera = Camera::framing(Vec3::splat(-3.5), Vec3::splat(3.5));
    camera.orbit(0.6, 0.35);
    let background = RenderSettings::default().background;
    let hidden = [VolumeSettings { visible: false, ..Default::default() }];
    let target = OffscreenTarget::new(&ctx.device, size);
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let frame = FrameInput { camera: &camera, background, clouds: &hidden, size, tile: None };
    renderer.render(&ctx, &mut encoder, &target.color_view, &frame);
    ctx.queue.submit([encoder.finish()]);
    let gpu = target.read_rgba(&ctx.device, &ctx.queue).unwrap();
    let bg = gpu.get_pixel(0, 0).0;
    // The CPU: a ray from the eye through each pixel's centre, met with every arrow.
    let world_from_clip = renderer.clip_from_world(&camera, size).inverse();
    let eye = camera.eye().as_dvec3();
    let (mut covered, mut differ) = (0, 0);
    for py in 0..size[1] {
        for px in 0..size[0] {
            let ndc = Vec4::new(
                (px as f32 + 0.5) / size[0] as f32 * 2.0 - 1.0,
                1.0 - (py as f32 + 0.5) / size[1] as f32 * 2.0,
                1.0,
                1.0,
            );
            let far = world_from_clip * ndc;
            let dir = ((far.truncate() / far.w).as_dvec3() - eye).normalize();
            let cpu = arrows.iter().any(|a| a.hit(eye, dir).is_some());
            let drawn = (0..3).any(|c| gpu.get_pixel(px, py).0[c].abs_diff(bg[c]) > 4);
            covered += usize::from(cpu);
            differ += usize::from(cpu != drawn);
        }
    }
    eprintln!("arrows: {covered} pixels covered by the CPU ray cast, {differ} differ on the GPU");
    assert!(covered > 500, "{covered} pixels");
    assert!(differ * 100 <= covered * 3, "{differ} of {covered} pixels differ");
}

#[test]
fn atoms_moved_in_place_draw_as_atoms_uploaded_anew() {
    use orbcloud::gpu::{FrameInput, OffscreenTarget, Renderer};
    use orbcloud::scene::{AtomStyle, Camera, VolumeSettings};
    let ctx = common::lavapipe();
    let doc = orbcloud::formats::load(&fixture("water_rhf_631g.fchk")).unwrap();
    let mut moved = doc.molecule.clone();
    for (k, atom) in moved.atoms.iter_mut().enumerate() {
        atom.position += glam::DVec3::new(0.3 * k as f64, -0.2, 0.1 * k as f64);
    }
    let size = [160u32, 120];
    let camera = Camera::framing(glam::Vec3::splat(-3.0), glam::Vec3::splat(3.0));
    let hidden = [VolumeSettings { visible: false, ..Default::default() }];
    let draw = |renderer: &mut Renderer| {
        let target = OffscreenTarget::new(&ctx.device, size);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let frame = FrameInput { camera: &camera, background: [0.0; 3], clouds: &hidden, size, tile: None };
        renderer.render(&ctx, &mut encoder, &target.color_view, &frame);
        ctx.queue.submit([encoder.finish()]);
        target.read_rgba(&ctx.device, &ctx.queue).unwrap()
    };
    let mut in_place = Renderer::new(&ctx);
    in_place.main().set_atoms(&ctx, &doc.molecule, AtomStyle::BallAndStick, None);
    let before = draw(&mut in_place);
    assert!(in_place.main().move_atoms(&ctx, &moved), "the same atoms and bonds move in place");
    let after = draw(&mut in_place);
    let mut anew = Renderer::new(&ctx);
    anew.main().set_atoms(&ctx, &moved, AtomStyle::BallAndStick, None);
    let reference = draw(&mut anew);
    assert!(common::mean_difference(&before, &after) > 0.5, "the atoms moved");
    assert_eq!(after, reference, "moved in place, the picture is the one of the atoms uploaded anew");
    let mut fewer = moved.clone();
    fewer.atoms.pop();
    fewer.bonds.retain(|b| b.a < 2 && b.b < 2);
    assert!(!in_place.main().move_atoms(&ctx, &fewer), "other atoms are uploaded anew");
}
