//! The last phase of a frame: the float colour copied into the caller's 8-bit sRGB target,
//! with the translucent surfaces' fragment lists sorted and composited over it when there are
//! any ([`super::oit`]).

use super::{COLOR_FORMAT, GpuContext};

pub struct ResolvePass {
    pipeline: wgpu::RenderPipeline,
    composite: wgpu::RenderPipeline,
    weighted: wgpu::RenderPipeline,
    /// The scene colour's layout (group 1 of every resolve program).
    pub layout: wgpu::BindGroupLayout,
}

/// What the resolve composites over the scene: the fragment lists' composite group, or
/// weighted blending's targets.
#[derive(Debug, Clone, Copy)]
pub enum Lists<'a> {
    Sorted(&'a wgpu::BindGroup),
    Weighted(&'a wgpu::BindGroup),
    /// A walk over clouds in one depth order, with the sorted lists when there are any: the
    /// lists, the walk's pipeline and its bind group ([`super::volume::VolumePass::walk`]).
    Walk(Option<&'a wgpu::BindGroup>, &'a wgpu::RenderPipeline, &'a wgpu::BindGroup),
}

/// Which rows a resolve writes, and whether it is the frame's first.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rows {
    pub start: u32,
    pub count: u32,
    pub first: bool,
}

impl ResolvePass {
    /// `lists`: the layout of the fragment lists' composite group; `weighted`: of weighted
    /// blending's targets.
    pub fn new(ctx: &GpuContext, lists: &wgpu::BindGroupLayout, weighted: &wgpu::BindGroupLayout) -> Self {
        let device = &ctx.device;
        let module = super::shader_module(device, "resolve.wgsl");
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("resolve bind group layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let pipeline = |label, layouts: &[Option<&wgpu::BindGroupLayout>], entry| {
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: layouts,
                immediate_size: 0,
            });
            super::bufferless_pipeline(device, label, &pipeline_layout, &module, ("vs_fullscreen", entry), COLOR_FORMAT)
        };
        // Group 0 is a walk's clouds (volume_interleave.wgsl); 1 the scene, 2 the lists, 3 weighted
        // blending's targets.
        let composite =
            pipeline("resolve with translucent surfaces", &[None, Some(&layout), Some(lists)], "fs_composite");
        let weighted =
            pipeline("resolve weighted blending", &[None, Some(&layout), None, Some(weighted)], "fs_weighted");
        let pipeline = pipeline("resolve", &[None, Some(&layout)], "fs_main");
        Self { pipeline, composite, weighted, layout }
    }

    /// The bind group through which the pass reads `color` (the frame's float colour).
    pub fn bind(&self, device: &wgpu::Device, color: &wgpu::TextureView) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("resolve bind group"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(color) }],
        })
    }

    /// Resolves into `output`: the whole frame, or with `lists` (the fragment lists' composite
    /// group) the translucent surfaces composited over it in `rows` (the whole frame when
    /// `None`); a later band keeps the rows the earlier ones wrote.
    pub fn draw(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        color: &wgpu::BindGroup,
        output: &wgpu::TextureView,
        lists: Option<Lists>,
        rows: Option<Rows>,
        width: u32,
    ) {
        let load = match rows {
            Some(Rows { first: false, .. }) => wgpu::LoadOp::Load,
            _ => wgpu::LoadOp::Clear(wgpu::Color::BLACK),
        };
        let scissor = rows.map(|Rows { start, count, .. }| [0, start, width, count.max(1)]);
        self.record(encoder, color, output, lists, load, scissor);
    }

    /// A walk of a further group of clouds ([`Lists::Walk`]) over what the resolve wrote, in
    /// the pixels of `rect` ([x0, y0, x1, y1)) among `rows`: the group's clouds cover no other.
    pub fn draw_walk(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        color: &wgpu::BindGroup,
        output: &wgpu::TextureView,
        walk: Lists,
        rect: [u32; 4],
        rows: Option<Rows>,
    ) {
        let (y0, y1) = match rows {
            Some(r) => (rect[1].max(r.start), rect[3].min(r.start + r.count)),
            None => (rect[1], rect[3]),
        };
        if y1 > y0 && rect[2] > rect[0] {
            let scissor = [rect[0], y0, rect[2] - rect[0], y1 - y0];
            self.record(encoder, color, output, Some(walk), wgpu::LoadOp::Load, Some(scissor));
        }
    }

    /// One pass of the resolve's program for `lists`, within `scissor` (x, y, width, height).
    fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        color: &wgpu::BindGroup,
        output: &wgpu::TextureView,
        lists: Option<Lists>,
        load: wgpu::LoadOp<wgpu::Color>,
        scissor: Option<[u32; 4]>,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("resolve"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: output,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let Some([x, y, w, h]) = scissor {
            pass.set_scissor_rect(x, y, w, h);
        }
        match lists {
            Some(Lists::Sorted(lists)) => {
                pass.set_pipeline(&self.composite);
                pass.set_bind_group(2, lists, &[]);
            }
            Some(Lists::Weighted(targets)) => {
                pass.set_pipeline(&self.weighted);
                pass.set_bind_group(3, targets, &[]);
            }
            Some(Lists::Walk(lists, pipeline, clouds)) => {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, clouds, &[]);
                if let Some(lists) = lists {
                    pass.set_bind_group(2, lists, &[]);
                }
            }
            None => pass.set_pipeline(&self.pipeline),
        }
        pass.set_bind_group(1, color, &[]);
        pass.draw(0..3, 0..1);
    }
}
