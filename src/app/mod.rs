//! The eframe viewer: the only module that uses egui and rfd.

pub mod detail;
pub mod jobs;
mod loader;
pub mod measure;
mod orbitals;
mod panels;
pub mod scan;
pub mod state;
pub mod viewport;

use std::path::PathBuf;
use std::sync::Arc;

use crate::gpu::{GpuContext, context::device_descriptor};
use crate::headless::WavefunctionView;
use crate::headless::default_camera;
use crate::model::Document;
use loader::LoadJob;
use scan::{ScanFailure, ScanJob, ScanSource, ScanView};
pub use state::{OrbitalView, ViewState};
use viewport::Viewport;

/// Opens the window on `files` (the bundled demo when empty) and runs until it closes.
pub fn run(files: Vec<PathBuf>) -> eframe::Result<()> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("orbcloud")
            .with_inner_size([1280.0, 800.0])
            .with_drag_and_drop(true),
        wgpu_options: egui_wgpu::WgpuConfiguration { wgpu_setup: wgpu_setup(false), ..Default::default() },
        ..Default::default()
    };
    eframe::run_native("orbcloud", options, Box::new(|cc| Ok(Box::new(OrbApp::new(cc, files)))))
}

/// The window's device: the renderer's features and the adapter's limits. `lavapipe` picks
/// the Vulkan CPU adapter (tests).
pub fn wgpu_setup(lavapipe: bool) -> egui_wgpu::WgpuSetup {
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    setup.device_descriptor = Arc::new(device_descriptor);
    if lavapipe {
        setup.instance_descriptor.backends = wgpu::Backends::VULKAN;
        setup.native_adapter_selector = Some(Arc::new(|adapters, _surface| {
            adapters
                .iter()
                .find(|a| a.get_info().device_type == wgpu::DeviceType::Cpu)
                .cloned()
                .ok_or_else(|| "no Vulkan CPU adapter (install mesa-vulkan-drivers libvulkan1)".to_owned())
        }));
    }
    egui_wgpu::WgpuSetup::CreateNew(setup)
}

pub struct OrbApp {
    pub doc: Document,
    pub view: ViewState,
    /// The orbital browser's choices (documents with a wavefunction).
    pub orbitals: OrbitalView,
    scroll_to_frontier: bool,
    viewport: Option<Viewport>,
    job: Option<LoadJob>,
    /// Files given on the command line or dropped, waiting to be loaded one after another.
    queue: Vec<PathBuf>,
    pub error: Option<String>,
    pub status: String,
    /// An open dihedral scan (shown instead of `doc`), and one being prepared.
    pub scan: Option<ScanView>,
    scan_job: Option<ScanJob>,
    /// Points along the longest side of a scan's common grid.
    pub scan_points: usize,
    /// Memory allowed for a scan's key volumes (bytes); `None`: derived from the device.
    pub scan_budget: Option<u64>,
    /// A scan that did not fit the GPU's memory, and the grid that would.
    pub scan_retry: Option<(ScanSource, usize)>,
    /// Picked atoms and measurements between them.
    pub measurements: measure::Measurements,
}

impl OrbApp {
    /// Opens `files`, or with none the bundled PSB3 scan.
    pub fn new(cc: &eframe::CreationContext<'_>, files: Vec<PathBuf>) -> Self {
        let demo = files.is_empty();
        let mut app = Self::empty(cc, files);
        if demo {
            app.open_scan(ScanSource::Demo, &cc.egui_ctx);
        }
        app
    }

    /// Opens the bundled formaldehyde cube (a single volume, no scan).
    pub fn cube_demo(cc: &eframe::CreationContext<'_>) -> Self {
        let mut app = Self::empty(cc, Vec::new());
        match crate::demo::document() {
            Ok(doc) => app.show_document(doc),
            Err(e) => app.error = Some(e.to_string()),
        }
        app
    }

