//! The eframe viewer: the only module that uses egui and rfd.

pub mod compute;
mod correlation;
pub mod detail;
mod difference;
mod excited;
pub mod files;
pub mod jobs;
mod joining;
pub mod legend;
mod loader;
pub mod measure;
pub mod models;
pub mod nci_plot;
mod orbitals;
mod panels;
pub mod panes;
pub mod picture;
pub mod plane_pane;
pub mod progressive;
pub mod record;
pub mod restart;
pub mod scan;
mod scene_panel;
pub mod session;
pub mod state;
pub mod vibrations;
pub mod viewport;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::gpu::{GpuContext, context::device_descriptor};
use crate::model::{Atom, Document, Molecule};
use crate::scene::framing::default_camera;
use crate::scene::{ObjectState, RenderSettings, ViewPreset};
use loader::LoadJob;
use scan::{ObjectScan, ScanFailure, ScanJob, ScanSource};
pub use state::ViewState;
use viewport::Viewport;

/// A bundled demo the viewer can open.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Demo {
    /// The PSB3 twist scan (Naka et al., docs/references.md): what the viewer opens with no file.
    Scan,
    /// Formaldehyde's HOMO as a cube.
    Cube,
    /// Butadiene's HOMO meeting SO₂'s LUMO, translucent (Koide and Miyata, docs/references.md).
    Cycloaddition,
}

impl Demo {
    pub const ALL: [Demo; 3] = [Demo::Scan, Demo::Cube, Demo::Cycloaddition];

    pub fn label(self) -> &'static str {
        match self {
            Demo::Scan => "PSB3 twist (dihedral scan)",
            Demo::Cube => "formaldehyde HOMO (cube)",
            Demo::Cycloaddition => "diene HOMO + SO₂ LUMO (translucent)",
        }
    }
}

/// Opens the window on `files` (with none, `demo`, or the bundled scan) and runs until it
/// closes. When the GPU device is lost, the window closes and a new one opens on a new device
/// with the scene as it was ([`restart`]). `ORBCLOUD_SIMULATE_DEVICE_LOSS=SECONDS` rehearses
/// that: the first window reports its device lost after that long.
pub fn run(files: Vec<PathBuf>, demo: Option<Demo>) -> eframe::Result<()> {
    let slot: restart::CarrySlot = Arc::default();
    let rehearse = std::env::var("ORBCLOUD_SIMULATE_DEVICE_LOSS").ok().and_then(|s| s.parse::<f64>().ok());
    let mut first = Some((files, demo));
    loop {
        let options = eframe::NativeOptions {
            viewport: egui::ViewportBuilder::default()
                .with_title("orbcloud")
                .with_inner_size([1280.0, 800.0])
                .with_drag_and_drop(true),
            wgpu_options: egui_wgpu::WgpuConfiguration { wgpu_setup: wgpu_setup(false), ..Default::default() },
            // Returns when the window closes, so that another can open after a lost device.
            run_and_return: true,
            ..Default::default()
        };
        let carried = slot.lock().unwrap_or_else(std::sync::PoisonError::into_inner).take();
        let opening = first.take();
        let next = slot.clone();
        eframe::run_native(
            "orbcloud",
            options,
            Box::new(move |cc| {
                let mut app = match (carried, opening) {
                    (Some(carried), _) => OrbApp::resume(cc, carried),
                    (None, Some((files, Some(demo)))) if files.is_empty() => {
                        let mut app = OrbApp::empty(cc, Vec::new());
                        app.open_demo(demo, &cc.egui_ctx);
                        app.rehearse_device_loss(rehearse);
                        app
                    }
                    (None, opening) => {
                        let mut app = OrbApp::new(cc, opening.map(|(files, _)| files).unwrap_or_default());
                        app.rehearse_device_loss(rehearse);
                        app
                    }
                };
                if let Some(path) = session::last_session_path() {
                    app.keep_session_in(path);
                }
                app.restart_into(next);
                Ok(Box::new(app))
            }),
        )?;
        if slot.lock().unwrap_or_else(std::sync::PoisonError::into_inner).is_none() {
            return Ok(());
        }
    }
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

/// One object of the scene: a document and what the user set for it.
pub struct SceneObject {
    /// Shared with the background jobs that evaluate and cut it.
    pub doc: Arc<Document>,
    /// The one source of truth for what the object shows: the panels edit it in place.
    pub state: ObjectState,
    /// How many of its atoms its selection shows (counted when the selection or the model
    /// changes, not every frame).
    pub shown_atoms: usize,
    /// The scan it is a frame of (its key volumes), when it is one.
    pub scan: Option<ObjectScan>,
}

impl SceneObject {
    fn count_shown_atoms(&mut self) {
        let mask = crate::scene::selection::shown_atoms(&self.doc, &self.state.selection);
        self.shown_atoms = mask.map_or(self.doc.molecule.atoms.len(), |m| m.iter().filter(|&&s| s).count());
    }
}

/// A change to the scene's list of objects, asked for in a panel and made after the frame's
/// edits are applied (so the states compared before and after are those of the same objects).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SceneEdit {
    Select(usize),
    Remove(usize),
}

/// How a file being loaded joins the scene.
#[derive(Debug, Clone, PartialEq)]
pub enum Opening {
    /// Added beside what is open.
    Add,
    /// Replaces every object.
    Replace,
    /// Restored from a session, as it was saved.
    Restore(Box<ObjectState>),
}

/// Text sizes readable at 1280×800 (egui's defaults make small print of 9 points).
fn readable_text(ctx: &egui::Context) {
    use egui::{FontFamily, FontId, TextStyle};
    ctx.all_styles_mut(|style| {
        for (text_style, size) in [
            (TextStyle::Small, 11.0),
            (TextStyle::Body, 13.5),
            (TextStyle::Button, 13.5),
            (TextStyle::Monospace, 12.5),
            (TextStyle::Heading, 18.0),
        ] {
            let family =
                if text_style == TextStyle::Monospace { FontFamily::Monospace } else { FontFamily::Proportional };
            style.text_styles.insert(text_style, FontId::new(size, family));
        }
    });
}

/// How a lost GPU device is reported.
const DEVICE_LOST: &str = "the GPU device was lost";

/// Recent files kept.
const RECENT_FILES: usize = 10;

