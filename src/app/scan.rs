//! Scans in the window: HOMO and LUMO side by side with linked cameras and the coordinate's value, a
//! slider with the key angles as ticks, play/loop, and the orbital energies against the coordinate.

use super::jobs::{Pending, spawn};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use egui::{Key, RichText};

use super::World;
use super::detail::{Detail, interacting};
use super::measure::{self, Measurements};
use super::state::ViewState;
use super::viewport::{TwistInput, Viewport};
use crate::evaluate::meshes::isosurfaces_within;
use crate::formats::scan::{ScanFile, load_scan};
use crate::gpu::GpuContext;
use crate::layers::key_volumes::{KeyOptions, ScanScene, ScanSceneError, mix};
use crate::model::scan::{Coordinate, Follow};
use crate::scene::{AtomStyle, Interpolation, RenderSettings, ScanState};

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

/// An open scan: its resident key volumes, the coordinate's value, and one view per orbital.
pub struct ScanView {
    pub scene: Arc<ScanScene>,
    /// The coordinate's value in its unit (degrees, Å, or a path's position), within the scan's range.
    pub value: f64,
    pub mode: Interpolation,
    pub playing: bool,
    /// Bounce between the ends instead of stopping.
    pub looping: bool,
    /// Animation speed, the coordinate's units per second.
    pub speed: f64,
    /// Primary drags change the value (Naka et al., docs/references.md); else they orbit and only a drag on the bond twists.
    pub drag_twists: bool,
    direction: f64,
    pub(super) views: Vec<Viewport>,
    /// Where the scan came from (to open it again, following orbitals another way).
    pub source: ScanSource,
    /// How its views draw the orbitals at the value: cloud, isosurface, atoms (the side panel edits it).
    pub settings: RenderSettings,
    /// The atom style the views were last shown with.
    styled: AtomStyle,
    /// The correlation diagram under the views.
    pub diagram: super::correlation::DiagramView,
}

/// What the scan's controls ask for that needs the key volumes made anew.
#[derive(Debug, Clone, PartialEq)]
pub enum ScanRequest {
    /// Follow the orbitals this way.
    Follow(Follow),
    /// Show this orbital (as manifests name it) in the first view, followed by character.
    Show(String),
}

impl ScanView {
    /// One viewport per orbital of the scan, each on its handle of the window's device.
    pub fn new(scene: ScanScene, source: ScanSource, contexts: Vec<GpuContext>) -> Self {
        let views = contexts.into_iter().map(Viewport::new).collect();
        // Open where the picture says most: the key frame nearest the middle of the range.
        let (lo, hi) = scene.scan.range();
        let value = scene.scan.frames[scene.scan.nearest_frame(0.5 * (lo + hi))].at;
        Self {
            scene: Arc::new(scene),
            value,
            mode: Interpolation::Exact,
            playing: false,
            looping: true,
            // A sweep of the whole range in six seconds (30°/s for a half-turn scan).
            speed: ((hi - lo) / 6.0).max(1e-3),
            drag_twists: true,
            direction: 1.0,
            views,
            source,
            settings: RenderSettings::default(),
            styled: AtomStyle::default(),
            diagram: Default::default(),
        }
    }

    /// What a session keeps of the scan: its source, the value, how it is mixed, drawn and
    /// played, and the orbitals its views follow.
    pub fn state(&self) -> ScanState {
        ScanState {
            manifest: match &self.source {
                ScanSource::File(path) => Some(path.clone()),
                ScanSource::Demo => None,
            },
            value: self.value,
            mode: self.mode,
            looping: self.looping,
            speed: self.speed,
            drag_scans: self.drag_twists,
            settings: self.settings,
            orbitals: self.scene.scan.orbitals.clone(),
            follow: self.scene.tracks.follow,
            diagram: self.diagram.window,
        }
    }

    /// Takes the value and the interaction settings `state` holds (a session's, or the same
    /// scan's opened before to follow its orbitals another way); the value is clamped into this
    /// scan's range.
    pub fn restore(&mut self, state: &ScanState) {
        self.set_value(state.value);
        self.mode = state.mode;
        self.looping = state.looping;
        self.speed = state.speed;
        self.drag_twists = state.drag_scans;
        self.settings = state.settings;
        self.diagram.window = state.diagram;
    }

    /// Where atom `atom` of the skeleton at the value is drawn in view `view` (for tests and overlays).
    pub fn atom_on_screen(&self, view: usize, atom: usize, camera: &crate::scene::Camera) -> Option<egui::Pos2> {
        let p = self.scene.scan.geometry_at(self.value).atoms.get(atom)?.position.as_vec3();
        self.views.get(view)?.to_screen(camera, p)
    }