    fn empty(cc: &eframe::CreationContext<'_>, files: Vec<PathBuf>) -> Self {
        let viewport = cc
            .wgpu_render_state
            .as_ref()
            .map(|rs| Viewport::new(GpuContext::from_parts(rs.adapter.clone(), rs.device.clone(), rs.queue.clone())));
        let mut app = Self {
            doc: Document::default(),
            view: ViewState::default(),
            orbitals: OrbitalView::default(),
            scroll_to_frontier: false,
            viewport,
            job: None,
            queue: files.into_iter().rev().collect(),
            error: None,
            status: String::new(),
            scan: None,
            scan_job: None,
            scan_points: crate::headless::scan::DEFAULT_SCAN_POINTS,
            scan_retry: None,
            scan_budget: None,
            measurements: measure::Measurements::default(),
        };
        if app.viewport.is_none() {
            app.error = Some("no wgpu render state: the viewer needs eframe's wgpu backend".into());
        }
        app
    }

    /// The σ of the grid shown (what isosurface levels in σ refer to) and whether its values
    /// are signed (an orbital: two surfaces).
    pub fn shown_grid(&self) -> (Option<f64>, bool) {
        let computed = self.viewport.as_ref().and_then(|vp| vp.computed_grid());
        match computed.or(self.doc.volumes.get(self.view.volume)) {
            Some(g) => (Some(g.stats.sigma), g.kind == crate::model::grid::ValueKind::Signed),
            None => (None, true),
        }
    }

    /// Where atom `atom` of the open document is drawn in the window (for tests and overlays).
    pub fn atom_on_screen(&self, atom: usize) -> Option<egui::Pos2> {
        let position = self.doc.molecule.atoms.get(atom)?.position.as_vec3();
        self.viewport.as_ref()?.to_screen(&self.view.camera, position)
    }

    /// What is under the resting pointer in the single-file view.
    pub fn hovered(&self) -> Option<crate::gpu::frame::PickId> {
        self.viewport.as_ref()?.hovered
    }

    /// Each view shown: (size on screen, size of its last frame), pixels. The frame is smaller
    /// while a drag or the animation runs on a CPU adapter ([`detail`]).
    pub fn view_sizes(&self) -> Vec<([u32; 2], [u32; 2])> {
        let views: Vec<&Viewport> = match &self.scan {
            Some(scan) => scan.views.iter().collect(),
            None => self.viewport.iter().collect(),
        };
        views.into_iter().filter_map(|v| v.size().zip(v.rendered_size())).collect()
    }

    /// A new handle on the window's device (for scan views and the key-volume job).
    fn gpu_context(&self) -> Option<GpuContext> {
        let c = &self.viewport.as_ref()?.ctx;
        Some(GpuContext::from_parts(c.adapter.clone(), c.device.clone(), c.queue.clone()))
    }

    /// Starts loading a file in the background (a `.scan.toml` opens as a scan); what is shown
    /// stays until it has loaded.
    pub fn open(&mut self, path: PathBuf, ctx: &egui::Context) {
        if path.to_string_lossy().to_ascii_lowercase().ends_with(".scan.toml") {
            self.open_scan(ScanSource::File(path), ctx);
            return;
        }
        let ctx = ctx.clone();
        self.job = Some(LoadJob::start(path, move || ctx.request_repaint()));
    }

    /// Loads a scan and makes its key volumes in the background, following orbitals as its
    /// manifest says.
    pub fn open_scan(&mut self, source: ScanSource, ctx: &egui::Context) {
        self.open_scan_following(source, None, ctx);
    }

    /// [`Self::open_scan`], following orbitals by `follow` when given.
    pub fn open_scan_following(
        &mut self,
        source: ScanSource,
        follow: Option<crate::model::scan::Follow>,
        ctx: &egui::Context,
    ) {
        let Some(gpu) = self.gpu_context() else { return };
        if let Some(job) = self.scan_job.take() {
            job.cancel();
        }
        let ctx = ctx.clone();
        let options = crate::headless::scan::KeyOptions {
            points: self.scan_points,
            budget: self.scan_budget,
            ..Default::default()
        };
        self.scan_job = Some(ScanJob::start(gpu, source, options, follow, move || ctx.request_repaint()));
    }

    pub fn is_loading(&self) -> bool {
        self.job.is_some() || !self.queue.is_empty() || self.scan_job.is_some()
    }

