//! The window computes (egui_kittest on lavapipe, PySCF in the Python `ORBCLOUD_PYTHON` names,
//! which `scripts/test` sets up): *Scan this…* on a measured dihedral runs a scan whose frames
//! open while the rest are still being computed.

mod common;
#[path = "common/viewer.rs"]
mod viewer_support;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use orbcloud::app::{OrbApp, wgpu_setup};
use orbcloud::model::measure::Measurement;
use viewer_support::wait_loaded;

const H2O2: &str = "4
hydrogen peroxide
O 0.000000 0.727000 -0.060000
O 0.000000 -0.727000 -0.060000
H 0.839000 0.880000 0.480000
H -0.839000 -0.880000 0.480000
";

/// The viewer at 1280×800 on hydrogen peroxide's geometry (an XYZ file in `dir`).
fn h2o2(dir: &std::path::Path) -> Harness<'static, OrbApp> {
    require_pyscf();
    let xyz = dir.join("h2o2.xyz");
    std::fs::write(&xyz, H2O2).unwrap();
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(move |cc| OrbApp::new(cc, vec![xyz]));
    wait_loaded(&mut h);
    h
}

/// Fails at once, saying what to install, when the computing Python lacks PySCF.
fn require_pyscf() {
    let python = orbcloud::sources::compute::python();
    let ok =
        std::process::Command::new(&python).args(["-c", "import pyscf"]).output().is_ok_and(|o| o.status.success());
    assert!(ok, "`{python}` cannot import pyscf: run scripts/test (it sets ORBCLOUD_PYTHON) or pip install pyscf");
}

#[test]
fn scan_this_on_a_measured_dihedral_computes_a_scan_whose_frames_open_while_it_runs() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = h2o2(dir.path());
    // The H–O–O–H dihedral measured (picking itself is tested in tests/viewer.rs).
    h.state_mut().measurements.list.push(Measurement::new(&[2, 0, 1, 3]).unwrap());
    h.run_steps(2);
    h.get_by_label("Scan this…").click();
    h.run_steps(2);
    let dialog = &h.state().scan_dialog;
    assert!(dialog.open, "the Scan window opened");
    assert!((dialog.now.abs() - 115.0).abs() < 15.0, "the measured dihedral: {}", dialog.now);
    assert!(dialog.folder.starts_with(&dir.path().display().to_string()), "beside the file: {}", dialog.folder);
    // Seven values at B3LYP/6-31G* (about half a second each), one after another.
    let d = &mut h.state_mut().scan_dialog;
    (d.from, d.to, d.step, d.workers) = (60.0, 180.0, 20.0, 1);
    h.run_steps(1);
    h.get_by_label("Compute").click();
    let mut seen_while_running = Vec::new();
    wait_computed(&mut h, |ended, frames| {
        if !ended && frames > 0 {
            seen_while_running.push(frames);
        }
    });
    let app = h.state();
    let run = app.computing.as_ref().unwrap();
    assert_eq!(run.done.len(), 7, "{}", run.progress);
    assert!(
        !seen_while_running.is_empty() && seen_while_running.iter().all(|&n| n < 7),
        "frames opened while the rest were computed: {seen_while_running:?}"
    );
    let scan = &app.scan().unwrap().scene.scan;
    assert_eq!(scan.values(), vec![60.0, 80.0, 100.0, 120.0, 140.0, 160.0, 180.0]);
    assert_eq!(scan.coordinate.label(), "dihedral 3-1-2-4");
    assert!(run.progress.starts_with("computed: 7 of 7"), "{}", run.progress);
}

