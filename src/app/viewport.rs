//! The 3D view inside the window: renders through the shared [`Renderer`] into an offscreen
//! texture that egui shows as an image, and turns mouse and keys into camera moves.

use egui::{Key, PointerButton, Sense};

use super::state::{DRAG_ROTATE, KEY_ROTATE, KEY_ZOOM, ViewState};
use crate::gpu::gto::GtoFillPass;
use crate::gpu::{FrameInput, GpuContext, GpuError, OffscreenTarget, Renderer};
use crate::headless::WavefunctionView;
use crate::model::Document;

pub struct Viewport {
    pub ctx: GpuContext,
    renderer: Renderer,
    fill: Option<GtoFillPass>,
    target: Option<(OffscreenTarget, egui::TextureId)>,
    /// The state the texture currently shows; a frame is drawn only when this changes.
    drawn: Option<(ViewState, [u32; 2], u64)>,
    /// Bumped whenever the renderer's data changes.
    generation: u64,
}

impl Viewport {
    pub fn new(ctx: GpuContext) -> Self {
        let renderer = Renderer::new(&ctx);
        Self { ctx, renderer, fill: None, target: None, drawn: None, generation: 0 }
    }

    /// Uploads a document's molecule and chosen volume.
    pub fn set_document(&mut self, doc: &Document, view: &ViewState) -> Result<(), GpuError> {
        self.renderer.set_volume(&self.ctx, doc.volumes.get(view.volume))?;
        self.renderer.set_molecule(&self.ctx, &doc.molecule, view.settings.atoms);
        self.generation += 1;
        Ok(())
    }

    pub fn set_volume(&mut self, doc: &Document, index: usize) -> Result<(), GpuError> {
        self.renderer.set_volume(&self.ctx, doc.volumes.get(index))?;
        self.generation += 1;
        Ok(())
    }

    /// Shows a wavefunction's orbital or density (see [`crate::headless::show_wavefunction`]).
    pub fn show_wavefunction(&mut self, doc: &Document, view: &WavefunctionView) -> Result<(), GpuError> {
        crate::headless::show_wavefunction(&self.ctx, &mut self.renderer, &mut self.fill, doc, view)?;
        self.generation += 1;
        Ok(())
    }

    pub fn set_atom_style(&mut self, doc: &Document, view: &ViewState) {
        self.renderer.set_molecule(&self.ctx, &doc.molecule, view.settings.atoms);
        self.generation += 1;
    }

    /// Shows the view in the remaining space of `ui`, applying mouse and keyboard input to
    /// `view.camera`.
    pub fn show(&mut self, ui: &mut egui::Ui, render_state: &egui_wgpu::RenderState, view: &mut ViewState) {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        handle_input(ui, &response, view);
        let ppp = ui.ctx().pixels_per_point();
        let size = [(rect.width() * ppp).round().max(1.0) as u32, (rect.height() * ppp).round().max(1.0) as u32];
        if self.target.as_ref().is_none_or(|(t, _)| t.size != size) {
            let target = OffscreenTarget::new(&self.ctx.device, size);
            let mut egui_renderer = render_state.renderer.write();
            let id = match self.target.take() {
                Some((_, id)) => {
                    egui_renderer.update_egui_texture_from_wgpu_texture(
                        &self.ctx.device,
                        &target.encoded_view,
                        wgpu::FilterMode::Linear,
                        id,
                    );
                    id
                }
                None => egui_renderer.register_native_texture(
                    &self.ctx.device,
                    &target.encoded_view,
                    wgpu::FilterMode::Linear,
                ),
            };
            self.target = Some((target, id));
            self.drawn = None;
        }
        let key = (*view, size, self.generation);
        if let Some((target, id)) = &self.target {
            if self.drawn != Some(key) {
                let mut encoder =
                    self.ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("viewport") });
                let frame = FrameInput { camera: &view.camera, settings: &view.settings, size };
                self.renderer.render(&self.ctx, &mut encoder, &target.color_view, &frame);
                self.ctx.queue.submit([encoder.finish()]);
                self.drawn = Some(key);
            }
            let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
            ui.painter().image(*id, rect, uv, egui::Color32::WHITE);
        }
    }

    /// Renders the current view at `size` and reads it back (for screenshots).
    pub fn snapshot(&mut self, view: &ViewState, size: [u32; 2]) -> Result<image::RgbaImage, GpuError> {
        let target = OffscreenTarget::new(&self.ctx.device, size);
        let mut encoder =
            self.ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("snapshot") });
        let frame = FrameInput { camera: &view.camera, settings: &view.settings, size };
        self.renderer.render(&self.ctx, &mut encoder, &target.color_view, &frame);
        self.ctx.queue.submit([encoder.finish()]);
        // The viewport's own frame must be redrawn: the renderer's buffers changed size.
        self.drawn = None;
        target.read_rgba(&self.ctx.device, &self.ctx.queue)
    }

    pub fn size(&self) -> Option<[u32; 2]> {
        self.target.as_ref().map(|(t, _)| t.size)
    }
}

fn handle_input(ui: &egui::Ui, response: &egui::Response, view: &mut ViewState) {
    let clip_drag = ui.input(|i| i.modifiers.command) && view.settings.volume.clip.enabled;
    if clip_drag && response.dragged_by(PointerButton::Primary) {
        // Ctrl + drag moves the clipping plane: a view height of drag is the camera distance.
        let h = response.rect.height().max(1.0);
        view.settings.volume.clip.offset -= response.drag_delta().y / h * view.camera.distance * 0.5;
        return;
    }
    let cam = &mut view.camera;
    if response.dragged_by(PointerButton::Primary) {
        let d = response.drag_delta();
        cam.orbit(-d.x * DRAG_ROTATE, d.y * DRAG_ROTATE);
    }
    if response.dragged_by(PointerButton::Secondary) || response.dragged_by(PointerButton::Middle) {
        let d = response.drag_delta();
        let h = response.rect.height().max(1.0);
        cam.pan(d.x / h, d.y / h);
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            cam.zoom((-scroll * 0.002).exp());
        }
    }
    // Keys act whenever no text field has focus.
    if ui.ctx().egui_wants_keyboard_input() {
        return;
    }
    ui.input(|i| {
        // Shift + arrows belong to the orbital browser.
        if i.modifiers.shift {
            return;
        }
        let step = |k| i.key_pressed(k) as i32 as f32;
        cam.orbit(
            (step(Key::ArrowLeft) - step(Key::ArrowRight)) * KEY_ROTATE,
            (step(Key::ArrowUp) - step(Key::ArrowDown)) * KEY_ROTATE,
        );
        if i.key_pressed(Key::Plus) || i.key_pressed(Key::Equals) || i.key_pressed(Key::PageUp) {
            cam.zoom(1.0 / KEY_ZOOM);
        }
        if i.key_pressed(Key::Minus) || i.key_pressed(Key::PageDown) {
            cam.zoom(KEY_ZOOM);
        }
    });
}
