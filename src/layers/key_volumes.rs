//! A dihedral scan on the GPU (Naka et al., docs/references.md): every key volume of the chosen orbitals evaluated on
//! one common grid and kept resident as a 3D texture, so any value is drawn by mixing the two key
//! volumes around it, with the skeleton turned to the value.

use std::sync::Arc;

use glam::DVec3;

use thiserror::Error;

use crate::gpu::gto::{GtoFillPass, read_volume};
use crate::gpu::renderer::Layer;
use crate::gpu::volume::{VolumeTexture, residency_budget, texel_bytes};
use crate::gpu::{FrameInput, GpuContext, GpuError, OffscreenTarget, Renderer};
use crate::model::GridSpec;
use crate::model::cartesian::CartesianExpansion;
use crate::model::scan::{Bracket, Follow, Scan, ScanError, Tracks};
use crate::model::units::EV_PER_HARTREE;
use crate::model::{Document, PreparedBasis, VolumeGrid};
use crate::scene::framing::ORBITAL_MARGIN;
use crate::scene::{AtomStyle, Camera, Interpolation, RenderSettings};

/// Points along the longest side of the common grid unless asked otherwise.
pub const DEFAULT_SCAN_POINTS: usize = 64;

#[derive(Debug, Error)]
pub enum ScanSceneError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Scan(#[from] ScanError),
    #[error(
        "{count} key volumes of {dims:?} points need {needed_mib:.1} MiB, more than the {budget_mib:.1} MiB this GPU \
         allows; a grid of {fits} points along the longest side fits"
    )]
    OverBudget { count: usize, dims: [usize; 3], needed_mib: f64, budget_mib: f64, fits: usize },
    #[error("cancelled")]
    Cancelled,
}

/// How key volumes are made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyOptions {
    /// Points along the longest side of the common grid (wavefunction frames).
    pub points: usize,
    /// R16Float (default: half the memory) or R32Float.
    pub format: wgpu::TextureFormat,
    /// Memory allowed for the key volumes (bytes); `None`: derived from the device limits.
    pub budget: Option<u64>,
    pub follow: Follow,
}

impl Default for KeyOptions {
    fn default() -> Self {
        Self { points: DEFAULT_SCAN_POINTS, format: wgpu::TextureFormat::R16Float, budget: None, follow: Follow::Index }
    }
}

/// A scan with all its key volumes resident on the GPU.
pub struct ScanScene {
    /// Shared with the documents of the scan's object ([`crate::model::Document::scan`]).
    pub scan: Arc<Scan>,
    pub tracks: Tracks,
    pub grid: GridSpec,
    /// `keys[slot][frame]`, phase-aligned, each with the slot's common opacity scale.
    keys: Vec<Vec<VolumeTexture>>,
    /// The same key volumes' values (what isosurfaces at the value are mixed from).
    key_grids: Vec<Vec<Arc<VolumeGrid>>>,
    /// Largest |ψ| per slot over all frames: one opacity scale for the whole scan, so the
    /// cloud does not brighten or fade between frames for nothing.
    pub scale: Vec<f64>,
    /// The box a camera frames to show the whole sweep: every frame's atoms and where each
    /// slot's orbital is visible in any frame (bohr).
    pub visible: (DVec3, DVec3),
    /// Memory the key volumes take, and the budget they had to fit.
    pub bytes: u64,
    pub budget: u64,
}

