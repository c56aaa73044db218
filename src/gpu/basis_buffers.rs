//! A basis expansion of an orbital in GPU storage buffers: what the fill pass (`gto`) and the
//! slices evaluating orbitals per sample (`volume`'s direct mode) read.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::model::cartesian::CartesianExpansion;

/// Mirror of `GtoShell` in gto_common.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuShell {
    pub center: [f32; 3],
    pub cutoff2: f32,
    pub l: u32,
    pub prim_offset: u32,
    pub prim_count: u32,
    pub weight_offset: u32,
}
const _: () = assert!(std::mem::size_of::<GpuShell>() == 32);

/// The flat arrays the kernels read.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GtoArrays {
    pub shells: Vec<GpuShell>,
    pub prims: Vec<[f32; 2]>,
    pub weights: Vec<f32>,
}

impl GtoArrays {
    pub fn new(e: &CartesianExpansion) -> Self {
        let mut out = Self::default();
        for s in &e.shells {
            out.shells.push(GpuShell {
                center: s.center.as_vec3().to_array(),
                cutoff2: (s.cutoff * s.cutoff).min(f32::MAX as f64) as f32,
                l: s.l,
                prim_offset: out.prims.len() as u32,
                prim_count: s.primitives.len() as u32,
                weight_offset: out.weights.len() as u32,
            });
            out.prims.extend(s.primitives.iter().map(|[a, d]| [*a as f32, *d as f32]));
            out.weights.extend(s.weights.iter().map(|&w| w as f32));
        }
        out
    }
}

/// Storage buffers holding one expansion, bound as group 1 of the GTO kernels.
pub struct GtoBuffers {
    pub bind_group: wgpu::BindGroup,
}

pub fn gto_layout(device: &wgpu::Device, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayout {
    let storage =
        |binding| super::buffer_entry(binding, visibility, wgpu::BufferBindingType::Storage { read_only: true });
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("gto bind group layout"),
        entries: &[storage(0), storage(1), storage(2)],
    })
}

impl GtoBuffers {
    pub fn new(device: &wgpu::Device, layout: &wgpu::BindGroupLayout, arrays: &GtoArrays) -> Self {
        // Empty storage buffers are not allowed: pad each with one element.
        let buffer = |label: &str, mut bytes: Vec<u8>| {
            if bytes.is_empty() {
                bytes.resize(32, 0);
            }
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &bytes,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        // An empty expansion must evaluate to zero: the padding shell has l = 0 and no primitives.
        let shells = buffer("gto shells", bytemuck::cast_slice(&arrays.shells).to_vec());
        let prims = buffer("gto primitives", bytemuck::cast_slice(&arrays.prims).to_vec());
        let weights = buffer("gto weights", bytemuck::cast_slice(&arrays.weights).to_vec());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gto bind group"),
            layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: shells.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: prims.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: weights.as_entire_binding() },
            ],
        });
        Self { bind_group }
    }
}
