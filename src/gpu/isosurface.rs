//! Lit isosurfaces: one triangle mesh per surface (an orbital's +v and −v, a density's one).
//! Opaque ones draw in the opaque phase with depth and pick ids; translucent ones (Koide and Miyata, docs/references.md)
//! append their fragments to the frame's per-pixel lists ([`super::oit`]).

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::GpuContext;
use super::frame::{Draw, ObjectView, Phase, PickId, opaque_depth, opaque_targets};
use super::occlusion::{BatchCuller, CulledBatches};
use super::oit::Transparency;
use crate::model::isosurface::Mesh;
use crate::model::octree::{LodLevel, LodView, Selection};
use crate::scene::transfer::NO_CUT;
use crate::scene::translucency::{MAX_TRANSLUCENT_SURFACES, Optics, SurfaceLook};

/// Mirror of `SurfaceUniforms` in isosurface.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct SurfaceUniforms {
    pub clip_from_world: [[f32; 4]; 4],
    pub eye: [f32; 4],
    pub light: [f32; 4],
    pub color: [f32; 4],
    pub pick: [u32; 4],
    /// The object's clipping plane (unit n, d; points with n·p > d are cut away), or
    /// [`NO_CUT`].
    pub cut: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<SurfaceUniforms>() == 144);

/// One splat as the instance buffer holds it (mirror of `vs_splat`'s inputs).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct SplatInstance {
    centre: [f32; 3],
    radius: f32,
    normal: [f32; 3],
    tint: [f32; 3],
}

/// Interleaved position, normal and tint (the vertex's colour, white for a one-colour
/// surface), as the vertex buffer holds them.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct SurfaceVertex {
    position: [f32; 3],
    normal: [f32; 3],
    tint: [f32; 3],
}

struct GpuSurface {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    uniforms: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    color: [f32; 3],
    /// The surface's index in its layer.
    pick: u32,
    optics: Option<Optics>,
    /// This frame: its index among the frame's translucent surfaces (`None`: drawn opaque).
    translucent: Option<u32>,
    /// Lee et al.'s level of detail (big opaque surfaces): the octrees of the mesh and of its
    /// coarser versions (their reordered indices, one after another, are the index buffer)
    /// and what this frame draws of them.
    lod: Option<Lod>,
}

struct Lod {
    /// Finest (the mesh itself) first.
    levels: LodLevels,
    /// Where each level's triangles and cells start among all levels'.
    starts: Vec<(u32, u32)>,
    /// The level drawn this frame.
    level: usize,
    threshold_px: f32,
    /// The selection's batches on the GPU, drawn in two phases with occlusion culling.
    batches: CulledBatches,
    /// Room for a splat per cell.
    splats: wgpu::Buffer,
    selection: Selection,
    /// The selection's splats, as uploaded.
    staged: Vec<SplatInstance>,
}

/// What the last frame drew of the surfaces with a level of detail: triangles chosen, points,
/// triangles in all (of the mesh itself), and the coarsest version drawn (0: the mesh).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LodStats {
    pub triangles: u64,
    pub splats: u64,
    pub total_triangles: u64,
    pub level: usize,
}

/// A mesh's levels of detail, finest (the mesh itself) first.
pub type LodLevels = Vec<LodLevel>;

/// Of the triangles the level of detail chose last frame: those drawn first (their cluster
/// was seen the frame before), and those drawn after the occlusion test; the rest it hid.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OcclusionStats {
    pub chosen: u64,
    pub first: u64,
    pub second: u64,
}

/// The octree's leaves: about an atom's size (3 Å), in bohr.
pub const LEAF_SIZE: f32 = 5.7;

/// Coarser versions of a big surface: each keeps this share of the previous one's triangles,
/// within an error of MAX_VERSION_ERROR (bohr); so many at most. On the 10⁵-atom SES (1.7 M
/// triangles) they hold 1.35 M down to 0.57 M and take about 2 s on two cores.
pub const VERSION_KEEPS: f32 = 0.8;
pub const MAX_VERSION_ERROR: f32 = 2.0;
pub const COARSER_VERSIONS: usize = 6;

