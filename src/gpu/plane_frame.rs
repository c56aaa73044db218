//! Lines of constant width on screen, depth-tested with the opaque scene: the plane map's
//! frame drawn where the plane lies, so atoms in front of it hide it (`shaders/plane_frame.wgsl`).

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::GpuContext;
use super::frame::{Draw, Phase, Prepare, opaque_storage_bind_group};

/// Mirror of `LineUniforms` in plane_frame.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct LineUniforms {
    pub clip_from_object: [[f32; 4]; 4],
    pub color: [f32; 4],
    /// The frame's size in pixels, the lines' width in pixels, unused.
    pub screen: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<LineUniforms>() == 96);

/// The lines' width on screen, pixels.
const WIDTH: f32 = 2.0;

/// One layer's lines: their segments' buffer, drawn in the opaque phase.
pub struct PlaneFramePass {
    pipeline: Arc<wgpu::RenderPipeline>,
    layout: Arc<wgpu::BindGroupLayout>,
    uniforms: wgpu::Buffer,
    /// The segments' buffer bound with the uniforms, and how many there are.
    segments: Option<(wgpu::BindGroup, u32)>,
    color: [f32; 3],
}

impl PlaneFramePass {
    fn with(ctx: &GpuContext, pipeline: Arc<wgpu::RenderPipeline>, layout: Arc<wgpu::BindGroupLayout>) -> Self {
        let uniforms = super::uniform_buffer(&ctx.device, "plane frame uniforms", std::mem::size_of::<LineUniforms>());
        Self { pipeline, layout, uniforms, segments: None, color: [1.0, 0.75, 0.3] }
    }

    /// Draws the segments `lines` (the object's frame) in linear RGB `color` from the next
    /// frame on; none when empty.
    pub fn set_lines(&mut self, ctx: &GpuContext, lines: &[[Vec3; 2]], color: [f32; 3]) {
        self.color = color;
        if lines.is_empty() {
            self.segments = None;
            return;
        }
        let data: Vec<[f32; 8]> = lines.iter().map(|[a, b]| [a.x, a.y, a.z, 1.0, b.x, b.y, b.z, 1.0]).collect();
        let bytes = bytemuck::cast_slice(&data);
        let bind = opaque_storage_bind_group(&ctx.device, &self.layout, &self.uniforms, "plane frame segments", bytes);
        self.segments = Some((bind, data.len() as u32));
    }

    /// How many segments it draws.
    pub fn count(&self) -> u32 {
        self.segments.as_ref().map_or(0, |s| s.1)
    }
}

impl super::frame::Representation for PlaneFramePass {
    fn new(ctx: &GpuContext, _shared: &super::frame::Shared<'_>) -> Self {
        let (pipeline, layout) = super::frame::opaque_storage_pipeline(&ctx.device, "plane_frame.wgsl", "plane frame");
        Self::with(ctx, Arc::new(pipeline), Arc::new(layout))
    }

    fn instance(&self, ctx: &GpuContext) -> Self {
        Self::with(ctx, self.pipeline.clone(), self.layout.clone())
    }

    fn clear(&mut self, _ctx: &GpuContext) {
        self.segments = None;
    }
}

impl Draw for PlaneFramePass {
    fn prepare(&mut self, f: &Prepare<'_>) {
        if self.segments.is_none() {
            return;
        }
        let [r, g, b] = self.color;
        let u = LineUniforms {
            clip_from_object: f.view.clip_from_object.to_cols_array_2d(),
            color: [r, g, b, 1.0],
            screen: [f.size[0] as f32, f.size[1] as f32, WIDTH, 0.0],
        };
        f.ctx.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
    }

    fn phases(&self) -> &'static [Phase] {
        &[Phase::Opaque]
    }

    fn draw(&self, _phase: Phase, pass: &mut wgpu::RenderPass<'_>) {
        if let Some((bind, count)) = &self.segments {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, bind, &[]);
            pass.draw(0..6, 0..*count);
        }
    }
}
