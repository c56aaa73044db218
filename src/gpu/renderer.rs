//! One renderer for every host: the window, the CLI and the tests draw through it.

use glam::{Mat4, Vec3};

use super::arrows::ArrowsPass;
use super::atoms::AtomsPass;
use super::frame::{Draw, FrameTargets, ObjectView, Phase, PhaseNode, PickId, Prepare, STANDARD_FRAME};
use super::isosurface::IsosurfacePass;
use super::occlusion::DepthPyramid;
use super::oit::{FragmentDump, FragmentLists, FragmentStats, MAX_BANDS, Transparency};
use super::resolve::{Lists, ResolvePass, Rows};
use super::volume::{MAX_WALKED, VolumePass, VolumeTexture, overlapping_groups};
use super::{GpuContext, GpuError};
use crate::model::GridSpec;
use crate::model::cartesian::CartesianExpansion;
use crate::model::octree::box_corners;
use crate::model::{Molecule, VolumeGrid};
use crate::scene::translucency::TranslucentSurface;
use crate::scene::{AtomColors, AtomStyle, Camera, ClipPlane, RenderSettings, VolumeSettings};

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

/// One object of the scene on the GPU: its atoms, isosurfaces and cloud, each a long-lived
/// instance of its pass, drawn where `world_from_object` places them. Its index in the
/// renderer is the object number its pick ids carry.
pub struct Layer {
    pub atoms: AtomsPass,
    /// Arrows (a normal mode's displacements) drawn with the atoms.
    pub arrows: ArrowsPass,
    pub surfaces: IsosurfacePass,
    pub volume: VolumePass,
    /// A rigid placement (rotation and translation).
    pub world_from_object: Mat4,
    /// Whether the layer is drawn at all.
    pub visible: bool,
    /// The molecule's bounds in the object's frame, padded by the largest atom.
    molecule_bounds: Option<(Vec3, Vec3)>,
    /// The object's clipping plane, its offset measured from `clip_centre` (object frame).
    pub clip: ClipPlane,
    pub clip_centre: Vec3,
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

    /// Shows a value between two key volumes of a scan (Naka et al., docs/references.md), mixed (1−k):k.
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

    /// Shows an orbital evaluated per fragment from its basis functions (Jang and Varetto's direct mode),
    /// its opacity and gradient scaled to `(max |ψ|, max |∇ψ|)`.
    pub fn set_direct(
        &mut self,
        ctx: &GpuContext,
        expansion: &CartesianExpansion,
        geometry: &GridSpec,
        scale: (f64, f64),
    ) {
        self.volume.set_direct(ctx, expansion, geometry, scale);
    }

    /// Empties the layer (no atoms, surfaces or cloud), keeping its pipelines.
    pub fn clear(&mut self, ctx: &GpuContext) {
        self.set_molecule(ctx, &Molecule::default(), AtomStyle::Hidden);
        self.volume.set_texture(ctx, None);
        self.surfaces.clear();
        self.arrows.clear();
    }

