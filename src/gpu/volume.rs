//! The volume pass: a grid as a 3D texture, drawn as translucent slices back to front.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use bytemuck::{Pod, Zeroable};
use glam::{DMat4, DVec3, Mat4, Vec3, Vec4};
use wgpu::util::DeviceExt;

use super::basis_buffers::{GtoArrays, GtoBuffers, gto_layout};
use super::classify::{ClassifiedVolumes, Classifier};
use super::{DEPTH_FORMAT, GpuContext, GpuError, SCENE_FORMAT};
use crate::model::GridSpec;
use crate::model::bricks::{BRICK_CELLS, BrickRanges};
use crate::model::cartesian::CartesianExpansion;
use crate::model::{VolumeGrid, grid::ValueKind};
use crate::scene::occupancy::{Occupancy, visible_floor};
use crate::scene::slicing::{GridBox, Slices};
use crate::scene::{DensityScale, Interpolation, TransferKind, VolumeSettings};

/// Mirror of `VolumeUniforms` in volume_slices.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct VolumeUniforms {
    pub clip_from_world: [[f32; 4]; 4],
    pub tex_from_world: [[f32; 4]; 4],
    pub eye: [f32; 4],
    pub plane: [f32; 4],
    pub positive_color: [f32; 4],
    pub negative_color: [f32; 4],
    pub k1: f32,
    pub k2: f32,
    pub inv_max: f32,
    pub ref_step: f32,
    pub signed_field: u32,
    pub shape_positive: u32,
    pub shape_negative: u32,
    pub tf_bits: u32,
    pub visible_min: f32,
    pub morph_k: f32,
    pub log_lo: f32,
    pub inv_log_span: f32,
    pub tf_positive: [f32; 4],
    pub tf_negative: [f32; 4],
    pub gradient_power: f32,
    pub boundary: f32,
    pub inv_max_grad: f32,
    /// Grid cells per brick edge, the walk's empty-brick test's scale.
    pub brick_cells: f32,
    pub clip: [f32; 4],
    pub light: [f32; 4],
    pub world_from_clip: [[f32; 4]; 4],
    pub box_from_world: [[f32; 4]; 4],
    pub slab: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<VolumeUniforms>() == 464);

pub use crate::scene::opacity::visibility_threshold;

/// Values below this fraction of the grid's largest |value| are invisible at any opacity
/// setting the viewer offers (ψ² of 10⁻⁸ of the maximum).
const ACTIVE_FRACTION: f64 = 1e-4;

/// The part of the grid's box that holds visible values: slices are cut only there, which
/// spares the fragments that cube files' generous margins would cost.
fn active_box(grid: &VolumeGrid) -> GridBox {
    let (lo, hi) = grid
        .active_bounds((ACTIVE_FRACTION * grid.stats.max_abs) as f32)
        .unwrap_or(([0; 3], grid.dims.map(|d| d.saturating_sub(1))));
    let lo_f = DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64);
    GridBox {
        origin: grid.world_from_grid.transform_point3(lo_f).as_vec3(),
        edges: std::array::from_fn(|a| (grid.step(a) * (hi[a] - lo[a]) as f64).as_vec3()),
    }
}

/// A grid uploaded to the GPU, with what the shader needs to place and scale it. Clones share
/// the texture.
#[derive(Debug, Clone)]
pub struct VolumeTexture {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    pub dims: [usize; 3],
    /// Texture coordinates (0..1, texel centres at grid points) from world (bohr).
    pub tex_from_world: Mat4,
    pub grid_box: GridBox,
    pub kind: ValueKind,
    pub max_abs: f32,
    /// Largest gradient magnitude (per bohr), the scale of gradient-based transfer functions.
    pub max_grad: f32,
    /// Mean grid spacing (bohr): the step k1 refers to.
    pub step: f32,
    /// The values' range per brick, where they are known: slices skip the bricks the transfer
    /// function cannot show.
    pub bricks: Option<Arc<BrickRanges>>,
}

impl VolumeTexture {
    /// Uploads a grid. The texture's x (fastest) axis is the grid's k (cube files' fastest), so
    /// no transposition is needed; `tex_from_world` swaps the axes instead.
    pub fn upload(ctx: &GpuContext, grid: &VolumeGrid) -> Result<Self, GpuError> {
        Self::upload_as(ctx, grid, ctx.volume_format)
    }

    /// [`Self::upload`] into a texture of `format` (R32Float needs the device's
    /// FLOAT32_FILTERABLE; R16Float always filters).
    pub fn upload_as(ctx: &GpuContext, grid: &VolumeGrid, format: wgpu::TextureFormat) -> Result<Self, GpuError> {
        let [nx, ny, nz] = grid.dims;
        let max = ctx.device.limits().max_texture_dimension_3d;
        if grid.dims.iter().any(|&d| d == 0 || d > max as usize) {
            return Err(GpuError::VolumeTooLarge { dims: grid.dims, max });
        }
        let bytes: Vec<u8> = match format {
            wgpu::TextureFormat::R32Float => bytemuck::cast_slice(&grid.values).to_vec(),
            _ => {
                let halves: Vec<half::f16> = grid.values.iter().map(|&v| half::f16::from_f32(v)).collect();
                bytemuck::cast_slice(&halves).to_vec()
            }
        };
        let texture = ctx.device.create_texture_with_data(
            &ctx.queue,
            &super::texture_descriptor(
                &format!("volume {}", grid.label),
                wgpu::Extent3d { width: nz as u32, height: ny as u32, depth_or_array_layers: nx as u32 },
                wgpu::TextureDimension::D3,
                format,
                wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            ),
            wgpu::util::TextureDataOrder::LayerMajor,
            &bytes,
        );
        let mut volume = Self::from_texture(texture, grid.dims, grid.world_from_grid, grid.kind, grid.stats.max_abs);
        volume.grid_box = active_box(grid);
        volume.bricks = Some(Arc::new(BrickRanges::of(grid, BRICK_CELLS)));
        volume.max_grad = grid.max_gradient().max(1e-30) as f32;
        Ok(volume)
    }

