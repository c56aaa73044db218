//! The 3D view inside the window: renders through the shared [`Renderer`] into an offscreen
//! texture that egui shows as an image, and turns mouse and keys into camera moves.

use egui::{Key, PointerButton, Sense};

use super::detail::Detail;
use super::jobs::Latest;
use super::state::{DRAG_ROTATE, KEY_ROTATE, KEY_ZOOM, ViewState};
use crate::gpu::context::guarded;
use crate::gpu::frame::PickId;
use crate::gpu::gto::GtoFillPass;
use crate::gpu::oit::FragmentStats;
use crate::gpu::{FrameInput, GpuContext, GpuError, OffscreenTarget, Renderer, Tile};
use crate::headless::scan::ScanScene;
use crate::headless::{Evaluated, WavefunctionView, evaluate_within, isosurfaces_within, molecular_surface};
use crate::model::isosurface::Mesh;
use crate::model::{Document, VolumeGrid};
use crate::scene::translucency::SurfaceLook;
use crate::scene::{IsosurfaceSettings, ObjectState, RenderSettings, SurfaceChoice, SurfaceSettings, VolumeSettings};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// What a frame drew: the view, the clouds, the size, the scene's generation and the bits of
/// the level-of-detail scale; a frame is drawn again when any of them changes.
type Drawn = (ViewState, Vec<VolumeSettings>, [u32; 2], u64, u32);

/// A click in the view: what the frame showed under the pointer, and whether Shift was held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Click {
    pub picked: Option<PickId>,
    pub shift: bool,
}

/// How a drag in a scan view twists the dihedral (seed 000: horizontal drag changes θ).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TwistInput {
    /// Every primary drag twists (else the view orbits, unless the drag starts on the bond).
    pub drag_twists: bool,
    /// The rotatable bond (world, bohr): a drag that starts on it twists.
    pub bond: Option<[glam::Vec3; 2]>,
}

/// How long one UI frame may spend drawing bands of a costly frame, and how long one band
/// should take: inputs are answered within about 100 ms whatever the view shows.
const FRAME_BUDGET: Duration = Duration::from_millis(40);
const BAND_TIME: Duration = Duration::from_millis(25);

/// A costly frame being drawn in bands: the first row not drawn yet, and rows per band.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Progress {
    next_row: u32,
    rows: u32,
}

/// The note for a document's volume shown at every `step`-th point (`None` when whole).
fn coarser(doc: &Document, state: &ObjectState, step: usize) -> Option<String> {
    let grid = doc.volumes.get(state.volume).filter(|_| step > 1)?;
    Some(crate::headless::coarser_note(&doc.source, grid.dims, step))
}

/// Screen distance (points) within which a press grabs the rotatable bond.
const BOND_GRAB: f32 = 10.0;

/// An orbital or density evaluated in the background, with a note when its grid had to be
/// coarser than asked.
type Evaluation = Result<(Option<Evaluated>, Option<String>), GpuError>;

/// Isosurfaces made in the background, each with its colour, and a note when they had to be
/// cut from a coarser grid.
pub type Meshes = (Vec<(Mesh, SurfaceLook)>, Option<String>);
/// Meshes with the octrees they are drawn with, built in the same job.
type Prepared = (Vec<(Mesh, SurfaceLook)>, Vec<Option<crate::gpu::isosurface::LodLevels>>, Option<String>);

fn prepared((meshes, note): Meshes) -> Prepared {
    let trees = crate::gpu::isosurface::lod_trees(&meshes);
    (meshes, trees, note)
}

/// What the viewport keeps per object besides its renderer layer.
struct ObjectJobs {
    /// Values on the grid shown when computed from a basis (cube files' grids stay in the
    /// document): isosurfaces are cut from it.
    computed: Option<Arc<VolumeGrid>>,
    /// Orbitals filled on the GPU and densities evaluated on the CPU, with a note when the grid
    /// had to be coarser than asked.
    evaluation: Latest<Evaluation>,
    /// Marching cubes over the grid shown, and the molecular surface.
    extraction: Latest<Prepared>,
    /// The last molecular surface built, kept while only its look changes (an isosurface
    /// slider moving does not build it again).
    surface: Arc<Mutex<Option<BuiltSurface>>>,
    /// Thousandths of the molecular surface being built (the status line's bar); 0 when none is.
    surface_progress: Arc<AtomicU32>,
}

