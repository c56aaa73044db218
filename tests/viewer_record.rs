//! *Record…* in the viewer (egui_kittest on lavapipe): a movie records in the background while
//! the window keeps answering, can be cancelled, and when left to finish writes every frame.

mod common;
#[path = "common/viewer.rs"]
mod viewer_support;

use viewer_support::harness;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use orbcloud::app::OrbApp;

/// Steps the window until `done` holds (failing after `seconds`).
fn step_until(h: &mut Harness<'static, OrbApp>, seconds: u64, what: &str, done: impl Fn(&OrbApp) -> bool) {
    let start = std::time::Instant::now();
    while !done(h.state()) {
        assert!(start.elapsed().as_secs() < seconds, "{what} not after {seconds} s");
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
}

#[test]
fn record_starts_and_cancels_while_the_window_answers() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness();
    viewer_support::wait_loaded(&mut h);
    h.get_by_label("Record…").click();
    h.run_steps(2);
    assert!(h.state().record.open, "the Record window opens");
    assert!(h.state().record.output.ends_with("_turntable.gif"), "{}", h.state().record.output);
    // A long turntable, so that it is still under way when cancelled.
    let frames = dir.path().join("long/");
    {
        let d = &mut h.state_mut().record;
        d.frames = 400;
        d.size = [96, 72];
        d.output = frames.display().to_string();
    }
    h.run_steps(1);
    h.get_by_label("Start").click();
    h.run_steps(1);
    assert!(h.state().recording.is_some(), "recording: {:?}", h.state().error);
    step_until(&mut h, 60, "a first frame", |app| app.recording.as_ref().is_some_and(|r| r.counts().0 >= 2));
    // The window answers while frames render: a control changes what it shows.
    let before = h.state().view.background;
    h.state_mut().view.background = [0.3, 0.3, 0.3];
    h.run_steps(2);
    assert_ne!(h.state().view.background, before);
    assert!(h.state().recording.is_some(), "still recording");
    assert!(h.query_all_by_label_contains("recording ").count() >= 1, "the status line shows the recording");
    h.get_by_label("Cancel").click();
    step_until(&mut h, 60, "the recording to stop", |app| app.recording.is_none());
    let status = h.state().status.clone();
    assert!(status.contains("cancelled"), "{status}");
    let written = std::fs::read_dir(&frames).unwrap().count();
    assert!((2..400).contains(&written), "{written} frames were written before the cancel");
    assert!(h.state().error.is_none(), "{:?}", h.state().error);

    // Left to finish, a short GIF holds every frame.
    let gif_path = dir.path().join("turn.gif");
    {
        let d = &mut h.state_mut().record;
        d.open = true;
        d.frames = 6;
        d.output = gif_path.display().to_string();
    }
    h.run_steps(1);
    h.get_by_label("Start").click();
    h.run_steps(1);
    assert!(h.state().recording.is_some(), "recording again: {:?}", h.state().error);
    step_until(&mut h, 120, "the recording to finish", |app| app.recording.is_none());
    assert!(h.state().status.starts_with("wrote"), "{}", h.state().status);
    let mut decoder = gif::DecodeOptions::new().read_info(std::fs::File::open(&gif_path).unwrap()).unwrap();
    let mut n = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        n += 1;
    }
    assert_eq!(n, 6);
}

/// A scan is recorded as any object is: *Record…* proposes its sweep, and the movie holds its
/// views side by side; *Play* moves its value.
#[test]
fn a_scan_plays_and_records_its_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = Harness::builder()
        .with_size([1100.0, 720.0])
        .wgpu_setup(orbcloud::app::wgpu_setup(true))
        .build_eframe(|cc| OrbApp::new(cc, Vec::new()));
    step_until(&mut h, 300, "the scan", |app| app.scan().is_some());
    h.run_steps(2);
    let start = h.state().scan().unwrap().value;
    h.get_by_label("Play").click();
    step_until(&mut h, 60, "the value to move", |app| app.scan().is_some_and(|s| s.value != start));
    h.get_by_label("Pause").click();
    h.run_steps(1);
    h.get_by_label("Record…").click();
    h.run_steps(2);
    assert!(h.state().record.output.ends_with("_sweep.gif"), "{}", h.state().record.output);
    let gif_path = dir.path().join("sweep.gif");
    {
        let d = &mut h.state_mut().record;
        d.frames = 4;
        d.size = [64, 48];
        d.output = gif_path.display().to_string();
    }
    h.run_steps(1);
    h.get_by_label("Start").click();
    h.run_steps(1);
    assert!(h.state().recording.is_some(), "recording: {:?}", h.state().error);
    step_until(&mut h, 180, "the sweep to finish", |app| app.recording.is_none());
    assert!(h.state().status.starts_with("wrote"), "{}", h.state().status);
    let mut decoder = gif::DecodeOptions::new().read_info(std::fs::File::open(&gif_path).unwrap()).unwrap();
    assert_eq!((decoder.width(), decoder.height()), (128, 48), "HOMO and LUMO side by side");
    let mut n = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        n += 1;
    }
    assert_eq!(n, 4);
}

#[test]
fn save_png_writes_any_size_supersampled_and_transparent() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness();
    viewer_support::wait_loaded(&mut h);
    h.get_by_label("Save PNG").click();
    h.run_steps(2);
    assert!(h.state().picture.open, "the Save PNG window opens");
    assert_eq!(h.state().picture.size, h.state().view_sizes().first().map(|(s, _)| *s), "at the view's size");
    {
        let d = &mut h.state_mut().picture;
        d.size = Some([200, 150]);
        d.scale = 2;
        d.transparent = true;
    }
    let path = dir.path().join("figure.png");
    h.state_mut().save_png(&path);
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
    let img = image::open(&path).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (200, 150));
    assert_eq!(img.get_pixel(0, 0).0[3], 0, "the background is transparent");
    assert!(img.pixels().any(|p| p.0[3] == 255), "the molecule is opaque");
}
