//! Scans in the window. A scan opens as an object whose document is its skeleton at the value
//! ([`crate::model::Document::scan`]) and whose quantities are its views ([`Source::Scan`]), each in
//! a pane of its own: HOMO and LUMO side by side with linked cameras. Its state
//! ([`ScanState`]: the value, the interpolation, playing) is the object's, so sessions, clipping,
//! isosurfaces and panes treat it as any object's; this module adds its controls (the slider
//! with the key values as ticks, play/loop, the correlation diagram) and its drags.

use super::jobs::{Pending, spawn};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use egui::Key;

use super::SceneObject;
use super::correlation::DiagramView;
use super::viewport::{Twist, TwistInput, Viewport};
use crate::formats::scan::{ScanFile, load_scan};
use crate::gpu::GpuContext;
use crate::layers::key_volumes::{KeyOptions, ScanScene, ScanSceneError};
use crate::model::scan::{Coordinate, Follow, Scan};
use crate::scene::objects::MAX_PANES;
use crate::scene::{AtomLook, Interpolation, ObjectState, QuantityState, RenderSettings, ScanState, Source};

/// Where a scan comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum ScanSource {
    File(PathBuf),
    /// The bundled PSB3 scan.
    Demo,
}

/// Loads a scan and makes its key volumes on a background thread (the GPU compute pass runs
/// there too), with progress and cancellation; the window keeps what it shows meanwhile.
pub struct ScanJob {
    pub name: String,
    pub source: ScanSource,
    done: Arc<AtomicUsize>,
    total: Arc<AtomicUsize>,
    cancel: Arc<AtomicBool>,
    result: Pending<Result<ScanScene, ScanFailure>>,
    /// The first key frame's molecule once the manifest is read: the window shows it while
    /// the key volumes are made, and whether it does already.
    skeleton: Arc<std::sync::Mutex<Option<crate::model::Molecule>>>,
    pub skeleton_shown: bool,
}

/// Why a scan did not open.
#[derive(Debug)]
pub enum ScanFailure {
    Cancelled,
    /// The key volumes would not fit: a grid of `fits` points along the longest side would.
    OverBudget {
        message: String,
        fits: usize,
    },
    Other(String),
}

impl ScanJob {
    /// `follow`: how orbitals are followed across frames; `None`: as the manifest says.
    pub fn start(
        ctx: GpuContext,
        source: ScanSource,
        options: KeyOptions,
        follow: Option<Follow>,
        orbitals: Option<Vec<String>>,
        repaint: impl Fn() + Send + Sync + 'static,
    ) -> Self {
        let name = match &source {
            ScanSource::File(p) => p.display().to_string(),
            ScanSource::Demo => crate::sources::demo::SCAN_NAME.to_string(),
        };
        let (done, total, cancel) =
            (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)), Arc::new(AtomicBool::new(false)));
        let (d, t, c) = (done.clone(), total.clone(), cancel.clone());
        let skeleton = Arc::new(std::sync::Mutex::new(None));
        let first = skeleton.clone();
        let job_source = source.clone();
        let repaint = Arc::new(repaint);
        let progress = repaint.clone();
        let work = move || {
            let run = || -> Result<ScanScene, ScanFailure> {
                let mut file: ScanFile = match &source {
                    ScanSource::File(p) => load_scan(p),
                    ScanSource::Demo => crate::sources::demo::scan(),
                }
                .map_err(|e| ScanFailure::Other(e.to_string()))?;
                if let Some(frame) = file.scan.frames.first() {
                    *first.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some(frame.molecule.clone());
                    progress();
                }
                if let Some(names) = orbitals {
                    file.scan.orbitals = names;
                    file.scan.check_orbitals().map_err(|e| ScanFailure::Other(e.to_string()))?;
                }
                let options = KeyOptions { follow: follow.unwrap_or(file.follow), ..options };
                ScanScene::build(&ctx, file.scan, &options, &mut |n, of| {
                    d.store(n, Ordering::Relaxed);
                    t.store(of, Ordering::Relaxed);
                    progress();
                    !c.load(Ordering::Relaxed)
                })
                .map_err(|e| match e {
                    ScanSceneError::Cancelled => ScanFailure::Cancelled,
                    ScanSceneError::OverBudget { fits, .. } => ScanFailure::OverBudget { message: e.to_string(), fits },
                    e => ScanFailure::Other(e.to_string()),
                })
            };
            run()
        };
        let result = spawn(&format!("opening the scan {name}"), work, move || repaint());
        Self { name, source: job_source, done, total, cancel, result, skeleton, skeleton_shown: false }
    }

    /// The first key frame's molecule, once the manifest has been read.
    pub fn skeleton(&self) -> Option<crate::model::Molecule> {
        self.skeleton.lock().unwrap_or_else(std::sync::PoisonError::into_inner).clone()
    }

    /// Key volumes made so far, of how many.
    pub fn progress(&self) -> (usize, usize) {
        (self.done.load(Ordering::Relaxed), self.total.load(Ordering::Relaxed))
    }

    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    pub fn poll(&self) -> Option<Result<ScanScene, ScanFailure>> {
        self.result.poll().map(|r| r.unwrap_or_else(|e| Err(ScanFailure::Other(e))))
    }
}

