//! The 3D view inside the window: renders through the shared [`Renderer`] into an offscreen
//! texture that egui shows as an image, and turns mouse and keys into camera moves.

use egui::{Key, PointerButton, Sense};

use super::detail::Detail;
use super::jobs::Latest;
use super::progressive::{Progressive, Turn};
use super::state::{DRAG_ROTATE, KEY_ROTATE, KEY_ZOOM, ViewState};
use crate::evaluate::interaction::{self, Kind};
use crate::evaluate::meshes::{color_isosurfaces, isosurfaces_within, molecular_surface};
use crate::evaluate::{Evaluated, WavefunctionView, evaluate_within};
use crate::gpu::context::guarded;
use crate::gpu::frame::PickId;
use crate::gpu::gto::GtoFillPass;
use crate::gpu::oit::FragmentStats;
use crate::gpu::{FrameInput, GpuContext, GpuError, OffscreenTarget, Renderer};
use crate::layers::key_volumes::ScanScene;
use crate::model::isosurface::Mesh;
use crate::model::{Document, VolumeGrid};
use crate::scene::objects::Part;
use crate::scene::translucency::SurfaceLook;
use crate::scene::{ClipPlane, ObjectState, Source, SurfaceChoice, SurfaceSettings, VolumeSettings};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

/// What a frame drew: the view, the clouds, the size, the scene's generation and the bits of
/// the level-of-detail scale; a frame is drawn again when any of them changes.
type Drawn = (ViewState, Vec<VolumeSettings>, [u32; 2], u64, u32);

/// A click in the view: what the frame showed under the pointer, and whether Shift was held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Click {
    pub picked: Option<PickId>,
    pub shift: bool,
}

/// One pane of a split view, as the caller describes it each frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Pane {
    pub camera: crate::scene::Camera,
    /// Which renderer layers it draws ([`Viewport::pane_layers`]).
    pub layers: Vec<bool>,
    /// What it shows, in words (written at its top).
    pub label: String,
}

/// What a pane's picture was drawn from: its pane, clouds, size, background and the scene's
/// generation; drawn again when any of them changes.
type PaneDrawn = (Pane, Vec<VolumeSettings>, [u32; 2], [f32; 3], u64);

/// A pane's picture on the GPU and in egui.
struct PaneTarget {
    target: OffscreenTarget,
    id: egui::TextureId,
    drawn: Option<PaneDrawn>,
}

/// How a drag in a scan view twists the dihedral (Naka et al.: horizontal drag changes the value).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TwistInput {
    /// Every primary drag twists (else the view orbits, unless the drag starts on the bond).
    pub drag_scans: bool,
    /// The rotatable bond (world, bohr): a drag that starts on it twists.
    pub bond: Option<[glam::Vec3; 2]>,
    /// A drag that starts on the bond moves its atom to the pointer (a bond length, an angle)
    /// rather than the coordinate by the drag's horizontal length.
    pub direct: bool,
}

/// What a drag in a scan's view asks of the coordinate.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Twist {
    /// The drag's horizontal length as a fraction of the view's width.
    pub along: f32,
    /// Where the pointer holds the grabbed atom (points, in the window).
    pub pointer: Option<egui::Pos2>,
    /// The pane of a split view the drag is in.
    pub pane: usize,
}

/// The note for a document's data set `i` shown at every `step`-th point (`None` when whole).
fn coarser(doc: &Document, i: usize, step: usize) -> Option<String> {
    let grid = doc.volumes.get(i).filter(|_| step > 1)?;
    Some(crate::layers::coarser_note(&doc.source, grid.dims, step))
}

/// An offscreen target of `size` shown through an egui texture: `old`'s texture id when given
/// (it then shows the new target), else a new one.
fn egui_target(
    device: &wgpu::Device,
    render_state: &egui_wgpu::RenderState,
    size: [u32; 2],
    old: Option<egui::TextureId>,
) -> (OffscreenTarget, egui::TextureId) {
    let target = OffscreenTarget::new(device, size);
    let mut egui_renderer = render_state.renderer.write();
    let filter = wgpu::FilterMode::Linear;
    let id = match old {
        Some(id) => {
            egui_renderer.update_egui_texture_from_wgpu_texture(device, &target.encoded_view, filter, id);
            id
        }
        None => egui_renderer.register_native_texture(device, &target.encoded_view, filter),
    };
    (target, id)
}

/// Makes `slot` an [`egui_target`] of `size`, keeping its texture id; true when it was made anew.
fn sized_target(
    slot: &mut Option<(OffscreenTarget, egui::TextureId)>,
    device: &wgpu::Device,
    render_state: &egui_wgpu::RenderState,
    size: [u32; 2],
) -> bool {
    if slot.as_ref().is_some_and(|(t, _)| t.size == size) {
        return false;
    }
    *slot = Some(egui_target(device, render_state, size, slot.as_ref().map(|(_, id)| *id)));
    true
}

