//! Dihedral scans: phase alignment, the interpolation error at a held-out angle, three-pass
//! against exact interpolation on lavapipe, the GPU mix against the CPU-interpolated grid, a
//! golden image at −90°, and the manifest's errors.

mod common;

use std::path::{Path, PathBuf};

use orbcloud::formats::cube_write;
use orbcloud::formats::scan::{init, load_scan};
use orbcloud::gpu::volume::VolumeTexture;
use orbcloud::gpu::{FrameInput, OffscreenTarget, Renderer};
use orbcloud::layers::key_volumes::{KeyOptions, ScanScene};
use orbcloud::model::VolumeGrid;
use orbcloud::model::scan::{Coordinate, Follow, Scan, Tracks};
use orbcloud::scene::{Interpolation, RenderSettings};
use orbcloud::sources::demo;

fn psb3() -> Scan {
    demo::scan().expect("bundled scan loads").scan
}

fn assets() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/psb3")
}

fn norm(v: &[f32]) -> f64 {
    v.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt()
}

#[test]
fn phase_alignment_undoes_the_solvers_sign_flips() {
    let scan = psb3();
    let tracks = scan.track(Follow::Index).unwrap();
    for slot in 0..2 {
        // PySCF turned the HOMO over once (−150° → −120°) and the LUMO twice (−180° → −150°,
        // −30° → 0°) in this scan (scripts/make_psb3_scan.py finds the same with PySCF's own
        // cross-geometry overlaps); after alignment every step overlaps its predecessor
        // positively and strongly.
        let expected: &[usize] = if slot == 0 { &[2] } else { &[1, 14] };
        let flipped: Vec<usize> = (0..scan.frames.len()).filter(|&f| tracks.points[slot][f].flipped).collect();
        assert_eq!(flipped, expected, "{}", scan.orbitals[slot]);
        for (f, p) in tracks.points[slot].iter().enumerate().skip(1) {
            assert!(p.overlap > 0.5, "{} step {f}: aligned overlap {}", scan.orbitals[slot], p.overlap);
        }
    }
    assert!(tracks.swaps.is_empty(), "no character swaps in PSB3's frontier orbitals: {:?}", tracks.swaps);
    // Flipping one frame's orbital in the input is seen and undone.
    let mut flipped = scan.clone();
    if let orbcloud::model::scan::FrameContent::Wavefunctions(w) = &mut flipped.frames[4].content {
        let wf = &mut w[0];
        let homo = tracks.points[0][4].index;
        wf.orbitals[homo].coefficients.iter_mut().for_each(|c| *c = -*c);
    }
    let t2 = flipped.track(Follow::Index).unwrap();
    assert_ne!(t2.points[0][4].flipped, tracks.points[0][4].flipped);
    assert!((t2.points[0][4].overlap - tracks.points[0][4].overlap).abs() < 1e-9);
}

#[test]
fn swapped_orbitals_are_reported_and_followed_by_overlap() {
    // HOMO and HOMO−1 trading places in one frame is what a character swap looks like.
    let scan = psb3();
    let mut swapped = scan.clone();
    if let orbcloud::model::scan::FrameContent::Wavefunctions(w) = &mut swapped.frames[2].content {
        let wf = &mut w[0];
        let spin = orbcloud::model::Spin::Alpha;
        let (h, h1) = (wf.homo(spin).unwrap(), wf.resolve("homo-1".parse().unwrap(), spin).unwrap());
        let c = wf.orbitals[h].coefficients.clone();
        wf.orbitals[h].coefficients = wf.orbitals[h1].coefficients.clone();
        wf.orbitals[h1].coefficients = c;
    }
    let by_name = swapped.track(Follow::Index).unwrap();
    assert!(by_name.swaps.iter().any(|s| s.slot == 0 && s.frame == 2), "swap not reported: {:?}", by_name.swaps);
    let by_overlap = swapped.track(Follow::Overlap).unwrap();
    let p = by_overlap.points[0][2];
    assert!(p.overlap > 0.5, "followed orbital overlaps {}", p.overlap);
    assert_ne!(p.index, by_name.points[0][2].index);
}