/// What the window keeps of the scan an object is a frame of: its key volumes, resident on
/// the GPU, where it came from, and the correlation diagram made from it.
pub struct ObjectScan {
    pub keys: Arc<ScanScene>,
    pub source: ScanSource,
    pub diagram: DiagramView,
}

impl ObjectScan {
    pub fn new(keys: Arc<ScanScene>, source: ScanSource) -> Self {
        Self { keys, source, diagram: DiagramView::default() }
    }

    pub fn scan(&self) -> &Scan {
        &self.keys.scan
    }

    /// The manifest sessions name it by (`None`: the bundled scan).
    pub fn manifest(&self) -> Option<PathBuf> {
        match &self.source {
            ScanSource::File(path) => Some(path.clone()),
            ScanSource::Demo => None,
        }
    }
}

/// The open scan as tests and overlays read it ([`super::OrbApp::scan`]).
pub struct OpenScan<'a> {
    /// The coordinate's value and the interpolation, as the object's state holds them.
    pub value: f64,
    pub mode: Interpolation,
    pub scene: &'a ScanScene,
    pub object: &'a SceneObject,
    /// The value and interpolation the GPU was last given.
    pub(super) shown: Option<(f64, Interpolation)>,
}

impl OpenScan<'_> {
    /// What each view (the object's scan quantities) shows: the value and interpolation its
    /// layer was last given (None before).
    pub fn shown(&self) -> Vec<Option<(f64, Interpolation)>> {
        let views = self.object.state.quantities.iter().filter(|q| matches!(q.source, Source::Scan(_)));
        views.map(|_| self.shown).collect()
    }
}

/// What the scan's controls ask for that needs the key volumes made anew.
#[derive(Debug, Clone, PartialEq)]
pub enum ScanRequest {
    /// Follow the orbitals this way.
    Follow(Follow),
    /// Show this orbital (as manifests name it) in the first view, followed by character.
    Show(String),
}

/// The state a scan opens with: at the key frame nearest the middle of its range, one
/// quantity per view (an orbital's cloud, as `defaults` draw it) in a pane of its own.
pub fn opening_state(keys: &ScanScene, manifest: Option<PathBuf>, defaults: &RenderSettings) -> ObjectState {
    let mut state = ObjectState {
        atoms: AtomLook::of(defaults),
        scan: Some(ScanState::opening(&keys.scan, manifest)),
        ..ObjectState::default()
    };
    fit_views(&mut state, keys.slots(), defaults);
    state
}

