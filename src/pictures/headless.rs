//! Rendering to an image without a window: the CLI's `render`, the benchmarks and the
//! golden-image tests use this, through the same [`Renderer`] as the viewer.

use crate::gpu::oit::FragmentStats;
use crate::gpu::{FrameInput, GpuContext, GpuError, OffscreenTarget, Renderer};
use crate::layers::{object_centre, show_atoms, show_isosurfaces};
use crate::model::Document;
use crate::scene::{AtomLook, Camera, RenderSettings, VolumeSettings};

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
        let layer = renderer.main();
        show_atoms(ctx, layer, doc, &AtomLook::of(settings), "");
        layer.clip_centre = object_centre(doc);
        let grid = volume_index.and_then(|i| doc.volumes.get(i));
        layer.set_volume(ctx, grid)?;
        if let Some(grid) = grid {
            show_isosurfaces(ctx, layer, grid, &settings.iso);
        }
        Ok(Self { renderer, target: OffscreenTarget::new(&ctx.device, size) })
    }

    /// Records and submits one frame (waits for it only when it has translucent surfaces).
    pub fn draw(&mut self, ctx: &GpuContext, camera: &Camera, settings: &RenderSettings) {
        // The one layer holds the whole scene: the plane cuts all of it.
        self.renderer.main().clip = settings.clip;
        let frame = FrameInput::single(camera, settings, self.target.size);
        draw_exact(ctx, &mut self.renderer, &self.target.color_view, &frame);
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

/// Draws `frame` into `output` and submits it. With translucent surfaces it waits for the
/// fragment counts, and a frame whose lists overflowed is drawn again in more bands until every
/// fragment was kept. Returns the last counts.
pub fn draw_exact(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    output: &wgpu::TextureView,
    frame: &FrameInput,
) -> Option<FragmentStats> {
    let mut last_bands = 0;
    loop {
        let mut encoder = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        renderer.render(ctx, &mut encoder, output, frame);
        ctx.queue.submit([encoder.finish()]);
        let stats = renderer.settle_fragments(ctx)?;
        // No more bands to be had (one per row, or the most there are): the counts say so.
        if stats.fits() || stats.bands == last_bands {
            return Some(stats);
        }
        last_bands = stats.bands;
    }
}

/// Draws `renderer`'s scene from `camera` over `background` into `target` (every translucent
/// fragment kept, [`draw_exact`]) and reads the picture back, with the fragment counts.
pub fn picture(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    target: &OffscreenTarget,
    camera: &Camera,
    background: [f32; 3],
    clouds: &[VolumeSettings],
) -> Result<(image::RgbaImage, Option<FragmentStats>), GpuError> {
    let frame = FrameInput { camera, background, clouds, size: target.size, tile: None };
    let stats = draw_exact(ctx, renderer, &target.color_view, &frame);
    Ok((target.read_rgba(&ctx.device, &ctx.queue)?, stats))
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
