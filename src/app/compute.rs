//! *Scan this…* (a measured distance, angle or dihedral scanned with PySCF), *Compute orbitals
//! for these frames…* (a scan job's own frames, each a single point at its geometry) and
//! *Compute orbitals* (a structure's wavefunction): computations of [`crate::sources::compute`] run in the
//! background from the window. A scan's frames open as they finish: the manifest of the frames
//! done so far is written and opened again whenever more are done, so the slider's range grows
//! while the rest are computed.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;

use crate::formats::scan::Computed;
use crate::model::Document;
use crate::model::scan::{Coordinate, PathMeasure};
use crate::sources::compute::{self, Event, FrameJob, Held, Job, Settings};

/// The choices of the *Scan* window: plain data.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanDialog {
    pub open: bool,
    /// The object scanned and its coordinate (atoms of that object, 0-based).
    pub object: usize,
    pub coordinate: Coordinate,
    /// The coordinate's value in the object's geometry.
    pub now: f64,
    pub from: f64,
    pub to: f64,
    pub step: f64,
    pub settings: Settings,
    /// Cores to compute on.
    pub workers: usize,
    /// A Dask scheduler's address (empty: this machine).
    pub dask: String,
    /// Where the frames and the manifest go.
    pub folder: String,
    /// The frames are the object's own (a scan job's, [`Document::job_scan`]), each computed
    /// at its geometry: no range, no geometry to choose.
    pub job: bool,
}

impl Default for ScanDialog {
    fn default() -> Self {
        Self {
            open: false,
            object: 0,
            coordinate: Coordinate::Path(PathMeasure::ArcLength),
            now: 0.0,
            from: 0.0,
            to: 0.0,
            step: 1.0,
            settings: Settings::default(),
            workers: compute::cores(),
            dask: String::new(),
            folder: String::new(),
            job: false,
        }
    }
}

/// The folder of `source` when it is a file (a demo or a document made in memory is not): what
/// is computed from a file goes beside it; else into the temporary folder.
pub fn beside(source: &Path) -> PathBuf {
    let file = std::fs::canonicalize(source).ok().filter(|p| p.is_file());
    file.and_then(|p| p.parent().map(Path::to_path_buf)).unwrap_or_else(std::env::temp_dir)
}

impl ScanDialog {
    /// The window for `coordinate` of object `object` (document `doc`), with a range around
    /// its value: a dihedral's full turn from −180° in 30° steps, ±30° of an angle in 10°
    /// steps, a bond from 0.3 Å shorter to 0.9 Å longer in 0.2 Å steps.
    pub fn for_coordinate(object: usize, coordinate: Coordinate, doc: &Document) -> Self {
        let now = coordinate.measure(&doc.molecule).unwrap_or(0.0);
        let round = |v: f64, to: f64| (v / to).round() * to;
        let (from, to, step) = match coordinate {
            Coordinate::Dihedral(_) => (-180.0, 180.0, 30.0),
            Coordinate::Angle(_) => ((round(now, 1.0) - 30.0).max(1.0), (round(now, 1.0) + 30.0).min(179.0), 10.0),
            _ => ((round(now, 0.01) - 0.3).max(0.3), round(now, 0.01) + 0.9, 0.2),
        };
        let source = Path::new(&doc.source);
        let name = format!(
            "{}_{}{}",
            compute::stem(source),
            coordinate.kind(),
            coordinate.atoms().iter().map(|a| (a + 1).to_string()).collect::<Vec<_>>().join("-")
        );
        let folder = beside(source).join(name);
        Self {
            open: true,
            object,
            coordinate,
            now,
            from,
            to,
            step,
            folder: folder.display().to_string(),
            ..Self::default()
        }
    }
}

impl ScanDialog {
    /// The window for the frames of a scan job object `object` holds (a Gaussian or ORCA relaxed
    /// scan's log): its coordinate, the range its frames cover, the folder beside the file.
    pub fn for_job(object: usize, doc: &Document) -> Self {
        let Some(job) = &doc.job_scan else { return Self::default() };
        let (from, to) =
            job.values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        let source = Path::new(&doc.source);
        let folder = beside(source).join(format!("{}_frames", compute::stem(source)));
        Self {
            open: true,
            object,
            coordinate: job.coordinate,
            now: doc.structure.as_ref().and_then(|v| job.values.get(v.model).copied()).unwrap_or(from),
            from,
            to,
            step: 0.0,
            folder: folder.display().to_string(),
            job: true,
            ..Self::default()
        }
    }
}