    /// Wraps a texture already holding a grid's values (texel x = grid k, as [`Self::upload`]).
    pub fn from_texture(
        texture: wgpu::Texture,
        dims: [usize; 3],
        world_from_grid: DMat4,
        kind: ValueKind,
        max_abs: f64,
    ) -> Self {
        let [nx, ny, nz] = dims;
        let view = texture.create_view(&Default::default());
        // tex = ((k + ½)/nz, (j + ½)/ny, (i + ½)/nx) for grid point (i, j, k).
        let tex_from_grid = DMat4::from_cols(
            DVec3::new(0.0, 0.0, 1.0 / nx as f64).extend(0.0),
            DVec3::new(0.0, 1.0 / ny as f64, 0.0).extend(0.0),
            DVec3::new(1.0 / nz as f64, 0.0, 0.0).extend(0.0),
            DVec3::new(0.5 / nz as f64, 0.5 / ny as f64, 0.5 / nx as f64).extend(1.0),
        );
        let tex_from_world = (tex_from_grid * world_from_grid.inverse()).as_mat4();
        let step = |a: usize| world_from_grid.col(a).truncate();
        let voxel = glam::DMat3::from_cols(step(0), step(1), step(2)).determinant().abs();
        let edges = |a: usize| (step(a) * (dims[a].max(1) - 1) as f64).as_vec3();
        Self {
            texture,
            view,
            dims,
            tex_from_world,
            grid_box: GridBox {
                origin: world_from_grid.w_axis.truncate().as_vec3(),
                edges: [edges(0), edges(1), edges(2)],
            },
            kind,
            max_abs: max_abs.max(1e-30) as f32,
            // Without the values at hand: an orbital changes by about its maximum over half a bohr.
            max_grad: (2.0 * max_abs).max(1e-30) as f32,
            step: voxel.cbrt().max(1e-6) as f32,
            bricks: None,
        }
    }
}

/// Which fragment program draws the slices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Program {
    /// One 3D texture.
    Slices,
    /// Jang and Varetto's direct mode: the orbital from its basis functions.
    Direct,
    /// Two key volumes mixed per sample.
    Exact,
    /// Naka et al.'s three-pass compositing, in one pass.
    ThreePass,
    /// Naka et al.'s α-mix (the reference the three passes approximate).
    AlphaMix,
    /// A full-screen pass of the resolve: translucent surfaces' fragments and the samples of
    /// up to [`MAX_WALKED`] clouds composited in one walk per pixel (volume_interleave.wgsl).
    Interleave,
    /// The same walk over several clouds without translucent surfaces.
    Clouds,
}

impl Program {
    fn entry(self) -> &'static str {
        match self {
            Program::Slices => "fs_main",
            Program::Direct => "fs_direct",
            Program::Exact | Program::ThreePass | Program::AlphaMix => "fs_morph",
            Program::Interleave => "fs_interleave",
            Program::Clouds => "fs_clouds",
        }
    }

    fn walks(self) -> bool {
        matches!(self, Program::Interleave | Program::Clouds)
    }

    /// Whether it samples a texture's slices a slab of planes per fragment (volume_slab.wgsl).
    fn slabs(self) -> bool {
        matches!(self, Program::Slices | Program::Exact | Program::ThreePass | Program::AlphaMix)
    }
}

/// Which variant of the slice shader a frame needs: each is its own pipeline, specialised by
/// WGSL override constants.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct Variant {
    program: Program,
    gradient: bool,
    shaped: bool,
    clip: bool,
    /// The clouds a walk takes (0 for the slice programs): with one, its slices drew it first.
    clouds: u8,
    /// Planes per fragment of a texture's slices (1 for the programs without slabs).
    slab: u8,
    /// The cloud's `signed_field` for the slab programs (0 for the others, which read the uniform).
    field: u8,
    /// α-mix and three-pass sample the key volumes' classified textures ([`Classifier`]).
    classified: bool,
}

impl Variant {
    /// The plain slices of a 3D texture with the power law, one plane per fragment.
    const PLAIN: Variant = Variant {
        program: Program::Slices,
        gradient: false,
        shaped: false,
        clip: false,
        clouds: 0,
        slab: 1,
        field: 1,
        classified: false,
    };
}

/// How many planes one fragment of a texture's slices samples, where the eye lies before them
/// all: each fragment's fixed cost on a CPU rasteriser (rasterising, interpolating, blending)
/// is about what sampling several planes costs, so slabs of 8 take about half the time of one
/// slice per plane (volume_slices.wgsl).
pub const SLAB_PLANES: usize = 8;

/// The most clouds one walk composites (one group of clouds that overlap on screen); a group's
/// further clouds are drawn by their slices, behind.
pub const MAX_WALKED: usize = 4;

/// A slice shader module and its pipeline layout.
struct SliceShader {
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
}

impl SliceShader {
    fn new(device: &wgpu::Device, name: &str, groups: &[Option<&wgpu::BindGroupLayout>]) -> Self {
        let module = super::shader_module(device, name);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(name),
            bind_group_layouts: groups,
            immediate_size: 0,
        });
        Self { module, layout }
    }
}

/// The second key volume of an interpolated frame, and how to mix.
struct Morph {
    partner: VolumeTexture,
    /// B, then A's and B's classified textures (where a frame has not classified them, their
    /// plain textures stand in, unread).
    bind_group: wgpu::BindGroup,
    /// The classified textures `bind_group` holds, if any.
    bound: Option<[wgpu::TextureView; 2]>,
    k: f32,
    mode: Interpolation,
}

/// What every cloud shares: shader modules, layouts, the sampler and the pipelines built so far
/// (one per [`Variant`], built the first time a frame needs it).
struct VolumeShaders {
    slices: SliceShader,
    direct: SliceShader,
    morph: SliceShader,
    interleave: SliceShader,
    /// The walk over clouds without fragment lists: the interleave module, no group 2.
    clouds: SliceShader,
    layout: wgpu::BindGroupLayout,
    /// The slab programs' group 2: the opaque scene's depth, which a slab's samples stop at.
    depth_layout: wgpu::BindGroupLayout,
    /// The walk's group 0: [`MAX_WALKED`] clouds' uniforms and textures and the scene's depth.
    walk_layout: wgpu::BindGroupLayout,
    morph_layout: wgpu::BindGroupLayout,
    gto_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    classifier: Classifier,
    pipelines: Mutex<HashMap<Variant, wgpu::RenderPipeline>>,
}

