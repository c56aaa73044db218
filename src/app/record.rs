//! *Record…*: a movie of what the window shows (a scan's coordinate swept, the scene turning,
//! the active object's vibration), drawn in the background on a target of its own while the
//! window stays live, with its progress and *Cancel* in the status line.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::Ordering;

use egui::RichText;

use super::OrbApp;
use super::jobs::{Pending, spawn};
use crate::pictures::figure::Figure;
use crate::pictures::movie::{MovieFormat, MovieWriter, sweep};
use crate::pictures::shots::{Motion, Progress, ScanShots, SceneShots, ShotError, record};

/// What a recording shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordWhat {
    /// The open scan's coordinate over its range.
    Sweep,
    /// The scene turning a full circle.
    Turntable,
    /// One period of the active object's vibration.
    Vibration,
}

/// The choices of the *Record…* window.
pub struct RecordDialog {
    pub open: bool,
    pub what: RecordWhat,
    pub frames: usize,
    pub fps: f64,
    /// Each view's size.
    pub size: [u32; 2],
    /// A scan's sweep there and back.
    pub bounce: bool,
    /// Supersampling factor.
    pub scale: u32,
    pub output: String,
}

impl Default for RecordDialog {
    fn default() -> Self {
        Self {
            open: false,
            what: RecordWhat::Turntable,
            frames: 36,
            fps: 12.0,
            size: [640, 480],
            bounce: false,
            scale: 1,
            output: String::new(),
        }
    }
}

/// A recording under way.
pub struct Recording {
    pub path: PathBuf,
    pub progress: Arc<Progress>,
    result: Pending<Result<PathBuf, String>>,
}

impl Recording {
    /// Frames written so far, of how many.
    pub fn counts(&self) -> (usize, usize) {
        (self.progress.done.load(Ordering::Relaxed), self.progress.total.load(Ordering::Relaxed))
    }

    pub fn cancel(&self) {
        self.progress.cancel.store(true, Ordering::Relaxed);
    }
}

/// A name for the movie from what is shown: `psb3_sweep.gif`, `benzene_turntable.gif`.
fn proposed_name(source: &str, what: RecordWhat) -> String {
    let stem = super::picture::file_stem(source);
    let what = match what {
        RecordWhat::Sweep => "sweep",
        RecordWhat::Turntable => "turntable",
        RecordWhat::Vibration => "vibration",
    };
    format!("{stem}_{what}.gif")
}

impl OrbApp {
    /// Opens the *Record…* window with choices fitting what is shown.
    pub fn open_record_dialog(&mut self) {
        let vibrating = self.objects.get(self.active).is_some_and(|o| o.state.vibration.mode.is_some());
        let what = match (self.scan_object(), vibrating) {
            (Some(_), _) => RecordWhat::Sweep,
            (None, true) => RecordWhat::Vibration,
            (None, false) => RecordWhat::Turntable,
        };
        let source = match self.scan_object().and_then(|o| o.scan.as_ref()).map(|s| &s.source) {
            Some(super::scan::ScanSource::File(path)) => path.display().to_string(),
            Some(super::scan::ScanSource::Demo) => "psb3".into(),
            None => self.doc().source.clone(),
        };
        let dir = self.last_folder.clone().unwrap_or_else(|| std::env::current_dir().unwrap_or_default());
        let d = &mut self.record;
        d.open = true;
        d.what = what;
        if d.output.is_empty() {
            d.output = dir.join(proposed_name(&source, what)).display().to_string();
        }
    }

    /// Starts the recording the dialog describes, in the background.
    pub fn start_recording(&mut self, egui_ctx: &egui::Context) {
        if self.recording.is_some() {
            return;
        }
        let d = &self.record;
        let path = PathBuf::from(d.output.trim());
        if let Err(e) = MovieFormat::of(&path).and_then(|f| f.check(&path)) {
            self.error = Some(e.to_string());
            return;
        }
        let Some(ctx) = self.viewport.as_ref().map(|v| v.ctx.clone()) else { return };
        let figure = Figure { scale: d.scale.clamp(1, crate::pictures::figure::MAX_SCALE), transparent: false };
        let (frames, fps, size) = (d.frames.clamp(1, 10_000), d.fps, d.size.map(|s| s.clamp(16, 4096)));
        let progress = Arc::new(Progress::default());
        let job_progress = progress.clone();
        let out = path.clone();
        let waker = egui_ctx.clone();
        let repaint = move || waker.request_repaint();
        let scan = self.scan_object().and_then(|o| Some((o, o.scan.as_ref()?, o.state.scan.as_ref()?)));
        let work: Box<dyn FnOnce() -> Result<PathBuf, ShotError> + Send> = match (d.what, scan) {
            (RecordWhat::Sweep, Some((object, scan, state))) => {
                let scene = scan.keys.clone();
                let (lo, hi) = scene.scan.range();
                let values = sweep(lo, hi, frames, d.bounce);
                // Every view drawn as the first is (the views of a sweep share their settings).
                let settings = object.state.render_settings(0, self.view.background);
                let (camera, mode) = (self.view.camera, state.mode);
                let views = scene.slots() as u32;
                Box::new(move || {
                    let mut shots = ScanShots::new(&ctx, scene, values, camera, settings, mode, figure, size);
                    let writer = MovieWriter::create(&out, [size[0] * views, size[1]], fps, shots.values.len())?;
                    let count = shots.values.len();
                    record(writer, count, &job_progress, |k| Ok(shots.at(&ctx, shots.values[k])?))
                })
            }
            (RecordWhat::Sweep, None) => {
                self.error = Some("a sweep records an open scan's coordinate: open a scan first".into());
                return;
            }
            (what, _) => {
                let motion = match what {
                    RecordWhat::Vibration => {
                        let Some(object) = self.objects.get(self.active) else { return };
                        let Some(mode) = object.state.vibration.mode else {
                            self.error = Some("choose a normal mode in the Vibrations panel first".into());
                            return;
                        };
                        Motion::Vibration { mode, amplitude: object.state.vibration.amplitude as f64 }
                    }
                    _ => Motion::Turntable,
                };
                // A vibration moves the scene's first object: the active one goes first.
                let first = matches!(motion, Motion::Vibration { .. }).then_some(self.active);
                let order = first.into_iter().chain((0..self.objects.len()).filter(|&i| Some(i) != first));
                let scene: Vec<_> = (order.map(|i| &self.objects[i]).filter(|o| o.state.visible))
                    .map(|o| (o.doc.clone(), o.state.clone()))
                    .collect();
                let (camera, background) = (self.view.camera, self.view.background);
                let arrows = self.objects.get(self.active).is_some_and(|o| o.state.vibration.arrows);
                let points = self.objects.get(self.active).map_or(64, |o| o.state.evaluation.grid_points);
                Box::new(move || {
                    let mut shots =
                        SceneShots::new(&ctx, scene, camera, background, motion, frames, figure, size, points)?;
                    if arrows {
                        shots.show_arrows(&ctx);
                    }
                    let writer = MovieWriter::create(&out, size, fps, shots.len())?;
                    let count = shots.len();
                    record(writer, count, &job_progress, |k| Ok(shots.frame(&ctx, k)?))
                })
            }
        };
        let result = spawn("recording", move || work().map_err(|e| e.to_string()), repaint);
        if let Some(dir) = path.parent() {
            self.last_folder = Some(dir.to_path_buf());
        }
        self.status = format!("recording {}", path.display());
        self.recording = Some(Recording { path, progress, result });
        self.record.open = false;
    }