/// A coarser version is drawn where the view shows its error under this many pixels (times
/// the level-of-detail factor while dragging), at the mesh's nearest corner. The error weighs
/// normals too, so it reads larger than the move. Measured on the 10⁵-atom SES at 800×600:
/// framed, the version drawn (0.69 M triangles) changes the picture by 1.77/255; zoomed out
/// 2×, (0.57 M) by 0.60/255.
pub const MAX_ERROR_PX: f32 = 2.5;

/// The LOD threshold (pixels) of a surface drawn with a level of detail: opaque ones that ask.
fn lod_threshold(look: &SurfaceLook) -> Option<f32> {
    look.lod_px.filter(|_| look.optics.is_none())
}

/// The levels of detail each mesh is drawn with (`None` where it has none): its coarser
/// versions and every level's octree. Plain CPU work, for a background job.
pub fn lod_trees(meshes: &[(Mesh, SurfaceLook)]) -> Vec<Option<LodLevels>> {
    meshes
        .iter()
        .map(|(mesh, look)| lod_threshold(look).filter(|_| !mesh.is_empty()).map(|_| lod_levels(mesh)))
        .collect()
}

/// `mesh`'s levels of detail: its own octree, then its coarser versions'.
pub fn lod_levels(mesh: &Mesh) -> LodLevels {
    LodLevel::all(mesh, LEAF_SIZE, (VERSION_KEEPS, MAX_VERSION_ERROR, COARSER_VERSIONS))
}

pub struct IsosurfacePass {
    pipeline: wgpu::RenderPipeline,
    closed: wgpu::RenderPipeline,
    splat: wgpu::RenderPipeline,
    collect: wgpu::RenderPipeline,
    weighted: wgpu::RenderPipeline,
    transparency: Transparency,
    layout: wgpu::BindGroupLayout,
    culler: BatchCuller,
    /// Whether big surfaces are occlusion culled (tests compare frames without it).
    occlusion: bool,
    surfaces: Vec<GpuSurface>,
    /// The frame's fragment lists (set in `prepare` when a surface is translucent).
    lists: Option<wgpu::BindGroup>,
    /// Whether this frame's clipping plane cuts the surfaces.
    cut: bool,
}

