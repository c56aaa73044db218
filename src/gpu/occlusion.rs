//! Occlusion culling of big surfaces in two phases, into indirect draws. The batches a
//! surface's level of detail chose ([`crate::model::octree::Batch`]) whose cluster was seen
//! last frame are drawn first; a depth pyramid is built from what they (and everything else
//! opaque) left; every batch is tested against it, the ones it does not hide are marked seen,
//! and those not drawn yet are drawn next. A batch is dropped only where the depth test would
//! have failed every one of its fragments, so the picture is unchanged.

use bytemuck::{Pod, Zeroable};

use super::GpuContext;
use crate::model::octree::Batch;

/// Mirror of `PyramidSize` in depth_pyramid_common.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct PyramidSize {
    pub frame: [u32; 4],
}

/// Pixels on a tile's side, and tiles on a block's (`PYRAMID_TILE`, `PYRAMID_BLOCK`).
const TILE: u32 = 8;
const BLOCK: u32 = 8;

/// Tiles and blocks of a frame of `size` pixels: how many words the pyramid holds.
fn pyramid_words(size: [u32; 2]) -> (u32, u32) {
    let tiles = size.map(|v| v.div_ceil(TILE));
    let blocks = tiles.map(|v| v.div_ceil(BLOCK));
    (tiles[0] * tiles[1], blocks[0] * blocks[1])
}

const WORKGROUP: u32 = 64;

/// The frame's depth pyramid, built once per frame when a pass asks for it.
pub struct DepthPyramid {
    tiles: wgpu::ComputePipeline,
    blocks: wgpu::ComputePipeline,
    build_layout: wgpu::BindGroupLayout,
    /// What the culling shaders bind as their group 1: the pyramid, its size and the depth.
    pub read_layout: wgpu::BindGroupLayout,
    size_uniform: wgpu::Buffer,
    /// For the frame size it was made for: the pyramid, and the groups that build and read it.
    frame: Option<PyramidFrame>,
}

struct PyramidFrame {
    size: [u32; 2],
    build: wgpu::BindGroup,
    read: wgpu::BindGroup,
}

impl DepthPyramid {
    pub fn new(ctx: &GpuContext) -> Self {
        let device = &ctx.device;
        let compute = wgpu::ShaderStages::COMPUTE;
        let build_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth pyramid build"),
            entries: &[
                depth_entry(0),
                super::buffer_entry(1, compute, wgpu::BufferBindingType::Storage { read_only: false }),
                super::uniform_entry(2, compute),
            ],
        });
        let read_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth pyramid read"),
            entries: &[
                super::buffer_entry(0, compute, wgpu::BufferBindingType::Storage { read_only: true }),
                super::uniform_entry(1, compute),
                depth_entry(2),
            ],
        });
        let module = super::shader_module(device, "depth_pyramid.wgsl");
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth pyramid"),
            bind_group_layouts: &[Some(&build_layout)],
            immediate_size: 0,
        });
        let pipeline = |entry| compute_pipeline(device, &layout, &module, entry);
        Self {
            tiles: pipeline("cs_tiles"),
            blocks: pipeline("cs_blocks"),
            build_layout,
            read_layout,
            size_uniform: super::uniform_buffer(device, "depth pyramid size", size_of::<PyramidSize>()),
            frame: None,
        }
    }

    /// Makes the pyramid for frames of `size` reading `depth` (the frame's depth target, made
    /// anew with the size).
    pub fn resize(&mut self, ctx: &GpuContext, size: [u32; 2], depth: &wgpu::TextureView) {
        let device = &ctx.device;
        let (tiles, blocks) = pyramid_words(size);
        let pyramid = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("depth pyramid"),
            size: 4 * u64::from(tiles + blocks),
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let u = PyramidSize { frame: [size[0], size[1], 0, 0] };
        ctx.queue.write_buffer(&self.size_uniform, 0, bytemuck::bytes_of(&u));
        let build = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("depth pyramid build"),
            layout: &self.build_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(depth) },
                wgpu::BindGroupEntry { binding: 1, resource: pyramid.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: self.size_uniform.as_entire_binding() },
            ],
        });
        let read = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("depth pyramid read"),
            layout: &self.read_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: pyramid.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: self.size_uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(depth) },
            ],
        });
        self.frame = Some(PyramidFrame { size, build, read });
    }

    /// Records the pyramid's build from the frame's depth as it stands; returns the group the
    /// culling shaders read it through.
    pub fn build(&self, encoder: &mut wgpu::CommandEncoder) -> Option<&wgpu::BindGroup> {
        let frame = self.frame.as_ref()?;
        let (tiles, blocks) = pyramid_words(frame.size);
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("depth pyramid"), timestamp_writes: None });
        pass.set_bind_group(0, &frame.build, &[]);
        pass.set_pipeline(&self.tiles);
        pass.dispatch_workgroups(tiles.div_ceil(WORKGROUP), 1, 1);
        pass.set_pipeline(&self.blocks);
        pass.dispatch_workgroups(blocks.div_ceil(WORKGROUP), 1, 1);
        Some(&frame.read)
    }
}