impl VolumeShaders {
    /// The pipeline of `variant`, built now if no cloud has needed it before.
    fn pipeline(&self, device: &wgpu::Device, variant: Variant) -> wgpu::RenderPipeline {
        let mut pipelines = self.pipelines.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        pipelines
            .entry(variant)
            .or_insert_with(|| match variant.program {
                Program::Interleave => make_interleave_pipeline(device, &self.interleave, variant),
                Program::Clouds => make_interleave_pipeline(device, &self.clouds, variant),
                _ => make_pipeline(device, (&self.slices, &self.direct, &self.morph), variant),
            })
            .clone()
    }
}

/// One cloud: its volume, uniforms and slices. Clouds made with [`VolumePass::instance`] share
/// the first one's shaders and pipelines.
pub struct VolumePass {
    shared: Arc<VolumeShaders>,
    /// The variant this frame draws with (set in `prepare`); three-pass frames draw each slice
    /// with the three programs in turn.
    variant: Variant,
    /// This frame's pipelines, one per program, in the order each slice is drawn with them.
    frame_pipeline: Option<wgpu::RenderPipeline>,
    morph: Option<Morph>,
    /// Key volumes classified for α-mix and three-pass, kept while the transfer function stays.
    classified: ClassifiedVolumes,
    uniforms: wgpu::Buffer,
    vertices: wgpu::Buffer,
    vertex_count: u32,
    /// This frame's slice triangles (world), as uploaded.
    slice_vertices: Vec<Vec3>,
    /// The occupied cells for the last visibility floor (None: nothing to skip), kept while
    /// the volume and the floor stay.
    occupancy: Option<(f32, Option<Occupancy>)>,
    /// Which bricks can show a value, one texel each (1: may show), for the visibility floor it
    /// was made for (None: every brick), read where a walk samples the cloud.
    shown_bricks: Option<(Option<f32>, wgpu::TextureView)>,
    bind_group: Option<wgpu::BindGroup>,
    volume: Option<VolumeTexture>,
    /// Basis functions of the orbital shown in direct mode (then `volume` holds only its box).
    direct: Option<GtoBuffers>,
    /// This frame's cloud is composited by a walk over several clouds, not by its slices.
    walked: bool,
    /// This frame's uniforms, as written to `uniforms` (a walk copies them into its array).
    frame_uniforms: VolumeUniforms,
    /// The slab programs' group 2, for the depth view it was made with.
    depth_group: Option<(wgpu::TextureView, wgpu::BindGroup)>,
    /// The most planes a fragment of the texture's slices samples ([`SLAB_PLANES`]).
    slab_planes: usize,
    /// This frame's most slice planes per texel along the view ([`super::frame::Prepare`]).
    planes_per_texel: f32,
}

/// The override constants of `variant` (a walk's: whether any of its clouds needs each).
fn constants(variant: Variant) -> Vec<(&'static str, f64)> {
    let flag = |b: bool| f64::from(u8::from(b));
    let mut constants =
        vec![("GRADIENT", flag(variant.gradient)), ("SHAPED", flag(variant.shaped)), ("CLIP", flag(variant.clip))];
    if variant.program.walks() {
        constants.extend([("CLOUDS", f64::from(variant.clouds)), ("PREDRAWN", flag(variant.clouds == 1))]);
    }
    if variant.program.slabs() {
        constants.extend([("SLAB", f64::from(variant.slab)), ("FIELD", f64::from(variant.field))]);
    }
    let mix = match variant.program {
        Program::Exact => Some(0.0),
        Program::AlphaMix => Some(1.0),
        Program::ThreePass => Some(2.0),
        _ => None,
    };
    constants.extend(mix.map(|m| ("MIX", m)));
    if mix.is_some() {
        constants.push(("CLASSIFIED", flag(variant.classified)));
    }
    constants
}

