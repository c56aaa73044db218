//! A scene of objects: each opened file with its own placement and representations. Plain,
//! serialisable data; what owns GPU resources lives in the viewer and the renderer's layers.

use glam::{EulerRot, Mat4, Quat, Vec3};
use serde::{Deserialize, Serialize};

use crate::model::Document;
use crate::model::orbitals::Quantity;

use super::excited_view::ExcitedView;
use super::quantity::{AtomLook, Evaluation, QuantityState, Source, first_source};
pub use super::scan_state::{LegacyScan, ScanState};
use super::vibration::VibrationState;
use super::{Camera, ClipPlane, IsosurfaceSettings, RenderSettings, SurfaceChoice, SurfaceSettings};

/// Where an object sits in the scene: a rigid placement (rotation about the object's own
/// origin, then a translation), so distances and the clouds' opacity per path are unchanged.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(default)]
pub struct Placement {
    /// Translation, bohr.
    pub offset: [f32; 3],
    /// Rotation about x, then y, then z, degrees.
    pub rotation_deg: [f32; 3],
}

impl Placement {
    pub fn world_from_object(&self) -> Mat4 {
        let [x, y, z] = self.rotation_deg.map(f32::to_radians);
        Mat4::from_rotation_translation(Quat::from_euler(EulerRot::ZYX, z, y, x), Vec3::from(self.offset))
    }

    pub fn is_identity(&self) -> bool {
        *self == Self::default()
    }

    /// The offset along x that puts a box `lo..hi` (object frame) `gap` beyond `right_edge`
    /// (the scene's largest x): a second molecule placed beside the first.
    pub fn beside(right_edge: f32, lo: Vec3, gap: f32) -> Self {
        Self { offset: [right_edge + gap - lo.x, 0.0, 0.0], rotation_deg: [0.0; 3] }
    }

    /// The offset that puts the box `lo..hi` (object frame) `gap` beyond the scene along
    /// `axis` (a unit vector: the screen's right as the scene is seen), centred on the scene
    /// across it. `scene` is the scene's atoms' box: a new molecule lands beside the others as
    /// the view shows them, not behind them along the line of sight.
    pub fn beside_along(axis: Vec3, scene: (Vec3, Vec3), lo: Vec3, hi: Vec3, gap: f32) -> Self {
        let extent = |(l, h): (Vec3, Vec3)| {
            let dots = crate::model::octree::box_corners(l, h).map(|c| c.dot(axis));
            dots.iter().fold((f32::MAX, f32::MIN), |(a, b), &d| (a.min(d), b.max(d)))
        };
        let (_, far) = extent(scene);
        let (near, _) = extent((lo, hi));
        let across = (scene.0 + scene.1) / 2.0 - (lo + hi) / 2.0;
        let offset = axis * (far + gap - near) + (across - axis * across.dot(axis));
        Self { offset: offset.to_array(), rotation_deg: [0.0; 3] }
    }

    /// The axis-aligned box around the box `lo..hi` of the object's frame, placed.
    pub fn placed_box(&self, lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
        let m = self.world_from_object();
        let corners = crate::model::octree::box_corners(lo, hi).map(|c| m.transform_point3(c));
        corners.iter().fold((corners[0], corners[0]), |(l, h), &c| (l.min(c), h.max(c)))
    }
}