/// The frame's depth, read by compute shaders with `textureLoad`.
fn depth_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Depth,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

fn compute_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// Mirror of `CullUniforms` in surface_cull.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct CullUniforms {
    pub clip_from_object: [[f32; 4]; 4],
    pub counts: [u32; 4],
}

/// Mirror of `Batch` in surface_cull.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GpuBatch {
    pub lo: [f32; 3],
    pub first_index: u32,
    pub hi: [f32; 3],
    pub index_count: u32,
    pub cluster: [u32; 4],
}

/// Bytes of one indexed indirect draw (`DrawArgs`).
const DRAW_ARGS: u64 = 20;

/// The culling shaders, shared by every surface drawn with a level of detail.
#[derive(Clone)]
pub struct BatchCuller {
    split: wgpu::ComputePipeline,
    cull: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl BatchCuller {
    pub fn new(ctx: &GpuContext, pyramid: &wgpu::BindGroupLayout) -> Self {
        let device = &ctx.device;
        let compute = wgpu::ShaderStages::COMPUTE;
        let rw = wgpu::BufferBindingType::Storage { read_only: false };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("surface batches"),
            entries: &[
                super::uniform_entry(0, compute),
                super::buffer_entry(1, compute, wgpu::BufferBindingType::Storage { read_only: true }),
                super::buffer_entry(2, compute, rw),
                super::buffer_entry(3, compute, rw),
                super::buffer_entry(4, compute, rw),
            ],
        });
        let module = super::shader_module(device, "surface_cull.wgsl");
        let pipeline_layout = |groups: &[Option<&wgpu::BindGroupLayout>]| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("surface batches"),
                bind_group_layouts: groups,
                immediate_size: 0,
            })
        };
        let split = compute_pipeline(device, &pipeline_layout(&[Some(&layout)]), &module, "cs_split");
        let cull = compute_pipeline(device, &pipeline_layout(&[Some(&layout), Some(pyramid)]), &module, "cs_cull");
        Self { split, cull, layout }
    }
}

/// One surface's batches on the GPU: this frame's list, which clusters were seen when, and the
/// two phases' indirect draws.
pub struct CulledBatches {
    uniforms: wgpu::Buffer,
    seen: wgpu::Buffer,
    /// Room for this many batches in the buffers below.
    capacity: usize,
    batches: wgpu::Buffer,
    early: wgpu::Buffer,
    late: wgpu::Buffer,
    group: wgpu::BindGroup,
    /// Batches this frame, and the frame's number.
    count: u32,
    frame: u32,
    staged: Vec<GpuBatch>,
}

impl CulledBatches {
    /// For a mesh whose octree has `clusters` cells (the clusters are among them).
    pub fn new(ctx: &GpuContext, culler: &BatchCuller, clusters: usize) -> Self {
        let device = &ctx.device;
        let uniforms = super::uniform_buffer(device, "surface batch culling", size_of::<CullUniforms>());
        // Zeroed: no cluster was seen before the first frame (numbered from 2).
        let seen = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("clusters seen"),
            size: 4 * clusters.max(1) as u64,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let (capacity, batches, early, late, group) = Self::lists(device, culler, &uniforms, &seen, 1024);
        Self { uniforms, seen, capacity, batches, early, late, group, count: 0, frame: 1, staged: Vec::new() }
    }