#[test]
fn the_skeleton_follows_theta_and_the_charge_moves_at_minus_90() {
    let scan = psb3();
    for frame in &scan.frames {
        let m = scan.geometry_at(frame.at);
        for (a, b) in m.atoms.iter().zip(&frame.molecule.atoms) {
            assert!((a.position - b.position).length() < 1e-9, "key frame {}° not reproduced", frame.at);
        }
    }
    let m = scan.geometry_at(-97.5);
    assert!((scan.coordinate.measure(&m).unwrap() - -97.5).abs() < 1e-6);
    // Naka et al.'s picture at −90°: HOMO on the C=N side, LUMO on the allyl side. Partition ψ² by
    // nearest atom on the common grid.
    let tracks = scan.track(Follow::Index).unwrap();
    let grid = scan.common_grid(orbcloud::scene::framing::ORBITAL_MARGIN, 48);
    let f = scan.frames.iter().position(|f| f.at == -90.0).unwrap();
    let atoms = &scan.frames[f].molecule.atoms;
    let moving: Vec<bool> = (0..atoms.len()).map(|i| scan.moving.contains(&i)).collect();
    let spec = grid;
    let fraction_moving = |slot: usize| {
        let v = scan.key_values(&tracks, slot, f, &grid);
        let (mut on, mut all) = (0.0, 0.0);
        let [nx, ny, nz] = grid.dims;
        for i in 0..nx {
            for j in 0..ny {
                for k in 0..nz {
                    let p = spec.point(i, j, k);
                    let w = v[(i * ny + j) * nz + k] as f64;
                    let nearest = (0..atoms.len())
                        .min_by(|&a, &b| {
                            (atoms[a].position - p)
                                .length_squared()
                                .total_cmp(&(atoms[b].position - p).length_squared())
                        })
                        .unwrap();
                    all += w * w;
                    if moving[nearest] {
                        on += w * w;
                    }
                }
            }
        }
        on / all
    };
    let (homo, lumo) = (fraction_moving(0), fraction_moving(1));
    eprintln!(
        "at -90°: HOMO {:.1}% on the C=N side, LUMO {:.1}% on the allyl side",
        homo * 100.0,
        (1.0 - lumo) * 100.0
    );
    assert!(homo > 0.8, "HOMO on the C=N side: {homo}");
    assert!(lumo < 0.2, "LUMO on the C=N side: {lumo}");
}

/// Relative L2 error of interpolating frame `held` from its neighbours, and of showing the
/// nearer neighbour instead.
fn held_out_error(scan: &Scan, held: usize, slot: usize, points: usize) -> (f64, f64) {
    let mut frames = scan.frames.clone();
    let truth_frame = frames.remove(held);
    let without = Scan::new(scan.title.clone(), scan.coordinate, scan.orbitals.clone(), frames).unwrap();
    let tracks: Tracks = without.track(Follow::Index).unwrap();
    let grid = scan.common_grid(orbcloud::scene::framing::ORBITAL_MARGIN, points);
    let interpolated = without.interpolated_values(&tracks, slot, truth_frame.at, &grid);
    let full = scan.track(Follow::Index).unwrap();
    let mut truth = scan.key_values(&full, slot, held, &grid);
    // The truth's sign as the held-out sequence would align it.
    let dot: f64 = truth.iter().zip(&interpolated).map(|(&a, &b)| a as f64 * b as f64).sum();
    if dot < 0.0 {
        truth.iter_mut().for_each(|x| *x = -*x);
    }
    let diff: Vec<f32> = truth.iter().zip(&interpolated).map(|(a, b)| a - b).collect();
    let nearest = without.nearest_frame(truth_frame.at);
    let mut key = without.key_values(&tracks, slot, nearest, &grid);
    let dot: f64 = truth.iter().zip(&key).map(|(&a, &b)| a as f64 * b as f64).sum();
    if dot < 0.0 {
        key.iter_mut().for_each(|x| *x = -*x);
    }
    let key_diff: Vec<f32> = truth.iter().zip(&key).map(|(a, b)| a - b).collect();
    (norm(&diff) / norm(&truth), norm(&key_diff) / norm(&truth))
}