    /// The value and interpolation each view last drew (None before its first frame).
    pub fn shown(&self) -> Vec<Option<(f64, Interpolation)>> {
        self.views.iter().map(|v| v.scan_shown).collect()
    }

    pub fn set_value(&mut self, value: f64) {
        let (lo, hi) = self.scene.scan.range();
        self.value = value.clamp(lo, hi);
    }

    /// Moves the value on by `dt` seconds of animation.
    fn advance(&mut self, dt: f64) {
        let (lo, hi) = self.scene.scan.range();
        let mut t = self.value + self.direction * self.speed * dt;
        if t >= hi || t <= lo {
            if self.looping {
                self.direction = -self.direction;
            } else {
                self.playing = false;
            }
            t = t.clamp(lo, hi);
        }
        self.value = t;
    }

    /// The key frame's value before (`-1`) or after (`+1`) the value.
    fn step_key(&mut self, dir: i32) {
        let angles = self.scene.scan.values();
        let next = if dir > 0 {
            angles.iter().copied().find(|&a| a > self.value + 1e-6)
        } else {
            angles.iter().rev().copied().find(|&a| a < self.value - 1e-6)
        };
        if let Some(a) = next {
            self.value = a;
        }
    }

    /// The coordinate's value that puts the grabbed atom under `pointer` in view `view`: a bond
    /// length scaled by how far along the bond's screen direction the pointer is, an angle
    /// changed by the pointer's turn about the vertex on screen; none for a dihedral or a path.
    fn held_value(&self, view: usize, pointer: egui::Pos2, camera: &crate::scene::Camera) -> Option<f64> {
        let screen = |atom: usize| self.atom_on_screen(view, atom, camera);
        match self.scene.scan.coordinate {
            Coordinate::Distance([i, j]) => {
                let (a, b) = (screen(i)?, screen(j)?);
                let axis = b - a;
                let length = axis.length();
                (length > 2.0).then(|| self.value * ((pointer - a).dot(axis) / (length * length)) as f64)
            }
            Coordinate::Angle([i, j, k]) => {
                // The screen angle at the vertex from the fixed arm to the moving atom, at the value and
                // a degree on: one Newton step on that (a plane seen at a slant turns more or
                // less on screen than in space).
                let opening = |m: &crate::model::Molecule, p: Option<egui::Pos2>| {
                    let at = |a: usize| self.views.get(view)?.to_screen(camera, m.atoms[a].position.as_vec3());
                    let (fixed, vertex) = (at(i)?, at(j)?);
                    let w = p.map_or_else(|| at(k), Some)? - vertex;
                    let u = fixed - vertex;
                    Some((u.x * w.y - u.y * w.x).atan2(u.x * w.x + u.y * w.y).abs().to_degrees() as f64)
                };
                let (here, further) =
                    (self.scene.scan.geometry_at(self.value), self.scene.scan.geometry_at(self.value + 1.0));
                let (now, on, wanted) =
                    (opening(&here, None)?, opening(&further, None)?, opening(&here, Some(pointer))?);
                let slope = on - now;
                (slope.abs() > 0.05).then(|| self.value + (wanted - now) / slope)
            }
            Coordinate::Dihedral(_) | Coordinate::Path(_) => None,
        }
    }

    /// The bond the coordinate moves about at the value (a dihedral's rotatable bond, an angle's
    /// moving arm, a distance's bond), for grabbing it with the mouse; none for a path.
    fn bond(&self) -> Option<[glam::Vec3; 2]> {
        let (j, k) = match self.scene.scan.coordinate {
            Coordinate::Distance([i, j]) => (i, j),
            Coordinate::Angle([_, j, k]) | Coordinate::Dihedral([_, j, k, _]) => (j, k),
            Coordinate::Path(_) => return None,
        };
        let m = self.scene.scan.geometry_at(self.value);
        Some([m.atoms[j].position.as_vec3(), m.atoms[k].position.as_vec3()])
    }
}