/// A thin bar along the bottom of the view, `done` (0..1) of it filled, and the words.
fn progress_bar(painter: &egui::Painter, rect: egui::Rect, done: f32) {
    let bar = egui::Rect::from_min_max(egui::pos2(rect.left(), rect.bottom() - 4.0), rect.right_bottom());
    painter.rect_filled(bar, 0.0, egui::Color32::from_black_alpha(140));
    let filled = egui::Rect::from_min_size(bar.min, egui::vec2(bar.width() * done.clamp(0.0, 1.0), bar.height()));
    painter.rect_filled(filled, 0.0, egui::Color32::from_rgb(90, 160, 255));
    painter.text(
        bar.left_top() + egui::vec2(6.0, -4.0),
        egui::Align2::LEFT_BOTTOM,
        format!("refining {:.0} %", 100.0 * done),
        egui::FontId::proportional(12.0),
        egui::Color32::from_gray(220),
    );
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

/// What the viewport keeps per renderer layer besides the layer.
struct LayerJobs {
    /// A quantity's values on its grid when computed from a basis (cube files' grids stay in the
    /// document): isosurfaces are cut from it.
    computed: Option<Arc<VolumeGrid>>,
    /// Direct mode's orbital measured at samples (its opacity and σ without a grid).
    sampled: Option<Arc<crate::evaluate::Sampled>>,
    /// Orbitals filled on the GPU and densities evaluated on the CPU, with a note when the grid
    /// had to be coarser than asked.
    evaluation: Latest<Evaluation>,
    /// A quantity's isosurfaces (marching cubes over its grid), or an atoms layer's molecular
    /// surface.
    extraction: Latest<Prepared>,
    /// The last molecular surface built, kept while only its look changes (an isosurface
    /// slider moving does not build it again).
    surface: Arc<Mutex<Option<BuiltSurface>>>,
    /// Thousandths of the molecular surface being built (the status line's bar); 0 when none is.
    surface_progress: Arc<AtomicU32>,
    /// The map a quantity's isosurfaces are coloured with by another quantity, and that
    /// quantity's name (for the colour bar).
    iso_map: Arc<Mutex<Option<(crate::scene::coloring::ValueMap, String)>>>,
    /// An atoms layer's atoms displaced along a mode: (mode, phase bits, amplitude bits).
    displaced: Option<(usize, u64, u32)>,
}

/// A molecular surface with what it was built from: its settings and the atoms' fingerprint.
struct BuiltSurface {
    settings: SurfaceSettings,
    atoms: (usize, [u64; 3]),
    mesh: Mesh,
    note: Option<String>,
    /// The map of values it was last coloured with (for the view's colour bar).
    map: Option<crate::scene::coloring::ValueMap>,
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
    /// The schedule of a costly picture drawn in bands over several frames.
    progressive: Progressive,
    /// The state the texture currently shows; a frame is drawn only when this changes.
    drawn: Option<Drawn>,
    /// Bumped whenever the renderer's data changes.
    generation: u64,
    /// Which object and part each renderer layer draws ([`layer_parts`]); empty for a view of
    /// one layer (a scan's).
    parts: Vec<(usize, Part)>,
    /// Per renderer layer: its computed grid and its background jobs.
    slots: Vec<LayerJobs>,
    /// Wakes the window when a job ends.
    repaint: Arc<dyn Fn() + Send + Sync>,
    /// Each layer's cloud settings (set by the caller each frame, [`Self::set_clouds`]).
    pub clouds: Vec<VolumeSettings>,
    /// The last click, until the caller takes it.
    pub click: Option<Click>,
    /// The scene's documents, which a quantity's fragments may name (set by the caller before
    /// quantities are shown).
    pub documents: Vec<Arc<Document>>,
    /// A click on a picture still being drawn: where, and whether Shift was held. It is picked
    /// once the whole picture (and so every pixel's id) is there.
    pending_click: Option<(egui::Pos2, bool)>,
    /// What is under the resting pointer (hover highlight), and where the pointer was.
    pub hovered: Option<PickId>,
    hovered_at: Option<egui::Pos2>,
    /// Where the view was laid out, and the size it was drawn at (for overlays).
    layout: Option<(egui::Rect, [u32; 2])>,
    /// Whether the current drag twists the dihedral.
    twisting: bool,
    /// Whether that drag started on the coordinate's bond: the grabbed atom follows the pointer.
    grabbed: bool,
    /// The coarse picture shown while a costly frame is drawn ([`Detail::PREVIEW`]).
    preview: Option<(OffscreenTarget, egui::TextureId)>,
    /// A frame with translucent surfaces was drawn and its fragment counts are not back yet.
    awaiting_fragments: bool,
    /// The last frame's fragment counts, when it had translucent surfaces.
    fragments: Option<FragmentStats>,
    /// The panes of a split view (none while the view is one).
    split: Vec<PaneTarget>,
    /// Where each pane was laid out, and the size it was drawn at.
    pane_layout: Vec<(egui::Rect, [u32; 2])>,
    /// The key volumes of the objects that are frames of a scan, by object.
    scan_keys: std::collections::BTreeMap<usize, Arc<ScanScene>>,
    /// The plane map's frame drawn: the object and its lines.
    plane_frame: Option<(usize, Vec<[glam::Vec3; 2]>)>,
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
            progressive: Progressive::default(),
            drawn: None,
            generation: 0,
            parts: Vec::new(),
            slots: Vec::new(),
            repaint: Arc::new(|| {}),
            clouds: Vec::new(),
            click: None,
            documents: Vec::new(),
            pending_click: None,
            hovered: None,
            hovered_at: None,
            layout: None,
            twisting: false,
            grabbed: false,
            preview: None,
            awaiting_fragments: false,
            fragments: None,
            split: Vec::new(),
            pane_layout: Vec::new(),
            scan_keys: Default::default(),
            plane_frame: None,
        }
    }

    /// The renderer layer that draws `part` of object `n`.
    fn layer_of(&self, n: usize, part: Part) -> Option<usize> {
        self.parts.iter().position(|&p| p == (n, part))
    }

    /// The layers that draw object `n`.
    fn layers_of(&self, n: usize) -> std::ops::Range<usize> {
        let first = self.parts.iter().position(|&(o, _)| o == n).unwrap_or(self.parts.len());
        let count = self.parts.iter().filter(|&&(o, _)| o == n).count();
        first..first + count
    }

    /// Inserts an empty layer at `l` drawing `part` of object `n`, with jobs of its own.
    fn insert_layer(&mut self, l: usize, n: usize, part: Part) {
        self.renderer.insert(&self.ctx, l);
        self.parts.insert(l, (n, part));
        let slot = self.new_slot();
        self.slots.insert(l.min(self.slots.len()), slot);
        self.generation += 1;
    }

    /// Removes layer `l` and its jobs.
    fn remove_layer(&mut self, l: usize) {
        self.renderer.remove(&self.ctx, l);
        self.parts.remove(l);
        if l < self.slots.len() {
            let mut slot = self.slots.remove(l);
            slot.evaluation.cancel();
            slot.extraction.cancel();
        }
        self.generation += 1;
    }

    /// Puts object `n` of the scene on the GPU, in place of what it showed (or after the last
    /// object): its atoms with its placement, and each of its quantities ([`Self::set_quantity`];
    /// orbitals, densities and isosurfaces follow in the background). Returns a note when a data
    /// set is more than the GPU holds and is shown coarser.
    pub fn set_object(
        &mut self,
        n: usize,
        doc: &Arc<Document>,
        state: &ObjectState,
    ) -> Result<Option<String>, GpuError> {
        let old = self.layers_of(n);
        let at = old.start;
        for l in old.rev() {
            self.remove_layer(l);
        }
        self.insert_layer(at, n, Part::Atoms);
        let keys = self.scan_keys.get(&n).cloned();
        let (ctx, layer) = (&self.ctx, self.renderer.layer_mut(&self.ctx, at));
        guarded(&ctx.device, || {
            crate::layers::show_object_atoms(ctx, layer, doc, state);
            layer.clip_centre = clip_centre(doc, keys.as_deref());
            Ok(())
        })?;
        self.update_surface(n, doc, state);
        self.set_arrows(n, doc, state);
        let mut notes = Vec::new();
        for k in 0..state.quantities.len() {
            self.insert_layer(at + 1 + k, n, Part::Quantity(k));
            notes.extend(self.set_quantity(n, k, doc, state)?);
        }
        Ok(notes.into_iter().reduce(|a, b| format!("{a}; {b}")))
    }

    /// Makes object `n`'s quantity layers follow its quantities after some were added or
    /// removed (`before` → `state`): layers of quantities kept at the start and the end stay
    /// with their values and jobs; those between are made anew.
    pub fn relayout_quantities(
        &mut self,
        n: usize,
        doc: &Arc<Document>,
        before: &ObjectState,
        state: &ObjectState,
    ) -> Result<Option<String>, GpuError> {
        let (old, new) = (&before.quantities, &state.quantities);
        let same = |a: &crate::scene::QuantityState, b: &crate::scene::QuantityState| a.source == b.source;
        let prefix = old.iter().zip(new).take_while(|(a, b)| same(a, b)).count();
        let room = old.len().min(new.len()) - prefix;
        let suffix = old.iter().rev().zip(new.iter().rev()).take(room).take_while(|(a, b)| same(a, b)).count();
        let Some(atoms) = self.layer_of(n, Part::Atoms) else { return self.set_object(n, doc, state) };
        for k in (prefix..old.len() - suffix).rev() {
            self.remove_layer(atoms + 1 + k);
        }
        for k in prefix..new.len() - suffix {
            self.insert_layer(atoms + 1 + k, n, Part::Quantity(k));
        }
        // The layers after the change draw quantities renumbered.
        for k in 0..new.len() {
            self.parts[atoms + 1 + k] = (n, Part::Quantity(k));
        }
        let mut notes = Vec::new();
        for k in prefix..new.len() - suffix {
            notes.extend(self.set_quantity(n, k, doc, state)?);
        }
        self.set_visibility(n, state);
        Ok(notes.into_iter().reduce(|a, b| format!("{a}; {b}")))
    }

    /// Shows quantity `k` of object `n`: a data set of the document at once (a note when it is
    /// shown coarser), an orbital or density of its wavefunction evaluated in the background
    /// ([`crate::evaluate::evaluate_wavefunction`]; [`Self::poll`] shows it when it is done). Its
    /// isosurfaces follow.
    pub fn set_quantity(
        &mut self,
        n: usize,
        k: usize,
        doc: &Arc<Document>,
        state: &ObjectState,
    ) -> Result<Option<String>, GpuError> {
        let (Some(l), Some(q)) = (self.layer_of(n, Part::Quantity(k)), state.quantities.get(k)) else {
            return Ok(None);
        };
        let keys = self.scan_keys.get(&n).cloned();
        let (ctx, layer) = (&self.ctx, self.renderer.layer_mut(&self.ctx, l));
        crate::layers::place_layer(layer, state, Part::Quantity(k));
        layer.clip_centre = clip_centre(doc, keys.as_deref());
        self.generation += 1;
        match q.source {
            Source::Scan(_) => {
                let slot = &mut self.slots[l];
                slot.evaluation.cancel();
                slot.sampled = None;
                self.show_scan_view(n, k, state);
                Ok(None)
            }
            Source::Volume(i) => {
                let step = guarded(&ctx.device, || layer.set_volume(ctx, doc.volumes.get(i)))?;
                let slot = &mut self.slots[l];
                slot.evaluation.cancel();
                slot.computed = None;
                slot.sampled = None;
                self.update_isosurfaces(n, k, doc, state);
                Ok(coarser(doc, i, step))
            }
            // Spherical atoms' quantities, and the density's of several fragments (NCI), sum
            // every part's density.
            source @ (Source::Promolecular(_) | Source::Wavefunction(_))
                if let Some((kind, quantity)) = interaction::of_source(source, &q.fragments) =>
            {
                self.request_interaction(l, kind, doc, q, state, quantity);
                Ok(None)
            }
            Source::Promolecular(_) => Ok(None),
            Source::Wavefunction(quantity) => {
                let e = &state.evaluation;
                let functions = doc.wavefunction.as_ref().and_then(|wf| e.restriction(&wf.basis));
                // Direct mode fills a grid only for what cuts or colours from one.
                let grid = q.wants_grid() || (k == state.selected && state.surface.color_by_volume);
                let view = WavefunctionView { quantity, direct: e.direct, points: e.grid_points, functions, grid };
                let ctx = self.ctx.clone();
                let fill = self.fill.get_or_insert_with(|| Arc::new(GtoFillPass::new(&ctx))).clone();
                let doc = doc.clone();
                self.slots[l].evaluation.request(move |_| {
                    let limits = ctx.device.limits();
                    evaluate_within(&ctx, &fill, &doc, &view, &limits)
                });
                Ok(None)
            }
        }
    }

    /// Evaluates `quantity` of the summed densities of an interaction (`q`'s fragments, the
    /// spherical atoms' for `kind` [`Kind::Spherical`]) on the CPU into layer `l`.
    fn request_interaction(
        &mut self,
        l: usize,
        kind: Kind,
        doc: &Arc<Document>,
        q: &crate::scene::QuantityState,
        state: &ObjectState,
        quantity: crate::model::orbitals::Quantity,
    ) {
        let (doc, fragments, points) = (doc.clone(), q.fragments.clone(), state.evaluation.grid_points);
        let others = self.documents.clone();
        self.slots[l].evaluation.request(move |_| {
            // What cannot be made (an element without an atomic density, a selection that picks
            // no atom, a fragment not open) is said, and nothing is shown.
            Ok(match interaction::grid(&doc, kind, &fragments, &others, quantity, points) {
                Ok(grid) => {
                    let note = (kind == Kind::Spherical).then(|| interaction::note(&doc)).flatten();
                    (Some(Evaluated::of_values(grid)), note)
                }
                Err(why) => (None, Some(why)),
            })
        });
    }

    /// Draws the plane map's frame `lines` (object `n`'s frame) with object `n`'s atoms; none
    /// when empty. Uploaded only when they changed.
    pub fn show_plane_frame(&mut self, n: usize, lines: Vec<[glam::Vec3; 2]>) {
        let wanted = (!lines.is_empty()).then_some((n, lines));
        if self.plane_frame == wanted {
            return;
        }
        if let Some(l) = self.plane_frame.as_ref().and_then(|(was, _)| self.layer_of(*was, Part::Atoms)) {
            self.renderer.layer_mut(&self.ctx, l).plane_frame.set_lines(&self.ctx, &[], PLANE_FRAME_COLOR);
        }
        if let Some((n, lines)) = &wanted
            && let Some(l) = self.layer_of(*n, Part::Atoms)
        {
            self.renderer.layer_mut(&self.ctx, l).plane_frame.set_lines(&self.ctx, lines, PLANE_FRAME_COLOR);
        }
        self.plane_frame = wanted;
        self.generation += 1;
    }

    /// Gives object `n` the key volumes of the scan it is a frame of (`None`: it is none); its
    /// [`Source::Scan`] quantities draw from them. Set before [`Self::set_object`].
    pub fn set_scan_keys(&mut self, n: usize, keys: Option<Arc<ScanScene>>) {
        match keys {
            Some(keys) => self.scan_keys.insert(n, keys),
            None => self.scan_keys.remove(&n),
        };
    }

    /// Object `n`'s scan view `k` at the scan's value: the mixing weight of its key volumes (the
    /// bind groups stay while the value is between the same two), the values at the value
    /// mixed for its isosurfaces and the panels, and the isosurfaces cut again.
    fn show_scan_view(&mut self, n: usize, k: usize, state: &ObjectState) {
        let (Some(l), Some(q), Some(scan)) =
            (self.layer_of(n, Part::Quantity(k)), state.quantities.get(k), &state.scan)
        else {
            return;
        };
        let (Source::Scan(slot), Some(keys)) = (q.source, self.scan_keys.get(&n).cloned()) else { return };
        keys.show_view(&self.ctx, self.renderer.layer_mut(&self.ctx, l), slot, scan.value, scan.mode);
        self.generation += 1;
        // The values at the value are mixed (a grid per view and value) only while an isosurface
        // of the view is shown; hiding the last one clears the surfaces once.
        if !q.wants_grid() {
            if self.slots[l].computed.take().is_some() {
                self.slots[l].extraction.request(|_| prepared(Default::default()));
            }
            return;
        }
        let grid = Arc::new(keys.values_at(slot, scan.value));
        self.slots[l].computed = Some(grid.clone());
        let levels = q.isosurfaces.clone();
        let max_bytes = self.ctx.device.limits().max_buffer_size;
        self.slots[l].extraction.request(move |_| prepared(isosurfaces_within(&grid, &levels, max_bytes)));
    }

    /// Moves object `n` (a scan's frame) to its scan's value: the skeleton in place (`doc` is
    /// the frame at the value) and every view's key volumes and isosurfaces.
    pub fn set_scan_frame(&mut self, n: usize, doc: &Document, state: &ObjectState) {
        if let Some(l) = self.layer_of(n, Part::Atoms) {
            let layer = self.renderer.layer_mut(&self.ctx, l);
            if !layer.move_atoms(&self.ctx, &doc.molecule) {
                self.set_atoms(n, doc, state);
            }
        }
        for k in 0..state.quantities.len() {
            self.show_scan_view(n, k, state);
        }
        self.generation += 1;
    }

    /// Cuts every isosurface of object `n`'s quantity `k` from its grid in the background;
    /// [`Self::poll`] shows them when they are done.
    pub fn update_isosurfaces(&mut self, n: usize, k: usize, doc: &Arc<Document>, state: &ObjectState) {
        let (Some(l), Some(q)) = (self.layer_of(n, Part::Quantity(k)), state.quantities.get(k)) else { return };
        if let Source::Scan(_) = q.source {
            return self.show_scan_view(n, k, state);
        }
        let computed = self.slots[l].computed.clone();
        let doc = doc.clone();
        let volume = match q.source {
            Source::Volume(i) => Some(i),
            Source::Wavefunction(_) | Source::Scan(_) | Source::Promolecular(_) => None,
        };
        let levels = q.isosurfaces.clone();
        let max_bytes = self.ctx.device.limits().max_buffer_size;
        let iso_map = self.slots[l].iso_map.clone();
        let (fragments, others) = (q.fragments.clone(), self.documents.clone());
        self.slots[l].extraction.request(move |_| {
            let grid = computed.as_deref().or(volume.and_then(|i| doc.volumes.get(i)));
            let Some(grid) = grid else { return prepared(Default::default()) };
            let (mut meshes, note) = isosurfaces_within(grid, &levels, max_bytes);
            let signed = grid.kind == crate::model::grid::ValueKind::Signed;
            let of = crate::evaluate::meshes::Evaluating { doc: &doc, fragments: &fragments, others: &others };
            let map = color_isosurfaces(of, &levels, signed, &mut meshes);
            *iso_map.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = map;
            prepared((meshes, note))
        });
    }

    /// The map object `n`'s quantity `k` has its isosurfaces coloured with by another quantity,
    /// and that quantity's name.
    pub fn isosurface_map(&self, n: usize, k: usize) -> Option<(crate::scene::coloring::ValueMap, String)> {
        let l = self.layer_of(n, Part::Quantity(k))?;
        self.slots[l].iso_map.lock().unwrap_or_else(std::sync::PoisonError::into_inner).clone()
    }

    /// The map object `n`'s molecular surface is coloured with, when it is coloured by a
    /// volume's values.
    pub fn surface_map(&self, n: usize) -> Option<crate::scene::coloring::ValueMap> {
        let l = self.layer_of(n, Part::Atoms)?;
        let cache = self.slots[l].surface.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        cache.as_ref().and_then(|b| b.map)
    }

    /// Builds (or colours anew) object `n`'s molecular surface in the background, around the
    /// atoms it shows; coloured by the values of its selected quantity when it asks for that.
    pub fn update_surface(&mut self, n: usize, doc: &Arc<Document>, state: &ObjectState) {
        let Some(l) = self.layer_of(n, Part::Atoms) else { return };
        let shown = self.layer_of(n, Part::Quantity(state.selected)).and_then(|q| self.slots[q].computed.clone());
        let volume = state.selected_quantity().and_then(|q| match q.source {
            Source::Volume(i) => Some(i),
            Source::Wavefunction(_) | Source::Scan(_) | Source::Promolecular(_) => None,
        });
        let slot = &self.slots[l];
        let (cache, progress) = (slot.surface.clone(), slot.surface_progress.clone());
        let doc = doc.clone();
        let (surface, selection) = (state.surface, state.selection.clone());
        let max_bytes = self.ctx.device.limits().max_buffer_size;
        self.slots[l].extraction.request(move |cancel| {
            let grid = shown.as_deref().or(volume.and_then(|i| doc.volumes.get(i)));
            let shown = (&*doc, &surface, selection.as_str(), grid);
            let (built, note) = molecular_surface_cached(&cache, shown, max_bytes, (cancel, &progress));
            progress.store(0, Ordering::Relaxed);
            prepared((built.into_iter().collect(), note))
        });
    }

    /// Makes layer `l`'s isosurfaces with `make` in the background (the newest request wins);
    /// `make` gets the largest buffer this device makes (bytes). [`Self::poll_meshes`] shows
    /// them when they are done.
    pub fn request_meshes(&mut self, l: usize, make: impl FnOnce(u64) -> Meshes + Send + 'static) {
        let max_bytes = self.ctx.device.limits().max_buffer_size;
        self.slot(l).extraction.request(move |_| prepared(make(max_bytes)));
    }

    /// Shows layer `l`'s isosurfaces if their job finished: `Ok` with the triangle count and
    /// any note, or the failure.
    pub fn poll_meshes(&mut self, l: usize) -> Option<Result<(usize, Option<String>), String>> {
        let result = self.slot(l).extraction.poll()?;
        self.generation += 1;
        Some(result.and_then(|(meshes, trees, note)| {
            let (ctx, layer) = (&self.ctx, self.renderer.layer_mut(&self.ctx, l));
            guarded(&ctx.device, || {
                layer.surfaces.set_meshes_with_trees(ctx, &meshes, trees);
                Ok(())
            })
            .map_err(|e| e.to_string())?;
            Ok((meshes.iter().map(|(m, _)| m.triangle_count()).sum(), note))
        }))
    }

    /// Shows what object `n`'s finished jobs made; returns what to tell the user (`Err`: a
    /// failure) and the quantities whose newly evaluated values are shown.
    pub fn poll(
        &mut self,
        n: usize,
        doc: &Arc<Document>,
        state: &ObjectState,
    ) -> (Vec<Result<String, String>>, Vec<usize>) {
        let mut said = Vec::new();
        let mut evaluated = Vec::new();
        for l in self.layers_of(n) {
            let Some(result) = self.slots[l].evaluation.poll() else { continue };
            let Part::Quantity(k) = self.parts[l].1 else { continue };
            let result = result.and_then(|r| r.map_err(|e| e.to_string()));
            if let Ok((_, Some(note))) = &result {
                said.push(Ok(note.clone()));
            }
            let shown = result.and_then(|(evaluated, _)| {
                let Some(evaluated) = evaluated else { return Ok(None) };
                let (ctx, layer) = (&self.ctx, self.renderer.layer_mut(&self.ctx, l));
                guarded(&ctx.device, || evaluated.show(ctx, layer)).map(Some).map_err(|e| e.to_string())
            });
            match shown {
                Ok(values) => {
                    if values.is_some() {
                        evaluated.push(k);
                    }
                    let (grid, sampled) = values.map_or((None, None), |v| (v.grid, v.sampled));
                    self.slots[l].computed = grid.map(Arc::new);
                    self.slots[l].sampled = sampled.map(Arc::new);
                    self.generation += 1;
                    self.update_isosurfaces(n, k, doc, state);
                    if k == state.selected && state.surface.color_by_volume {
                        self.update_surface(n, doc, state);
                    }
                }
                Err(e) => said.push(Err(format!("{}: {e}", doc.source))),
            }
        }
        // A scan's isosurfaces are cut at its value: say which (when some arrive).
        let scan = self.scan_keys.get(&n).cloned().zip(state.scan.as_ref());
        let isosurfaces = || {
            scan.as_ref()
                .map_or("isosurfaces".into(), |(k, s)| format!("isosurfaces at {}", k.coordinate_label(s.value)))
        };
        for l in self.layers_of(n) {
            let atoms = self.parts[l].1 == Part::Atoms;
            let meshes = self.poll_meshes(l);
            let what = || if atoms { "molecular surface".to_string() } else { isosurfaces() };
            match meshes {
                Some(Ok((0, _))) | None => {}
                Some(Ok((triangles, note))) => said.push(Ok(note.map_or_else(
                    || format!("{}: {triangles} triangles", what()),
                    |note| format!("{note}: {triangles} triangles"),
                ))),
                Some(Err(e)) => said.push(Err(format!("{}: {}: {e}", doc.source, what()))),
            }
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
        self.progressive.take_ms()
    }

    /// Object `n`'s quantity `k` on its grid, when computed from a basis (an orbital or
    /// density; a data set stays in the document): isosurfaces are cut from it.
    pub fn computed_grid(&self, n: usize, k: usize) -> Option<&VolumeGrid> {
        self.slots.get(self.layer_of(n, Part::Quantity(k))?)?.computed.as_deref()
    }

    /// Object `n`'s quantity `k` measured at samples (direct mode).
    pub fn sampled(&self, n: usize, k: usize) -> Option<&crate::evaluate::Sampled> {
        self.slots.get(self.layer_of(n, Part::Quantity(k))?)?.sampled.as_deref()
    }

    /// The values object `n`'s quantity `k` shows: computed, or the document's data set.
    pub fn shown_grid<'a>(
        &'a self,
        n: usize,
        k: usize,
        doc: &'a Document,
        state: &ObjectState,
    ) -> Option<&'a VolumeGrid> {
        match state.quantities.get(k)?.source {
            Source::Volume(i) => doc.volumes.get(i),
            Source::Wavefunction(_) | Source::Scan(_) | Source::Promolecular(_) => self.computed_grid(n, k),
        }
    }

    fn new_slot(&self) -> LayerJobs {
        let repaint = self.repaint.clone();
        let again = self.repaint.clone();
        LayerJobs {
            computed: None,
            sampled: None,
            evaluation: Latest::new("evaluating the orbital", move || repaint()),
            extraction: Latest::new("cutting isosurfaces", move || again()),
            surface: Arc::default(),
            surface_progress: Arc::default(),
            iso_map: Arc::default(),
            displaced: None,
        }
    }

    /// Layer `l`'s jobs (made for a view of one layer, a scan's).
    fn slot(&mut self, l: usize) -> &mut LayerJobs {
        while self.slots.len() <= l {
            let slot = self.new_slot();
            self.slots.push(slot);
        }
        &mut self.slots[l]
    }

    /// Restyles, recolours and reselects object `n`'s atoms (positions stay on the GPU).
    pub fn set_atom_look(&mut self, n: usize, doc: &Document, state: &ObjectState) {
        let Some(l) = self.layer_of(n, Part::Atoms) else { return };
        let look = crate::layers::atom_look(doc, &state.atoms, &state.selection);
        let atoms = &mut self.renderer.layer_mut(&self.ctx, l).atoms;
        atoms.sizes = crate::layers::sizes(&state.atoms);
        atoms.set_look(&self.ctx, state.atoms.style, &look);
        atoms.depth_cue = state.atoms.depth_cue;
        self.generation += 1;
    }

    /// Puts object `n`'s molecule anew (another model or frame of a structure, or back at the
    /// file's geometry after a mode).
    pub fn set_atoms(&mut self, n: usize, doc: &Document, state: &ObjectState) {
        let Some(l) = self.layer_of(n, Part::Atoms) else { return };
        let layer = self.renderer.layer_mut(&self.ctx, l);
        crate::layers::show_atoms(&self.ctx, layer, doc, &state.atoms, &state.selection);
        self.slots[l].displaced = None;
        self.generation += 1;
    }

    /// Draws the arrows of object `n`'s shown mode (none when no mode or no arrows are asked
    /// for), from the modes' geometry, with its atoms.
    pub fn set_arrows(&mut self, n: usize, doc: &Document, state: &ObjectState) {
        let Some(l) = self.layer_of(n, Part::Atoms) else { return };
        let v = state.vibration;
        let arrows = v.arrows_key().zip(doc.vibrations.as_ref());
        let arrows =
            arrows.and_then(|((mode, _), modes)| crate::model::arrow::mode_arrows(modes, mode, v.amplitude as f64));
        let layer = self.renderer.layer_mut(&self.ctx, l);
        layer.arrows.set_arrows(&self.ctx, &arrows.unwrap_or_default(), crate::scene::vibration::ARROW_COLOR);
        self.generation += 1;
    }

    /// Draws object `n`'s atoms displaced along its shown mode at `phase` (radians), when they
    /// are not there already; the bonds stay the file's. Whether anything was drawn anew.
    pub fn displace_atoms(&mut self, n: usize, doc: &Document, state: &ObjectState, phase: f64) -> bool {
        let (Some(l), Some(v), Some(mode)) = (self.layer_of(n, Part::Atoms), &doc.vibrations, state.vibration.mode)
        else {
            return false;
        };
        let key = (mode, phase.to_bits(), state.vibration.amplitude.to_bits());
        if self.slots[l].displaced == Some(key) {
            return false;
        }
        let Some(positions) = v.displaced(mode, phase, state.vibration.amplitude as f64) else { return false };
        let mut molecule = doc.molecule.clone();
        for (atom, p) in molecule.atoms.iter_mut().zip(positions) {
            atom.position = p;
        }
        let layer = self.renderer.layer_mut(&self.ctx, l);
        // Each frame of the animation moves the atoms in place; only the first uploads them.
        if self.slots[l].displaced.is_none() || !layer.move_atoms(&self.ctx, &molecule) {
            let look = crate::layers::atom_look(doc, &state.atoms, &state.selection);
            let layer = self.renderer.layer_mut(&self.ctx, l);
            layer.atoms.sizes = crate::layers::sizes(&state.atoms);
            layer.set_atoms(&self.ctx, &molecule, state.atoms.style, Some(&look));
            layer.atoms.depth_cue = state.atoms.depth_cue;
        }
        self.slots[l].displaced = Some(key);
        self.generation += 1;
        true
    }

    /// Gives every layer of object `n` its placement and visibility (the object's, and each
    /// quantity's).
    pub fn set_visibility(&mut self, n: usize, state: &ObjectState) {
        for l in self.layers_of(n) {
            let part = self.parts[l].1;
            crate::layers::place_layer(self.renderer.layer_mut(&self.ctx, l), state, part);
        }
        self.generation += 1;
    }

    /// Each layer's cloud for the next frames: a quantity layer's own, none for atoms.
    pub fn set_clouds(&mut self, states: &[&ObjectState]) {
        let hidden = VolumeSettings { visible: false, ..VolumeSettings::default() };
        self.clouds = self
            .parts
            .iter()
            .map(|&(n, part)| match part {
                Part::Atoms => hidden,
                Part::Quantity(k) => states.get(n).and_then(|s| s.quantities.get(k)).map_or(hidden, |q| q.cloud),
            })
            .collect();
    }

    /// The clipping plane each layer of object `n` draws with ((unit n, d), `None` when off).
    pub fn clip_planes(&self, n: usize) -> Vec<Option<glam::Vec4>> {
        let layers = self.layers_of(n).filter_map(|l| self.renderer.layer(l));
        layers.map(|l| l.clip.plane(l.clip_centre)).collect()
    }

    /// Which of the renderer's layers pane `pane` of `count` draws: every object's atoms, and
    /// the quantities drawn in that pane ([`crate::scene::QuantityState::in_pane`]), while the
    /// object and the quantity are shown.
    pub fn pane_layers(&self, states: &[&ObjectState], pane: usize, count: usize) -> Vec<bool> {
        self.parts
            .iter()
            .map(|&(n, part)| {
                let Some(s) = states.get(n) else { return false };
                s.visible
                    && match part {
                        Part::Atoms => true,
                        Part::Quantity(k) => s.quantities.get(k).is_some_and(|q| q.visible && q.in_pane(pane, count)),
                    }
            })
            .collect()
    }

    /// Shows `panes` side by side in the remaining space of `ui`, each drawn whole whenever what
    /// it shows changes. A drag or the keys move the camera of the pane under the pointer
    /// (`view.camera` for the first, `view.panes.cameras` for the others; one camera when
    /// linked); a click picks in the pane clicked ([`Self::click`]).
    pub fn show_split(
        &mut self,
        ui: &mut egui::Ui,
        render_state: &egui_wgpu::RenderState,
        view: &mut ViewState,
        panes: &[Pane],
        twist: Option<TwistInput>,
    ) -> Twist {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        let count = panes.len().max(1);
        let width = rect.width() / count as f32;
        let rects: Vec<egui::Rect> = (0..count)
            .map(|p| {
                egui::Rect::from_min_size(
                    rect.min + egui::vec2(p as f32 * width, 0.0),
                    egui::vec2(width, rect.height()),
                )
            })
            .collect();
        let pointer = response.interact_pointer_pos().or(response.hover_pos());
        let under = pointer.and_then(|pos| rects.iter().position(|r| r.contains(pos))).unwrap_or(0);
        let mut twisted = Twist::default();
        if let (Some(t), Some(&layout)) = (twist, self.pane_layout.get(under)) {
            twisted = self.twist(&response, layout, &view.panes.camera(under, &view.camera), t);
            twisted.pane = under;
        }
        // A drag that moves a scan's coordinate does not move the camera.
        if !self.twisting {
            if view.panes.linked || under == 0 {
                handle_input(ui, &response, view, None);
            } else {
                let mut own = ViewState { camera: view.panes.cameras[under], ..*view };
                handle_input(ui, &response, &mut own, None);
                view.panes.cameras[under] = own.camera;
            }
        }
        let ppp = ui.ctx().pixels_per_point();
        let shown = [(width * ppp).round().max(1.0) as u32, (rect.height() * ppp).round().max(1.0) as u32];
        let size = self.detail.render_size(shown);
        let clouds: Vec<VolumeSettings> = self.clouds.iter().map(|&c| self.detail.cloud(c)).collect();
        for gone in self.split.drain(count.min(self.split.len())..) {
            render_state.renderer.write().free_texture(&gone.id);
        }
        self.pane_layout.clear();
        self.renderer.set_detail(&self.detail);
        for (p, pane) in panes.iter().enumerate() {
            let pane = Pane { camera: fit_width(view.panes.camera(p, &view.camera), size), ..pane.clone() };
            let key = (pane, clouds.clone(), size, view.background, self.generation);
            if self.split.get(p).is_none_or(|t| t.target.size != size) {
                let old = self.split.get(p).map(|t| t.id);
                let (target, id) = egui_target(&self.ctx.device, render_state, size, old);
                let slot = PaneTarget { target, id, drawn: None };
                if p < self.split.len() {
                    self.split[p] = slot;
                } else {
                    self.split.push(slot);
                }
            }
            if self.split[p].drawn.as_ref() != Some(&key) {
                self.draw_pane(&key.0, &clouds, view.background, p);
                self.split[p].drawn = Some(key);
                // The single view's frame is stale: the renderer's targets were drawn for panes.
                self.drawn = None;
            }
            let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
            ui.painter().image(self.split[p].id, rects[p], uv, egui::Color32::WHITE);
            ui.painter().text(
                rects[p].left_top() + egui::vec2(8.0, 6.0),
                egui::Align2::LEFT_TOP,
                &panes[p].label,
                egui::FontId::proportional(14.0),
                egui::Color32::from_white_alpha(230),
            );
            if p > 0 {
                let x = rects[p].left();
                let stroke = egui::Stroke::new(1.0, ui.visuals().widgets.noninteractive.bg_stroke.color);
                ui.painter().vline(x, rect.y_range(), stroke);
            }
            self.pane_layout.push((rects[p], size));
        }
        self.shown_size = Some(shown);
        // Overlays (measurements, labels) are drawn on the first pane.
        self.layout = self.pane_layout.first().copied();
        self.hovered = None;
        // Panes are drawn whole each time (no bands): a banded single view left unfinished
        // when the view split is started again from its first band when it comes back.
        self.progressive.stop();
        if response.clicked_by(PointerButton::Primary)
            && let Some(pos) = response.interact_pointer_pos()
            && let Some(p) = rects.iter().position(|r| r.contains(pos))
        {
            let shift = ui.input(|i| i.modifiers.shift);
            let pane = Pane { camera: fit_width(view.panes.camera(p, &view.camera), size), ..panes[p].clone() };
            match self.pick_in_pane(&pane, &clouds, view.background, p, pos) {
                Ok(picked) => self.click = Some(Click { picked, shift }),
                Err(e) => log::warn!("picking failed: {e}"),
            }
        }
        twisted
    }

    /// Draws `pane` into its target whole (translucent surfaces settled, in bands if need be),
    /// with only its layers shown; the layers' own visibility is kept.
    fn draw_pane(&mut self, pane: &Pane, clouds: &[VolumeSettings], background: [f32; 3], p: usize) {
        let kept: Vec<bool> =
            (0..pane.layers.len()).map(|l| self.renderer.layer(l).is_some_and(|l| l.visible)).collect();
        for (l, &v) in pane.layers.iter().enumerate() {
            self.renderer.layer_mut(&self.ctx, l).visible = v;
        }
        let size = self.split[p].target.size;
        let frame = FrameInput { camera: &pane.camera, background, clouds, size, tile: None };
        crate::pictures::headless::draw_exact(&self.ctx, &mut self.renderer, &self.split[p].target.color_view, &frame);
        for (l, v) in kept.into_iter().enumerate() {
            self.renderer.layer_mut(&self.ctx, l).visible = v;
        }
    }

    /// What pane `p` shows at window position `pos` (the pane drawn again, for its pick ids).
    fn pick_in_pane(
        &mut self,
        pane: &Pane,
        clouds: &[VolumeSettings],
        background: [f32; 3],
        p: usize,
        pos: egui::Pos2,
    ) -> Result<Option<PickId>, GpuError> {
        let Some(&(rect, size)) = self.pane_layout.get(p) else { return Ok(None) };
        self.draw_pane(pane, clouds, background, p);
        let rel = (pos - rect.min) / rect.size();
        let picked =
            self.renderer.pick(&self.ctx, [(rel.x * size[0] as f32) as u32, (rel.y * size[1] as f32) as u32])?;
        Ok(picked.map(|id| self.object_of(id)))
    }

    /// Each pane's (size on screen, size drawn) of the last split frame; empty for one view.
    pub fn pane_sizes(&self) -> Vec<([u32; 2], [u32; 2])> {
        let shown = self.shown_size.unwrap_or_default();
        self.split.iter().take(self.pane_layout.len()).map(|t| (shown, t.target.size)).collect()
    }

    /// Pane `p`'s last picture, read back (tests, screenshots of a split view).
    pub fn pane_picture(&self, p: usize) -> Result<image::RgbaImage, GpuError> {
        let t = self.split.get(p).ok_or_else(|| GpuError::Readback(format!("no pane {p}")))?;
        t.target.read_rgba(&self.ctx.device, &self.ctx.queue)
    }

    /// Leaves a split view (its panes' targets are kept for the next split, drawn anew).
    pub fn unsplit(&mut self) {
        if !self.pane_layout.is_empty() {
            self.pane_layout.clear();
            self.split.iter_mut().for_each(|t| t.drawn = None);
            self.drawn = None;
        }
    }

    /// Drops every object's GPU data and jobs.
    pub fn clear(&mut self) {
        for l in (0..self.parts.len()).rev() {
            self.remove_layer(l);
        }
        self.renderer.truncate(1);
        self.renderer.main().clear(&self.ctx);
        self.slots.clear();
        self.scan_keys.clear();
        self.plane_frame = None;
        self.generation += 1;
    }

    /// Removes object `n`; the objects after it move down by one.
    pub fn remove_object(&mut self, n: usize) {
        // The plane's frame is drawn again where the next frame asks.
        self.show_plane_frame(n, Vec::new());
        for l in self.layers_of(n).rev() {
            self.remove_layer(l);
        }
        for p in &mut self.parts {
            if p.0 > n {
                p.0 -= 1;
            }
        }
        self.scan_keys.remove(&n);
        self.scan_keys = std::mem::take(&mut self.scan_keys)
            .into_iter()
            .map(|(m, keys)| (if m > n { m - 1 } else { m }, keys))
            .collect();
    }

    /// The object a pick id's layer belongs to, in place of the layer (views of one layer
    /// keep it).
    fn object_of(&self, id: PickId) -> PickId {
        let object = |l: u32| self.parts.get(l as usize).map_or(l, |&(n, _)| n as u32);
        match id {
            PickId::Atom { object: l, index } => PickId::Atom { object: object(l), index },
            PickId::Surface { object: l, index } => PickId::Surface { object: object(l), index },
        }
    }

    /// Shows `molecule` alone in the first layer (a scan's first frame while its key volumes
    /// are made).
    pub fn show_molecule(&mut self, molecule: &crate::model::Molecule, style: crate::scene::AtomStyle) {
        self.renderer.main().set_molecule(&self.ctx, molecule, style);
        self.generation += 1;
    }

    /// Shows the view in the remaining space of `ui`, applying mouse and keyboard input to
    /// `view.camera`; Ctrl + drag moves `clip` (the edited object's clipping plane) when it is on.
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        render_state: &egui_wgpu::RenderState,
        view: &mut ViewState,
        clip: Option<&mut ClipPlane>,
    ) {
        let _ = self.show_twistable(ui, render_state, view, clip, None);
    }

    /// What this frame's drag in the view laid out at `layout` (seen from `camera`) does to a
    /// scan's coordinate; whether the drag twists rather than turns the camera is kept until
    /// it ends.
    fn twist(
        &mut self,
        response: &egui::Response,
        layout: (egui::Rect, [u32; 2]),
        camera: &crate::scene::Camera,
        t: TwistInput,
    ) -> Twist {
        let mut twisted = Twist::default();
        if response.drag_started_by(PointerButton::Primary) {
            let on_bond = t.bond.zip(response.interact_pointer_pos()).is_some_and(|(bond, p)| {
                let ends = (self.to_screen_at(layout, camera, bond[0]), self.to_screen_at(layout, camera, bond[1]));
                matches!(ends, (Some(a), Some(b)) if distance_to_segment(p, a, b) < BOND_GRAB)
            });
            self.twisting = t.drag_scans || on_bond;
            self.grabbed = on_bond && t.direct;
        }
        if !response.dragged() {
            self.twisting = false;
            self.grabbed = false;
        }
        if self.twisting && response.dragged_by(PointerButton::Primary) {
            match response.interact_pointer_pos().filter(|_| self.grabbed) {
                Some(p) => twisted.pointer = Some(p),
                None => twisted.along = response.drag_delta().x / layout.0.width().max(1.0),
            }
        }
        twisted
    }

    /// [`Self::show`] for a scan view: returns the drag of this frame on the coordinate (its
    /// horizontal length as a fraction of the view's width, or where a grabbed atom is held).
    pub fn show_twistable(
        &mut self,
        ui: &mut egui::Ui,
        render_state: &egui_wgpu::RenderState,
        view: &mut ViewState,
        clip: Option<&mut ClipPlane>,
        twist: Option<TwistInput>,
    ) -> Twist {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        let ppp = ui.ctx().pixels_per_point();
        let size = [(rect.width() * ppp).round().max(1.0) as u32, (rect.height() * ppp).round().max(1.0) as u32];
        let twisted = match twist {
            Some(t) => self.twist(&response, (rect, size), &view.camera, t),
            None => Twist::default(),
        };
        if !self.twisting {
            handle_input(ui, &response, view, clip);
        }
        self.shown_size = Some(size);
        let drawn = *view;
        let shown = size;
        let size = self.detail.render_size(size);
        if sized_target(&mut self.target, &self.ctx.device, render_state, size) {
            self.drawn = None;
        }
        let clouds: Vec<VolumeSettings> = self.clouds.iter().map(|&c| self.detail.cloud(c)).collect();
        self.renderer.set_detail(&self.detail);
        let key = (drawn, clouds, size, self.generation, self.detail.lod_scale.to_bits());
        let changed = self.drawn.as_ref() != Some(&key);
        if changed && self.target.is_some() {
            // A costly frame (orbitals evaluated per sample, or any frame on a CPU rasteriser)
            // is drawn in bands over several UI frames, so the window answers while the
            // picture fills in; a cheap one still takes one band. Until then a coarse picture
            // of the whole view may stand in, drawn at once; a frame already drawn coarse (a
            // drag) needs none.
            let cpu = self.ctx.info.device_type == wgpu::DeviceType::Cpu;
            let costly = self.renderer.is_costly();
            let banded = self.progressive.bands_needed(cpu, costly);
            if self.progressive.start(banded, self.detail == Detail::FULL, costly) {
                self.draw_preview(render_state, &key.0, shown);
            }
        }
        let shown_target = self.target.as_ref().map(|(t, id)| (t.color_view.clone(), *id));
        if let Some((color_view, id)) = &shown_target {
            if changed || self.progressive.drawing() {
                let frame = FrameInput {
                    camera: &key.0.camera,
                    background: key.0.background,
                    clouds: &key.1,
                    size,
                    tile: None,
                };
                if self.progressive.drawing() {
                    let (renderer, ctx) = (&mut self.renderer, &self.ctx);
                    let turn = self.progressive.turn(size, self.detail == Detail::FULL, |tile| {
                        let mut encoder = ctx.device.create_command_encoder(&Default::default());
                        renderer.render(ctx, &mut encoder, color_view, &FrameInput { tile: Some(tile), ..frame });
                        ctx.queue.submit([encoder.finish()]);
                        // Waiting here keeps each frame's GPU work within the budget.
                        let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
                    });
                    if turn != Turn::Done {
                        ui.ctx().request_repaint();
                    }
                    if turn == Turn::WantPreview {
                        self.draw_preview(render_state, &key.0, shown);
                        self.progressive.preview_drawn();
                    }
                } else {
                    let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
                    self.renderer.render(&self.ctx, &mut encoder, color_view, &frame);
                    self.ctx.queue.submit([encoder.finish()]);
                    // Timed when the GPU is done, without waiting for it here.
                    let done = Arc::new(std::sync::OnceLock::new());
                    let set = Arc::clone(&done);
                    self.ctx.queue.on_submitted_work_done(move || {
                        let _ = set.set(std::time::Instant::now());
                    });
                    self.progressive.submitted_whole(done);
                }
                self.drawn = Some(key);
                self.awaiting_fragments = self.renderer.has_translucent();
                if !self.awaiting_fragments {
                    self.fragments = None;
                }
            }
            self.paint(ui.painter(), rect, *id, size[1]);
        }
        self.check_fragments(ui.ctx());
        let _ = self.ctx.device.poll(wgpu::PollType::Poll);
        self.progressive.poll_whole();
        self.layout = Some((rect, size));
        // Hover: read the id under the pointer when it moved and no button is held.
        let pointer = response.hover_pos().filter(|_| !ui.input(|i| i.pointer.any_down()));
        // Ids are read from the picture being drawn: while it is drawn in bands they hold the
        // rows drawn so far, so hover and clicks below those rows wait for their band.
        if pointer != self.hovered_at && pointer.is_none_or(|p| self.ids_ready(p)) {
            self.hovered_at = pointer;
            self.hovered = pointer.and_then(|pos| self.pick_at(pos).ok().flatten());
        }
        if response.clicked_by(PointerButton::Primary)
            && let Some(pos) = response.interact_pointer_pos()
        {
            self.pending_click = Some((pos, shift_at_release(ui)));
        }
        if let Some((pos, shift)) = self.pending_click.filter(|&(pos, _)| self.ids_ready(pos)) {
            self.pending_click = None;
            match self.pick_at(pos) {
                Ok(picked) => self.click = Some(Click { picked, shift }),
                Err(e) => log::warn!("picking failed: {e}"),
            }
        }
        twisted
    }

    /// Paints the view's picture into `rect`: while a frame is drawn in bands over a coarse
    /// picture, the coarse one with the rows drawn so far over it, and the bands' progress.
    fn paint(&self, painter: &egui::Painter, rect: egui::Rect, id: egui::TextureId, rows_total: u32) {
        let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        match (&self.preview, self.progressive.rows_drawn()) {
            (Some((_, coarse)), Some(rows)) if self.progressive.is_previewing() => {
                // The coarse picture, with the rows of the full one drawn so far over it.
                painter.image(*coarse, rect, uv, egui::Color32::WHITE);
                let done = rows as f32 / rows_total.max(1) as f32;
                let top = egui::Rect::from_min_size(rect.min, egui::vec2(rect.width(), rect.height() * done));
                painter.image(
                    id,
                    top,
                    egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, done)),
                    egui::Color32::WHITE,
                );
            }
            _ => {
                painter.image(id, rect, uv, egui::Color32::WHITE);
            }
        }
        if let Some(rows) = self.progressive.rows_drawn().filter(|_| self.progressive.shows_progress()) {
            progress_bar(painter, rect, rows as f32 / rows_total.max(1) as f32);
        }
    }

    /// Whether the ids at window position `pos` are the current picture's: it is whole, or
    /// drawn in bands past that row (a band restarts from the top when the view changes, and a
    /// coarse preview drawn in between leaves the full-size ids from the first band on). A
    /// picture that keeps changing (a vibration playing) still reaches every row in turn.
    fn ids_ready(&self, pos: egui::Pos2) -> bool {
        let (Some(next_row), Some((rect, size))) = (self.progressive.rows_drawn(), self.layout) else { return true };
        let row = ((pos.y - rect.min.y) / rect.height().max(1.0) * size[1] as f32).max(0.0) as u32;
        row < next_row
    }

    /// Whether a click waits for its row of the picture to be drawn before it is picked.
    pub fn is_picking(&self) -> bool {
        self.pending_click.is_some()
    }

    /// Draws the coarse picture of `view` for a view shown at `shown` pixels into the preview
    /// target, at once.
    fn draw_preview(&mut self, render_state: &egui_wgpu::RenderState, view: &ViewState, shown: [u32; 2]) {
        let detail = Detail::PREVIEW;
        let size = detail.render_size(shown);
        sized_target(&mut self.preview, &self.ctx.device, render_state, size);
        let Some((target, _)) = &self.preview else { return };
        let clouds: Vec<VolumeSettings> = self.clouds.iter().map(|&c| detail.cloud(c)).collect();
        self.renderer.set_detail(&detail);
        let frame = FrameInput { camera: &view.camera, background: view.background, clouds: &clouds, size, tile: None };
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        self.renderer.render(&self.ctx, &mut encoder, &target.color_view, &frame);
        self.ctx.queue.submit([encoder.finish()]);
        let _ = self.ctx.device.poll(wgpu::PollType::wait_indefinitely());
        self.renderer.set_detail(&self.detail);
    }

    /// Whether a coarse picture stands in while the full one is drawn.
    pub fn is_previewing(&self) -> bool {
        self.progressive.is_previewing()
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
        let picked =
            self.renderer.pick(&self.ctx, [(rel.x * size[0] as f32) as u32, (rel.y * size[1] as f32) as u32])?;
        Ok(picked.map(|id| self.object_of(id)))
    }

    /// The world point (bohr) of the opaque surface under the pointer when it rests on one
    /// (an isosurface, not an atom): where the NCI plot marks the surface's point.
    pub fn hovered_surface_point(&self, camera: &crate::scene::Camera) -> Option<(u32, glam::Vec3)> {
        let Some(PickId::Surface { object, .. }) = self.hovered else { return None };
        let (pos, (rect, size)) = (self.hovered_at?, self.layout?);
        let rel = (pos - rect.min) / rect.size();
        let pixel = [(rel.x * size[0] as f32) as u32, (rel.y * size[1] as f32) as u32];
        let depth = self.renderer.depth_at(&self.ctx, pixel).ok()??;
        let camera = if self.pane_layout.is_empty() { *camera } else { fit_width(*camera, size) };
        let world_from_clip = self.renderer.clip_from_world(&camera, size).inverse();
        let p = world_from_clip * glam::Vec4::new(rel.x * 2.0 - 1.0, 1.0 - rel.y * 2.0, depth, 1.0);
        Some((object, p.truncate() / p.w))
    }

    /// How many more layers the scene can take (each object one for its atoms and one per
    /// quantity).
    pub fn room(&self) -> usize {
        (crate::gpu::renderer::MAX_LAYERS - 1).saturating_sub(self.parts.len())
    }

    /// Where world point `p` (bohr) lies on screen in the last frame laid out.
    pub fn to_screen(&self, camera: &crate::scene::Camera, p: glam::Vec3) -> Option<egui::Pos2> {
        self.to_screen_at(self.layout?, camera, p)
    }

    /// Where world point `p` is drawn in pane `pane` of a split view seen from `camera` (the
    /// single view's place when the view is not split).
    pub fn to_screen_in(&self, pane: usize, camera: &crate::scene::Camera, p: glam::Vec3) -> Option<egui::Pos2> {
        let layout = self.pane_layout.get(pane).copied().or(self.layout)?;
        self.to_screen_at(layout, camera, p)
    }

    fn to_screen_at(
        &self,
        (rect, size): (egui::Rect, [u32; 2]),
        camera: &crate::scene::Camera,
        p: glam::Vec3,
    ) -> Option<egui::Pos2> {
        // A split view's panes are drawn from their camera stood back to fit the pane's width.
        let camera = if self.pane_layout.is_empty() { *camera } else { fit_width(*camera, size) };
        let c = self.renderer.clip_from_world(&camera, size) * p.extend(1.0);
        (c.w > 1e-6).then(|| {
            let ndc = c.truncate() / c.w;
            rect.min + egui::vec2((ndc.x * 0.5 + 0.5) * rect.width(), (0.5 - ndc.y * 0.5) * rect.height())
        })
    }

    /// Renders the current view at `size` and reads it back (for screenshots).
    pub fn snapshot(&mut self, view: &ViewState, size: [u32; 2]) -> Result<image::RgbaImage, GpuError> {
        let target = OffscreenTarget::new(&self.ctx.device, size);
        // Every translucent fragment kept, as `render` draws it.
        let (picture, _) = crate::pictures::headless::picture(
            &self.ctx,
            &mut self.renderer,
            &target,
            &view.camera,
            view.background,
            &self.clouds,
        )?;
        // The viewport's own frame must be redrawn: the renderer's buffers changed size.
        self.drawn = None;
        Ok(picture)
    }

    /// How much of a frame drawn in bands is done (0..1); `None` when none is under way.
    pub fn progress(&self) -> Option<f32> {
        let rows = self.progressive.rows_drawn()?;
        Some(rows as f32 / self.rendered_size()?[1].max(1) as f32)
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

    /// Where the view was last laid out in the window.
    pub fn rect(&self) -> Option<egui::Rect> {
        self.layout.map(|(rect, _)| rect)
    }

    /// Width over height of the view as last laid out.
    pub fn aspect(&self) -> Option<f32> {
        let [w, h] = self.shown_size?;
        (h > 0).then(|| w as f32 / h as f32)
    }
}