/// What an object shows and how: plain data, saved in sessions. The one source of truth for
/// the object: panels edit it in place, and [`changes`] tells the GPU side what to redo.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, from = "StoredObject")]
pub struct ObjectState {
    /// The file it was read from; `None` for the bundled demo.
    pub path: Option<std::path::PathBuf>,
    /// Data sets appended to the file's own, in order (`Source::Volume` numbers them after
    /// `path`'s): files of the same atoms that joined it, differences with other files.
    pub added: Vec<AddedVolume>,
    /// Whether the object is drawn at all.
    pub visible: bool,
    pub placement: Placement,
    pub atoms: AtomLook,
    /// Its quantities (orbitals, densities, data sets), each with its cloud and isosurfaces.
    pub quantities: Vec<QuantityState>,
    /// The quantity the panels edit.
    pub selected: usize,
    /// How its wavefunction's quantities are evaluated.
    pub evaluation: Evaluation,
    /// Which atoms of a structure are shown ([`super::selection::Selection`]; empty: all).
    pub selection: String,
    /// A molecular surface around the atoms shown.
    pub surface: SurfaceSettings,
    /// The normal mode shown, how it moves, its arrows and the IR spectrum's broadening.
    pub vibration: VibrationState,
    /// The excited state picked and the UV-vis spectrum's broadening and axis.
    pub excited: ExcitedView,
    /// The clipping plane that cuts all its representations (its atoms when asked), in the
    /// object's frame, its offset from the centre of the object's bounds
    /// ([`crate::model::Document::bounds`]).
    pub clip: ClipPlane,
    /// The scan it is a frame of: where the coordinate stands and how it plays (its views are
    /// its quantities, [`Source::Scan`]).
    pub scan: Option<ScanState>,
}

/// A data set an object holds beyond its file's own, made again when a session reopens.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum AddedVolume {
    /// A file of the same atoms whose data sets joined (a potential cube beside a density cube).
    Joined { path: std::path::PathBuf },
    /// Quantity `of` minus file `minus`'s same quantity, on `of`'s grid (`points` per axis for
    /// a wavefunction's).
    Difference { of: Source, minus: std::path::PathBuf, points: usize },
}

impl Default for ObjectState {
    fn default() -> Self {
        Self {
            path: None,
            added: Vec::new(),
            visible: true,
            placement: Placement::default(),
            atoms: AtomLook::default(),
            quantities: Vec::new(),
            selected: 0,
            evaluation: Evaluation::default(),
            selection: String::new(),
            surface: SurfaceSettings::default(),
            vibration: VibrationState::default(),
            excited: ExcitedView::default(),
            clip: ClipPlane::default(),
            scan: None,
        }
    }
}

impl ObjectState {
    /// A newly opened `doc` as `defaults` show it: its first quantity ([`first_source`]), big
    /// structures space filling.
    pub fn opening(doc: &Document, defaults: &RenderSettings) -> Self {
        let chains = doc.structure.as_ref().map_or(0, |s| s.structure.chains.len());
        let settings = defaults.for_structure(doc.molecule.atoms.len(), chains);
        let mut state = Self { atoms: AtomLook::of(&settings), ..Self::default() };
        state.quantities.extend(first_source(doc).map(|s| QuantityState::new(s, &settings)));
        // An orbital opens readable at once: its ± surfaces over the cloud, as chemists know
        // orbitals from other viewers (the cloud alone reads as a faint haze at first sight).
        for q in state.quantities.iter_mut().filter(|q| q.source.orbital().is_some()) {
            for iso in &mut q.isosurfaces {
                iso.visible = true;
                iso.translucent = true;
            }
        }
        state.fit_to(doc, defaults);
        state
    }

    /// An object drawn as `settings` say: their atoms, and `source` (when given) with their cloud
    /// and their isosurface (the state of one renderer layer, as tests and single renders use).
    pub fn of_settings(source: Option<Source>, settings: &RenderSettings) -> Self {
        let quantities = source.map(|s| QuantityState::new(s, settings)).into_iter().collect();
        Self { atoms: AtomLook::of(settings), quantities, clip: settings.clip, ..Self::default() }
    }

    /// The quantity the panels edit, if the object has any.
    pub fn selected_quantity(&self) -> Option<&QuantityState> {
        self.quantities.get(self.selected)
    }

    pub fn selected_quantity_mut(&mut self) -> Option<&mut QuantityState> {
        self.quantities.get_mut(self.selected)
    }