/// The full-screen pipeline that walks fragments and clouds' samples together for `variant`'s
/// transfer functions.
fn make_interleave_pipeline(device: &wgpu::Device, shader: &SliceShader, variant: Variant) -> wgpu::RenderPipeline {
    let constants = constants(variant);
    let options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(&format!("cloud with translucent surfaces {variant:?}")),
        layout: Some(&shader.layout),
        vertex: wgpu::VertexState {
            module: &shader.module,
            entry_point: Some("vs_fullscreen"),
            compilation_options: options.clone(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &shader.module,
            entry_point: Some(variant.program.entry()),
            compilation_options: options,
            targets: &[Some(wgpu::ColorTargetState {
                format: super::COLOR_FORMAT,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The slice pipeline for one shader variant.
fn make_pipeline(
    device: &wgpu::Device,
    shaders: (&SliceShader, &SliceShader, &SliceShader),
    variant: Variant,
) -> wgpu::RenderPipeline {
    let shader = match variant.program {
        Program::Slices => &shaders.0,
        Program::Direct => &shaders.1,
        _ => &shaders.2,
    };
    let constants = constants(variant);
    let options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(&format!("volume slices {variant:?}")),
        layout: Some(&shader.layout),
        vertex: wgpu::VertexState {
            module: &shader.module,
            // The texture's slices pass their fragments what a slab needs (volume_slices.wgsl).
            entry_point: Some(if variant.program.slabs() { "vs_slab" } else { "vs_main" }),
            compilation_options: options.clone(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3],
            })],
        },
        primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
        // Test against the atoms' depth so they hide the cloud behind them; never write.
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(false),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &shader.module,
            entry_point: Some(variant.program.entry()),
            compilation_options: options,
            targets: &[Some(wgpu::ColorTargetState {
                format: SCENE_FORMAT,
                // Every program draws a slice as one premultiplied "over".
                blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A filterable 3D texture, read by the slice fragment shaders.
fn volume_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D3,
            multisampled: false,
        },
        count: None,
    }
}

impl VolumePass {
    /// `scene` and `lists`: the layouts of the resolve's scene colour and of the fragment
    /// lists, which the pass that takes translucent surfaces through the cloud reads.
    pub fn new(ctx: &GpuContext, scene: &wgpu::BindGroupLayout, lists: &wgpu::BindGroupLayout) -> Self {
        let device = &ctx.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("volume bind group layout"),
            entries: &[
                super::uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT),
                // The classification's vertex stage places layers by the volume's size.
                wgpu::BindGroupLayoutEntry { visibility: wgpu::ShaderStages::VERTEX_FRAGMENT, ..volume_entry(1) },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let gto_layout = gto_layout(device, wgpu::ShaderStages::FRAGMENT);
        let morph_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("key volume B layout"),
            entries: &[volume_entry(0), volume_entry(1), volume_entry(2)],
        });
        let depth_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("volume slices' scene depth"),
            entries: &[depth_entry(0)],
        });
        let slices = SliceShader::new(device, "volume_slices.wgsl", &[Some(&layout), None, Some(&depth_layout)]);
        let direct = SliceShader::new(device, "volume_direct.wgsl", &[Some(&layout), Some(&gto_layout)]);
        let morph =
            SliceShader::new(device, "volume_morph.wgsl", &[Some(&layout), Some(&morph_layout), Some(&depth_layout)]);
        let walk_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cloud walk bind group layout"),
            entries: &walk_entries(),
        });
        let interleave =
            SliceShader::new(device, "volume_interleave.wgsl", &[Some(&walk_layout), Some(scene), Some(lists)]);
        let clouds = SliceShader::new(device, "volume_interleave.wgsl", &[Some(&walk_layout), Some(scene)]);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("volume sampler"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let classifier = Classifier::new(device, &layout);
        let shared = VolumeShaders {
            slices,
            direct,
            morph,
            interleave,
            clouds,
            layout,
            depth_layout,
            walk_layout,
            morph_layout,
            gto_layout,
            sampler,
            classifier,
            pipelines: Mutex::new(HashMap::new()),
        };
        shared.pipeline(device, Variant::PLAIN);
        Self::with_shared(device, Arc::new(shared))
    }

    /// Another cloud drawn with this one's shaders and pipelines.
    pub fn instance(&self, ctx: &GpuContext) -> Self {
        Self::with_shared(&ctx.device, self.shared.clone())
    }

    fn with_shared(device: &wgpu::Device, shared: Arc<VolumeShaders>) -> Self {
        Self {
            shared,
            variant: Variant::PLAIN,
            frame_pipeline: None,
            morph: None,
            classified: ClassifiedVolumes::default(),
            uniforms: super::uniform_buffer(device, "volume uniforms", std::mem::size_of::<VolumeUniforms>()),
            vertices: Self::vertex_buffer(device, 1024),
            vertex_count: 0,
            slice_vertices: Vec::new(),
            occupancy: None,
            shown_bricks: None,
            bind_group: None,
            volume: None,
            direct: None,
            walked: false,
            frame_uniforms: VolumeUniforms::zeroed(),
            depth_group: None,
            slab_planes: SLAB_PLANES,
            planes_per_texel: f32::INFINITY,
        }
    }

    fn vertex_buffer(device: &wgpu::Device, count: usize) -> wgpu::Buffer {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("volume slice vertices"),
            size: (count * 12) as u64,
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    /// Replaces the volume shown (None shows none).
    pub fn set_volume(&mut self, ctx: &GpuContext, grid: Option<&VolumeGrid>) -> Result<(), GpuError> {
        let volume = grid.map(|g| VolumeTexture::upload(ctx, g)).transpose()?;
        self.set_texture(ctx, volume);
        Ok(())
    }

    /// Jang and Varetto's direct mode: the slices through `geometry`'s box evaluate `expansion` per
    /// fragment. `max_abs` scales the opacity like a grid's maximum and `max_grad` the analytic
    /// gradient (both measured: [`crate::model::gto::PreparedBasis::sampled_range`]); the grid
    /// spacing of `geometry` is the reference step of k1.
    pub fn set_direct(
        &mut self,
        ctx: &GpuContext,
        expansion: &CartesianExpansion,
        geometry: &GridSpec,
        (max_abs, max_grad): (f64, f64),
    ) {
        // The texture binding is unused by the direct shader but part of the shared layout.
        let placeholder = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("direct-mode placeholder volume"),
            size: wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: ctx.volume_format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let mut shape = VolumeTexture::from_texture(
            placeholder,
            geometry.dims,
            geometry.world_from_grid,
            ValueKind::Signed,
            max_abs,
        );
        shape.max_grad = max_grad.max(1e-30) as f32;
        self.set_texture(ctx, Some(shape));
        self.direct = Some(GtoBuffers::new(&ctx.device, &self.shared.gto_layout, &GtoArrays::new(expansion)));
    }

    /// Shows a volume already on the GPU (None shows none).
    pub fn set_texture(&mut self, ctx: &GpuContext, volume: Option<VolumeTexture>) {
        self.direct = None;
        self.occupancy = None;
        self.shown_bricks = None;
        self.morph = None;
        self.volume = volume;
        self.bind_group = self.volume.as_ref().map(|v| self.volume_group(&ctx.device, &v.view));
    }

    /// Group 0 of the slices: this cloud's uniforms and the volume `view`.
    fn volume_group(&self, device: &wgpu::Device, view: &wgpu::TextureView) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("volume bind group"),
            layout: &self.shared.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(view) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(&self.shared.sampler) },
            ],
        })
    }

    /// Naka et al.'s interpolated frame: key volumes `a` and `b` (one grid, one scale: `a`'s box
    /// and `max_abs` are used) mixed (1−k):k as `mode` says.
    pub fn set_morph(&mut self, ctx: &GpuContext, mut a: VolumeTexture, b: VolumeTexture, k: f32, mode: Interpolation) {
        // Dragging within one pair of key volumes changes only the weight: the bind groups stay.
        let same_pair = self.volume.as_ref().is_some_and(|v| v.texture == a.texture)
            && self.morph.as_ref().is_some_and(|m| m.partner.texture == b.texture);
        if let Some(morph) = self.morph.as_mut().filter(|_| same_pair) {
            morph.k = k.clamp(0.0, 1.0);
            morph.mode = mode;
            return;
        }
        // A mix can show a brick where either volume can.
        a.bricks = match (&a.bricks, &b.bricks) {
            (Some(x), Some(y)) => x.union(y).map(Arc::new),
            _ => None,
        };
        let bind_group = self.morph_group(&ctx.device, &b, [&a.view, &b.view]);
        self.set_texture(ctx, Some(a));
        self.morph = Some(Morph { partner: b, bind_group, bound: None, k: k.clamp(0.0, 1.0), mode });
    }

    /// Group 1 of the key volume programs: B and the two classified textures.
    fn morph_group(
        &self,
        device: &wgpu::Device,
        b: &VolumeTexture,
        classified: [&wgpu::TextureView; 2],
    ) -> wgpu::BindGroup {
        let view = wgpu::BindingResource::TextureView;
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("key volume B"),
            layout: &self.shared.morph_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: view(&b.view) },
                wgpu::BindGroupEntry { binding: 1, resource: view(classified[0]) },
                wgpu::BindGroupEntry { binding: 2, resource: view(classified[1]) },
            ],
        })
    }

    /// Whether this frame's α-mix or three-pass samples classified key volumes: both classified
    /// (now, or kept from an earlier frame) for the transfer function of `u`, which the uniform
    /// buffer holds, and bound. Not where the transfer function needs the gradient (its
    /// lighting follows the view) nor for the exact mix.
    fn bind_classified(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, u: &VolumeUniforms) -> bool {
        let (Some(a), Some(a_group), Some(morph)) = (&self.volume, &self.bind_group, &self.morph) else { return false };
        let wanted = matches!(morph.mode, Interpolation::ThreePass | Interpolation::AlphaMix) && !self.variant.gradient;
        let mut kept = std::mem::take(&mut self.classified);
        let views = wanted.then(|| {
            let b = &morph.partner;
            let classifier = &self.shared.classifier;
            [
                classifier.classified(device, queue, &mut kept, a, (|| a_group.clone(), u)),
                classifier.classified(device, queue, &mut kept, b, (|| self.volume_group(device, &b.view), u)),
            ]
        });
        self.classified = kept;
        let Some(morph) = &self.morph else { return false };
        if morph.bound != views {
            let partner = &morph.partner;
            let group = match &views {
                Some([x, y]) => self.morph_group(device, partner, [x, y]),
                None => self.morph_group(device, partner, [&a.view, &partner.view]),
            };
            let morph = self.morph.as_mut().expect("checked above");
            morph.bind_group = group;
            morph.bound = views.clone();
        }
        views.is_some()
    }

    /// Whether the orbital is evaluated per sample from its basis functions (direct mode).
    pub fn is_direct(&self) -> bool {
        self.direct.is_some()
    }

    pub fn volume(&self) -> Option<&VolumeTexture> {
        self.volume.as_ref()
    }

    /// Caps the planes one fragment samples (1: a slice per plane, as a reference to compare
    /// slabs against); at most [`SLAB_PLANES`].
    pub fn set_slab_planes(&mut self, planes: usize) {
        self.slab_planes = planes.clamp(1, SLAB_PLANES);
    }

    /// How many planes each fragment of this frame's slices samples.
    pub fn planes_per_fragment(&self) -> usize {
        self.variant.slab as usize
    }

    /// The triangles of this frame's slices (world), back to front.
    pub fn slice_vertices(&self) -> &[Vec3] {
        &self.slice_vertices
    }

    /// The cells of the volume's box that `settings` can show, where some can be skipped: not
    /// in direct mode (no grid), nor where the values' bricks are unknown or the transfer
    /// function shows values near zero.
    fn occupancy(&mut self, settings: &VolumeSettings) -> Option<&Occupancy> {
        let floor = self.skip_floor(settings)?;
        let vol = self.volume.as_ref()?;
        let bricks = vol.bricks.as_ref()?;
        let signed = vol.kind == ValueKind::Signed;
        if self.occupancy.as_ref().is_none_or(|(f, _)| *f != floor) {
            let cells = Occupancy::new(&vol.grid_box, bricks, &bricks.occupied(floor, signed)).filter(|o| !o.is_full());
            self.occupancy = Some((floor, cells));
        }
        self.occupancy.as_ref()?.1.as_ref()
    }

    /// The smallest value `settings` shows, where bricks below it can be skipped (see
    /// [`Self::occupancy`]).
    fn skip_floor(&self, settings: &VolumeSettings) -> Option<f32> {
        let vol = self.volume.as_ref().filter(|_| settings.skip_empty && self.direct.is_none())?;
        vol.bricks.as_ref()?;
        visible_floor(settings, vol.kind == ValueKind::Signed, vol.max_abs)
    }

    /// The bricks `settings` can show as a texture (texel x = the grid's k, as the volume's),
    /// made again when the visibility floor changes; one texel "shown" where nothing is skipped.
    fn update_shown_bricks(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, settings: &VolumeSettings) {
        let floor = self.skip_floor(settings);
        if self.shown_bricks.as_ref().is_some_and(|(f, _)| *f == floor) {
            return;
        }
        let (counts, flags) = match (floor, self.volume.as_ref().and_then(|v| Some((v.kind, v.bricks.as_ref()?)))) {
            (Some(floor), Some((kind, bricks))) => {
                let flags = bricks.occupied(floor, kind == ValueKind::Signed);
                (bricks.counts, flags.iter().map(|&o| o as u8).collect())
            }
            _ => ([1, 1, 1], vec![1u8]),
        };
        let texture = device.create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some("shown bricks"),
                size: wgpu::Extent3d {
                    width: counts[2] as u32,
                    height: counts[1] as u32,
                    depth_or_array_layers: counts[0] as u32,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format: wgpu::TextureFormat::R8Uint,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            &flags,
        );
        self.shown_bricks = Some((floor, texture.create_view(&Default::default())));
    }

    /// Cuts this frame's slices and uploads them with the uniforms; `clip`: the object's
    /// clipping plane ([`super::frame::Prepare::clip`]).
    #[allow(
        clippy::too_many_arguments,
        reason = "a frame's per-view inputs, each named where the renderer calls it once"
    )]
    pub fn set_view(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        view: &super::frame::ObjectView,
        settings: &VolumeSettings,
        clip: Option<Vec4>,
        size: [u32; 2],
    ) {
        let (eye, view_dir) = (view.eye, view.view_dir);
        self.vertex_count = 0;
        self.slice_vertices.clear();
        if !settings.visible {
            return;
        }
        let mode = settings.mode;
        let cells = self.occupancy(settings).map(|o| (*o).clone());
        self.update_shown_bricks(device, queue, settings);
        let Some(vol) = &self.volume else { return };
        let count = match self.direct {
            // Direct mode evaluates the orbital itself: it has no texels to count.
            Some(_) => settings.slices,
            None => settings.slices.min(texel_planes(vol, mode, eye, view_dir, self.planes_per_texel)),
        };
        let slices = match &cells {
            Some(o) => o.slices(&vol.grid_box, mode, count, eye, view_dir),
            None => vol.grid_box.slices(mode, count, eye, view_dir),
        };
        let planes = slices.starts.len() as f32;
        let program = match (&self.direct, &self.morph) {
            (Some(_), _) => Program::Direct,
            (None, Some(m)) => match m.mode {
                Interpolation::Exact => Program::Exact,
                Interpolation::ThreePass => Program::ThreePass,
                Interpolation::AlphaMix => Program::AlphaMix,
            },
            (None, None) => Program::Slices,
        };
        let slabs = (program.slabs())
            .then(|| slices.slabs(self.slab_planes, eye))
            .flatten()
            .filter(|v| before_near_plane(v, view.clip_from_object));
        let slab = if slabs.is_some() { self.slab_planes as u8 } else { 1 };
        let Slices { vertices, normal, spacing, nearest, .. } = slices;
        let vertices = slabs.unwrap_or(vertices);
        if vertices.is_empty() {
            return;
        }
        if (self.vertices.size() as usize) < vertices.len() * 12 {
            self.vertices = Self::vertex_buffer(device, vertices.len().next_power_of_two());
        }
        queue.write_buffer(&self.vertices, 0, bytemuck::cast_slice(&vertices));
        self.vertex_count = vertices.len() as u32;
        self.slice_vertices = vertices;
        let signed = vol.kind == ValueKind::Signed;
        let (log_lo, inv_log_span) = settings.density_scale.log_uniforms();
        let t = &settings.transfer;
        let signed_field = match (signed, settings.density_scale) {
            (true, _) => 1,
            (false, DensityScale::Linear) => 0,
            (false, DensityScale::Log { .. }) => 2,
        };
        self.variant = Variant {
            program,
            gradient: t.needs_gradient(),
            shaped: t.kind == TransferKind::Shaped,
            clip: clip.is_some(),
            clouds: 0,
            slab,
            field: if program.slabs() { signed_field as u8 } else { 0 },
            classified: false,
        };
        let lobe = |l: &crate::scene::transfer::Lobe| [l.center, l.width, l.opacity, 0.0];
        let v = self.variant;
        let bits = [(t.shading, TF_SHADING), (v.gradient, TF_GRADIENT), (v.shaped, TF_SHAPED), (v.clip, TF_CLIP)]
            .iter()
            .filter(|(on, _)| *on)
            .fold(0, |bits, (_, bit)| bits | bit);
        let rgb = |c: [f32; 3]| Vec4::new(c[0], c[1], c[2], 1.0).to_array();
        let u = VolumeUniforms {
            clip_from_world: view.clip_from_object.to_cols_array_2d(),
            tex_from_world: vol.tex_from_world.to_cols_array_2d(),
            eye: eye.extend(1.0).to_array(),
            plane: normal.extend(spacing).to_array(),
            positive_color: rgb(settings.positive_color),
            negative_color: rgb(settings.negative_color),
            k1: settings.k1,
            k2: settings.k2,
            inv_max: 1.0 / vol.max_abs,
            ref_step: vol.step,
            signed_field,
            shape_positive: t.positive.shape.index(),
            shape_negative: t.negative.shape.index(),
            tf_bits: bits,
            visible_min: visibility_threshold(settings.k1, settings.k2, signed),
            morph_k: self.morph.as_ref().map_or(0.0, |m| m.k),
            log_lo,
            inv_log_span,
            tf_positive: lobe(&t.positive),
            tf_negative: lobe(&t.negative),
            gradient_power: t.gradient_power,
            boundary: t.boundary.clamp(0.0, 1.0),
            inv_max_grad: 1.0 / vol.max_grad,
            brick_cells: BRICK_CELLS as f32,
            clip: clip.unwrap_or(crate::scene::transfer::NO_CUT).to_array(),
            light: view.light.extend(0.0).to_array(),
            world_from_clip: view.clip_from_object.inverse().to_cols_array_2d(),
            box_from_world: walked_box(&vol.grid_box, cells.as_ref()).inverse().to_cols_array_2d(),
            slab: [nearest, planes, size[0] as f32, size[1] as f32],
        };
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        self.frame_uniforms = u;
        self.variant.classified = self.bind_classified(device, queue, &u);
        self.frame_pipeline = Some(self.shared.pipeline(device, self.variant));
    }

    /// Whether a walk can take this frame's cloud: one drawn from a 3D texture in one pass
    /// (direct-mode and interpolated clouds stay behind the surfaces and the walked clouds).
    pub fn walkable(&self) -> bool {
        self.bind_group.is_some() && self.variant.program == Program::Slices && self.vertex_count > 0
    }

    /// The pixels this frame's cloud can cover, [x0, y0, x1, y1) (its walked box's corners on
    /// screen); the whole frame where a corner lies behind the eye.
    pub fn screen_rect(&self) -> [u32; 4] {
        let u = &self.frame_uniforms;
        let [w, h] = [u.slab[2], u.slab[3]];
        let whole = [0, 0, w as u32, h as u32];
        let clip_from_world = Mat4::from_cols_array_2d(&u.clip_from_world);
        let world_from_box = Mat4::from_cols_array_2d(&u.box_from_world).inverse();
        let mut lo = glam::Vec2::splat(f32::INFINITY);
        let mut hi = glam::Vec2::splat(f32::NEG_INFINITY);
        for n in 0..8 {
            let corner = Vec3::new((n & 1) as f32, ((n >> 1) & 1) as f32, (n >> 2) as f32);
            let c = clip_from_world * world_from_box.transform_point3(corner).extend(1.0);
            if c.w <= 1e-6 {
                return whole;
            }
            // Pixels from normalised device coordinates (y down).
            let p = glam::Vec2::new((c.x / c.w + 1.0) * 0.5 * w, (1.0 - c.y / c.w) * 0.5 * h);
            (lo, hi) = (lo.min(p), hi.max(p));
        }
        // A pixel's centre inside the projected box lies in the rectangle with one pixel spare.
        let x0 = (lo.x.floor() - 1.0).clamp(0.0, w) as u32;
        let y0 = (lo.y.floor() - 1.0).clamp(0.0, h) as u32;
        let x1 = (hi.x.ceil() + 1.0).clamp(0.0, w) as u32;
        let y1 = (hi.y.ceil() + 1.0).clamp(0.0, h) as u32;
        [x0, y0, x1, y1]
    }

    /// Leaves this frame's cloud to a walk over several clouds: its slices are not drawn.
    pub fn set_walked(&mut self, walked: bool) {
        self.walked = walked;
    }

    /// The full-screen pipeline that composites `clouds` (walkable, at most [`MAX_WALKED`]) in
    /// one depth order, with the translucent surfaces' fragments when `lists`, and its bind
    /// group; `depth` is the opaque scene's. One cloud is walked only where fragments are, over
    /// what its slices drew.
    pub fn walk(
        ctx: &GpuContext,
        clouds: &[&VolumePass],
        depth: &wgpu::TextureView,
        lists: bool,
    ) -> Option<(wgpu::RenderPipeline, wgpu::BindGroup)> {
        let first = clouds.first()?;
        let clouds = &clouds[..clouds.len().min(MAX_WALKED)];
        let shared = &first.shared;
        let views: Vec<&wgpu::TextureView> =
            clouds.iter().map(|c| c.volume.as_ref().map(|v| &v.view)).collect::<Option<_>>()?;
        let uniforms: Vec<VolumeUniforms> =
            (0..MAX_WALKED).map(|k| clouds.get(k).map_or(VolumeUniforms::zeroed(), |c| c.frame_uniforms)).collect();
        // A buffer per walk: a frame may walk several groups of clouds.
        let walk_uniforms = ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("cloud walk uniforms"),
            contents: bytemuck::cast_slice(&uniforms),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bricks: Vec<&wgpu::TextureView> =
            clouds.iter().map(|c| c.shown_bricks.as_ref().map(|(_, v)| v)).collect::<Option<_>>()?;
        let view = |k: usize| wgpu::BindingResource::TextureView(views.get(k).copied().unwrap_or(views[0]));
        let bricks_view = |k: usize| wgpu::BindingResource::TextureView(bricks.get(k).copied().unwrap_or(bricks[0]));
        let mut entries = vec![
            wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(&shared.sampler) },
            wgpu::BindGroupEntry { binding: WALK_UNIFORMS, resource: walk_uniforms.as_entire_binding() },
            wgpu::BindGroupEntry { binding: WALK_DEPTH, resource: wgpu::BindingResource::TextureView(depth) },
        ];
        entries.extend(
            WALK_TEXTURES.iter().enumerate().map(|(k, &binding)| wgpu::BindGroupEntry { binding, resource: view(k) }),
        );
        entries.extend(
            (WALK_BRICKS.iter().enumerate())
                .map(|(k, &binding)| wgpu::BindGroupEntry { binding, resource: bricks_view(k) }),
        );
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("cloud walk bind group"),
            layout: &shared.walk_layout,
            entries: &entries,
        });
        let variant = Variant {
            program: if lists { Program::Interleave } else { Program::Clouds },
            gradient: clouds.iter().any(|c| c.variant.gradient),
            shaped: clouds.iter().any(|c| c.variant.shaped),
            clip: false,
            clouds: clouds.len() as u8,
            slab: 1,
            field: 0,
            classified: false,
        };
        Some((shared.pipeline(&ctx.device, variant), bind_group))
    }
}

