//! Several quantities of one molecule in the viewer (egui_kittest on lavapipe): a density joins
//! an orbital from the orbital browser and is shown, hidden and removed; HOMO and LUMO side by
//! side in linked panes; sessions keep quantities, panes and measurements (and old sessions
//! still open); the panels show exactly the selected object's quantities.

mod common;
#[path = "common/viewer.rs"]
mod viewer_support;

use std::path::{Path, PathBuf};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use orbcloud::app::{OrbApp, wgpu_setup};
use orbcloud::model::orbitals::{Quantity, Spin};
use orbcloud::scene::Source::{self, Wavefunction};
use orbcloud::scene::objects::AddedVolume;
use viewer_support::{click_at, wait_loaded};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

/// The viewer at 1280×800 (the size the panels are laid out for) with `files` open.
fn open(files: Vec<PathBuf>) -> Harness<'static, OrbApp> {
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(move |cc| OrbApp::new(cc, files));
    wait_loaded(&mut h);
    h
}

fn sources(app: &OrbApp) -> Vec<Source> {
    app.objects[app.active].state.quantities.iter().map(|q| q.source).collect()
}

/// The view as a PNG would save it.
fn picture(h: &mut Harness<'static, OrbApp>, dir: &Path, name: &str) -> image::RgbaImage {
    let path = dir.join(format!("{name}.png"));
    h.state_mut().save_png(&path);
    image::open(&path).expect("the view was saved").to_rgba8()
}

#[test]
fn a_density_joins_the_homo_from_the_orbital_browser_and_is_shown_hidden_and_removed() {
    let mut h = open(vec![fixture("wavefunctions/benzene_631gs.molden")]);
    let dir = tempfile::tempdir().unwrap();
    let wf = h.state().doc().wavefunction.clone().expect("a wavefunction");
    let homo = wf.homo(Spin::Alpha).unwrap();
    assert_eq!(sources(h.state()), [Wavefunction(Quantity::Orbital(homo))], "opens on the HOMO alone");
    let alone = picture(&mut h, dir.path(), "homo");

    h.get_by_label("+ total density").click();
    wait_loaded(&mut h);
    assert_eq!(sources(h.state()), [Wavefunction(Quantity::Orbital(homo)), Wavefunction(Quantity::Density)]);
    assert_eq!(h.state().objects[0].state.selected, 1, "the new quantity is the one the panels edit");
    assert!(h.query_by_label("total density · cloud").is_some(), "the scene panel lists it");
    let both = picture(&mut h, dir.path(), "both");
    assert!(
        common::mean_difference(&alone, &both) > 1.0,
        "the density's cloud shows: {}",
        common::mean_difference(&alone, &both)
    );

    // Hidden, the picture is the HOMO's alone again; shown, it is back.
    h.state_mut().objects[0].state.quantities[1].visible = false;
    h.run_steps(2);
    assert_eq!(common::mean_difference(&alone, &picture(&mut h, dir.path(), "hidden")), 0.0, "hidden");
    h.state_mut().objects[0].state.quantities[1].visible = true;
    h.run_steps(2);
    assert_eq!(common::mean_difference(&both, &picture(&mut h, dir.path(), "shown")), 0.0, "shown again");

    // Removed with its × in the scene panel (the first × removes the object, then one per
    // quantity): the HOMO stays, drawn as before.
    let removes = h.state().objects[0].state.quantities.len();
    assert_eq!(h.get_all_by_label("×").count(), 1 + removes);
    h.get_all_by_label("×").nth(2).expect("the density's ×").click();
    wait_loaded(&mut h);
    assert_eq!(sources(h.state()), [Wavefunction(Quantity::Orbital(homo))]);
    assert_eq!(common::mean_difference(&alone, &picture(&mut h, dir.path(), "removed")), 0.0, "the HOMO alone again");

    // A row of the browser switches the selected quantity; its menu adds an orbital instead.
    let lumo = wf.lumo(Spin::Alpha).unwrap();
    h.get_by_label_contains(&format!("MO {} ", lumo + 1)).click_secondary();
    h.run_steps(2);
    h.get_by_label("add to this view").click();
    wait_loaded(&mut h);
    assert_eq!(sources(h.state()), [Wavefunction(Quantity::Orbital(homo)), Wavefunction(Quantity::Orbital(lumo))]);
}