pub struct OrbApp {
    /// The scene: every open file, in the order opened (object `n` is the renderer's layer `n`).
    pub objects: Vec<SceneObject>,
    /// The object the side panel and the orbital browser edit.
    pub active: usize,
    /// The camera, the background and the labels: what is the scene's, not an object's.
    pub view: ViewState,
    /// What a newly opened object starts with (kept between runs).
    pub defaults: RenderSettings,
    /// Changes to the list of objects asked for this frame ([`SceneEdit`]).
    pub pending: Vec<SceneEdit>,
    /// Each object's state as the GPU shows it: what the next frame's edits are compared with
    /// ([`Self::apply_changes`]), wherever they came from (a panel, a test, a script).
    applied: Vec<ObjectState>,
    /// Where the IR spectrum was last drawn (tests click its peaks); its x is the negated
    /// wavenumber (wavenumbers fall from left to right).
    pub spectrum: Option<egui_plot::PlotTransform>,
    /// Where the UV-vis spectrum was last drawn (tests click its bands); its x is eV.
    pub uv_vis: Option<egui_plot::PlotTransform>,
    /// A session's measurements, kept until its files have loaded.
    restoring_measurements: Option<Vec<crate::model::measure::Measurement>>,
    /// A session's scan being opened: its object as it was saved, and the measurements.
    restoring_scan: Option<(ObjectState, Vec<crate::model::measure::Measurement>)>,
    /// Whether *Open…* and dropped files replace the scene instead of adding to it.
    pub open_replaces: bool,
    scroll_to_frontier: bool,
    viewport: Option<Viewport>,
    job: Option<(LoadJob, Opening)>,
    /// Files given on the command line, dropped or named by a session, waiting to be loaded one
    /// after another (last first).
    queue: Vec<(PathBuf, Opening)>,
    pub error: Option<String>,
    pub status: String,
    /// A scan being prepared (it opens as an object, in place of the scene).
    scan_job: Option<ScanJob>,
    /// A quantity minus another file's being made ([`difference`]).
    difference: Option<difference::DifferenceJob>,
    /// Points along the longest side of a scan's common grid.
    pub scan_points: usize,
    /// Memory allowed for a scan's key volumes (bytes); `None`: derived from the device.
    pub scan_budget: Option<u64>,
    /// A scan that did not fit the GPU's memory, and the grid that would.
    pub scan_retry: Option<(ScanSource, usize)>,
    /// Picked atoms and measurements between them; atoms are numbered through the scene
    /// ([`Self::world`]).
    pub measurements: measure::Measurements,
    /// Which model of a multi-model structure is shown, and whether they play in turn.
    pub models: models::Player,
    /// Every object's atoms where they are placed, one numbering through the scene.
    world: World,
    /// Where the session is saved between runs (`None`: not kept, as in tests).
    pub last_session: Option<PathBuf>,
    /// GPU errors outside any error scope, reported by the device's handler.
    gpu_errors: Arc<std::sync::Mutex<Vec<String>>>,
    /// Whether to ask the system's file dialog first (cleared once it turns out there is none).
    pub native_dialogs: bool,
    /// The in-window file chooser, when open.
    pub browser: Option<files::FileBrowser>,
    /// Files opened recently, newest first (kept with the last session).
    pub recent: Vec<PathBuf>,
    /// Where the scene goes when the device is lost, for the next window ([`restart`]).
    restart: Option<restart::CarrySlot>,
    /// When a rehearsed device loss is reported.
    rehearsal: Option<std::time::Instant>,
    /// A message that stays in the status line until dismissed (the scene came back on a new
    /// device).
    pub notice: Option<String>,
    /// The *Scan* window's choices (*Scan this…* on a measurement), and the computation under
    /// way (a scan, or a structure's orbitals).
    pub scan_dialog: compute::ScanDialog,
    /// The plane map beside the view.
    pub plane: plane_pane::PlanePane,
    /// The NCI plot below the view, while an NCI surface is the selected quantity.
    pub nci_plot: nci_plot::NciPlot,
    /// The selection a structure's NCI surface is asked between (and the rest); empty: all atoms.
    pub nci_between: String,
    pub computing: Option<compute::ComputeRun>,
    /// The *Compute orbitals* window: the object and the level of theory.
    pub orbitals_dialog: Option<(usize, crate::sources::compute::Settings)>,
    /// The *Record…* window's choices, and the recording under way.
    pub record: record::RecordDialog,
    /// The *Save PNG* window's choices.
    pub picture: picture::PictureDialog,
    pub recording: Option<record::Recording>,
    /// The folder a picture or movie was last saved in.
    pub last_folder: Option<PathBuf>,
}

/// The scene's atoms in world space, numbered object after object: what measurements index.
#[derive(Debug, Clone, Default)]
pub struct World {
    pub molecule: Molecule,
    /// Index of each object's first atom.
    pub offsets: Vec<usize>,
    /// Each object's document, for what a file says of an atom (residue, chain, B-factor).
    pub docs: Vec<Arc<Document>>,
}

impl World {
    fn of(objects: &[SceneObject]) -> Self {
        let mut world = Self::default();
        for o in objects {
            world.offsets.push(world.molecule.atoms.len());
            world.docs.push(o.doc.clone());
            let m = o.state.placement.world_from_object().as_dmat4();
            world.molecule.atoms.extend(
                o.doc.molecule.atoms.iter().map(|a| Atom { position: m.transform_point3(a.position), ..a.clone() }),
            );
        }
        world
    }

    /// One molecule as the whole scene (a scan's skeleton at the value).
    pub fn single(molecule: Molecule) -> Self {
        Self { molecule, offsets: vec![0], docs: Vec::new() }
    }

    /// What object `object`'s file says of its atom `index` beyond element and position:
    /// "A ALA 42 CA · B 12.3 · occupancy 0.50", `None` for files without residues.
    pub fn annotation(&self, object: usize, index: usize) -> Option<String> {
        let view = self.docs.get(object)?.structure.as_ref()?;
        let i = *view.atoms.get(index)? as usize;
        let s = &view.structure;
        if s.residues.get(s.residue[i] as usize)?.name.as_str().is_empty() {
            return None; // an XYZ frame: nothing beyond the element
        }
        Some(format!("{} · B {:.1} · occupancy {:.2}", s.describe(i), s.b_factor[i], s.occupancy[i]))
    }

