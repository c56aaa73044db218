//! One renderer for every host: the window, the CLI and the tests draw through it.

use glam::Vec3;

use super::atoms::AtomsPass;
use super::frame::{Draw, FrameTargets, Phase, PhaseNode, PickId, STANDARD_FRAME};
use super::isosurface::IsosurfacePass;
use super::resolve::ResolvePass;
use super::volume::{VolumePass, VolumeTexture};
use super::{GpuContext, GpuError};
use crate::model::GridSpec;
use crate::model::cartesian::CartesianExpansion;
use crate::model::{Molecule, VolumeGrid};
use crate::scene::{AtomStyle, Camera, RenderSettings};

/// What one frame needs besides the long-lived GPU state.
#[derive(Debug, Clone, Copy)]
pub struct FrameInput<'a> {
    pub camera: &'a Camera,
    pub settings: &'a RenderSettings,
    /// Target size in pixels.
    pub size: [u32; 2],
}

/// Draws a frame as [`STANDARD_FRAME`] describes it: each phase one render pass over the shared
/// [`FrameTargets`], each drawer drawing in the phases it names.
pub struct Renderer {
    pub volume: VolumePass,
    pub atoms: AtomsPass,
    pub surfaces: IsosurfacePass,
    resolve: ResolvePass,
    frame: &'static [PhaseNode],
    /// The targets at the last frame's size, and the resolve pass's view of their colour.
    targets: Option<(FrameTargets, wgpu::BindGroup)>,
    /// Bounds of everything drawn (bohr), for the depth range.
    bounds: Option<(Vec3, Vec3)>,
    molecule_bounds: Option<(Vec3, Vec3)>,
}

impl Renderer {
    pub fn new(ctx: &GpuContext) -> Self {
        Self {
            volume: VolumePass::new(ctx),
            atoms: AtomsPass::new(ctx),
            surfaces: IsosurfacePass::new(ctx),
            resolve: ResolvePass::new(ctx),
            frame: STANDARD_FRAME,
            targets: None,
            bounds: None,
            molecule_bounds: None,
        }
    }

    pub fn set_molecule(&mut self, ctx: &GpuContext, molecule: &Molecule, style: AtomStyle) {
        self.atoms.set_molecule(ctx, molecule, style);
        // Pad by the largest space-filling radius so near/far planes never clip an atom.
        self.molecule_bounds = molecule.bounds().map(|(lo, hi)| (lo.as_vec3() - 4.5, hi.as_vec3() + 4.5));
        self.update_bounds();
    }

    pub fn set_volume(&mut self, ctx: &GpuContext, grid: Option<&VolumeGrid>) -> Result<(), GpuError> {
        self.volume.set_volume(ctx, grid)?;
        self.update_bounds();
        Ok(())
    }

    /// Shows a volume already on the GPU (a filled GTO grid).
    pub fn set_volume_texture(&mut self, ctx: &GpuContext, volume: VolumeTexture) {
        self.volume.set_texture(ctx, Some(volume));
        self.update_bounds();
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
        self.update_bounds();
    }

    /// Shows an orbital evaluated per fragment from its basis functions (seed 004's direct mode).
    pub fn set_direct(&mut self, ctx: &GpuContext, expansion: &CartesianExpansion, geometry: &GridSpec, max_abs: f64) {
        self.volume.set_direct(ctx, expansion, geometry, max_abs);
        self.update_bounds();
    }

    fn update_bounds(&mut self) {
        let volume = self.volume.volume().map(|v| {
            let c = v.grid_box.corners();
            c.iter().fold((c[0], c[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)))
        });
        self.bounds = match (self.molecule_bounds, volume) {
            (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1))),
            (a, b) => a.or(b),
        };
    }

    /// The projection a frame of `size` pixels uses: the depth range holds everything drawn.
    pub fn clip_from_world(&self, camera: &Camera, size: [u32; 2]) -> glam::Mat4 {
        let aspect = size[0].max(1) as f32 / size[1].max(1) as f32;
        let radius = self
            .bounds
            .map(|(lo, hi)| (hi - camera.target).abs().max((camera.target - lo).abs()).length())
            .unwrap_or(10.0);
        camera.clip_from_world(aspect, radius)
    }

    /// The representations, in the order they draw within a phase.
    fn drawers(&self) -> [&dyn Draw; 3] {
        [&self.atoms, &self.surfaces, &self.volume]
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
        let clip_from_world = self.clip_from_world(cam, frame.size);
        let eye = cam.eye();
        let view_dir = (cam.target - eye).normalize_or(Vec3::NEG_Z);
        self.atoms.prepare(&ctx.queue, clip_from_world, eye, cam.target);
        self.surfaces.prepare(&ctx.queue, clip_from_world, eye, super::atoms::headlight(eye, cam.target).0);
        self.volume.prepare(&ctx.device, &ctx.queue, clip_from_world, eye, view_dir, &frame.settings.volume);
        let Some((targets, resolve)) = &self.targets else { return };
        for node in self.frame {
            if node.phase == Phase::Resolve {
                self.resolve.draw(encoder, resolve, output);
                continue;
            }
            let mut pass = targets.begin(encoder, node, frame.settings.background);
            for drawer in self.drawers().into_iter().filter(|d| d.phases().contains(&node.phase)) {
                drawer.draw(node.phase, &mut pass);
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
