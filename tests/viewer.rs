//! The viewer in egui_kittest on lavapipe: starts on the demo, reacts to controls and the mouse,
//! and keeps what it shows when a file fails to load.

mod common;
#[path = "common/viewer.rs"]
mod viewer_support;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use orbcloud::app::{OrbApp, wgpu_setup};
use orbcloud::scene::{Shape, SliceMode, TransferKind};
use viewer_support::{click_at, harness, hover, wait_loaded};

/// A primary-button drag `dx` points to the right from `from`, in five moves; returns the
/// views' (size on screen, size drawn) in the middle of the drag.
fn drag_right(h: &mut Harness<'static, OrbApp>, from: egui::Pos2, dx: f32) -> Vec<([u32; 2], [u32; 2])> {
    h.hover_at(from);
    h.drag_at(from);
    h.run_steps(1);
    let mut during = Vec::new();
    for i in 1..=5 {
        h.hover_at(from + egui::vec2(dx * i as f32 / 5.0, 0.0));
        h.run_steps(1);
        if i == 3 {
            during = h.state().view_sizes();
        }
    }
    h.drop_at(from + egui::vec2(dx, 0.0));
    h.run_steps(1);
    during
}

/// Lavapipe is a CPU adapter: while a drag runs every view draws fewer pixels (together at most
/// `CPU_INTERACTIVE_PIXELS`); the first frame after it draws every pixel again.
fn assert_drag_detail(h: &mut Harness<'static, OrbApp>, during: &[([u32; 2], [u32; 2])], views: usize) {
    use orbcloud::app::detail::CPU_INTERACTIVE_PIXELS;
    assert_eq!(during.len(), views, "{during:?}");
    let drawn: u32 = during.iter().map(|(_, d)| d[0] * d[1]).sum();
    assert!(drawn <= CPU_INTERACTIVE_PIXELS, "{drawn} pixels drawn during the drag: {during:?}");
    assert!(during.iter().all(|(s, d)| d[0] < s[0] && d[1] < s[1]), "{during:?}");
    h.run_steps(1);
    let after = h.state().view_sizes();
    assert_eq!(after.len(), views);
    assert!(after.iter().all(|(s, d)| s == d), "full size after the drag: {after:?}");
}

#[test]
fn starts_on_the_demo_and_changes_controls() {
    let mut h = harness();
    h.run_steps(2);
    let app = h.state();
    assert_eq!(app.doc().volumes.len(), 1, "the demo cube has one orbital");
    assert_eq!(app.doc().molecule.atoms.len(), 4, "formaldehyde");
    assert_eq!(app.selected_quantity().unwrap().cloud.mode, SliceMode::ViewAligned);

    h.get_by_label("axis stacks").click();
    h.run_steps(2);
    assert_eq!(h.state().selected_quantity().unwrap().cloud.mode, SliceMode::AxisAligned);

    // Below the isosurfaces: scrolled into view first, as a user would.
    h.get_by_label("Transfer function").scroll_to_me();
    h.run_steps(20);
    h.get_by_label("Transfer function").click();
    h.run_steps(2);
    h.get_by_label("shapes").click();
    h.run_steps(2);
    assert_eq!(h.state().selected_quantity().unwrap().cloud.transfer.kind, TransferKind::Shaped);
    // Jang and Varetto's pairing: the left half on ψ > 0, the right half on ψ < 0.
    h.get_by_label("nested cores").click();
    h.run_steps(2);
    let t = h.state().selected_quantity().unwrap().cloud.transfer;
    assert_eq!((t.positive.shape, t.negative.shape), (Shape::LeftHalfGaussian, Shape::RightHalfGaussian));

    h.get_by_label("show cloud").click();
    h.run_steps(2);
    assert!(!h.state().selected_quantity().unwrap().cloud.visible);
}

#[test]
fn dragging_the_view_orbits_the_camera() {
    let mut h = harness();
    h.run_steps(2);
    let yaw = h.state().view.camera.yaw;
    let during = drag_right(&mut h, egui::pos2(650.0, 350.0), 100.0);
    let moved = h.state().view.camera.yaw;
    assert!((moved - yaw).abs() > 0.3, "yaw {yaw} -> {moved}");
    assert_drag_detail(&mut h, &during, 1);
}