/// The clouds grouped so that no group's rectangle ([x0, y0, x1, y1), the bounds of its
/// clouds' `rects`) overlaps another's: clouds that overlap, directly or through others, and
/// groups whose bounds would overlap are merged. Each group (indices in order, with its bounds)
/// can then be walked on its own, in its own rectangle.
pub fn overlapping_groups(rects: &[[u32; 4]]) -> Vec<(Vec<usize>, [u32; 4])> {
    let overlap = |a: &[u32; 4], b: &[u32; 4]| a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
    let mut groups: Vec<(Vec<usize>, [u32; 4])> = (0..rects.len()).map(|i| (vec![i], rects[i])).collect();
    // Merge any two whose bounds overlap until none do (bounds only grow, so this ends).
    while let Some((a, b)) = (0..groups.len())
        .flat_map(|a| (a + 1..groups.len()).map(move |b| (a, b)))
        .find(|&(a, b)| overlap(&groups[a].1, &groups[b].1))
    {
        let (members, r) = groups.remove(b);
        let g = &mut groups[a];
        g.0.extend(members);
        g.0.sort_unstable();
        g.1 = [g.1[0].min(r[0]), g.1[1].min(r[1]), g.1[2].max(r[2]), g.1[3].max(r[3])];
    }
    groups
}

