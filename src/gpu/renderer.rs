//! One renderer for every host: the window, the CLI and the tests draw through it.

use glam::{Mat4, Vec3};

use super::atoms::AtomsPass;
use super::frame::{Draw, FrameTargets, ObjectView, Phase, PhaseNode, PickId, STANDARD_FRAME};
use super::isosurface::IsosurfacePass;
use super::resolve::ResolvePass;
use super::volume::{VolumePass, VolumeTexture};
use super::{GpuContext, GpuError};
use crate::model::GridSpec;
use crate::model::cartesian::CartesianExpansion;
use crate::model::{Molecule, VolumeGrid};
use crate::scene::{AtomColors, AtomStyle, Camera, RenderSettings, VolumeSettings};

/// What one frame needs besides the long-lived GPU state.
#[derive(Debug, Clone, Copy)]
pub struct FrameInput<'a> {
    pub camera: &'a Camera,
    /// Linear RGB.
    pub background: [f32; 3],
    /// Each layer's cloud settings, by layer index; a layer past the end draws no cloud.
    pub clouds: &'a [VolumeSettings],
    /// Target size in pixels.
    pub size: [u32; 2],
    /// Draw only this part of the clouds (a frame too costly for one go, drawn over several).
    pub tile: Option<Tile>,
}

/// One band of a frame drawn progressively: the first clears the targets and draws every opaque
/// thing; each draws the clouds inside its rectangle only, over what the earlier ones left.
/// Every tile resolves the whole frame, so the picture fills in band by band.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tile {
    /// x, y, width, height in pixels.
    pub rect: [u32; 4],
    pub first: bool,
}

impl<'a> FrameInput<'a> {
    /// A frame of one layer drawn with `settings` (the CLI, scan views, tests).
    pub fn single(camera: &'a Camera, settings: &'a RenderSettings, size: [u32; 2]) -> Self {
        Self {
            camera,
            background: settings.background,
            clouds: std::slice::from_ref(&settings.volume),
            size,
            tile: None,
        }
    }
}

/// One object of the scene on the GPU: its atoms, isosurfaces and cloud, each a long-lived
/// instance of its pass, drawn where `world_from_object` places them. Its index in the
/// renderer is the object number its pick ids carry.
pub struct Layer {
    pub atoms: AtomsPass,
    pub surfaces: IsosurfacePass,
    pub volume: VolumePass,
    /// A rigid placement (rotation and translation).
    pub world_from_object: Mat4,
    /// Whether the layer is drawn at all.
    pub visible: bool,
    /// The molecule's bounds in the object's frame, padded by the largest atom.
    molecule_bounds: Option<(Vec3, Vec3)>,
}

impl Layer {
    /// Shows a molecule's atoms in a style, coloured by element.
    pub fn set_molecule(&mut self, ctx: &GpuContext, molecule: &Molecule, style: AtomStyle) {
        self.set_atoms(ctx, molecule, style, None);
    }

    /// Shows a molecule's atoms in a style and colours (by element when `None`).
    pub fn set_atoms(&mut self, ctx: &GpuContext, molecule: &Molecule, style: AtomStyle, colors: Option<&AtomColors>) {
        self.atoms.set_molecule(ctx, molecule, style, colors);
        // Pad by the largest space-filling radius so near/far planes never clip an atom.
        self.molecule_bounds = molecule.bounds().map(|(lo, hi)| (lo.as_vec3() - 4.5, hi.as_vec3() + 4.5));
    }

    /// Shows `grid` as the layer's cloud. A grid over this device's limits is shown at every
    /// `step`-th point instead ([`super::volume::fitting_step`]); returns the step (1: whole).
    pub fn set_volume(&mut self, ctx: &GpuContext, grid: Option<&VolumeGrid>) -> Result<usize, GpuError> {
        let step = grid.map_or(1, |g| {
            super::volume::fitting_step(g.dims, super::volume::texel_bytes(ctx.volume_format), &ctx.device.limits())
        });
        match grid {
            Some(g) if step > 1 => self.volume.set_volume(ctx, Some(&g.subsampled(step)))?,
            _ => self.volume.set_volume(ctx, grid)?,
        }
        Ok(step)
    }

    /// Shows a volume already on the GPU (a filled GTO grid).
    pub fn set_volume_texture(&mut self, ctx: &GpuContext, volume: VolumeTexture) {
        self.volume.set_texture(ctx, Some(volume));
    }

