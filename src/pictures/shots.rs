//! What a movie's frames show, drawn one after another on a target of their own: a scan's
//! coordinate swept ([`ScanShots`]) or a scene turning or vibrating ([`SceneShots`]). The
//! command line's `movie` and the viewer's *Record…* both draw through these, so their frames
//! are the pictures `scan render` and `render` make.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use crate::gpu::{GpuContext, GpuError, OffscreenTarget, Renderer};
use crate::layers::key_volumes::{ScanPainter, ScanScene};
use crate::layers::{show_atoms, show_scene};
use crate::model::Document;
use crate::model::arrow::mode_arrows;
use crate::pictures::figure::{Figure, caption};
use crate::pictures::headless::picture;
use crate::pictures::movie::{MovieError, MovieWriter, full_turn};
use crate::scene::coloring::ValueMap;
use crate::scene::vibration::ARROW_COLOR;
use crate::scene::{Camera, Interpolation, ObjectState, RenderSettings, VolumeSettings};

#[derive(Debug, thiserror::Error)]
pub enum ShotError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Movie(#[from] MovieError),
    #[error("{0}")]
    Scene(String),
    #[error("cancelled after {0} frames")]
    Cancelled(usize),
}

/// How a scene moves over a movie.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// A full turn about the screen's vertical axis.
    Turntable,
    /// One period of the first object's normal mode `mode` (0-based), its largest atom moving
    /// `amplitude` bohr at the turning points.
    Vibration { mode: usize, amplitude: f64 },
}

/// A scan's views side by side at each value of `values`, captioned as the window shows them.
pub struct ScanShots {
    pub scene: Arc<ScanScene>,
    /// The views drawn, left to right (all of the scan's orbitals unless told otherwise).
    pub slots: Vec<usize>,
    pub values: Vec<f64>,
    pub camera: Camera,
    pub settings: RenderSettings,
    pub interpolation: Interpolation,
    pub figure: Figure,
    pub captions: bool,
    /// Each view's size.
    pub size: [u32; 2],
    painter: ScanPainter,
}

impl ScanShots {
    #[allow(clippy::too_many_arguments, reason = "a movie's inputs, as the command line and *Record…* name them")]
    pub fn new(
        ctx: &GpuContext,
        scene: Arc<ScanScene>,
        values: Vec<f64>,
        camera: Camera,
        settings: RenderSettings,
        interpolation: Interpolation,
        figure: Figure,
        size: [u32; 2],
    ) -> Self {
        let painter = ScanPainter::new(ctx, figure.drawn_size(size));
        let slots = (0..scene.slots()).collect();
        Self { scene, slots, values, camera, settings, interpolation, figure, captions: true, size, painter }
    }

    /// The views at value `value`.
    pub fn at(&mut self, ctx: &GpuContext, value: f64) -> Result<image::RgbaImage, GpuError> {
        let slots = &self.slots;
        let background = self.settings.background;
        let (scene, painter, settings) = (&self.scene, &mut self.painter, &mut self.settings);
        let mut image = self.figure.draw(background, |bg| {
            settings.background = bg;
            painter.paint(scene, ctx, slots, value, self.interpolation, &self.camera, settings)
        })?;
        settings.background = background;
        if self.captions {
            caption_views(&mut image, scene, slots, value, self.size[0]);
        }
        Ok(image)
    }
}

/// Captions each view of a scan picture (`slots` side by side, each `width` wide) with its
/// orbital and energy and the coordinate's value at the value, as the window labels them.
pub fn caption_views(image: &mut image::RgbaImage, scene: &ScanScene, slots: &[usize], value: f64, width: u32) {
    for (n, &slot) in slots.iter().enumerate() {
        let lines = [scene.label(slot, value), scene.coordinate_label(value)];
        caption(image, n as u32 * width, width, &lines);
    }
}

/// A scene of objects (each a document and what it shows) from a camera, turning or vibrating.
pub struct SceneShots<D> {
    scene: Vec<(D, ObjectState)>,
    moving: Option<Document>,
    renderer: Renderer,
    target: OffscreenTarget,
    clouds: Vec<VolumeSettings>,
    /// The colour bar each frame carries (a surface coloured by another quantity).
    color_map: Option<(ValueMap, String)>,
    camera: Camera,
    background: [f32; 3],
    motion: Motion,
    figure: Figure,
    steps: Vec<f64>,
}