/// A molecular surface with what it was built from: its settings and the atoms' fingerprint.
struct BuiltSurface {
    settings: SurfaceSettings,
    atoms: (usize, [u64; 3]),
    mesh: Mesh,
    note: Option<String>,
}

/// Enough of the atoms shown to tell when a surface must be built again (another model,
/// another selection): their count and the sum of their positions' bits.
fn fingerprint(doc: &Document, selection: &str) -> (usize, [u64; 3]) {
    let sum = doc.molecule.atoms.iter().fold([0u64; 3], |acc, a| {
        let p = a.position.to_array().map(f64::to_bits);
        [acc[0].wrapping_add(p[0]), acc[1].wrapping_add(p[1]), acc[2].wrapping_add(p[2])]
    });
    let mut hash = std::hash::DefaultHasher::new();
    std::hash::Hash::hash(selection, &mut hash);
    (doc.molecule.atoms.len(), [sum[0], sum[1], sum[2] ^ std::hash::Hasher::finish(&hash)])
}

pub struct Viewport {
    pub ctx: GpuContext,
    renderer: Renderer,
    fill: Option<Arc<GtoFillPass>>,
    target: Option<(OffscreenTarget, egui::TextureId)>,
    /// The view's size on screen, pixels (the target may be smaller while interacting).
    shown_size: Option<[u32; 2]>,
    /// What the next frames draw: set each frame by the caller.
    pub detail: Detail,
    /// The surfaces' level-of-detail scale while interacting, kept to the frame-time budget.
    pub lod_budget: super::detail::LodBudget,
    /// When the picture being drawn was started, and how long the last complete one took (ms,
    /// taken once).
    picture_started: Option<Instant>,
    picture_ms: Option<f64>,
    /// The state the texture currently shows; a frame is drawn only when this changes.
    drawn: Option<Drawn>,
    /// Bumped whenever the renderer's data changes.
    generation: u64,
    /// Per object: its computed grid and its background jobs.
    slots: Vec<ObjectJobs>,
    /// Wakes the window when a job ends.
    repaint: Arc<dyn Fn() + Send + Sync>,
    /// Each object's cloud settings (set by the caller each frame); empty: one layer drawn with
    /// the view's settings (scan views).
    pub clouds: Vec<VolumeSettings>,
    /// The last click, until the caller takes it.
    pub click: Option<Click>,
    /// What is under the resting pointer (hover highlight), and where the pointer was.
    pub hovered: Option<PickId>,
    hovered_at: Option<egui::Pos2>,
    /// Where the view was laid out, and the size it was drawn at (for overlays).
    layout: Option<(egui::Rect, [u32; 2])>,
    /// Whether the current drag twists the dihedral.
    twisting: bool,
    /// A costly frame being drawn band by band, and how many rows the last band drew.
    progress: Option<Progress>,
    band_rows: u32,
    /// The scan frame shown: (θ, interpolation), for tests and redraws.
    pub scan_shown: Option<(f64, crate::scene::Interpolation)>,
    /// The θ and settings a scan view's isosurfaces were last asked for (`None`: hidden).
    pub scan_iso: Option<(f64, IsosurfaceSettings)>,
    /// A frame with translucent surfaces was drawn and its fragment counts are not back yet.
    awaiting_fragments: bool,
    /// The last frame's fragment counts, when it had translucent surfaces.
    fragments: Option<FragmentStats>,
}

impl Viewport {
    /// Wakes `ctx`'s window whenever a background job of the view ends.
    pub fn set_repaint(&mut self, ctx: egui::Context) {
        self.repaint = Arc::new(move || ctx.request_repaint());
    }

    pub fn new(ctx: GpuContext) -> Self {
        let renderer = Renderer::new(&ctx);
        Self {
            ctx,
            renderer,
            fill: None,
            target: None,
            shown_size: None,
            detail: Detail::FULL,
            lod_budget: Default::default(),
            picture_started: None,
            picture_ms: None,
            drawn: None,
            generation: 0,
            slots: Vec::new(),
            repaint: Arc::new(|| {}),
            clouds: Vec::new(),
            click: None,
            hovered: None,
            hovered_at: None,
            layout: None,
            twisting: false,
            scan_shown: None,
            progress: None,
            band_rows: 8,
            scan_iso: None,
            awaiting_fragments: false,
            fragments: None,
        }
    }

