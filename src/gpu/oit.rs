//! Exact order-independent transparency for Koide and Miyata's translucent surfaces: per-pixel
//! fragment lists built by the surfaces' collect pass (isosurface.wgsl), sorted and composited
//! by the resolve (resolve.wgsl).
//!
//! Memory is bounded: the node buffer holds a budget of fragments fixed from the device's
//! limits. A frame that needs more is not cut short: the count of what it needed is read back
//! and the frame is drawn again in horizontal bands, each collected and composited on its own
//! ([`FragmentLists::bands`]), as Koide and Miyata drew its tiles.

use std::sync::Arc;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU8, Ordering};

use bytemuck::{Pod, Zeroable};

use super::GpuContext;
use crate::scene::translucency::{Fragment, MAX_TRANSLUCENT_SURFACES, Optics, TranslucentSurface};

/// Bytes of one fragment node (oit_common.wgsl's `FragmentNode`).
pub const NODE_BYTES: u64 = 16;
/// Most bytes of fragment nodes, whatever the device allows.
pub const NODE_BUDGET_BYTES: u64 = 64 << 20;
/// Most bands a frame is split into.
pub const MAX_BANDS: u32 = 64;

/// Mirror of `ListInfo` in oit_common.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct ListInfo {
    pub width: u32,
    pub capacity: u32,
    pub surfaces: u32,
    pub _pad: u32,
}

/// Mirror of `SurfaceOptics` in oit_common.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GpuOptics {
    pub a: [f32; 4],
    pub b: [f32; 4],
    pub c: [f32; 4],
    pub d: [f32; 4],
    pub f: [f32; 4],
    pub g: [f32; 4],
    pub glow_d: [f32; 4],
    pub glow_f: [f32; 4],
    pub glow_g: [f32; 4],
    pub same_object: [u32; 4],
}

impl GpuOptics {
    fn new(o: &Optics, same_object: u64) -> Self {
        let v = |c: [f32; 3], w: f32| [c[0], c[1], c[2], w];
        Self {
            a: v(o.a, o.n),
            b: v(o.b, 0.0),
            c: v(o.c, 0.0),
            d: v(o.d, 0.0),
            f: v(o.f, 0.0),
            g: v(o.g, 0.0),
            glow_d: v(o.glow_d, 0.0),
            glow_f: v(o.glow_f, 0.0),
            glow_g: v(o.glow_g, 0.0),
            same_object: [same_object as u32, (same_object >> 32) as u32, 0, 0],
        }
    }
}

/// The counts of every band, then the deep pixels.
const READBACK_BYTES: u64 = (MAX_BANDS as u64 + 1) * 4;

const TABLE_BYTES: usize = MAX_TRANSLUCENT_SURFACES * size_of::<GpuOptics>();

/// What the last frame's fragment lists held, read back from the GPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FragmentStats {
    /// The most fragments one band of the frame produced.
    pub needed: u32,
    /// Nodes the buffer holds.
    pub capacity: u32,
    /// Bands the frame was drawn in.
    pub bands: u32,
    /// Pixels with more fragments than the resolve sorts (their farthest were left out).
    pub deep_pixels: u32,
}

impl FragmentStats {
    /// Whether every fragment was stored.
    pub fn fits(&self) -> bool {
        self.needed <= self.capacity
    }

    /// Bands that fit `needed` fragments spread as this frame's were, with a margin.
    pub fn bands_needed(&self) -> u32 {
        if self.fits() {
            return self.bands;
        }
        let ratio = self.needed as f64 / self.capacity.max(1) as f64;
        ((self.bands.max(1) as f64 * ratio * 1.25).ceil() as u32).clamp(self.bands + 1, MAX_BANDS)
    }

    /// Bytes of fragment storage in use: heads and nodes.
    pub fn node_bytes(&self) -> u64 {
        self.capacity as u64 * NODE_BYTES
    }
}

/// How translucent surfaces are composited.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Transparency {
    /// Per-pixel fragment lists sorted in exact depth order, with Koide and Miyata's glow.
    #[default]
    Exact,
    /// Weighted blended order-independent transparency (McGuire & Bavoil 2013): one pass,
    /// bounded memory, approximate; kept to measure what exact order buys.
    WeightedBlended,
}

/// Weighted blending's two targets: the weighted sum of colour and alpha, and the product of
/// 1 − α (the revealage).
pub struct WeightedTargets {
    pub accum: wgpu::TextureView,
    pub revealage: wgpu::TextureView,
    pub resolve_bind: wgpu::BindGroup,
}