    /// Takes a finished recording's outcome into the status line.
    pub fn poll_recording(&mut self) {
        let Some(rec) = &self.recording else { return };
        let Some(outcome) = rec.result.poll() else { return };
        let (done, _) = rec.counts();
        self.status = match outcome.and_then(|r| r) {
            Ok(path) => format!("wrote {} ({done} frames)", path.display()),
            Err(e) if e.starts_with("cancelled") => format!("recording {e}: {}", rec.path.display()),
            Err(e) => {
                self.error = Some(format!("recording {}: {e}", rec.path.display()));
                String::new()
            }
        };
        self.recording = None;
    }
}

/// The *Record…* window.
pub fn record_window(ctx: &egui::Context, app: &mut OrbApp) {
    if !app.record.open {
        return;
    }
    let mut open = true;
    let mut start = false;
    let has_scan = app.scan_object().is_some();
    let has_modes = app.objects.get(app.active).is_some_and(|o| o.doc.vibrations.is_some());
    egui::Window::new("Record").open(&mut open).resizable(false).show(ctx, |ui| {
        let d = &mut app.record;
        ui.horizontal(|ui| {
            ui.add_enabled_ui(has_scan, |ui| ui.radio_value(&mut d.what, RecordWhat::Sweep, "sweep the scan"));
            ui.radio_value(&mut d.what, RecordWhat::Turntable, "turntable");
            ui.add_enabled_ui(has_modes, |ui| ui.radio_value(&mut d.what, RecordWhat::Vibration, "vibration"));
        });
        egui::Grid::new("record options").num_columns(2).show(ui, |ui| {
            ui.label("frames");
            ui.add(egui::DragValue::new(&mut d.frames).range(2..=2000));
            ui.end_row();
            ui.label("frames per second");
            ui.add(egui::DragValue::new(&mut d.fps).range(1.0..=60.0));
            ui.end_row();
            ui.label(if has_scan { "each view" } else { "size" });
            ui.horizontal(|ui| {
                ui.add(egui::DragValue::new(&mut d.size[0]).range(16..=4096));
                ui.label("×");
                ui.add(egui::DragValue::new(&mut d.size[1]).range(16..=4096));
            });
            ui.end_row();
            ui.label("supersampling");
            ui.add(egui::DragValue::new(&mut d.scale).range(1..=crate::pictures::figure::MAX_SCALE).suffix("×"));
            ui.end_row();
            if d.what == RecordWhat::Sweep {
                ui.label("");
                ui.checkbox(&mut d.bounce, "there and back");
                ui.end_row();
            }
            ui.label("file");
            ui.add(egui::TextEdit::singleline(&mut d.output).desired_width(280.0));
            ui.end_row();
        });
        ui.label(RichText::new(".gif, .apng, a folder/ of PNG frames; .mp4 and .webm through ffmpeg").weak().small());
        start = ui.button("Start").clicked();
    });
    app.record.open &= open;
    if start {
        app.start_recording(ctx);
    }
}

/// The recording's progress bar and *Cancel* in the status line.
pub fn record_status(ui: &mut egui::Ui, app: &OrbApp) {
    let Some(rec) = &app.recording else { return };
    let (done, total) = rec.counts();
    let f = if total == 0 { 0.0 } else { done as f32 / total as f32 };
    ui.add(egui::ProgressBar::new(f).desired_width(160.0).text(format!("recording {done}/{total}")));
    ui.label(rec.path.display().to_string());
    if ui.button("Cancel").on_hover_text("stop recording; the frames written so far stay").clicked() {
        rec.cancel();
    }
    ui.separator();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_come_from_the_file_and_the_motion() {
        assert_eq!(proposed_name("/data/benzene.molden", RecordWhat::Turntable), "benzene_turntable.gif");
        assert_eq!(proposed_name("psb3.scan.toml", RecordWhat::Sweep), "psb3_sweep.gif");
        assert_eq!(proposed_name("", RecordWhat::Vibration), "orbcloud_vibration.gif");
    }
}