    /// Shows θ between two key volumes of a scan (seed 000), mixed (1−k):k.
    pub fn set_morph(
        &mut self,
        ctx: &GpuContext,
        a: VolumeTexture,
        b: VolumeTexture,
        k: f32,
        mode: crate::scene::Interpolation,
    ) {
        self.volume.set_morph(ctx, a, b, k, mode);
    }

    /// Shows an orbital evaluated per fragment from its basis functions (seed 004's direct mode).
    pub fn set_direct(&mut self, ctx: &GpuContext, expansion: &CartesianExpansion, geometry: &GridSpec, max_abs: f64) {
        self.volume.set_direct(ctx, expansion, geometry, max_abs);
    }

    /// Empties the layer (no atoms, surfaces or cloud), keeping its pipelines.
    pub fn clear(&mut self, ctx: &GpuContext) {
        self.set_molecule(ctx, &Molecule::default(), AtomStyle::Hidden);
        self.volume.set_texture(ctx, None);
        self.surfaces.clear();
    }

    /// The world-space box around everything the layer draws.
    fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let volume = self.volume.volume().map(|v| v.grid_box.corners().to_vec()).unwrap_or_default();
        let atoms = self.molecule_bounds.map(|(lo, hi)| corners(lo, hi)).unwrap_or_default();
        let points: Vec<Vec3> =
            volume.into_iter().chain(atoms).map(|p| self.world_from_object.transform_point3(p)).collect();
        let first = *points.first()?;
        Some(points.iter().fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))))
    }

    /// The representations, in the order they draw within a phase.
    fn drawers(&self) -> [&dyn Draw; 3] {
        [&self.atoms, &self.surfaces, &self.volume]
    }
}

fn corners(lo: Vec3, hi: Vec3) -> Vec<Vec3> {
    (0..8).map(|i| Vec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][(i >> 1) & 1], [lo.z, hi.z][i >> 2])).collect()
}

/// Most objects one scene draws: the object field of a [`PickId`] has 6 bits.
pub const MAX_LAYERS: usize = 64;

/// Draws a frame as [`STANDARD_FRAME`] describes it: each phase one render pass over the shared
/// [`FrameTargets`]; in each, every layer's drawers that draw in that phase, layer by layer.
pub struct Renderer {
    /// At least one; layer `n` is object `n` of the scene.
    layers: Vec<Layer>,
    resolve: ResolvePass,
    frame: &'static [PhaseNode],
    /// The targets at the last frame's size, and the resolve pass's view of their colour.
    targets: Option<(FrameTargets, wgpu::BindGroup)>,
}

impl Renderer {
    pub fn new(ctx: &GpuContext) -> Self {
        let layer = Layer {
            atoms: AtomsPass::new(ctx),
            surfaces: IsosurfacePass::new(ctx),
            volume: VolumePass::new(ctx),
            world_from_object: Mat4::IDENTITY,
            visible: true,
            molecule_bounds: None,
        };
        Self { layers: vec![layer], resolve: ResolvePass::new(ctx), frame: STANDARD_FRAME, targets: None }
    }

    /// Layer `n` (object `n`); layer 0 always exists.
    pub fn layer(&self, n: usize) -> Option<&Layer> {
        self.layers.get(n)
    }

    /// Layer `n`, made (empty, sharing the first layer's pipelines) if the scene had fewer.
    /// `n` is clamped to [`MAX_LAYERS`] − 1.
    pub fn layer_mut(&mut self, ctx: &GpuContext, n: usize) -> &mut Layer {
        let n = n.min(MAX_LAYERS - 1);
        while self.layers.len() <= n {
            let first = &self.layers[0];
            let layer = Layer {
                atoms: first.atoms.instance(ctx),
                surfaces: first.surfaces.instance(),
                volume: first.volume.instance(ctx),
                world_from_object: Mat4::IDENTITY,
                visible: true,
                molecule_bounds: None,
            };
            self.layers.push(layer);
        }
        &mut self.layers[n]
    }

    /// The first layer: the whole scene of a single-document host.
    pub fn main(&mut self) -> &mut Layer {
        &mut self.layers[0]
    }

    /// Keeps the first `n` layers (at least one), dropping the GPU data of the rest.
    pub fn truncate(&mut self, n: usize) {
        self.layers.truncate(n.max(1));
    }

    /// Removes layer `n`; the layers after it move down by one. Removing the only layer empties
    /// it instead.
    pub fn remove(&mut self, ctx: &GpuContext, n: usize) {
        if self.layers.len() == 1 {
            self.layers[0].clear(ctx);
            self.layers[0].world_from_object = Mat4::IDENTITY;
            self.layers[0].visible = true;
        } else if n < self.layers.len() {
            self.layers.remove(n);
        }
    }