impl IsosurfacePass {
    /// `lists`: the layout of the fragment lists' collect group; `pyramid`: of the depth
    /// pyramid's read group.
    pub fn new(ctx: &GpuContext, lists: &wgpu::BindGroupLayout, pyramid: &wgpu::BindGroupLayout) -> Self {
        let device = &ctx.device;
        let module = super::shader_module(device, "isosurface.wgsl");
        let (layout, pipeline_layout) = super::uniform_layouts(device, "isosurface");
        let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3];
        let vertex = wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<SurfaceVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &attributes,
            })],
        };
        let opaque = |label, cull_mode| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pipeline_layout),
                vertex: vertex.clone(),
                primitive: wgpu::PrimitiveState { cull_mode, ..Default::default() },
                depth_stencil: Some(opaque_depth()),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &opaque_targets(),
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        // Both sides: a surface cut by the grid's box shows its inside.
        let pipeline = opaque("isosurfaces", None);
        // A closed surface (molecular surfaces, wound counter-clockwise seen from outside) shows
        // only its outside: the rasteriser skips the half facing away.
        let closed = opaque("closed surfaces", Some(wgpu::Face::Back));
        let splat_attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32, 2 => Float32x3, 3 => Float32x3];
        let splat = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("surface splats"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_splat"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<SplatInstance>() as u64,
                    step_mode: wgpu::VertexStepMode::Instance,
                    attributes: &splat_attributes,
                })],
            },
            primitive: wgpu::PrimitiveState { topology: wgpu::PrimitiveTopology::TriangleStrip, ..Default::default() },
            depth_stencil: Some(opaque_depth()),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_splat"),
                compilation_options: Default::default(),
                targets: &opaque_targets(),
            }),
            multiview_mask: None,
            cache: None,
        });
        let collect_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("translucent isosurfaces"),
            bind_group_layouts: &[Some(&layout), Some(lists)],
            immediate_size: 0,
        });
        let translucent = |label, entry, targets: &[Option<wgpu::ColorTargetState>]| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&collect_layout),
                vertex: vertex.clone(),
                // Every face: front faces enter a surface, back faces leave it.
                primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        // The pass needs an attachment; nothing is written to it.
        let collect = translucent(
            "translucent isosurfaces",
            "fs_collect",
            &[Some(wgpu::ColorTargetState {
                format: super::SCENE_FORMAT,
                blend: None,
                write_mask: wgpu::ColorWrites::empty(),
            })],
        );
        let add = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let reveal = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Zero,
            dst_factor: wgpu::BlendFactor::OneMinusSrc,
            operation: wgpu::BlendOperation::Add,
        };
        let weighted = translucent(
            "weighted blended isosurfaces",
            "fs_weighted",
            &[
                Some(wgpu::ColorTargetState {
                    format: super::oit::ACCUM_FORMAT,
                    blend: Some(wgpu::BlendState { color: add, alpha: add }),
                    write_mask: wgpu::ColorWrites::ALL,
                }),
                Some(wgpu::ColorTargetState {
                    format: super::oit::REVEALAGE_FORMAT,
                    blend: Some(wgpu::BlendState { color: reveal, alpha: reveal }),
                    write_mask: wgpu::ColorWrites::ALL,
                }),
            ],
        );
        Self {
            pipeline,
            closed,
            splat,
            collect,
            weighted,
            layout,
            culler: BatchCuller::new(ctx, pyramid),
            occlusion: true,
            surfaces: Vec::new(),
            lists: None,
            cut: false,
            transparency: Transparency::Exact,
        }
    }

    /// Replaces the surfaces shown: each mesh with its look. Surface `n` picks as
    /// `PickId::Surface { object, index: n }`, the object given each frame (translucent ones
    /// are not picked: what lies behind them is).
    pub fn set_meshes(&mut self, ctx: &GpuContext, meshes: &[(Mesh, SurfaceLook)]) {
        self.set_meshes_with_trees(ctx, meshes, lod_trees(meshes));
    }

    /// [`Self::set_meshes`] with the octrees [`lod_trees`] built (off the UI thread: a
    /// million triangles take a sixth of a second).
    pub fn set_meshes_with_trees(
        &mut self,
        ctx: &GpuContext,
        meshes: &[(Mesh, SurfaceLook)],
        trees: Vec<Option<LodLevels>>,
    ) {
        let device = &ctx.device;
        let mut trees = trees.into_iter();
        self.surfaces = meshes
            .iter()
            .map(|m| (m, trees.next().flatten()))
            .enumerate()
            .filter(|(_, ((mesh, _), _))| !mesh.is_empty())
            .map(|(n, ((mesh, look), tree))| {
                let vertices: Vec<SurfaceVertex> = (mesh.positions.iter().zip(&mesh.normals).enumerate())
                    .map(|(i, (p, n))| SurfaceVertex {
                        position: p.to_array(),
                        normal: n.to_array(),
                        tint: mesh.colors.get(i).copied().unwrap_or([1.0; 3]),
                    })
                    .collect();
                let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("isosurface vertices"),
                    contents: bytemuck::cast_slice(&vertices),
                    usage: wgpu::BufferUsages::VERTEX,
                });
                // Drawn with a level of detail: each level's octree order of its triangles, one
                // level after another.
                let levels = tree.filter(|l| !l.is_empty()).zip(lod_threshold(look));
                let contents: Vec<u32> = match &levels {
                    Some((levels, _)) => levels.iter().flat_map(|l| l.tree.indices.iter().copied()).collect(),
                    None => mesh.indices.clone(),
                };
                let indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("isosurface indices"),
                    contents: bytemuck::cast_slice(&contents),
                    usage: wgpu::BufferUsages::INDEX,
                });
                let lod = levels.map(|(levels, threshold_px)| {
                    let starts: Vec<(u32, u32)> = levels
                        .iter()
                        .scan((0u32, 0u32), |at, l| {
                            let start = *at;
                            *at = (at.0 + l.tree.indices.len() as u32 / 3, at.1 + l.tree.cells.len() as u32);
                            Some(start)
                        })
                        .collect();
                    let cells: usize = levels.iter().map(|l| l.tree.cells.len()).sum();
                    let most = levels.iter().map(|l| l.tree.cells.len()).max().unwrap_or(1);
                    Lod {
                        splats: device.create_buffer(&wgpu::BufferDescriptor {
                            label: Some("surface splats"),
                            size: (most.max(1) * std::mem::size_of::<SplatInstance>()) as u64,
                            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                            mapped_at_creation: false,
                        }),
                        batches: CulledBatches::new(ctx, &self.culler, cells),
                        levels,
                        starts,
                        level: 0,
                        threshold_px,
                        selection: Selection::default(),
                        staged: Vec::new(),
                    }
                });
                let uniforms = super::uniform_buffer(device, "isosurface uniforms", size_of::<SurfaceUniforms>());
                let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("isosurface bind group"),
                    layout: &self.layout,
                    entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() }],
                });
                let pick = n as u32;
                GpuSurface {
                    vertices,
                    indices,
                    index_count: mesh.indices.len() as u32,
                    uniforms,
                    bind_group,
                    color: look.color,
                    pick,
                    optics: look.optics,
                    translucent: None,
                    lod,
                }
            })
            .collect();
    }

    pub fn clear(&mut self) {
        self.surfaces.clear();
    }

    pub fn is_empty(&self) -> bool {
        self.surfaces.is_empty()
    }

    /// Another set of surfaces drawn with this one's pipeline.
    pub fn instance(&self) -> Self {
        Self {
            pipeline: self.pipeline.clone(),
            closed: self.closed.clone(),
            splat: self.splat.clone(),
            collect: self.collect.clone(),
            weighted: self.weighted.clone(),
            layout: self.layout.clone(),
            culler: self.culler.clone(),
            occlusion: self.occlusion,
            surfaces: Vec::new(),
            lists: None,
            cut: false,
            transparency: Transparency::Exact,
        }
    }

    /// What the last frame drew of the surfaces drawn with a level of detail.
    pub fn lod_stats(&self) -> LodStats {
        let mut stats = LodStats::default();
        for lod in self.surfaces.iter().filter_map(|s| s.lod.as_ref()) {
            stats.triangles += lod.selection.triangles as u64;
            stats.splats += lod.staged.len() as u64;
            stats.total_triangles += lod.levels[0].tree.indices.len() as u64 / 3;
            stats.level = stats.level.max(lod.level);
        }
        stats
    }

    /// Whether big surfaces are occlusion culled from the next frame on (on by default; the
    /// picture is the same either way).
    pub fn set_occlusion_culling(&mut self, on: bool) {
        self.occlusion = on;
    }

    /// How the last frame's occlusion test split the triangles of the surfaces drawn with a
    /// level of detail (read back from the GPU).
    pub fn occlusion_stats(&self, ctx: &GpuContext) -> Result<OcclusionStats, super::GpuError> {
        let mut stats = OcclusionStats::default();
        for lod in self.surfaces.iter().filter_map(|s| s.lod.as_ref()) {
            let (first, second) = lod.batches.read_drawn(ctx)?;
            stats.chosen += lod.selection.triangles as u64;
            stats.first += first;
            stats.second += second;
        }
        Ok(stats)
    }

    /// The optics of the translucent surfaces, in the order [`Self::prepare`] numbers them.
    pub fn translucent(&self) -> impl Iterator<Item = Optics> + '_ {
        self.surfaces.iter().filter_map(|s| s.optics)
    }

    /// This frame's camera, in the frame of the object the surfaces belong to; their pick ids
    /// name `object`. `lod`: the frame's pixels and the factor on each level of detail's
    /// threshold (`None` keeps what the last call chose: a later tile of the same frame).
    /// Translucent surfaces are numbered from `first_translucent` among the
    /// frame's; past [`MAX_TRANSLUCENT_SURFACES`] they are drawn opaque. `lists`: the frame's
    /// fragment lists, and how they are composited. `clip`: the object's clipping plane (a
    /// closed surface cut open shows its inside).
    #[allow(
        clippy::too_many_arguments,
        reason = "a frame's per-view inputs, each named where the renderer calls it once"
    )]
    pub fn set_view(
        &mut self,
        ctx: &GpuContext,
        view: &ObjectView,
        object: u32,
        lod: Option<([u32; 2], f32)>,
        first_translucent: usize,
        lists: Option<(&wgpu::BindGroup, Transparency)>,
        clip: Option<glam::Vec4>,
    ) {
        self.cut = clip.is_some();
        self.lists = lists.map(|(l, _)| l.clone());
        self.transparency = lists.map_or(Transparency::Exact, |(_, t)| t);
        let mut next = first_translucent;
        for s in &mut self.surfaces {
            s.translucent = None;
            if s.optics.is_some() && next < MAX_TRANSLUCENT_SURFACES && lists.is_some() {
                s.translucent = Some(next as u32);
                next += 1;
            }
            let u = SurfaceUniforms {
                clip_from_world: view.clip_from_object.to_cols_array_2d(),
                eye: view.eye.extend(1.0).to_array(),
                light: view.light.extend(0.0).to_array(),
                color: [s.color[0], s.color[1], s.color[2], 1.0],
                pick: [PickId::Surface { object, index: s.pick }.encode(), s.translucent.unwrap_or(0), 0, 0],
                cut: clip.unwrap_or(NO_CUT).to_array(),
            };
            ctx.queue.write_buffer(&s.uniforms, 0, bytemuck::bytes_of(&u));
            if let (Some(lod), Some((size, lod_scale))) = (&mut s.lod, lod) {
                let lod_view = LodView {
                    clip_from_object: view.clip_from_object,
                    eye: view.eye,
                    height_px: size[1] as f32,
                    threshold_px: lod.threshold_px * lod_scale,
                    back_faces: clip.is_none(),
                };
                let root = &lod.levels[0].tree.cells[0];
                let errors = lod.levels.iter().map(|l| l.error);
                lod.level = lod_view.coarsest_within(errors, (root.lo, root.hi), MAX_ERROR_PX * lod_scale);
                lod.levels[lod.level].tree.select(&lod_view, &mut lod.selection);
                // Batches of this level, in the index buffer and the seen flags of all levels.
                let (triangles, cells) = lod.starts[lod.level];
                for b in &mut lod.selection.batches {
                    b.triangles = b.triangles.start + triangles..b.triangles.end + triangles;
                    b.cluster += cells;
                }
                lod.staged.clear();
                lod.staged.extend(lod.selection.splats.iter().map(|p| SplatInstance {
                    centre: p.centre.to_array(),
                    radius: p.radius,
                    normal: p.normal.to_array(),
                    tint: p.color.to_array(),
                }));
                if !lod.staged.is_empty() {
                    ctx.queue.write_buffer(&lod.splats, 0, bytemuck::cast_slice(&lod.staged));
                }
                lod.batches.prepare(ctx, &self.culler, view.clip_from_object, &lod.selection.batches);
            }
        }
    }
}

