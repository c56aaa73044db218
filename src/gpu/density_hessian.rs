//! The total density's value, gradient and Hessian on a grid, evaluated on the GPU from the
//! occupied orbitals' cartesian Gaussians (analytic second derivatives, any l): what NCI's
//! quantities (s, sign(λ₂)ρ, their cut fields, ∇²ρ) are made of. The pass writes the ten
//! derivatives in single precision; the quantities are finished from them on the CPU in double
//! precision by the same code as the CPU reference's (`model::nci`), so λ₂'s eigenvalues and
//! NCIPLOT's cuts are the reference's, and s = |∇ρ|/ρ^{4/3} is not taken in f32 where ρ is tiny.

use bytemuck::{Pod, Zeroable};

use super::basis_buffers::{GpuShell, GtoArrays, GtoBuffers, gto_layout};
use super::{GpuContext, GpuError};
use crate::model::cartesian::CartesianDensity;
use crate::model::grid::GridSpec;
use crate::model::nci::{self, WavefunctionDensity};
use crate::model::orbitals::{Quantity, Wavefunction};

/// Mirror of `HessianParams` in density_hessian.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct HessianParams {
    pub world_from_grid: [[f32; 4]; 4],
    /// nx, ny, nz, groups of four orbitals (the buffers hold a multiple of [`BATCH`]).
    pub dims: [u32; 4],
    /// The chunk's first point, its points, cartesian components per group, the batch's first
    /// group.
    pub chunk: [u32; 4],
}
const _: () = assert!(std::mem::size_of::<HessianParams>() == 96);

/// f32 values the pass writes per point: ρ, ∇ρ, the Hessian's xx, xy, xz, yy, yz, zz.
pub const VALUES_PER_POINT: usize = 10;

/// Groups of four orbitals one dispatch evaluates (`BATCH` in density_hessian.wgsl): each
/// shell's exponentials and monomials are taken once per batch of 16 orbitals, and the
/// batches' sums add up in the output.
pub const BATCH: usize = 4;

/// Invocations per workgroup (`@workgroup_size` of `cs_density_hessian`).
const WORKGROUP: u32 = 64;

/// Points per dispatch at most: each dispatch stays short (an operating system resets a GPU
/// whose work runs for seconds), and its output is 10 MiB.
pub const MAX_CHUNK_POINTS: usize = 1 << 18;

/// The density's cartesian Gaussians as the pass reads them: the shells and primitives of
/// [`GtoArrays`] and, per group of four orbitals, one weight per orbital and cartesian
/// component (group g's component c at 4·(g·cartesians + c) + orbital), with the groups'
/// occupations; groups are padded to a multiple of [`BATCH`] with orbitals of no weight and no
/// occupation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DensityArrays {
    pub gto: GtoArrays,
    pub occupations: Vec<[f32; 4]>,
    /// Cartesian components per group.
    pub cartesians: u32,
    /// Groups holding an orbital (the rest pad to a multiple of [`BATCH`]).
    pub live_groups: u32,
}

impl DensityArrays {
    pub fn new(density: &CartesianDensity) -> Self {
        let mut out = Self::default();
        let Some(first) = density.orbitals.first() else {
            return out;
        };
        let groups = density.orbitals.len().div_ceil(4).div_ceil(BATCH) * BATCH;
        let mut offset = 0u32;
        for s in &first.shells {
            out.gto.shells.push(GpuShell {
                center: s.center.as_vec3().to_array(),
                cutoff2: (s.cutoff * s.cutoff).min(f32::MAX as f64) as f32,
                l: s.l,
                prim_offset: out.gto.prims.len() as u32,
                prim_count: s.primitives.len() as u32,
                weight_offset: offset,
            });
            out.gto.prims.extend(s.primitives.iter().map(|[a, d]| [*a as f32, *d as f32]));
            offset += s.weights.len() as u32;
        }
        out.cartesians = offset;
        out.live_groups = density.orbitals.len().div_ceil(4) as u32;
        out.gto.weights = vec![0.0; groups * offset as usize * 4];
        for (i, orbital) in density.orbitals.iter().enumerate() {
            let (g, lane) = (i / 4, i % 4);
            for (s, shell) in orbital.shells.iter().enumerate() {
                let first = out.gto.shells[s].weight_offset as usize;
                for (c, w) in shell.weights.iter().enumerate() {
                    out.gto.weights[4 * (g * offset as usize + first + c) + lane] = *w as f32;
                }
            }
        }
        out.occupations = vec![[0.0; 4]; groups];
        for (i, n) in density.occupations.iter().enumerate() {
            out.occupations[i / 4][i % 4] = *n as f32;
        }
        out
    }

    /// Groups of four orbitals the buffers hold (a multiple of [`BATCH`]).
    pub fn groups(&self) -> u32 {
        self.occupations.len() as u32
    }
}

/// The compute pass; its pipeline is built once per device.
pub struct DensityHessianPass {
    pipeline: wgpu::ComputePipeline,
    params_layout: wgpu::BindGroupLayout,
    gto_layout: wgpu::BindGroupLayout,
}