#[test]
fn homo_and_lumo_of_one_file_side_by_side_in_linked_panes_and_a_session_keeps_them() {
    let benzene = fixture("wavefunctions/benzene_631gs.molden");
    let mut h = open(vec![benzene.clone()]);
    let dir = tempfile::tempdir().unwrap();
    let wf = h.state().doc().wavefunction.clone().unwrap();
    let (homo, lumo) = (wf.homo(Spin::Alpha).unwrap(), wf.lumo(Spin::Alpha).unwrap());
    // The HOMO opens with its ±ψ surfaces: the LUMO beside it is drawn the same way.
    assert!(h.state().objects[0].state.quantities[0].isosurfaces[0].visible, "an orbital opens with its surfaces");
    h.get_by_label_contains(&format!("MO {} ", lumo + 1)).click_secondary();
    h.run_steps(2);
    h.get_by_label("show beside (a pane of its own)").click();
    wait_loaded(&mut h);
    let app = h.state();
    assert_eq!(app.view.panes.count, 2);
    let state = &app.objects[0].state;
    assert!(state.quantities.iter().all(|q| q.isosurfaces[0].visible), "both panes keep the isosurfaces");
    assert_eq!(state.quantities[1].isosurfaces, state.quantities[0].isosurfaces);
    // Surfaces off again: the clicks below pick atoms, not surfaces.
    h.state_mut().objects[0].state.quantities.iter_mut().for_each(|q| q.isosurfaces[0].visible = false);
    wait_loaded(&mut h);
    let app = h.state();
    let state = &app.objects[0].state;
    let placed: Vec<_> = state.quantities.iter().map(|q| (q.source, q.pane)).collect();
    assert_eq!(
        placed,
        [(Wavefunction(Quantity::Orbital(homo)), Some(0)), (Wavefunction(Quantity::Orbital(lumo)), Some(1))]
    );
    let sizes = app.view_sizes();
    assert_eq!(sizes.len(), 2, "two panes drawn: {sizes:?}");
    // Each pane is labelled with its orbital and energy.
    let labels: Vec<String> = (0..2).map(|p| orbcloud::app::panes::label(&app.objects, p, 2)).collect();
    assert!(labels[0].starts_with("HOMO  E = ") && labels[1].starts_with("LUMO  E = "), "{labels:?}");
    let split = picture(&mut h, dir.path(), "split");
    let w = split.width() / 2;
    let (left, right) = (
        image::imageops::crop_imm(&split, 0, 0, w, split.height()).to_image(),
        image::imageops::crop_imm(&split, w, 0, w, split.height()).to_image(),
    );
    assert!(
        common::mean_difference(&left, &right) > 2.0,
        "HOMO and LUMO differ: {}",
        common::mean_difference(&left, &right)
    );

    // Linked: a drag in the right pane turns both.
    let yaw = h.state().view.camera.yaw;
    // The view lies between the side panel (290 points) and the orbital browser (400): its
    // right pane spans about 585..880.
    let from = egui::pos2(760.0, 420.0);
    drag(&mut h, from, 80.0);
    assert!((h.state().view.camera.yaw - yaw).abs() > 0.2, "the shared camera turned");
    let turned = picture(&mut h, dir.path(), "turned");
    let (l2, r2) = (
        image::imageops::crop_imm(&turned, 0, 0, w, turned.height()).to_image(),
        image::imageops::crop_imm(&turned, w, 0, w, turned.height()).to_image(),
    );
    assert!(
        common::mean_difference(&left, &l2) > 0.5 && common::mean_difference(&right, &r2) > 0.5,
        "both panes turned"
    );

    // Unlinked: the right pane turns alone.
    h.get_by_label("one camera").click();
    h.run_steps(2);
    let (shared, own) = (h.state().view.camera, h.state().view.panes.cameras[1]);
    drag(&mut h, from, -80.0);
    assert_eq!(h.state().view.camera, shared, "the first pane's camera stays");
    assert!((h.state().view.panes.cameras[1].yaw - own.yaw).abs() > 0.2, "the second pane's camera turned");
    h.get_by_label("one camera").click();
    h.run_steps(2);

    // Two atoms measured in the first pane; the session keeps quantities, panes and the
    // measurement; reopened after the scene was replaced, everything is as it was.
    let (a, b) = (h.state().atom_on_screen(0).unwrap(), h.state().atom_on_screen(1).unwrap());
    click_at(&mut h, a, false);
    click_at(&mut h, b, true);
    assert_eq!(h.state().measurements.list.len(), 1, "{}", h.state().status);
    let session = dir.path().join("split.orbcloud.toml");
    h.state_mut().save_session(&session);
    let saved = (h.state().objects[0].state.clone(), h.state().view.panes, h.state().measurements.list.clone());
    let ctx = h.ctx.clone();
    h.state_mut().open_as(fixture("wavefunctions/h2o_cart_631gs.molden"), orbcloud::app::Opening::Replace, &ctx);
    wait_loaded(&mut h);
    assert!(h.state().measurements.list.is_empty());
    h.state_mut().open(session, &ctx);
    wait_loaded(&mut h);
    let app = h.state();
    assert_eq!((app.objects[0].state.clone(), app.view.panes, app.measurements.list.clone()), saved);
    assert_eq!(app.view_sizes().len(), 2, "split again");
}

/// A primary-button drag `dx` points to the right from `from`.
/// The largest |shown − want| over the shown grid, and the largest |want|.
fn worst_difference(app: &OrbApp, want: impl Fn(glam::DVec3) -> f64) -> (f64, f64) {
    let grid = app.shown_values().expect("values shown");
    let [nx, ny, nz] = grid.dims;
    let (mut worst, mut max) = (0f64, 0f64);
    for i in (0..nx).step_by(3) {
        for j in (0..ny).step_by(3) {
            for k in (0..nz).step_by(3) {
                let w = want(grid.point(i, j, k));
                worst = worst.max((grid.values[(i * ny + j) * nz + k] as f64 - w).abs());
                max = max.max(w.abs());
            }
        }
    }
    (worst, max)
}

/// Jang and Varetto's atomic-orbital selector picks single basis functions: ticking O 2px alone
/// restricts the HOMO (water's lone pair) to c·χ(2px); right-clicking O 3dxy shows that bare
/// d function as a quantity of its own.
#[test]
fn the_atomic_orbital_selector_picks_single_basis_functions() {
    use orbcloud::model::basis_labels::find_function;
    let mut h = open(vec![fixture("wavefunctions/h2o_ccpvtz.molden")]);
    // Kept for a look: target/tmp/ao_*.png.
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let doc = h.state().doc().clone();
    let wf = doc.wavefunction.as_ref().expect("a wavefunction");
    let prepared = orbcloud::model::PreparedBasis::new(&wf.basis);
    let homo = wf.homo(Spin::Alpha).unwrap();
    let homo_picture = picture(&mut h, dir, "ao_homo");

    h.get_by_label("Atomic orbitals").click();
    h.run_steps(2);
    h.get_by_label("none").click();
    h.run_steps(1);
    // Water's first "2px" is the oxygen's.
    h.get_all_by_label("2px").next().expect("the O 2px box").click();
    wait_loaded(&mut h);
    let px = find_function(&doc.molecule, &wf.basis, "O1 2px").unwrap();
    let e = &h.state().objects[0].state.evaluation;
    assert!(e.ao_filter, "ticking applies the selection");
    let ticked: Vec<usize> = e.functions.iter().enumerate().filter(|(_, on)| **on).map(|(k, _)| k).collect();
    assert_eq!(ticked, [px], "only O 2px is ticked");
    let c = wf.orbitals[homo].coefficients[px];
    let (worst, max) = worst_difference(h.state(), |p| c * prepared.basis_values(p)[px]);
    assert!(max > 0.05 && worst < 1e-5, "the HOMO's O 2px part: worst {worst:.2e} of {max:.3}");
    let restricted = picture(&mut h, dir, "ao_homo_on_o_2px");
    let d = common::mean_difference(&homo_picture, &restricted);
    assert!(d > 0.5, "the picture changes ({d})");

    // Right-click O 3dxy: shown alone, normalised as the basis defines it.
    h.get_all_by_label("3dxy").next().expect("the O 3dxy box").click_secondary();
    h.run_steps(2);
    h.get_by_label("show O1 3dxy alone").click();
    wait_loaded(&mut h);
    let dxy = find_function(&doc.molecule, &wf.basis, "O1 3dxy").unwrap();
    assert_eq!(sources(h.state()), [Wavefunction(Quantity::BasisFunction(dxy))]);
    assert!(h.query_by_label_contains("O1 3dxy · cloud").is_some(), "the scene panel names it");
    let (worst, max) = worst_difference(h.state(), |p| prepared.basis_values(p)[dxy]);
    assert!(max > 0.1 && worst < 1e-5, "the bare O 3dxy: worst {worst:.2e} of {max:.3}");
    picture(&mut h, dir, "ao_bare_3dxy");
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
}