/// `camera` stood back so that what fits its height fits a view of `size` narrower than it is
/// tall (a pane of a split view): the panes show the whole molecule, not a slice of it.
/// Whether Shift was held as the primary button was released (the frame's modifiers may
/// already have moved on).
fn shift_at_release(ui: &egui::Ui) -> bool {
    ui.input(|i| {
        (i.events.iter().rev())
            .find_map(|e| match e {
                egui::Event::PointerButton { button: PointerButton::Primary, pressed: false, modifiers, .. } => {
                    Some(modifiers.shift)
                }
                _ => None,
            })
            .unwrap_or(i.modifiers.shift)
    })
}

/// The plane map's frame in the view (linear RGB): the amber of the map's outline.
const PLANE_FRAME_COLOR: [f32; 3] = [1.0, 0.72, 0.19];

/// Where an object's clipping plane is measured from: the middle of what its scan's sweep shows
/// (the same at every value), else of its document.
fn clip_centre(doc: &Document, keys: Option<&ScanScene>) -> glam::Vec3 {
    keys.map_or_else(|| crate::layers::object_centre(doc), ScanScene::clip_centre)
}

fn fit_width(mut camera: crate::scene::Camera, size: [u32; 2]) -> crate::scene::Camera {
    let aspect = size[0] as f32 / size[1].max(1) as f32;
    if aspect < 1.0 {
        camera.distance /= aspect.max(0.2);
    }
    camera
}