/// What a computation is for.
enum Purpose {
    /// A scan: its manifest's folder and title, coordinate, settings and input file.
    Scan { folder: PathBuf, title: String, coordinate: Coordinate, settings: Settings, input: String },
    /// One wavefunction, opened when written.
    Orbitals { output: PathBuf },
}

/// A computation under way (or just ended) in the background.
pub struct ComputeRun {
    purpose: Purpose,
    cancel: Arc<AtomicBool>,
    events: mpsc::Receiver<Result<Event, String>>,
    pub total: usize,
    /// Frames done (file, value), and those that failed (value, why).
    pub done: Vec<(String, f64)>,
    pub failed: Vec<(f64, String)>,
    versions: std::collections::BTreeMap<String, String>,
    /// What the status line says of it.
    pub progress: String,
    /// Ended (finished, failed or cancelled).
    pub ended: bool,
    /// How many frames the scan last opened had, and how many times frames were opened while
    /// the rest were still being computed.
    pub shown: usize,
    pub opened_while_running: usize,
    /// The progress last put in the status line.
    pub announced: String,
}

/// What a poll asks the window to do.
pub enum Opened {
    Nothing,
    /// Open this manifest (the frames done so far) as a scan.
    Scan(PathBuf),
    /// Open this wavefunction.
    File(PathBuf),
}

impl ComputeRun {
    fn start(job: Job, purpose: Purpose, repaint: impl Fn() + Send + 'static) -> Self {
        let cancel = Arc::new(AtomicBool::new(false));
        let (send, events) = mpsc::channel();
        let total = job.frames.len();
        let stop = cancel.clone();
        std::thread::spawn(move || {
            let result = compute::run(&job, &stop, &mut |e| {
                let _ = send.send(Ok(e.clone()));
                repaint();
            });
            if let Err(e) = result {
                let _ = send.send(Err(e.to_string()));
            }
            repaint();
        });
        Self {
            purpose,
            cancel,
            events,
            total,
            done: Vec::new(),
            failed: Vec::new(),
            versions: Default::default(),
            progress: format!("computing: 0 of {total} frames"),
            ended: false,
            shown: 0,
            opened_while_running: 0,
            announced: String::new(),
        }
    }

    /// Starts the scan `dialog` asks for on `doc`'s geometry.
    pub fn scan(dialog: &ScanDialog, doc: &Document, repaint: impl Fn() + Send + 'static) -> Result<Self, String> {
        let source = Path::new(&doc.source);
        let title = compute::stem(source);
        let (frames, start) = if dialog.job {
            let job = compute::job_scan_frames(doc, &title).ok_or("the object holds no scan job's frames")?;
            (job?.1, 0)
        } else {
            let values = compute::values(dialog.from, dialog.to, dialog.step)?;
            compute::rigid_scan(&doc.molecule, &dialog.coordinate, &values, &title).map_err(|e| e.to_string())?
        };
        // A scan job's frames are its relaxed geometries, each computed as a single point: the
        // manifest's record says what the frames are.
        let recorded = Settings { relaxed: dialog.settings.relaxed || dialog.job, ..dialog.settings.clone() };
        let settings = Settings { relaxed: dialog.settings.relaxed && !dialog.job, ..dialog.settings.clone() };
        let folder = PathBuf::from(dialog.folder.trim());
        let job = Job {
            settings,
            coordinate: Held::of(&dialog.coordinate),
            start,
            dir: folder.clone(),
            output: Some(folder.join("compute-output.txt")),
            workers: dialog.workers.max(1),
            dask: Some(dialog.dask.trim().to_string()).filter(|a| !a.is_empty()),
            frames,
        };
        let purpose = Purpose::Scan {
            folder,
            title,
            coordinate: dialog.coordinate,
            settings: recorded,
            input: doc.source.clone(),
        };
        Ok(Self::start(job, purpose, repaint))
    }

