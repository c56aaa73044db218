//! The frame as data: named targets that every pass shares, and the phases that draw into them,
//! in the order the frame description gives.
//!
//! A representation (atoms, a cloud, an isosurface, later point splats or order-independent
//! transparency) implements [`Draw`]: it says in which phases it draws and records its draws when
//! the renderer opens that phase's render pass. Adding one means adding a drawer, not editing the
//! frame.

use super::target::target_texture;
use super::{DEPTH_FORMAT, SCENE_FORMAT};

/// Per-pixel object ids for picking (0: nothing).
pub const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// A target of the frame, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Target {
    /// Linear float colour (HDR): the scene is composited here.
    Color,
    /// Depth of the opaque geometry; a texture later phases can also sample.
    Depth,
    /// The id of the opaque surface in each pixel ([`PickId`]), read back for picking.
    Ids,
    /// Each atom layer's culled draw lists and compute-rasterised small spheres.
    Splats,
    /// The depth pyramid of the first opaque draws, and the draws of what it does not hide
    /// ([`super::occlusion`]).
    Visible,
    /// Per-pixel lists of translucent surface fragments ([`super::oit`]).
    Fragments,
    /// The caller's 8-bit sRGB view.
    Output,
}

/// One phase: one render pass over the shared targets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Phase {
    /// Compute work before drawing: frustum culling, level of detail, small spheres rasterised.
    Cull,
    /// Opaque geometry (atoms, isosurfaces): clears colour, depth and ids, writes all three.
    /// Big surfaces draw only the parts seen last frame here.
    Opaque,
    /// Compute: a depth pyramid from the opaque depth, and big surfaces' parts tested against it
    /// (skipped when no pass asks).
    Occlusion,
    /// The parts of big surfaces not drawn yet that the pyramid does not hide, over what the
    /// opaque phase drew.
    OpaqueLate,
    /// Translucent clouds back to front: blends over colour, tests depth without writing it.
    Translucent,
    /// Translucent surfaces append their fragments in front of the opaque depth to per-pixel
    /// lists (Koide and Miyata, docs/references.md); a frame whose lists overflow their budget repeats this and the
    /// resolve band by band.
    Fragments,
    /// Sorts each pixel's fragments and composites them over the float colour, exactly in
    /// depth order, into the caller's output.
    Resolve,
}

/// What a phase reads and writes, so the order can be checked and shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PhaseNode {
    pub phase: Phase,
    pub label: &'static str,
    pub reads: &'static [Target],
    pub writes: &'static [Target],
}

/// The frame every host draws: culling and small spheres (compute), opaque geometry, the
/// occlusion test and what it leaves of big surfaces, then translucent clouds over it,
/// translucent surfaces into fragment lists, then resolve.
pub const STANDARD_FRAME: &[PhaseNode] = &[
    PhaseNode { phase: Phase::Cull, label: "cull and splat", reads: &[], writes: &[Target::Splats] },
    PhaseNode {
        phase: Phase::Opaque,
        label: "opaque",
        reads: &[Target::Splats],
        writes: &[Target::Color, Target::Depth, Target::Ids],
    },
    PhaseNode { phase: Phase::Occlusion, label: "occlusion test", reads: &[Target::Depth], writes: &[Target::Visible] },
    PhaseNode {
        phase: Phase::OpaqueLate,
        label: "opaque, not hidden",
        reads: &[Target::Visible, Target::Depth],
        writes: &[Target::Color, Target::Depth, Target::Ids],
    },
    PhaseNode {
        phase: Phase::Translucent,
        label: "translucent",
        reads: &[Target::Color, Target::Depth],
        writes: &[Target::Color],
    },
    PhaseNode {
        phase: Phase::Fragments,
        label: "translucent surfaces",
        reads: &[Target::Depth],
        writes: &[Target::Fragments],
    },
    PhaseNode {
        phase: Phase::Resolve,
        label: "sort, composite and resolve",
        reads: &[Target::Color, Target::Fragments],
        writes: &[Target::Output],
    },
];