    /// Uploads object `n` of the scene: its molecule, the volume its state chooses and its
    /// placement; its isosurfaces are cut in the background. Returns a note when the volume is
    /// more than the GPU holds and is shown coarser.
    pub fn set_object(
        &mut self,
        n: usize,
        doc: &Arc<Document>,
        state: &ObjectState,
    ) -> Result<Option<String>, GpuError> {
        let (ctx, layer) = (&self.ctx, self.renderer.layer_mut(&self.ctx, n));
        let step = guarded(&ctx.device, || crate::headless::show_document(ctx, layer, doc, state))?;
        let slot = self.slot(n);
        slot.evaluation.cancel();
        slot.computed = None;
        self.generation += 1;
        self.update_isosurfaces(n, doc, state);
        Ok(coarser(doc, state, step))
    }

    /// Shows the volume object `n`'s state chooses (a note when it is shown coarser).
    pub fn set_volume(
        &mut self,
        n: usize,
        doc: &Arc<Document>,
        state: &ObjectState,
    ) -> Result<Option<String>, GpuError> {
        let (ctx, layer) = (&self.ctx, self.renderer.layer_mut(&self.ctx, n));
        let step = guarded(&ctx.device, || layer.set_volume(ctx, doc.volumes.get(state.volume)))?;
        self.generation += 1;
        self.update_isosurfaces(n, doc, state);
        Ok(coarser(doc, state, step))
    }

    /// Evaluates a wavefunction's orbital or density for object `n` in the background
    /// ([`crate::headless::evaluate_wavefunction`]); [`Self::poll`] shows it when it is done.
    pub fn show_wavefunction(&mut self, n: usize, doc: &Arc<Document>, view: WavefunctionView) {
        if doc.wavefunction.is_none() {
            return;
        }
        let ctx = self.ctx.clone();
        let fill = self.fill.get_or_insert_with(|| Arc::new(GtoFillPass::new(&ctx))).clone();
        let doc = doc.clone();
        self.slot(n).evaluation.request(move |_| {
            let limits = ctx.device.limits();
            evaluate_within(&ctx, &fill, &doc, &view, &limits)
        });
    }

    /// Cuts every isosurface object `n`'s state asks for, from the grid it shows, in the
    /// background; [`Self::poll`] shows them when they are done.
    pub fn update_isosurfaces(&mut self, n: usize, doc: &Arc<Document>, state: &ObjectState) {
        let computed = self.slot(n).computed.clone();
        let cache = self.slot(n).surface.clone();
        let progress = self.slot(n).surface_progress.clone();
        let (doc, volume) = (doc.clone(), state.volume);
        let levels: Vec<IsosurfaceSettings> = state.all_isosurfaces().copied().collect();
        let (surface, selection) = (state.surface, state.selection.clone());
        let max_bytes = self.ctx.device.limits().max_buffer_size;
        self.slot(n).extraction.request(move |cancel| {
            let grid = computed.as_deref().or(doc.volumes.get(volume));
            let (mut meshes, note) = grid.map(|g| isosurfaces_within(g, &levels, max_bytes)).unwrap_or_default();
            let shown = (&*doc, &surface, selection.as_str(), grid);
            let (built, surface_note) = molecular_surface_cached(&cache, shown, max_bytes, (cancel, &progress));
            progress.store(0, Ordering::Relaxed);
            meshes.extend(built);
            prepared((meshes, note.into_iter().chain(surface_note).reduce(|a, b| format!("{a}; {b}"))))
        });
    }

    /// Makes object `n`'s isosurfaces with `make` in the background (the newest request wins);
    /// `make` gets the largest buffer this device makes (bytes). [`Self::poll_meshes`] shows
    /// them when they are done.
    pub fn request_meshes(&mut self, n: usize, make: impl FnOnce(u64) -> Meshes + Send + 'static) {
        let max_bytes = self.ctx.device.limits().max_buffer_size;
        self.slot(n).extraction.request(move |_| prepared(make(max_bytes)));
    }