    fn show_document(&mut self, doc: Document) {
        let mut view = self.view;
        view.camera = default_camera(&doc);
        view.volume = 0;
        if let Some(vp) = &mut self.viewport
            && let Err(e) = vp.set_document(&doc, &view)
        {
            self.error = Some(format!("{}: {e}", doc.source));
            return;
        }
        self.status = format!("opened {}", doc.source);
        self.scan = None;
        self.orbitals = doc.wavefunction.as_ref().map(OrbitalView::for_wavefunction).unwrap_or_default();
        self.scroll_to_frontier = true;
        self.measurements = measure::Measurements::default();
        self.doc = doc;
        self.view = view;
        self.show_wavefunction();
    }

    /// Computes what the orbital browser asks for and hands it to the viewport.
    fn show_wavefunction(&mut self) {
        let Some(vp) = &mut self.viewport else { return };
        let ov = &self.orbitals;
        let view = WavefunctionView {
            quantity: ov.shown,
            direct: ov.direct,
            points: ov.grid_points,
            shells: ov.ao_filter.then_some(ov.shell_mask.as_slice()),
        };
        if let Err(e) = vp.show_wavefunction(&self.doc, &view, &self.view) {
            self.error = Some(e.to_string());
        }
    }

    fn poll_job(&mut self, ctx: &egui::Context) {
        if let Some(job) = &self.job
            && let Some(result) = job.poll()
        {
            self.job = None;
            match result {
                Ok(doc) => self.show_document(doc),
                Err(e) => self.error = Some(e.to_string()),
            }
        }
        if let Some(job) = &self.scan_job
            && let Some(result) = job.poll()
        {
            let (name, source) = (job.name.clone(), job.source.clone());
            self.scan_job = None;
            match result {
                Ok(scene) => {
                    // One device handle per view.
                    let contexts: Option<Vec<GpuContext>> = (0..scene.slots()).map(|_| self.gpu_context()).collect();
                    if let Some(contexts) = contexts {
                        let reopened = self.scan.take().filter(|old| old.source == source);
                        if reopened.is_none() {
                            self.view.camera = scene.camera();
                        }
                        self.status = format!(
                            "opened {name}: {} key volumes, {:.1} MiB of {:.0} MiB",
                            scene.slots() * scene.scan.frames.len(),
                            scene.bytes as f64 / 1048576.0,
                            scene.budget as f64 / 1048576.0
                        );
                        if !scene.tracks.swaps.is_empty() {
                            self.status += &format!(
                                "; {} orbital character swap(s) (see `orbcloud scan info`)",
                                scene.tracks.swaps.len()
                            );
                        }
                        let mut view = ScanView::new(scene, source, contexts);
                        if let Some(old) = &reopened {
                            view.keep_interaction_of(old);
                        }
                        self.scan = Some(view);
                    }
                }
                Err(ScanFailure::Cancelled) => self.status = format!("{name}: cancelled"),
                Err(ScanFailure::OverBudget { message, fits }) => {
                    self.error = Some(format!("{name}: {message}"));
                    self.scan_retry = Some((source, fits));
                }
                Err(ScanFailure::Other(e)) => self.error = Some(e),
            }
        }
        if self.job.is_none()
            && let Some(next) = self.queue.pop()
        {
            self.open(next, ctx);
        }
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw.dropped_files.iter().map(|f| f.path().to_path_buf()).filter(|p| !p.as_os_str().is_empty()).collect()
        });
        for path in dropped.into_iter().rev() {
            self.queue.push(path);
        }
    }

    /// Applies a change of the shown volume or atom style made in the panels.
    fn apply(&mut self, before: &ViewState) {
        let Some(vp) = &mut self.viewport else { return };
        if before.volume != self.view.volume {
            if let Err(e) = vp.set_volume(&self.doc, &self.view) {
                self.error = Some(e.to_string());
            }
        } else if before.settings.iso != self.view.settings.iso {
            let triangles = vp.update_isosurfaces(&self.doc, &self.view);
            if self.view.settings.iso.visible {
                self.status = format!("isosurfaces: {triangles} triangles");
            }
        }
        if before.settings.atoms != self.view.settings.atoms {
            vp.set_atom_style(&self.doc, &self.view);
            if let Some(scan) = &mut self.scan {
                scan::restyle(scan);
            }
        }
    }

    /// Saves the current view as a PNG: where the user chooses, or in the working directory
    /// when no file dialog is available.
    fn screenshot(&mut self) {
        let Some(vp) = &mut self.viewport else { return };
        let mut size = vp.size().unwrap_or([1280, 800]);
        if let Some(scan) = &self.scan {
            size = scan.views.first().and_then(|v| v.size()).unwrap_or([640, 600]);
        }
        let default_name = format!(
            "orbcloud-{}.png",
            std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0)
        );
        // Cancelling the dialog means no file: nothing is written anywhere.
        let Some(path) =
            rfd::FileDialog::new().add_filter("PNG image", &["png"]).set_file_name(&default_name).save_file()
        else {
            return;
        };
        let shot = match &mut self.scan {
            Some(scan) => {
                let mut out = image::RgbaImage::new(size[0] * scan.views.len() as u32, size[1]);
                let mut result = Ok(());
                for (n, v) in scan.views.iter_mut().enumerate() {
                    match v.snapshot(&self.view, size) {
                        Ok(img) => image::imageops::replace(&mut out, &img, (n as u32 * size[0]) as i64, 0),
                        Err(e) => result = Err(e),
                    }
                }
                result.map(|()| out)
            }
            None => vp.snapshot(&self.view, size),
        };
        match shot.map(|img| img.save(&path)) {
            Ok(Ok(())) => self.status = format!("saved {}", path.display()),
            Ok(Err(e)) => self.error = Some(format!("{}: {e}", path.display())),
            Err(e) => self.error = Some(e.to_string()),
        }
    }
}