impl IsosurfacePass {
    /// The surfaces drawn with a level of detail, with what they draw this frame.
    fn lods(&self) -> impl Iterator<Item = (&GpuSurface, &Lod)> {
        self.surfaces.iter().filter_map(|s| Some((s, s.lod.as_ref()?)))
    }

    /// Binds a surface's mesh for its triangles.
    fn bind_mesh(s: &GpuSurface, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_bind_group(0, &s.bind_group, &[]);
        pass.set_vertex_buffer(0, s.vertices.slice(..));
        pass.set_index_buffer(s.indices.slice(..), wgpu::IndexFormat::Uint32);
    }

    /// The chosen triangles of the surfaces drawn with a level of detail: in the opaque phase
    /// those seen last frame (all of them without occlusion culling), in the late one those
    /// the occlusion test left.
    fn draw_lod_triangles(&self, pass: &mut wgpu::RenderPass<'_>, late: bool) {
        // Cut open, a closed surface shows its inside.
        pass.set_pipeline(if self.cut { &self.pipeline } else { &self.closed });
        for (s, lod) in self.lods() {
            Self::bind_mesh(s, pass);
            if self.occlusion {
                lod.batches.draw(pass, late);
            } else if !late {
                for b in &lod.selection.batches {
                    pass.draw_indexed(3 * b.triangles.start..3 * b.triangles.end, 0, 0..1);
                }
            }
        }
    }
}