/// True when every target a phase reads was written by an earlier phase.
pub fn is_ordered(frame: &[PhaseNode]) -> bool {
    frame
        .iter()
        .enumerate()
        .all(|(n, node)| node.reads.iter().all(|t| frame[..n].iter().any(|earlier| earlier.writes.contains(t))))
}

/// A representation that draws in some phases of the frame.
pub trait Draw {
    /// Takes the frame's camera and settings before any phase is recorded (culling lists,
    /// uniforms, slices, level of detail).
    fn prepare(&mut self, _frame: &Prepare<'_>) {}
    /// How many translucent surfaces it draws this frame (they are numbered across the frame).
    fn translucent_surfaces(&self) -> usize {
        0
    }
    /// The phases it draws in.
    fn phases(&self) -> &'static [Phase];
    /// Records its draws into the open render pass of `phase`.
    fn draw(&self, phase: Phase, pass: &mut wgpu::RenderPass<'_>);
    /// Records its compute work of [`Phase::Cull`].
    fn compute(&self, _encoder: &mut wgpu::CommandEncoder) {}
    /// Whether this frame it has draws the depth pyramid may hide: then the frame builds the
    /// pyramid and opens [`Phase::OpaqueLate`].
    fn culls_by_depth(&self) -> bool {
        false
    }
    /// Records its occlusion tests of [`Phase::Occlusion`] against the depth pyramid (the
    /// group [`super::occlusion::DepthPyramid::build`] returns).
    fn occlude(&self, _encoder: &mut wgpu::CommandEncoder, _pyramid: &wgpu::BindGroup) {}
}

/// The renderer's layouts a representation's pipelines are built against.
pub struct Shared<'a> {
    /// The resolve pass's group of the frame's colour and depth (what a cloud's walk reads).
    pub scene: &'a wgpu::BindGroupLayout,
    /// The fragment lists translucent surfaces append to.
    pub collect: &'a wgpu::BindGroupLayout,
    /// The fragment lists as the composite reads them.
    pub composite: &'a wgpu::BindGroupLayout,
    /// The depth pyramid occlusion tests read.
    pub pyramid: &'a wgpu::BindGroupLayout,
}

/// A kind of drawing a layer holds (atoms, arrows, isosurfaces, clouds, …): made once per
/// renderer, instanced per layer, listed in [`super::layer::Representations`].
pub trait Representation: Draw + Sized {
    /// The first instance, its pipelines built.
    fn new(ctx: &super::GpuContext, shared: &Shared<'_>) -> Self;
    /// An empty instance sharing this one's pipelines.
    fn instance(&self, ctx: &super::GpuContext) -> Self;
    /// Draws nothing from now on, keeping its pipelines.
    fn clear(&mut self, ctx: &super::GpuContext);
}

/// What each representation of a layer is given every frame ([`Draw::prepare`]).
pub struct Prepare<'a> {
    pub ctx: &'a super::GpuContext,
    /// The camera seen from the layer's object.
    pub view: &'a ObjectView,
    /// The layer's number: the object field of its pick ids.
    pub layer: u32,
    /// The frame's size in pixels.
    pub size: [u32; 2],
    /// The opaque scene's depth, which the translucent phase reads.
    pub depth: &'a wgpu::TextureView,
    /// A later band of a frame drawn in bands: the first band's culling and level of detail
    /// stand (preparing them again would count frames the seen-last-frame lists skip).
    pub later_tile: bool,
    /// The factor on level-of-detail thresholds (above 1 while the user drags).
    pub lod_scale: f32,
    /// Clouds' slice planes per texel along the view at most (infinite: as many as asked).
    pub planes_per_texel: f32,
    /// The number of the layer's first translucent surface among the frame's.
    pub first_translucent: usize,
    /// The fragment lists translucent surfaces append to (when the frame has any and the layer
    /// is drawn), and how they are composited.
    pub lists: Option<(&'a wgpu::BindGroup, super::oit::Transparency)>,
    /// The layer's cloud.
    pub cloud: &'a crate::scene::VolumeSettings,
    /// The object's clipping plane in its own frame, (unit n, d): points with n·p > d are cut
    /// away from the clouds and surfaces; `None` when off.
    pub clip: Option<glam::Vec4>,
    /// Whether the plane cuts the atoms and bonds too.
    pub clip_atoms: bool,
}

/// The frame's camera as one object sees it: every vector in the object's own frame, so a
/// placed object's passes draw its data as uploaded. Placements are rigid, so distances (and
/// the clouds' per-step opacity) are the same in both frames.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectView {
    pub clip_from_object: glam::Mat4,
    pub eye: glam::Vec3,
    /// Unit vector from the eye towards the camera's target.
    pub view_dir: glam::Vec3,
    /// Unit vector towards the light.
    pub light: glam::Vec3,
    /// The camera's up vector.
    pub up: glam::Vec3,
}

impl ObjectView {
    /// The camera (`clip_from_world`, `eye`, `view_dir`, `light`, `up` in world space) seen
    /// from an object placed at `world_from_object`.
    pub fn new(world: &ObjectView, world_from_object: glam::Mat4) -> Self {
        let object_from_world = world_from_object.inverse();
        Self {
            clip_from_object: world.clip_from_object * world_from_object,
            eye: object_from_world.transform_point3(world.eye),
            view_dir: object_from_world.transform_vector3(world.view_dir).normalize_or(glam::Vec3::NEG_Z),
            light: object_from_world.transform_vector3(world.light).normalize_or(glam::Vec3::Z),
            up: object_from_world.transform_vector3(world.up).normalize_or(glam::Vec3::Y),
        }
    }
}

/// What an id in the [`Target::Ids`] target names. Bits 30–31: the kind; 24–29: the object;
/// 0–23: the atom or surface within it (enough for 16 million atoms).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PickId {
    Atom { object: u32, index: u32 },
    Surface { object: u32, index: u32 },
}