impl eframe::App for OrbApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.poll_job(&ctx);
        let before = self.view;
        let action = panels::top_bar(ui, self);
        panels::status_bar(ui, self);
        panels::side_panel(ui, self);
        let orbitals_before = self.orbitals.clone();
        orbitals::panel(ui, &self.doc, &mut self.orbitals, &mut self.scroll_to_frontier);
        if self.orbitals != orbitals_before {
            self.show_wavefunction();
        }
        self.apply(&before);
        match action {
            panels::Action::Open => {
                if let Some(path) = rfd::FileDialog::new()
                    .add_filter(
                        "Cube, Molden, fchk, scan",
                        &["cube", "cub", "molden", "mold", "fchk", "fch", "toml", "gz"],
                    )
                    .pick_file()
                {
                    self.open(path, &ctx);
                } else {
                    self.status = "no file chosen (open files from the command line or drop them on the window)".into();
                }
            }
            panels::Action::Screenshot => self.screenshot(),
            panels::Action::ResetView => {
                self.view.camera = match &self.scan {
                    Some(scan) => scan.scene.camera(),
                    None => default_camera(&self.doc),
                }
            }
            panels::Action::None => {}
        }
        panels::error_window(ui, self);
        let refollow = self.scan.as_mut().and_then(|scan| scan::controls(ui, scan).map(|f| (scan.source.clone(), f)));
        if let Some((source, follow)) = refollow {
            self.open_scan_following(source, Some(follow), &ctx);
        }
        egui::CentralPanel::no_frame().show(ui, |ui| {
            let Some(rs) = frame.wgpu_render_state() else { return };
            match (&mut self.scan, &mut self.viewport) {
                (Some(scan), _) => scan::views(ui, rs, scan, &mut self.view),
                (None, Some(vp)) => {
                    vp.detail =
                        detail::Detail::for_frame(detail::interacting(ui.ctx(), false), vp.ctx.info.device_type, 1);
                    vp.show(ui, rs, &mut self.view);
                    if let Some(click) = vp.click.take() {
                        let said = self.measurements.click(click, &self.doc.molecule);
                        if !said.is_empty() {
                            self.status = said;
                        }
                    }
                    measure::overlay(ui, vp, &self.view.camera, &self.doc.molecule, &self.measurements);
                }
                (None, None) => {}
            }
        });
        if self.is_loading() {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
    }
}