fn distance_to_segment(p: egui::Pos2, a: egui::Pos2, b: egui::Pos2) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_sq().max(1e-6)).clamp(0.0, 1.0);
    (p - (a + t * ab)).length()
}

fn handle_input(ui: &egui::Ui, response: &egui::Response, view: &mut ViewState, clip: Option<&mut ClipPlane>) {
    let clip = clip.filter(|c| c.enabled && ui.input(|i| i.modifiers.command));
    if let Some(clip) = clip
        && response.dragged_by(PointerButton::Primary)
    {
        // Ctrl + drag moves the clipping plane: a view height of drag is the camera distance.
        let h = response.rect.height().max(1.0);
        clip.offset -= response.drag_delta().y / h * view.camera.distance * 0.5;
        // The layers take the moved plane next frame.
        ui.ctx().request_repaint();
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
    // The wheel zooms; with Alt it is the plane map's (which moves its plane).
    if response.hovered() && !ui.input(|i| i.modifiers.alt) {
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
            Ok(Some((mesh, note))) => *cache = Some(BuiltSurface { settings: *settings, atoms, mesh, note, map: None }),
            Ok(None) => return (None, None),
            Err(e) => return (None, Some(format!("molecular surface: {e}"))),
        }
    }
    let built = cache.as_mut().expect("just built");
    let mut mesh = built.mesh.clone();
    built.map = crate::evaluate::meshes::color_surface(&mut mesh, doc, settings, selection, grid);
    (Some((mesh, settings.look())), built.note.clone())
}