    /// The scene-wide number of atom `index` of object `object`.
    pub fn atom(&self, object: usize, index: usize) -> Option<usize> {
        Some(self.offsets.get(object)? + index).filter(|&i| i < self.molecule.atoms.len())
    }
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
        app.open_demo(Demo::Cube, &cc.egui_ctx);
        app
    }

    /// Opens a bundled demo in place of the scene.
    pub fn open_demo(&mut self, demo: Demo, ctx: &egui::Context) {
        match demo {
            Demo::Scan => self.open_scan(ScanSource::Demo, ctx),
            Demo::Cube => match crate::sources::demo::document() {
                Ok(doc) => self.add_object(doc, Opening::Replace),
                Err(e) => self.error = Some(e.to_string()),
            },
            Demo::Cycloaddition => match crate::sources::demo::cycloaddition() {
                Ok(scene) => {
                    self.clear_scene();
                    for (doc, state) in scene {
                        self.add_object(doc, Opening::Restore(Box::new(state)));
                    }
                    self.view.camera = self.framing_camera();
                    let (yaw, pitch) = crate::sources::demo::CYCLOADDITION_VIEW;
                    self.view.camera.orbit(yaw, pitch);
                    self.status = format!("opened {}", crate::sources::demo::CYCLOADDITION_NAME);
                }
                Err(e) => self.error = Some(e.to_string()),
            },
        }
    }

    fn empty(cc: &eframe::CreationContext<'_>, files: Vec<PathBuf>) -> Self {
        readable_text(&cc.egui_ctx);
        let viewport = cc
            .wgpu_render_state
            .as_ref()
            .map(|rs| Viewport::new(GpuContext::from_parts(rs.adapter.clone(), rs.device.clone(), rs.queue.clone())))
            .map(|mut vp| {
                vp.set_repaint(cc.egui_ctx.clone());
                vp
            });
        // An error no scope caught (wgpu's default is to panic) is shown, and the viewer goes on.
        let gpu_errors: Arc<std::sync::Mutex<Vec<String>>> = Arc::default();
        if let Some(vp) = &viewport {
            let (errors, repaint) = (gpu_errors.clone(), cc.egui_ctx.clone());
            vp.ctx.device.on_uncaptured_error(Arc::new(move |e| {
                log::error!("GPU: {e}");
                errors.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push(e.to_string());
                repaint.request_repaint();
            }));
            // A lost device: the scene moves to a new window on a new device (`restart`).
            let (errors, repaint) = (gpu_errors.clone(), cc.egui_ctx.clone());
            vp.ctx.device.set_device_lost_callback(move |reason, message| {
                if reason != wgpu::DeviceLostReason::Destroyed {
                    errors
                        .lock()
                        .unwrap_or_else(std::sync::PoisonError::into_inner)
                        .push(format!("{DEVICE_LOST} ({message})"));
                    repaint.request_repaint();
                }
            });
        }
        let mut app = Self {
            objects: Vec::new(),
            active: 0,
            view: ViewState::default(),
            defaults: RenderSettings::default(),
            pending: Vec::new(),
            applied: Vec::new(),
            restoring_measurements: None,
            restoring_scan: None,
            spectrum: None,
            uv_vis: None,
            open_replaces: false,
            scroll_to_frontier: false,
            viewport,
            job: None,
            queue: files.into_iter().rev().map(|p| (p, Opening::Add)).collect(),
            error: None,
            status: String::new(),
            scan_job: None,
            difference: None,
            scan_points: crate::layers::key_volumes::DEFAULT_SCAN_POINTS,
            scan_retry: None,
            scan_budget: None,
            measurements: measure::Measurements::default(),
            models: models::Player::default(),
            world: World::default(),
            last_session: None,
            gpu_errors,
            native_dialogs: true,
            browser: None,
            recent: Vec::new(),
            restart: None,
            rehearsal: None,
            notice: None,
            scan_dialog: compute::ScanDialog::default(),
            plane: {
                let repaint = cc.egui_ctx.clone();
                plane_pane::PlanePane::new(move || repaint.request_repaint())
            },
            nci_between: String::new(),
            nci_plot: {
                let repaint = cc.egui_ctx.clone();
                nci_plot::NciPlot::new(move || repaint.request_repaint())
            },
            computing: None,
            orbitals_dialog: None,
            record: record::RecordDialog::default(),
            picture: picture::PictureDialog::default(),
            recording: None,
            last_folder: None,
        };
        if app.viewport.is_none() {
            app.error = Some("no wgpu render state: the viewer needs eframe's wgpu backend".into());
        }
        app
    }

    /// The active object's document (an empty one when the scene is empty).
    pub fn doc(&self) -> &Document {
        static EMPTY: std::sync::LazyLock<Document> = std::sync::LazyLock::new(Document::default);
        self.objects.get(self.active).map_or(&EMPTY, |o| &o.doc)
    }

    /// Every object's atoms where they are placed (what measurements and picks number).
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The values the active object's selected quantity shows, once they are there.
    pub fn shown_values(&self) -> Option<&crate::model::VolumeGrid> {
        let o = self.objects.get(self.active)?;
        self.viewport.as_ref()?.shown_grid(self.active, o.state.selected, &o.doc, &o.state)
    }

    /// The σ of the grid the active object's selected quantity shows (what isosurface levels
    /// in σ refer to) and whether its values are signed (an orbital: two surfaces).
    pub fn shown_grid(&self) -> (Option<f64>, bool) {
        let signed = |q: &crate::scene::QuantityState| match q.source {
            crate::scene::Source::Wavefunction(
                crate::model::orbitals::Quantity::Orbital(_)
                | crate::model::orbitals::Quantity::BasisFunction(_)
                | crate::model::orbitals::Quantity::TransitionDensity(_),
            ) => true,
            crate::scene::Source::Wavefunction(_) | crate::scene::Source::Promolecular(_) => false,
            crate::scene::Source::Volume(_) | crate::scene::Source::Scan(_) => true,
        };
        // Direct mode without a grid: the σ of its samples over the same box.
        let sampled = || {
            let (vp, o) = (self.viewport.as_ref()?, self.objects.get(self.active)?);
            vp.sampled(self.active, o.state.selected).map(|s| &s.range.samples)
        };
        match self.shown_values().or_else(sampled) {
            Some(g) => (Some(g.stats.sigma), g.kind == crate::model::grid::ValueKind::Signed),
            None => (None, self.objects.get(self.active).and_then(|o| o.state.selected_quantity()).is_none_or(signed)),
        }
    }

    /// The active object, when there is one.
    pub fn active_object(&self) -> Option<&SceneObject> {
        self.objects.get(self.active)
    }

    /// How many of the active object's atoms its selection shows.
    pub fn shown_atoms(&self) -> usize {
        self.active_object().map_or(0, |o| o.shown_atoms)
    }

    /// The quantity the side panel edits: the active object's selected one.
    pub fn selected_quantity(&self) -> Option<&crate::scene::QuantityState> {
        self.active_object()?.state.selected_quantity()
    }

    /// Where atom `atom` of the scene (numbered through every object, [`World`]) is drawn in
    /// the window (for tests and overlays).
    pub fn atom_on_screen(&self, atom: usize) -> Option<egui::Pos2> {
        let position = self.world.molecule.atoms.get(atom)?.position.as_vec3();
        self.viewport.as_ref()?.to_screen(&self.view.camera, position)
    }

    /// Whether a scan being prepared shows its first frame (no scan or file open yet).
    pub fn shows_scan_skeleton(&self) -> bool {
        self.scan_object().is_none() && self.scan_job.as_ref().is_some_and(|j| j.skeleton_shown)
    }

    /// Where a point of the scene (bohr) is drawn in the single-file view.
    pub fn point_on_screen(&self, p: glam::Vec3) -> Option<egui::Pos2> {
        self.viewport.as_ref()?.to_screen(&self.view.camera, p)
    }

    /// Where the 3-D view lies in the window (as last laid out).
    pub fn view_rect(&self) -> Option<egui::Rect> {
        self.viewport.as_ref()?.rect()
    }

    /// What is under the resting pointer in the single-file view.
    pub fn hovered(&self) -> Option<crate::gpu::frame::PickId> {
        self.viewport.as_ref()?.hovered
    }

    /// *Scan this…* on measurement `n`: the *Scan* window for its coordinate, when its atoms
    /// are one object's.
    pub fn scan_measurement(&mut self, n: usize) {
        let Some(m) = self.measurements.list.get(n) else { return };
        let object = |atom: usize| self.world.offsets.iter().rposition(|&first| first <= atom);
        let Some(o) = object(m.atoms[0]) else { return };
        if m.atoms.iter().any(|&a| object(a) != Some(o)) {
            self.status = "a scan moves atoms of one molecule: measure within one file".into();
            return;
        }
        let first = self.world.offsets[o];
        let atoms: Vec<usize> = m.atoms.iter().map(|a| a - first).collect();
        let coordinate = match *atoms.as_slice() {
            [i, j] => crate::model::scan::Coordinate::Distance([i, j]),
            [i, j, k] => crate::model::scan::Coordinate::Angle([i, j, k]),
            [i, j, k, l] => crate::model::scan::Coordinate::Dihedral([i, j, k, l]),
            _ => return,
        };
        if let Err(e) = crate::model::scan::moving_atoms(&self.objects[o].doc.molecule, &coordinate) {
            self.status = format!("{} cannot be scanned: {e}", coordinate.label());
            return;
        }
        self.scan_dialog = compute::ScanDialog::for_coordinate(o, coordinate, &self.objects[o].doc);
    }

    /// The *Scan* and *Compute orbitals* windows, and the computation's progress: frames done
    /// open as a scan, a computed wavefunction opens in place of its structure.
    fn compute_windows(&mut self, ctx: &egui::Context) {
        let (start, cancel) = compute::scan_window(ctx, &mut self.scan_dialog, self.computing.as_ref());
        let running = self.computing.as_ref().is_some_and(|c| !c.ended);
        if cancel && let Some(c) = &self.computing {
            c.cancel();
        }
        let repaint = {
            let ctx = ctx.clone();
            move || ctx.request_repaint()
        };
        if start && !running {
            let Some(o) = self.objects.get(self.scan_dialog.object) else { return };
            match compute::ComputeRun::scan(&self.scan_dialog, &o.doc, repaint.clone()) {
                Ok(run) => self.computing = Some(run),
                Err(e) => self.error = Some(format!("Scan: {e}")),
            }
        }
        if let Some((o, settings)) = &mut self.orbitals_dialog
            && compute::orbitals_window(ctx, settings)
            && !running
            && let Some(object) = self.objects.get(*o)
        {
            let source = std::path::Path::new(&object.doc.source);
            let name = format!(
                "{}_{}.molden",
                crate::sources::compute::stem(source),
                settings.level().replace(['/', '*'], "_")
            );
            let output = compute::beside(source).join(name);
            self.computing = Some(compute::ComputeRun::orbitals(&object.doc, settings.clone(), output, repaint));
            self.orbitals_dialog = None;
        }
        let loading = self.scan_job.is_some() || self.job.is_some();
        let Some(run) = &mut self.computing else { return };
        let opened = run.poll(loading);
        if run.announced != run.progress {
            run.announced = run.progress.clone();
            self.status = run.progress.clone();
        }
        match opened {
            compute::Opened::Scan(path) => self.open_scan(scan::ScanSource::File(path), ctx),
            compute::Opened::File(path) => {
                let how = if self.objects.len() <= 1 { Opening::Replace } else { Opening::Add };
                self.open_as(path, how, ctx);
            }
            compute::Opened::Nothing => {}
        }
    }

    /// Whether a click in a view waits for its picture to be whole before it is picked.
    pub fn is_picking(&self) -> bool {
        self.viewport.as_ref().is_some_and(viewport::Viewport::is_picking)
    }

    /// How much of a costly frame (drawn in bands) the single-file view has drawn (0..1);
    /// `None` when no such frame is under way.
    pub fn frame_progress(&self) -> Option<f32> {
        self.viewport.as_ref()?.progress()
    }

    /// Whether a coarse picture stands in while the single-file view's costly frame is drawn.
    pub fn previewing(&self) -> bool {
        self.viewport.as_ref().is_some_and(viewport::Viewport::is_previewing)
    }

    /// What the single-file view's translucent surfaces took (fragments, bands).
    pub fn fragment_note(&self) -> Option<String> {
        self.viewport.as_ref()?.fragment_note()
    }

    /// The clipping plane each layer of object `n` draws with in the single-file view
    /// ([`Viewport::clip_planes`]).
    pub fn clip_planes(&self, n: usize) -> Vec<Option<glam::Vec4>> {
        self.viewport.as_ref().map(|vp| vp.clip_planes(n)).unwrap_or_default()
    }

    /// Each view shown: (size on screen, size of its last frame), pixels. The frame is smaller
    /// while a drag or the animation runs on a CPU adapter ([`detail`]).
    pub fn view_sizes(&self) -> Vec<([u32; 2], [u32; 2])> {
        if let Some(panes) = self.viewport.as_ref().map(Viewport::pane_sizes).filter(|p| !p.is_empty()) {
            return panes;
        }
        self.viewport.iter().filter_map(|v| v.size().zip(v.rendered_size())).collect()
    }

    /// The object that is a frame of a scan (the scan open), when there is one.
    pub fn scan_object(&self) -> Option<&SceneObject> {
        self.objects.iter().find(|o| o.scan.is_some())
    }

    pub fn scan_object_mut(&mut self) -> Option<&mut SceneObject> {
        self.objects.iter_mut().find(|o| o.scan.is_some())
    }

    /// The open scan: its object's value and key volumes, and what the GPU shows of it.
    pub fn scan(&self) -> Option<scan::OpenScan<'_>> {
        let n = self.objects.iter().position(|o| o.scan.is_some())?;
        let object = &self.objects[n];
        let state = object.state.scan.as_ref()?;
        Some(scan::OpenScan {
            value: state.value,
            mode: state.mode,
            scene: &object.scan.as_ref()?.keys,
            object,
            shown: self.applied.get(n).and_then(|a| a.scan.as_ref()).map(|s| (s.value, s.mode)),
        })
    }

    /// Pane `p`'s last picture of a split view (tests, screenshots).
    pub fn pane_picture(&self, p: usize) -> Option<image::RgbaImage> {
        self.viewport.as_ref()?.pane_picture(p).ok()
    }

    /// Moves the open scan to `value` (clamped into its range); the GPU follows in the next frame.
    pub fn set_scan_value(&mut self, value: f64) {
        if let Some(o) = self.scan_object_mut()
            && let (Some(scan), Some(state)) = (&o.scan, &mut o.state.scan)
        {
            state.set_value(scan.scan(), value);
        }
    }

    /// A new handle on the window's device (for the key-volume job).
    fn gpu_context(&self) -> Option<GpuContext> {
        Some(self.viewport.as_ref()?.ctx.clone())
    }

    /// Starts loading a file in the background, added to the scene or replacing it as
    /// [`Self::open_replaces`] says (a `.scan.toml` opens as a scan, a `.orbcloud.toml` as a
    /// session); what is shown stays until it has loaded.
    pub fn open(&mut self, path: PathBuf, ctx: &egui::Context) {
        let how = if self.open_replaces { Opening::Replace } else { Opening::Add };
        self.open_as(path, how, ctx);
    }

    /// [`Self::open`], joining the scene as `how` says.
    pub fn open_as(&mut self, path: PathBuf, how: Opening, ctx: &egui::Context) {
        let name = path.to_string_lossy().to_ascii_lowercase();
        if name.ends_with(".scan.toml") {
            self.open_scan(ScanSource::File(path), ctx);
            return;
        }
        if name.ends_with(crate::scene::objects::SESSION_SUFFIX) {
            self.open_session(&path, ctx);
            return;
        }
        let repaint = ctx.clone();
        let added = match &how {
            Opening::Restore(state) => state.added.clone(),
            _ => Vec::new(),
        };
        self.job = Some((LoadJob::start(path, added, move || repaint.request_repaint()), how));
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
        self.open_scan_with(source, follow, None, ctx);
    }

    /// [`Self::open_scan_following`], its views showing `orbitals` (as manifests name them)
    /// when given.
    pub fn open_scan_with(
        &mut self,
        source: ScanSource,
        follow: Option<crate::model::scan::Follow>,
        orbitals: Option<Vec<String>>,
        ctx: &egui::Context,
    ) {
        let Some(gpu) = self.gpu_context() else { return };
        if let Some(job) = self.scan_job.take() {
            job.cancel();
        }
        let ctx = ctx.clone();
        let options = crate::layers::key_volumes::KeyOptions {
            points: self.scan_points,
            budget: self.scan_budget,
            ..Default::default()
        };
        self.scan_job = Some(ScanJob::start(gpu, source, options, follow, orbitals, move || ctx.request_repaint()));
    }

    /// Where world point `p` (bohr) lies in the window, in the last frame's view.
    pub fn on_screen(&self, p: glam::Vec3) -> Option<egui::Pos2> {
        self.viewport.as_ref()?.to_screen(&self.view.camera, p)
    }

    /// Whether a file, a scan or a job of the scene is still being worked on.
    pub fn is_loading(&self) -> bool {
        self.job.is_some()
            || !self.queue.is_empty()
            || self.scan_job.is_some()
            || self.difference.is_some()
            || self.busy().is_some()
    }

    /// Adds a loaded document to the scene as `how` says: beside the others, instead of them,
    /// or as a session saved it. It becomes the active object.
    fn add_object(&mut self, doc: Document, how: Opening) {
        self.add_shared_object(Arc::new(doc), how);
    }

    /// [`Self::add_object`] of a document already shared (carried from a lost device's window).
    fn add_shared_object(&mut self, doc: Arc<Document>, how: Opening) {
        let restoring = matches!(how, Opening::Restore(_));
        let replace = how == Opening::Replace;
        let defaults = self.defaults;
        let mut state = match how {
            Opening::Restore(mut state) => {
                state.fit_to(&doc, &defaults);
                *state
            }
            _ => ObjectState {
                path: (!doc.source.is_empty()).then(|| PathBuf::from(&doc.source)).filter(|p| p.exists()),
                ..ObjectState::opening(&doc, &defaults)
            },
        };
        if replace {
            self.clear_scene();
        }
        let keep = self.objects.len();
        if !restoring
            && keep > 0
            && let (Some((lo, hi)), Some((s_lo, s_hi))) = (doc.bounds(), self.world.molecule.bounds())
        {
            // Beside the scene across the view it opens in: 4 bohr past it along the screen's
            // right, so files opened one after another stand side by side, never one behind
            // another.
            let (right, _) = self.scene_camera().screen_axes();
            let scene = (s_lo.as_vec3(), s_hi.as_vec3());
            state.placement = crate::scene::Placement::beside_along(right, scene, lo.as_vec3(), hi.as_vec3(), 4.0);
        }
        let Some(vp) = &mut self.viewport else { return };
        if vp.room() < 1 + state.quantities.len() {
            self.error = Some(format!("{}: the scene is full ({} objects and their quantities)", doc.source, keep));
            return;
        }
        vp.documents = self.objects.iter().map(|o| o.doc.clone()).chain([doc.clone()]).collect();
        let note = match vp.set_object(keep, &doc, &state) {
            Ok(note) => note,
            Err(e) => {
                vp.remove_object(keep);
                self.error = Some(format!("{}: {e}", doc.source));
                return;
            }
        };
        self.status = note.unwrap_or_else(|| format!("opened {}", doc.source));
        // What the file held that could not be read (a malformed mode section, no orbitals)
        // stays in the status line until dismissed.
        if !doc.problems.is_empty() {
            self.notice = Some(doc.problems.join("; "));
        }
        if let Some(path) = &state.path {
            files::remember(&mut self.recent, path, RECENT_FILES);
        }
        self.applied.push(state.clone());
        let mut object = SceneObject { doc, state, shown_atoms: 0, scan: None };
        object.count_shown_atoms();
        self.objects.push(object);
        self.active = self.objects.len() - 1;
        for k in 0..self.objects[self.active].state.quantities.len() {
            self.auto_opacity(self.active, k);
        }
        // Quantities of the objects before it whose fragments name it (a session's, restored in
        // order) are made again, now with its density.
        let source = self.objects[self.active].doc.source.clone();
        if let Some(vp) = &mut self.viewport {
            // `vp.documents` already holds it (set before its quantities were shown).
            for (n, o) in self.objects.iter().enumerate().take(self.active) {
                for (k, q) in o.state.quantities.iter().enumerate() {
                    if q.fragments.files.contains(&source)
                        && let Err(e) = vp.set_quantity(n, k, &o.doc, &o.state)
                    {
                        log::warn!("{}: {e}", o.doc.source);
                    }
                }
            }
        }
        self.world = World::of(&self.objects);
        if !restoring {
            self.view.camera = self.scene_camera();
        }
        self.scroll_to_frontier = true;
    }

    /// Shows a scan whose key volumes are made as an object in place of the scene: as a
    /// session saved it (`restoring`), as it stood when it is the same scan reopened (following
    /// orbitals another way), or as it opens.
    fn open_scan_object(
        &mut self,
        keys: Arc<crate::layers::key_volumes::ScanScene>,
        source: ScanSource,
        restoring: Option<(ObjectState, Vec<crate::model::measure::Measurement>)>,
    ) {
        let name = match &source {
            ScanSource::File(p) => p.display().to_string(),
            ScanSource::Demo => crate::sources::demo::SCAN_NAME.to_string(),
        };
        let reopened =
            self.scan_object().filter(|o| o.scan.as_ref().is_some_and(|s| s.source == source)).map(|o| o.state.clone());
        let fresh = reopened.is_none() && restoring.is_none();
        let measurements = match (&restoring, fresh) {
            (Some((_, kept)), _) => {
                // A session's measurements number the scan's atoms.
                let atoms = keys.scan.frames.first().map_or(0, |f| f.molecule.atoms.len());
                kept.iter().filter(|m| m.atoms.iter().all(|&a| a < atoms)).cloned().collect()
            }
            (None, true) => Vec::new(),
            (None, false) => self.measurements.list.clone(),
        };
        let manifest = match &source {
            ScanSource::File(path) => Some(path.clone()),
            ScanSource::Demo => None,
        };
        let mut state = match restoring.map(|(state, _)| state).or(reopened) {
            Some(mut state) => {
                let playback = state.scan.get_or_insert_with(|| crate::scene::ScanState::opening(&keys.scan, None));
                playback.manifest = manifest;
                playback.orbitals = keys.scan.orbitals.clone();
                playback.follow = keys.tracks.follow;
                let value = playback.value;
                playback.set_value(&keys.scan, value);
                state
            }
            None => scan::opening_state(&keys, manifest, &self.defaults),
        };
        scan::fit_views(&mut state, keys.slots(), &self.defaults);
        let value = state.scan.as_ref().map_or(0.0, |s| s.value);
        let doc = Arc::new(keys.document_at(value, &name));
        self.clear_scene();
        if let Some(vp) = &mut self.viewport {
            vp.set_scan_keys(0, Some(keys.clone()));
        }
        let camera = self.view.camera;
        self.add_shared_object(doc, Opening::Restore(Box::new(state)));
        if let Some(o) = self.objects.first_mut() {
            o.scan = Some(ObjectScan::new(keys.clone(), source));
        }
        self.measurements.list = measurements;
        // Each view in a pane of its own, one camera for all.
        let views = keys.slots().clamp(1, crate::scene::objects::MAX_PANES);
        while self.view.panes.count < views {
            self.view.panes.add(camera);
        }
        self.view.panes.count = views;
        self.view.panes.linked = true;
        self.view.camera = if fresh { keys.camera() } else { camera };
        self.status = format!(
            "opened {name}: {} key volumes, {:.1} MiB of {:.0} MiB",
            keys.slots() * keys.scan.frames.len(),
            keys.bytes as f64 / 1048576.0,
            keys.budget as f64 / 1048576.0
        );
        if !keys.tracks.swaps.is_empty() {
            self.status +=
                &format!("; {} orbital character swap(s) (see `orbcloud scan info`)", keys.tracks.swaps.len());
        }
    }

    /// The open scan's controls below the view, its keys and its playing: the value moves in
    /// the object's state (the GPU follows in [`Self::apply_changes`]); a change of the orbitals
    /// followed makes its key volumes anew. Whether it plays.
    fn scan_controls(&mut self, ui: &mut egui::Ui, ctx: &egui::Context) -> bool {
        let whole = self.viewport.as_ref().is_none_or(|vp| vp.progress().is_none());
        let Some(o) = self.scan_object_mut() else { return false };
        let plays = scan::drive(ui, o, whole);
        let (Some(scan), Some(state)) = (&mut o.scan, &mut o.state.scan) else { return plays };
        let source = scan.source.clone();
        let orbitals = scan.scan().orbitals.clone();
        match scan::controls(ui, scan, state) {
            Some(scan::ScanRequest::Follow(follow)) => self.open_scan_following(source, Some(follow), ctx),
            Some(scan::ScanRequest::Show(name)) => {
                // The clicked orbital in the first view, the others as they were; by character,
                // as the diagram's line follows it.
                let mut orbitals = orbitals;
                if orbitals.is_empty() {
                    orbitals.push(name);
                } else {
                    orbitals[0] = name;
                }
                self.open_scan_with(source, Some(crate::model::scan::Follow::Overlap), Some(orbitals), ctx);
            }
            None => {}
        }
        plays
    }

    /// Frames what the scene shows, keeping the direction the camera looks from.
    pub fn reframe(&mut self) {
        let framed = self.framing_camera();
        (self.view.camera.target, self.view.camera.distance) = (framed.target, framed.distance);
    }

    /// Frames the scene's atoms (with room for the orbitals around them) to fill the width of
    /// each pane of a split view, which is narrower than tall: the single view's framing fits
    /// only their height. Each pane's camera is the view's, stood back by the pane's narrowness
    /// ([`viewport`]'s `fit_width`), so the distance set here is what that leaves exact.
    fn frame_panes(&mut self) {
        const ROOM: f32 = 3.0;
        let count = self.view.panes.count;
        let Some(rect) = self.viewport.as_ref().and_then(Viewport::rect).filter(|_| count > 1) else { return };
        let aspect = rect.width() / count as f32 / rect.height().max(1.0);
        let atoms: Vec<glam::Vec3> = self.world.molecule.atoms.iter().map(|a| a.position.as_vec3()).collect();
        let camera = &mut self.view.camera;
        camera.fit_exactly(&atoms, aspect, ROOM);
        if aspect < 1.0 {
            camera.distance *= aspect.max(0.2);
        }
    }

    /// Frames the active object's ρ = 0.002 surface (its atoms padded by the surface's reach)
    /// in the part of the view its colour bar leaves free, looking as the view does.
    pub(crate) fn frame_beside_bar(&mut self) {
        // The 0.002 a.u. density surface lies about a van der Waals radius beyond the nuclei.
        const REACH: f32 = 3.8;
        let (Some(o), Some(vp)) = (self.objects.get(self.active), &self.viewport) else { return };
        let (Some(rect), Some(aspect)) = (vp.rect(), vp.aspect()) else { return };
        let m = o.state.placement.world_from_object();
        let atoms: Vec<glam::Vec3> =
            o.doc.molecule.atoms.iter().map(|a| m.transform_point3(a.position.as_vec3())).collect();
        let camera = &mut self.view.camera;
        let free = ((rect.width() - legend::BAR_ROOM) / rect.width().max(1.0)).clamp(0.3, 1.0);
        camera.fit_exactly(&atoms, aspect * free, REACH);
        camera.leave_room_right(legend::BAR_ROOM, [rect.width(), rect.height()], true);
    }

    /// A camera that frames every object where it is placed, looking at the first one as a new
    /// file opens ([`ViewPreset::Auto`]: its principal axes, tilted).
    pub fn scene_camera(&self) -> crate::scene::Camera {
        let mut camera = self.framing_camera();
        if let Some(first) = self.objects.first() {
            let view = crate::scene::view::first_view(&first.doc.molecule);
            let m = first.state.placement.world_from_object();
            camera.look_along(m.transform_vector3(view.direction), m.transform_vector3(view.up));
        }
        // Several molecules side by side are wider than tall: every atom (2 bohr inside the
        // edges) in the view as it is laid out, not only in its height.
        if self.objects.len() > 1
            && let Some(aspect) = self.viewport.as_ref().and_then(viewport::Viewport::aspect)
        {
            camera.fit_points(self.world.molecule.atoms.iter().map(|a| a.position.as_vec3()), aspect, 2.0);
        }
        camera
    }

    /// Turns the camera to `preset`: `Auto` as a new file opens, x/y/z along the scene's axes,
    /// a bond or a plane of the selected atoms (numbered through the scene).
    pub fn look(&mut self, preset: ViewPreset) {
        let view = match preset {
            ViewPreset::Auto => {
                let target = self.view.camera.target;
                let distance = self.view.camera.distance;
                self.view.camera = self.scene_camera();
                (self.view.camera.target, self.view.camera.distance) = (target, distance);
                return;
            }
            _ => preset.direction(&self.world.molecule),
        };
        match view {
            Ok(v) => self.view.camera.look_along(v.direction, v.up),
            Err(e) => self.status = e,
        }
    }

    /// A camera that frames every object where it is placed (the atoms a selection shows),
    /// from the default direction.
    fn framing_camera(&self) -> crate::scene::Camera {
        match self.objects.as_slice() {
            [] => crate::scene::Camera::default(),
            [only] if only.state.placement.is_identity() && only.state.selection.is_empty() => {
                default_camera(&only.doc)
            }
            objects => {
                let boxes = objects.iter().filter_map(|o| {
                    let (lo, hi) = crate::scene::framing::framing_box_of(&o.doc, &o.state.selection)?;
                    Some(o.state.placement.placed_box(lo, hi))
                });
                match boxes.reduce(|a, b| (a.0.min(b.0), a.1.max(b.1))) {
                    Some((lo, hi)) => crate::scene::Camera::framing(lo, hi),
                    None => crate::scene::Camera::default(),
                }
            }
        }
    }

    /// Makes object `n` the one the panels edit.
    pub fn select(&mut self, n: usize) {
        if n < self.objects.len() {
            self.active = n;
            self.scroll_to_frontier = true;
        }
    }

    /// Removes object `n` from the scene (measurements, which number the scene's atoms, go too).
    pub fn remove_object(&mut self, n: usize) {
        if n >= self.objects.len() {
            return;
        }
        self.objects.remove(n);
        self.applied.remove(n);
        if let Some(vp) = &mut self.viewport {
            vp.remove_object(n);
        }
        self.measurements = measure::Measurements::default();
        self.world = World::of(&self.objects);
        self.active = if n < self.active { self.active - 1 } else { self.active };
        self.active = self.active.min(self.objects.len().saturating_sub(1));
    }

    /// Makes what the GPU shows follow each object's state after the edits since the last
    /// call, as [`crate::scene::changes`] decides; called once a frame, after the panels.
    pub fn apply_changes(&mut self) {
        let mut moved = false;
        if let Some(vp) = &mut self.viewport {
            vp.documents = self.objects.iter().map(|o| o.doc.clone()).collect();
        }
        for n in 0..self.objects.len().min(self.applied.len()) {
            let (Some(vp), Some(o)) = (&mut self.viewport, self.objects.get_mut(n)) else { break };
            if self.applied[n] == o.state {
                continue;
            }
            let was = std::mem::replace(&mut self.applied[n], o.state.clone());
            let was = &was;
            let changes = crate::scene::changes(was, &o.state);
            if changes.is_empty() {
                continue;
            }
            // A scan's new value: its document is the skeleton there, the GPU moves the atoms
            // in place and sets each view's mixing weight.
            if changes.scan_frame
                && let (Some(scan), Some(s)) = (&o.scan, &o.state.scan)
            {
                o.doc = Arc::new(scan.keys.document_at(s.value, &o.doc.source));
                vp.set_scan_frame(n, &o.doc, &o.state);
                moved = true;
            }
            let o = &*o;
            let mut notes = Vec::new();
            if changes.layers {
                notes.push(vp.relayout_quantities(n, &o.doc, was, &o.state));
            }
            for (k, q) in changes.quantities.iter().enumerate() {
                if q.values {
                    notes.push(vp.set_quantity(n, k, &o.doc, &o.state));
                } else if q.isosurfaces {
                    vp.update_isosurfaces(n, k, &o.doc, &o.state);
                }
            }
            if changes.atoms {
                vp.set_atom_look(n, &o.doc, &o.state);
            }
            if changes.surface {
                vp.update_surface(n, &o.doc, &o.state);
            }
            if changes.rest {
                vp.set_atoms(n, &o.doc, &o.state);
            }
            if changes.arrows {
                vp.set_arrows(n, &o.doc, &o.state);
            }
            if changes.placement || changes.visibility || changes.clip {
                vp.set_visibility(n, &o.state);
            }
            moved |= changes.placement;
            for note in notes {
                match note {
                    Ok(Some(note)) => self.status = note,
                    Ok(None) => {}
                    Err(e) => self.error = Some(format!("{}: {e}", o.doc.source)),
                }
            }
            let refit: Vec<usize> = match changes.layers {
                true => (0..o.state.quantities.len()).collect(),
                false => (changes.quantities.iter().enumerate())
                    .filter(|(_, q)| q.values || q.opacity)
                    .map(|(k, _)| k)
                    .collect(),
            };
            for k in refit {
                self.auto_opacity(n, k);
            }
            if changes.atoms {
                self.objects[n].count_shown_atoms();
            }
        }
        if moved {
            self.world = World::of(&self.objects);
        }
    }

    /// Moves the atoms of every object that shows a normal mode to where the mode is at
    /// `seconds` into the animation; whether any mode plays (the window then keeps drawing).
    fn animate_modes(&mut self, seconds: f64) -> bool {
        let Some(vp) = &mut self.viewport else { return false };
        let mut playing = false;
        for (n, o) in self.objects.iter().enumerate() {
            let v = o.state.vibration;
            if v.mode.is_some() && o.doc.vibrations.is_some() {
                vp.displace_atoms(n, &o.doc, &o.state, v.phase(seconds));
                playing |= v.playing;
            }
        }
        playing
    }

    /// The panels of the active object beside and below the view: its orbital browser, its
    /// normal modes and the plane map (a scan shows its own controls instead).
    fn object_panels(&mut self, ui: &mut egui::Ui, ctx: &egui::Context) {
        let defaults = self.defaults;
        // A scan shows its own orbitals; the browser belongs to the scene's objects.
        if let Some(o) = self.objects.get_mut(self.active).filter(|o| o.scan.is_none()) {
            let view = &mut self.view;
            let reframe = orbitals::panel(
                ui,
                &o.doc,
                &mut o.state,
                &defaults,
                (&mut view.panes, &view.camera),
                &mut self.scroll_to_frontier,
                &mut view.panels.orbitals,
            );
            match reframe {
                orbitals::Reframe::BesideBar => self.frame_beside_bar(),
                orbitals::Reframe::Panes => self.frame_panes(),
                orbitals::Reframe::None => {}
            }
        }
        if let Some(o) = self.objects.get_mut(self.active).filter(|o| o.scan.is_none()) {
            vibrations::panel(ui, &o.doc, &mut o.state.vibration, &mut self.spectrum);
        }
        let documents: Vec<Arc<Document>> = self.objects.iter().map(|o| o.doc.clone()).collect();
        if let Some(o) = self.objects.get_mut(self.active).filter(|o| o.scan.is_none()) {
            // The surface's point under the pointer, in the object's own frame, marked on the plot.
            let active = self.active as u32;
            let shows_nci = o.state.selected_quantity().is_some_and(|q| nci_plot::is_nci_surface(q.source));
            let hovered = (self.viewport.as_ref().filter(|_| shows_nci))
                .and_then(|vp| vp.hovered_surface_point(&self.view.camera))
                .filter(|&(object, _)| object == active)
                .map(|(_, p)| o.state.placement.world_from_object().inverse().transform_point3(p));
            let others: Vec<Arc<Document>> = documents.clone();
            if let Some(q) = o.state.selected_quantity() {
                let of = crate::evaluate::meshes::Evaluating { doc: &o.doc, fragments: &q.fragments, others: &others };
                self.nci_plot.hover(of, q.source, hovered);
            }
            self.nci_plot.panel(ui, &o.doc, &others, o.state.selected_quantity_mut());
        }
        let mut ntos = None;
        if let Some(o) = self.objects.get_mut(self.active).filter(|o| o.scan.is_none()) {
            let asked = excited::panel(ui, &o.doc, &mut o.state.excited, &mut self.uv_vis);
            if let Some(k) = asked.ntos {
                ntos = Some((self.active, k));
            }
            let view = &mut self.view;
            // A state's transition density is the file's to show, also when its NTOs stood in
            // for it.
            let transition = |p: &orbitals::Pick| {
                matches!(p, orbitals::Pick::Switch(crate::model::orbitals::Quantity::TransitionDensity(_)))
            };
            o.state.visible |= asked.picks.iter().any(transition);
            let reframes: Vec<_> = (asked.picks.into_iter())
                .map(|p| orbitals::apply(p, &mut o.state, &defaults, (&mut view.panes, &view.camera)))
                .collect();
            if reframes.contains(&orbitals::Reframe::Panes) {
                self.frame_panes();
            }
        }
        if let Some((n, k)) = ntos {
            self.show_ntos(n, k);
        }
        if self.plane.open
            && let Some(o) = self.objects.get(self.active).filter(|o| o.scan.is_none())
        {
            let source = o.state.selected_quantity().map(|q| q.source);
            let measured = self.measured_plane_atoms();
            // The view's plane in the object's own frame: through the camera's target, facing it.
            let object_from_world = o.state.placement.world_from_object().inverse().as_dmat4();
            let camera = &self.view.camera;
            let facing = plane_pane::Through::Facing {
                origin: object_from_world.transform_point3(camera.target.as_dvec3()),
                normal: object_from_world.transform_vector3((camera.eye() - camera.target).as_dvec3()),
            };
            if plane_pane::panel(ui, &mut self.plane, (&o.doc, source), measured, facing) {
                let stem =
                    Path::new(&o.doc.source).file_stem().map_or("map".into(), |s| s.to_string_lossy().into_owned());
                if let Some(path) = self.choose(files::Purpose::SaveMap, &format!("{stem}-plane.png")) {
                    self.chosen(files::Purpose::SaveMap, path, ctx);
                }
            }
        }
    }

    /// The first three atoms of the last measurement of three or more atoms, when all lie in the
    /// active object: 1-based, as the plane pane numbers them.
    fn measured_plane_atoms(&self) -> Option<[usize; 3]> {
        let m = self.measurements.list.iter().rev().find(|m| m.atoms.len() >= 3)?;
        let first = *self.world.offsets.get(self.active)?;
        let n = self.objects.get(self.active)?.doc.molecule.atoms.len();
        let local = |a: usize| a.checked_sub(first).filter(|&i| i < n).map(|i| i + 1);
        Some([local(m.atoms[0])?, local(m.atoms[1])?, local(m.atoms[2])?])
    }

    /// Puts back a session's measurements once its files have loaded (those naming atoms the
    /// scene does not have are left out).
    fn restore_measurements(&mut self) {
        let Some(list) = self.restoring_measurements.take() else { return };
        let atoms = self.world.molecule.atoms.len();
        self.measurements.list = list.into_iter().filter(|m| m.atoms.iter().all(|&a| a < atoms)).collect();
    }

    /// Makes the object list changes the panels asked for.
    fn apply_scene_edits(&mut self) {
        for edit in std::mem::take(&mut self.pending) {
            match edit {
                SceneEdit::Select(n) => self.select(n),
                SceneEdit::Remove(n) => self.remove_object(n),
            }
        }
    }

    /// After a failed load with nothing open and nothing else coming, opens the bundled demo:
    /// the window never stays empty because a file did not open.
    fn show_demo_if_empty(&mut self, ctx: &egui::Context) {
        let nothing = self.objects.is_empty() && self.scan_job.is_none();
        if nothing && self.queue.is_empty() && self.job.is_none() {
            self.open_scan(ScanSource::Demo, ctx);
        }
    }

    /// A path for `purpose` from the system's file dialog; where there is none, opens the
    /// in-window chooser instead (its choice is acted on when made) and returns `None`.
    fn choose(&mut self, purpose: files::Purpose, file_name: &str) -> Option<PathBuf> {
        if self.native_dialogs {
            match files::native(purpose, file_name) {
                files::Native::Answered(chosen) => return chosen,
                files::Native::Missing => self.native_dialogs = false,
            }
        }
        // Pictures go where the last one went; files open from where the last one came.
        let last_saved =
            self.last_folder.clone().filter(|_| matches!(purpose, files::Purpose::SavePng | files::Purpose::SaveMap));
        let dir = last_saved
            .or_else(|| self.recent.first().and_then(|p| p.parent()).map(Path::to_path_buf))
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_else(|| PathBuf::from("/"));
        self.browser = Some(files::FileBrowser::new(purpose, dir, file_name));
        None
    }

    /// Does what a path chosen for `purpose` is for.
    fn chosen(&mut self, purpose: files::Purpose, path: PathBuf, ctx: &egui::Context) {
        match purpose {
            files::Purpose::Open => self.open(path, ctx),
            files::Purpose::SaveSession => self.save_session(&session::with_suffix(path)),
            files::Purpose::SavePng => self.save_png(&path),
            files::Purpose::SaveMap => match self.plane.save(&path) {
                Ok(()) => {
                    self.status = format!("saved the plane map as {}", path.display());
                    self.last_folder = path.parent().map(Path::to_path_buf);
                }
                Err(e) => self.error = Some(e),
            },
        }
    }

    /// Shows the in-window chooser, when open, and acts on its choice.
    fn file_browser(&mut self, ctx: &egui::Context) {
        let Some(browser) = &mut self.browser else { return };
        let purpose = browser.purpose;
        match browser.show(ctx, &self.recent) {
            files::Choice::None => {}
            files::Choice::Closed => self.browser = None,
            files::Choice::Chosen(path) => {
                self.browser = None;
                self.chosen(purpose, path, ctx);
            }
        }
    }

    /// Shows what the objects' background jobs (orbitals, densities, isosurfaces) finished.
    fn poll_object_jobs(&mut self) {
        let Some(vp) = &mut self.viewport else { return };
        let mut evaluated = Vec::new();
        for (n, o) in self.objects.iter().enumerate() {
            let (said, shown) = vp.poll(n, &o.doc, &o.state);
            for said in said {
                match said {
                    Ok(status) => self.status = status,
                    Err(e) => self.error = Some(e),
                }
            }
            evaluated.extend(shown.into_iter().map(|k| (n, k)));
        }
        for (n, k) in evaluated {
            self.auto_opacity(n, k);
        }
    }

    /// Chooses the k1 of object `n`'s quantity `k` from the values it shows, when its cloud
    /// asks for that.
    fn auto_opacity(&mut self, n: usize, k: usize) {
        let (Some(vp), Some(o)) = (&self.viewport, self.objects.get_mut(n)) else { return };
        let grid = vp.shown_grid(n, k, &o.doc, &o.state);
        let sampled = vp.sampled(n, k);
        let Some(q) = o.state.quantities.get_mut(k) else { return };
        match (grid, sampled) {
            (Some(grid), _) => crate::evaluate::auto_opacity(&mut q.cloud, grid),
            (None, Some(sampled)) => crate::evaluate::auto_opacity_sampled(&mut q.cloud, sampled),
            (None, None) => {}
        }
    }

    /// What the scene's background jobs are doing, in words, and how far when that is known
    /// (`None`: nothing).
    pub fn busy(&self) -> Option<(&'static str, Option<f32>)> {
        self.viewport.as_ref()?.busy()
    }

    /// Stops the scene's background jobs (evaluations, isosurfaces).
    pub fn cancel_jobs(&mut self) {
        if let Some(vp) = &mut self.viewport {
            vp.cancel_jobs();
            self.status = "cancelled".into();
        }
    }

    fn poll_job(&mut self, ctx: &egui::Context) {
        self.poll_object_jobs();
        self.poll_difference();
        let reported: Vec<String> =
            std::mem::take(&mut *self.gpu_errors.lock().unwrap_or_else(std::sync::PoisonError::into_inner));
        if let Some(lost) = reported.iter().find(|e| e.starts_with(DEVICE_LOST)) {
            self.save_last_session();
            let reason = lost.trim_start_matches(DEVICE_LOST).trim_matches([' ', '(', ')']).to_string();
            if self.carry_away(&reason, ctx) {
                return;
            }
            let kept = self
                .last_session
                .as_ref()
                .map_or(String::new(), |p| format!(" The scene is saved in {}.", p.display()));
            self.error = Some(format!(
                "{DEVICE_LOST}: the view cannot be drawn any more.{kept} Restart orbcloud and choose *Last session* to reopen it."
            ));
        } else if let Some(last) = reported.last() {
            self.error = Some(format!("the GPU reported an error (the view may be incomplete): {last}"));
        }
        if let Some((job, _)) = &self.job
            && let Some(result) = job.poll()
        {
            let Some((_, how)) = self.job.take() else { return };
            match result {
                Ok(doc) => self.add_or_join(doc, how),
                Err(e) => {
                    self.error = Some(e.clone());
                    self.show_demo_if_empty(ctx);
                }
            }
        }
        if let Some(job) = &self.scan_job
            && let Some(result) = job.poll()
        {
            let (name, source) = (job.name.clone(), job.source.clone());
            self.scan_job = None;
            // A session's scan that does not open leaves nothing to restore into a later one.
            let restoring = self.restoring_scan.take();
            match result {
                Ok(scene) => self.open_scan_object(Arc::new(scene), source, restoring),
                Err(ScanFailure::Cancelled) => self.status = format!("{name}: cancelled"),
                Err(ScanFailure::OverBudget { message, fits }) => {
                    self.error = Some(format!("{name}: {message}"));
                    self.scan_retry = Some((source, fits));
                }
                Err(ScanFailure::Other(e)) => {
                    self.error = Some(e);
                    self.show_demo_if_empty(ctx);
                }
            }
        }
        if self.job.is_none()
            && let Some((next, how)) = self.queue.pop()
        {
            self.open_as(next, how, ctx);
        }
        if self.job.is_none() && self.queue.is_empty() {
            self.restore_measurements();
        }
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw.dropped_files.iter().map(|f| f.path().to_path_buf()).filter(|p| !p.as_os_str().is_empty()).collect()
        });
        // Several files dropped at once: the first replaces (when asked), the rest are added.
        let first = if self.open_replaces { Opening::Replace } else { Opening::Add };
        let count = dropped.len();
        for (n, path) in dropped.into_iter().enumerate().rev() {
            self.queue.push((path, if n == 0 && count > 0 { first.clone() } else { Opening::Add }));
        }
    }
}