#[test]
fn interpolating_a_held_out_angle_comes_close_to_the_true_orbital() {
    let scan = psb3();
    let held = scan.frames.iter().position(|f| f.at == -90.0).unwrap();
    for slot in 0..2 {
        let (err, nearest) = held_out_error(&scan, held, slot, 48);
        eprintln!(
            "{} at -90° from -95°/-85°: interpolation error {:.2}% (nearest key frame {:.2}%)",
            scan.orbitals[slot],
            err * 100.0,
            nearest * 100.0
        );
        assert!(err < 0.08, "{}: relative L2 error {err}", scan.orbitals[slot]);
        assert!(err < 0.6 * nearest, "interpolation ({err}) should beat the nearest key ({nearest})");
    }
}

fn small_scene(ctx: &orbcloud::gpu::GpuContext) -> ScanScene {
    let options = KeyOptions { points: 40, ..KeyOptions::default() };
    ScanScene::build(ctx, psb3(), &options, &mut |_, _| true).unwrap()
}

fn settings() -> RenderSettings {
    let mut s = RenderSettings::default();
    s.volume.k1 = 0.6;
    s.volume.slices = 96;
    s
}

#[test]
fn three_pass_stays_close_to_exact_and_equals_it_at_key_angles() {
    let ctx = common::lavapipe();
    let scene = small_scene(&ctx);
    let camera = scene.camera();
    let size = [160, 120];
    let s = settings();
    let render = |value: f64, mode| scene.render(&ctx, &[0, 1], value, mode, &camera, &s, size).unwrap();
    // At a key angle k = 0: both reduce to that frame's volume.
    let (mean, max) =
        common::mean_max_difference(&render(-90.0, Interpolation::Exact), &render(-90.0, Interpolation::ThreePass));
    // Only the rounding of two half-float blends instead of one separates them.
    assert!(mean < 1.0 && max <= 4, "at a key angle three-pass differs from exact: mean {mean}, max {max}");
    // Between: Naka et al.'s approximation; report and bound its error.
    let mut worst: f64 = 0.0;
    for value in [-97.5, -87.5, -45.0] {
        let exact = render(value, Interpolation::Exact);
        let three = render(value, Interpolation::ThreePass);
        let (mean, max) = common::mean_max_difference(&exact, &three);
        eprintln!("θ = {value}°: three-pass vs exact: mean {mean:.2}/255, max {max}/255");
        worst = worst.max(mean);
        // Both must differ from the nearer key frame's picture: they interpolate.
        let key = render(scene.scan.frames[scene.scan.nearest_frame(value)].at, Interpolation::Exact);
        assert!(common::mean_max_difference(&exact, &key).0 > 0.02, "θ = {value}: exact shows only a key frame");
    }
    assert!(worst < 2.0, "three-pass strays from exact by {worst}/255 on average");
}

#[test]
fn the_gpu_mix_matches_the_cpu_interpolated_grid() {
    let ctx = common::lavapipe();
    let scene = small_scene(&ctx);
    let s = settings();
    let camera = scene.camera();
    let size = [128, 96];
    let value = -97.5;
    for slot in 0..2 {
        let mixed = scene.render(&ctx, &[slot], value, Interpolation::Exact, &camera, &s, size).unwrap();
        // The CPU's interpolated volume, uploaded alone, on the same box and scale.
        let grid: VolumeGrid = scene.interpolated_grid(slot, value);
        let mut volume = VolumeTexture::upload_as(&ctx, &grid, wgpu::TextureFormat::R32Float).unwrap();
        let key = scene.key_volume(slot, 0);
        volume.max_abs = key.max_abs;
        volume.max_grad = key.max_grad;
        volume.grid_box = key.grid_box;
        let mut renderer = Renderer::new(&ctx);
        let layer = renderer.main();
        layer.set_molecule(&ctx, &scene.scan.geometry_at(value), s.atoms);
        layer.set_volume_texture(&ctx, volume);
        let target = OffscreenTarget::new(&ctx.device, size);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        renderer.render(&ctx, &mut encoder, &target.color_view, &FrameInput::single(&camera, &s, size));
        ctx.queue.submit([encoder.finish()]);
        let reference = target.read_rgba(&ctx.device, &ctx.queue).unwrap();
        let (mean, max) = common::mean_max_difference(&mixed, &reference);
        eprintln!("slot {slot}: GPU mix vs CPU interpolation: mean {mean:.3}/255, max {max}/255");
        assert!(mean < 0.3 && max <= 6, "slot {slot}: mean {mean}, max {max}");
    }
}

