//! One renderer for every host: the window, the CLI and the tests draw through it.

use glam::{Mat4, Vec3};

use super::frame::{FrameTargets, ObjectView, Phase, PhaseNode, PickId, Prepare, STANDARD_FRAME, Shared};
pub use super::layer::Layer;
use super::layer::Representations;
use super::occlusion::DepthPyramid;
use super::oit::{FragmentDump, FragmentLists, FragmentStats, MAX_BANDS, Transparency};
use super::resolve::{Lists, ResolvePass, Rows};
use super::volume::{MAX_WALKED, VolumePass, overlapping_groups};
use super::{GpuContext, GpuError};
use crate::scene::translucency::TranslucentSurface;
use crate::scene::{Camera, RenderSettings, VolumeSettings};

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
/// Every tile resolves the whole frame (a walk over clouds: the first copies the whole frame
/// without them, each walks its own rows), so the picture fills in band by band.
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

/// Most objects one scene draws: the object field of a [`PickId`] has 6 bits.
pub const MAX_LAYERS: usize = 64;

/// Draws a frame as [`STANDARD_FRAME`] describes it: each phase one render pass over the shared
/// [`FrameTargets`]; in each, every layer's drawers that draw in that phase, layer by layer.
pub struct Renderer {
    /// At least one; layer `n` is object `n` of the scene.
    layers: Vec<Layer>,
    resolve: ResolvePass,
    /// The translucent surfaces' fragment lists, shared by every layer.
    lists: FragmentLists,
    /// The depth pyramid big surfaces' occlusion tests read.
    pyramid: DepthPyramid,
    transparency: Transparency,
    lod_scale: f32,
    planes_per_texel: f32,
    frame: &'static [PhaseNode],
    /// The targets at the last frame's size, and the resolve pass's view of their colour.
    targets: Option<(FrameTargets, wgpu::BindGroup)>,
}

impl Renderer {
    pub fn new(ctx: &GpuContext) -> Self {
        Self::with_lists(ctx, FragmentLists::new(ctx))
    }

    /// A renderer whose fragment lists hold `capacity` fragments per band (tests use a small
    /// one to see frames drawn in bands).
    pub fn with_fragment_capacity(ctx: &GpuContext, capacity: u32) -> Self {
        Self::with_lists(ctx, FragmentLists::with_capacity(ctx, capacity))
    }

    fn with_lists(ctx: &GpuContext, lists: FragmentLists) -> Self {
        let resolve = ResolvePass::new(ctx, &lists.composite_layout, &lists.weighted_layout);
        let pyramid = DepthPyramid::new(ctx);
        let shared = Shared {
            scene: &resolve.layout,
            collect: &lists.collect_layout,
            composite: &lists.composite_layout,
            pyramid: &pyramid.read_layout,
        };
        let layer = Layer::new(Representations::new(ctx, &shared));
        Self {
            layers: vec![layer],
            resolve,
            lists,
            pyramid,
            transparency: Transparency::Exact,
            lod_scale: 1.0,
            planes_per_texel: f32::INFINITY,
            frame: STANDARD_FRAME,
            targets: None,
        }
    }

    /// How translucent surfaces are composited from the next frame on.
    pub fn set_transparency(&mut self, transparency: Transparency) {
        self.transparency = transparency;
    }

    /// Multiplies every surface's level-of-detail threshold (Lee et al., docs/references.md) and the error its coarser
    /// versions may show: above 1 while the user drags, so more of a big surface is drawn as
    /// points or coarser and the view keeps up.
    pub fn set_lod_scale(&mut self, scale: f32) {
        self.lod_scale = scale;
    }

    /// Caps every cloud's slice planes at this many per texel of its grid along the view
    /// ([`crate::scene::detail::Detail::planes_per_texel`]); infinite (the default) draws the
    /// slice count each cloud asks for.
    pub fn set_planes_per_texel(&mut self, planes: f32) {
        self.planes_per_texel = planes;
    }