/// Gives each of a scan's `views` a quantity (in a pane of its own) where the state has none
/// (a session written before scans were objects, a scan reopened with more orbitals), and drops
/// those of views it no longer has.
pub fn fit_views(state: &mut ObjectState, views: usize, defaults: &RenderSettings) {
    state.quantities.retain(|q| !matches!(q.source, Source::Scan(slot) if slot >= views));
    for slot in 0..views {
        if !state.quantities.iter().any(|q| q.source == Source::Scan(slot)) {
            let pane = Some(slot.min(MAX_PANES - 1));
            state.quantities.push(QuantityState { pane, ..QuantityState::new(Source::Scan(slot), defaults) });
        }
    }
    state.selected = state.selected.min(state.quantities.len().saturating_sub(1));
}

/// The pane captions of a scan's view: "HOMO  −0.3012 Eh  (−8.20 eV)" at the value, and the
/// coordinate there.
pub fn view_label(scan: &ObjectScan, slot: usize, value: f64) -> String {
    format!("{}\n{}", scan.keys.label(slot, value), scan.keys.coordinate_label(value))
}

/// The bottom panel: the coordinate's slider with key ticks, play/loop, interpolation mode, how orbitals are
/// followed, energy plot. Returns a change of the following, which needs the key volumes anew.
pub fn controls(ui: &mut egui::Ui, scan: &mut ObjectScan, state: &mut ScanState) -> Option<ScanRequest> {
    let mut follow = None;
    egui::Panel::bottom("scan controls").resizable(true).default_size(300.0).show(ui, |ui| {
        let s = scan.keys.scan.clone();
        let (lo, hi) = s.range();
        ui.horizontal(|ui| {
            let play = if state.playing { "Pause" } else { "Play" };
            // One width for both words: the slider beside it stays where it is.
            let hover = format!("Animate the {} (Space)", s.coordinate.kind());
            if ui.add_sized([58.0, 22.0], egui::Button::new(play)).on_hover_text(hover).clicked() {
                state.playing = !state.playing;
            }
            ui.checkbox(&mut state.looping, "loop");
            let unit = s.coordinate.unit().trim();
            let span = (hi - lo).max(1e-6);
            ui.add(egui::DragValue::new(&mut state.speed).range(span / 60.0..=span * 2.0).suffix(format!(" {unit}/s")))
                .on_hover_text("animation speed");
            ui.separator();
            // Room for the value box and the slider's label after the rail.
            let width = (ui.available_width() - 150.0).max(160.0);
            ui.spacing_mut().slider_width = width;
            let mut value = state.value;
            let c = s.coordinate;
            let decimals = if matches!(c, Coordinate::Distance(_)) { 3 } else { 1 };
            let slider =
                ui.add(egui::Slider::new(&mut value, lo..=hi).suffix(c.unit()).fixed_decimals(decimals).text(c.kind()));
            if slider.changed() {
                state.set_value(&s, value);
            }
            key_ticks(ui, slider.rect, &s, width);
        });
        ui.horizontal(|ui| {
            ui.radio_value(&mut state.mode, Interpolation::Exact, "exact")
                .on_hover_text("mix the two key volumes per sample");
            ui.radio_value(&mut state.mode, Interpolation::ThreePass, "three-pass")
                .on_hover_text("the real-time approximation: per slice attenuate by one key volume, add (1−k)A and kB");
            ui.radio_value(&mut state.mode, Interpolation::AlphaMix, "α-mix").on_hover_text(
                "per slice the two key volumes' colours and opacities mixed (what three-pass approximates)",
            );
            let mut by_overlap = scan.keys.tracks.follow == Follow::Overlap;
            let swaps = scan.keys.tracks.swaps.len();
            if ui
                .checkbox(&mut by_overlap, "follow character")
                .on_hover_text(format!(
                    "follow each orbital by overlap with the previous frame instead of by name \
                     ({swaps} character swap(s) in this scan)"
                ))
                .changed()
            {
                follow = Some(ScanRequest::Follow(if by_overlap { Follow::Overlap } else { Follow::Index }));
            }
            ui.checkbox(&mut state.drag_scans, "drag scans")
                .on_hover_text("a horizontal drag changes the coordinate (right-drag pans); off: drag the bond");
            ui.separator();
            ui.label("diagram: HOMO−k … LUMO+k, k");
            ui.add(egui::DragValue::new(&mut state.diagram).range(0..=8)).on_hover_text(
                "the orbitals the correlation diagram shows; a click on a line shows it in the first view",
            );
        });
        scan.diagram.window = state.diagram;
        let asked = super::correlation::plot(ui, &mut scan.diagram, &s, state.value);
        if let Some(value) = asked.value {
            state.set_value(&s, value);
        }
        if let Some(name) = asked.orbital {
            follow = Some(ScanRequest::Show(name));
        }
    });
    follow
}