#[test]
fn golden_psb3_at_minus_90() {
    let ctx = common::lavapipe();
    let scene = small_scene(&ctx);
    let camera = scene.camera();
    let img = scene.render(&ctx, &[0, 1], -90.0, Interpolation::Exact, &camera, &settings(), [200, 150]).unwrap();
    common::assert_golden("scan_psb3_m90", &img);
}

// ---- manifests -------------------------------------------------------------------------

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn copy_frames(dir: &Path, names: &[&str]) {
    for n in names {
        std::fs::copy(assets().join(n), dir.join(n)).unwrap();
    }
}

fn load_err(path: &Path) -> String {
    match load_scan(path) {
        Ok(_) => panic!("{} should not load", path.display()),
        Err(e) => e.to_string(),
    }
}

/// A manifest of the −180° PSB3 frame and `file` at `angle`.
fn two_frames(dihedral: &str, angle: i32, file: &str) -> String {
    format!(
        "dihedral = {dihedral}\n[[frame]]\nangle = -180\nfile = \"psb3_m180.molden.gz\"\n[[frame]]\nangle = {angle}\nfile = \"{file}\"\n"
    )
}

/// Writes a manifest into `dir` and returns the error loading it gives.
fn manifest_err(dir: &Path, name: &str, text: &str) -> String {
    load_err(&write(dir, name, text))
}

#[test]
fn manifest_errors_name_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    copy_frames(dir.path(), &["psb3_m180.molden.gz", "psb3_m150.molden.gz"]);
    let water = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions");
    let water = std::fs::read_dir(&water)
        .unwrap()
        .filter_map(std::result::Result::ok)
        .map(|e| e.path())
        .find(|p| p.to_string_lossy().contains("h2o") && p.to_string_lossy().ends_with(".molden"))
        .expect("a water Molden fixture");
    std::fs::copy(&water, dir.path().join("water.molden")).unwrap();

    let e = manifest_err(
        dir.path(),
        "dup.scan.toml",
        "dihedral = [2, 3, 4, 5]\n[[frame]]\nangle = -180\nfile = \"psb3_m180.molden.gz\"\n\n[[frame]]\nangle = -180.0\nfile = \"psb3_m150.molden.gz\"\n",
    );
    assert!(e.contains("dup.scan.toml:6") && e.contains("different from the frame on line 2"), "{e}");

    let e = manifest_err(dir.path(), "atoms.scan.toml", &two_frames("[2, 3, 4, 5]", -90, "water.molden"));
    assert!(
        e.contains("atoms.scan.toml:5") && e.contains("water.molden") && e.contains("the atoms of the first frame"),
        "{e}"
    );

    let e = manifest_err(dir.path(), "bad.scan.toml", "dihedral = [2, 3, 4]\n");
    assert!(e.contains("bad.scan.toml:1"), "{e}");

    let e = manifest_err(dir.path(), "ring.scan.toml", &two_frames("[2, 3, 40, 5]", -150, "psb3_m150.molden.gz"));
    assert!(e.contains("ring.scan.toml:1") && e.contains("atom 40"), "{e}");

    let e = manifest_err(
        dir.path(),
        "orb.scan.toml",
        &format!("orbitals = [\"lumo+30\"]\n{}", two_frames("[2, 3, 4, 5]", -150, "psb3_m150.molden.gz")),
    );
    assert!(e.contains("lumo+30"), "{e}");

    // A frame file that is missing or broken: the manifest's line, then the file's own error.
    let e = manifest_err(dir.path(), "gone.scan.toml", &two_frames("[2, 3, 4, 5]", -150, "nope.molden"));
    assert!(e.contains("gone.scan.toml:5") && e.contains("nope.molden"), "{e}");
    write(dir.path(), "broken.molden", "[Molden Format]\n[Atoms] AU\nC 1 6 0.0 zero 0.0\n");
    let e = manifest_err(dir.path(), "broken.scan.toml", &two_frames("[2, 3, 4, 5]", -150, "broken.molden"));
    assert!(e.contains("broken.scan.toml:5") && e.contains("broken.molden:3"), "{e}");
}