    /// Whether a frame is costly enough to draw in tiles: a visible cloud evaluates its orbital
    /// per sample (seed 004's direct mode).
    pub fn is_costly(&self) -> bool {
        self.layers.iter().any(|l| l.visible && l.volume.is_direct())
    }

    pub fn layer_count(&self) -> usize {
        self.layers.len()
    }

    /// Bounds of everything drawn (world, bohr), for the depth range.
    fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.layers.iter().filter(|l| l.visible).filter_map(Layer::bounds).reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
    }

    /// The projection a frame of `size` pixels uses: the depth range holds everything drawn.
    pub fn clip_from_world(&self, camera: &Camera, size: [u32; 2]) -> glam::Mat4 {
        let aspect = size[0].max(1) as f32 / size[1].max(1) as f32;
        let radius = self
            .bounds()
            .map(|(lo, hi)| (hi - camera.target).abs().max((camera.target - lo).abs()).length())
            .unwrap_or(10.0);
        camera.clip_from_world(aspect, radius)
    }

    /// Records the frame into `encoder`, phase by phase as the frame description orders them;
    /// the last phase copies the float colour into `output` (a [`super::COLOR_FORMAT`] view of
    /// `frame.size`).
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        output: &wgpu::TextureView,
        frame: &FrameInput,
    ) {
        if self.targets.as_ref().is_none_or(|(t, _)| t.size != frame.size.map(|v| v.max(1))) {
            let targets = FrameTargets::new(&ctx.device, frame.size);
            let bind = self.resolve.bind(&ctx.device, &targets.color_view);
            self.targets = Some((targets, bind));
        }
        let cam = frame.camera;
        let eye = cam.eye();
        let (light, up) = super::atoms::headlight(eye, cam.target, cam.up());
        let world = ObjectView {
            clip_from_object: self.clip_from_world(cam, frame.size),
            eye,
            view_dir: (cam.target - eye).normalize_or(Vec3::NEG_Z),
            light,
            up,
        };
        let hidden = VolumeSettings { visible: false, ..VolumeSettings::default() };
        for (n, layer) in self.layers.iter_mut().enumerate() {
            let view = ObjectView::new(&world, layer.world_from_object);
            layer.atoms.prepare(ctx, &view, n as u32, frame.size);
            layer.surfaces.prepare(&ctx.queue, &view, n as u32);
            let cloud = frame.clouds.get(n).unwrap_or(&hidden);
            layer.volume.prepare(&ctx.device, &ctx.queue, &view, cloud);
        }
        let Some((targets, resolve)) = &self.targets else { return };
        for node in self.frame {
            if node.phase == Phase::Resolve {
                self.resolve.draw(encoder, resolve, output);
                continue;
            }
            // A later tile keeps what the first drew: only the clouds inside it are added.
            if matches!(node.phase, Phase::Cull | Phase::Opaque) && frame.tile.is_some_and(|t| !t.first) {
                continue;
            }
            if node.phase == Phase::Cull {
                for layer in self.layers.iter().filter(|l| l.visible) {
                    for drawer in layer.drawers().into_iter().filter(|d| d.phases().contains(&Phase::Cull)) {
                        drawer.compute(encoder);
                    }
                }
                continue;
            }
            let mut pass = targets.begin(encoder, node, frame.background);
            if let Some(Tile { rect: [x, y, w, h], .. }) = frame.tile
                && node.phase == Phase::Translucent
            {
                let [fw, fh] = targets.size;
                let (x, y) = (x.min(fw - 1), y.min(fh - 1));
                pass.set_scissor_rect(x, y, w.clamp(1, fw - x), h.clamp(1, fh - y));
            }
            for layer in self.layers.iter().filter(|l| l.visible) {
                for drawer in layer.drawers().into_iter().filter(|d| d.phases().contains(&node.phase)) {
                    drawer.draw(node.phase, &mut pass);
                }
            }
        }
    }

    /// What the last frame drew at `pixel` (x right, y down, in that frame's pixels): an atom,
    /// a surface, or nothing. Blocks until the frame is done.
    pub fn pick(&self, ctx: &GpuContext, pixel: [u32; 2]) -> Result<Option<PickId>, GpuError> {
        let Some((targets, _)) = &self.targets else { return Ok(None) };
        if pixel[0] >= targets.size[0] || pixel[1] >= targets.size[1] {
            return Ok(None);
        }
        let bytes = super::readback::read_texel(&ctx.device, &ctx.queue, &targets.ids, pixel, 4)?;
        Ok(PickId::decode(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])))
    }
}