impl super::frame::Representation for IsosurfacePass {
    fn new(ctx: &GpuContext, shared: &super::frame::Shared<'_>) -> Self {
        Self::new(ctx, shared.collect, shared.pyramid)
    }

    fn instance(&self, _ctx: &GpuContext) -> Self {
        self.instance()
    }

    fn clear(&mut self, _ctx: &GpuContext) {
        self.clear();
    }
}

impl Draw for IsosurfacePass {
    fn prepare(&mut self, f: &super::frame::Prepare<'_>) {
        let lod = (!f.later_tile).then_some((f.size, f.lod_scale));
        self.set_view(f.ctx, f.view, f.layer, lod, f.first_translucent, f.lists, f.clip);
    }

    fn translucent_surfaces(&self) -> usize {
        self.translucent().count()
    }

    fn phases(&self) -> &'static [Phase] {
        &[Phase::Cull, Phase::Opaque, Phase::OpaqueLate, Phase::Fragments]
    }

    fn compute(&self, encoder: &mut wgpu::CommandEncoder) {
        if self.occlusion {
            for (_, lod) in self.lods() {
                lod.batches.split(&self.culler, encoder);
            }
        }
    }

    fn culls_by_depth(&self) -> bool {
        self.occlusion && self.lods().next().is_some()
    }

    fn occlude(&self, encoder: &mut wgpu::CommandEncoder, pyramid: &wgpu::BindGroup) {
        for (_, lod) in self.lods() {
            lod.batches.cull(&self.culler, encoder, pyramid);
        }
    }

    fn draw(&self, phase: Phase, pass: &mut wgpu::RenderPass<'_>) {
        match phase {
            Phase::OpaqueLate => return self.draw_lod_triangles(pass, true),
            Phase::Opaque => self.draw_lod_triangles(pass, false),
            _ => {}
        }
        let translucent = phase == Phase::Fragments;
        if translucent {
            let Some(lists) = &self.lists else { return };
            pass.set_pipeline(match self.transparency {
                Transparency::Exact => &self.collect,
                Transparency::WeightedBlended => &self.weighted,
            });
            pass.set_bind_group(1, lists, &[]);
        } else {
            pass.set_pipeline(&self.pipeline);
        }
        for s in self.surfaces.iter().filter(|s| s.translucent.is_some() == translucent && s.lod.is_none()) {
            Self::bind_mesh(s, pass);
            pass.draw_indexed(0..s.index_count, 0, 0..1);
        }
        if !translucent {
            pass.set_pipeline(&self.splat);
            for (s, lod) in self.lods().filter(|(_, lod)| !lod.staged.is_empty()) {
                pass.set_bind_group(0, &s.bind_group, &[]);
                pass.set_vertex_buffer(0, lod.splats.slice(..));
                pass.draw(0..4, 0..lod.staged.len() as u32);
            }
        }
    }
}