#[test]
fn cube_series_must_share_one_grid() {
    let dir = tempfile::tempdir().unwrap();
    let scan = psb3();
    let tracks = scan.track(Follow::Index).unwrap();
    let grid = scan.common_grid(orbcloud::scene::framing::ORBITAL_MARGIN, 16);
    let mut names = Vec::new();
    for (f, frame) in scan.frames.iter().enumerate().take(3) {
        let values = scan.key_values(&tracks, 0, f, &grid);
        let mut world = grid.world_from_grid;
        if f == 2 {
            // A different origin: another grid.
            world.w_axis.x += 0.5;
        }
        let g = VolumeGrid::new("homo", grid.dims, world, values);
        let name = format!("homo_{f}.cube");
        std::fs::write(dir.path().join(&name), cube_write::write("t", "homo", &frame.molecule, &[(&g, 1)])).unwrap();
        names.push((frame.at, name));
    }
    let manifest = |n: usize| {
        let mut t = "dihedral = [2, 3, 4, 5]\norbitals = [\"homo\"]\n".to_string();
        for (a, name) in names.iter().take(n) {
            t += &format!("\n[[frame]]\nangle = {a}\ncubes = [\"{name}\"]\n");
        }
        t
    };
    let ok = write(dir.path(), "ok.scan.toml", &manifest(2));
    let loaded = load_scan(&ok).unwrap();
    // Cube series align by the grid overlap.
    let t = loaded.scan.track(Follow::Index).unwrap();
    assert!(t.points[0][1].overlap > 0.5);
    let bad = write(dir.path(), "grids.scan.toml", &manifest(3));
    let e = load_err(&bad);
    assert!(e.contains("grids.scan.toml:12") && e.contains("the grid of homo_0.cube"), "{e}");
}

#[test]
fn init_measures_the_most_changing_dihedral_and_sorts() {
    let dir = tempfile::tempdir().unwrap();
    let names = ["psb3_000.molden.gz", "psb3_m180.molden.gz", "psb3_m090.molden.gz", "psb3_m120.molden.gz"];
    copy_frames(dir.path(), &names);
    let made = init(dir.path(), None).unwrap();
    assert_eq!(made.coordinate, Coordinate::Dihedral([1, 2, 3, 4]), "C2-C3-C4-C5");
    let angles: Vec<f64> = made.frames.iter().map(|f| f.1).collect();
    for (a, want) in angles.iter().zip([-180.0, -120.0, -90.0, 0.0]) {
        assert!((a - want).abs() < 1e-3, "{angles:?}");
    }
    std::fs::write(&made.path, &made.text).unwrap();
    let loaded = load_scan(&made.path).unwrap();
    assert_eq!(loaded.scan.frames.len(), 4);
    // Files of another molecule are refused by name.
    let water = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions");
    let w = std::fs::read_dir(&water)
        .unwrap()
        .filter_map(std::result::Result::ok)
        .map(|e| e.path())
        .find(|p| p.to_string_lossy().ends_with(".molden"))
        .unwrap();
    std::fs::copy(&w, dir.path().join("zz_other.molden")).unwrap();
    let e = init(dir.path(), None).unwrap_err().to_string();
    assert!(e.contains("zz_other.molden"), "{e}");
}