const KIND_SHIFT: u32 = 30;
const OBJECT_SHIFT: u32 = 24;
const INDEX_MASK: u32 = (1 << OBJECT_SHIFT) - 1;

impl PickId {
    /// The high bits of every id of `kind` (1 atoms, 2 surfaces) in `object`; a shader adds the
    /// index.
    pub fn base(kind: u32, object: u32) -> u32 {
        kind << KIND_SHIFT | (object & 0x3f) << OBJECT_SHIFT
    }

    pub fn atom_base(object: u32) -> u32 {
        Self::base(1, object)
    }

    pub fn surface_base(object: u32) -> u32 {
        Self::base(2, object)
    }

    pub fn encode(self) -> u32 {
        match self {
            PickId::Atom { object, index } => Self::atom_base(object) | (index & INDEX_MASK),
            PickId::Surface { object, index } => Self::surface_base(object) | (index & INDEX_MASK),
        }
    }

    pub fn decode(raw: u32) -> Option<Self> {
        let (object, index) = ((raw >> OBJECT_SHIFT) & 0x3f, raw & INDEX_MASK);
        match raw >> KIND_SHIFT {
            1 => Some(PickId::Atom { object, index }),
            2 => Some(PickId::Surface { object, index }),
            _ => None,
        }
    }
}

/// The targets of one frame size; rebuilt when the size changes.
pub struct FrameTargets {
    pub size: [u32; 2],
    pub color: wgpu::Texture,
    pub color_view: wgpu::TextureView,
    pub depth: wgpu::Texture,
    pub depth_view: wgpu::TextureView,
    pub ids: wgpu::Texture,
    pub ids_view: wgpu::TextureView,
}

impl FrameTargets {
    pub fn new(device: &wgpu::Device, size: [u32; 2]) -> Self {
        let size = [size[0].max(1), size[1].max(1)];
        let texture = |label, format, usage| target_texture(device, label, size, format, usage);
        let read = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC;
        let color = texture("frame colour", SCENE_FORMAT, read);
        let depth = texture("frame depth", DEPTH_FORMAT, read);
        let ids = texture("frame ids", ID_FORMAT, wgpu::TextureUsages::COPY_SRC);
        Self {
            size,
            color_view: color.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            ids_view: ids.create_view(&Default::default()),
            color,
            depth,
            ids,
        }
    }