    #[allow(clippy::type_complexity, reason = "the two passes' buffers and bind groups, returned together once")]
    fn lists(
        device: &wgpu::Device,
        culler: &BatchCuller,
        uniforms: &wgpu::Buffer,
        seen: &wgpu::Buffer,
        capacity: usize,
    ) -> (usize, wgpu::Buffer, wgpu::Buffer, wgpu::Buffer, wgpu::BindGroup) {
        let buffer = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
        };
        let n = capacity as u64;
        let batches = buffer(
            "surface batches",
            n * size_of::<GpuBatch>() as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let draws = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_SRC;
        let early = buffer("surface draws first", n * DRAW_ARGS, draws);
        let late = buffer("surface draws not hidden", n * DRAW_ARGS, draws);
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("surface batches"),
            layout: &culler.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: batches.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: seen.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: early.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: late.as_entire_binding() },
            ],
        });
        (capacity, batches, early, late, group)
    }

    /// Uploads this frame's batches (triangle runs of the mesh's index buffer) and camera.
    pub fn prepare(&mut self, ctx: &GpuContext, culler: &BatchCuller, clip_from_object: glam::Mat4, batches: &[Batch]) {
        let most = (u16::MAX as usize) * WORKGROUP as usize;
        let batches = &batches[..batches.len().min(most)];
        if batches.len() > self.capacity {
            let capacity = batches.len().next_power_of_two();
            (self.capacity, self.batches, self.early, self.late, self.group) =
                Self::lists(&ctx.device, culler, &self.uniforms, &self.seen, capacity);
        }
        self.frame += 1;
        self.count = batches.len() as u32;
        let u = CullUniforms {
            clip_from_object: clip_from_object.to_cols_array_2d(),
            counts: [self.count, self.frame, 0, 0],
        };
        ctx.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        self.staged.clear();
        self.staged.extend(batches.iter().map(|b| GpuBatch {
            lo: b.lo.to_array(),
            first_index: 3 * b.triangles.start,
            hi: b.hi.to_array(),
            index_count: 3 * (b.triangles.end - b.triangles.start),
            cluster: [b.cluster, 0, 0, 0],
        }));
        if !self.staged.is_empty() {
            ctx.queue.write_buffer(&self.batches, 0, bytemuck::cast_slice(&self.staged));
        }
    }

    /// Before drawing: the batches seen last frame become the first draws.
    pub fn split(&self, culler: &BatchCuller, encoder: &mut wgpu::CommandEncoder) {
        self.dispatch(encoder, "surface split", &culler.split, None);
    }

    /// After the first draws and the pyramid: the batches it does not hide are seen, and those
    /// not drawn yet become the second draws.
    pub fn cull(&self, culler: &BatchCuller, encoder: &mut wgpu::CommandEncoder, pyramid: &wgpu::BindGroup) {
        self.dispatch(encoder, "surface cull", &culler.cull, Some(pyramid));
    }

    /// One invocation per batch of `pipeline`, the pyramid bound as group 1 where given.
    fn dispatch(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        pipeline: &wgpu::ComputePipeline,
        pyramid: Option<&wgpu::BindGroup>,
    ) {
        if self.count == 0 {
            return;
        }
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        if let Some(pyramid) = pyramid {
            pass.set_bind_group(1, pyramid, &[]);
        }
        pass.dispatch_workgroups(self.count.div_ceil(WORKGROUP), 1, 1);
    }

    /// Records the first (`late` false) or second draws into a pass whose pipeline, vertex and
    /// index buffers are set.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, late: bool) {
        if self.count > 0 {
            pass.multi_draw_indexed_indirect(if late { &self.late } else { &self.early }, 0, self.count);
        }
    }

    /// The last frame's triangles drawn first and second, read back (for tests and benches).
    pub fn read_drawn(&self, ctx: &GpuContext) -> Result<(u64, u64), super::GpuError> {
        let n = self.count as u64 * DRAW_ARGS;
        if n == 0 {
            return Ok((0, 0));
        }
        let sum = |buffer: &wgpu::Buffer| -> Result<u64, super::GpuError> {
            let bytes = super::readback::read_buffer(&ctx.device, &ctx.queue, buffer, n)?;
            let words: &[u32] = bytemuck::cast_slice(&bytes);
            Ok(words.chunks_exact(5).map(|d| u64::from(d[0] / 3)).sum())
        };
        Ok((sum(&self.early)?, sum(&self.late)?))
    }
}