    /// Shows object `n`'s isosurfaces if their job finished: `Ok` with the triangle count and
    /// any note, or the failure.
    pub fn poll_meshes(&mut self, n: usize) -> Option<Result<(usize, Option<String>), String>> {
        let result = self.slot(n).extraction.poll()?;
        self.generation += 1;
        Some(result.and_then(|(meshes, trees, note)| {
            let (ctx, layer) = (&self.ctx, self.renderer.layer_mut(&self.ctx, n));
            guarded(&ctx.device, || {
                layer.surfaces.set_meshes_with_trees(ctx, &meshes, trees);
                Ok(())
            })
            .map_err(|e| e.to_string())?;
            Ok((meshes.iter().map(|(m, _)| m.triangle_count()).sum(), note))
        }))
    }

    /// Shows what object `n`'s finished jobs made; returns what to tell the user (`Err`: a
    /// failure) and whether a newly evaluated grid is shown.
    pub fn poll(&mut self, n: usize, doc: &Arc<Document>, state: &ObjectState) -> (Vec<Result<String, String>>, bool) {
        let mut said = Vec::new();
        let mut evaluated = false;
        if let Some(result) = self.slot(n).evaluation.poll() {
            let result = result.and_then(|r| r.map_err(|e| e.to_string()));
            if let Ok((_, Some(note))) = &result {
                said.push(Ok(note.clone()));
            }
            let shown = result.and_then(|(evaluated, _)| {
                let Some(evaluated) = evaluated else { return Ok(None) };
                let (ctx, layer) = (&self.ctx, self.renderer.layer_mut(&self.ctx, n));
                guarded(&ctx.device, || evaluated.show(ctx, layer)).map(Some).map_err(|e| e.to_string())
            });
            match shown {
                Ok(grid) => {
                    evaluated = grid.is_some();
                    self.slot(n).computed = grid.map(Arc::new);
                    self.generation += 1;
                    self.update_isosurfaces(n, doc, state);
                }
                Err(e) => said.push(Err(format!("{}: {e}", doc.source))),
            }
        }
        match self.poll_meshes(n) {
            Some(Ok((0, _))) | None => {}
            Some(Ok((triangles, note))) => said
                .push(Ok(note.map_or(format!("isosurfaces: {triangles} triangles"), |note| {
                    format!("{note}: {triangles} triangles")
                }))),
            Some(Err(e)) => said.push(Err(format!("{}: isosurfaces: {e}", doc.source))),
        }
        (said, evaluated)
    }

    /// What runs in the background for the scene, in words, and how far it is when that is
    /// known (`None`: nothing runs).
    pub fn busy(&self) -> Option<(&'static str, Option<f32>)> {
        let surface = self.slots.iter().map(|s| s.surface_progress.load(Ordering::Relaxed)).max().unwrap_or(0);
        if self.slots.iter().any(|s| s.evaluation.is_busy()) {
            Some(("evaluating on the grid…", None))
        } else if surface > 0 {
            Some(("building the molecular surface…", Some(surface as f32 / 1000.0)))
        } else if self.slots.iter().any(|s| s.extraction.is_busy()) {
            Some(("cutting surfaces…", None))
        } else {
            None
        }
    }

    /// Stops every background job of the scene (what they would have shown is dropped).
    pub fn cancel_jobs(&mut self) {
        for s in &mut self.slots {
            s.evaluation.cancel();
            s.extraction.cancel();
        }
    }

    /// How long the last complete picture took to draw (ms), once.
    pub fn take_picture_ms(&mut self) -> Option<f64> {
        self.picture_ms.take()
    }

    /// Object `n`'s values on the grid it shows, when they are not one of its document's (an
    /// orbital or density computed from a basis): isosurfaces are cut from it.
    pub fn computed_grid(&self, n: usize) -> Option<&VolumeGrid> {
        self.slots.get(n)?.computed.as_deref()
    }

    fn slot(&mut self, n: usize) -> &mut ObjectJobs {
        while self.slots.len() <= n {
            let repaint = self.repaint.clone();
            let again = self.repaint.clone();
            self.slots.push(ObjectJobs {
                computed: None,
                evaluation: Latest::new("evaluating the orbital", move || repaint()),
                extraction: Latest::new("cutting isosurfaces", move || again()),
                surface: Arc::default(),
                surface_progress: Arc::default(),
            });
        }
        &mut self.slots[n]
    }