    /// Opens the render pass of a drawing phase (not [`Phase::Resolve`]) over these targets.
    pub fn begin<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        node: &PhaseNode,
        background: [f32; 3],
    ) -> wgpu::RenderPass<'e> {
        // The opaque phase starts the frame; every later one draws over it.
        let clear = node.phase == Phase::Opaque;
        let attachment = |view, clear_to: wgpu::Color| wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: if clear { wgpu::LoadOp::Clear(clear_to) } else { wgpu::LoadOp::Load },
                store: wgpu::StoreOp::Store,
            },
        };
        let [r, g, b] = background.map(f64::from);
        let mut colors = vec![Some(attachment(&self.color_view, wgpu::Color { r, g, b, a: 1.0 }))];
        if node.writes.contains(&Target::Ids) {
            colors.push(Some(attachment(&self.ids_view, wgpu::Color::TRANSPARENT)));
        }
        let depth_ops = node.writes.contains(&Target::Depth).then_some(wgpu::Operations {
            load: if clear { wgpu::LoadOp::Clear(1.0) } else { wgpu::LoadOp::Load },
            store: wgpu::StoreOp::Store,
        });
        // A phase that only reads depth opens it read-only; the fragment lists read it as a
        // texture instead.
        let depth = (node.phase != Phase::Fragments).then_some(wgpu::RenderPassDepthStencilAttachment {
            view: &self.depth_view,
            depth_ops,
            stencil_ops: None,
        });
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(node.label),
            color_attachments: &colors,
            depth_stencil_attachment: depth,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }
}

/// The colour targets of a pipeline drawing in [`Phase::Opaque`]: scene colour, then ids.
pub fn opaque_targets() -> [Option<wgpu::ColorTargetState>; 2] {
    [
        Some(wgpu::ColorTargetState { format: SCENE_FORMAT, blend: None, write_mask: wgpu::ColorWrites::ALL }),
        Some(wgpu::ColorTargetState { format: ID_FORMAT, blend: None, write_mask: wgpu::ColorWrites::ALL }),
    ]
}

/// The pipeline of a representation drawn in the opaque phase from a uniform block (binding 0)
/// and a read-only storage buffer (binding 1) alone, no vertex buffers (arrow impostors, the
/// plane's frame): `shader`'s `vs_main` and `fs_main`, both windings, into the opaque targets
/// with depth. Returns it with its bind group's layout.
pub fn opaque_storage_pipeline(
    device: &wgpu::Device,
    shader: &str,
    label: &str,
) -> (wgpu::RenderPipeline, wgpu::BindGroupLayout) {
    let module = super::shader_module(device, shader);
    let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(&format!("{label} bind group layout")),
        entries: &[
            super::uniform_entry(0, stages),
            super::buffer_entry(1, stages, wgpu::BufferBindingType::Storage { read_only: true }),
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(&format!("{label} pipeline layout")),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        // Both windings: an impostor's box or a line's quad is drawn whichever way it faces.
        primitive: wgpu::PrimitiveState::default(),
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
    });
    (pipeline, layout)
}

/// The bind group of an [`opaque_storage_pipeline`]: `uniforms` at binding 0 and a new storage
/// buffer of `contents` at binding 1.
pub fn opaque_storage_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    uniforms: &wgpu::Buffer,
    label: &str,
    contents: &[u8],
) -> wgpu::BindGroup {
    use wgpu::util::DeviceExt;
    let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE,
    });
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(&format!("{label} bind group")),
        layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: buffer.as_entire_binding() },
        ],
    })
}

/// Depth state of opaque geometry: tested and written.
pub fn opaque_depth() -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Less),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_standard_frame_reads_only_what_was_written() {
        assert!(is_ordered(STANDARD_FRAME));
        let mut reversed = STANDARD_FRAME.to_vec();
        reversed.reverse();
        assert!(!is_ordered(&reversed));
    }

    #[test]
    fn pick_ids_round_trip() {
        for id in [
            PickId::Atom { object: 0, index: 0 },
            PickId::Atom { object: 5, index: 999_999 },
            PickId::Surface { object: 63, index: 1 },
        ] {
            assert_eq!(PickId::decode(id.encode()), Some(id));
        }
        assert_eq!(PickId::decode(0), None);
    }
}