/// The bottom panel: the coordinate's slider with key ticks, play/loop, interpolation mode, how orbitals are
/// followed, energy plot. Returns a change of the following, which needs the key volumes anew.
pub fn controls(ui: &mut egui::Ui, scan: &mut ScanView) -> Option<ScanRequest> {
    let mut follow = None;
    egui::Panel::bottom("scan controls").resizable(true).default_size(300.0).show(ui, |ui| {
        let (lo, hi) = scan.scene.scan.range();
        ui.horizontal(|ui| {
            let play = if scan.playing { "Pause" } else { "Play" };
            // One width for both words: the slider beside it stays where it is.
            let hover = format!("Animate the {} (Space)", scan.scene.scan.coordinate.kind());
            if ui.add_sized([58.0, 22.0], egui::Button::new(play)).on_hover_text(hover).clicked() {
                scan.playing = !scan.playing;
            }
            ui.checkbox(&mut scan.looping, "loop");
            let unit = scan.scene.scan.coordinate.unit().trim();
            let span = (hi - lo).max(1e-6);
            ui.add(egui::DragValue::new(&mut scan.speed).range(span / 60.0..=span * 2.0).suffix(format!(" {unit}/s")))
                .on_hover_text("animation speed");
            ui.separator();
            // Room for the value box and the slider's label after the rail.
            let width = (ui.available_width() - 150.0).max(160.0);
            ui.spacing_mut().slider_width = width;
            let mut value = scan.value;
            let c = scan.scene.scan.coordinate;
            let decimals = if matches!(c, crate::model::scan::Coordinate::Distance(_)) { 3 } else { 1 };
            let slider =
                ui.add(egui::Slider::new(&mut value, lo..=hi).suffix(c.unit()).fixed_decimals(decimals).text(c.kind()));
            if slider.changed() {
                scan.set_value(value);
            }
            key_ticks(ui, slider.rect, scan, width);
        });
        ui.horizontal(|ui| {
            ui.radio_value(&mut scan.mode, Interpolation::Exact, "exact")
                .on_hover_text("mix the two key volumes per sample");
            ui.radio_value(&mut scan.mode, Interpolation::ThreePass, "three-pass")
                .on_hover_text("the real-time approximation: per slice attenuate by one key volume, add (1−k)A and kB");
            ui.radio_value(&mut scan.mode, Interpolation::AlphaMix, "α-mix").on_hover_text(
                "per slice the two key volumes' colours and opacities mixed (what three-pass approximates)",
            );
            let mut by_overlap = scan.scene.tracks.follow == Follow::Overlap;
            let swaps = scan.scene.tracks.swaps.len();
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
            ui.checkbox(&mut scan.drag_twists, "drag scans")
                .on_hover_text("a horizontal drag changes the coordinate (right-drag pans); off: drag the bond");
            ui.separator();
            ui.label("diagram: HOMO−k … LUMO+k, k");
            ui.add(egui::DragValue::new(&mut scan.diagram.window).range(0..=8)).on_hover_text(
                "the orbitals the correlation diagram shows; a click on a line shows it in the first view",
            );
        });
        let asked = super::correlation::plot(ui, &mut scan.diagram, &scan.scene.scan, scan.value);
        if let Some(value) = asked.value {
            scan.set_value(value);
        }
        if let Some(name) = asked.orbital {
            follow = Some(ScanRequest::Show(name));
        }
    });
    follow
}

/// Marks the key angles under the slider.
fn key_ticks(ui: &egui::Ui, rect: egui::Rect, scan: &ScanView, width: f32) {
    let (lo, hi) = scan.scene.scan.range();
    let painter = ui.painter();
    // The slider's rail starts at the left of its rect and is `width` long (the handle's
    // radius inset at each end).
    let inset = rect.height() * 0.5;
    let x0 = rect.left() + inset;
    let x1 = rect.left() + width - inset;
    let stroke = egui::Stroke::new(1.5, ui.visuals().widgets.inactive.fg_stroke.color);
    for a in scan.scene.scan.values() {
        let x = x0 + ((a - lo) / (hi - lo).max(1e-9)) as f32 * (x1 - x0);
        painter.line_segment([egui::pos2(x, rect.bottom() - 4.0), egui::pos2(x, rect.bottom() + 1.0)], stroke);
    }
}