fn drag(h: &mut Harness<'static, OrbApp>, from: egui::Pos2, dx: f32) {
    h.hover_at(from);
    h.drag_at(from);
    h.run_steps(1);
    for i in 1..=4 {
        h.hover_at(from + egui::vec2(dx * i as f32 / 4.0, 0.0));
        h.run_steps(1);
    }
    h.drop_at(from + egui::vec2(dx, 0.0));
    h.run_steps(2);
}

#[test]
fn a_session_written_before_quantities_still_opens() {
    let benzene = fixture("wavefunctions/benzene_631gs.molden");
    let dir = tempfile::tempdir().unwrap();
    let session = dir.path().join("old.orbcloud.toml");
    // As sessions were written when an object held one quantity (the first isosurface in
    // `settings.iso`, the orbital in `quantity`).
    let text = format!(
        r#"background = [0.1, 0.1, 0.1]
recent = []

[camera]
target = [0.0, 0.0, 0.0]
distance = 25.0
yaw = 0.4
pitch = 0.3
fov_y = 0.6

[[objects]]
path = "{}"
visible = true
volume = 0
quantity = {{ Orbital = 19 }}
selection = ""

[objects.placement]
offset = [0.0, 0.0, 0.0]
rotation_deg = [0.0, 0.0, 0.0]

[objects.settings]
atoms = "Sticks"
atom_colors = "Element"
background = [0.1, 0.1, 0.1]
depth_cue = 0.0

[objects.settings.volume]
visible = false
mode = "ViewAligned"
slices = 100
k1 = 0.2
k2 = 0.6
positive_color = [0.9, 0.12, 0.1]
negative_color = [0.1, 0.3, 0.95]

[objects.settings.volume.transfer]
kind = "PowerLaw"
shading = false
boundary = 0.0
gradient_power = 0.0
positive = {{ shape = "Gaussian", center = 0.5, width = 0.1, opacity = 0.5 }}
negative = {{ shape = "Gaussian", center = 0.5, width = 0.1, opacity = 0.5 }}

[objects.settings.volume.clip]
enabled = false
normal = [0.0, 0.0, 1.0]
offset = 0.0

[objects.settings.iso]
visible = true
level = {{ Absolute = 0.04 }}
positive_color = [0.85, 0.1, 0.08]
negative_color = [0.08, 0.25, 0.85]
density_color = [0.55, 0.62, 0.75]
"#,
        benzene.display()
    );
    std::fs::write(&session, text).unwrap();
    let mut h = open(vec![fixture("wavefunctions/h2o_cart_631gs.molden")]);
    let ctx = h.ctx.clone();
    h.state_mut().open(session, &ctx);
    wait_loaded(&mut h);
    let app = h.state();
    assert_eq!(app.objects.len(), 1);
    let state = &app.objects[0].state;
    assert_eq!(state.atoms.style, orbcloud::scene::AtomStyle::Sticks);
    assert_eq!(state.quantities.len(), 1);
    let q = &state.quantities[0];
    assert_eq!(q.source, Wavefunction(Quantity::Orbital(19)));
    assert!(!q.cloud.visible && q.cloud.slices == 100);
    assert_eq!(q.isosurfaces[0].level, orbcloud::scene::IsoLevel::Absolute(0.04));
    assert!(app.status.starts_with("isosurfaces: "), "its isosurface is cut: {}", app.status);
}

#[test]
fn the_panels_follow_the_scene() {
    // An unrestricted file: β in the browser shows the β orbital of the same place, and a
    // reopened β orbital lists β.
    let mut h = open(vec![fixture("wavefunctions/h2o_cation_uhf_631gs.molden")]);
    let wf = h.state().doc().wavefunction.clone().unwrap();
    h.get_by_label("β").click();
    wait_loaded(&mut h);
    let shown = h.state().selected_quantity().unwrap().source.orbital().expect("an orbital");
    assert_eq!(shown, wf.homo(Spin::Beta).unwrap(), "β switches to the β HOMO");
    h.get_by_label("α").click();
    wait_loaded(&mut h);
    assert_eq!(h.state().selected_quantity().unwrap().source.orbital(), wf.homo(Spin::Alpha));
    let beta_lumo = wf.lumo(Spin::Beta).unwrap();
    h.state_mut().objects[0].state.quantities[0].source = Wavefunction(Quantity::Orbital(beta_lumo));
    wait_loaded(&mut h);
    assert_eq!(h.state().objects[0].state.evaluation.spin, Spin::Beta, "the list follows the orbital shown");
    // Spins and densities are separate, labelled rows.
    assert!(h.query_by_label("orbitals of spin").is_some() && h.query_by_label("show").is_some());

    // A long file name keeps its × inside the panel; *+ isosurface* is on screen at 1280×800.
    let dir = tempfile::tempdir().unwrap();
    let long = dir.path().join(format!("{}.molden", "a_very_long_name_of_a_calculation_".repeat(4)));
    std::fs::copy(fixture("wavefunctions/h2o_cart_631gs.molden"), &long).unwrap();
    let h = open(vec![long]);
    let remove = h.get_all_by_label("×").next().expect("the object's ×").rect();
    assert!(remove.right() < 300.0, "× at {remove:?}");
    let add = h.get_by_label("+ isosurface").rect();
    assert!(add.bottom() < 800.0, "+ isosurface at {add:?}");

    // A protein: no cloud or isosurface controls, and a selection says how many atoms it shows
    // and frames them when entered.
    let mut h = open(vec![fixture("structures/4e43_excerpt.pdb")]);
    assert!(h.query_by_label("show cloud").is_none() && h.query_by_label("+ isosurface").is_none());
    let distance = h.state().view.camera.distance;
    let total = h.state().doc().molecule.atoms.len();
    h.state_mut().objects[0].state.selection = "resi 30-34".into();
    h.run_steps(2);
    let shown = h.state().shown_atoms();
    assert!(shown > 0 && shown < total, "{shown} of {total}");
    assert!(h.query_by_label_contains(&format!("{shown} of {total} atoms shown")).is_some());
    h.state_mut().reframe();
    assert!(h.state().view.camera.distance < distance, "framed closer on the atoms shown");

    // After a scan opens, the previous file's orbital browser is gone.
    let mut h = open(vec![fixture("wavefunctions/h2o_cart_631gs.molden")]);
    // The browser's heading and the top bar's toggle that closes it.
    assert_eq!(h.query_all_by_label("Orbitals").count(), 2);
    let ctx = h.ctx.clone();
    h.state_mut().open_demo(orbcloud::app::Demo::Scan, &ctx);
    let start = std::time::Instant::now();
    while h.state().scan().is_none() {
        assert!(start.elapsed().as_secs() < 300, "no scan: {:?}", h.state().error);
        std::thread::sleep(std::time::Duration::from_millis(50));
        h.run_steps(1);
    }
    h.run_steps(2);
    assert_eq!(h.query_all_by_label("Orbitals").count(), 0, "the orbital browser left with its file");
}

