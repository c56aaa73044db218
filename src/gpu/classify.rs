//! Key volumes classified for a transfer function: each texel's extinction and colour in a
//! texture of halves (volume_classify.wgsl). Naka et al. keep their key volumes as coloured
//! translucent textures made once, and mix those while θ is dragged; α-mix and three-pass do the
//! same here (volume_morph.wgsl): what a key volume's texel looks like does not depend on k, so
//! a frame samples it instead of classifying both volumes' samples at every plane.

use super::volume::{VolumeTexture, VolumeUniforms};

/// The format of a classified texel (volume_classify.wgsl): an orbital's signed extinction per
/// reference step (one half: a sample costs least), or a density's extinction and colour.
/// `signed_field` is the frame's (both key volumes are drawn as the first one is).
fn format(signed_field: u32) -> wgpu::TextureFormat {
    match signed_field {
        1 => wgpu::TextureFormat::R16Float,
        _ => wgpu::TextureFormat::Rg16Float,
    }
}

/// The classified textures a cloud keeps: the pair it shows and the pair before (a drag back
/// across a key angle finds them).
const KEPT: usize = 4;

/// The transfer function's parameters that a classification depends on, as bit patterns taken
/// from a frame's uniforms (not the view, the mix ratio or the colours, which are applied per
/// sample).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct TransferKey([u32; 16]);

impl TransferKey {
    fn of(u: &VolumeUniforms) -> Self {
        let f = |x: f32| x.to_bits();
        let [p, n] = [u.tf_positive, u.tf_negative];
        Self([
            f(u.k1),
            f(u.k2),
            f(u.inv_max),
            f(u.visible_min),
            u.signed_field,
            u.shape_positive,
            u.shape_negative,
            u.tf_bits & super::volume::TF_SHAPED,
            f(u.log_lo),
            f(u.inv_log_span),
            f(p[0]),
            f(p[1]),
            f(p[2]),
            f(n[0]),
            f(n[1]),
            f(n[2]),
        ])
    }
}

/// The largest side of the 2D texture the layers are drawn into (WebGPU's guaranteed
/// `max_texture_dimension_2d`; volume_classify.wgsl's ATLAS_SIDE).
const ATLAS_SIDE: u32 = 8192;

/// How a key volume's layers (w × h texels each) are placed in the 2D texture one pass draws:
/// in rows of `columns` tiles, `rows` rows (volume_classify.wgsl's `vs_classify`).
struct Atlas {
    columns: u32,
    rows: u32,
    /// The rows that fit the texture's side.
    most_rows: u32,
}

impl Atlas {
    fn new(w: u32, h: u32, layers: u32) -> Self {
        let columns = layers.min(ATLAS_SIDE / w);
        let most_rows = ATLAS_SIDE / h;
        Self { columns, rows: layers.min(columns * most_rows).div_ceil(columns), most_rows }
    }

    /// Layers one pass draws.
    fn per_pass(&self) -> u32 {
        self.columns * self.most_rows
    }
}

/// One key volume's classified texture, for the transfer function it was made with.
struct Classified {
    /// The key volume's texture (compared by identity).
    source: wgpu::Texture,
    transfer: TransferKey,
    view: wgpu::TextureView,
}

/// A cloud's classified key volumes, the most recently used first.
#[derive(Default)]
pub struct ClassifiedVolumes(Vec<Classified>);

/// The pipelines that classify a key volume's texels, one per texture format.
pub struct Classifier {
    /// Draws into an orbital's (R16Float) texture, then a density's (Rg16Float).
    pipelines: [wgpu::RenderPipeline; 2],
}

impl Classifier {
    /// `layout`: the slices' group 0 (the uniforms and the volume), which the pass reads.
    pub fn new(device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> Self {
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("key volume classification"),
            bind_group_layouts: &[Some(layout)],
            immediate_size: 0,
        });
        let module = super::shader_module(device, "volume_classify.wgsl");
        let pipeline = |format: wgpu::TextureFormat| {
            let label = format!("key volume classification into {format:?}");
            super::bufferless_pipeline(
                device,
                &label,
                &pipeline_layout,
                &module,
                ("vs_classify", "fs_classify"),
                format,
            )
        };
        Self { pipelines: [pipeline(format(1)), pipeline(format(0))] }
    }

    /// `volume` classified for the transfer function of `u` (written to the uniform buffer
    /// before this call): from `kept`, or drawn now and submitted ahead of the frame that samples
    /// it, reading the slices' group 0 that `group` makes (the uniforms and `volume`), which is
    /// made only then.
    pub fn classified(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        kept: &mut ClassifiedVolumes,
        volume: &VolumeTexture,
        (group, u): (impl FnOnce() -> wgpu::BindGroup, &VolumeUniforms),
    ) -> wgpu::TextureView {
        let transfer = TransferKey::of(u);
        if let Some(i) = kept.0.iter().position(|c| c.source == volume.texture && c.transfer == transfer) {
            let hit = kept.0.remove(i);
            let view = hit.view.clone();
            kept.0.insert(0, hit);
            return view;
        }
        let size = volume.texture.size();
        let format = format(u.signed_field);
        let texture = device.create_texture(&super::texture_descriptor(
            "classified key volume",
            size,
            wgpu::TextureDimension::D3,
            format,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        ));
        let view = texture.create_view(&Default::default());
        let [w, h, layers] = [size.width, size.height, size.depth_or_array_layers];
        let atlas = Atlas::new(w, h, layers);
        let tiles = device.create_texture(&super::texture_descriptor(
            "classified layers",
            wgpu::Extent3d { width: atlas.columns * w, height: atlas.rows * h, depth_or_array_layers: 1 },
            wgpu::TextureDimension::D2,
            format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        ));
        let tiles_view = tiles.create_view(&Default::default());
        let pipeline = &self.pipelines[usize::from(u.signed_field != 1)];
        let group = group();
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("classify key volume") });
        for first in (0..layers).step_by(atlas.per_pass() as usize) {
            let last = (first + atlas.per_pass()).min(layers);
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("classify layers"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &tiles_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    ..Default::default()
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &group, &[]);
                pass.draw(0..6, first..last);
            }
            for layer in first..last {
                let tile = layer - first;
                let origin = wgpu::Origin3d { x: tile % atlas.columns * w, y: tile / atlas.columns * h, z: 0 };
                encoder.copy_texture_to_texture(
                    wgpu::TexelCopyTextureInfo { origin, ..tiles.as_image_copy() },
                    wgpu::TexelCopyTextureInfo {
                        origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
                        ..texture.as_image_copy()
                    },
                    wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
                );
            }
        }
        queue.submit([encoder.finish()]);
        kept.0.insert(0, Classified { source: volume.texture.clone(), transfer, view: view.clone() });
        kept.0.truncate(KEPT);
        view
    }
}