/// The bindings of the walked clouds' textures (volume_interleave.wgsl): cloud 0's is the
/// slices' own; 2 is the sampler.
const WALK_TEXTURES: [u32; MAX_WALKED] = [1, 4, 5, 6];
/// The walked clouds' uniforms, one array.
const WALK_UNIFORMS: u32 = 3;
/// The opaque scene's depth in a walk's group 0.
const WALK_DEPTH: u32 = 7;
/// Each walked cloud's shown bricks ([`VolumePass::update_shown_bricks`]).
const WALK_BRICKS: [u32; MAX_WALKED] = [8, 9, 10, 11];

/// Group 0 of a walk over clouds.
fn walk_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    let mut entries = vec![wgpu::BindGroupLayoutEntry {
        binding: 2,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }];
    entries.push(super::uniform_entry(WALK_UNIFORMS, wgpu::ShaderStages::FRAGMENT));
    entries.extend(WALK_TEXTURES.map(volume_entry));
    entries.push(depth_entry(WALK_DEPTH));
    entries.extend(WALK_BRICKS.map(|binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Uint,
            view_dimension: wgpu::TextureViewDimension::D3,
            multisampled: false,
        },
        count: None,
    }));
    entries
}

/// The opaque scene's depth, read by a fragment shader.
fn depth_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Depth,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// Whether all of `vertices` lie beyond the near plane of `clip_from_world`: a slab's polygon
/// cut there would lose its deeper planes' samples where they are not cut.
fn before_near_plane(vertices: &[Vec3], clip_from_world: Mat4) -> bool {
    vertices.iter().all(|&v| {
        let c = clip_from_world * v.extend(1.0);
        c.w > 0.0 && c.z >= 0.0
    })
}