#[test]
fn a_normal_mode_animates_with_arrows_and_a_click_on_its_band_picks_it() {
    let ts = fixture("modes/nh3_planar_rhf_sto3g.molden");
    let mut h = open(vec![ts]);
    let dir = tempfile::tempdir().unwrap();
    assert!(h.query_by_label("Vibrations").is_some(), "the modes panel");
    let still = picture(&mut h, dir.path(), "still");
    // The imaginary mode, marked with an i.
    h.get_by_label_contains("1117.82i").click();
    h.run_steps(3);
    assert_eq!(h.state().objects[0].state.vibration.mode, Some(0));
    h.run_steps(1);
    assert!(h.query_by_label_contains("mode 1: 1117.8i cm-1").is_some(), "named, imaginary");
    wait_loaded(&mut h);
    let a = picture(&mut h, dir.path(), "a");
    for _ in 0..10 {
        std::thread::sleep(std::time::Duration::from_millis(30));
        h.run_steps(1);
    }
    let b = picture(&mut h, dir.path(), "b");
    assert!(common::mean_difference(&still, &a) > 0.05, "the atoms moved and the arrows show");
    assert!(common::mean_difference(&a, &b) > 0.01, "and keep moving: {}", common::mean_difference(&a, &b));

    // A click on the 1852 cm⁻¹ band picks its mode.
    let transform = h.state().spectrum.expect("the spectrum is drawn");
    let band = transform.position_from_point(&egui_plot::PlotPoint::new(-1851.99, 3.0));
    click_at(&mut h, band, false);
    h.run_steps(2);
    assert_eq!(h.state().objects[0].state.vibration.mode, Some(1), "the band's mode");
    h.run_steps(2);
    assert!(h.query_by_label_contains("mode 2: 1852.0 cm-1").is_some(), "the mode shown is named");

    // The session keeps the mode and its settings; "none" puts the atoms back.
    h.state_mut().objects[0].state.vibration.amplitude = 0.7;
    h.run_steps(2);
    let session = dir.path().join("modes.orbcloud.toml");
    h.state_mut().save_session(&session);
    let saved = h.state().objects[0].state.vibration;
    let ctx = h.ctx.clone();
    h.state_mut().open_as(fixture("wavefunctions/h2o_cart_631gs.molden"), orbcloud::app::Opening::Replace, &ctx);
    wait_loaded(&mut h);
    assert!(h.query_by_label("Vibrations").is_none(), "a file without modes has no modes panel");
    h.state_mut().open(session, &ctx);
    wait_loaded(&mut h);
    assert_eq!(h.state().objects[0].state.vibration, saved);
    h.get_by_label("none").click();
    h.run_steps(3);
    wait_loaded(&mut h);
    assert_eq!(common::mean_difference(&still, &picture(&mut h, dir.path(), "rest")), 0.0, "back at rest");
}

/// Pixels of `img` clearly red and clearly blue (the ends of the diverging map).
fn red_and_blue(img: &image::RgbaImage) -> (usize, usize) {
    let (mut red, mut blue) = (0, 0);
    for p in img.pixels() {
        let [r, _, b, _] = p.0.map(i32::from);
        red += usize::from(r > b + 25);
        blue += usize::from(b > r + 25);
    }
    (red, blue)
}

#[test]
fn a_density_cube_and_its_potential_cube_open_as_one_object_shown_as_an_esp_map() {
    let (density, potential) = (fixture("esp/h2o_density.cube"), fixture("esp/h2o_potential.cube"));
    let mut h = open(vec![density.clone(), potential.clone()]);
    let dir = tempfile::tempdir().unwrap();
    let app = h.state();
    assert_eq!(app.objects.len(), 1, "the potential joined the density's object: {}", app.status);
    assert_eq!(app.doc().volumes.len(), 2);
    assert_eq!(sources(app), [Source::Volume(0), Source::Volume(1), Source::Volume(0)]);
    let state = &app.objects[0].state;
    assert_eq!(state.added, [AddedVolume::Joined { path: potential.clone() }]);
    assert!(!state.quantities[0].visible && !state.quantities[1].visible, "the map takes the view");
    let map = &state.quantities[2];
    assert_eq!(map.isosurfaces[0].color_by, Some(Source::Volume(1)), "the density's surface coloured by the potential");
    assert!(!map.cloud.visible);
    let notice = app.notice.clone().unwrap_or_default();
    assert!(notice.contains("h2o_potential.cube joined") && notice.contains("ESP map"), "{notice}");

    // Oxygen's lone pairs attract a positive charge (red), the hydrogens repel it (blue).
    let shown = picture(&mut h, dir.path(), "esp_map");
    let (red, blue) = red_and_blue(&shown);
    assert!(red > 100 && blue > 100, "both ends of the map show: {red} red, {blue} blue pixels");

    // A session keeps the joined file; reopened after the scene was replaced, all is as it was.
    let session = dir.path().join("pair.orbcloud.toml");
    h.state_mut().save_session(&session);
    let saved = h.state().objects[0].state.clone();
    let ctx = h.ctx.clone();
    h.state_mut().open_as(fixture("wavefunctions/h2o_cart_631gs.molden"), orbcloud::app::Opening::Replace, &ctx);
    wait_loaded(&mut h);
    h.state_mut().open(session, &ctx);
    wait_loaded(&mut h);
    assert_eq!(h.state().objects.len(), 1);
    assert_eq!(h.state().objects[0].state, saved);
    assert_eq!(h.state().doc().volumes.len(), 2, "the potential cube was read again");
    let reopened = picture(&mut h, dir.path(), "reopened");
    assert!(common::mean_difference(&shown, &reopened) < 0.5, "{}", common::mean_difference(&shown, &reopened));

    // A cube of other atoms opens beside it, as its own object.
    let demo = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/demo.cube.gz");
    h.state_mut().open_as(demo, orbcloud::app::Opening::Add, &ctx);
    wait_loaded(&mut h);
    assert_eq!(h.state().objects.len(), 2, "other atoms do not join");
}