/// Formats of [`WeightedTargets`].
pub const ACCUM_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const REVEALAGE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;

/// A frame's fragment lists read back ([`FragmentLists::read`]).
#[derive(Debug, Clone)]
pub struct FragmentDump {
    pub size: [u32; 2],
    /// Per pixel, row by row.
    pub lists: Vec<Vec<Fragment>>,
    pub surfaces: Vec<TranslucentSurface>,
}

/// The lists' buffers at one frame size, and the bind groups of the collect and composite
/// passes.
pub struct FragmentLists {
    info: wgpu::Buffer,
    heads: wgpu::Buffer,
    nodes: wgpu::Buffer,
    counter: wgpu::Buffer,
    /// The counter after each band, and the deep-pixel count: copied out for the read-back.
    needed: wgpu::Buffer,
    readback: wgpu::Buffer,
    deep: wgpu::Buffer,
    table: wgpu::Buffer,
    pub collect_layout: wgpu::BindGroupLayout,
    pub composite_layout: wgpu::BindGroupLayout,
    pub weighted_layout: wgpu::BindGroupLayout,
    /// Weighted blending's targets at this size, made when first used.
    weighted: Option<WeightedTargets>,
    collect_bind: Option<wgpu::BindGroup>,
    composite_bind: Option<wgpu::BindGroup>,
    size: [u32; 2],
    capacity: u32,
    /// Bands the next frame is drawn in.
    pub bands: u32,
    /// Translucent surfaces this frame.
    pub surfaces: usize,
    /// Their optics and objects, as the composite reads them.
    described: Vec<TranslucentSurface>,
    /// The read-back: 0 idle, 1 copied and not yet mapped, 2 being mapped.
    state: Arc<AtomicU8>,
    /// The last mapped read-back not yet taken: the most any band needed, and the deep
    /// pixels.
    last: Arc<Mutex<Option<(u32, u32)>>>,
}

fn storage(device: &wgpu::Device, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(4),
        usage: wgpu::BufferUsages::STORAGE | usage,
        mapped_at_creation: false,
    })
}

impl FragmentLists {
    pub fn new(ctx: &GpuContext) -> Self {
        let device = &ctx.device;
        let limits = device.limits();
        let bytes = NODE_BUDGET_BYTES.min(limits.max_storage_buffer_binding_size).min(limits.max_buffer_size);
        Self::with_capacity(ctx, (bytes / NODE_BYTES) as u32)
    }

