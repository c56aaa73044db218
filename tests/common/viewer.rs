//! Shared by the viewer's tests (egui_kittest on lavapipe): waiting for files and jobs, and
//! clicking in the view.
#![allow(dead_code, reason = "each test binary uses some of these helpers")]

use egui_kittest::Harness;
use orbcloud::app::{OrbApp, wgpu_setup};

/// The viewer on its bundled cube demo at 1000×700, on lavapipe.
pub fn harness() -> Harness<'static, OrbApp> {
    let h = Harness::builder()
        .with_size([1000.0, 700.0])
        .wgpu_setup(wgpu_setup(true))
        .build_eframe(|cc| OrbApp::cube_demo(cc));
    assert!(h.state().error.is_none(), "viewer failed to start: {:?}", h.state().error);
    h
}

/// Steps the app until nothing is loading (failing after a minute).
pub fn wait_loaded(h: &mut Harness<'static, OrbApp>) {
    let start = std::time::Instant::now();
    h.run_steps(1);
    while h.state().is_loading() {
        assert!(start.elapsed().as_secs() < 60, "still loading after a minute");
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
    h.run_steps(2);
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
}

/// A primary click at `pos`, with Shift held when `shift`.
pub fn click_at(h: &mut Harness<'static, OrbApp>, pos: egui::Pos2, shift: bool) {
    let modifiers = if shift { egui::Modifiers::SHIFT } else { egui::Modifiers::NONE };
    h.event(egui::Event::ModifiersChanged(modifiers));
    h.hover_at(pos);
    let button = |pressed| egui::Event::PointerButton { pos, button: egui::PointerButton::Primary, pressed, modifiers };
    h.event(button(true));
    h.run_steps(1);
    h.event(button(false));
    h.run_steps(1);
    // The pick waits for its row of a picture drawn in bands, which a busy machine draws over
    // many frames.
    let start = std::time::Instant::now();
    while h.state().is_picking() {
        assert!(start.elapsed().as_secs() < 60, "the click was not picked after a minute");
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.run_steps(1);
}

/// Rests the pointer at `pos` until what lies under it has been read from a whole picture.
pub fn hover(h: &mut Harness<'static, OrbApp>, pos: egui::Pos2) {
    h.hover_at(pos);
    h.run_steps(1);
    let start = std::time::Instant::now();
    while h.state().frame_progress().is_some() {
        assert!(start.elapsed().as_secs() < 60, "the picture is still being drawn after a minute");
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
    h.run_steps(1);
}
