//! Arrows as impostors: a normal mode's displacements, each arrow a shaft and a head met exactly
//! per pixel by the eye ray (`shaders/arrows.wgsl`; the CPU reference is
//! [`crate::model::arrow::Arrow::hit`]).

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::GpuContext;
use super::frame::{Draw, Phase, Prepare, opaque_storage_bind_group};
use crate::model::arrow::Arrow;

/// Mirror of `Arrow` in arrows.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuArrow {
    pub start: [f32; 3],
    pub shaft_radius: f32,
    pub to: [f32; 3],
    pub head_radius: f32,
    pub head_length: f32,
    pub pad0: f32,
    pub pad1: f32,
    pub pad2: f32,
}
const _: () = assert!(std::mem::size_of::<GpuArrow>() == 48);

impl From<&Arrow> for GpuArrow {
    fn from(a: &Arrow) -> Self {
        Self {
            start: a.from.as_vec3().to_array(),
            shaft_radius: a.shaft_radius as f32,
            to: a.to.as_vec3().to_array(),
            head_radius: a.head_radius as f32,
            head_length: a.head_length as f32,
            pad0: 0.0,
            pad1: 0.0,
            pad2: 0.0,
        }
    }
}

/// Mirror of `ArrowUniforms` in arrows.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct ArrowUniforms {
    pub clip_from_object: [[f32; 4]; 4],
    pub eye: [f32; 4],
    pub light: [f32; 4],
    pub color: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<ArrowUniforms>() == 112);

/// The arrows of one layer: their storage buffer, drawn in the opaque phase.
pub struct ArrowsPass {
    pipeline: Arc<wgpu::RenderPipeline>,
    layout: Arc<wgpu::BindGroupLayout>,
    uniforms: wgpu::Buffer,
    /// The arrows' buffer bound with the uniforms, and how many there are.
    arrows: Option<(wgpu::BindGroup, u32)>,
    color: [f32; 3],
}

impl ArrowsPass {
    pub fn new(ctx: &GpuContext) -> Self {
        let (pipeline, layout) = super::frame::opaque_storage_pipeline(&ctx.device, "arrows.wgsl", "arrows");
        Self::with(ctx, Arc::new(pipeline), Arc::new(layout))
    }

    fn with(ctx: &GpuContext, pipeline: Arc<wgpu::RenderPipeline>, layout: Arc<wgpu::BindGroupLayout>) -> Self {
        let uniforms = super::uniform_buffer(&ctx.device, "arrow uniforms", std::mem::size_of::<ArrowUniforms>());
        Self { pipeline, layout, uniforms, arrows: None, color: [0.95, 0.75, 0.1] }
    }

    /// Another layer's arrows, sharing this one's pipeline.
    pub fn instance(&self, ctx: &GpuContext) -> Self {
        Self::with(ctx, self.pipeline.clone(), self.layout.clone())
    }

    /// Draws `arrows` (the object's frame) in linear RGB `color` from the next frame on; none
    /// when empty.
    pub fn set_arrows(&mut self, ctx: &GpuContext, arrows: &[Arrow], color: [f32; 3]) {
        self.color = color;
        if arrows.is_empty() {
            self.arrows = None;
            return;
        }
        let data: Vec<GpuArrow> = arrows.iter().map(GpuArrow::from).collect();
        let bytes = bytemuck::cast_slice(&data);
        let bind = opaque_storage_bind_group(&ctx.device, &self.layout, &self.uniforms, "arrows", bytes);
        self.arrows = Some((bind, data.len() as u32));
    }

    pub fn clear(&mut self) {
        self.arrows = None;
    }

    /// How many arrows it draws.
    pub fn count(&self) -> u32 {
        self.arrows.as_ref().map_or(0, |a| a.1)
    }
}

impl super::frame::Representation for ArrowsPass {
    fn new(ctx: &GpuContext, _shared: &super::frame::Shared<'_>) -> Self {
        Self::new(ctx)
    }

    fn instance(&self, ctx: &GpuContext) -> Self {
        self.instance(ctx)
    }

    fn clear(&mut self, _ctx: &GpuContext) {
        self.clear();
    }
}

impl Draw for ArrowsPass {
    fn prepare(&mut self, f: &Prepare<'_>) {
        if self.arrows.is_none() {
            return;
        }
        let [r, g, b] = self.color;
        let u = ArrowUniforms {
            clip_from_object: f.view.clip_from_object.to_cols_array_2d(),
            eye: f.view.eye.extend(1.0).to_array(),
            light: f.view.light.extend(0.0).to_array(),
            color: [r, g, b, 1.0],
        };
        f.ctx.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
    }

    fn phases(&self) -> &'static [Phase] {
        &[Phase::Opaque]
    }

    fn draw(&self, _phase: Phase, pass: &mut wgpu::RenderPass<'_>) {
        if let Some((bind, count)) = &self.arrows {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, bind, &[]);
            pass.draw(0..36, 0..*count);
        }
    }
}