#[test]
fn a_structure_without_orbitals_computes_them_and_opens_them_in_its_place() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = h2o2(dir.path());
    assert!(h.state().objects[0].doc.wavefunction.is_none());
    h.get_by_label("Compute orbitals…").click();
    h.run_steps(2);
    let settings = &mut h.state_mut().orbitals_dialog.as_mut().expect("the Compute orbitals window").1;
    (settings.method, settings.basis) = ("hf".into(), "sto-3g".into());
    h.run_steps(1);
    h.get_by_label("Compute").click();
    let start = std::time::Instant::now();
    while h.state().objects.first().is_none_or(|o| o.doc.wavefunction.is_none()) || h.state().is_loading() {
        assert!(start.elapsed().as_secs() < 120, "no orbitals: {}", h.state().status);
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
    let app = h.state();
    assert_eq!(app.objects.len(), 1, "the computed wavefunction takes the structure's place");
    let doc = &app.objects[0].doc;
    assert!(doc.source.ends_with("h2o2_HF_STO-3G.molden"), "{}", doc.source);
    assert!(std::path::Path::new(&doc.source).starts_with(dir.path()), "beside the file: {}", doc.source);
    assert_eq!(doc.wavefunction.as_ref().unwrap().orbitals.len(), 12, "RHF/STO-3G of H2O2: 12 orbitals");
}

/// A Gaussian relaxed scan's log (scripts/make_scan_log_fixtures.py) offers *Compute orbitals for
/// these frames…*: its own five geometries are computed and open as a scan of the dihedral the
/// job scanned, at the values measured in them.
#[test]
fn a_scan_jobs_frames_compute_into_a_scan_of_its_coordinate() {
    require_pyscf();
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("h2o2_scan.log");
    let fixture = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/logs/h2o2_scan.log");
    std::fs::copy(fixture, &log).unwrap();
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(move |cc| OrbApp::new(cc, vec![log]));
    wait_loaded(&mut h);
    assert!(h.state().models.energy_plot.is_some(), "the frames' energies are plotted");
    h.get_by_label("Compute orbitals for these frames…").click();
    h.run_steps(2);
    let dialog = &h.state().scan_dialog;
    assert!(dialog.open && dialog.job, "the Scan window for the job's frames");
    assert_eq!(dialog.coordinate.label(), "dihedral 3-1-2-4");
    assert!((dialog.from - 120.0).abs() < 1e-3 && (dialog.to - 360.0).abs() < 1e-3, "{dialog:?}");
    let d = &mut h.state_mut().scan_dialog;
    (d.settings.method, d.settings.basis, d.workers) = ("hf".into(), "sto-3g".into(), 2);
    h.run_steps(1);
    h.get_by_label("Compute").click();
    wait_computed(&mut h, |_, _| {});
    let app = h.state();
    let scan = &app.scan().unwrap().scene.scan;
    assert_eq!(scan.coordinate.label(), "dihedral 3-1-2-4");
    let values = scan.values();
    assert_eq!(values.len(), 5);
    for (v, e) in values.iter().zip([120.0, 180.0, 240.0, 300.0, 360.0]) {
        assert!((v - e).abs() < 1e-3, "{values:?}");
    }
    let manifest = dir.path().join("h2o2_scan_frames/h2o2_scan.scan.toml");
    let loaded = orbcloud::formats::scan::load_scan(&manifest).unwrap();
    assert!(loaded.computed.is_some_and(|c| c.relaxed), "the frames are the job's relaxed geometries");
}

/// Steps the window until the computation under way has ended and the open scan shows every
/// frame it made (failing on a failed computation or after five minutes); `watch` sees each
/// step's (ended, frames the scan shows).
fn wait_computed(h: &mut Harness<'static, OrbApp>, mut watch: impl FnMut(bool, usize)) {
    let start = std::time::Instant::now();
    loop {
        assert!(start.elapsed().as_secs() < 300, "the scan did not finish: {}", h.state().status);
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
        let app = h.state();
        let run = app.computing.as_ref().expect("a computation");
        assert!(!run.progress.starts_with("computing failed"), "{}", run.progress);
        let frames = app.scan().map_or(0, |s| s.scene.scan.frames.len());
        watch(run.ended, frames);
        if run.ended && run.shown == run.done.len() && !app.is_loading() && frames == run.done.len() {
            return;
        }
    }
}