#[test]
fn a_density_minus_another_files_density_joins_as_a_data_set_and_a_session_makes_it_again() {
    let (a, b) = (fixture("wavefunctions/h2o_ccpvtz.molden"), fixture("wavefunctions/h2o_cart_631gs.molden"));
    let mut h = open(vec![a.clone(), b.clone()]);
    assert_eq!(h.state().objects.len(), 2, "files with wavefunctions open as objects of their own");
    h.state_mut().select(0);
    h.state_mut().objects[0].state.quantities[0].source = Wavefunction(Quantity::Density);
    wait_loaded(&mut h);
    assert_eq!(h.state().subtractable(), [(1, "h2o_cart_631gs.molden".to_string())]);

    h.get_by_label("minus").click();
    h.run_steps(2);
    h.get_by_label("h2o_cart_631gs.molden").click();
    wait_loaded(&mut h);
    let app = h.state();
    assert_eq!(sources(app), [Wavefunction(Quantity::Density), Source::Volume(0)]);
    let grid = &app.objects[0].doc.volumes[0];
    assert_eq!(grid.label, "total density − h2o_cart_631gs.molden");
    assert!(grid.stats.min < 0.0 && grid.stats.max > 0.0, "a difference has both signs");

    // Each point is ρ_A − ρ_B there, by the evaluator tested against PySCF.
    let density = |doc: &orbcloud::model::Document, p: glam::DVec3| {
        let wf = doc.wavefunction.as_ref().unwrap();
        let prepared = orbcloud::model::gto::PreparedBasis::new(&wf.basis);
        prepared.quantity_at_points(wf, &doc.molecule, Quantity::Density, &[p])[0]
    };
    let (da, db) = (&app.objects[0].doc, &app.objects[1].doc);
    for (i, j, k) in [(10, 20, 30), (36, 36, 36), (50, 40, 20), (36, 30, 40)] {
        let p = grid.point(i, j, k);
        let want = density(da, p) - density(db, p);
        let got = grid.value(i, j, k) as f64;
        assert!((got - want).abs() < 1e-5 * want.abs().max(1.0), "at {p}: {got} against {want}");
    }

    // A session makes it again from the two files.
    let dir = tempfile::tempdir().unwrap();
    let session = dir.path().join("difference.orbcloud.toml");
    h.state_mut().save_session(&session);
    let saved = h.state().objects[0].state.clone();
    let values = h.state().objects[0].doc.volumes[0].values.clone();
    let ctx = h.ctx.clone();
    h.state_mut().open(session, &ctx);
    wait_loaded(&mut h);
    let app = h.state();
    assert_eq!(app.objects[0].state, saved);
    assert_eq!(app.objects[0].doc.volumes[0].values, values, "the same difference, made again");
}

#[test]
fn a_plane_map_beside_the_view_is_exact_follows_the_plane_and_saves_its_figure() {
    use orbcloud::model::gto::PreparedBasis;
    use orbcloud::model::units::BOHR_PER_ANGSTROM;
    let mut h = open(vec![fixture("wavefunctions/benzene_631gs.fchk")]);
    let dir = tempfile::tempdir().unwrap();
    h.get_by_label("Plane map").click();
    // Steps until the full map of the plane at `offset` is shown.
    let wait = |h: &mut Harness<'static, OrbApp>, offset: f64| {
        let start = std::time::Instant::now();
        loop {
            h.run_steps(1);
            let app = h.state();
            assert!(app.plane.error.is_none(), "{:?}", app.plane.error);
            if let Some(made) = app.plane.made()
                && made.map().plane.points == app.plane.points
                && made.offset() == offset
            {
                break;
            }
            assert!(start.elapsed().as_secs() < 120, "no map at {offset} Å after two minutes");
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
    };
    wait(&mut h, 0.0);
    let check = |app: &OrbApp| {
        let made = app.plane.made().unwrap();
        let doc = &app.objects[0].doc;
        let wf = doc.wavefunction.as_ref().unwrap();
        let homo = Quantity::Orbital(wf.homo(Spin::Alpha).unwrap());
        let map = made.map();
        // Exact: the evaluator's own value at every 997th point of the map.
        let points: Vec<_> = map.plane.points().into_iter().step_by(997).collect();
        let expected = PreparedBasis::new(&wf.basis).quantity_at_points(wf, &doc.molecule, homo, &points);
        let got: Vec<f64> = map.values.iter().copied().step_by(997).collect();
        let worst = got.iter().zip(&expected).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(worst <= 1e-9 * map.max_abs().max(1e-12), "worst {worst:e} of {}", map.max_abs());
        // The plane lies the offset away from the ring's first three atoms.
        let atoms: Vec<_> = doc.molecule.atoms[..3].iter().map(|a| a.position).collect();
        let normal = (atoms[1] - atoms[0]).cross(atoms[2] - atoms[0]).normalize();
        let distance = (map.plane.center - atoms[0]).dot(normal).abs();
        assert!((distance - made.offset() * BOHR_PER_ANGSTROM).abs() < 1e-9, "{distance} bohr");
        map.vanishes()
    };
    assert!(check(h.state()), "the π HOMO vanishes in the ring's plane");
    // Moved half an ångström off the ring, in the view (Alt + wheel, 0.1 Å a notch), the map
    // follows: the π lobes. The camera stays where it was.
    let view = h.state().view_rect().unwrap();
    let distance = h.state().view.camera.distance;
    h.hover_at(view.center());
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::ALT));
    for _ in 0..5 {
        h.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Line,
            delta: egui::vec2(0.0, 1.0),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Unknown,
            modifiers: egui::Modifiers::ALT,
        });
        h.run_steps(1);
    }
    // The wheel's smoothed remainder is spent while Alt is still held.
    h.run_steps(20);
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.run_steps(1);
    assert!((h.state().plane.offset - 0.5).abs() < 1e-9, "offset {}", h.state().plane.offset);
    assert_eq!(h.state().view.camera.distance, distance, "Alt + wheel moves the plane, not the camera");
    h.state_mut().plane.offset = 0.5;
    wait(&mut h, 0.5);
    assert!(!check(h.state()), "the HOMO's lobes above the ring");
    let svg = dir.path().join("homo.svg");
    h.state().plane.save(&svg).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.matches(r#"class="contour""#).count() > 4 && text.contains("stroke-dasharray"),
        "contours, negative dashed"
    );
    let png = dir.path().join("homo.png");
    h.state().plane.save(&png).unwrap();
    assert!(image::open(&png).unwrap().width() > 200);
}