    /// Makes the state fit `doc` (a session saved for a file that has changed since, or one
    /// written before quantities existed): quantities `doc` does not hold are dropped (a
    /// data set that is not there becomes the file's first quantity), the selection points at
    /// one that is, and the atomic-orbital selector has one entry per basis function (a
    /// per-shell one spread over each shell's functions).
    pub fn fit_to(&mut self, doc: &Document, defaults: &RenderSettings) {
        for q in &mut self.quantities {
            if let (Source::Volume(_), false) = (q.source, q.source.exists_in(doc)) {
                q.source = first_source(doc).unwrap_or(q.source);
            }
        }
        self.quantities.retain(|q| q.source.exists_in(doc));
        for iso in self.quantities.iter_mut().flat_map(|q| &mut q.isosurfaces) {
            iso.color_by = iso.color_by.filter(|s| s.exists_in(doc));
        }
        if self.quantities.is_empty()
            && let Some(source) = first_source(doc)
        {
            self.quantities.push(QuantityState::new(source, defaults));
        }
        self.selected = self.selected.min(self.quantities.len().saturating_sub(1));
        if let Some(wf) = &doc.wavefunction {
            self.evaluation.functions = self.evaluation.ticked(&wf.basis);
        }
    }

    /// The settings one renderer layer draws quantity `k` with (its cloud, its first
    /// isosurface, the object's atoms) over `background`.
    pub fn render_settings(&self, k: usize, background: [f32; 3]) -> RenderSettings {
        let base = RenderSettings { background, ..RenderSettings::default() };
        let mut settings = self.atoms.onto(base);
        settings.clip = self.clip;
        if let Some(q) = self.quantities.get(k) {
            settings.volume = q.cloud;
            settings.iso = q.isosurfaces.first().copied().unwrap_or_default();
        }
        settings
    }
}

/// What an object's renderer layers must redo after its state changed ([`changes`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Changes {
    /// Quantities were added, removed or reordered: the object's quantity layers are made anew.
    pub layers: bool,
    /// Style, colouring, depth cue or which atoms are shown.
    pub atoms: bool,
    pub placement: bool,
    /// The object's or a quantity's visibility.
    pub visibility: bool,
    /// The molecular surface is built again.
    pub surface: bool,
    /// The shown mode's arrows are drawn anew (another mode, amplitude, or none).
    pub arrows: bool,
    /// The atoms go back to the file's geometry (no mode is shown any more).
    pub rest: bool,
    /// The clipping plane moved, or was turned on or off.
    pub clip: bool,
    /// The scan's value or interpolation changed: the skeleton moves in place and each view's
    /// mixing weight is set (the key volumes stay bound), its isosurfaces cut at the value.
    pub scan_frame: bool,
    /// Per quantity (when `layers` is false): what to redo.
    pub quantities: Vec<QuantityChanges>,
}

/// What one quantity's layer must redo.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct QuantityChanges {
    /// Its values: another data set or orbital, or other evaluation options.
    pub values: bool,
    /// Its isosurfaces are cut again.
    pub isosurfaces: bool,
    /// The law its automatic opacity follows changed: k1 is chosen again.
    pub opacity: bool,
}

impl QuantityChanges {
    pub fn any(&self) -> bool {
        self.values || self.isosurfaces || self.opacity
    }
}

impl Changes {
    /// Whether nothing needs to be redone.
    pub fn is_empty(&self) -> bool {
        !(self.layers
            || self.atoms
            || self.placement
            || self.visibility
            || self.surface
            || self.arrows
            || self.rest
            || self.clip
            || self.scan_frame)
            && self.quantities.iter().all(|q| !q.any())
    }
}

/// Which part of an object one renderer layer draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// Its atoms and molecular surface.
    Atoms,
    /// Its quantity `k`: cloud and isosurfaces.
    Quantity(usize),
}

/// The renderer layers of a scene's objects, in order: each object's atoms, then one layer per
/// quantity. Each entry names the object (its index) and the part.
pub fn layer_parts<'a>(states: impl IntoIterator<Item = &'a ObjectState>) -> Vec<(usize, Part)> {
    states
        .into_iter()
        .enumerate()
        .flat_map(|(n, s)| {
            std::iter::once((n, Part::Atoms)).chain((0..s.quantities.len()).map(move |k| (n, Part::Quantity(k))))
        })
        .collect()
}