impl DensityHessianPass {
    pub fn new(ctx: &GpuContext) -> Self {
        let device = &ctx.device;
        let module = super::shader_module(device, "density_hessian.wgsl");
        let params_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("density hessian layout"),
            entries: &[
                super::uniform_entry(0, wgpu::ShaderStages::COMPUTE),
                super::buffer_entry(
                    1,
                    wgpu::ShaderStages::COMPUTE,
                    wgpu::BufferBindingType::Storage { read_only: true },
                ),
                super::buffer_entry(
                    2,
                    wgpu::ShaderStages::COMPUTE,
                    wgpu::BufferBindingType::Storage { read_only: false },
                ),
            ],
        });
        let gto_layout = gto_layout(device, wgpu::ShaderStages::COMPUTE);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("density hessian pipeline layout"),
            bind_group_layouts: &[Some(&params_layout), Some(&gto_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("density hessian"),
            layout: Some(&layout),
            module: &module,
            entry_point: Some("cs_density_hessian"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self { pipeline, params_layout, gto_layout }
    }

    /// `quantity` (one made of ρ's derivatives, or ρ itself) of `wf`'s total density on `grid`,
    /// cube order: the derivatives on the GPU, the quantity finished on the CPU
    /// ([`nci::quantity_of_single`]).
    pub fn quantity_grid(
        &self,
        ctx: &GpuContext,
        wf: &Wavefunction,
        quantity: Quantity,
        grid: &GridSpec,
    ) -> Result<Vec<f32>, GpuError> {
        let density = WavefunctionDensity::new(wf).cartesian();
        let derivatives = self.derivatives(ctx, &density, grid)?;
        Ok(nci::quantity_of_single(&derivatives, quantity))
    }

    /// ρ, ∇ρ and the Hessian of `density` at every point of `grid`, cube order, in chunks the
    /// device holds.
    pub fn derivatives(
        &self,
        ctx: &GpuContext,
        density: &CartesianDensity,
        grid: &GridSpec,
    ) -> Result<Vec<[f32; 10]>, GpuError> {
        self.derivatives_in_chunks(ctx, density, grid, MAX_CHUNK_POINTS)
    }

    /// [`Self::derivatives`], at most `chunk` points per dispatch (fewer where the device's
    /// limits say so).
    pub fn derivatives_in_chunks(
        &self,
        ctx: &GpuContext,
        density: &CartesianDensity,
        grid: &GridSpec,
        chunk: usize,
    ) -> Result<Vec<[f32; 10]>, GpuError> {
        let device = &ctx.device;
        let limits = device.limits();
        let total = grid.len();
        let [nx, ny, nz] = grid.dims;
        if total == 0 {
            return Ok(Vec::new());
        }
        if u32::try_from(total).is_err() {
            return Err(GpuError::Rejected(format!("{nx}×{ny}×{nz} points are more than one pass indexes")));
        }
        let arrays = DensityArrays::new(density);
        let largest = [
            arrays.gto.weights.len() * 4,
            arrays.gto.shells.len() * std::mem::size_of::<GpuShell>(),
            arrays.gto.prims.len() * 8,
        ]
        .into_iter()
        .max()
        .unwrap_or(0) as u64;
        let binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        if largest > binding {
            return Err(GpuError::Rejected(format!(
                "the orbitals' weights take {largest} bytes; this GPU binds at most {binding}"
            )));
        }
        let bytes_per_point = (VALUES_PER_POINT * 4) as u64;
        let chunk = (chunk as u64)
            .min(binding / bytes_per_point)
            .min(limits.max_compute_workgroups_per_dimension as u64 * WORKGROUP as u64)
            .min(total as u64)
            .max(1);
        let out_size = chunk * bytes_per_point;

        let gto = GtoBuffers::new(device, &self.gto_layout, &arrays.gto);
        let occupations =
            storage_init(device, "density hessian occupations", bytemuck::cast_slice(&arrays.occupations));
        let params = super::uniform_buffer(device, "density hessian params", std::mem::size_of::<HessianParams>());
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("density hessian output"),
            size: out_size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("density hessian bind group"),
            layout: &self.params_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: occupations.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: output.as_entire_binding() },
            ],
        });

        let mut out: Vec<[f32; 10]> = Vec::with_capacity(total);
        if arrays.groups() == 0 {
            // No occupied orbital: no density.
            out.resize(total, [0.0; 10]);
            return Ok(out);
        }
        let mut first = 0usize;
        while first < total {
            let count = (total - first).min(chunk as usize);
            // One submission per batch: the parameters written before each are the ones it
            // reads, and each batch adds to what the one before wrote.
            for batch in (0..arrays.groups()).step_by(BATCH) {
                let values = HessianParams {
                    world_from_grid: grid.world_from_grid.as_mat4().to_cols_array_2d(),
                    dims: [nx as u32, ny as u32, nz as u32, arrays.live_groups],
                    chunk: [first as u32, count as u32, arrays.cartesians, batch],
                };
                ctx.queue.write_buffer(&params, 0, bytemuck::bytes_of(&values));
                let mut encoder =
                    device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("density hessian") });
                {
                    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("density hessian"),
                        timestamp_writes: None,
                    });
                    pass.set_pipeline(&self.pipeline);
                    pass.set_bind_group(0, &group, &[]);
                    pass.set_bind_group(1, &gto.bind_group, &[]);
                    pass.dispatch_workgroups((count as u32).div_ceil(WORKGROUP), 1, 1);
                }
                ctx.queue.submit([encoder.finish()]);
            }
            let bytes = super::readback::read_buffer(device, &ctx.queue, &output, count as u64 * bytes_per_point)?;
            let floats: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
            out.extend(floats.chunks_exact(VALUES_PER_POINT).map(|v| std::array::from_fn(|t| v[t])));
            first += count;
        }
        Ok(out)
    }
}

/// A read-only storage buffer holding `bytes` (padded to one element when empty: empty
/// storage buffers are not allowed).
fn storage_init(device: &wgpu::Device, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    let padding = [0u8; 16];
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: if bytes.is_empty() { &padding } else { bytes },
        usage: wgpu::BufferUsages::STORAGE,
    })
}