impl<D: std::borrow::Borrow<Document>> SceneShots<D> {
    /// Shows `scene` (orbitals evaluated on grids of `points` per side) for `frames` frames of
    /// `size` each.
    #[allow(clippy::too_many_arguments, reason = "a movie's inputs, as the command line and *Record…* name them")]
    pub fn new(
        ctx: &GpuContext,
        scene: Vec<(D, ObjectState)>,
        camera: Camera,
        background: [f32; 3],
        motion: Motion,
        frames: usize,
        figure: Figure,
        size: [u32; 2],
        points: usize,
    ) -> Result<Self, ShotError> {
        let mut renderer = Renderer::new(ctx);
        let shown = show_scene(ctx, &mut renderer, &scene, points)?;
        // The first object's atoms move with a vibration: a copy of its document to move them in.
        let moving = match motion {
            Motion::Vibration { mode, .. } => {
                let doc =
                    scene.first().map(|(d, _)| d.borrow()).ok_or(ShotError::Scene("the scene is empty".into()))?;
                let Some(v) = &doc.vibrations else {
                    return Err(ShotError::Scene(format!("{}: no normal modes in this file", doc.source)));
                };
                if mode >= v.modes.len() {
                    return Err(ShotError::Scene(format!(
                        "mode {} is out of range: the file has {}",
                        mode + 1,
                        v.modes.len()
                    )));
                }
                Some(doc.clone())
            }
            Motion::Turntable => None,
        };
        let target = OffscreenTarget::new(&ctx.device, figure.drawn_size(size));
        Ok(Self {
            scene,
            moving,
            renderer,
            target,
            clouds: shown.clouds,
            color_map: shown.color_map,
            camera,
            background,
            motion,
            figure,
            steps: full_turn(frames),
        })
    }

    /// Shows the first object's displacement arrows along the vibration (what `--arrows` asks).
    pub fn show_arrows(&mut self, ctx: &GpuContext) {
        let Motion::Vibration { mode, amplitude } = self.motion else { return };
        let Some(v) = self.scene.first().and_then(|(d, _)| d.borrow().vibrations.as_ref()) else { return };
        let arrows = mode_arrows(v, mode, amplitude).unwrap_or_default();
        self.renderer.layer_mut(ctx, 0).arrows.set_arrows(ctx, &arrows, ARROW_COLOR);
    }

    pub fn len(&self) -> usize {
        self.steps.len()
    }

    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// Frame `k`: the camera turned by k/N of a circle, or the atoms at k/N of the period
    /// (phase 360°·k/N, as `render --phase` takes it).
    pub fn frame(&mut self, ctx: &GpuContext, k: usize) -> Result<image::RgbaImage, GpuError> {
        let mut camera = self.camera;
        match self.motion {
            Motion::Turntable => camera.orbit(self.steps[k] as f32, 0.0),
            Motion::Vibration { mode, amplitude } => {
                if let (Some(shown), Some((_, state))) = (&mut self.moving, self.scene.first()) {
                    let phase = (360.0 * k as f64 / self.steps.len() as f64).to_radians();
                    if let Some(moved) = shown.vibrations.as_ref().and_then(|v| v.displaced(mode, phase, amplitude)) {
                        for (atom, p) in shown.molecule.atoms.iter_mut().zip(moved) {
                            atom.position = p;
                        }
                        show_atoms(ctx, self.renderer.layer_mut(ctx, 0), shown, &state.atoms, &state.selection);
                    }
                }
            }
        }
        let (renderer, target, clouds) = (&mut self.renderer, &self.target, &self.clouds);
        let mut img =
            self.figure.draw(self.background, |bg| Ok(picture(ctx, renderer, target, &camera, bg, clouds)?.0))?;
        if let Some((map, name)) = &self.color_map {
            value_bar(&mut img, map, name);
        }
        Ok(img)
    }
}

/// The colour bar of a surface coloured by a volume's values, at the right of `img`: the map's
/// range, in atomic units, titled with the volume's name.
/// The width [`value_bar`] covers at the right of an image `height` pixels tall.
pub fn value_bar_width(height: u32, map: &ValueMap, name: &str) -> f32 {
    let [lo, mid, hi] = map.ticks();
    crate::pictures::figure::color_bar_width(height, [&lo, &mid, &hi], &ValueMap::title(name))
}

pub fn value_bar(img: &mut image::RgbaImage, map: &ValueMap, name: &str) {
    let color = |t: f32| map.at(t).map(crate::pictures::figure::encoded);
    let [lo, mid, hi] = map.ticks();
    crate::pictures::figure::color_bar(img, color, [&lo, &mid, &hi], &ValueMap::title(name));
}

/// How far a recording has got, shared with whoever shows it, and a flag that stops it.
#[derive(Debug, Default)]
pub struct Progress {
    pub done: AtomicUsize,
    pub total: AtomicUsize,
    pub cancel: AtomicBool,
}

/// Writes `count` frames drawn by `frame(k)` to `writer`, counting them in `progress` and
/// stopping (the file left as far as it got) when its flag is raised.
pub fn record(
    mut writer: MovieWriter,
    count: usize,
    progress: &Progress,
    mut frame: impl FnMut(usize) -> Result<image::RgbaImage, ShotError>,
) -> Result<std::path::PathBuf, ShotError> {
    progress.total.store(count, Ordering::Relaxed);
    for k in 0..count {
        if progress.cancel.load(Ordering::Relaxed) {
            let written = writer.written();
            writer.finish()?;
            return Err(ShotError::Cancelled(written));
        }
        writer.push(&frame(k)?)?;
        progress.done.store(k + 1, Ordering::Relaxed);
    }
    Ok(writer.finish()?)
}