/// What the GPU side must redo for an object whose state went from `before` to `after` (one
/// frame's edits): the one place that decides it.
pub fn changes(before: &ObjectState, after: &ObjectState) -> Changes {
    let layers = before.quantities.len() != after.quantities.len();
    let evaluation = before.evaluation.direct != after.evaluation.direct
        || before.evaluation.grid_points != after.evaluation.grid_points
        || before.evaluation.selection() != after.evaluation.selection();
    let quantities = if layers {
        Vec::new()
    } else {
        before
            .quantities
            .iter()
            .zip(&after.quantities)
            .map(|(a, b)| {
                let wavefunction = matches!(b.source, Source::Wavefunction(_));
                let (was, now) = (&a.cloud, &b.cloud);
                // Direct mode fills a grid only for isosurfaces: showing the first asks for one.
                let grid = wavefunction && after.evaluation.direct && b.wants_grid() && !a.wants_grid();
                let promolecular = matches!(b.source, Source::Promolecular(_));
                let points = before.evaluation.grid_points != after.evaluation.grid_points;
                QuantityChanges {
                    values: a.source != b.source
                        || a.fragments != b.fragments
                        || (wavefunction && (evaluation || grid))
                        || (promolecular && points),
                    isosurfaces: a.isosurfaces != b.isosurfaces,
                    opacity: was.k2 != now.k2
                        || was.density_scale != now.density_scale
                        || (now.auto_k1 && !was.auto_k1),
                }
            })
            .collect()
    };
    let visible = |s: &ObjectState| (s.visible, s.quantities.iter().map(|q| (q.visible, q.pane)).collect::<Vec<_>>());
    let scan_frame = before.scan.as_ref().map(|s| (s.value, s.mode)) != after.scan.as_ref().map(|s| (s.value, s.mode));
    Changes {
        layers,
        atoms: before.atoms != after.atoms || before.selection != after.selection,
        placement: before.placement != after.placement,
        visibility: visible(before) != visible(after),
        // A molecular surface follows the atoms a selection shows, and a scan's skeleton.
        surface: before.surface != after.surface
            || (after.surface.choice != SurfaceChoice::Off && (before.selection != after.selection || scan_frame)),
        arrows: before.vibration.arrows_key() != after.vibration.arrows_key(),
        rest: before.vibration.mode.is_some() && after.vibration.mode.is_none(),
        clip: before.clip != after.clip,
        scan_frame,
        quantities,
    }
}

/// An object state as sessions store it: today's fields, and those of sessions written before
/// objects held several quantities (one cloud in `settings.volume`, the first isosurface in
/// `settings.iso`, the rest in `isosurfaces`, the data set in `volume`, the orbital in
/// `quantity`), turned into one quantity; and the clipping plane each cloud had before the
/// plane belonged to the object (the first one on becomes the object's).
#[derive(Deserialize, Default)]
#[serde(default)]
struct StoredObject {
    path: Option<std::path::PathBuf>,
    added: Vec<AddedVolume>,
    visible: Option<bool>,
    placement: Placement,
    atoms: Option<AtomLook>,
    quantities: Vec<QuantityState>,
    selected: usize,
    evaluation: Evaluation,
    selection: String,
    surface: SurfaceSettings,
    vibration: VibrationState,
    excited: ExcitedView,
    clip: Option<ClipPlane>,
    settings: Option<RenderSettings>,
    isosurfaces: Vec<IsosurfaceSettings>,
    volume: usize,
    quantity: Option<Quantity>,
    scan: Option<ScanState>,
}