impl OrbApp {
    /// The 3-D view in the window's centre: the scene (split into panes when asked), a scan's
    /// drags, the colour bars, picks and measurements, the plane map's frame and its Alt + wheel.
    /// `playing`: a mode or a scan moves, so the view draws as while a drag runs.
    fn view_panel(&mut self, ui: &mut egui::Ui, rs: &egui_wgpu::RenderState, playing: bool) {
        if let Some(vp) = &mut self.viewport {
            // A scan being prepared in an empty window: its first frame at once, framed.
            if let Some(job) = self.scan_job.as_mut().filter(|j| !j.skeleton_shown && self.objects.is_empty())
                && let Some(molecule) = job.skeleton()
            {
                vp.show_molecule(&molecule, self.defaults.atoms);
                // A session's scan keeps the session's camera.
                if let Some((lo, hi)) = molecule.bounds().filter(|_| self.restoring_scan.is_none()) {
                    self.view.camera = crate::scene::Camera::framing(lo.as_vec3(), hi.as_vec3());
                }
                job.skeleton_shown = true;
            }
            // A mode or a scan playing redraws every frame, as a drag does.
            let interacting = detail::interacting(ui.ctx(), playing);
            // Panes share the pixels a frame may draw while something moves.
            let panes = self.view.panes.count.max(1);
            vp.detail = detail::Detail::for_frame(interacting, vp.ctx.info.device_type, panes);
            let picture_ms = vp.take_picture_ms();
            vp.detail.lod_scale = vp.lod_budget.next(interacting, picture_ms);
            let states: Vec<&ObjectState> = self.objects.iter().map(|o| &o.state).collect();
            vp.set_clouds(&states);
            let count = self.view.panes.count;
            // The plane map's frame where the plane lies, in the active object.
            let frame = if self.plane.open { plane_pane::frame_lines(&self.plane) } else { Vec::new() };
            vp.show_plane_frame(self.active, frame);
            let scan = self.objects.iter().position(|o| o.scan.is_some());
            let twist = scan.and_then(|n| scan::twist_input(ui, &self.objects[n]));
            let twisted = if count > 1 {
                let panes: Vec<viewport::Pane> = (0..count)
                    .map(|p| viewport::Pane {
                        camera: self.view.camera,
                        layers: vp.pane_layers(&states, p, count),
                        label: panes::label(&self.objects, p, count),
                    })
                    .collect();
                vp.show_split(ui, rs, &mut self.view, &panes, twist)
            } else {
                vp.unsplit();
                let clip = self.objects.get_mut(self.active).map(|o| &mut o.state.clip);
                vp.show_twistable(ui, rs, &mut self.view, clip, twist)
            };
            if let Some(n) = scan
                && scan::apply_twist(&mut self.objects[n], twisted, vp, &self.view.camera)
            {
                ui.ctx().request_repaint();
            }
            if let Some(o) = self.objects.get(self.active).filter(|o| o.state.surface.color_by_volume)
                && let Some(map) = vp.surface_map(self.active)
            {
                let name = o.state.selected_quantity().map(|q| q.source.name(&o.doc)).unwrap_or_default();
                legend::value_bar(ui, ui.min_rect(), &map, &name);
            } else if let Some(o) = self.objects.get(self.active)
                && let Some(k) = o
                    .state
                    .quantities
                    .iter()
                    .position(|q| q.visible && q.isosurfaces.iter().any(|i| i.visible && i.color_by.is_some()))
                && let Some((map, name)) = vp.isosurface_map(self.active, k)
            {
                legend::value_bar(ui, ui.min_rect(), &map, &name);
            }
            if let Some(click) = vp.click.take() {
                let said = self.measurements.click(click, &self.world);
                if !said.is_empty() {
                    self.status = said;
                }
            }
            measure::overlay(ui, vp, &self.view.camera, &self.world, &self.measurements, self.view.labels);
            if self.objects.get(self.active).is_some() && self.plane.open {
                // Alt + wheel over the view moves the plane along its normal, 0.1 Å a notch.
                let notches: Vec<f32> = ui.input(|i| {
                    (i.raw.events.iter())
                        .filter_map(|e| match e {
                            egui::Event::MouseWheel { delta, modifiers, .. } if modifiers.alt => {
                                Some(delta.y + delta.x)
                            }
                            _ => None,
                        })
                        .filter(|d| *d != 0.0)
                        .collect()
                });
                if vp.rect().is_some_and(|r| ui.rect_contains_pointer(r)) {
                    for d in notches {
                        self.plane.nudge(f64::from(d.signum()) * 0.1);
                    }
                }
            }
        }
    }
}