    /// Lists of at most `capacity` fragments per band (tests force bands with a small one).
    pub fn with_capacity(ctx: &GpuContext, capacity: u32) -> Self {
        let device = &ctx.device;
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let rw = wgpu::BufferBindingType::Storage { read_only: false };
        let ro = wgpu::BufferBindingType::Storage { read_only: true };
        let uniform = wgpu::BufferBindingType::Uniform;
        let entry = super::buffer_entry;
        let depth_entry = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: fragment,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let collect_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fragment lists: collect"),
            entries: &[
                entry(0, fragment, uniform),
                entry(1, fragment, rw),
                entry(2, fragment, rw),
                entry(3, fragment, rw),
                depth_entry(4),
                entry(5, fragment, uniform),
            ],
        });
        let texture = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: fragment,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let weighted_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("weighted blending: resolve"),
            entries: &[texture(0), texture(1)],
        });
        let composite_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fragment lists: composite"),
            entries: &[
                entry(0, fragment, uniform),
                entry(1, fragment, ro),
                entry(2, fragment, ro),
                entry(3, fragment, uniform),
                entry(4, fragment, rw),
                depth_entry(5),
            ],
        });
        let copy = wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        Self {
            info: super::uniform_buffer(device, "fragment list info", size_of::<ListInfo>()),
            heads: storage(device, "fragment list heads", 4, copy),
            // Made when a frame first has translucent surfaces.
            nodes: storage(device, "fragment nodes", 4, wgpu::BufferUsages::COPY_SRC),
            counter: storage(device, "fragment counter", 4, copy),
            needed: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fragments needed"),
                size: READBACK_BYTES,
                usage: copy,
                mapped_at_creation: false,
            }),
            readback: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fragments read back"),
                size: READBACK_BYTES,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            deep: storage(device, "deep pixels", 4, copy),
            table: super::uniform_buffer(device, "translucent optics", TABLE_BYTES),
            collect_layout,
            composite_layout,
            weighted_layout,
            weighted: None,
            collect_bind: None,
            composite_bind: None,
            size: [0, 0],
            capacity,
            bands: 1,
            surfaces: 0,
            described: Vec::new(),
            state: Arc::new(AtomicU8::new(0)),
            last: Arc::new(Mutex::new(None)),
        }
    }

    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Sets this frame's surfaces and size; `depth` is the frame's opaque depth.
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        size: [u32; 2],
        surfaces: &[TranslucentSurface],
        depth: &wgpu::TextureView,
        resized: bool,
    ) {
        let device = &ctx.device;
        self.surfaces = surfaces.len().min(MAX_TRANSLUCENT_SURFACES);
        self.described = surfaces[..self.surfaces].to_vec();
        if self.surfaces == 0 {
            return;
        }
        if size != self.size || resized || self.collect_bind.is_none() {
            self.size = size;
            let nodes = self.capacity as u64 * NODE_BYTES;
            if self.nodes.size() < nodes {
                self.nodes = storage(device, "fragment nodes", nodes, wgpu::BufferUsages::COPY_SRC);
            }
            let copy = wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
            self.heads = storage(device, "fragment list heads", size[0] as u64 * size[1] as u64 * 4, copy);
            self.collect_bind = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("fragment lists: collect"),
                layout: &self.collect_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: wgpu::Buffer::as_entire_binding(&self.info) },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::Buffer::as_entire_binding(&self.heads) },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::Buffer::as_entire_binding(&self.nodes) },
                    wgpu::BindGroupEntry { binding: 3, resource: wgpu::Buffer::as_entire_binding(&self.counter) },
                    wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(depth) },
                    wgpu::BindGroupEntry { binding: 5, resource: wgpu::Buffer::as_entire_binding(&self.table) },
                ],
            }));
            self.weighted = None;
            self.composite_bind = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("fragment lists: composite"),
                layout: &self.composite_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: wgpu::Buffer::as_entire_binding(&self.info) },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::Buffer::as_entire_binding(&self.heads) },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::Buffer::as_entire_binding(&self.nodes) },
                    wgpu::BindGroupEntry { binding: 3, resource: wgpu::Buffer::as_entire_binding(&self.table) },
                    wgpu::BindGroupEntry { binding: 4, resource: wgpu::Buffer::as_entire_binding(&self.deep) },
                    wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(depth) },
                ],
            }));
        }
        let info = ListInfo { width: size[0], capacity: self.capacity, surfaces: self.surfaces as u32, _pad: 0 };
        ctx.queue.write_buffer(&self.info, 0, bytemuck::bytes_of(&info));
        let table: Vec<GpuOptics> = surfaces
            .iter()
            .take(MAX_TRANSLUCENT_SURFACES)
            .map(|s| {
                let same = surfaces
                    .iter()
                    .take(MAX_TRANSLUCENT_SURFACES)
                    .enumerate()
                    .filter(|(_, o)| o.object == s.object)
                    .fold(0u64, |m, (k, _)| m | 1 << k);
                GpuOptics::new(&s.optics, same)
            })
            .collect();
        ctx.queue.write_buffer(&self.table, 0, bytemuck::cast_slice(&table));
    }

    /// Weighted blending's targets at the frame's size (after [`Self::prepare`]).
    pub fn weighted_targets(&mut self, ctx: &GpuContext) -> &WeightedTargets {
        let size = self.size;
        let layout = &self.weighted_layout;
        self.weighted.get_or_insert_with(|| {
            let texture = |label, format| {
                super::target::target_texture(&ctx.device, label, size, format, wgpu::TextureUsages::TEXTURE_BINDING)
                    .create_view(&Default::default())
            };
            let accum = texture("weighted colour", ACCUM_FORMAT);
            let revealage = texture("revealage", REVEALAGE_FORMAT);
            let resolve_bind = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("weighted blending: resolve"),
                layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&accum) },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&revealage) },
                ],
            });
            WeightedTargets { accum, revealage, resolve_bind }
        })
    }

    /// Weighted blending's targets, when made.
    pub fn weighted(&self) -> Option<&WeightedTargets> {
        self.weighted.as_ref()
    }

    /// The bind group of the surfaces' collect pass (after [`Self::prepare`] with surfaces).
    pub fn collect_bind(&self) -> Option<&wgpu::BindGroup> {
        self.collect_bind.as_ref()
    }

    pub fn composite_bind(&self) -> Option<&wgpu::BindGroup> {
        self.composite_bind.as_ref()
    }

    /// Empties the lists before a band is collected.
    pub fn clear(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.heads, 0, None);
        encoder.clear_buffer(&self.counter, 0, None);
    }

    /// Empties the deep-pixel count before a frame.
    pub fn begin_frame(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.deep, 0, None);
        encoder.clear_buffer(&self.needed, 0, None);
    }

    /// After band `band` was collected: keeps its count.
    pub fn end_band(&self, encoder: &mut wgpu::CommandEncoder, band: u32) {
        encoder.copy_buffer_to_buffer(&self.counter, 0, &self.needed, band.min(MAX_BANDS - 1) as u64 * 4, 4);
    }

    /// After the frame's composite: copies the counts out to be mapped, unless the last
    /// frame's are still on their way.
    pub fn end_frame(&self, encoder: &mut wgpu::CommandEncoder) {
        if self.state.compare_exchange(0, 1, Ordering::AcqRel, Ordering::Acquire).is_ok() {
            encoder.copy_buffer_to_buffer(&self.deep, 0, &self.needed, MAX_BANDS as u64 * 4, 4);
            encoder.copy_buffer_to_buffer(&self.needed, 0, &self.readback, 0, READBACK_BYTES);
        }
    }

    /// Starts mapping what [`Self::end_frame`] copied (call after the frame was submitted);
    /// the counts land in [`Self::last_stats`] when the device is next polled.
    pub fn request_stats(&self) {
        if self.state.compare_exchange(1, 2, Ordering::AcqRel, Ordering::Acquire).is_err() {
            return;
        }
        let (state, last, buffer) = (Arc::clone(&self.state), Arc::clone(&self.last), self.readback.clone());
        self.readback.slice(..).map_async(wgpu::MapMode::Read, move |result| {
            if result.is_ok() {
                let words: Option<Vec<u32>> =
                    buffer.slice(..).get_mapped_range().ok().map(|view| bytemuck::pod_collect_to_vec(&view));
                buffer.unmap();
                if let Some(words) = words {
                    let needed = words[..MAX_BANDS as usize].iter().copied().max().unwrap_or(0);
                    *last.lock().unwrap_or_else(std::sync::PoisonError::into_inner) =
                        Some((needed, words[MAX_BANDS as usize]));
                }
            }
            state.store(0, Ordering::Release);
        });
    }

    /// What the last mapped frame held, once: `None` until a new read-back has landed.
    pub fn take_stats(&self) -> Option<FragmentStats> {
        let (needed, deep_pixels) = self.last.lock().unwrap_or_else(std::sync::PoisonError::into_inner).take()?;
        Some(FragmentStats { needed, capacity: self.capacity, bands: self.bands, deep_pixels })
    }

    /// Waits for the counts of the frame just submitted.
    pub fn read_stats(&self, ctx: &GpuContext) -> Option<FragmentStats> {
        self.request_stats();
        let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
        self.take_stats()
    }

    /// Every pixel's fragments as the last band left them (the whole frame when it was drawn
    /// in one), unsorted, with the surfaces they name: what the CPU reference composites.
    pub fn read(&self, ctx: &GpuContext) -> Result<FragmentDump, super::GpuError> {
        let [w, h] = self.size;
        let read = |b: &wgpu::Buffer, bytes: u64| super::readback::read_buffer(&ctx.device, &ctx.queue, b, bytes);
        let heads: Vec<u32> = bytemuck::pod_collect_to_vec(&read(&self.heads, w as u64 * h as u64 * 4)?);
        let count = heads.iter().filter(|&&h| h > 0).count();
        let nodes: Vec<[u32; 4]> = if count == 0 {
            Vec::new()
        } else {
            bytemuck::pod_collect_to_vec(&read(&self.nodes, self.capacity as u64 * NODE_BYTES)?)
        };
        let half = |bits: u32| half::f16::from_bits(bits as u16).to_f32();
        let lists = heads
            .iter()
            .map(|&head| {
                let mut list = Vec::new();
                let mut link = head;
                while link > 0 && link <= nodes.len() as u32 && list.len() <= nodes.len() {
                    let [depth, cosines, highlight_surface, next] = nodes[link as usize - 1];
                    list.push(Fragment {
                        depth: f32::from_bits(depth),
                        surface: highlight_surface >> 16,
                        n_dot_v: half(cosines & 0xffff),
                        n_dot_l: half(cosines >> 16),
                        r_dot_v: half(highlight_surface & 0xffff),
                    });
                    link = next;
                }
                list
            })
            .collect();
        Ok(FragmentDump { size: self.size, lists, surfaces: self.described.clone() })
    }

    /// The rows of band `band` of `bands` in a frame `height` pixels tall.
    pub fn band_rows(height: u32, band: u32, bands: u32) -> (u32, u32) {
        let per = height.div_ceil(bands.max(1));
        let start = (band * per).min(height);
        (start, (start + per).min(height) - start)
    }
}