#[test]
fn a_bad_file_reports_an_error_and_keeps_the_open_document() {
    let mut h = harness();
    h.run_steps(1);
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("broken.cube");
    std::fs::write(&bad, "title\ncomment\n    2 0.0 0.0 0.0\n    3 0.5 0.0 0.0\n").unwrap();
    let ctx = h.ctx.clone();
    h.state_mut().open(bad, &ctx);
    for _ in 0..200 {
        h.run_steps(1);
        if !h.state().is_loading() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    h.run_steps(2);
    let app = h.state();
    let err = app.error.as_deref().expect("an error is shown");
    assert!(err.contains("broken.cube") && err.contains(":4"), "{err}");
    assert_eq!(app.doc().molecule.atoms.len(), 4, "the demo stays open");
    h.get_by_label("Dismiss").click();
    h.run_steps(2);
    assert!(h.state().error.is_none());
}

#[test]
fn a_molden_file_opens_on_its_homo_and_the_browser_switches_orbitals() {
    use orbcloud::model::orbitals::Quantity;
    use orbcloud::scene::Source::Wavefunction;
    let Some(dir) = common::refdata("viewer::a_molden_file_opens_on_its_homo_and_the_browser_switches_orbitals") else {
        return;
    };
    let path = dir.join("nh3_orca.molden");
    assert!(path.exists(), "reference corpus missing: {}", path.display());
    let mut h = Harness::builder()
        .with_size([1200.0, 800.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(|cc| OrbApp::new(cc, vec![path]));
    for _ in 0..300 {
        h.run_steps(1);
        if !h.state().is_loading() && h.state().doc().wavefunction.is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    h.run_steps(2);
    let app = h.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    let wf = app.doc().wavefunction.as_ref().expect("the Molden file loaded");
    let homo = wf.homo(orbcloud::model::Spin::Alpha).unwrap();
    let shown = |app: &OrbApp| app.selected_quantity().map(|q| q.source);
    assert_eq!(shown(app), Some(Wavefunction(Quantity::Orbital(homo))), "opens on the HOMO");
    // The status line names a restricted file's orbital without a spin.
    h.get_by_label_contains("occupation 2.00");
    assert!(h.query_by_label_contains("Alpha").is_none() && h.query_by_label_contains(" α ").is_none());
    let lumo = wf.lumo(orbcloud::model::Spin::Alpha).unwrap();
    h.get_by_label_contains(&format!("MO {} ", lumo + 1)).click();
    h.run_steps(2);
    assert_eq!(shown(h.state()), Some(Wavefunction(Quantity::Orbital(lumo))));
    assert_eq!(h.state().active_object().unwrap().state.quantities.len(), 1, "a click switches, it does not add");
    h.get_by_label("per sample (direct)").click();
    h.run_steps(2);
    assert!(h.state().active_object().unwrap().state.evaluation.direct);
    h.get_by_label("total density").click();
    h.run_steps(2);
    assert_eq!(shown(h.state()), Some(Wavefunction(Quantity::Density)));
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
}

/// Steps the app until a scan that satisfies `ready` is open (key volumes are made on a
/// background thread), failing on an error or after five minutes.
fn wait_for_scan(h: &mut Harness<'static, OrbApp>, ready: impl Fn(&orbcloud::app::scan::OpenScan) -> bool) {
    let start = std::time::Instant::now();
    while !h.state().scan().is_some_and(|s| ready(&s)) {
        assert!(h.state().error.is_none(), "scan failed: {:?}", h.state().error);
        assert!(start.elapsed().as_secs() < 300, "no scan after five minutes");
        std::thread::sleep(std::time::Duration::from_millis(50));
        h.run_steps(1);
    }
    h.run_steps(2);
}

/// The viewer as `cargo run` opens it: the bundled scan, once its key volumes are made (on a
/// background thread).
fn scan_demo() -> Harness<'static, OrbApp> {
    let mut h = Harness::builder()
        .with_size([1100.0, 720.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(|cc| OrbApp::new(cc, Vec::new()));
    wait_for_scan(&mut h, |_| true);
    h
}

/// Opens `path` and steps the app until it reports an error (failing after a minute).
fn open_expecting_error(h: &mut Harness<'static, OrbApp>, path: std::path::PathBuf) -> String {
    let ctx = h.ctx.clone();
    h.state_mut().open(path.clone(), &ctx);
    let start = std::time::Instant::now();
    while h.state().error.is_none() {
        assert!(start.elapsed().as_secs() < 60, "no error opening {}", path.display());
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
    h.state().error.clone().unwrap()
}

#[test]
fn the_scan_demo_opens_side_by_side_and_a_drag_twists_both_views() {
    let mut h = scan_demo();
    let scan = h.state().scan().unwrap();
    assert_eq!(scan.value, -90.0, "opens at the twisted geometry");
    assert_eq!(scan.shown().len(), 2, "HOMO and LUMO side by side");
    assert_eq!(h.state().view.panes.count, 2, "each in a pane of its own");
    assert!(scan.shown().iter().all(|s| s.map(|(t, _)| t) == Some(-90.0)), "{:?}", scan.shown());
    h.get_by_label("Play");
    assert!(h.query_all_by_label("dihedral").count() >= 1, "the θ slider");

    // Naka et al.: a horizontal drag across the (left) view turns the bond.
    let during = drag_right(&mut h, egui::pos2(500.0, 260.0), 90.0);
    assert_drag_detail(&mut h, &during, 2);
    h.run_steps(1);
    let scan = h.state().scan().unwrap();
    let value = scan.value;
    assert!(value > -85.0, "θ after dragging right: {value}");
    for (slot, shown) in scan.shown().iter().enumerate() {
        assert_eq!(shown.map(|(t, _)| t), Some(value), "view {slot} does not show the new θ");
    }

    // The interpolation mode switches both views.
    h.get_by_label("three-pass").click();
    h.run_steps(2);
    let scan = h.state().scan().unwrap();
    assert!(scan.shown().iter().all(|s| s.map(|(_, m)| m) == Some(orbcloud::scene::Interpolation::ThreePass)));

    // Following orbitals by character makes the key volumes anew and keeps θ and the mode.
    h.get_by_label("follow character").click();
    h.run_steps(1);
    wait_for_scan(&mut h, |s| s.scene.tracks.follow == orbcloud::model::scan::Follow::Overlap);
    let scan = h.state().scan().unwrap();
    assert_eq!(scan.value, value);
    assert_eq!(scan.mode, orbcloud::scene::Interpolation::ThreePass);

    // A manifest with one frame says where it is wrong, and the open scan stays.
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.scan.toml");
    std::fs::write(&bad, "dihedral = [2, 3, 4, 5]\n[[frame]]\nangle = 0\nfile = \"a.molden\"\n").unwrap();
    let err = open_expecting_error(&mut h, bad);
    assert!(err.contains("bad.scan.toml:"), "{err}");
    assert_eq!(h.state().scan().map(|s| s.value), Some(value), "the scan stays open");
}

/// A scan is an object: its views are its quantities, one per pane, and its clipping plane is
/// the object's, cutting its atoms' layer and every view along one plane that stays put while
/// the coordinate moves.
#[test]
fn a_scan_is_an_object_whose_views_are_panes_cut_by_its_clipping_plane() {
    use orbcloud::scene::Source;
    let mut h = scan_demo();
    let app = h.state();
    assert_eq!(app.objects.len(), 1);
    let views: Vec<_> = app.objects[0].state.quantities.iter().map(|q| (q.source, q.pane)).collect();
    assert_eq!(views, [(Source::Scan(0), Some(0)), (Source::Scan(1), Some(1))]);
    let coloured = |h: &Harness<'static, OrbApp>| {
        let picture = h.state().pane_picture(0).expect("pane 1 drawn");
        picture.pixels().filter(|p| (p[0] as i32 - p[2] as i32).abs() > 60).count()
    };
    let whole = coloured(&h);
    assert!(whole > 2000, "the HOMO's red and blue: {whole} pixels");
    {
        let clip = &mut h.state_mut().objects[0].state.clip;
        clip.enabled = true;
        clip.normal = [0.0, 0.0, 1.0];
        clip.offset = 0.0;
    }
    h.run_steps(3);
    let cut = coloured(&h);
    eprintln!("coloured pixels of the HOMO pane: {whole} whole, {cut} cut");
    assert!(cut < whole * 3 / 4, "half the sweep's box cut away: {cut} of {whole} pixels");
    let planes = h.state().clip_planes(0);
    assert_eq!(planes.len(), 3, "the atoms and two views");
    assert!(planes.iter().all(|p| p.is_some() && *p == planes[0]), "{planes:?}");
    let value = h.state().scan().unwrap().value;
    h.state_mut().set_scan_value(value + 20.0);
    h.run_steps(3);
    assert_eq!(h.state().scan().unwrap().shown()[0].map(|s| s.0), Some(value + 20.0));
    assert_eq!(h.state().clip_planes(0), planes, "the plane stays where it was as the value moves");
}

#[test]
fn a_scan_too_large_for_the_gpu_offers_a_coarser_grid() {
    let manifest = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/psb3/psb3.scan.toml");
    let mut h = Harness::builder()
        .with_size([1100.0, 720.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(|cc| OrbApp::cube_demo(cc));
    h.state_mut().scan_budget = Some(1 << 20);
    let error = open_expecting_error(&mut h, manifest);
    assert!(error.contains("MiB") && error.contains("fits"), "{error}");
    let fits = h.state().scan_retry.as_ref().map(|r| r.1).expect("a grid that fits is offered");
    h.run_steps(2);
    h.get_by_label(&format!("Open with {fits} points")).click();
    h.run_steps(1);
    wait_for_scan(&mut h, |_| true);
    let scan = h.state().scan().unwrap();
    assert!(scan.scene.bytes <= 1 << 20, "{} bytes", scan.scene.bytes);
}

#[test]
fn isosurfaces_follow_the_slider_and_atoms_are_picked_and_measured() {
    let mut h = harness();
    h.run_steps(2);
    h.get_by_label("show ψ = ±value").click();
    wait_loaded(&mut h);
    assert!(h.state().selected_quantity().unwrap().isosurfaces[0].visible);
    let first = h.state().status.clone();
    assert!(first.starts_with("isosurfaces: ") && !first.starts_with("isosurfaces: 0 "), "{first}");
    // Dragging the iso value changes the surfaces.
    let slider = h.get_by_role_and_label(egui::accesskit::Role::Slider, "value (a.u.)").rect();
    let from = slider.left_center() + egui::vec2(slider.width() * 0.3, 0.0);
    h.drag_at(from);
    h.run_steps(1);
    h.hover_at(from + egui::vec2(slider.width() * 0.2, 0.0));
    h.run_steps(1);
    h.drop_at(from + egui::vec2(slider.width() * 0.2, 0.0));
    wait_loaded(&mut h);
    let level = h.state().selected_quantity().unwrap().isosurfaces[0].level;
    assert_ne!(level, orbcloud::scene::IsoLevel::Absolute(0.05), "the slider moved");
    assert_ne!(h.state().status, first, "the surfaces were cut anew: {}", h.state().status);

    // Hide the surfaces and the cloud so the atoms are what the clicks hit.
    h.get_by_label("show ψ = ±value").click();
    h.get_by_label("show cloud").click();
    h.run_steps(2);
    let o = h.state().atom_on_screen(1).expect("the oxygen is on screen");
    click_at(&mut h, o, false);
    assert!(h.state().status.starts_with("atom 2 O"), "{}", h.state().status);
    let c = h.state().atom_on_screen(0).unwrap();
    hover(&mut h, c);
    assert_eq!(h.state().hovered(), Some(orbcloud::gpu::frame::PickId::Atom { object: 0, index: 0 }), "hover");
    click_at(&mut h, c, true);
    let app = h.state();
    assert_eq!(app.measurements.selection, vec![1, 0]);
    assert_eq!(app.measurements.list.len(), 1);
    assert!(app.status.starts_with("O2–C1 1.") && app.status.ends_with(" Å"), "{}", app.status);
    // A click on the background clears the selection and keeps the measurement.
    click_at(&mut h, egui::pos2(985.0, 100.0), false);
    assert!(h.state().measurements.selection.is_empty());
    assert_eq!(h.state().measurements.list.len(), 1);
}

#[test]
fn files_join_the_scene_are_measured_across_and_a_session_reopens_them() {
    use orbcloud::app::Opening;
    let demo = orbcloud::sources::demo::document().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let files: Vec<_> = ["a.cube", "b.cube"].iter().map(|n| dir.path().join(n)).collect();
    // The second a slightly different geometry (one hydrogen 0.01 bohr away): a cube of the
    // same atoms would join the first object as a quantity.
    let mut moved = demo.molecule.clone();
    moved.atoms[3].position.x += 0.01;
    for (f, molecule) in files.iter().zip([&demo.molecule, &moved]) {
        let text = orbcloud::formats::cube_write::write("demo", "copy", molecule, &[(&demo.volumes[0], 1)]);
        std::fs::write(f, &text).unwrap();
    }
    let mut h = harness();
    h.run_steps(1);
    let ctx = h.ctx.clone();
    // The first replaces the demo; the second joins beside it.
    h.state_mut().open_as(files[0].clone(), Opening::Replace, &ctx);
    wait_loaded(&mut h);
    h.state_mut().open(files[1].clone(), &ctx);
    wait_loaded(&mut h);
    let app = h.state();
    assert_eq!(app.objects.len(), 2);
    assert_eq!(app.active, 1, "the new file is the one the panels edit");
    let offset = glam::Vec3::from(app.objects[1].state.placement.offset);
    assert_eq!(app.world().molecule.atoms.len(), 8);
    // Beside the first across the view: every atom of the second right of every atom of the first.
    let xs = |range: std::ops::Range<usize>| -> Vec<f32> { range.map(|a| app.atom_on_screen(a).unwrap().x).collect() };
    let (first, second) = (xs(0..4), xs(4..8));
    assert!(
        second.iter().all(|x| first.iter().all(|f| x > f)),
        "placed beside the first: {first:?} then {second:?}, offset {offset}"
    );

    // Hide the active object's cloud; the other keeps its own.
    h.get_by_label("show cloud").click();
    h.run_steps(2);
    assert!(!h.state().objects[1].state.quantities[0].cloud.visible);
    assert!(h.state().objects[0].state.quantities[0].cloud.visible);
    // An oxygen of each molecule: the distance between them is the placement's offset.
    let (o1, o2) = (h.state().atom_on_screen(1).unwrap(), h.state().atom_on_screen(5).unwrap());
    click_at(&mut h, o1, false);
    assert!(h.state().status.starts_with("atom 2 O"), "{}", h.state().status);
    click_at(&mut h, o2, true);
    let expected = offset.length() as f64 * orbcloud::model::units::ANGSTROM_PER_BOHR;
    assert!(h.state().status.ends_with(&format!("{expected:.3} Å")), "{} (expected {expected:.3})", h.state().status);
    // A second isosurface for object 2.
    h.get_by_label("+ isosurface").click();
    wait_loaded(&mut h);
    assert_eq!(h.state().objects[1].state.quantities[0].isosurfaces.len(), 2);
    assert!(h.state().status.starts_with("isosurfaces: "), "{}", h.state().status);

    // Move object 2 and turn it; save; replace the scene with the demo file; reopen.
    let moved = orbcloud::scene::Placement { offset: [20.0, 1.0, 0.0], rotation_deg: [0.0, 0.0, 45.0] };
    h.state_mut().objects[1].state.placement = moved;
    h.run_steps(1);
    let session = dir.path().join("scene.orbcloud.toml");
    h.state_mut().save_session(&session);
    let saved: Vec<_> = h.state().objects.iter().map(|o| o.state.clone()).collect();
    let camera = h.state().view.camera;
    h.state_mut().open_as(files[0].clone(), Opening::Replace, &ctx);
    wait_loaded(&mut h);
    assert_eq!(h.state().objects.len(), 1);
    h.state_mut().open(session, &ctx);
    wait_loaded(&mut h);
    let app = h.state();
    let reopened: Vec<_> = app.objects.iter().map(|o| o.state.clone()).collect();
    assert_eq!(reopened, saved, "files, representations and placements as saved");
    assert_eq!(app.view.camera, camera);
    assert_eq!(app.world().molecule.atoms.len(), 8);

    // Closing keeps the scene; the next start takes its settings for new files and offers it.
    let last = dir.path().join("config/last.orbcloud.toml");
    h.state_mut().view.background = [0.9, 0.9, 0.9];
    h.state_mut().objects[1].state.quantities[0].cloud.k1 = 0.55;
    h.state_mut().keep_session_in(last.clone());
    h.state_mut().save_last_session();
    let mut next = harness();
    next.state_mut().keep_session_in(last.clone());
    let app = next.state();
    assert_eq!(app.view.background, [0.9, 0.9, 0.9]);
    assert_eq!(app.defaults.volume.k1, 0.55, "new files start with the last settings");
    assert_eq!(orbcloud::sources::session::read(&last).unwrap().session.objects.len(), 2);
    next.run_steps(2);
    next.get_by_label("Last session").click();
    wait_loaded(&mut next);
    assert_eq!(next.state().objects.len(), 2, "the last session reopened");
}

#[test]
fn a_scan_shows_isosurfaces_at_theta_and_its_measured_dihedral_follows_theta() {
    use orbcloud::model::measure::Measurement;
    let mut h = scan_demo();
    h.get_by_label("show ψ = ±value").click();
    let start = std::time::Instant::now();
    while !h.state().status.starts_with("isosurfaces at dihedral") {
        assert!(start.elapsed().as_secs() < 60, "no isosurfaces: {}", h.state().status);
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
    let status = h.state().status.clone();
    assert!(status.contains("dihedral 2-3-4-5 = -90.0°"), "{status}");
    h.get_by_label("show ψ = ±value").click();
    h.get_by_label("show cloud").click();
    h.run_steps(3);

    // Pick the four atoms of the scanned dihedral in the left view, Shift held after the first.
    let dihedral = h.state().scan().unwrap().scene.scan.coordinate.atoms().to_vec();
    for (n, &atom) in dihedral.iter().enumerate() {
        let app = h.state();
        let p = app.atom_on_screen(atom).expect("on screen");
        click_at(&mut h, p, n > 0);
    }
    // An atom of the moving end may sit in front of the one aimed at; any dihedral about the
    // scanned bond j–k follows θ.
    let app = h.state();
    let m: &Measurement = app.measurements.list.first().expect("a measurement");
    assert_eq!(app.measurements.list.len(), 1, "{}", app.status);
    assert!(m.atoms.len() == 4 && m.atoms[1..3] == dihedral[1..3], "{:?} about {dihedral:?}", m.atoms);
    assert!(app.status.ends_with('°'), "{}", app.status);
    let value_at = |app: &OrbApp| {
        let scan = app.scan().unwrap();
        app.measurements.list[0].value(&scan.scene.scan.geometry_at(scan.value)).unwrap()
    };
    let before = value_at(app);
    // Step θ to the next key angle: the measured dihedral turns by as much.
    let value = app.scan().unwrap().value;
    h.key_press(egui::Key::CloseBracket);
    h.run_steps(2);
    let app = h.state();
    let turned = app.scan().unwrap().value - value;
    assert!(turned > 1.0, "θ moved: {turned}");
    let change = (value_at(app) - before + 540.0).rem_euclid(360.0) - 180.0;
    assert!((change.abs() - turned).abs() < 1.0, "dihedral changed by {change:.2}°, θ by {turned:.2}°");
}

#[test]
fn a_session_keeps_the_scan_where_it_stood_with_its_measurements() {
    use orbcloud::scene::Interpolation;
    let mut h = scan_demo();
    let (lo, hi) = h.state().scan().unwrap().scene.scan.range();
    let atoms = h.state().scan().unwrap().scene.scan.coordinate.atoms().to_vec();
    let value = lo + 0.3 * (hi - lo);
    {
        let app = h.state_mut();
        app.set_scan_value(value);
        let object = app.scan_object_mut().unwrap();
        let scan = object.state.scan.as_mut().unwrap();
        scan.mode = Interpolation::ThreePass;
        scan.looping = false;
        object.state.quantities[0].isosurfaces[0].visible = true;
        app.measurements.list = vec![orbcloud::model::measure::Measurement::new(&atoms).unwrap()];
    }
    h.run_steps(2);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scan.orbcloud.toml");
    h.state_mut().save_session(&path);
    let saved = orbcloud::sources::session::read(&path).unwrap().session;
    let kept = saved.objects.iter().find_map(|o| o.scan.as_ref()).expect("the session keeps the scan");
    assert!(kept.manifest.is_none() && (kept.value - value).abs() < 1e-9, "{kept:?}");

    // Somewhere else, then the session again: the scan comes back as it stood.
    h.state_mut().set_scan_value(hi);
    h.state_mut().clear_scene();
    h.run_steps(2);
    assert!(h.state().scan().is_none() && h.state().measurements.list.is_empty());
    let ctx = h.ctx.clone();
    h.state_mut().open_session(&path, &ctx);
    wait_for_scan(&mut h, |s| (s.value - value).abs() < 1e-9);
    let app = h.state();
    let scan = app.scan().unwrap();
    let state = &scan.object.state;
    let (looping, iso) = (state.scan.as_ref().unwrap().looping, state.quantities[0].isosurfaces[0].visible);
    assert_eq!((scan.mode, looping, iso), (Interpolation::ThreePass, false, true));
    assert_eq!(app.measurements.list.len(), 1, "the measurement on the scan's atoms comes back");
    assert_eq!(app.measurements.list[0].atoms, atoms);
    assert_eq!(app.view.camera, saved.camera, "the session's camera, not a fresh framing");
}

#[test]
fn files_open_without_a_system_dialog_and_a_failed_file_leaves_the_demo() {
    let demo = orbcloud::sources::demo::document().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("copy.cube");
    std::fs::write(
        &file,
        orbcloud::formats::cube_write::write("demo", "copy", &demo.molecule, &[(&demo.volumes[0], 1)]),
    )
    .unwrap();
    let mut h = harness();
    // As on a bare X server: no dialog backend.
    h.state_mut().native_dialogs = false;
    h.get_by_label("Open…").click();
    h.run_steps(2);
    assert!(h.state().browser.is_some(), "the in-window chooser opens");
    h.get_by_role(egui::accesskit::Role::TextInput).click();
    h.run_steps(1);
    h.get_by_role(egui::accesskit::Role::TextInput).type_text(file.to_str().unwrap());
    h.run_steps(1);
    h.key_press(egui::Key::Enter);
    wait_loaded(&mut h);
    assert!(h.state().browser.is_none());
    assert_eq!(h.state().objects.len(), 2, "the file joined the scene");
    let canonical = std::fs::canonicalize(&file).unwrap();
    assert_eq!(h.state().recent.first(), Some(&canonical), "and is the first recent file");
    // The recent list opens it again from the chooser.
    h.get_by_label("Open…").click();
    h.run_steps(2);
    h.get_by_label(&canonical.display().to_string()).click();
    wait_loaded(&mut h);
    assert_eq!(h.state().objects.len(), 3);

    // A file that fails to open, with nothing else open: the demo shows instead of nothing.
    let bad = dir.path().join("broken.molden");
    std::fs::write(&bad, "[Molden Format]\n[Atoms] AU\nC 1 6 0.0 0.0\n").unwrap();
    let mut h = Harness::builder()
        .with_size([1100.0, 720.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(move |cc| OrbApp::new(cc, vec![bad.clone()]));
    let start = std::time::Instant::now();
    while h.state().error.is_none() || h.state().scan().is_none() {
        assert!(start.elapsed().as_secs() < 300, "no error and demo: {:?}", h.state().error);
        std::thread::sleep(std::time::Duration::from_millis(50));
        h.run_steps(1);
    }
    assert!(h.state().error.as_deref().unwrap().contains("broken.molden"));
}

#[test]
fn direct_mode_draws_in_bands_and_the_window_keeps_answering() {
    let benzene = std::path::PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/wavefunctions/benzene_631gs.molden"
    ));
    let mut h = Harness::builder()
        .with_size([1000.0, 700.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(move |cc| OrbApp::cube_demo(cc));
    let ctx = h.ctx.clone();
    h.state_mut().open_as(benzene, orbcloud::app::Opening::Replace, &ctx);
    wait_loaded(&mut h);
    h.state_mut().objects[0].state.quantities[0].cloud.slices = 48;
    h.get_by_label("per sample (direct)").click();
    wait_loaded(&mut h);
    assert!(h.state().objects[0].state.evaluation.direct);
    // 96 basis functions per sample: the frame is drawn band by band, each UI frame short.
    let (mut steps, mut slowest, mut total, mut seen) = (0, 0.0f64, 0.0f64, Vec::new());
    h.run_steps(1);
    // The coarse picture stands in at once while the full one fills in.
    assert!(h.state().frame_progress().is_some() && h.state().previewing(), "a preview while the frame is drawn");
    while let Some(p) = h.state().frame_progress() {
        seen.push(p);
        let t = std::time::Instant::now();
        h.run_steps(1);
        slowest = slowest.max(t.elapsed().as_secs_f64());
        total += t.elapsed().as_secs_f64();
        steps += 1;
        assert!(steps < 3000, "the frame never finished");
        if steps == 3 {
            // An input in the middle of the frame is applied in the next UI frame (and starts
            // the frame anew from the new view).
            let yaw = h.state().view.camera.yaw;
            h.key_press(egui::Key::ArrowLeft);
            h.run_steps(1);
            assert_ne!(h.state().view.camera.yaw, yaw, "the key was applied at once");
        }
    }
    eprintln!("direct mode: {steps} UI frames, slowest {:.0} ms, progress {seen:?}", slowest * 1e3);
    // After the restart at step 3 the picture fills in band by band.
    let after = &seen[4.min(seen.len())..];
    assert!(after.len() >= 2 && after.windows(2).all(|w| w[1] >= w[0]), "the picture fills in: {seen:?}");
    // Relative to the whole picture's time, not a wall-clock figure: a busy machine slows both
    // alike, and a frame drawn whole in one UI frame would take all of it.
    assert!(slowest < 0.25 * total, "a UI frame took {slowest:.2} s of the picture's {total:.2} s");
    assert!(!h.state().previewing(), "the full picture replaced the preview");
}

#[test]
fn a_structure_shows_its_models_and_picks_tell_residues() {
    use orbcloud::app::Opening;
    let mut h = harness();
    h.run_steps(1);
    let ctx = h.ctx.clone();
    let nmr =
        std::path::PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/structures/nmr_excerpt.pdb"));
    h.state_mut().open_as(nmr, Opening::Replace, &ctx);
    wait_loaded(&mut h);
    let first = h.state().objects[0].doc.molecule.atoms[0].position;
    // Playing steps through the three models, a step at most every 120 ms, and wraps around.
    h.state_mut().models.playing = true;
    let mut seen = Vec::new();
    for _ in 0..3 {
        std::thread::sleep(std::time::Duration::from_millis(150));
        h.run_steps(1);
        seen.push(h.state().objects[0].doc.structure.as_ref().unwrap().model);
    }
    assert_eq!(seen, vec![1, 2, 0]);
    h.state_mut().models.playing = false;
    h.state_mut().show_model(2);
    h.run_steps(2);
    let app = h.state();
    let view = app.objects[0].doc.structure.as_ref().unwrap();
    assert_eq!((view.model, view.structure.models.len()), (2, 3));
    assert!(app.objects[0].doc.molecule.atoms[0].position.distance(first) > 1e-3, "model 3's own coordinates");
    // What the file says of an atom: chain, residue, atom name, B-factor, occupancy.
    let about = app.world().annotation(0, 0).expect("residue information");
    assert!(about.starts_with("A ") && about.contains(" 1 N") && about.contains("occupancy 1.00"), "{about}");
}

#[test]
fn the_translucent_demo_opens_two_molecules_in_exact_order_from_the_demos_menu() {
    let mut h = harness();
    h.get_by_label("Demos").click();
    h.run_steps(2);
    h.get_by_label("diene HOMO + SO₂ LUMO (translucent)").click();
    let start = std::time::Instant::now();
    // The orbitals are evaluated in the background; then the frame's fragment counts come back.
    while h.state().fragment_note().is_none() {
        assert!(start.elapsed().as_secs() < 120, "no translucent frame; error: {:?}", h.state().error);
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
    let app = h.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    assert_eq!(app.objects.len(), 2, "butadiene and SO₂");
    let note = app.fragment_note().unwrap();
    assert!(note.contains("exact order"), "{note}");
    for object in &app.objects {
        let sources: Vec<_> = object.state.quantities.iter().map(|q| q.source).collect();
        assert_eq!(sources.len(), 2, "{:?}: its density and its orbital, {sources:?}", object.doc.source);
        for q in &object.state.quantities {
            let iso = q.isosurfaces[0];
            assert!(iso.visible && iso.translucent && !q.cloud.visible, "{:?}", object.doc.source);
        }
    }
    // The translucent controls of the active object's isosurface.
    h.get_by_label("translucent");
}

#[test]
fn a_lost_device_brings_the_scene_back_on_a_new_device_without_reading_files_again() {
    use std::sync::{Arc, Mutex};
    let mut h = harness();
    let slot: orbcloud::app::restart::CarrySlot = Arc::new(Mutex::new(None));
    h.state_mut().restart_into(slot.clone());
    h.state_mut().view.camera.orbit(0.7, 0.2);
    let camera = h.state().view.camera;
    let docs: Vec<_> = h.state().documents().cloned().collect();
    assert_eq!(docs.len(), 1);
    h.state().lose_device("rehearsed in a test");
    h.run_steps(2);
    let carried = slot.lock().unwrap().take().expect("the scene was handed on");
    drop(h);
    let mut next = Harness::builder()
        .with_size([1000.0, 700.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(move |cc| OrbApp::resume(cc, carried));
    next.run_steps(3);
    let app = next.state();
    assert!(app.error.is_none(), "{:?}", app.error);
    let notice = app.notice.clone().unwrap_or_default();
    assert!(notice.contains("back on a new device"), "{notice}");
    let resumed: Vec<_> = app.documents().cloned().collect();
    assert_eq!(resumed.len(), 1);
    assert!(Arc::ptr_eq(&resumed[0], &docs[0]), "the document itself, not read again");
    assert_eq!(app.view.camera, camera);
    // And it draws: the view holds the cube's cloud on the new device.
    next.get_by_label("show cloud");
}

#[test]
fn a_structure_gets_a_molecular_surface_from_the_scene_panel_that_follows_its_selection() {
    use orbcloud::app::Opening;
    use orbcloud::gpu::frame::PickId;
    let mut h = harness();
    h.run_steps(1);
    let ctx = h.ctx.clone();
    let pdb =
        std::path::PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/structures/4e43_excerpt.pdb"));
    h.state_mut().open_as(pdb, Opening::Replace, &ctx);
    wait_loaded(&mut h);
    h.get_by_role_and_label(egui::accesskit::Role::ComboBox, "surface").click();
    h.run_steps(2);
    h.get_by_label("solvent-excluded").click();
    wait_loaded(&mut h);
    let state = h.state().objects[0].state.surface;
    assert_eq!(state.choice, orbcloud::scene::SurfaceChoice::SolventExcluded);
    let all = h.state().status.clone();
    assert!(all.starts_with("molecular surface: ") && !all.starts_with("molecular surface: 0 "), "{all}");
    // The surface covers the atoms: what lies under an atom's centre is the surface.
    let atom = h.state().atom_on_screen(0).expect("an atom on screen");
    hover(&mut h, atom);
    assert!(matches!(h.state().hovered(), Some(PickId::Surface { object: 0, .. })), "{:?}", h.state().hovered());
    // Leaving the waters out wraps fewer atoms: fewer triangles.
    h.state_mut().objects[0].state.selection = "not resn HOH".into();
    wait_loaded(&mut h);
    let count = |s: &str| s.split_whitespace().nth(2).and_then(|n| n.parse::<usize>().ok()).expect(s);
    let protein = h.state().status.clone();
    assert!(count(&protein) < count(&all), "{protein} vs {all}");
    // Turning it off leaves no surface.
    h.get_by_role_and_label(egui::accesskit::Role::ComboBox, "surface").click();
    h.run_steps(2);
    h.get_by_label("off").click();
    wait_loaded(&mut h);
    hover(&mut h, atom);
    assert!(!matches!(h.state().hovered(), Some(PickId::Surface { .. })), "{:?}", h.state().hovered());
}

/// The water bending scan of tests/fixtures/scans, as `scan init` writes its manifest, in a
/// temporary folder (file names made absolute).
fn bending_scan(dir: &std::path::Path) -> Harness<'static, OrbApp> {
    let frames = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/scans/water_bend");
    let made = orbcloud::formats::scan::init(&frames, None).unwrap();
    let manifest = dir.join("bend.scan.toml");
    std::fs::write(&manifest, made.text.replace("file = \"", &format!("file = \"{}/", frames.display()))).unwrap();
    let mut h = Harness::builder()
        .with_size([1100.0, 720.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(|cc| OrbApp::new(cc, vec![manifest]));
    wait_for_scan(&mut h, |_| true);
    h
}

#[test]
fn grabbing_the_moving_hydrogen_bends_the_angle() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = bending_scan(dir.path());
    let start = h.state().scan().unwrap().value;
    let screen = |h: &Harness<'static, OrbApp>, atom: usize| {
        let app = h.state();
        app.atom_on_screen(atom).expect("on screen")
    };
    let (vertex, fixed, moving) = (screen(&h, 0), screen(&h, 1), screen(&h, 2));
    // Turn the moving hydrogen about the oxygen on screen, away from the fixed one, by 10°.
    let (arm, away) = (moving - vertex, fixed - vertex);
    let sign = if arm.x * away.y - arm.y * away.x > 0.0 { -1.0f32 } else { 1.0 };
    let target = |deg: f32| {
        let (s, c) = (sign * deg.to_radians()).sin_cos();
        vertex + egui::vec2(c * arm.x - s * arm.y, s * arm.x + c * arm.y)
    };
    // The screen angle at the oxygen between the fixed hydrogen and a point.
    let opening = |p: egui::Pos2| {
        let (u, w) = (fixed - vertex, p - vertex);
        (u.x * w.y - u.y * w.x).atan2(u.x * w.x + u.y * w.y).abs().to_degrees()
    };
    // Grab the arm near the hydrogen (on the bond), then move the pointer round the vertex.
    let grip = vertex + 0.7 * arm;
    h.hover_at(grip);
    h.drag_at(grip);
    h.run_steps(1);
    for deg in [3.0, 6.0, 8.0, 10.0, 10.0, 10.0] {
        h.hover_at(target(deg));
        h.run_steps(1);
    }
    h.drop_at(target(10.0));
    h.run_steps(2);
    let value = h.state().scan().unwrap().value;
    let (held, wanted) = (opening(screen(&h, 2)), opening(target(10.0)));
    eprintln!("angle {start:.1}° → {value:.1}°; on screen the hydrogen at {held:.1}°, the pointer at {wanted:.1}°");
    assert!((held - wanted).abs() < 1.5, "the hydrogen follows the pointer: {held} vs {wanted}");
    assert!(value > start + 5.0, "grabbing the hydrogen opens the angle: {start} → {value}");
}

/// The clipping plane is the object's, edited under its atoms: on, it leaves the atoms whole
/// until asked to cut them too, and then an atom beyond it is no longer there to pick.
#[test]
fn the_object_s_clipping_plane_cuts_its_atoms_when_asked() {
    use orbcloud::gpu::frame::PickId;
    let mut h = harness();
    h.run_steps(2);
    let oxygen = h.state().atom_on_screen(1).expect("the oxygen on screen");
    let picks = |h: &mut Harness<'static, OrbApp>| {
        hover(h, oxygen);
        h.state().hovered()
    };
    let oxygen_id = Some(PickId::Atom { object: 0, index: 1 });
    assert_eq!(picks(&mut h), oxygen_id);
    h.get_by_label("Clipping plane").scroll_to_me();
    h.run_steps(20);
    h.get_by_label("Clipping plane").click();
    h.run_steps(2);
    h.get_by_label("clip").click();
    h.run_steps(2);
    assert!(h.state().objects[0].state.clip.enabled);
    // A plane one bohr before the oxygen's centre, facing away from the object's centre.
    let doc = h.state().doc();
    let (centre, o) = (orbcloud::layers::object_centre(doc), doc.molecule.atoms[1].position.as_vec3());
    let n = (o - centre).normalize();
    let clip = &mut h.state_mut().objects[0].state.clip;
    clip.normal = n.to_array();
    clip.offset = (o - centre).dot(n) - 1.0;
    h.run_steps(3);
    // Every layer of the object (its atoms, its cloud) cuts along the same plane.
    let plane = h.state().objects[0].state.clip.plane(centre);
    assert_eq!(h.state().clip_planes(0), [plane, plane], "the atoms' layer and the quantity's");
    assert_eq!(picks(&mut h), oxygen_id, "atoms are cut only when asked");
    h.get_by_label("cut atoms and bonds too").click();
    h.run_steps(2);
    assert!(h.state().objects[0].state.clip.atoms);
    let hovered = picks(&mut h);
    assert_ne!(hovered, oxygen_id, "the oxygen beyond the plane is cut away");
}

/// Files opened one after another stand side by side across the view, each visible, not one
/// behind another along the line of sight; *Reset view* frames them the same way.
#[test]
fn files_opened_together_stand_side_by_side_across_the_view() {
    let fixture =
        |n: &str| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions").join(n);
    // Water first: it lies in the yz plane, so it is seen along x, the axis files once lined up on.
    let files = vec![fixture("h2o_ccpvtz.fchk"), fixture("benzene_631gs.fchk"), fixture("h3o_cation_631gss.fchk")];
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(move |cc| OrbApp::new(cc, files));
    wait_loaded(&mut h);
    // Each molecule's atoms on screen: all inside the view, the molecules' centres apart.
    let check = |app: &OrbApp| {
        // Whole atoms, not only their centres: 3 % of the view's width inside its edges.
        let view = app.view_rect().expect("a view");
        let view = view.shrink(0.03 * view.width());
        let world = app.world();
        let mut xs = Vec::new();
        for o in 0..app.objects.len() {
            let first = world.offsets[o];
            let n = app.objects[o].doc.molecule.atoms.len();
            let points: Vec<egui::Pos2> =
                (first..first + n).map(|a| app.atom_on_screen(a).expect("projected")).collect();
            assert!(points.iter().all(|p| view.contains(*p)), "molecule {o} in the view {view:?}: {points:?}");
            xs.push(points.iter().map(|p| p.x).sum::<f32>() / n as f32);
        }
        xs.sort_by(f32::total_cmp);
        // Apart across the view by more than a tenth of its width each.
        let apart = view.width() / 10.0;
        assert!(xs.len() == 3 && xs[1] - xs[0] > apart && xs[2] - xs[1] > apart, "side by side: {xs:?} in {view:?}");
    };
    check(h.state());
    h.get_by_label("Reset view").click();
    h.run_steps(2);
    check(h.state());
}

#[test]
fn the_view_gets_most_of_the_window_and_the_panels_fit_beside_it_or_close() {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/wavefunctions/h2o_cation_uhf_631gs.molden");
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(move |cc| OrbApp::new(cc, vec![file]));
    wait_loaded(&mut h);
    let view = h.state().view_rect().expect("a view");
    assert!(view.width() > 0.5 * 1280.0, "the view is {} of 1280 px", view.width());
    // An unrestricted file's browser holds the most: each of its controls lies whole between the
    // view and the window's edge.
    for label in ["ESP map", "+ electrostatic potential", "per sample (direct)", "β"] {
        let r = h.get_by_label(label).rect();
        assert!(r.min.x >= view.max.x - 0.5 && r.max.x <= 1280.5, "{label} at {r:?}, the view {view:?}");
    }
    let heading = h.get_all_by_label("Orbitals").map(|n| n.rect()).max_by(|a, b| a.min.y.total_cmp(&b.min.y)).unwrap();
    assert!(heading.min.x >= view.max.x - 0.5, "the heading {heading:?} is cut");
    // The top bar's toggles close both panels: the view takes the window's width.
    for toggle in ["Scene", "Orbitals"] {
        let top = h.get_all_by_label(toggle).min_by(|a, b| a.rect().min.y.total_cmp(&b.rect().min.y)).unwrap();
        top.click();
        h.run_steps(1);
    }
    h.run_steps(20);
    let wide = h.state().view_rect().expect("a view");
    assert!(wide.width() > 1200.0, "with the panels closed the view is {} px", wide.width());
}

#[test]
fn the_demo_shows_its_molecule_at_once_while_its_key_volumes_are_made() {
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(|cc| OrbApp::new(cc, Vec::new()));
    let start = std::time::Instant::now();
    while !h.state().shows_scan_skeleton() {
        assert!(h.state().scan().is_none(), "the scan opened before its first frame was shown");
        assert!(start.elapsed().as_secs() < 60, "no molecule after a minute");
        std::thread::sleep(std::time::Duration::from_millis(10));
        h.run_steps(1);
    }
    h.run_steps(2);
    assert!(h.query_by_label_contains("its first frame is shown while").is_some(), "the status says what is prepared");
    // The molecule is drawn: its atoms lie in the view.
    let view = h.state().view_rect().expect("a view");
    assert!(view.width() > 600.0);
    wait_for_scan(&mut h, |_| true);
}