/// Marks the key values under the slider.
fn key_ticks(ui: &egui::Ui, rect: egui::Rect, scan: &Scan, width: f32) {
    let (lo, hi) = scan.range();
    let painter = ui.painter();
    // The slider's rail starts at the left of its rect and is `width` long (the handle's
    // radius inset at each end).
    let inset = rect.height() * 0.5;
    let x0 = rect.left() + inset;
    let x1 = rect.left() + width - inset;
    let stroke = egui::Stroke::new(1.5, ui.visuals().widgets.inactive.fg_stroke.color);
    for a in scan.values() {
        let x = x0 + ((a - lo) / (hi - lo).max(1e-9)) as f32 * (x1 - x0);
        painter.line_segment([egui::pos2(x, rect.bottom() - 4.0), egui::pos2(x, rect.bottom() + 1.0)], stroke);
    }
}

/// The keys of a scan's object this frame: Space plays or pauses, [ and ] step between key
/// frames; a playing scan moves on by the frame's time once the last picture is whole (a
/// frame that takes longer than a UI frame would otherwise be restarted at every step and
/// only its top ever shown). Whether it plays (the window keeps drawing).
pub fn drive(ui: &egui::Ui, object: &mut SceneObject, picture_whole: bool) -> bool {
    let (Some(scan), Some(state)) = (&object.scan, &mut object.state.scan) else { return false };
    let s = scan.scan();
    if !ui.ctx().egui_wants_keyboard_input() {
        let (space, prev, next) = ui
            .input(|i| (i.key_pressed(Key::Space), i.key_pressed(Key::OpenBracket), i.key_pressed(Key::CloseBracket)));
        if space {
            state.playing = !state.playing;
        }
        if prev {
            state.step_key(s, -1);
        }
        if next {
            state.step_key(s, 1);
        }
    }
    if state.playing && picture_whole {
        let dt = ui.input(|i| i.stable_dt) as f64;
        state.advance(s, dt.min(0.1));
    }
    state.playing
}

/// How a drag in the view twists the scan's object `object` at its value.
pub fn twist_input(ui: &egui::Ui, object: &SceneObject) -> Option<TwistInput> {
    let (scan, state) = (object.scan.as_ref()?, object.state.scan.as_ref()?);
    let s = scan.scan();
    // The bond's position matters only where a press may start a drag that grabs it.
    let pressed = ui.input(|i| i.pointer.primary_down());
    let direct = !matches!(s.coordinate, Coordinate::Dihedral(_) | Coordinate::Path(_));
    let grab = pressed && (!state.drag_scans || direct);
    let placed = object.state.placement.world_from_object();
    let bond = grab.then(|| bond(s, state.value)).flatten().map(|b| b.map(|p| placed.transform_point3(p)));
    Some(TwistInput { drag_scans: state.drag_scans, bond, direct })
}