impl ScanScene {
    /// Evaluates every key volume (GPU compute for wavefunctions), reading each back once to
    /// find its range, and keeps them as textures of `options.format`. `progress(done, total)`
    /// is called after each; returning false cancels.
    pub fn build(
        ctx: &GpuContext,
        scan: Scan,
        options: &KeyOptions,
        progress: &mut dyn FnMut(usize, usize) -> bool,
    ) -> Result<Self, ScanSceneError> {
        let tracks = scan.track(options.follow)?;
        // Wavefunctions: the box where every slot's orbital decays in every frame; cube series:
        // their own grid.
        let decay = scan.decay_box(&tracks);
        let grid_of = |points| match decay {
            Some((lo, hi)) => GridSpec::cubic_voxels(lo, hi, points),
            None => scan.common_grid(ORBITAL_MARGIN, points),
        };
        let grid = grid_of(options.points);
        let slots = scan.orbitals.len();
        let count = slots * scan.frames.len();
        let per_volume = grid.len() as u64 * texel_bytes(options.format);
        let budget = options.budget.unwrap_or_else(|| residency_budget(&ctx.device.limits()));
        let needed = per_volume * count as u64;
        if needed > budget {
            // The largest grid that fits: start from the cube-root estimate, then step down
            // (dimensions round up, so the estimate may still be too large).
            let texel = texel_bytes(options.format) * count as u64;
            let estimate = (options.points as f64 * (budget as f64 / needed as f64).cbrt()).floor() as usize;
            let fits = (2..=estimate.max(2)).rev().find(|&p| grid_of(p).len() as u64 * texel <= budget).unwrap_or(2);
            return Err(ScanSceneError::OverBudget {
                count,
                dims: grid.dims,
                needed_mib: needed as f64 / 1048576.0,
                budget_mib: budget as f64 / 1048576.0,
                fits,
            });
        }
        let mut fill: Option<GtoFillPass> = None;
        let mut grids: Vec<Vec<VolumeGrid>> = vec![Vec::with_capacity(scan.frames.len()); slots];
        for (f, frame) in scan.frames.iter().enumerate() {
            for (slot, slot_grids) in grids.iter_mut().enumerate() {
                let values = match (frame.wavefunction(slot), scan.aligned_coefficients(&tracks, slot, f)) {
                    (Some(wf), Some(c)) => {
                        let prepared = PreparedBasis::new(&wf.basis);
                        let fill = fill.get_or_insert_with(|| GtoFillPass::new(ctx));
                        let geometry = grid;
                        let texture =
                            fill.fill(ctx, &CartesianExpansion::from_coefficients(&prepared, &c), &geometry)?;
                        read_volume(ctx, &texture)?
                    }
                    _ => scan.key_values(&tracks, slot, f, &grid),
                };
                let label = format!("{} at {}", scan.orbitals[slot], scan.coordinate.value_text(frame.at));
                slot_grids.push(VolumeGrid::new(label, grid.dims, grid.world_from_grid, values));
                if !progress(f * slots + slot + 1, count) {
                    return Err(ScanSceneError::Cancelled);
                }
            }
        }
        let visible = visible_box(&scan, &grids);
        let mut keys = Vec::with_capacity(slots);
        let mut scale = Vec::with_capacity(slots);
        for slot_grids in &grids {
            let max_abs = slot_grids.iter().map(|g| g.stats.max_abs).fold(1e-30, f64::max);
            // One box for the whole sweep: the union of where each frame's cloud is visible.
            let mut textures: Vec<VolumeTexture> = Vec::with_capacity(slot_grids.len());
            for g in slot_grids {
                textures.push(VolumeTexture::upload_as(ctx, g, options.format)?);
            }
            let union = textures.iter().map(|t| t.grid_box).reduce(|a, b| a.union(&b));
            let max_grad = textures.iter().map(|t| t.max_grad).fold(1e-30, f32::max);
            for t in &mut textures {
                t.max_abs = max_abs as f32;
                t.max_grad = max_grad;
                if let Some(u) = union {
                    t.grid_box = u;
                }
            }
            keys.push(textures);
            scale.push(max_abs);
        }
        let key_grids = grids.into_iter().map(|g| g.into_iter().map(Arc::new).collect()).collect();
        Ok(Self { scan: Arc::new(scan), tracks, grid, keys, key_grids, scale, visible, bytes: needed, budget })
    }

    pub fn slots(&self) -> usize {
        self.keys.len()
    }

    /// Puts slot `slot` at the value into `renderer`'s first layer: the two key volumes around
    /// the value and the skeleton turned to the value.
    pub fn show(
        &self,
        ctx: &GpuContext,
        renderer: &mut Renderer,
        slot: usize,
        value: f64,
        mode: Interpolation,
        style: AtomStyle,
    ) {
        let layer = renderer.main();
        self.show_view(ctx, layer, slot, value, mode);
        layer.set_molecule(ctx, &self.scan.geometry_at(value), style);
    }

