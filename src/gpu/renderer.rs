//! One renderer for every host: the window, the CLI and the tests draw through it.

use glam::Vec3;

use super::atoms::AtomsPass;
use super::gto::GridGeometry;
use super::resolve::{ResolvePass, SceneBuffers};
use super::volume::{VolumePass, VolumeTexture};
use super::{GpuContext, GpuError};
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

pub struct Renderer {
    pub volume: VolumePass,
    pub atoms: AtomsPass,
    resolve: ResolvePass,
    buffers: Option<SceneBuffers>,
    /// Bounds of everything drawn (bohr), for the depth range.
    bounds: Option<(Vec3, Vec3)>,
    molecule_bounds: Option<(Vec3, Vec3)>,
}

impl Renderer {
    pub fn new(ctx: &GpuContext) -> Self {
        Self {
            volume: VolumePass::new(ctx),
            atoms: AtomsPass::new(ctx),
            resolve: ResolvePass::new(ctx),
            buffers: None,
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
    pub fn set_direct(
        &mut self,
        ctx: &GpuContext,
        expansion: &CartesianExpansion,
        geometry: &GridGeometry,
        max_abs: f64,
    ) {
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

    /// Records the frame into `encoder`: clear, opaque impostors, slices back to front, all in
    /// the float scene buffer; then copies that into `output` (a [`super::COLOR_FORMAT`] view of
    /// `frame.size`).
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        output: &wgpu::TextureView,
        frame: &FrameInput,
    ) {
        if self.buffers.as_ref().is_none_or(|b| b.size != frame.size) {
            self.buffers = Some(self.resolve.buffers(&ctx.device, frame.size));
        }
        let Some(buffers) = &self.buffers else { return };
        let cam = frame.camera;
        let clip_from_world = self.clip_from_world(cam, frame.size);
        let eye = cam.eye();
        let view_dir = (cam.target - eye).normalize_or(Vec3::NEG_Z);
        self.atoms.prepare(&ctx.queue, clip_from_world, eye, cam.target);
        self.volume.prepare(&ctx.device, &ctx.queue, clip_from_world, eye, view_dir, &frame.settings.volume);
        let [r, g, b] = frame.settings.background;
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("scene"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &buffers.color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r: r as f64, g: g as f64, b: b as f64, a: 1.0 }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &buffers.depth_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.atoms.draw(&mut pass);
        self.volume.draw(&mut pass);
        drop(pass);
        self.resolve.draw(encoder, buffers, output);
    }
}