impl From<StoredObject> for ObjectState {
    fn from(s: StoredObject) -> Self {
        let mut quantities = s.quantities;
        if quantities.is_empty()
            && let Some(settings) = &s.settings
        {
            // A file with a wavefunction resolves `Volume` to its first quantity ([`ObjectState::fit_to`]).
            let source = s.quantity.map_or(Source::Volume(s.volume), Source::Wavefunction);
            let isosurfaces = std::iter::once(settings.iso).chain(s.isosurfaces).collect();
            quantities.push(QuantityState {
                source,
                visible: true,
                cloud: settings.volume,
                isosurfaces,
                pane: None,
                fragments: Default::default(),
            });
        }
        let clouds = quantities.iter().map(|q| q.cloud.stored_clip).chain(s.settings.map(|s| s.volume.stored_clip));
        let stored: Vec<ClipPlane> = clouds.flatten().collect();
        let clip = s.clip.or_else(|| stored.iter().find(|c| c.enabled).or(stored.first()).copied());
        for q in &mut quantities {
            q.cloud.stored_clip = None;
        }
        Self {
            path: s.path,
            added: s.added,
            visible: s.visible.unwrap_or(true),
            placement: s.placement,
            atoms: s.atoms.or(s.settings.as_ref().map(AtomLook::of)).unwrap_or_default(),
            quantities,
            selected: s.selected,
            evaluation: s.evaluation,
            selection: s.selection,
            surface: s.surface,
            vibration: s.vibration,
            excited: s.excited,
            clip: clip.unwrap_or_default(),
            scan: s.scan,
        }
    }
}

/// Most panes a view is split into.
pub const MAX_PANES: usize = 4;

/// How the view is split: panes side by side, each showing the quantities assigned to it
/// ([`QuantityState::pane`]) with every object's atoms, from one camera or each from its own.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Panes {
    /// 1 (one view) to [`MAX_PANES`].
    pub count: usize,
    /// Every pane seen from the first pane's camera (the scene's camera).
    pub linked: bool,
    /// The cameras of unlinked panes (the first pane's is the scene's camera).
    pub cameras: [Camera; MAX_PANES],
}

impl Default for Panes {
    fn default() -> Self {
        Self { count: 1, linked: true, cameras: [Camera::default(); MAX_PANES] }
    }
}

impl Panes {
    /// Pane `p`'s camera, `first` being the scene's.
    pub fn camera(&self, p: usize, first: &Camera) -> Camera {
        if self.linked || p == 0 { *first } else { self.cameras[p.min(MAX_PANES - 1)] }
    }

    /// Adds a pane (up to [`MAX_PANES`]) seen from `camera` when unlinked; returns its index.
    pub fn add(&mut self, camera: Camera) -> usize {
        if self.count < MAX_PANES {
            self.cameras[self.count] = camera;
            self.count += 1;
        }
        self.count - 1
    }
}

/// A saved scene (`*.orbcloud.toml`): the camera, the background and every object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default)]
pub struct Session {
    pub camera: Camera,
    /// How the view is split into panes.
    pub panes: Panes,
    /// Distances, angles and dihedrals measured, by atom numbered through the scene's objects.
    pub measurements: Vec<crate::model::measure::Measurement>,
    /// Linear RGB.
    pub background: Option<[f32; 3]>,
    pub objects: Vec<ObjectState>,
    /// Files opened recently, newest first (the session kept between runs).
    pub recent: Vec<std::path::PathBuf>,
    /// A scan as sessions kept it before scans were objects: read, never written (it opens as an
    /// object, [`LegacyScan::into_object`]).
    #[serde(skip_serializing)]
    pub scan: Option<LegacyScan>,
}