    /// Puts view `slot` at the value into `layer`: the two key volumes around the value, mixed
    /// as `mode` says. Within one pair of key volumes only the mixing weight changes.
    pub fn show_view(&self, ctx: &GpuContext, layer: &mut Layer, slot: usize, value: f64, mode: Interpolation) {
        let Bracket { a, b, k } = self.scan.bracket(value);
        let Some(keys) = self.keys.get(slot) else { return };
        layer.set_morph(ctx, keys[a].clone(), keys[b].clone(), k as f32, mode);
        layer.clip_centre = self.clip_centre();
    }

    /// Where a clipping plane's offset is measured from: the middle of what the sweep shows (the
    /// same at every value, so a plane stays put while the coordinate moves).
    pub fn clip_centre(&self) -> glam::Vec3 {
        (0.5 * (self.visible.0 + self.visible.1)).as_vec3()
    }

    /// View `slot`'s values at the value, mixed on the CPU from the two key volumes around it (what
    /// its isosurfaces are cut from).
    pub fn values_at(&self, slot: usize, value: f64) -> VolumeGrid {
        let (a, b, k) = self.bracket_grids(slot, value);
        mix(&a, &b, k)
    }

    /// The document of the scan's object at the value: the skeleton there, the scan shared.
    pub fn document_at(&self, value: f64, source: &str) -> Document {
        Document {
            source: source.to_string(),
            title: self.scan.title.clone(),
            molecule: self.scan.geometry_at(value),
            scan: Some(self.scan.clone()),
            ..Document::default()
        }
    }

    /// A camera framing what the sweep shows ([`ScanScene::visible`]), looking at the first key
    /// frame's skeleton along its principal axes, tilted ([`crate::scene::view::first_view`]).
    pub fn camera(&self) -> Camera {
        let (lo, hi) = self.visible;
        let mut camera = Camera::framing(lo.as_vec3(), hi.as_vec3());
        if let Some(frame) = self.scan.frames.first() {
            let view = crate::scene::view::first_view(&frame.molecule);
            camera.look_along(view.direction, view.up);
        }
        camera
    }

    /// Renders `slots` at the value side by side (left to right), each `size`, into one image.
    #[allow(clippy::too_many_arguments, reason = "a side-by-side picture's inputs, as `scan render` names them")]
    pub fn render(
        &self,
        ctx: &GpuContext,
        slots: &[usize],
        value: f64,
        mode: Interpolation,
        camera: &Camera,
        settings: &RenderSettings,
        size: [u32; 2],
    ) -> Result<image::RgbaImage, GpuError> {
        ScanPainter::new(ctx, size).paint(self, ctx, slots, value, mode, camera, settings)
    }

    /// A slot's key volume in one frame.
    pub fn key_volume(&self, slot: usize, frame: usize) -> &VolumeTexture {
        &self.keys[slot][frame]
    }

    /// "HOMO  −0.3012 Eh  (−8.20 eV)" (after the view's caption, if any) at the value, the energy interpolated between key frames.
    pub fn label(&self, slot: usize, value: f64) -> String {
        let name = self.scan.slot_name(slot);
        match self.scan.energy_at(&self.tracks, slot, value) {
            Some(e) => format!("{name}  {e:.4} Eh  ({:.2} eV)", e * EV_PER_HARTREE).replace('-', "−"),
            None => name,
        }
    }

    /// The coordinate at the value in words: "dihedral 1-2-3-4 = 45.0°", "distance 1-2 = 1.200 Å".
    pub fn coordinate_label(&self, value: f64) -> String {
        let c = &self.scan.coordinate;
        format!("{} = {}", c.label(), c.value_text(value))
    }

    /// The two key volumes' values around the value and the weight k of the second: slot `slot` at the value
    /// is (1−k)·a + k·b ([`mix`]).
    pub fn bracket_grids(&self, slot: usize, value: f64) -> (Arc<VolumeGrid>, Arc<VolumeGrid>, f32) {
        let Bracket { a, b, k } = self.scan.bracket(value);
        let keys = &self.key_grids[slot];
        (keys[a].clone(), keys[b].clone(), k as f32)
    }