impl eframe::App for OrbApp {
    fn on_exit(&mut self) {
        self.save_last_session();
    }

    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.tick_rehearsal(&ctx);
        self.poll_job(&ctx);
        self.poll_recording();
        let action = panels::top_bar(ui, self);
        panels::status_bar(ui, self);
        record::record_window(&ctx, self);
        self.compute_windows(&ctx);
        picture::picture_window(&ctx, self);
        panels::side_panel(ui, self);
        self.object_panels(ui, &ctx);
        let scan_plays = self.scan_controls(ui, &ctx);
        self.apply_changes();
        self.apply_scene_edits();
        let modes_play = self.animate_modes(ui.input(|i| i.time));
        if let Some(model) = models::tick(&ctx, self) {
            self.show_model(model);
        }
        match action {
            panels::Action::Open => {
                if let Some(path) = self.choose(files::Purpose::Open, "") {
                    self.open(path, &ctx);
                }
            }
            panels::Action::SaveSession => {
                if let Some(path) = self.choose(files::Purpose::SaveSession, "scene.orbcloud.toml") {
                    self.save_session(&session::with_suffix(path));
                }
            }
            panels::Action::Demo(demo) => self.open_demo(demo, &ctx),
            panels::Action::ReopenLast => {
                if let Some(path) = self.last_session.clone() {
                    self.open_session(&path, &ctx);
                }
            }
            panels::Action::Record => self.open_record_dialog(),
            panels::Action::Screenshot => self.open_picture_dialog(),
            panels::Action::ResetView => {
                self.view.camera = match self.scan_object().and_then(|o| o.scan.as_ref()) {
                    Some(scan) => scan.keys.camera(),
                    None => self.scene_camera(),
                };
                if self.scan_object().is_none() {
                    self.frame_panes();
                }
            }
            panels::Action::None => {}
        }
        panels::error_window(ui, self);
        self.file_browser(&ctx);
        egui::CentralPanel::no_frame().show(ui, |ui| {
            if let Some(rs) = frame.wgpu_render_state() {
                self.view_panel(ui, rs, modes_play || scan_plays);
            }
        });
        if self.is_loading() || self.recording.is_some() {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
        if modes_play || scan_plays {
            ctx.request_repaint();
        }
    }
}
