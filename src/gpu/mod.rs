//! The GPU layer: adapter and device selection, offscreen targets, and the render passes.
//!
//! Passes draw into targets they do not own, in the phases of a frame description
//! ([`frame`]); the window, the CLI and the tests all call [`Renderer::render`]. Nothing here
//! reads files or knows about the UI.

pub mod arrows;
pub mod atoms;
pub mod basis_buffers;
pub mod classify;
pub mod context;
pub mod density_hessian;
pub mod frame;
pub mod gto;
pub mod isosurface;
pub mod layer;
pub mod occlusion;
pub mod oit;
pub mod plane_frame;
pub mod readback;
pub mod renderer;
pub mod resolve;
pub mod target;
pub mod volume;

pub use context::{AdapterPreference, GpuContext, GpuError};
pub use renderer::{FrameInput, Renderer, Tile};
pub use target::OffscreenTarget;

/// The format of the final image (sRGB storage).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// The scene is drawn into this first: blending hundreds of faint slices in 8 bits would round
/// each slice's contribution away.
pub const SCENE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Depth buffer shared by the opaque impostors and the translucent slices.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Every WGSL shader, by file name, for validation and pipeline creation.
pub const SHADERS: &[(&str, &str)] = &[
    ("volume_common.wgsl", include_str!("../../shaders/volume_common.wgsl")),
    ("volume_gradient.wgsl", include_str!("../../shaders/volume_gradient.wgsl")),
    ("volume_field.wgsl", include_str!("../../shaders/volume_field.wgsl")),
    ("volume_interleave.wgsl", include_str!("../../shaders/volume_interleave.wgsl")),
    ("volume_slab.wgsl", include_str!("../../shaders/volume_slab.wgsl")),
    ("volume_slices.wgsl", include_str!("../../shaders/volume_slices.wgsl")),
    ("volume_direct.wgsl", include_str!("../../shaders/volume_direct.wgsl")),
    ("volume_morph.wgsl", include_str!("../../shaders/volume_morph.wgsl")),
    ("volume_classify.wgsl", include_str!("../../shaders/volume_classify.wgsl")),
    ("atoms_common.wgsl", include_str!("../../shaders/atoms_common.wgsl")),
    ("atoms.wgsl", include_str!("../../shaders/atoms.wgsl")),
    ("atoms_cull.wgsl", include_str!("../../shaders/atoms_cull.wgsl")),
    ("atoms_splat_pair.wgsl", include_str!("../../shaders/atoms_splat_pair.wgsl")),
    ("atoms_splat_packed.wgsl", include_str!("../../shaders/atoms_splat_packed.wgsl")),
    ("fullscreen.wgsl", include_str!("../../shaders/fullscreen.wgsl")),
    ("oit_common.wgsl", include_str!("../../shaders/oit_common.wgsl")),
    ("oit_sort.wgsl", include_str!("../../shaders/oit_sort.wgsl")),
    ("resolve.wgsl", include_str!("../../shaders/resolve.wgsl")),
    ("isosurface.wgsl", include_str!("../../shaders/isosurface.wgsl")),
    ("depth_pyramid_common.wgsl", include_str!("../../shaders/depth_pyramid_common.wgsl")),
    ("depth_pyramid.wgsl", include_str!("../../shaders/depth_pyramid.wgsl")),
    ("surface_cull.wgsl", include_str!("../../shaders/surface_cull.wgsl")),
    ("gto_common.wgsl", include_str!("../../shaders/gto_common.wgsl")),
    ("gto_fill.wgsl", include_str!("../../shaders/gto_fill.wgsl")),
    ("density_hessian.wgsl", include_str!("../../shaders/density_hessian.wgsl")),
    ("arrows.wgsl", include_str!("../../shaders/arrows.wgsl")),
    ("plane_frame.wgsl", include_str!("../../shaders/plane_frame.wgsl")),
];