    /// The exactly interpolated volume of a slot at the value, evaluated on the CPU (for export).
    pub fn interpolated_grid(&self, slot: usize, value: f64) -> VolumeGrid {
        let label = format!("{} at {value}° (interpolated)", self.scan.orbitals[slot]);
        self.scan.interpolated_grid(&self.tracks, slot, value, &self.grid, label)
    }
}

/// Draws a scan's views one picture after another with one renderer and target: what
/// [`ScanScene::render`] does once, a movie does per frame.
pub struct ScanPainter {
    renderer: Renderer,
    target: OffscreenTarget,
}

impl ScanPainter {
    /// A painter of views `size` each.
    pub fn new(ctx: &GpuContext, size: [u32; 2]) -> Self {
        Self { renderer: Renderer::new(ctx), target: OffscreenTarget::new(&ctx.device, size) }
    }

    /// `slots` of `scene` at the value side by side (left to right), each the painter's size.
    #[allow(clippy::too_many_arguments, reason = "a side-by-side picture's inputs, as `scan render` names them")]
    pub fn paint(
        &mut self,
        scene: &ScanScene,
        ctx: &GpuContext,
        slots: &[usize],
        value: f64,
        mode: Interpolation,
        camera: &Camera,
        settings: &RenderSettings,
    ) -> Result<image::RgbaImage, GpuError> {
        let size = self.target.size;
        let mut out = image::RgbaImage::new(size[0] * slots.len() as u32, size[1]);
        for (n, &slot) in slots.iter().enumerate() {
            scene.show(ctx, &mut self.renderer, slot, value, mode, settings.atoms);
            self.renderer.main().clip = settings.clip;
            let mut encoder =
                ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("scan frame") });
            let frame = FrameInput::single(camera, settings, size);
            self.renderer.render(ctx, &mut encoder, &self.target.color_view, &frame);
            ctx.queue.submit([encoder.finish()]);
            let view = self.target.read_rgba(&ctx.device, &ctx.queue)?;
            image::imageops::replace(&mut out, &view, (n as u32 * size[0]) as i64, 0);
        }
        Ok(out)
    }
}

/// Where a sweep is visible: every key frame's atoms (padded by a ball's radius) and the points
/// where each slot's orbital reaches a twentieth of its largest |ψ| in any frame.
fn visible_box(scan: &Scan, grids: &[Vec<VolumeGrid>]) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for frame in &scan.frames {
        if let Some((a, b)) = frame.molecule.bounds() {
            lo = lo.min(a - DVec3::splat(2.0));
            hi = hi.max(b + DVec3::splat(2.0));
        }
    }
    for slot in grids {
        let max_abs = slot.iter().map(|g| g.stats.max_abs).fold(0.0, f64::max);
        for g in slot {
            let Some((a, b)) = g.active_bounds((VISIBLE_FRACTION * max_abs) as f32) else { continue };
            for corner in 0..8 {
                let pick = |axis: usize| if corner >> axis & 1 == 0 { a[axis] } else { b[axis] } as f64;
                let p = g.world_from_grid.transform_point3(DVec3::new(pick(0), pick(1), pick(2)));
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
    }
    if lo.x > hi.x { (DVec3::splat(-5.0), DVec3::splat(5.0)) } else { (lo, hi) }
}

/// The fraction of an orbital's largest |ψ| below which its cloud is too faint to frame.
const VISIBLE_FRACTION: f64 = 0.05;

/// (1−k)·a + k·b on their common grid: a scan's orbital between two key volumes, as the exact
/// interpolation mode draws it.
pub fn mix(a: &VolumeGrid, b: &VolumeGrid, k: f32) -> VolumeGrid {
    let values = a.values.iter().zip(&b.values).map(|(&x, &y)| (1.0 - k) * x + k * y).collect();
    let mut g = VolumeGrid::new("interpolated", a.dims, a.world_from_grid, values);
    g.kind = crate::model::grid::ValueKind::Signed;
    g
}