#[test]
fn an_esp_map_is_framed_beside_its_colour_bar() {
    let mut h = open(vec![fixture("wavefunctions/benzene_631gs.fchk")]);
    h.get_by_label("ESP map").click();
    wait_loaded(&mut h);
    let app = h.state();
    let view = app.view_rect().expect("a view");
    let free = view.right() - orbcloud::app::legend::BAR_ROOM;
    // The ρ = 0.002 surface reaches about 3.8 bohr past the nuclei: every atom's reach towards
    // the bar stays left of it, and the surface is not shrunk to a corner.
    let (right, _) = app.view.camera.screen_axes();
    let reach: Vec<egui::Pos2> = app
        .world()
        .molecule
        .atoms
        .iter()
        .map(|a| app.point_on_screen(a.position.as_vec3() + right * 3.8).unwrap())
        .collect();
    let rightmost = reach.iter().map(|p| p.x).fold(f32::MIN, f32::max);
    assert!(rightmost < free, "the surface reaches x = {rightmost}, the bar starts at {free}");
    let leftmost = reach.iter().map(|p| p.x).fold(f32::MAX, f32::min);
    assert!(rightmost - leftmost > 0.3 * (free - view.left()), "framed to fill the free part: {leftmost}..{rightmost}");
}

#[test]
fn panes_show_the_molecule_across_their_width_and_reset_view_refits_them() {
    let mut h = open(vec![fixture("wavefunctions/benzene_631gs.molden")]);
    let lumo = h.state().doc().wavefunction.as_ref().unwrap().lumo(Spin::Alpha).unwrap();
    h.get_by_label_contains(&format!("MO {} ", lumo + 1)).click_secondary();
    h.run_steps(2);
    h.get_by_label("show beside (a pane of its own)").click();
    wait_loaded(&mut h);
    // How much of the first pane's width the atoms span.
    let span = |app: &OrbApp| {
        let pane = app.view_rect().expect("a pane");
        let xs: Vec<f32> =
            (0..app.world().molecule.atoms.len()).map(|a| app.atom_on_screen(a).expect("on screen").x).collect();
        let (lo, hi) = xs.iter().fold((f32::MAX, f32::MIN), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        assert!(lo > pane.left() && hi < pane.right(), "the molecule inside its pane: {lo}..{hi} in {pane:?}");
        (hi - lo) / pane.width()
    };
    assert_eq!(h.state().view.panes.count, 2);
    let framed = span(h.state());
    assert!(framed > 0.5, "the atoms span {framed:.2} of the pane's width");
    h.state_mut().view.camera.distance *= 3.0;
    h.run_steps(2);
    assert!(span(h.state()) < 0.5 * framed, "zoomed out");
    h.get_by_label("Reset view").click();
    h.run_steps(3);
    assert!((span(h.state()) - framed).abs() < 0.05, "Reset view frames the panes again: {}", span(h.state()));
}

#[test]
fn a_td_checkpoint_lists_its_states_and_a_click_on_a_band_picks_one_its_density_shown_in_two_colours() {
    let Some(corpus) = common::refdata("excited states in the window") else { return };
    let td = corpus.join("logs/basicGaussian09_dvb_td.fchk");
    let mut h = open(vec![td]);
    wait_loaded(&mut h);
    assert!(h.query_by_label("Excited states").is_some(), "the states panel");
    assert!(h.query_by_label_contains("5 states from Gaussian").is_some(), "what the list holds");
    // The bright state 2 (f 0.588, 6.062 eV): a click on its band picks it. The file holds
    // state 1's density only, so nothing else changes.
    let transform = h.state().uv_vis.expect("the spectrum is drawn");
    click_at(&mut h, transform.position_from_point(&egui_plot::PlotPoint::new(6.07, 0.3)), false);
    h.run_steps(2);
    assert_eq!(h.state().objects[0].state.excited.state, Some(1), "the band's state");
    assert!(h.query_by_label_contains("state 2: 6.062 eV, 204.5 nm").is_some(), "the state picked is named");
    // State 1 from the list: its difference density, two-coloured (gain red, loss blue).
    h.get_by_label_contains("5.629").click();
    h.run_steps(3);
    wait_loaded(&mut h);
    let o = &h.state().objects[0].state;
    let shown = o.selected_quantity().map(|q| q.source);
    assert_eq!(shown, Some(Source::Wavefunction(Quantity::DifferenceDensity)), "{shown:?}");
    let dir = tempfile::tempdir().unwrap();
    let (red, blue) = red_and_blue(&picture(&mut h, dir.path(), "difference"));
    assert!(red > 200 && blue > 200, "gain and loss both drawn: {red} red, {blue} blue pixels");
    h.get_by_label("attachment").click();
    h.run_steps(3);
    wait_loaded(&mut h);
    let shown = h.state().objects[0].state.selected_quantity().map(|q| q.source);
    assert_eq!(shown, Some(Source::Wavefunction(Quantity::Attachment)));
    assert!(h.query_by_label_contains("1.001 electrons move").is_some(), "the electrons moved");
}

/// A TD log opened after its checkpoint gives the checkpoint's states their printed
/// transitions (the log writes the molecule turned: the same molecule, other coordinates), and
/// *hole | particle* shows the state's natural transition orbitals side by side in panes, each
/// captioned with its weight, while the file's list stays to pick the next state.
#[test]
fn a_td_log_joins_its_checkpoint_and_a_state_shows_hole_and_particle_in_panes() {
    let Some(corpus) = common::refdata("natural transition orbitals in the window") else { return };
    let (td, log) = (corpus.join("logs/basicGaussian09_dvb_td.fchk"), corpus.join("logs/basicGaussian09_dvb_td.out"));
    let mut h = open(vec![td, log]);
    wait_loaded(&mut h);
    assert_eq!(h.state().objects.len(), 1, "the log joined the checkpoint");
    let notice = h.state().notice.clone().unwrap_or_default();
    assert!(notice.contains("5 states' transitions"), "{notice}");
    h.get_by_label_contains("6.062").click();
    h.run_steps(2);
    h.get_by_label("hole | particle").click();
    h.run_steps(2);
    wait_loaded(&mut h);
    let app = h.state();
    assert_eq!(app.objects.len(), 2, "the state's NTOs are an object of their own");
    assert!(!app.objects[0].state.visible, "the file steps aside");
    assert_eq!(app.active, 0, "the file's list of states stays");
    assert_eq!(app.view.panes.count, 2);
    let ntos = &app.objects[1];
    let names: Vec<String> = ntos.state.quantities.iter().map(|q| q.source.name(&ntos.doc)).collect();
    assert_eq!(names, ["hole 1", "particle 1"]);
    assert_eq!(ntos.state.quantities.iter().map(|q| q.pane).collect::<Vec<_>>(), [Some(0), Some(1)]);
    // State 2 is one pair, nearly: 0.972 of its weight.
    let weight = ntos.doc.wavefunction.as_ref().unwrap().orbitals[0].occupation;
    assert!((weight - 0.972).abs() < 1e-3 && ntos.doc.title.starts_with("state 2"), "{weight} {}", ntos.doc.title);
    // Each pane shows its orbital's two lobes.
    for p in 0..2 {
        let picture = h.state().pane_picture(p).expect("the pane is drawn");
        let (red, blue) = red_and_blue(&picture);
        assert!(red > 150 && blue > 150, "pane {p}: {red} red, {blue} blue pixels");
    }
    // Another state's NTOs take their place.
    h.get_by_label_contains("5.629").click();
    h.run_steps(2);
    h.get_by_label("hole | particle").click();
    h.run_steps(2);
    wait_loaded(&mut h);
    assert_eq!(h.state().objects.len(), 2);
    assert!(h.state().objects[1].doc.source.ends_with("(state 1 NTOs)"), "{}", h.state().objects[1].doc.source);
    // The same amplitudes make the state's transition density, a quantity of the file.
    h.get_by_label("transition density").click();
    h.run_steps(3);
    wait_loaded(&mut h);
    let file = &h.state().objects[0];
    let shown = file.state.selected_quantity().map(|q| q.source);
    assert_eq!(shown, Some(Source::Wavefunction(Quantity::TransitionDensity(1))));
    assert!(file.state.visible, "the file shows it");
}

/// Pixels of `img` that are an NCI surface's blue-green (attraction): green and blue above red.
fn blue_green(img: &image::RgbaImage) -> usize {
    img.pixels().filter(|p| p[1] as i32 > p[0] as i32 + 40 && p[2] as i32 > p[0] as i32 + 40).count()
}

#[test]
fn a_structures_nci_surface_between_a_selection_and_the_rest_shows_its_hydrogen_bond() {
    let mut h = open(vec![fixture("nci/water_dimer.pdb")]);
    let dir = tempfile::tempdir().unwrap();
    let before = blue_green(&picture(&mut h, dir.path(), "atoms"));
    h.state_mut().nci_between = "resn LIG".into();
    h.get_by_label("NCI surface").click();
    h.run_steps(3);
    wait_loaded(&mut h);
    let q = h.state().objects[0].state.selected_quantity().expect("the NCI surface is selected").clone();
    assert_eq!(q.source, Source::Promolecular(Quantity::NciGradient));
    assert_eq!(q.fragments.selection.as_deref(), Some("resn LIG"));
    assert_eq!(q.isosurfaces[0].color_by, Some(Source::Promolecular(Quantity::SignLambda2Rho)));
    let disc = blue_green(&picture(&mut h, dir.path(), "nci"));
    eprintln!("blue-green pixels: {before} with the atoms, {disc} with the NCI surface");
    assert!(disc > 30 && disc > 5 * before.max(1), "the hydrogen bond's disc: {disc} pixels");
    // Its plot: the hydrogen bond's spike of low s at negative sign(λ₂)ρ.
    let start = std::time::Instant::now();
    while h.state().nci_plot.points.is_empty() {
        assert!(start.elapsed().as_secs() < 300, "no NCI plot: {:?}", h.state().nci_plot.error);
        std::thread::sleep(std::time::Duration::from_millis(50));
        h.run_steps(1);
    }
    let points = h.state().nci_plot.points.clone();
    let lowest = |range: std::ops::Range<f64>| {
        points.iter().filter(|p| range.contains(&p[0])).map(|p| p[1]).fold(f64::INFINITY, f64::min)
    };
    assert!(lowest(-0.05..-0.005) < 0.5, "lowest s at the hydrogen bond: {:.2}", lowest(-0.05..-0.005));
    // The same interaction as a cloud: blue (λ₂ < 0) between the molecules.
    let (_, blue_before) = red_and_blue(&picture(&mut h, dir.path(), "surface"));
    h.get_by_label("NCI cloud").click();
    h.run_steps(3);
    wait_loaded(&mut h);
    let q = h.state().objects[0].state.selected_quantity().unwrap().clone();
    assert_eq!(
        (q.source, q.fragments.selection.as_deref()),
        (Source::Promolecular(Quantity::NciCloud), Some("resn LIG"))
    );
    let (_, blue) = red_and_blue(&picture(&mut h, dir.path(), "cloud"));
    assert!(blue > 20 && blue > blue_before, "the cloud's blue pixels: {blue} (the surface's picture: {blue_before})");
}

#[test]
fn two_files_are_fragments_whose_nci_lies_between_them() {
    let mut h = open(vec![fixture("nci/water_donor_631gs.molden"), fixture("nci/water_acceptor_631gs.molden")]);
    assert_eq!((h.state().objects.len(), h.state().active), (2, 1));
    // Opened beside each other, as any two files.
    let placed = |h: &Harness<'static, OrbApp>| h.state().objects.iter().map(|o| o.state.placement).collect::<Vec<_>>();
    assert_ne!(placed(&h)[0], placed(&h)[1]);
    h.state_mut().objects[1].state.evaluation.grid_points = 48;
    h.get_by_label("NCI surface").click();
    h.run_steps(3);
    wait_loaded(&mut h);
    let dir = tempfile::tempdir().unwrap();
    let alone = blue_green(&picture(&mut h, dir.path(), "alone"));
    h.get_by_label("+ water_donor_631gs.molden").click();
    h.run_steps(3);
    wait_loaded(&mut h);
    let q = h.state().objects[1].state.selected_quantity().unwrap().clone();
    assert_eq!(q.source, Source::Wavefunction(Quantity::NciGradient));
    assert_eq!(q.fragments.files, vec![h.state().objects[0].doc.source.clone()]);
    assert!(q.fragments.between_only, "the first fragment keeps what lies between them");
    // The donor now stands where its file puts it beside the acceptor: both drawn as summed.
    assert_eq!(placed(&h)[0], placed(&h)[1]);
    let disc = blue_green(&picture(&mut h, dir.path(), "pair"));
    eprintln!("blue-green pixels: {alone} with the acceptor alone, {disc} with the donor added");
    assert!(disc > 30 && disc > 3 * alone.max(1), "the hydrogen bond's disc: {disc} pixels (alone {alone})");
}

#[test]
fn a_water_dimer_s_nci_surface_shows_its_hydrogen_bond_in_blue_green() {
    let mut h = open(vec![fixture("nci/water_dimer_631gs.molden")]);
    wait_loaded(&mut h);
    let dir = tempfile::tempdir().unwrap();
    let before = blue_green(&picture(&mut h, dir.path(), "homo"));
    // A coarser grid than the window's: the density's Hessian at every point is the cost.
    h.state_mut().objects[0].state.evaluation.grid_points = 48;
    h.get_by_label("NCI surface").click();
    h.run_steps(3);
    wait_loaded(&mut h);
    let o = &h.state().objects[0].state;
    let q = o.selected_quantity().expect("the NCI surface is selected");
    assert_eq!(q.source, Source::Wavefunction(Quantity::NciGradient));
    let iso = q.isosurfaces[0];
    assert_eq!((iso.color_by, iso.color_range), (Some(Wavefunction(Quantity::SignLambda2Rho)), Some(0.05)));
    assert!(o.quantities.iter().filter(|q| q.visible).count() == 1, "it takes the view");
    let shown = picture(&mut h, dir.path(), "nci");
    let disc = blue_green(&shown);
    eprintln!("blue-green pixels: {before} with the HOMO, {disc} with the NCI surface");
    assert!(disc > 30 && disc > 5 * before.max(1), "the hydrogen bond's disc: {disc} pixels (HOMO: {before})");

    // The NCI plot below the view: the hydrogen bond is the spike of low s at sign(λ₂)ρ ≈ −0.02.
    let start = std::time::Instant::now();
    while h.state().nci_plot.points.is_empty() {
        assert!(start.elapsed().as_secs() < 300, "no NCI plot: {:?}", h.state().nci_plot.error);
        std::thread::sleep(std::time::Duration::from_millis(50));
        h.run_steps(1);
    }
    h.run_steps(2);
    let points = h.state().nci_plot.points.clone();
    let lowest = |range: std::ops::Range<f64>| {
        points.iter().filter(|p| range.contains(&p[0])).map(|p| p[1]).fold(f64::INFINITY, f64::min)
    };
    let (bond, positive) = (lowest(-0.04..-0.01), lowest(0.01..0.04));
    assert!(
        bond < 0.6 && positive > bond + 0.2,
        "lowest s: {bond:.2} at the hydrogen bond, {positive:.2} on the positive side"
    );
    // A drag across the spike keeps the disc's colours; across the empty positive side, the
    // disc turns grey.
    let transform = h.state().nci_plot.transform.expect("the plot is drawn");
    let at = |x: f64| transform.position_from_point(&egui_plot::PlotPoint::new(x, 1.0));
    let window_of = |h: &mut Harness<'static, OrbApp>, from: f64, to: f64| {
        drag(h, at(from), at(to).x - at(from).x);
        wait_loaded(h);
        let iso = h.state().objects[0].state.selected_quantity().unwrap().isosurfaces[0];
        iso.color_window.expect("a drag sets the colour window")
    };
    // The pointer on the disc (between the donor's H and the acceptor's O) marks its point on
    // the plot, at the hydrogen bond's sign(λ₂)ρ.
    let atoms = &h.state().objects[0].doc.molecule.atoms;
    let (donor_h, acceptor) = (atoms[2].position.as_vec3(), atoms[3].position.as_vec3());
    let (from, to) = (h.state().on_screen(donor_h).unwrap(), h.state().on_screen(acceptor).unwrap());
    // Along the bond on screen until the pointer rests on the disc (seen nearly edge on).
    for k in 0..=40 {
        h.hover_at(from + (to - from) * (0.1 + 0.8 * k as f32 / 40.0));
        h.run_steps(2);
        if h.state().nci_plot.hovered.is_some() {
            break;
        }
    }
    assert!(h.state().nci_plot.hovered.is_some(), "no point of the disc marked under the pointer");
    let [x, s] = h.state().nci_plot.hovered.unwrap();
    assert!((-0.04..-0.01).contains(&x) && s < 1.0, "the disc's point: sign(λ₂)ρ {x:.4}, s {s:.2}");
    h.hover_at(egui::pos2(5.0, 400.0));
    h.run_steps(2);
    let [lo, hi] = window_of(&mut h, -0.04, -0.01);
    assert!((lo + 0.04).abs() < 0.004 && (hi + 0.01).abs() < 0.004, "[{lo}, {hi}]");
    let lit = blue_green(&picture(&mut h, dir.path(), "lit"));
    window_of(&mut h, 0.01, 0.04);
    let grey = picture(&mut h, dir.path(), "unlit");
    let unlit = blue_green(&grey);
    assert!(lit * 10 > disc * 8 && unlit * 10 < disc, "the disc {disc} px, lit {lit}, grey {unlit}");

    // The same interaction as a cloud: blue (λ₂ < 0).
    h.get_by_label("NCI cloud").click();
    h.run_steps(3);
    wait_loaded(&mut h);
    let shown = h.state().objects[0].state.selected_quantity().map(|q| q.source);
    assert_eq!(shown, Some(Source::Wavefunction(Quantity::NciCloud)));
    // Against the grey disc's picture, which has no blue.
    let (blue, blue0) = (red_and_blue(&picture(&mut h, dir.path(), "cloud")).1, red_and_blue(&grey).1);
    assert!(blue > blue0 + 20, "the cloud adds {} blue pixels", blue.saturating_sub(blue0));
}

#[test]
fn an_optimisation_log_plays_its_frames_with_their_energies_and_a_click_on_the_plot_picks_one() {
    let Some(corpus) = common::refdata("a log's frames in the window") else { return };
    let mut h = open(vec![corpus.join("logs/basicGaussian09_dvb_gopt.out")]);
    wait_loaded(&mut h);
    let shown = |h: &Harness<'static, OrbApp>| h.state().objects[0].doc.structure.as_ref().map(|s| s.model);
    assert_eq!(shown(&h), Some(0), "the optimisation's first step");
    let transform = h.state().models.energy_plot.expect("the frames' energies are plotted");
    // The fourth step, converged but for the last digits: a click on its point shows it.
    click_at(&mut h, transform.position_from_point(&egui_plot::PlotPoint::new(4.0, 0.0)), false);
    wait_loaded(&mut h);
    assert_eq!(shown(&h), Some(3), "the frame clicked on the plot");
    assert!(h.query_by_label_contains("step 4: E = -382.3082").is_some(), "its energy named");
}