    /// Restyles, recolours and reselects object `n`'s atoms (positions stay on the GPU).
    pub fn set_atom_look(&mut self, n: usize, doc: &Document, state: &crate::scene::ObjectState) {
        let look = crate::headless::atom_look(doc, &state.settings, &state.selection);
        let atoms = &mut self.renderer.layer_mut(&self.ctx, n).atoms;
        atoms.set_look(&self.ctx, state.settings.atoms, &look);
        atoms.depth_cue = state.settings.depth_cue;
        self.generation += 1;
    }

    /// Puts object `n`'s molecule anew (another model or frame of a structure).
    pub fn set_atoms(&mut self, n: usize, doc: &Document, state: &crate::scene::ObjectState) {
        crate::headless::show_atoms(
            &self.ctx,
            self.renderer.layer_mut(&self.ctx, n),
            doc,
            &state.settings,
            &state.selection,
        );
        self.generation += 1;
    }

    /// Moves object `n` to `placement`.
    pub fn set_placement(&mut self, n: usize, placement: &crate::scene::Placement) {
        self.renderer.layer_mut(&self.ctx, n).world_from_object = placement.world_from_object();
        self.generation += 1;
    }

    /// Shows or hides object `n` whole.
    pub fn set_visible(&mut self, n: usize, visible: bool) {
        self.renderer.layer_mut(&self.ctx, n).visible = visible;
        self.generation += 1;
    }

    /// Keeps the first `n` objects, dropping the GPU data and jobs of the rest (the first
    /// layer is emptied when `n` is 0).
    pub fn truncate(&mut self, n: usize) {
        self.renderer.truncate(n);
        self.slots.truncate(n);
        if n == 0 {
            self.renderer.main().clear(&self.ctx);
        }
        self.generation += 1;
    }

    /// Removes object `n`; the objects after it move down by one.
    pub fn remove_object(&mut self, n: usize) {
        self.renderer.remove(&self.ctx, n);
        if n < self.slots.len() {
            self.slots.remove(n);
        }
        self.generation += 1;
    }

    /// Shows slot `slot` of a scan at θ (both key volumes and the twisted skeleton).
    pub fn show_scan(
        &mut self,
        scene: &ScanScene,
        slot: usize,
        theta: f64,
        mode: crate::scene::Interpolation,
        style: crate::scene::AtomStyle,
    ) {
        scene.show(&self.ctx, &mut self.renderer, slot, theta, mode, style);
        self.scan_shown = Some((theta, mode));
        self.generation += 1;
    }

    /// Shows the view in the remaining space of `ui`, applying mouse and keyboard input to
    /// `view.camera`.
    pub fn show(&mut self, ui: &mut egui::Ui, render_state: &egui_wgpu::RenderState, view: &mut ViewState) {
        self.show_twistable(ui, render_state, view, None);
    }