    /// The level of detail `detail` asks of surfaces and clouds.
    pub fn set_detail(&mut self, detail: &crate::scene::detail::Detail) {
        self.lod_scale = detail.lod_scale;
        self.planes_per_texel = detail.planes_per_texel;
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
            let layer = self.empty_layer(ctx);
            self.layers.push(layer);
        }
        &mut self.layers[n]
    }

    /// A layer that draws nothing, sharing the first layer's pipelines.
    fn empty_layer(&self, ctx: &GpuContext) -> Layer {
        Layer::new(self.layers[0].representations.instance(ctx))
    }

    /// Inserts an empty layer at `n` (at the end when past it); the layers from `n` on move up
    /// by one. A renderer of [`MAX_LAYERS`] layers takes no more.
    pub fn insert(&mut self, ctx: &GpuContext, n: usize) {
        if self.layers.len() < MAX_LAYERS {
            let layer = self.empty_layer(ctx);
            self.layers.insert(n.min(self.layers.len()), layer);
        }
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
    /// per sample (Jang and Varetto's direct mode).
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
        let radius =
            self.bounds().map_or(10.0, |(lo, hi)| (hi - camera.target).abs().max((camera.target - lo).abs()).length());
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
        let resized = self.ensure_targets(ctx, frame.size);
        let world = self.world_view(frame);
        let Some((targets, _)) = &self.targets else { return };
        // The frame's translucent surfaces, numbered across layers in drawing order.
        let translucent: Vec<TranslucentSurface> = (self.layers.iter().enumerate().filter(|(_, l)| l.visible))
            .flat_map(|(n, l)| {
                l.surfaces.translucent().map(move |optics| TranslucentSurface { optics, object: n as u32 })
            })
            .collect();
        self.lists.prepare(ctx, targets.size, &translucent, &targets.depth_view, resized);
        let weighted = self.transparency == Transparency::WeightedBlended;
        if weighted && self.lists.surfaces > 0 {
            self.lists.weighted_targets(ctx);
        }
        // A later tile keeps what the first drew: only the clouds inside it are added, and the
        // fragment lists of a frame drawn in one band.
        let later_tile = frame.tile.is_some_and(|t| !t.first);
        self.prepare_layers(ctx, &world, frame, later_tile);
        let oit = self.lists.surfaces > 0;
        let height = frame.size[1].max(1);
        // Weighted blending keeps no lists: one band always.
        let bands = if oit && !weighted { self.lists.bands.clamp(1, MAX_BANDS).min(height) } else { 1 };
        if !weighted {
            self.lists.bands = bands;
        }
        // The clouds drawn from a texture are composited in one depth order with each other and
        // the surfaces, by a walk per pixel (one cloud alone with no surfaces: by its slices).
        let sorted = oit && !weighted;
        let clouds: Vec<(usize, [u32; 4])> = (self.layers.iter().enumerate())
            .filter(|(_, l)| l.visible && l.volume.walkable())
            .map(|(n, l)| (n, l.volume.screen_rect()))
            .collect();
        let plan = plan_walks(&clouds, weighted, sorted, sorted && self.lists.composite_bind().is_some());
        for (n, layer) in self.layers.iter_mut().enumerate() {
            layer.volume.set_walked(plan.walked.contains(&n));
        }
        let Some((targets, _)) = &self.targets else { return };
        let walks: Vec<((wgpu::RenderPipeline, wgpu::BindGroup), [u32; 4])> = (plan.walks.iter())
            .filter_map(|(g, rect)| {
                let clouds: Vec<&VolumePass> = g.iter().map(|&n| &self.layers[n].volume).collect();
                Some((VolumePass::walk(ctx, &clouds, &targets.depth_view, sorted)?, *rect))
            })
            .collect();
        let shape = FrameShape { oit, weighted, sorted, bands, collects: oit && (bands > 1 || !later_tile) };
        self.encode_phases(encoder, output, frame, &shape, &walks);
    }

    /// The targets at `size`, made anew when it changed (then true).
    fn ensure_targets(&mut self, ctx: &GpuContext, size: [u32; 2]) -> bool {
        let resized = self.targets.as_ref().is_none_or(|(t, _)| t.size != size.map(|v| v.max(1)));
        if resized {
            let targets = FrameTargets::new(&ctx.device, size);
            let bind = self.resolve.bind(&ctx.device, &targets.color_view);
            self.pyramid.resize(ctx, targets.size, &targets.depth_view);
            self.targets = Some((targets, bind));
        }
        resized
    }

    /// The frame's camera seen from the world, with its headlight.
    fn world_view(&self, frame: &FrameInput) -> ObjectView {
        let cam = frame.camera;
        let eye = cam.eye();
        let (light, up) = super::atoms::headlight(eye, cam.target, cam.up());
        ObjectView {
            clip_from_object: self.clip_from_world(cam, frame.size),
            eye,
            view_dir: (cam.target - eye).normalize_or(Vec3::NEG_Z),
            light,
            up,
        }
    }

    /// Gives every layer's representations the frame ([`super::frame::Draw::prepare`]), the
    /// translucent surfaces numbered across layers in drawing order.
    fn prepare_layers(&mut self, ctx: &GpuContext, world: &ObjectView, frame: &FrameInput, later_tile: bool) {
        let Some((targets, _)) = &self.targets else { return };
        let lists = (self.lists.surfaces > 0).then(|| self.lists.collect_bind()).flatten();
        let hidden = VolumeSettings { visible: false, ..VolumeSettings::default() };
        let mut first_translucent = 0;
        for (n, layer) in self.layers.iter_mut().enumerate() {
            let view = ObjectView::new(world, layer.world_from_object);
            let prepare = Prepare {
                ctx,
                view: &view,
                layer: n as u32,
                size: frame.size,
                depth: &targets.depth_view,
                later_tile,
                lod_scale: self.lod_scale,
                planes_per_texel: self.planes_per_texel,
                first_translucent,
                lists: lists.filter(|_| layer.visible).map(|l| (l, self.transparency)),
                cloud: frame.clouds.get(n).unwrap_or(&hidden),
                clip: layer.clip.plane(layer.clip_centre),
                clip_atoms: layer.clip.atoms,
            };
            for drawer in layer.drawers_mut() {
                drawer.prepare(&prepare);
            }
            if layer.visible {
                first_translucent += layer.drawers().iter().map(|d| d.translucent_surfaces()).sum::<usize>();
            }
        }
    }

    /// Records the frame's phases: opaque passes, culling, the translucent fragments (in bands
    /// when the lists overflow), and the resolve that composites surfaces and walked clouds.
    fn encode_phases(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        output: &wgpu::TextureView,
        frame: &FrameInput,
        shape: &FrameShape,
        walks: &[((wgpu::RenderPipeline, wgpu::BindGroup), [u32; 4])],
    ) {
        let Some((targets, resolve)) = &self.targets else { return };
        let &FrameShape { oit, weighted, sorted, bands, collects } = shape;
        let later_tile = frame.tile.is_some_and(|t| !t.first);
        let [width, height] = targets.size;
        if collects && !weighted {
            self.lists.begin_frame(encoder);
        }
        let lists_bind = if sorted { self.lists.composite_bind() } else { None };
        // The first group's walk is the resolve of the whole frame; the others follow it in
        // their rectangles.
        let walk = walks.first().map(|((pipeline, clouds), _)| (pipeline, clouds));
        let further: Vec<(Lists, [u32; 4])> = (walks.iter().skip(1))
            .map(|((pipeline, clouds), rect)| (Lists::Walk(lists_bind, pipeline, clouds), *rect))
            .collect();
        let composite = match (oit, self.lists.weighted().filter(|_| weighted), walk) {
            (true, Some(w), _) => Some(Lists::Weighted(&w.resolve_bind)),
            (_, _, Some((pipeline, clouds))) => Some(Lists::Walk(lists_bind, pipeline, clouds)),
            (false, _, _) => None,
            (true, _, _) => lists_bind.map(Lists::Sorted),
        };
        // A tile of a walked frame walks its own rows; the first shows the rest without clouds.
        let walk_rows = frame
            .tile
            .filter(|_| matches!(composite, Some(Lists::Walk(..))))
            .map(|Tile { rect: [_, y, _, h], first }| (y, h, first));
        for node in self.frame {
            if node.phase == Phase::Resolve && walk_rows.is_some_and(|(_, _, first)| first) {
                self.resolve.draw(encoder, resolve, output, None, None, width);
            }
            match node.phase {
                Phase::Resolve if bands > 1 => {
                    for band in 0..bands {
                        let (start, count) = FragmentLists::band_rows(height, band, bands);
                        self.collect(encoder, targets, frame.background, Some((start, count)));
                        self.lists.end_band(encoder, band);
                        let rows = Rows { start, count, first: band == 0 };
                        if let Some(rows) = rows_to_resolve(walk_rows, Some(rows)) {
                            self.resolve.draw(encoder, resolve, output, composite, Some(rows), width);
                            for &(walk, rect) in &further {
                                self.resolve.draw_walk(encoder, resolve, output, walk, rect, Some(rows));
                            }
                        }
                    }
                }
                Phase::Resolve => {
                    let rows = rows_to_resolve(walk_rows, None);
                    self.resolve.draw(encoder, resolve, output, composite, rows, width);
                    for &(walk, rect) in &further {
                        self.resolve.draw_walk(encoder, resolve, output, walk, rect, rows);
                    }
                }
                Phase::Fragments if collects && weighted => self.collect_weighted(encoder),
                Phase::Fragments => {
                    if collects && bands == 1 {
                        self.collect(encoder, targets, frame.background, None);
                        self.lists.end_band(encoder, 0);
                    }
                }
                Phase::Cull | Phase::Opaque | Phase::Occlusion | Phase::OpaqueLate if later_tile => {}
                Phase::Occlusion | Phase::OpaqueLate if !self.culls_by_depth() => {}
                Phase::Occlusion => {
                    let Some(pyramid) = self.pyramid.build(encoder) else { continue };
                    for layer in self.layers.iter().filter(|l| l.visible) {
                        for drawer in layer.drawers().into_iter().filter(|d| d.culls_by_depth()) {
                            drawer.occlude(encoder, pyramid);
                        }
                    }
                }
                Phase::Cull => {
                    for layer in self.layers.iter().filter(|l| l.visible) {
                        for drawer in layer.drawers().into_iter().filter(|d| d.phases().contains(&Phase::Cull)) {
                            drawer.compute(encoder);
                        }
                    }
                }
                _ => {
                    let mut pass = targets.begin(encoder, node, frame.background);
                    if let Some(Tile { rect: [x, y, w, h], .. }) = frame.tile
                        && node.phase == Phase::Translucent
                    {
                        let [fw, fh] = targets.size;
                        let (x, y) = (x.min(fw - 1), y.min(fh - 1));
                        pass.set_scissor_rect(x, y, w.clamp(1, fw - x), h.clamp(1, fh - y));
                    }
                    self.draw_phase(node.phase, &mut pass);
                }
            }
        }
        if collects && !weighted {
            self.lists.end_frame(encoder);
        }
    }

    /// Weighted blending's one pass: every translucent fragment adds to the sums.
    fn collect_weighted(&self, encoder: &mut wgpu::CommandEncoder) {
        let Some(w) = self.lists.weighted() else { return };
        let attachment = |view, clear| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store },
            })
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("weighted blended surfaces"),
            color_attachments: &[
                attachment(&w.accum, wgpu::Color::TRANSPARENT),
                attachment(&w.revealage, wgpu::Color::WHITE),
            ],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.draw_phase(Phase::Fragments, &mut pass);
    }

    /// Whether a visible layer draws something this frame that the depth pyramid may hide.
    fn culls_by_depth(&self) -> bool {
        self.layers.iter().filter(|l| l.visible).any(|l| l.drawers().iter().any(|d| d.culls_by_depth()))
    }

    /// Every visible layer's drawers of `phase`, layer by layer, into the open pass.
    fn draw_phase(&self, phase: Phase, pass: &mut wgpu::RenderPass<'_>) {
        for layer in self.layers.iter().filter(|l| l.visible) {
            for drawer in layer.drawers().into_iter().filter(|d| d.phases().contains(&phase)) {
                drawer.draw(phase, pass);
            }
        }
    }

    /// Empties the fragment lists and collects the translucent surfaces' fragments, in the
    /// rows `band` (start, count) or the whole frame.
    fn collect(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        background: [f32; 3],
        band: Option<(u32, u32)>,
    ) {
        self.lists.clear(encoder);
        let Some(node) = self.frame.iter().find(|n| n.phase == Phase::Fragments) else { return };
        let mut pass = targets.begin(encoder, node, background);
        if let Some((start, count)) = band {
            pass.set_scissor_rect(0, start, targets.size[0], count.max(1));
        }
        self.draw_phase(Phase::Fragments, &mut pass);
    }

    /// The last frame's fragment lists (its last band's) and its float colour before the
    /// translucent surfaces went over it (linear RGB, row by row): what the CPU reference
    /// composites ([`crate::scene::translucency::composite`]).
    pub fn read_translucency(&self, ctx: &GpuContext) -> Result<(FragmentDump, Vec<[f32; 3]>), GpuError> {
        let Some((targets, _)) = &self.targets else { return Err(GpuError::Readback("no frame was drawn".into())) };
        let bytes = super::readback::read_texture(&ctx.device, &ctx.queue, &targets.color, 8)?;
        let halves: &[half::f16] = bytemuck::cast_slice(&bytes);
        let behind = halves.chunks_exact(4).map(|c| [c[0].to_f32(), c[1].to_f32(), c[2].to_f32()]).collect();
        Ok((self.lists.read(ctx)?, behind))
    }

    /// Whether the last frame drew translucent surfaces (through fragment lists).
    pub fn has_translucent(&self) -> bool {
        self.lists.surfaces > 0
    }

    /// Waits for the last frame's fragment counts. When the lists overflowed, later frames
    /// are drawn in more bands; the caller draws the frame again (`fits()` is false).
    pub fn settle_fragments(&mut self, ctx: &GpuContext) -> Option<FragmentStats> {
        if !self.has_translucent() || self.transparency != Transparency::Exact {
            return None;
        }
        let stats = self.lists.read_stats(ctx)?;
        self.lists.bands = stats.bands_needed();
        Some(stats)
    }

    /// Like [`Self::settle_fragments`] without waiting: the counts of a frame that has
    /// finished, if one has (the viewer asks every frame and redraws when they overflowed).
    pub fn poll_fragments(&mut self) -> Option<FragmentStats> {
        if !self.has_translucent() || self.transparency != Transparency::Exact {
            return None;
        }
        self.lists.request_stats();
        let stats = self.lists.take_stats()?;
        self.lists.bands = stats.bands_needed();
        Some(stats)
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

    /// The opaque depth the last frame drew at `pixel` (0 near; `None` where nothing was
    /// drawn). A depth texture is copied whole (WebGPU copies no part of one): a hover's
    /// question, not a frame's.
    pub fn depth_at(&self, ctx: &GpuContext, pixel: [u32; 2]) -> Result<Option<f32>, GpuError> {
        let Some((targets, _)) = &self.targets else { return Ok(None) };
        if pixel[0] >= targets.size[0] || pixel[1] >= targets.size[1] {
            return Ok(None);
        }
        let bytes = super::readback::read_texture(&ctx.device, &ctx.queue, &targets.depth, 4)?;
        let at = (pixel[1] * targets.size[0] + pixel[0]) as usize * 4;
        let depth = bytes.get(at..at + 4).map_or(1.0, |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        Ok((depth < 1.0).then_some(depth))
    }
}

/// How a frame composites what it draws, decided before any phase is recorded.
struct FrameShape {
    /// It has translucent surfaces.
    oit: bool,
    /// They are blended by weight (no lists, no walk).
    weighted: bool,
    /// They are kept in per-pixel lists in exact depth order.
    sorted: bool,
    /// The lists are filled and resolved in this many bands of rows.
    bands: u32,
    /// This tile fills the lists.
    collects: bool,
}

/// Which clouds a frame walks per pixel in one depth order, and where ([`plan_walks`]).
#[derive(Debug, PartialEq)]
pub struct WalkPlan {
    /// The groups walked, each its layers (at most [`MAX_WALKED`]) and screen rectangle; the
    /// first one's walk is the frame's resolve, the others follow it in their rectangles.
    pub walks: Vec<(Vec<usize>, [u32; 4])>,
    /// The layers walked together with others: their slices are not drawn.
    pub walked: Vec<usize>,
}

/// Plans a frame's walks from its walkable `clouds` (layer and screen rectangle, in layer
/// order). Clouds whose pixels overlap are walked together, up to [`MAX_WALKED`] (more are drawn
/// by their slices, behind); a group apart on screen is walked on its own, in its rectangle.
/// Nothing is walked under weighted blending (`weighted`); a lone cloud is walked only to meet
/// the surfaces' `sorted` lists, and a frame with sorted lists walks only when it can read them
/// (`lists`).
pub fn plan_walks(clouds: &[(usize, [u32; 4])], weighted: bool, sorted: bool, lists: bool) -> WalkPlan {
    let rects: Vec<[u32; 4]> = clouds.iter().map(|c| c.1).collect();
    let walks_group = |g: &[usize]| !weighted && (g.len() > 1 || (g.len() == 1 && sorted)) && (!sorted || lists);
    let walks: Vec<(Vec<usize>, [u32; 4])> = overlapping_groups(&rects)
        .into_iter()
        .map(|(g, rect)| (g.into_iter().map(|i| clouds[i].0).take(MAX_WALKED).collect::<Vec<_>>(), rect))
        .filter(|(g, _)| walks_group(g))
        .collect();
    let walked = walks.iter().filter(|(g, _)| g.len() > 1).flat_map(|(g, _)| g.iter().copied()).collect();
    WalkPlan { walks, walked }
}

/// The rows a resolve draws: a band's `rows` (or the whole frame), within a walked tile's own
/// rows when the frame is drawn in tiles (`walk_rows`: its first row, height and whether it
/// is the first tile).
fn rows_to_resolve(walk_rows: Option<(u32, u32, bool)>, rows: Option<Rows>) -> Option<Rows> {
    match (walk_rows, rows) {
        (None, rows) => rows,
        (Some((y, h, _)), None) => Some(Rows { start: y, count: h, first: false }),
        (Some((y, h, _)), Some(r)) => {
            let start = r.start.max(y);
            let end = (r.start + r.count).min(y + h);
            (end > start).then(|| Rows { start, count: end - start, first: false })
        }
    }
}

#[cfg(test)]
mod plan_tests {
    use super::*;

    #[test]
    fn overlapping_clouds_are_walked_together_and_apart_ones_alone() {
        // Layers 1 and 3 overlap on screen; layer 5 is apart.
        let clouds = [(1, [0, 0, 100, 100]), (3, [50, 50, 150, 150]), (5, [300, 0, 400, 100])];
        let plan = plan_walks(&clouds, false, false, false);
        assert_eq!(
            plan.walks,
            vec![(vec![1, 3], [0, 0, 150, 150])],
            "a lone cloud with no surfaces draws by its slices"
        );
        assert_eq!(plan.walked, vec![1, 3]);
        let with_surfaces = plan_walks(&clouds, false, true, true);
        assert_eq!(with_surfaces.walks.len(), 2, "with sorted surfaces every cloud meets them in a walk");
        assert_eq!(with_surfaces.walked, vec![1, 3], "a lone walked cloud still draws as itself");
        assert!(plan_walks(&clouds, false, true, false).walks.is_empty(), "unreadable lists: no walk");
        assert!(plan_walks(&clouds, true, false, false).walks.is_empty(), "weighted blending walks nothing");
    }

    #[test]
    fn at_most_max_walked_clouds_share_a_walk() {
        let clouds: Vec<(usize, [u32; 4])> = (0..MAX_WALKED + 2).map(|n| (n, [0, 0, 10, 10])).collect();
        let plan = plan_walks(&clouds, false, false, false);
        assert_eq!(plan.walks[0].0.len(), MAX_WALKED);
        assert!(!plan.walked.contains(&(MAX_WALKED + 1)), "the rest draw by their slices");
    }

    #[test]
    fn a_walked_tile_resolves_only_its_rows_of_each_band() {
        let band = Rows { start: 0, count: 100, first: true };
        assert_eq!(rows_to_resolve(None, Some(band)), Some(band));
        let tile = Some((40, 30, false));
        assert_eq!(rows_to_resolve(tile, None), Some(Rows { start: 40, count: 30, first: false }));
        assert_eq!(rows_to_resolve(tile, Some(band)), Some(Rows { start: 40, count: 30, first: false }));
        assert_eq!(rows_to_resolve(tile, Some(Rows { start: 80, count: 20, first: false })), None);
    }
}
