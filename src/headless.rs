//! Rendering a document to an image without a window: the CLI's `render`, the benchmarks and
//! the golden-image tests use this, through the same [`Renderer`] as the viewer.

use crate::gpu::{FrameInput, GpuContext, GpuError, OffscreenTarget, Renderer};
use crate::model::Document;
use crate::scene::{Camera, RenderSettings};

/// A camera that frames everything in the document from the default direction.
pub fn default_camera(doc: &Document) -> Camera {
    match doc.bounds() {
        Some((lo, hi)) => Camera::framing(lo.as_vec3(), hi.as_vec3()),
        None => Camera::default(),
    }
}

/// A renderer with an offscreen target of a fixed size.
pub struct Headless {
    pub renderer: Renderer,
    pub target: OffscreenTarget,
}

impl Headless {
    /// Loads `doc` (its volume `volume_index`, if any) into a new renderer.
    pub fn new(
        ctx: &GpuContext,
        doc: &Document,
        volume_index: Option<usize>,
        settings: &RenderSettings,
        size: [u32; 2],
    ) -> Result<Self, GpuError> {
        let mut renderer = Renderer::new(ctx);
        renderer.set_molecule(ctx, &doc.molecule, settings.atoms);
        renderer.set_volume(ctx, volume_index.and_then(|i| doc.volumes.get(i)))?;
        Ok(Self { renderer, target: OffscreenTarget::new(&ctx.device, size) })
    }

    /// Records and submits one frame (does not wait for it).
    pub fn draw(&mut self, ctx: &GpuContext, camera: &Camera, settings: &RenderSettings) {
        let mut encoder = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        let frame = FrameInput { camera, settings, size: self.target.size };
        self.renderer.render(ctx, &mut encoder, &self.target.color_view, &frame);
        ctx.queue.submit([encoder.finish()]);
    }

    /// Draws one frame and reads it back.
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        settings: &RenderSettings,
    ) -> Result<image::RgbaImage, GpuError> {
        self.draw(ctx, camera, settings);
        self.target.read_rgba(&ctx.device, &ctx.queue)
    }
}

/// Renders a document once: the whole pipeline in one call.
pub fn render_document(
    ctx: &GpuContext,
    doc: &Document,
    volume_index: Option<usize>,
    camera: &Camera,
    settings: &RenderSettings,
    size: [u32; 2],
) -> Result<image::RgbaImage, GpuError> {
    Headless::new(ctx, doc, volume_index, settings, size)?.render(ctx, camera, settings)
}