#[test]
fn the_bundled_scan_reads_from_memory() {
    // The viewer needs no files beside it.
    let s = demo::scan().unwrap();
    assert_eq!(s.scan.frames.len(), 15);
    assert_eq!(s.scan.range(), (-180.0, 0.0));
}

#[test]
fn a_scan_job_fchk_alone_is_explained() {
    // One fchk with the geometries of a scan but orbitals for the last point only.
    let dir = tempfile::tempdir().unwrap();
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions/h2o_cart_631gs.fchk");
    let mut text = std::fs::read_to_string(src).unwrap();
    let frames: Vec<f64> = (0..18).map(|i| i as f64 * 0.1).collect();
    text += &format!("{:<43}R   N={:>12}\n", "Opt point       1 Geometries", frames.len());
    for row in frames.chunks(5) {
        text += &row.iter().map(|x| format!("{x:>16.8E}")).collect::<String>();
        text += "\n";
    }
    std::fs::write(dir.path().join("scan.fchk"), text).unwrap();
    let e = init(dir.path(), None).unwrap_err().to_string();
    assert!(
        e.contains("scan.fchk")
            && e.contains("3 geometries in one file")
            && e.contains("one Molden or fchk file per angle"),
        "{e}"
    );
}

#[test]
fn key_volumes_respect_the_budget_and_can_be_cancelled() {
    let ctx = common::lavapipe();
    let options = KeyOptions { points: 32, budget: Some(1 << 20), ..KeyOptions::default() };
    let e = ScanScene::build(&ctx, psb3(), &options, &mut |_, _| true).err().expect("1 MiB cannot hold 30 volumes");
    let msg = e.to_string();
    assert!(msg.contains("30 key volumes") && msg.contains("points along the longest side fits"), "{msg}");
    let orbcloud::layers::key_volumes::ScanSceneError::OverBudget { fits, .. } = e else { panic!("{e}") };
    // The grid offered does fit.
    let options = KeyOptions { points: fits, budget: Some(1 << 20), ..KeyOptions::default() };
    let scene = ScanScene::build(&ctx, psb3(), &options, &mut |_, _| true).expect("the offered grid fits");
    assert!(scene.bytes <= 1 << 20);
    let options = KeyOptions { points: 16, ..KeyOptions::default() };
    let mut calls = 0;
    let e = ScanScene::build(&ctx, psb3(), &options, &mut |done, total| {
        calls += 1;
        assert_eq!(total, 30);
        done < 3
    })
    .err()
    .expect("cancelled");
    assert!(matches!(e, orbcloud::layers::key_volumes::ScanSceneError::Cancelled), "{e}");
    assert_eq!(calls, 3, "stops at the first refusal");
}

#[test]
fn each_view_may_read_its_own_files() {
    // The same orbital from two files side by side (here the same files twice, so both views
    // must track exactly as one file does).
    let dir = tempfile::tempdir().unwrap();
    let names = ["psb3_m180.molden.gz", "psb3_m150.molden.gz", "psb3_m120.molden.gz"];
    copy_frames(dir.path(), &names);
    let mut text =
        "dihedral = [2, 3, 4, 5]\norbitals = [\"homo\", \"homo\"]\ncaptions = [\"RHF\", \"RHF again\"]\n".to_string();
    for (n, a) in names.iter().zip([-180, -150, -120]) {
        text += &format!("\n[[frame]]\nangle = {a}\nfiles = [\"{n}\", \"{n}\"]\n");
    }
    let two = load_scan(&write(dir.path(), "two.scan.toml", &text)).unwrap();
    assert_eq!(two.scan.captions, ["RHF", "RHF again"]);
    let t2 = two.scan.track(Follow::Index).unwrap();
    let one = psb3().track(Follow::Index).unwrap();
    for slot in 0..2 {
        for f in 0..3 {
            assert_eq!(t2.points[slot][f], one.points[0][f], "slot {slot} frame {f}");
        }
    }
    let bad = text.replacen(
        "files = [\"psb3_m150.molden.gz\", \"psb3_m150.molden.gz\"]",
        "files = [\"psb3_m150.molden.gz\"]",
        1,
    );
    let e = load_err(&write(dir.path(), "bad.scan.toml", &bad));
    assert!(e.contains("bad.scan.toml:9") && e.contains("one file per orbital (2)"), "{e}");
}