/// How many planes `mode` needs across `vol`'s box for `per_texel` of them per texel of its
/// grid along the planes' normal, on the axis of the grid the normal crosses fastest (u32::MAX
/// when unbounded). Samples closer than that along a ray meet the same trilinear cells.
fn texel_planes(vol: &VolumeTexture, mode: crate::scene::SliceMode, eye: Vec3, view_dir: Vec3, per_texel: f32) -> u32 {
    if !per_texel.is_finite() {
        return u32::MAX;
    }
    // One plane spans the box: its spacing is the box's depth along the normal.
    let whole = vol.grid_box.slices(mode, 1, eye, view_dir);
    // Texels per unit of length along the normal, per texture axis (x is the grid's k).
    let [ni, nj, nk] = vol.dims.map(|d| d as f32);
    let along = vol.tex_from_world.transform_vector3(whole.normal).abs() * Vec3::new(nk, nj, ni);
    let planes = (per_texel * whole.spacing * along.max_element()).ceil();
    if planes.is_finite() { planes.max(1.0) as u32 } else { u32::MAX }
}

/// The box a walk samples the cloud in, as the map from the unit cube: the slices' box, cut to
/// the occupied cells where some are empty.
fn walked_box(grid_box: &GridBox, cells: Option<&Occupancy>) -> Mat4 {
    let e = grid_box.edges;
    let (lo, hi) = cells.and_then(Occupancy::occupied_bounds).unwrap_or(([0.0; 3], [1.0; 3]));
    let origin = grid_box.origin + lo[0] * e[0] + lo[1] * e[1] + lo[2] * e[2];
    Mat4::from_cols(
        ((hi[0] - lo[0]) * e[0]).extend(0.0),
        ((hi[1] - lo[1]) * e[1]).extend(0.0),
        ((hi[2] - lo[2]) * e[2]).extend(0.0),
        origin.extend(1.0),
    )
}