    /// [`Self::show`] for a scan view: returns the twist dragged this frame, as a fraction of
    /// the view's width (positive to the right).
    pub fn show_twistable(
        &mut self,
        ui: &mut egui::Ui,
        render_state: &egui_wgpu::RenderState,
        view: &mut ViewState,
        twist: Option<TwistInput>,
    ) -> f32 {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        let ppp = ui.ctx().pixels_per_point();
        let size = [(rect.width() * ppp).round().max(1.0) as u32, (rect.height() * ppp).round().max(1.0) as u32];
        let mut twisted = 0.0;
        if let Some(t) = twist {
            if response.drag_started_by(PointerButton::Primary) {
                self.layout = Some((rect, size));
                let on_bond = t.bond.zip(response.interact_pointer_pos()).is_some_and(|(bond, p)| {
                    let ends = (self.to_screen(&view.camera, bond[0]), self.to_screen(&view.camera, bond[1]));
                    matches!(ends, (Some(a), Some(b)) if distance_to_segment(p, a, b) < BOND_GRAB)
                });
                self.twisting = t.drag_twists || on_bond;
            }
            if !response.dragged() {
                self.twisting = false;
            }
            if self.twisting && response.dragged_by(PointerButton::Primary) {
                twisted = response.drag_delta().x / rect.width().max(1.0);
            }
        }
        if !self.twisting {
            handle_input(ui, &response, view);
        }
        self.shown_size = Some(size);
        let drawn = ViewState { settings: self.detail.apply(view.settings), ..*view };
        let size = self.detail.render_size(size);
        if self.target.as_ref().is_none_or(|(t, _)| t.size != size) {
            let target = OffscreenTarget::new(&self.ctx.device, size);
            let mut egui_renderer = render_state.renderer.write();
            let id = match self.target.take() {
                Some((_, id)) => {
                    egui_renderer.update_egui_texture_from_wgpu_texture(
                        &self.ctx.device,
                        &target.encoded_view,
                        wgpu::FilterMode::Linear,
                        id,
                    );
                    id
                }
                None => egui_renderer.register_native_texture(
                    &self.ctx.device,
                    &target.encoded_view,
                    wgpu::FilterMode::Linear,
                ),
            };
            self.target = Some((target, id));
            self.drawn = None;
        }
        let clouds: Vec<VolumeSettings> = if self.clouds.is_empty() {
            vec![drawn.settings.volume]
        } else {
            self.clouds
                .iter()
                .map(|&volume| self.detail.apply(RenderSettings { volume, ..drawn.settings }).volume)
                .collect()
        };
        self.renderer.set_lod_scale(self.detail.lod_scale);
        let key = (drawn, clouds, size, self.generation, self.detail.lod_scale.to_bits());
        if let Some((target, id)) = &self.target {
            let changed = self.drawn.as_ref() != Some(&key);
            if changed {
                self.picture_started = Some(Instant::now());
                // A costly frame (orbitals evaluated per sample, or any frame on a CPU rasteriser)
                // is drawn in bands over several UI frames, so the window answers while the
                // picture fills in; a cheap one still takes one band.
                let cpu = self.ctx.info.device_type == wgpu::DeviceType::Cpu;
                self.progress =
                    (cpu || self.renderer.is_costly()).then_some(Progress { next_row: 0, rows: self.band_rows });
            }
            if changed || self.progress.is_some() {
                let frame = FrameInput {
                    camera: &key.0.camera,
                    background: key.0.settings.background,
                    clouds: &key.1,
                    size,
                    tile: None,
                };
                match &mut self.progress {
                    None => {
                        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
                        self.renderer.render(&self.ctx, &mut encoder, &target.color_view, &frame);
                        self.ctx.queue.submit([encoder.finish()]);
                        self.picture_ms = self.picture_started.take().map(|t| t.elapsed().as_secs_f64() * 1e3);
                    }
                    Some(p) => {
                        let start = Instant::now();
                        while p.next_row < size[1] && start.elapsed() < FRAME_BUDGET {
                            let rows = p.rows.min(size[1] - p.next_row);
                            let tile = Tile { rect: [0, p.next_row, size[0], rows], first: p.next_row == 0 };
                            let band = Instant::now();
                            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
                            let frame = FrameInput { tile: Some(tile), ..frame };
                            self.renderer.render(&self.ctx, &mut encoder, &target.color_view, &frame);
                            self.ctx.queue.submit([encoder.finish()]);
                            // Waiting here keeps each frame's GPU work within the budget.
                            let _ = self.ctx.device.poll(wgpu::PollType::wait_indefinitely());
                            let per_row = band.elapsed().as_secs_f64() / rows as f64;
                            p.next_row += rows;
                            // At most twice the band before: one band measured fast (its GPU
                            // work overlapping the last) must not turn the rest of the frame
                            // into one band that holds the window for seconds.
                            let most = (2 * rows).min(size[1]);
                            p.rows = ((BAND_TIME.as_secs_f64() / per_row.max(1e-6)) as u32).clamp(1, most);
                        }
                        self.band_rows = p.rows;
                        if p.next_row >= size[1] {
                            self.progress = None;
                            self.picture_ms = self.picture_started.take().map(|t| t.elapsed().as_secs_f64() * 1e3);
                        } else {
                            ui.ctx().request_repaint();
                        }
                    }
                }
                self.drawn = Some(key);
                self.awaiting_fragments = self.renderer.has_translucent();
                if !self.awaiting_fragments {
                    self.fragments = None;
                }
            }
            let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
            ui.painter().image(*id, rect, uv, egui::Color32::WHITE);
        }
        self.check_fragments(ui.ctx());
        self.layout = Some((rect, size));
        // Hover: read the id under the pointer when it moved and no button is held.
        let pointer = response.hover_pos().filter(|_| !ui.input(|i| i.pointer.any_down()));
        if pointer != self.hovered_at {
            self.hovered_at = pointer;
            self.hovered = pointer.and_then(|pos| self.pick_at(pos).ok().flatten());
        }
        if response.clicked_by(PointerButton::Primary)
            && let Some(pos) = response.interact_pointer_pos()
        {
            // Shift as it was at the release (the frame's modifiers may already have moved on).
            let shift = ui.input(|i| {
                i.events
                    .iter()
                    .rev()
                    .find_map(|e| match e {
                        egui::Event::PointerButton {
                            button: PointerButton::Primary,
                            pressed: false,
                            modifiers,
                            ..
                        } => Some(modifiers.shift),
                        _ => None,
                    })
                    .unwrap_or(i.modifiers.shift)
            });
            match self.pick_at(pos) {
                Ok(picked) => self.click = Some(Click { picked, shift }),
                Err(e) => log::warn!("picking failed: {e}"),
            }
        }
        twisted
    }