#[test]
fn per_point_fchk_files_with_optimisation_histories_make_a_scan() {
    // scripts/make_scan_fchk_fixtures.py: three PSB3 frames as fchk files that also hold an
    // optimisation history, as each point of a relaxed scan does.
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/scan_fchk");
    let dir = tempfile::tempdir().unwrap();
    for e in std::fs::read_dir(&src).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, dir.path().join(p.file_name().unwrap())).unwrap();
    }
    let one = dir.path().join("psb3_m090.fchk.gz");
    let text = orbcloud::formats::read_text(&one).unwrap();
    let geometries = orbcloud::formats::fchk::geometries("psb3_m090.fchk.gz", &text).unwrap();
    assert_eq!(geometries.len(), 3, "the current geometry and two optimisation steps");
    let made = init(dir.path(), None).unwrap();
    assert_eq!(made.coordinate, Coordinate::Dihedral([1, 2, 3, 4]));
    let angles: Vec<f64> = made.frames.iter().map(|f| f.1).collect();
    for (a, want) in angles.iter().zip([-120.0, -90.0, -60.0]) {
        assert!((a - want).abs() < 1e-3, "the current geometry is measured, not a step: {angles:?}");
    }
    std::fs::write(&made.path, &made.text).unwrap();
    let fchk = load_scan(&made.path).unwrap().scan;
    let tracks = fchk.track(Follow::Index).unwrap();
    // The same orbitals as the bundled Molden frames at these angles.
    let molden = psb3();
    let molden_tracks = molden.track(Follow::Index).unwrap();
    let grid = molden.common_grid(orbcloud::scene::framing::ORBITAL_MARGIN, 24);
    for (f, angle) in [-120.0, -90.0, -60.0].into_iter().enumerate() {
        let m = molden.frames.iter().position(|fr| fr.at == angle).unwrap();
        for slot in 0..2 {
            let (e1, e2) = (tracks.points[slot][f].energy.unwrap(), molden_tracks.points[slot][m].energy.unwrap());
            assert!((e1 - e2).abs() < 1e-6, "{angle}° slot {slot}: {e1} vs {e2}");
            let a = fchk.key_values(&tracks, slot, f, &grid);
            let b = molden.key_values(&molden_tracks, slot, m, &grid);
            let dot: f64 = a.iter().zip(&b).map(|(&x, &y)| x as f64 * y as f64).sum();
            let s = dot.signum() as f32;
            let diff: Vec<f32> = a.iter().zip(&b).map(|(x, y)| x - s * y).collect();
            assert!(norm(&diff) < 1e-4 * norm(&b), "{angle}° slot {slot}: {}", norm(&diff) / norm(&b));
        }
    }
}

#[test]
fn playing_bounces_between_the_ends_or_stops_and_keys_step_between_frames() {
    let scan = demo::scan().unwrap().scan;
    let (lo, hi) = scan.range();
    let mut state = orbcloud::scene::ScanState::opening(&scan, None);
    assert!(scan.values().contains(&state.value), "opens on a key frame");
    state.set_value(&scan, f64::NAN);
    assert!(state.value.is_finite());
    state.set_value(&scan, hi + 100.0);
    assert_eq!(state.value, hi);
    state.playing = true;
    state.advance(&scan, 1.0);
    assert!(state.backwards && state.value == hi && state.playing, "turns at the end");
    state.advance(&scan, 0.1);
    assert!(state.value < hi, "and comes back");
    state.looping = false;
    state.set_value(&scan, lo + 1e-3);
    state.advance(&scan, 10.0);
    assert!(!state.playing && state.value == lo, "stops at the end");
    state.step_key(&scan, 1);
    assert_eq!(state.value, scan.values()[1]);
}