/// The bits of `VolumeUniforms::tf_bits` (volume_common.wgsl's TF_*).
const TF_SHADING: u32 = 1;
const TF_GRADIENT: u32 = 2;
pub(crate) const TF_SHAPED: u32 = 4;
const TF_CLIP: u32 = 8;

impl super::frame::Representation for VolumePass {
    fn new(ctx: &GpuContext, shared: &super::frame::Shared<'_>) -> Self {
        Self::new(ctx, shared.scene, shared.composite)
    }

    fn instance(&self, ctx: &GpuContext) -> Self {
        self.instance(ctx)
    }

    fn clear(&mut self, ctx: &GpuContext) {
        self.set_texture(ctx, None);
    }
}

impl super::frame::Draw for VolumePass {
    fn prepare(&mut self, f: &super::frame::Prepare<'_>) {
        self.planes_per_texel = f.planes_per_texel;
        self.set_view(&f.ctx.device, &f.ctx.queue, f.view, f.cloud, f.clip, f.size);
        if self.variant.program.slabs() && self.depth_group.as_ref().is_none_or(|(v, _)| v != f.depth) {
            let group = f.ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("volume slices' scene depth"),
                layout: &self.shared.depth_layout,
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(f.depth) }],
            });
            self.depth_group = Some((f.depth.clone(), group));
        }
    }

    fn phases(&self) -> &'static [super::frame::Phase] {
        &[super::frame::Phase::Translucent]
    }

    fn draw(&self, _phase: super::frame::Phase, pass: &mut wgpu::RenderPass<'_>) {
        let Some(bind_group) = &self.bind_group else {
            return;
        };
        if self.vertex_count == 0 || self.walked {
            return;
        }
        let Some(pipeline) = &self.frame_pipeline else { return };
        pass.set_bind_group(0, bind_group, &[]);
        if let Some(gto) = &self.direct {
            pass.set_bind_group(1, &gto.bind_group, &[]);
        }
        if let Some(morph) = &self.morph {
            pass.set_bind_group(1, &morph.bind_group, &[]);
        }
        if self.variant.program.slabs() {
            let Some((_, depth)) = &self.depth_group else { return };
            pass.set_bind_group(2, depth, &[]);
        }
        pass.set_vertex_buffer(0, self.vertices.slice(..self.vertex_count as u64 * 12));
        pass.set_pipeline(pipeline);
        pass.draw(0..self.vertex_count, 0..1);
    }
}

/// The smallest step (1: every point) at which a grid of `dims` fits this device as a volume
/// texture of `texel` bytes per point: every side within `max_texture_dimension_3d`, the
/// whole within half of [`residency_budget`] (one volume of many that may be resident).
pub fn fitting_step(dims: [usize; 3], texel: u64, limits: &wgpu::Limits) -> usize {
    let max_side = limits.max_texture_dimension_3d.max(1) as usize;
    let budget = residency_budget(limits) / 2;
    (1..=max_side.max(dims.into_iter().max().unwrap_or(1)))
        .find(|&s| {
            let d = dims.map(|n| n.div_ceil(s));
            d.iter().all(|&n| n <= max_side) && d.iter().product::<usize>() as u64 * texel <= budget
        })
        .unwrap_or(usize::MAX)
}

/// Bytes one texel of a volume format takes.
pub fn texel_bytes(format: wgpu::TextureFormat) -> u64 {
    format.block_copy_size(None).unwrap_or(4) as u64
}

/// How much memory resident volumes (a scan's key volumes) may take. wgpu reports no heap
/// sizes; the largest buffer the device allows is the nearest limit (lavapipe: its 2 GiB heap,
/// the paper's cards: their video memory), and three quarters of it leaves room for the frame.
pub fn residency_budget(limits: &wgpu::Limits) -> u64 {
    limits.max_buffer_size.min(16 << 30) / 4 * 3
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clouds_overlapping_on_screen_through_others_form_one_group() {
        // 0 and 2 overlap through 1; 3 stands apart; 4 touches 3's edge only (half-open).
        let rects = [[0, 0, 10, 10], [8, 8, 20, 12], [18, 0, 30, 9], [40, 40, 50, 50], [50, 40, 60, 50]];
        let groups = overlapping_groups(&rects);
        let members: Vec<Vec<usize>> = groups.iter().map(|(g, _)| g.clone()).collect();
        assert_eq!(members, vec![vec![0, 1, 2], vec![3], vec![4]]);
        assert_eq!(groups[0].1, [0, 0, 30, 12]);
        assert!(overlapping_groups(&[]).is_empty());
        // An L of two clouds around a third that touches neither: the third lies inside the L's
        // rectangle, where the L's walk would overwrite it, so all three are one group.
        let l = [[0, 0, 10, 30], [0, 20, 30, 30], [15, 0, 25, 15]];
        assert_eq!(overlapping_groups(&l), vec![(vec![0, 1, 2], [0, 0, 30, 30])]);
    }
}