    /// Reads the last frame's fragment counts once they are back: a frame whose lists
    /// overflowed is drawn again, in as many bands as it needs.
    fn check_fragments(&mut self, ctx: &egui::Context) {
        if !self.awaiting_fragments {
            return;
        }
        let _ = self.ctx.device.poll(wgpu::PollType::Poll);
        match self.renderer.poll_fragments() {
            Some(stats) => {
                self.awaiting_fragments = false;
                if !stats.fits() {
                    self.drawn = None;
                    ctx.request_repaint();
                }
                self.fragments = Some(stats);
            }
            None => ctx.request_repaint(),
        }
    }

    /// What the translucent surfaces of the last frame took: fragments, and bands when the
    /// frame needed more than the lists hold.
    pub fn fragment_note(&self) -> Option<String> {
        let s = self.fragments?;
        let millions = |n: u32| n as f64 / 1e6;
        Some(
            match (s.fits(), s.bands) {
                (true, 1) => format!("translucent: {:.2} M fragments, exact order", millions(s.needed)),
                (true, b) => format!(
                    "translucent: drawn in {b} bands of at most {:.2} M fragments, exact order",
                    millions(s.capacity)
                ),
                (false, _) => format!(
                    "translucent: {:.2} M fragments in a band, over the {:.2} M the lists hold: drawing again in more bands",
                    millions(s.needed),
                    millions(s.capacity)
                ),
            } + &if s.deep_pixels > 0 {
                format!("; {} pixels with over 48 layers show their nearest 48", s.deep_pixels)
            } else {
                String::new()
            },
        )
    }

    /// What the frame on screen (the one just drawn) shows at window position `pos`.
    fn pick_at(&self, pos: egui::Pos2) -> Result<Option<PickId>, GpuError> {
        let Some((rect, size)) = self.layout else { return Ok(None) };
        let rel = (pos - rect.min) / rect.size();
        self.renderer.pick(&self.ctx, [(rel.x * size[0] as f32) as u32, (rel.y * size[1] as f32) as u32])
    }

    /// Where world point `p` (bohr) lies on screen in the last frame laid out.
    pub fn to_screen(&self, camera: &crate::scene::Camera, p: glam::Vec3) -> Option<egui::Pos2> {
        let (rect, size) = self.layout?;
        let c = self.renderer.clip_from_world(camera, size) * p.extend(1.0);
        (c.w > 1e-6).then(|| {
            let ndc = c.truncate() / c.w;
            rect.min + egui::vec2((ndc.x * 0.5 + 0.5) * rect.width(), (0.5 - ndc.y * 0.5) * rect.height())
        })
    }

    /// Renders the current view at `size` and reads it back (for screenshots).
    pub fn snapshot(&mut self, view: &ViewState, size: [u32; 2]) -> Result<image::RgbaImage, GpuError> {
        let target = OffscreenTarget::new(&self.ctx.device, size);
        let mut encoder =
            self.ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("snapshot") });
        let clouds = if self.clouds.is_empty() { vec![view.settings.volume] } else { self.clouds.clone() };
        let frame = FrameInput {
            camera: &view.camera,
            background: view.settings.background,
            clouds: &clouds,
            size,
            tile: None,
        };
        self.renderer.render(&self.ctx, &mut encoder, &target.color_view, &frame);
        self.ctx.queue.submit([encoder.finish()]);
        // The viewport's own frame must be redrawn: the renderer's buffers changed size.
        self.drawn = None;
        target.read_rgba(&self.ctx.device, &self.ctx.queue)
    }

    /// How much of a frame drawn in bands is done (0..1); `None` when none is under way.
    pub fn progress(&self) -> Option<f32> {
        let p = self.progress?;
        Some(p.next_row as f32 / self.rendered_size()?[1].max(1) as f32)
    }

    /// The view's size on screen, pixels.
    pub fn size(&self) -> Option<[u32; 2]> {
        self.shown_size
    }

    /// The size of the last frame drawn (smaller than [`Self::size`] while interacting on a CPU
    /// adapter).
    pub fn rendered_size(&self) -> Option<[u32; 2]> {
        self.target.as_ref().map(|(t, _)| t.size)
    }
}