/// Shaders that are only complete with others prepended (WGSL has no includes): the module
/// for `name` is the concatenation of these files, in order.
pub const SHADER_MODULES: &[(&str, &[&str])] = &[
    (
        "volume_slices.wgsl",
        &["volume_common.wgsl", "volume_gradient.wgsl", "volume_field.wgsl", "volume_slab.wgsl", "volume_slices.wgsl"],
    ),
    (
        "volume_interleave.wgsl",
        &[
            "volume_common.wgsl",
            "volume_gradient.wgsl",
            "volume_field.wgsl",
            "fullscreen.wgsl",
            "oit_common.wgsl",
            "oit_sort.wgsl",
            "volume_interleave.wgsl",
        ],
    ),
    ("volume_direct.wgsl", &["volume_common.wgsl", "gto_common.wgsl", "volume_direct.wgsl"]),
    ("volume_morph.wgsl", &["volume_common.wgsl", "volume_gradient.wgsl", "volume_slab.wgsl", "volume_morph.wgsl"]),
    ("volume_classify.wgsl", &["volume_common.wgsl", "volume_classify.wgsl"]),
    ("gto_fill.wgsl", &["gto_common.wgsl", "gto_fill.wgsl"]),
    ("density_hessian.wgsl", &["gto_common.wgsl", "density_hessian.wgsl"]),
    ("atoms.wgsl", &["atoms_common.wgsl", "atoms.wgsl"]),
    ("atoms_splat_pair.wgsl", &["atoms_common.wgsl", "atoms_cull.wgsl", "atoms_splat_pair.wgsl"]),
    ("atoms_splat_packed.wgsl", &["atoms_common.wgsl", "atoms_cull.wgsl", "atoms_splat_packed.wgsl"]),
    ("isosurface.wgsl", &["oit_common.wgsl", "isosurface.wgsl"]),
    ("depth_pyramid.wgsl", &["depth_pyramid_common.wgsl", "depth_pyramid.wgsl"]),
    ("surface_cull.wgsl", &["depth_pyramid_common.wgsl", "surface_cull.wgsl"]),
    ("resolve.wgsl", &["fullscreen.wgsl", "oit_common.wgsl", "oit_sort.wgsl", "resolve.wgsl"]),
];

/// The full source of a shader module: its prerequisites, then itself.
pub fn module_source(name: &str) -> String {
    match SHADER_MODULES.iter().find(|(n, _)| *n == name) {
        Some((_, parts)) => parts.iter().map(|p| shader_source(p)).collect::<Vec<_>>().join("\n"),
        None => shader_source(name).to_string(),
    }
}

/// The shader module `name`, its prerequisites prepended ([`SHADER_MODULES`]).
pub(crate) fn shader_module(device: &wgpu::Device, name: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(name),
        source: wgpu::ShaderSource::Wgsl(module_source(name).into()),
    })
}

/// A render pipeline whose vertex stage `vs` makes its own triangles (no vertex buffers) and
/// whose fragment stage `fs` writes one `format` target as is: no depth, no blending.
pub(crate) fn bufferless_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    (vs, fs): (&str, &str),
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(vs),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fs),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A texture of one mip level and sample, used as `usage` says.
pub(crate) fn texture_descriptor(
    label: &str,
    size: wgpu::Extent3d,
    dimension: wgpu::TextureDimension,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::TextureDescriptor<'_> {
    wgpu::TextureDescriptor {
        label: Some(label),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension,
        format,
        usage,
        view_formats: &[],
    }
}

/// A bind-group layout of one uniform buffer (binding 0, vertex and fragment stages) and a
/// pipeline layout of just that group: what the opaque passes use.
pub(crate) fn uniform_layouts(device: &wgpu::Device, label: &str) -> (wgpu::BindGroupLayout, wgpu::PipelineLayout) {
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(&format!("{label} bind group layout")),
        entries: &[uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT)],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(&format!("{label} pipeline layout")),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    (layout, pipeline_layout)
}

/// A bind-group layout entry for a buffer (uniform, or read-only storage).
pub(crate) fn buffer_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    }
}

/// A uniform-buffer layout entry.
pub(crate) fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, visibility, wgpu::BufferBindingType::Uniform)
}

/// A uniform buffer of `size` bytes, written with `queue.write_buffer`.
pub(crate) fn uniform_buffer(device: &wgpu::Device, label: &str, size: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

pub(crate) fn shader_source(name: &str) -> &'static str {
    SHADERS.iter().find(|(n, _)| *n == name).map_or_else(|| panic!("shader {name} is not in gpu::SHADERS"), |(_, s)| *s)
}