    /// The world-space box around everything the layer draws.
    fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let volume = self.volume.volume().map(|v| v.grid_box.corners().to_vec()).unwrap_or_default();
        let atoms = self.molecule_bounds.map(|(lo, hi)| box_corners(lo, hi).to_vec()).unwrap_or_default();
        let points: Vec<Vec3> =
            volume.into_iter().chain(atoms).map(|p| self.world_from_object.transform_point3(p)).collect();
        let first = *points.first()?;
        Some(points.iter().fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))))
    }

    /// The representations, in the order they draw within a phase.
    fn drawers(&self) -> [&dyn Draw; 4] {
        [&self.atoms, &self.arrows, &self.surfaces, &self.volume]
    }

    fn drawers_mut(&mut self) -> [&mut dyn Draw; 4] {
        [&mut self.atoms, &mut self.arrows, &mut self.surfaces, &mut self.volume]
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
        let layer = Layer {
            atoms: AtomsPass::new(ctx),
            arrows: ArrowsPass::new(ctx),
            surfaces: IsosurfacePass::new(ctx, &lists.collect_layout, &pyramid.read_layout),
            volume: VolumePass::new(ctx, &resolve.layout, &lists.composite_layout),
            world_from_object: Mat4::IDENTITY,
            visible: true,
            molecule_bounds: None,
            clip: ClipPlane::default(),
            clip_centre: Vec3::ZERO,
        };
        Self {
            layers: vec![layer],
            resolve,
            lists,
            pyramid,
            transparency: Transparency::Exact,
            lod_scale: 1.0,
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
        let first = &self.layers[0];
        Layer {
            atoms: first.atoms.instance(ctx),
            arrows: first.arrows.instance(ctx),
            surfaces: first.surfaces.instance(),
            volume: first.volume.instance(ctx),
            world_from_object: Mat4::IDENTITY,
            visible: true,
            molecule_bounds: None,
            clip: ClipPlane::default(),
            clip_centre: Vec3::ZERO,
        }
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
        let resized = self.targets.as_ref().is_none_or(|(t, _)| t.size != frame.size.map(|v| v.max(1)));
        if resized {
            let targets = FrameTargets::new(&ctx.device, frame.size);
            let bind = self.resolve.bind(&ctx.device, &targets.color_view);
            self.pyramid.resize(ctx, targets.size, &targets.depth_view);
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
        let Some((targets, resolve)) = &self.targets else { return };
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
        let lists = (self.lists.surfaces > 0).then(|| self.lists.collect_bind()).flatten();
        let hidden = VolumeSettings { visible: false, ..VolumeSettings::default() };
        // A later tile keeps what the first drew: only the clouds inside it are added, and the
        // fragment lists of a frame drawn in one band.
        let later_tile = frame.tile.is_some_and(|t| !t.first);
        let mut first_translucent = 0;
        for (n, layer) in self.layers.iter_mut().enumerate() {
            let view = ObjectView::new(&world, layer.world_from_object);
            let prepare = Prepare {
                ctx,
                view: &view,
                layer: n as u32,
                size: frame.size,
                depth: &targets.depth_view,
                later_tile,
                lod_scale: self.lod_scale,
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
        let oit = self.lists.surfaces > 0;
        let [width, height] = targets.size;
        // Weighted blending keeps no lists: one band always.
        let bands = if oit && !weighted { self.lists.bands.clamp(1, MAX_BANDS).min(height) } else { 1 };
        if !weighted {
            self.lists.bands = bands;
        }
        let collects = oit && (bands > 1 || !later_tile);
        if collects && !weighted {
            self.lists.begin_frame(encoder);
        }
        // The clouds drawn from a texture are composited in one depth order with each other and
        // the surfaces, by a walk per pixel (one cloud alone with no surfaces: by its slices).
        let sorted = oit && !weighted;
        let walkable: Vec<usize> = (self.layers.iter().enumerate())
            .filter(|(_, l)| l.visible && l.volume.walkable())
            .map(|(n, _)| n)
            .collect();
        // Clouds whose pixels overlap are walked together, up to MAX_WALKED (more are drawn by
        // their slices, behind); a group apart on screen is walked on its own, in its rectangle.
        let rects: Vec<[u32; 4]> = walkable.iter().map(|&n| self.layers[n].volume.screen_rect()).collect();
        let groups: Vec<(Vec<usize>, [u32; 4])> = overlapping_groups(&rects)
            .into_iter()
            .map(|(g, rect)| (g.into_iter().map(|i| walkable[i]).take(MAX_WALKED).collect(), rect))
            .collect();
        let lists_bind = if sorted { self.lists.composite_bind() } else { None };
        // With surfaces, the walk reads their lists: none, no walk (the slices draw the clouds).
        let walks_group =
            |g: &[usize]| !weighted && (g.len() > 1 || (g.len() == 1 && sorted)) && (!sorted || lists_bind.is_some());
        for (n, layer) in self.layers.iter_mut().enumerate() {
            let walked = groups.iter().any(|(g, _)| g.len() > 1 && walks_group(g) && g.contains(&n));
            layer.volume.set_walked(walked);
        }
        let mut walks: Vec<((wgpu::RenderPipeline, wgpu::BindGroup), [u32; 4])> = (groups.iter())
            .filter(|(g, _)| walks_group(g))
            .filter_map(|(g, rect)| {
                let clouds: Vec<&VolumePass> = g.iter().map(|&n| &self.layers[n].volume).collect();
                Some((VolumePass::walk(ctx, &clouds, &targets.depth_view, sorted)?, *rect))
            })
            .collect();
        // The first group's walk is the resolve of the whole frame; the others follow it in
        // their rectangles.
        let further = walks.split_off(walks.len().min(1));
        let walk = walks.pop().map(|(walk, _)| walk);
        let further: Vec<(Lists, [u32; 4])> = further
            .iter()
            .map(|((pipeline, clouds), rect)| (Lists::Walk(lists_bind, pipeline, clouds), *rect))
            .collect();
        let composite = match (oit, self.lists.weighted().filter(|_| weighted), &walk) {
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
        let resolve_rows = |rows: Option<Rows>| match (walk_rows, rows) {
            (None, rows) => rows,
            (Some((y, h, _)), None) => Some(Rows { start: y, count: h, first: false }),
            (Some((y, h, _)), Some(r)) => {
                let start = r.start.max(y);
                let end = (r.start + r.count).min(y + h);
                (end > start).then_some(Rows { start, count: end - start, first: false })
            }
        };
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
                        if let Some(rows) = resolve_rows(Some(rows)) {
                            self.resolve.draw(encoder, resolve, output, composite, Some(rows), width);
                            for &(walk, rect) in &further {
                                self.resolve.draw_walk(encoder, resolve, output, walk, rect, Some(rows));
                            }
                        }
                    }
                }
                Phase::Resolve => {
                    let rows = resolve_rows(None);
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
}