fn distance_to_segment(p: egui::Pos2, a: egui::Pos2, b: egui::Pos2) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_sq().max(1e-6)).clamp(0.0, 1.0);
    (p - (a + t * ab)).length()
}

fn handle_input(ui: &egui::Ui, response: &egui::Response, view: &mut ViewState) {
    let clip_drag = ui.input(|i| i.modifiers.command) && view.settings.volume.clip.enabled;
    if clip_drag && response.dragged_by(PointerButton::Primary) {
        // Ctrl + drag moves the clipping plane: a view height of drag is the camera distance.
        let h = response.rect.height().max(1.0);
        view.settings.volume.clip.offset -= response.drag_delta().y / h * view.camera.distance * 0.5;
        return;
    }
    let cam = &mut view.camera;
    if response.dragged_by(PointerButton::Primary) {
        let d = response.drag_delta();
        cam.orbit(-d.x * DRAG_ROTATE, d.y * DRAG_ROTATE);
    }
    if response.dragged_by(PointerButton::Secondary) || response.dragged_by(PointerButton::Middle) {
        let d = response.drag_delta();
        let h = response.rect.height().max(1.0);
        cam.pan(d.x / h, d.y / h);
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            cam.zoom((-scroll * 0.002).exp());
        }
    }
    // Keys act whenever no text field has focus.
    if ui.ctx().egui_wants_keyboard_input() {
        return;
    }
    ui.input(|i| {
        // Shift + arrows belong to the orbital browser.
        if i.modifiers.shift {
            return;
        }
        let step = |k| i.key_pressed(k) as i32 as f32;
        cam.orbit(
            (step(Key::ArrowLeft) - step(Key::ArrowRight)) * KEY_ROTATE,
            (step(Key::ArrowUp) - step(Key::ArrowDown)) * KEY_ROTATE,
        );
        if i.key_pressed(Key::Plus) || i.key_pressed(Key::Equals) || i.key_pressed(Key::PageUp) {
            cam.zoom(1.0 / KEY_ZOOM);
        }
        if i.key_pressed(Key::Minus) || i.key_pressed(Key::PageDown) {
            cam.zoom(KEY_ZOOM);
        }
    });
}

/// The object's molecular surface with its look (nothing when it is off), from `cache` when the
/// geometry and atoms are those it was built for, coloured (by atoms, or by `grid`, the volume
/// the object shows); a note when it was built coarser or failed.
fn molecular_surface_cached(
    cache: &Mutex<Option<BuiltSurface>>,
    (doc, settings, selection, grid): (&Document, &SurfaceSettings, &str, Option<&VolumeGrid>),
    max_bytes: u64,
    (cancel, progress): (&AtomicBool, &AtomicU32),
) -> (Option<(Mesh, SurfaceLook)>, Option<String>) {
    if settings.choice == SurfaceChoice::Off {
        return (None, None);
    }
    let atoms = fingerprint(doc, selection);
    let mut cache = cache.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let fresh = cache.as_ref().is_some_and(|b| b.atoms == atoms && b.settings.same_geometry(settings));
    if !fresh {
        match molecular_surface(doc, settings, selection, max_bytes, (cancel, progress)) {
            Ok(Some((mesh, note))) => *cache = Some(BuiltSurface { settings: *settings, atoms, mesh, note }),
            Ok(None) => return (None, None),
            Err(e) => return (None, Some(format!("molecular surface: {e}"))),
        }
    }
    let built = cache.as_ref().expect("just built");
    let mut mesh = built.mesh.clone();
    crate::headless::color_surface(&mut mesh, doc, settings, selection, grid);
    (Some((mesh, settings.look())), built.note.clone())
}