/// The orbital views side by side, each labelled with its orbital and energy at the value; drags and
/// keys change the value; both views share `view` (camera and settings).
/// The scan's views side by side, each with its orbital at the value (cloud, isosurfaces at the value when
/// shown, atoms), picking and measurements on the skeleton at the value. Returns what to tell the user.
pub fn views(
    ui: &mut egui::Ui,
    render_state: &egui_wgpu::RenderState,
    scan: &mut ScanView,
    view: &mut ViewState,
    measurements: &mut Measurements,
) -> Option<String> {
    let mut said = None;
    let dt = ui.input(|i| i.stable_dt) as f64;
    if !ui.ctx().egui_wants_keyboard_input() {
        let (space, prev, next) = ui
            .input(|i| (i.key_pressed(Key::Space), i.key_pressed(Key::OpenBracket), i.key_pressed(Key::CloseBracket)));
        if space {
            scan.playing = !scan.playing;
        }
        if prev {
            scan.step_key(-1);
        }
        if next {
            scan.step_key(1);
        }
    }
    if scan.playing {
        // Each step of the animation is drawn whole before the next: a frame that takes longer
        // than a UI frame (drawn in bands) would otherwise be restarted at every step and only
        // its top ever shown.
        if scan.views.iter().all(|v| v.progress().is_none()) {
            scan.advance(dt.min(0.1));
        }
        ui.ctx().request_repaint();
    }
    // The bond's position matters only where a press may start a drag that grabs it.
    let grab = !scan.drag_twists && ui.input(|i| i.pointer.primary_down());
    let direct = !matches!(scan.scene.scan.coordinate, Coordinate::Dihedral(_) | Coordinate::Path(_));
    let bond = (grab || (direct && ui.input(|i| i.pointer.primary_down()))).then(|| scan.bond()).flatten();
    let twist = TwistInput { drag_twists: scan.drag_twists, bond, direct };
    let (lo, hi) = scan.scene.scan.range();
    let n = scan.views.len().max(1);
    let mut dragged = 0.0;
    let mut held: Option<(usize, egui::Pos2)> = None;
    if scan.styled != scan.settings.atoms {
        restyle(scan);
        scan.styled = scan.settings.atoms;
    }
    let style = scan.settings.atoms;
    // All views share one device, so one detail serves them.
    let detail = scan
        .views
        .first()
        .map_or(Detail::FULL, |vp| Detail::for_frame(interacting(ui.ctx(), scan.playing), vp.ctx.info.device_type, n));
    ui.columns(n, |columns| {
        for (slot, (ui, vp)) in columns.iter_mut().zip(scan.views.iter_mut()).enumerate() {
            if vp.scan_shown != Some((scan.value, scan.mode)) {
                vp.show_scan(&scan.scene, slot, scan.value, scan.mode, style);
            }
            ui.horizontal(|ui| {
                ui.strong(scan.scene.label(slot, scan.value));
                ui.label(RichText::new(scan.scene.coordinate_label(scan.value)).weak());
            });
            // Isosurfaces of the orbital at the value, cut in the background from the two key volumes.
            let wanted = scan.settings.iso.visible.then_some((scan.value, scan.settings.iso));
            if vp.scan_iso != wanted {
                vp.scan_iso = wanted;
                let (a, b, k) = scan.scene.bracket_grids(slot, scan.value);
                let iso = scan.settings.iso;
                vp.request_meshes(0, move |max_bytes| isosurfaces_within(&mix(&a, &b, k), &[iso], max_bytes));
            }
            match vp.poll_meshes(0) {
                Some(Ok((n, note))) if n > 0 => {
                    said = Some(format!(
                        "{}isosurfaces at {}: {n} triangles",
                        note.map_or(String::new(), |n| n + "; "),
                        scan.scene.coordinate_label(scan.value)
                    ));
                }
                Some(Err(e)) => said = Some(e),
                _ => {}
            }
            vp.detail = detail;
            vp.clouds = vec![scan.settings.volume];
            vp.set_clip(scan.settings.clip);
            let twisted = vp.show_twistable(ui, render_state, view, Some(&mut scan.settings.clip), Some(twist));
            dragged += twisted.along;
            held = held.or(twisted.pointer.map(|p| (slot, p)));
            let world = World::single(scan.scene.scan.geometry_at(scan.value));
            if let Some(click) = vp.click.take() {
                let text = measurements.click(click, &world);
                if !text.is_empty() {
                    said = Some(text);
                }
            }
            measure::overlay(ui, vp, &view.camera, &world, measurements, view.labels);
        }
    });
    if dragged != 0.0 {
        scan.set_value(scan.value + dragged as f64 * (hi - lo));
        ui.ctx().request_repaint();
    }
    if let Some(value) = held.and_then(|(v, p)| scan.held_value(v, p, &view.camera)) {
        scan.set_value(value);
        ui.ctx().request_repaint();
    }
    said
}

/// Re-applies the atom style to every view (after the side panel changed it).
pub fn restyle(scan: &mut ScanView) {
    for vp in &mut scan.views {
        vp.scan_shown = None;
    }
}

/// What a drag does to a scan's coordinate, in the status line's help: "twist the dihedral".
pub fn drag_words(coordinate: &crate::model::scan::Coordinate) -> &'static str {
    use crate::model::scan::Coordinate;
    match coordinate {
        Coordinate::Dihedral(_) => "twist the dihedral",
        Coordinate::Angle(_) => "bend the angle",
        Coordinate::Distance(_) => "stretch the bond",
        Coordinate::Path(_) => "move along the path",
    }
}