/// What a session file is called.
pub const SESSION_SUFFIX: &str = ".orbcloud.toml";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placements_are_rigid_and_place_beside() {
        let p = Placement { offset: [1.0, 2.0, 3.0], rotation_deg: [30.0, -45.0, 90.0] };
        let m = p.world_from_object();
        let (a, b) = (Vec3::new(0.3, -1.0, 2.0), Vec3::new(-2.0, 0.5, 1.0));
        let moved = |v| m.transform_point3(v);
        assert!(((moved(a) - moved(b)).length() - (a - b).length()).abs() < 1e-5, "distances kept");
        assert!((moved(Vec3::ZERO) - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-6);
        let z90 = Placement { rotation_deg: [0.0, 0.0, 90.0], ..Default::default() }.world_from_object();
        assert!((z90.transform_vector3(Vec3::X) - Vec3::Y).length() < 1e-6, "z rotation is counter-clockwise");
        // Across a view that looks along x (the screen's right is −z): the new box lies 4 bohr
        // past the scene along −z, centred on it in x and y.
        let scene = (Vec3::new(-1.0, -2.0, -3.0), Vec3::new(1.0, 2.0, 3.0));
        let across =
            Placement::beside_along(Vec3::NEG_Z, scene, Vec3::new(10.0, 10.0, 0.0), Vec3::new(12.0, 14.0, 2.0), 4.0);
        let (lo, hi) = across.placed_box(Vec3::new(10.0, 10.0, 0.0), Vec3::new(12.0, 14.0, 2.0));
        assert!((hi.z - (-7.0)).abs() < 1e-5, "4 bohr beyond z = −3: {hi}");
        assert!(((lo + hi) / 2.0).truncate().length() < 1e-5, "centred across: {lo} {hi}");
        let beside = Placement::beside(5.0, Vec3::new(-3.0, 0.0, 0.0), 4.0);
        assert_eq!(beside.offset, [12.0, 0.0, 0.0], "the new box starts 4 bohr past x = 5");
        assert!(Placement::default().is_identity() && !p.is_identity());
    }

    #[test]
    fn a_state_fits_the_file_it_is_opened_with() {
        use crate::model::orbitals::{MolecularOrbital, Spin, Wavefunction};
        let orbital = |occupation| MolecularOrbital {
            energy: occupation - 1.0,
            occupation,
            spin: Spin::Alpha,
            symmetry: String::new(),
            coefficients: vec![],
        };
        let wf = Wavefunction { orbitals: vec![orbital(2.0), orbital(0.0)], restricted: true, ..Default::default() };
        let doc = Document { wavefunction: Some(wf), ..Default::default() };
        let fresh = ObjectState::opening(&doc, &RenderSettings::default());
        assert_eq!(fresh.quantities.len(), 1, "a new file shows its HOMO");
        assert_eq!(fresh.quantities[0].source, Source::Wavefunction(Quantity::Orbital(0)));
        // A session naming an orbital the file lacks, and a data set (an old session without an
        // orbital): the first is dropped, the second becomes the file's first quantity.
        let mut restored = fresh.clone();
        restored.quantities[0].source = Source::Volume(0);
        restored
            .quantities
            .push(QuantityState::new(Source::Wavefunction(Quantity::Orbital(7)), &RenderSettings::default()));
        restored.selected = 1;
        restored.fit_to(&doc, &RenderSettings::default());
        assert_eq!(restored.quantities.iter().map(|q| q.source).collect::<Vec<_>>(), [fresh.quantities[0].source]);
        assert_eq!(restored.selected, 0);
    }

    #[test]
    fn changes_name_what_the_gpu_must_redo_and_nothing_else() {
        let defaults = RenderSettings::default();
        let homo = QuantityState::new(Source::Wavefunction(Quantity::Orbital(3)), &defaults);
        let density = QuantityState::new(Source::Wavefunction(Quantity::Density), &defaults);
        let before = ObjectState { quantities: vec![density, homo], ..Default::default() };
        assert!(changes(&before, &before).is_empty());
        // k1 moves with every frame's automatic opacity, a cloud's slices are the frame's:
        // nothing to redo.
        let mut after = before.clone();
        after.quantities[1].cloud.k1 = 0.9;
        after.quantities[1].cloud.slices = 64;
        assert!(changes(&before, &after).is_empty());
        after.quantities[1].isosurfaces[0].visible = true;
        let c = changes(&before, &after);
        assert_eq!(c.quantities[1], QuantityChanges { isosurfaces: true, ..Default::default() });
        assert!(!c.quantities[0].any() && !c.atoms && !c.layers);
        after.quantities[1].source = Source::Wavefunction(Quantity::Orbital(4));
        after.quantities[0].cloud.k2 = 1.2;
        let c = changes(&before, &after);
        assert!(c.quantities[1].values && c.quantities[0].opacity && !c.quantities[0].values);
        // Evaluation options re-evaluate every wavefunction quantity.
        let mut direct = before.clone();
        direct.evaluation.direct = true;
        assert!(changes(&before, &direct).quantities.iter().all(|q| q.values));
        // Direct mode holds no grid until an isosurface wants one: showing it evaluates anew
        // (with the grid), hiding it does not.
        let mut iso = direct.clone();
        iso.quantities[1].isosurfaces[0].visible = true;
        let c = changes(&direct, &iso);
        assert!(c.quantities[1].values && c.quantities[1].isosurfaces && !c.quantities[0].values);
        assert!(!changes(&iso, &direct).quantities[1].values);
        assert!(!changes(&before, &after_iso(&before)).quantities[1].values, "grid mode has its grid");
        // A quantity added: the layers are laid out again.
        let mut more = before.clone();
        more.quantities.push(more.quantities[0].clone());
        assert!(changes(&before, &more).layers);
        let mut moved = before.clone();
        moved.placement.offset[0] = 1.0;
        moved.quantities[0].visible = false;
        let c = changes(&before, &moved);
        assert!(c.placement && c.visibility && !c.atoms && !c.surface && !c.clip);
        // The clipping plane is the frame's: nothing is rebuilt, every layer takes it anew.
        let mut cut = before.clone();
        cut.clip.enabled = true;
        let c = changes(&before, &cut);
        assert!(c.clip && !c.placement && !c.surface && !c.atoms && c.quantities.iter().all(|q| !q.any()));
        // A scan's new value or interpolation: the frame only (atoms in place, mixing weights),
        // no quantity evaluated anew; playing or its speed changes nothing on the GPU.
        let scanned = ObjectState { scan: Some(super::ScanState::default()), ..before.clone() };
        let mut twisted = scanned.clone();
        twisted.scan.as_mut().unwrap().value = 30.0;
        let c = changes(&scanned, &twisted);
        assert!(c.scan_frame && !c.atoms && !c.layers && !c.surface && c.quantities.iter().all(|q| !q.any()));
        let mut played = scanned.clone();
        played.scan.as_mut().unwrap().playing = true;
        played.scan.as_mut().unwrap().speed = 5.0;
        assert!(changes(&scanned, &played).is_empty());
        // A molecular surface follows the skeleton.
        let mut surfaced = scanned.clone();
        surfaced.surface.choice = SurfaceChoice::Gaussian;
        let mut surfaced_twisted = surfaced.clone();
        surfaced_twisted.scan.as_mut().unwrap().value = 30.0;
        assert!(changes(&surfaced, &surfaced_twisted).surface);
        // Which atoms are shown restyles them, and wraps a molecular surface anew.
        let mut selected = before.clone();
        selected.surface.choice = SurfaceChoice::Gaussian;
        let mut narrower = selected.clone();
        narrower.selection = "chain A".into();
        let c = changes(&selected, &narrower);
        assert!(c.atoms && c.surface);
    }

    fn after_iso(s: &ObjectState) -> ObjectState {
        let mut s = s.clone();
        s.quantities[1].isosurfaces[0].visible = true;
        s
    }

    #[test]
    fn each_object_draws_in_an_atoms_layer_and_one_layer_per_quantity() {
        let defaults = RenderSettings::default();
        let q = QuantityState::new(Source::Volume(0), &defaults);
        let two = ObjectState { quantities: vec![q.clone(), q], ..Default::default() };
        let none = ObjectState::default();
        assert_eq!(
            layer_parts([&two, &none]),
            [(0, Part::Atoms), (0, Part::Quantity(0)), (0, Part::Quantity(1)), (1, Part::Atoms)]
        );
    }
}