    /// Computes `doc`'s wavefunction with `settings` into `output`.
    pub fn orbitals(doc: &Document, settings: Settings, output: PathBuf, repaint: impl Fn() + Send + 'static) -> Self {
        let dir = output.parent().map(Path::to_path_buf).unwrap_or_default();
        let file = output.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
        let job = Job {
            settings,
            coordinate: None,
            start: 0,
            dir,
            output: None,
            workers: compute::cores(),
            dask: None,
            frames: vec![FrameJob::new(file, 0.0, &doc.molecule)],
        };
        Self::start(job, Purpose::Orbitals { output }, repaint)
    }

    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Takes the events that came; `loading` says whether a scan is still being opened (a
    /// newer manifest then waits for it). Returns what to open.
    pub fn poll(&mut self, loading: bool) -> Opened {
        while let Ok(event) = self.events.try_recv() {
            match event {
                Ok(Event::Start { versions, .. }) => self.versions = versions,
                Ok(Event::Frame(r)) if r.ok => self.done.push((r.file, r.at)),
                Ok(Event::Frame(r)) => self.failed.push((r.at, r.error.unwrap_or_default())),
                Ok(Event::Done { .. }) => self.ended = true,
                Ok(Event::Error { message }) | Err(message) => {
                    self.ended = true;
                    self.progress = format!("computing failed: {message}");
                    return Opened::Nothing;
                }
            }
        }
        let (done, total) = (self.done.len(), self.total);
        let failed = if self.failed.is_empty() { String::new() } else { format!(", {} failed", self.failed.len()) };
        self.progress = if self.ended {
            format!("computed: {done} of {total} frames{failed}")
        } else {
            format!("computing: {done} of {total} frames{failed}")
        };
        match &self.purpose {
            Purpose::Orbitals { output } if self.ended && done == 1 && self.shown == 0 => {
                self.shown = 1;
                Opened::File(output.clone())
            }
            Purpose::Scan { folder, title, coordinate, settings, input }
                if done >= 2 && done != self.shown && !loading =>
            {
                let failed = self.failed.iter().map(|f| f.0).collect();
                let computed = Computed::of(settings, input, self.versions.clone(), failed);
                match compute::write_manifest(folder, title, coordinate, settings, &self.done, computed) {
                    Ok(path) => {
                        self.shown = done;
                        if !self.ended {
                            self.opened_while_running += 1;
                        }
                        Opened::Scan(path)
                    }
                    Err(e) => {
                        self.progress = format!("computing: {e}");
                        Opened::Nothing
                    }
                }
            }
            _ => Opened::Nothing,
        }
    }

    /// The failures to tell, each with its value.
    pub fn failures(&self) -> Vec<String> {
        let c = match &self.purpose {
            Purpose::Scan { coordinate, .. } => Some(coordinate),
            Purpose::Orbitals { .. } => None,
        };
        self.failed
            .iter()
            .map(|(at, why)| match c {
                Some(c) => format!("{}: {why}", c.value_text(*at)),
                None => why.clone(),
            })
            .collect()
    }
}

/// The *Scan* window: range, level of theory, where it runs; *Compute* or, while it runs,
/// progress and *Cancel*. Returns whether *Compute* and whether *Cancel* were pressed.
pub fn scan_window(ctx: &egui::Context, dialog: &mut ScanDialog, run: Option<&ComputeRun>) -> (bool, bool) {
    if !dialog.open {
        return (false, false);
    }
    let (mut start, mut cancel) = (false, false);
    let mut open = true;
    let unit = dialog.coordinate.unit().trim().to_string();
    // At the window's right, over the view's corner rather than the panels.
    let corner = egui::pos2(ctx.content_rect().right() - 390.0, 40.0);
    let window = egui::Window::new("Scan").open(&mut open).collapsible(true).resizable(false).default_pos(corner);
    window.show(ctx, |ui| {
        ui.label(format!("{} = {}", dialog.coordinate.label(), dialog.coordinate.value_text(dialog.now)));
        egui::Grid::new("scan range").num_columns(2).show(ui, |ui| {
            if dialog.job {
                // The job's own frames: their values and geometries are given.
                ui.label("frames");
                ui.label(format!(
                    "the job's, {} to {}",
                    dialog.coordinate.value_text(dialog.from),
                    dialog.coordinate.value_text(dialog.to)
                ));
                ui.end_row();
            } else {
                for (label, value) in [("from", &mut dialog.from), ("to", &mut dialog.to), ("step", &mut dialog.step)] {
                    ui.label(label);
                    ui.add(egui::DragValue::new(value).speed(0.1).suffix(format!(" {unit}")));
                    ui.end_row();
                }
                ui.label("geometry");
                ui.horizontal(|ui| {
                    ui.radio_value(&mut dialog.settings.relaxed, false, "rigid");
                    ui.radio_value(&mut dialog.settings.relaxed, true, "relaxed");
                });
                ui.end_row();
            }
            ui.label("method");
            ui.text_edit_singleline(&mut dialog.settings.method);
            ui.end_row();
            ui.label("basis");
            ui.text_edit_singleline(&mut dialog.settings.basis);
            ui.end_row();
            ui.label("");
            ui.horizontal(|ui| {
                if ui.button("B3LYP/6-31G*").on_hover_text("the default").clicked() {
                    (dialog.settings.method, dialog.settings.basis) = ("b3lyp".into(), "6-31g*".into());
                }
                if ui.button("quick look: HF/STO-3G").clicked() {
                    (dialog.settings.method, dialog.settings.basis) = ("hf".into(), "sto-3g".into());
                }
            });
            ui.end_row();
            ui.label("charge, 2S");
            ui.horizontal(|ui| {
                ui.add(egui::DragValue::new(&mut dialog.settings.charge).range(-20..=20));
                ui.add(egui::DragValue::new(&mut dialog.settings.spin).range(0..=20));
            });
            ui.end_row();
            ui.label("cores");
            ui.add(egui::DragValue::new(&mut dialog.workers).range(1..=1024));
            ui.end_row();
            ui.label("Dask scheduler");
            ui.add(egui::TextEdit::singleline(&mut dialog.dask).hint_text("tcp://host:8786 (none: this machine)"));
            ui.end_row();
            ui.label("folder");
            ui.text_edit_singleline(&mut dialog.folder);
            ui.end_row();
        });
        let frames = match dialog.job {
            true => Ok(Vec::new()),
            false => compute::values(dialog.from, dialog.to, dialog.step),
        };
        match (run, &frames) {
            (Some(r), _) if !r.ended => {
                ui.label(&r.progress);
                ui.add(egui::ProgressBar::new(r.done.len() as f32 / r.total.max(1) as f32));
                if ui.button("Cancel").clicked() {
                    cancel = true;
                }
            }
            (_, Ok(values)) => {
                if let Some(r) = run {
                    ui.label(&r.progress);
                    for f in r.failures() {
                        ui.label(egui::RichText::new(format!("left out: {f}")).small());
                    }
                }
                if dialog.job {
                    ui.label(format!("each frame's geometry, {}", dialog.settings.level()));
                } else {
                    ui.label(format!("{} frames, {}", values.len(), dialog.settings.level()));
                }
                if ui.button("Compute").clicked() {
                    start = true;
                }
            }
            (_, Err(e)) => {
                ui.colored_label(ui.visuals().warn_fg_color, e);
            }
        }
    });
    dialog.open &= open;
    (start, cancel)
}

/// The *Compute orbitals* window of a structure: method, basis, charge and spin. Returns
/// whether *Compute* was pressed.
pub fn orbitals_window(ctx: &egui::Context, settings: &mut Settings) -> bool {
    let mut start = false;
    egui::Window::new("Compute orbitals").collapsible(false).resizable(false).show(ctx, |ui| {
        egui::Grid::new("orbitals level").num_columns(2).show(ui, |ui| {
            ui.label("method");
            ui.text_edit_singleline(&mut settings.method);
            ui.end_row();
            ui.label("basis");
            ui.text_edit_singleline(&mut settings.basis);
            ui.end_row();
            ui.label("charge, 2S");
            ui.horizontal(|ui| {
                ui.add(egui::DragValue::new(&mut settings.charge).range(-20..=20));
                ui.add(egui::DragValue::new(&mut settings.spin).range(0..=20));
            });
            ui.end_row();
        });
        ui.label(egui::RichText::new("PySCF, on this machine's cores").small().weak());
        start = ui.button("Compute").clicked();
    });
    start
}