/// Applies this frame's drag to the scan's object: a horizontal drag moves the value over the
/// range by the drag's fraction of the view's width; a grabbed atom follows the pointer (a
/// bond length, an angle). Whether the value moved.
pub fn apply_twist(object: &mut SceneObject, twisted: Twist, vp: &Viewport, camera: &crate::scene::Camera) -> bool {
    let Some(scan) = &object.scan else { return false };
    let s = scan.keys.scan.clone();
    let placed = object.state.placement.world_from_object();
    let Some(state) = &mut object.state.scan else { return false };
    let (lo, hi) = s.range();
    let before = state.value;
    if twisted.along != 0.0 {
        state.set_value(&s, state.value + f64::from(twisted.along) * (hi - lo));
    }
    let screen = |m: &crate::model::Molecule, atom: usize| {
        vp.to_screen_in(twisted.pane, camera, placed.transform_point3(m.atoms.get(atom)?.position.as_vec3()))
    };
    if let Some(value) = twisted.pointer.and_then(|p| held_value(&s, state.value, p, &screen)) {
        state.set_value(&s, value);
    }
    state.value != before
}

/// The coordinate's value that puts the grabbed atom under `pointer`: a bond length scaled by
/// how far along the bond's screen direction the pointer is, an angle changed by the pointer's
/// turn about the vertex on screen; none for a dihedral or a path. `screen` says where an atom
/// of a geometry is drawn.
fn held_value(
    scan: &Scan,
    value: f64,
    pointer: egui::Pos2,
    screen: &dyn Fn(&crate::model::Molecule, usize) -> Option<egui::Pos2>,
) -> Option<f64> {
    let here = scan.geometry_at(value);
    match scan.coordinate {
        Coordinate::Distance([i, j]) => {
            let (a, b) = (screen(&here, i)?, screen(&here, j)?);
            let axis = b - a;
            let length = axis.length();
            (length > 2.0).then(|| value * ((pointer - a).dot(axis) / (length * length)) as f64)
        }
        Coordinate::Angle([i, j, k]) => {
            // The screen angle at the vertex from the fixed arm to the moving atom, at the value and
            // a degree on: one Newton step on that (a plane seen at a slant turns more or
            // less on screen than in space).
            let opening = |m: &crate::model::Molecule, p: Option<egui::Pos2>| {
                let (fixed, vertex) = (screen(m, i)?, screen(m, j)?);
                let w = p.map_or_else(|| screen(m, k), Some)? - vertex;
                let u = fixed - vertex;
                Some((u.x * w.y - u.y * w.x).atan2(u.x * w.x + u.y * w.y).abs().to_degrees() as f64)
            };
            let further = scan.geometry_at(value + 1.0);
            let (now, on, wanted) = (opening(&here, None)?, opening(&further, None)?, opening(&here, Some(pointer))?);
            let slope = on - now;
            (slope.abs() > 0.05).then(|| value + (wanted - now) / slope)
        }
        Coordinate::Dihedral(_) | Coordinate::Path(_) => None,
    }
}

/// The bond the coordinate moves about at the value (a dihedral's rotatable bond, an angle's
/// moving arm, a distance's bond), in the scan's frame, for grabbing it with the mouse; none
/// for a path.
fn bond(scan: &Scan, value: f64) -> Option<[glam::Vec3; 2]> {
    let (j, k) = match scan.coordinate {
        Coordinate::Distance([i, j]) => (i, j),
        Coordinate::Angle([_, j, k]) | Coordinate::Dihedral([_, j, k, _]) => (j, k),
        Coordinate::Path(_) => return None,
    };
    let m = scan.geometry_at(value);
    Some([m.atoms.get(j)?.position.as_vec3(), m.atoms.get(k)?.position.as_vec3()])
}

/// What a drag does to a scan's coordinate, in the status line's help: "twist the dihedral".
pub fn drag_words(coordinate: &crate::model::scan::Coordinate) -> &'static str {
    match coordinate {
        Coordinate::Dihedral(_) => "twist the dihedral",
        Coordinate::Angle(_) => "bend the angle",
        Coordinate::Distance(_) => "stretch the bond",
        Coordinate::Path(_) => "move along the path",
    }
}
