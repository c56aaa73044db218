//! Orbitals evaluated from their basis functions on the GPU: a compute pass that fills a 3D
//! texture for the slice renderer (exact orbitals, switched without resampling files).

use std::sync::atomic::{AtomicUsize, Ordering};

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::basis_buffers::{GtoArrays, GtoBuffers, gto_layout};
use super::volume::VolumeTexture;
use super::{GpuContext, GpuError};
use crate::model::cartesian::CartesianExpansion;
use crate::model::grid::{GridSpec, ValueKind};

/// Mirror of `FillParams` in gto_fill.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct FillParams {
    pub world_from_grid: [[f32; 4]; 4],
    /// nx, ny, nz, and the [`Component`] filled.
    pub dims: [u32; 4],
}
const _: () = assert!(std::mem::size_of::<FillParams>() == 80);

/// What a fill writes per grid point: ψ, or one component of its analytic gradient (what direct
/// mode shades with; filled to check it against the CPU).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Component {
    Value = 0,
    GradientX = 1,
    GradientY = 2,
    GradientZ = 3,
}

pub struct GtoFillPass {
    pipeline: wgpu::ComputePipeline,
    fill_layout: wgpu::BindGroupLayout,
    gto_layout: wgpu::BindGroupLayout,
    /// Grids filled so far (what shows that direct mode fills none).
    fills: AtomicUsize,
}

impl GtoFillPass {
    pub fn new(ctx: &GpuContext) -> Self {
        let device = &ctx.device;
        let module = super::shader_module(device, "gto_fill.wgsl");
        let fill_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gto fill layout"),
            entries: &[
                super::uniform_entry(0, wgpu::ShaderStages::COMPUTE),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: wgpu::TextureFormat::R32Float,
                        view_dimension: wgpu::TextureViewDimension::D3,
                    },
                    count: None,
                },
            ],
        });
        let gto_layout = gto_layout(device, wgpu::ShaderStages::COMPUTE);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gto fill pipeline layout"),
            bind_group_layouts: &[Some(&fill_layout), Some(&gto_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("gto fill"),
            layout: Some(&layout),
            module: &module,
            entry_point: Some("cs_fill"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self { pipeline, fill_layout, gto_layout, fills: AtomicUsize::new(0) }
    }

    /// How many grids this pass has filled.
    pub fn fills(&self) -> usize {
        self.fills.load(Ordering::Relaxed)
    }

    /// Evaluates `expansion` on `grid` into a new R32Float 3D texture (texel x = grid k).
    pub fn fill(
        &self,
        ctx: &GpuContext,
        expansion: &CartesianExpansion,
        grid: &GridSpec,
    ) -> Result<wgpu::Texture, GpuError> {
        self.fill_component(ctx, expansion, grid, Component::Value)
    }

    /// As [`Self::fill`], writing `component` of the orbital.
    pub fn fill_component(
        &self,
        ctx: &GpuContext,
        expansion: &CartesianExpansion,
        grid: &GridSpec,
        component: Component,
    ) -> Result<wgpu::Texture, GpuError> {
        let device = &ctx.device;
        let [nx, ny, nz] = grid.dims;
        let max = device.limits().max_texture_dimension_3d;
        if grid.dims.iter().any(|&d| d == 0 || d > max as usize) {
            return Err(GpuError::VolumeTooLarge { dims: grid.dims, max });
        }
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("gto volume"),
            size: wgpu::Extent3d { width: nz as u32, height: ny as u32, depth_or_array_layers: nx as u32 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let params = FillParams {
            world_from_grid: grid.world_from_grid.as_mat4().to_cols_array_2d(),
            dims: [nx as u32, ny as u32, nz as u32, component as u32],
        };
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("gto fill params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view = texture.create_view(&Default::default());
        let fill_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gto fill bind group"),
            layout: &self.fill_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&view) },
            ],
        });
        let gto = GtoBuffers::new(device, &self.gto_layout, &GtoArrays::new(expansion));
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("gto fill") });
        {
            let mut pass = encoder
                .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("gto fill"), timestamp_writes: None });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &fill_group, &[]);
            pass.set_bind_group(1, &gto.bind_group, &[]);
            pass.dispatch_workgroups((nz as u32).div_ceil(4), (ny as u32).div_ceil(4), (nx as u32).div_ceil(4));
        }
        ctx.queue.submit([encoder.finish()]);
        self.fills.fetch_add(1, Ordering::Relaxed);
        Ok(texture)
    }
}

/// A filled texture made ready for the slice renderer. `max_abs` scales the opacity (the CPU
/// knows it from the evaluator or a coarse estimate).
pub fn volume_from_texture(texture: wgpu::Texture, grid: &GridSpec, max_abs: f64) -> VolumeTexture {
    VolumeTexture::from_texture(texture, grid.dims, grid.world_from_grid, ValueKind::Signed, max_abs)
}

/// Reads an R32Float 3D texture back into cube order (x slowest, z fastest) — for tests, export
/// and checks against the CPU.
pub fn read_volume(ctx: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<f32>, GpuError> {
    let bytes = super::readback::read_texture(&ctx.device, &ctx.queue, texture, 4)?;
    Ok(bytemuck::pod_collect_to_vec(&bytes))
}
