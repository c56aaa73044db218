//! Atoms and bonds from GPU storage buffers (Kikuchi et al., docs/references.md): positions, packed attributes and bonds
//! are uploaded once; a colour change rewrites only the attributes, a style change only the
//! small radius table. Each frame a compute pass culls to the frustum and applies Lee et al.'s
//! screen-size level of detail: spheres of at most [`AtomsPass::splat_radius_px`] pixels are
//! rasterised in compute (exact per-pixel ray–sphere depth, nearest wins by an atomic maximum)
//! and resolved in one full-screen pass; bigger ones, and bonds thicker than a third of a
//! pixel, are appended to lists that instanced impostor quads draw (exact ray–sphere and
//! ray–cylinder intersection and depth).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};

use super::GpuContext;
use super::frame::{Draw, ObjectView, Phase, PickId, opaque_depth, opaque_targets};
use crate::model::{Molecule, units::BOHR_PER_ANGSTROM};
use crate::scene::transfer::NO_CUT;
use crate::scene::{AtomColors, AtomStyle};

/// Mirror of `Globals` in atoms_common.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct AtomGlobals {
    pub clip_from_world: [[f32; 4]; 4],
    pub eye: [f32; 4],
    pub light: [f32; 4],
    pub up: [f32; 4],
    /// x: the high bits of this object's atom pick ids ([`PickId::atom_base`]); y: 1 when the
    /// splat pixels are packed 64-bit words ([`SplatWords`]); z: 1 to walk each cell's atoms
    /// backwards ([`Cells::walk`]).
    pub pick: [u32; 4],
    /// Viewport width and height (px), pixels per bohr at unit clip w, the splat threshold (px).
    pub viewport: [f32; 4],
    pub ray_f0: [f32; 4],
    pub ray_fx: [f32; 4],
    pub ray_fy: [f32; 4],
    /// Atoms, bonds, style flags, invocations per dispatch row.
    pub counts: [u32; 4],
    /// x: stick radius; y: the largest atom radius drawn (bohr).
    pub sticks: [f32; 4],
    /// Cells to rasterise this frame, where their order starts in the lists, where the atom
    /// indices start in the cell data, this frame's number.
    pub cells: [u32; 4],
    /// Where the cell lists start: seen last frame, left for the occlusion test (later those
    /// that write ids), left and not hidden, and the frame each cell was last seen in.
    pub cell_lists: [u32; 4],
    /// Depth cueing: the nearest and farthest clip w of the molecule's box, and the strength.
    pub cue: [f32; 4],
    /// Clip z and w of the eye and of the view direction (the shader's depth without a matrix).
    pub clip_zw: [f32; 4],
    /// Clip z and w of the pixel rays' parts: ray_f0 − eye and ray_fx, then ray_fy.
    pub ray_zw: [f32; 4],
    pub ray_zw_y: [f32; 4],
    /// The object's clipping plane when it cuts atoms (unit n, d; points with n·p > d are cut
    /// away), else [`NO_CUT`].
    pub cut: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<AtomGlobals>() == 336);

/// Ball radius as a fraction of the van der Waals radius in ball-and-stick.
const BALL_FRACTION: f32 = 0.24;
/// Stick radius in ball-and-stick and sticks, ångström.
const STICK_RADIUS_ANG: f32 = 0.13;
/// Stick (and cap) radius of licorice, ångström.
const LICORICE_RADIUS_ANG: f32 = 0.3;
/// Radius of an unbonded atom (an ion, a water oxygen) in the lines style, ångström.
const LINES_BALL_ANG: f32 = 0.25;

const FLAG_GHOST: u32 = 1;
const FLAG_HIDDEN: u32 = 2;
const FLAG_BONDED: u32 = 4;
const STYLE_CYLINDERS: u32 = 1;
const STYLE_UNBONDED_ONLY: u32 = 2;
/// Radii per atomic number come first in the looks buffer, then the palette.
const PALETTE_AT: usize = 128;
/// u32s before the lists: the sphere and the bond indirect draw arguments, then the counts of
/// the cell lists (FIRST, LEFT, REST, IDS in atoms_cull.wgsl) from [`CELL_COUNTS_AT`].
const LIST_HEADER: usize = 12;
const CELL_COUNTS_AT: usize = 8;
/// Words per cell in the lists: this frame's order, three cell lists and the frame it was seen.
const LIST_WORDS_PER_CELL: usize = 5;
/// The cell lists' indirect dispatches (x, y, z, unused), reset every frame: seen last frame,
/// left and not hidden, shown.
const DISPATCH_ARGS: [u32; 12] = [0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0];
/// Coarse depth: pixels per tile side and tiles per block side (atoms_cull.wgsl).
const DEPTH_TILE: u32 = 8;
const DEPTH_BLOCK: u32 = 8;

/// Tiles and blocks of the coarse depth across a frame of `size` pixels.
fn coarse_depth_dims(size: [u32; 2]) -> ([u32; 2], [u32; 2]) {
    let tiles = size.map(|v| v.div_ceil(DEPTH_TILE));
    (tiles, tiles.map(|v| v.div_ceil(DEPTH_BLOCK)))
}
const WORKGROUP: u32 = 64;
/// Bytes a splat buffer takes per pixel: a depth key and an atom id.
const SPLAT_BYTES_PER_PIXEL: u64 = 8;

/// Atoms a spatial cell holds on average; a cell is culled, ordered nearest first and
/// rasterised by one workgroup. Measured on lavapipe (10⁶ atoms, 800×600): with every cell in
/// view dispatched, 256 was fastest (48 spent more on launching workgroups); once hidden cells
/// cost no workgroup (two-phase occlusion culling), 64 was (32 and 128 slower).
const CELL_ATOMS: f32 = 64.0;
/// The largest atom radius any style draws (bohr), padding cells' bounds for the CPU's frustum
/// culling (the GPU's occlusion tests pad by the largest radius drawn).
const MAX_ATOM_RADIUS: f32 = 5.0;
/// Header words per cell in `cell_data`.
const CELL_WORDS: usize = 6;

/// Atoms binned into cubic cells: the GPU's `cell_data` ([`CELL_WORDS`] per cell: first,
/// count and the sphere around its atom centres, centre and radius as f32 bits; then the atom
/// indices cell by cell, three times: each cell's sorted along x, y and z) and each cell's
/// sphere (centre, radius) for the CPU, which culls and orders cells every frame. The atoms' own
/// radius pads these spheres as the style asks.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Cells {
    pub data: Vec<u32>,
    pub spheres: Vec<[f32; 4]>,
    atoms: usize,
}

impl Cells {
    pub fn new(positions: &[[f32; 4]]) -> Self {
        let n = positions.len();
        if n == 0 {
            return Self::default();
        }
        let p = |i: usize| Vec3::new(positions[i][0], positions[i][1], positions[i][2]);
        let (lo, hi) = (0..n).fold((p(0), p(0)), |(lo, hi), i| (lo.min(p(i)), hi.max(p(i))));
        let extent = (hi - lo).max(Vec3::splat(1.0));
        let mut edge = (extent.x * extent.y * extent.z / n as f32 * CELL_ATOMS).cbrt().max(2.0);
        let dims = |edge: f32| (extent / edge).floor().as_uvec3() + 1;
        // At most a few cells per atom however the atoms spread.
        while dims(edge).as_u64vec3().element_product() > 4 * n as u64 + 8 {
            edge *= 1.26;
        }
        let d = dims(edge);
        let cell_of = |i: usize| {
            let c = ((p(i) - lo) / edge).floor().as_uvec3().min(d - 1);
            (c.x + d.x * (c.y + d.y * c.z)) as usize
        };
        let total = (d.x * d.y * d.z) as usize;
        let mut start = vec![0u32; total + 1];
        let cell: Vec<usize> = (0..n).map(cell_of).collect();
        for &c in &cell {
            start[c + 1] += 1;
        }
        for c in 0..total {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut atoms = vec![0u32; n];
        for (i, &c) in cell.iter().enumerate() {
            atoms[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        let mut data = Vec::new();
        let mut spheres = Vec::new();
        for c in 0..total {
            let count = start[c + 1] - start[c];
            if count > 0 {
                // The sphere around the box of the cell's atom centres: tighter than the cell's
                // for a cell the molecule's edge cuts.
                let members = &atoms[start[c] as usize..start[c + 1] as usize];
                let first = p(members[0] as usize);
                let (a, b) =
                    members.iter().fold((first, first), |(a, b), &i| (a.min(p(i as usize)), b.max(p(i as usize))));
                let sphere = (0.5 * (a + b)).extend(0.5 * (b - a).length()).to_array();
                data.extend([start[c], count]);
                data.extend(sphere.map(f32::to_bits));
                spheres.push(sphere);
            }
        }
        // Each cell's atoms sorted along x, along y and along z: a frame walks them in the order
        // of the axis nearest its view direction, nearer atoms first, so the ones behind find
        // their pixels already taken.
        for axis in 0..3 {
            let mut sorted = atoms.clone();
            for c in 0..total {
                let run = &mut sorted[start[c] as usize..start[c + 1] as usize];
                run.sort_unstable_by(|&i, &j| p(i as usize)[axis].total_cmp(&p(j as usize)[axis]));
            }
            data.extend(sorted);
        }
        Self { data, spheres, atoms: n }
    }

    /// Where the atom indices sorted along the axis nearest `view_dir` start in `data`, and
    /// whether to walk them backwards (nearest first either way).
    pub fn walk(&self, view_dir: Vec3) -> (u32, bool) {
        let a = view_dir.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        ((CELL_WORDS * self.len() + axis * self.atoms) as u32, view_dir[axis] < 0.0)
    }

    pub fn len(&self) -> usize {
        self.spheres.len()
    }

    pub fn is_empty(&self) -> bool {
        self.spheres.is_empty()
    }

    /// The cells any part of which the frustum of `clip_from_object` holds, nearest to `eye`
    /// (along `view_dir`) first.
    pub fn visible_order(&self, clip_from_object: Mat4, eye: Vec3, view_dir: Vec3) -> Vec<u32> {
        let r = |k: usize| clip_from_object.row(k);
        // Gribb–Hartmann planes for 0..1 depth: left, right, bottom, top, near, far.
        let planes = [r(3) + r(0), r(3) - r(0), r(3) + r(1), r(3) - r(1), r(2), r(3) - r(2)]
            .map(|p| p / p.truncate().length().max(1e-20));
        let mut visible: Vec<(f32, u32)> = self
            .spheres
            .iter()
            .enumerate()
            .filter(|(_, s)| {
                let c = Vec4::new(s[0], s[1], s[2], 1.0);
                planes.iter().all(|p| p.dot(c) >= -(s[3] + MAX_ATOM_RADIUS))
            })
            .map(|(k, s)| ((Vec3::new(s[0], s[1], s[2]) - eye).dot(view_dir), k as u32))
            .collect();
        visible.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        visible.into_iter().map(|(_, k)| k).collect()
    }
}

/// Cells of atoms in one frame: all, in the frustum, drawn first (seen the frame before),
/// tested against the coarse depth of those, drawn after that test, and the cells that may
/// show in the finished frame (they write ids and are drawn first next frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CellCounts {
    pub total: u32,
    pub in_view: u32,
    pub first: u32,
    pub tested: u32,
    pub rest: u32,
    pub shown: u32,
}

/// What the GPU holds per atom and bond, as plain arrays (testable without a GPU).
#[derive(Debug, Clone, PartialEq)]
pub struct AtomData {
    /// xyz bohr, w unused (16-byte loads).
    pub positions: Vec<[f32; 4]>,
    /// Bits 0–7 atomic number, 8–15 flags, 16–31 palette index.
    pub attrs: Vec<u32>,
    pub bonds: Vec<[u32; 2]>,
    pub cells: Cells,
}

impl AtomData {
    pub fn new(molecule: &Molecule, colors: &AtomColors) -> Self {
        let mut bonded = vec![false; molecule.atoms.len()];
        for b in &molecule.bonds {
            bonded[b.a as usize] = true;
            bonded[b.b as usize] = true;
        }
        let attrs = molecule
            .atoms
            .iter()
            .enumerate()
            .map(|(i, a)| {
                let hidden = colors.shown.get(i).is_some_and(|&shown| !shown);
                let flags = if a.ghost { FLAG_GHOST } else { 0 }
                    | if bonded[i] { FLAG_BONDED } else { 0 }
                    | if hidden { FLAG_HIDDEN } else { 0 };
                let color = colors.index.get(i).copied().unwrap_or(0) as u32;
                a.z.min(127) | flags << 8 | color << 16
            })
            .collect();
        let positions = positions_of(molecule);
        Self {
            cells: Cells::new(&positions),
            positions,
            attrs,
            bonds: molecule.bonds.iter().map(|b| [b.a, b.b]).collect(),
        }
    }

    /// Bytes on the GPU: positions, attributes, list slots, cells, bonds with their slots.
    pub fn gpu_bytes(&self) -> usize {
        self.positions.len() * (16 + 4 + 4)
            + self.cells.data.len() * 4
            + self.cells.len() * 4
            + self.bonds.len() * (8 + 4)
    }
}

/// Each atom's position as the shaders read it: xyz bohr, w unused.
fn positions_of(molecule: &Molecule) -> Vec<[f32; 4]> {
    molecule.atoms.iter().map(|a| a.position.as_vec3().extend(0.0).to_array()).collect()
}

/// The style's radius per atomic number (bohr, times `sizes.ball`), then the palette (linear RGB).
pub fn looks(style: AtomStyle, sizes: AtomSizes, colors: &AtomColors) -> Vec<[f32; 4]> {
    // Never past the cells' padding for the frustum culling.
    let radii = (0..PALETTE_AT).map(|z| [(radius(style, z as u32) * sizes.ball).min(MAX_ATOM_RADIUS), 0.0, 0.0, 0.0]);
    radii.chain(colors.palette.iter().map(|&c| linear_color(c))).collect()
}

/// The radius (bohr) an atom of atomic number `z` is drawn with in `style`.
fn radius(style: AtomStyle, z: u32) -> f32 {
    let e = crate::model::elements::element(z);
    let r = match style {
        AtomStyle::BallAndStick => e.vdw_radius * BALL_FRACTION,
        AtomStyle::SpaceFilling => e.vdw_radius,
        AtomStyle::Sticks => STICK_RADIUS_ANG,
        AtomStyle::Licorice => LICORICE_RADIUS_ANG,
        AtomStyle::Lines => LINES_BALL_ANG,
        AtomStyle::Hidden => 0.0,
    };
    r * BOHR_PER_ANGSTROM as f32
}

/// Stick radius (bohr) and style flags.
fn style_flags(style: AtomStyle) -> (f32, u32) {
    let bohr = BOHR_PER_ANGSTROM as f32;
    match style {
        AtomStyle::BallAndStick | AtomStyle::Sticks => (STICK_RADIUS_ANG * bohr, STYLE_CYLINDERS),
        AtomStyle::Licorice => (LICORICE_RADIUS_ANG * bohr, STYLE_CYLINDERS),
        AtomStyle::Lines => (0.0, STYLE_UNBONDED_ONLY),
        AtomStyle::SpaceFilling | AtomStyle::Hidden => (0.0, 0),
    }
}

pub(crate) fn linear_color(srgb: [u8; 3]) -> [f32; 4] {
    let [r, g, b] = crate::scene::coloring::linear(srgb);
    [r, g, b, 1.0]
}

/// Workgroups for `n` invocations, as (x, y) within the per-dimension limit, and the
/// invocations per row the shader indexes with.
fn dispatch(n: u32) -> ([u32; 2], u32) {
    let groups = n.div_ceil(WORKGROUP).max(1);
    let x = groups.min(65_535);
    ([x, groups.div_ceil(x)], x * WORKGROUP)
}

/// The buffers of one uploaded molecule.
struct Uploaded {
    positions: wgpu::Buffer,
    attrs: wgpu::Buffer,
    looks: wgpu::Buffer,
    bonds: wgpu::Buffer,
    /// Indirect draw arguments, cell list counts, the sphere list, the bond list, this frame's
    /// cell order, the cell lists and the frame each cell was last seen in.
    lists: wgpu::Buffer,
    /// Indirect dispatches of the cell lists ([`DISPATCH_ARGS`]) and their bind group.
    args: wgpu::Buffer,
    args_group: wgpu::BindGroup,
    cell_data: wgpu::Buffer,
    cells: Cells,
    /// Cells in this frame's view, nearest first (how many the compute passes walk).
    visible_cells: u32,
    /// Whether a sphere in view may project bigger than the rasteriser draws.
    big_spheres: bool,
    atoms: u32,
    bond_count: u32,
    /// CPU copy of the attributes: a recolouring changes their palette bits only.
    attr_words: Vec<u32>,
    /// The atoms' box (bohr).
    bounds: [Vec3; 2],
    /// The atomic numbers present: the largest radius drawn pads the cells' spheres.
    elements: Vec<u32>,
    group: wgpu::BindGroup,
}

pub struct AtomsPass {
    shared: std::sync::Arc<Pipelines>,
    globals: wgpu::Buffer,
    data: Option<Uploaded>,
    style: AtomStyle,
    /// Depth keys then atom ids, one of each per pixel; sized to the last frame.
    splat: Option<(wgpu::Buffer, [u32; 2])>,
    /// Bind groups of the lists and the splat buffer (compute: writable; render: read-only).
    frame_groups: Option<(wgpu::BindGroup, wgpu::BindGroup)>,
    /// Spheres up to this projected radius (pixels) are drawn by the compute rasteriser.
    pub splat_radius_px: f32,
    /// Frames prepared since the molecule was uploaded: cells seen in the last one are drawn
    /// first.
    frame: u32,
    /// How much the farthest atoms darken (0: none), QuteMol's depth cue: it tells front from
    /// back in a big structure.
    pub depth_cue: f32,
    /// Factors on the style's ball and stick radii (1: as the style draws them), taken by the
    /// next [`Self::set_molecule`] or [`Self::set_look`].
    pub sizes: AtomSizes,
}

/// Factors on a style's ball and stick radii.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AtomSizes {
    pub ball: f32,
    pub stick: f32,
}

impl Default for AtomSizes {
    fn default() -> Self {
        Self { ball: 1.0, stick: 1.0 }
    }
}

struct Pipelines {
    data_layout: wgpu::BindGroupLayout,
    compute_layout: wgpu::BindGroupLayout,
    args_layout: wgpu::BindGroupLayout,
    render_layout: wgpu::BindGroupLayout,
    split: wgpu::ComputePipeline,
    /// Rasterising the cells seen last frame, then the rest the coarse depth does not hide;
    /// each without and with the code for spheres too big to rasterise.
    atoms_first: [wgpu::ComputePipeline; 2],
    atoms_rest: [wgpu::ComputePipeline; 2],
    depth_tiles: wgpu::ComputePipeline,
    depth_blocks: wgpu::ComputePipeline,
    cull_left: wgpu::ComputePipeline,
    cull_shown: wgpu::ComputePipeline,
    /// The second pass that writes ids ([`SplatWords::Pair`] only).
    splat_ids: Option<wgpu::ComputePipeline>,
    words: SplatWords,
    cull_bonds: wgpu::ComputePipeline,
    spheres: wgpu::RenderPipeline,
    splats: wgpu::RenderPipeline,
    cylinders: wgpu::RenderPipeline,
    lines: wgpu::RenderPipeline,
}

/// Default splat threshold: measured on lavapipe, see docs/performance.md (`orbcloud bench spheres`).
pub const SPLAT_RADIUS_PX: f32 = 8.0;

/// How the compute rasteriser keeps a pixel's nearest depth and atom id.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplatWords {
    /// Two 32-bit words and a second pass for the ids: any device.
    Pair,
    /// One 64-bit word, depth above id, one atomic maximum: devices with 64-bit atomics.
    Packed,
}

impl SplatWords {
    /// The faster one the device can run.
    pub fn best(device: &wgpu::Device) -> Self {
        if device.features().contains(super::context::INT64_ATOMICS) { Self::Packed } else { Self::Pair }
    }
}

impl Pipelines {
    fn new(ctx: &GpuContext, words: SplatWords) -> Self {
        use wgpu::BufferBindingType::{Storage, Uniform};
        use wgpu::ShaderStages as S;
        let device = &ctx.device;
        let entry = super::buffer_entry;
        let all = S::VERTEX_FRAGMENT | S::COMPUTE;
        let read = Storage { read_only: true };
        let data_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("atoms data layout"),
            entries: &[
                entry(0, all, Uniform),
                entry(1, all, read),
                entry(2, all, read),
                entry(3, all, read),
                entry(4, all, read),
                entry(5, all, read),
            ],
        });
        let compute_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("atoms compute layout"),
            entries: &[
                entry(0, S::COMPUTE, Storage { read_only: false }),
                entry(1, S::COMPUTE, Storage { read_only: false }),
            ],
        });
        let args_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("atoms dispatch layout"),
            entries: &[entry(0, S::COMPUTE, Storage { read_only: false })],
        });
        let render_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("atoms render layout"),
            entries: &[entry(0, S::VERTEX, read), entry(1, S::FRAGMENT, read)],
        });
        let layout = |more: &[Option<&wgpu::BindGroupLayout>]| {
            let groups: Vec<_> = std::iter::once(Some(&data_layout)).chain(more.iter().copied()).collect();
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("atoms pipeline layout"),
                bind_group_layouts: &groups,
                immediate_size: 0,
            })
        };
        let compute_pl = layout(&[Some(&compute_layout)]);
        let listing_pl = layout(&[Some(&compute_layout), Some(&args_layout)]);
        let render_pl = layout(&[Some(&render_layout)]);
        let cull = super::shader_module(
            device,
            if words == SplatWords::Packed { "atoms_splat_packed.wgsl" } else { "atoms_splat_pair.wgsl" },
        );
        let pipeline = |entry: &str, big: bool, layout: &wgpu::PipelineLayout| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(layout),
                module: &cull,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &[("BIG_SPHERES", if big { 1.0 } else { 0.0 })],
                    ..Default::default()
                },
                cache: None,
            })
        };
        let compute = |entry: &str, big: bool| pipeline(entry, big, &compute_pl);
        let listing = |entry: &str| pipeline(entry, false, &listing_pl);
        let module = super::shader_module(device, "atoms.wgsl");
        let render = |label: &str, vs: &str, fs: &str, topology| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&render_pl),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState { topology, cull_mode: None, ..Default::default() },
                depth_stencil: Some(opaque_depth()),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &opaque_targets(),
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        use wgpu::PrimitiveTopology::{LineList, TriangleList};
        Self {
            split: listing("cs_split"),
            atoms_first: [compute("cs_atoms_first", false), compute("cs_atoms_first", true)],
            atoms_rest: [compute("cs_atoms_rest", false), compute("cs_atoms_rest", true)],
            depth_tiles: compute("cs_depth_tiles", false),
            depth_blocks: compute("cs_depth_blocks", false),
            cull_left: listing("cs_cull_left"),
            cull_shown: listing("cs_cull_shown"),
            splat_ids: (words == SplatWords::Pair).then(|| compute("cs_splat_ids", false)),
            words,
            cull_bonds: compute("cs_bonds", false),
            spheres: render("sphere impostors", "vs_sphere", "fs_sphere", TriangleList),
            splats: render("sphere splats", "vs_fullscreen", "fs_splats", TriangleList),
            cylinders: render("cylinder impostors", "vs_cylinder", "fs_cylinder", TriangleList),
            lines: render("bond lines", "vs_line", "fs_line", LineList),
            data_layout,
            compute_layout,
            args_layout,
            render_layout,
        }
    }
}

fn storage(ctx: &GpuContext, label: &str, bytes: &[u8], extra: wgpu::BufferUsages) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    // A binding may not be empty.
    let zeros = [0u8; 16];
    let contents = if bytes.is_empty() { &zeros[..] } else { bytes };
    ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | extra,
    })
}

impl AtomsPass {
    pub fn new(ctx: &GpuContext) -> Self {
        Self::with_words(ctx, SplatWords::best(&ctx.device))
    }

    /// Atoms rasterised with `words` (the device must have 64-bit atomics for `Packed`).
    pub fn with_words(ctx: &GpuContext, words: SplatWords) -> Self {
        Self::with(ctx, std::sync::Arc::new(Pipelines::new(ctx, words)))
    }

    fn with(ctx: &GpuContext, shared: std::sync::Arc<Pipelines>) -> Self {
        Self {
            shared,
            globals: super::uniform_buffer(&ctx.device, "atoms globals", std::mem::size_of::<AtomGlobals>()),
            data: None,
            style: AtomStyle::Hidden,
            splat: None,
            frame_groups: None,
            splat_radius_px: SPLAT_RADIUS_PX,
            frame: 0,
            depth_cue: 0.0,
            sizes: AtomSizes::default(),
        }
    }

    /// Another set of atoms drawn with this one's pipelines.
    pub fn instance(&self, ctx: &GpuContext) -> Self {
        Self::with(ctx, self.shared.clone())
    }

    /// Uploads a molecule in a style and colours (element colours when `colors` is `None`).
    pub fn set_molecule(
        &mut self,
        ctx: &GpuContext,
        molecule: &Molecule,
        style: AtomStyle,
        colors: Option<&AtomColors>,
    ) {
        let element;
        let colors = match colors.filter(|c| c.index.len() == molecule.atoms.len()) {
            Some(c) => c,
            None => {
                element = crate::scene::coloring::atom_colors(molecule, None, crate::scene::AtomColoring::Element);
                &element
            }
        };
        let data = AtomData::new(molecule, colors);
        let usage = wgpu::BufferUsages::empty();
        let positions = storage(ctx, "atom positions", bytemuck::cast_slice(&data.positions), usage);
        let attrs = storage(ctx, "atom attributes", bytemuck::cast_slice(&data.attrs), usage);
        let looks = storage(ctx, "atom looks", bytemuck::cast_slice(&looks(style, self.sizes, colors)), usage);
        let bonds = storage(ctx, "bonds", bytemuck::cast_slice(&data.bonds), usage);
        let list_words = LIST_HEADER + data.positions.len() + data.bonds.len() + LIST_WORDS_PER_CELL * data.cells.len();
        let lists = storage(
            ctx,
            "atom lists",
            &vec![0u8; list_words * 4],
            wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_SRC,
        );
        let args =
            storage(ctx, "atom cell dispatches", bytemuck::cast_slice(&DISPATCH_ARGS), wgpu::BufferUsages::INDIRECT);
        let args_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("atom cell dispatches"),
            layout: &self.shared.args_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: args.as_entire_binding() }],
        });
        let cell_data = storage(ctx, "atom cells", bytemuck::cast_slice(&data.cells.data), usage);
        let group =
            Self::data_group(ctx, &self.shared, &self.globals, [&positions, &attrs, &looks, &bonds, &cell_data]);
        self.style = style;
        self.frame_groups = None;
        self.frame = 0;
        self.data = Some(Uploaded {
            positions,
            attrs,
            looks,
            bonds,
            lists,
            args,
            args_group,
            cell_data,
            cells: data.cells,
            visible_cells: 0,
            big_spheres: true,
            atoms: data.positions.len() as u32,
            bond_count: data.bonds.len() as u32,
            elements: {
                let mut z: Vec<u32> = molecule.atoms.iter().map(|a| a.z).collect();
                z.sort_unstable();
                z.dedup();
                z
            },
            bounds: molecule.bounds().map_or([Vec3::ZERO; 2], |(lo, hi)| [lo.as_vec3(), hi.as_vec3()]),
            attr_words: data.attrs,
            group,
        });
    }

    /// Moves the uploaded atoms to `molecule`'s positions (the same atoms and bonds, as a
    /// vibration or a scan moves them), writing the positions and the culling cells in place;
    /// false, leaving everything as it was, when the atoms, the bonds or the cells' layout differ
    /// (then [`Self::set_molecule`] uploads anew). A frame of an animation thus makes no new
    /// buffers or bind groups.
    pub fn move_atoms(&mut self, ctx: &GpuContext, molecule: &Molecule) -> bool {
        let Some(d) = &mut self.data else { return false };
        let same_bonds = d.bond_count as usize == molecule.bonds.len();
        if d.atoms as usize != molecule.atoms.len() || !same_bonds {
            return false;
        }
        let positions = positions_of(molecule);
        let cells = Cells::new(&positions);
        if cells.data.len() != d.cells.data.len() || cells.len() != d.cells.len() {
            return false;
        }
        ctx.queue.write_buffer(&d.positions, 0, bytemuck::cast_slice(&positions));
        if !cells.data.is_empty() {
            ctx.queue.write_buffer(&d.cell_data, 0, bytemuck::cast_slice(&cells.data));
        }
        d.cells = cells;
        d.bounds = molecule.bounds().map_or([Vec3::ZERO; 2], |(lo, hi)| [lo.as_vec3(), hi.as_vec3()]);
        true
    }

    /// Restyles, recolours and reselects: rewrites the attributes' palette and hidden bits and
    /// the small radius and palette table; positions and bonds stay as uploaded.
    pub fn set_look(&mut self, ctx: &GpuContext, style: AtomStyle, colors: &AtomColors) {
        self.style = style;
        let Some(d) = &mut self.data else { return };
        if colors.index.len() != d.attr_words.len() {
            return;
        }
        for (i, (w, &c)) in d.attr_words.iter_mut().zip(&colors.index).enumerate() {
            let hidden = colors.shown.get(i).is_some_and(|&shown| !shown);
            *w = (*w & 0xffff & !(FLAG_HIDDEN << 8)) | if hidden { FLAG_HIDDEN << 8 } else { 0 } | (c as u32) << 16;
        }
        ctx.queue.write_buffer(&d.attrs, 0, bytemuck::cast_slice(&d.attr_words));
        self.write_looks(ctx, style, colors);
    }

    /// The bind group of the globals and the per-atom buffers (positions, attributes, looks,
    /// bonds, cells), in binding order.
    fn data_group(
        ctx: &GpuContext,
        shared: &Pipelines,
        globals: &wgpu::Buffer,
        buffers: [&wgpu::Buffer; 5],
    ) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry> = std::iter::once(globals)
            .chain(buffers)
            .enumerate()
            .map(|(binding, b)| wgpu::BindGroupEntry { binding: binding as u32, resource: b.as_entire_binding() })
            .collect();
        ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("atoms data"),
            layout: &shared.data_layout,
            entries: &entries,
        })
    }

    fn write_looks(&mut self, ctx: &GpuContext, style: AtomStyle, colors: &AtomColors) {
        let Some(d) = &mut self.data else { return };
        let bytes: Vec<u8> = bytemuck::cast_slice(&looks(style, self.sizes, colors)).to_vec();
        if bytes.len() as u64 > d.looks.size() {
            // A bigger palette: a new buffer, and the bind group that names it.
            let looks = storage(ctx, "atom looks", &bytes, wgpu::BufferUsages::empty());
            let buffers = [&d.positions, &d.attrs, &looks, &d.bonds, &d.cell_data];
            d.group = Self::data_group(ctx, &self.shared, &self.globals, buffers);
            d.looks = looks;
        } else {
            ctx.queue.write_buffer(&d.looks, 0, &bytes);
        }
    }

    /// How the last frame's occlusion culling went (read back from the GPU: for benchmarks and
    /// tests).
    pub fn cell_counts(&self, ctx: &GpuContext) -> Result<CellCounts, super::GpuError> {
        let Some(d) = self.drawn() else { return Ok(CellCounts::default()) };
        let words = super::readback::read_buffer(&ctx.device, &ctx.queue, &d.lists, LIST_HEADER as u64 * 4)?;
        let w: &[u32] = bytemuck::cast_slice(&words);
        let [first, tested, rest, shown] = std::array::from_fn(|k| w[CELL_COUNTS_AT + k]);
        Ok(CellCounts { total: d.cells.len() as u32, in_view: d.visible_cells, first, tested, rest, shown })
    }

    /// The depth cue's globals: the clip w where darkening starts (the molecule box's nearest
    /// corner) and where it is full (halfway from the box's centre to its farthest corner: what
    /// shows of a dense structure lies in front of its centre), and the strength.
    fn cue(&self, clip: Mat4) -> [f32; 4] {
        let Some(d) = self.data.as_ref().filter(|_| self.depth_cue > 0.0) else { return [0.0; 4] };
        let [lo, hi] = d.bounds;
        let w = |p: Vec3| (clip * p.extend(1.0)).w;
        let (near, far) = (0..8).fold((f32::INFINITY, f32::NEG_INFINITY), |(near, far), k| {
            let corner = Vec3::select(glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), hi, lo);
            (near.min(w(corner)), far.max(w(corner)))
        });
        let full = 0.5 * (w(0.5 * (lo + hi)) + far);
        [near.max(0.0), full, self.depth_cue.clamp(0.0, 1.0), 0.0]
    }

    /// Bytes of GPU memory the uploaded atoms take (not counting the per-pixel splat buffer).
    pub fn gpu_bytes(&self) -> u64 {
        self.data.as_ref().map_or(0, |d| {
            d.positions.size() + d.attrs.size() + d.looks.size() + d.bonds.size() + d.lists.size() + d.cell_data.size()
        })
    }

    fn drawn(&self) -> Option<&Uploaded> {
        self.data.as_ref().filter(|d| d.atoms > 0 && self.style != AtomStyle::Hidden)
    }

    /// This frame's camera, in the frame of the object the atoms belong to; their pick ids name
    /// `object`. `size` is the frame's in pixels; `cut`: the clipping plane when it cuts atoms
    /// (a sphere or bond crossing it shows its cut face).
    pub fn set_view(&mut self, ctx: &GpuContext, view: &ObjectView, object: u32, size: [u32; 2], cut: Option<Vec4>) {
        let clip = view.clip_from_object;
        let world_from_clip = clip.inverse();
        let far = |x: f32, y: f32| {
            let p = world_from_clip * Vec4::new(x, y, 1.0, 1.0);
            p.truncate() / p.w
        };
        let f0 = far(0.0, 0.0);
        let (fx, fy) = (far(1.0, 0.0) - f0, far(0.0, 1.0) - f0);
        // Clip z and w of points and directions: the shader's per-pixel depth is linear in them.
        let zw = |v: Vec4| {
            let c = clip * v;
            glam::Vec2::new(c.z, c.w)
        };
        let eye_zw = zw(view.eye.extend(1.0));
        let view_zw = zw((f0 - view.eye).normalize_or_zero().extend(0.0));
        let ray0 = zw((f0 - view.eye).extend(0.0));
        let ray_x = zw(fx.extend(0.0));
        let ray_y = zw(fy.extend(0.0));
        let (atoms, bonds) = self.data.as_ref().map_or((0, 0), |d| (d.atoms, d.bond_count));
        // Cells in view, nearest first: the compute passes walk them in this order.
        let order = match &self.data {
            Some(d) if self.style != AtomStyle::Hidden => d.cells.visible_order(clip, view.eye, view.view_dir),
            _ => Vec::new(),
        };
        let order_at = LIST_HEADER as u32 + atoms + bonds;
        let total_cells = self.data.as_ref().map_or(0, |d| d.cells.len() as u32);
        let (cells_at, backwards) = self.data.as_ref().map_or((0, false), |d| d.cells.walk(view.view_dir));
        let cell_lists = [1, 2, 3, 4].map(|k| order_at + k * total_cells);
        self.frame += 1;
        let (stick, style) = style_flags(self.style);
        let stick = stick * self.sizes.stick;
        let ball = self.sizes.ball;
        let largest = self.data.as_ref().map_or(0.0, |d| {
            d.elements.iter().map(|&z| (radius(self.style, z) * ball).min(MAX_ATOM_RADIUS)).fold(0.0, f32::max)
        });
        let size = size.map(|v| v.max(1));
        let pixels_per_bohr = clip.row(1).truncate().length() * 0.5 * size[1] as f32;
        let g = AtomGlobals {
            clip_from_world: clip.to_cols_array_2d(),
            eye: view.eye.extend(1.0).to_array(),
            light: view.light.extend(0.0).to_array(),
            up: view.up.extend(0.0).to_array(),
            pick: [PickId::atom_base(object), (self.shared.words == SplatWords::Packed) as u32, backwards as u32, 0],
            viewport: [size[0] as f32, size[1] as f32, pixels_per_bohr, self.splat_radius_px],
            ray_f0: f0.extend(0.0).to_array(),
            ray_fx: fx.extend(0.0).to_array(),
            ray_fy: fy.extend(0.0).to_array(),
            counts: [atoms, bonds, style, dispatch(bonds).1],
            sticks: [stick, largest, 0.0, 0.0],
            cells: [order.len() as u32, order_at, cells_at, self.frame],
            cell_lists,
            cue: self.cue(clip),
            clip_zw: [eye_zw.x, eye_zw.y, view_zw.x, view_zw.y],
            ray_zw: [ray0.x, ray0.y, ray_x.x, ray_x.y],
            ray_zw_y: [ray_y.x, ray_y.y, 0.0, 0.0],
            cut: cut.unwrap_or(NO_CUT).to_array(),
        };
        ctx.queue.write_buffer(&self.globals, 0, bytemuck::bytes_of(&g));
        let Some(d) = &mut self.data else { return };
        // Quads: six vertices per sphere and per bond; instance counts filled by the culling,
        // as are the cell lists' counts and dispatches.
        let header: [u32; LIST_HEADER] = [6, 0, 0, 0, 6, 0, 0, 0, 0, 0, 0, 0];
        ctx.queue.write_buffer(&d.lists, 0, bytemuck::cast_slice(&header));
        ctx.queue.write_buffer(&d.args, 0, bytemuck::cast_slice(&DISPATCH_ARGS));
        if !order.is_empty() {
            ctx.queue.write_buffer(&d.lists, order_at as u64 * 4, bytemuck::cast_slice(&order));
        }
        d.visible_cells = order.len() as u32;
        // The nearest cell bounds how big any sphere projects.
        d.big_spheres = order.first().is_none_or(|&c| {
            let s = d.cells.spheres[c as usize];
            let w = (clip * Vec4::new(s[0], s[1], s[2], 1.0)).w - s[3] - largest;
            w <= 0.0 || largest * pixels_per_bohr / w > self.splat_radius_px
        });
        let d = &*d;
        if self.splat.as_ref().is_none_or(|(_, s)| *s != size) {
            let (tiles, blocks) = coarse_depth_dims(size);
            // A word per coarse depth, 64-bit when the pixels are.
            let coarse = (tiles[0] * tiles[1] + blocks[0] * blocks[1]) as u64 * 8;
            let bytes = size[0] as u64 * size[1] as u64 * SPLAT_BYTES_PER_PIXEL + coarse;
            let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sphere splats"),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            self.splat = Some((buffer, size));
            self.frame_groups = None;
        }
        if self.frame_groups.is_none()
            && let Some((splat, _)) = &self.splat
        {
            let group = |layout: &wgpu::BindGroupLayout| {
                ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("atoms frame"),
                    layout,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: d.lists.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: splat.as_entire_binding() },
                    ],
                })
            };
            self.frame_groups = Some((group(&self.shared.compute_layout), group(&self.shared.render_layout)));
        }
    }
}

/// A light above-left of the viewer, moving with the camera, and the camera's up vector.
pub fn headlight(eye: Vec3, target: Vec3, camera_up: Vec3) -> (Vec3, Vec3) {
    let back = (eye - target).normalize_or(Vec3::Z);
    let right = camera_up.cross(back).normalize_or(Vec3::X);
    let up = back.cross(right);
    ((back + 0.6 * up - 0.4 * right).normalize(), up)
}

/// Projected radius in pixels of a sphere of `radius` at `center` (the shader's rule, for tests
/// and benchmarks).
pub fn projected_radius_px(clip_from_world: Mat4, center: Vec3, radius: f32, height_px: u32) -> f32 {
    let w = (clip_from_world * center.extend(1.0)).w;
    radius * clip_from_world.row(1).truncate().length() * 0.5 * height_px as f32 / w
}

impl super::frame::Representation for AtomsPass {
    fn new(ctx: &GpuContext, _shared: &super::frame::Shared<'_>) -> Self {
        Self::new(ctx)
    }

    fn instance(&self, ctx: &GpuContext) -> Self {
        self.instance(ctx)
    }

    fn clear(&mut self, ctx: &GpuContext) {
        self.set_molecule(ctx, &Molecule::default(), AtomStyle::Hidden, None);
    }
}

impl Draw for AtomsPass {
    fn prepare(&mut self, f: &super::frame::Prepare<'_>) {
        if !f.later_tile {
            self.set_view(f.ctx, f.view, f.layer, f.size, f.clip.filter(|_| f.clip_atoms));
        }
    }

    fn phases(&self) -> &'static [Phase] {
        &[Phase::Cull, Phase::Opaque]
    }

    fn compute(&self, encoder: &mut wgpu::CommandEncoder) {
        let (Some(d), Some((splat, _)), Some((compute, _))) = (self.drawn(), &self.splat, &self.frame_groups) else {
            return;
        };
        encoder.clear_buffer(splat, 0, None);
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("cull and splat"), timestamp_writes: None });
        pass.set_bind_group(0, &d.group, &[]);
        pass.set_bind_group(1, compute, &[]);
        if d.visible_cells > 0 {
            let p = &self.shared;
            let big = d.big_spheres as usize;
            let per_cell = dispatch(d.visible_cells).0;
            let run = |pass: &mut wgpu::ComputePass<'_>, pipeline, [x, y]: [u32; 2]| {
                pass.set_pipeline(pipeline);
                pass.dispatch_workgroups(x, y, 1);
            };
            let (tiles, blocks) = coarse_depth_dims(self.splat.as_ref().map_or([1, 1], |(_, s)| *s));
            let coarse = |pass: &mut wgpu::ComputePass<'_>| {
                run(pass, &p.depth_tiles, dispatch(tiles[0] * tiles[1]).0);
                run(pass, &p.depth_blocks, dispatch(blocks[0] * blocks[1]).0);
            };
            pass.set_bind_group(2, &d.args_group, &[]);
            run(&mut pass, &p.split, per_cell);
            pass.set_pipeline(&p.atoms_first[big]);
            pass.dispatch_workgroups_indirect(&d.args, 0);
            coarse(&mut pass);
            run(&mut pass, &p.cull_left, per_cell);
            pass.set_pipeline(&p.atoms_rest[big]);
            pass.dispatch_workgroups_indirect(&d.args, 16);
            coarse(&mut pass);
            run(&mut pass, &p.cull_shown, per_cell);
            if let Some(ids) = &p.splat_ids {
                pass.set_pipeline(ids);
                pass.dispatch_workgroups_indirect(&d.args, 32);
            }
        }
        if d.bond_count > 0 && style_flags(self.style).1 & STYLE_CYLINDERS != 0 {
            let ([x, y], _) = dispatch(d.bond_count);
            pass.set_pipeline(&self.shared.cull_bonds);
            pass.dispatch_workgroups(x, y, 1);
        }
    }

    fn draw(&self, _phase: Phase, pass: &mut wgpu::RenderPass<'_>) {
        let (Some(d), Some((_, render))) = (self.drawn(), &self.frame_groups) else { return };
        pass.set_bind_group(0, &d.group, &[]);
        pass.set_bind_group(1, render, &[]);
        if self.style == AtomStyle::Lines && d.bond_count > 0 {
            pass.set_pipeline(&self.shared.lines);
            pass.draw(0..4, 0..d.bond_count);
        }
        pass.set_pipeline(&self.shared.cylinders);
        pass.draw_indirect(&d.lists, 16);
        pass.set_pipeline(&self.shared.spheres);
        pass.draw_indirect(&d.lists, 0);
        pass.set_pipeline(&self.shared.splats);
        pass.draw(0..3, 0..1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Atom;
    use crate::scene::AtomColoring;
    use crate::scene::coloring::atom_colors;
    use glam::DVec3;

    #[test]
    fn packed_attributes_and_radii() {
        let atom = |z, x| Atom { z, charge: z as f64, position: DVec3::new(x, 0.0, 0.0), ghost: false };
        let mut m = Molecule::new(vec![atom(6, 0.0), atom(8, 2.28), atom(11, 9.0)]);
        m.atoms[2].ghost = true;
        assert_eq!(m.bonds.len(), 1);
        let colors = atom_colors(&m, None, AtomColoring::Element);
        let d = AtomData::new(&m, &colors);
        assert_eq!(d.attrs[0] & 0xff, 6);
        assert_eq!(d.attrs[0] >> 8 & 0xff, FLAG_BONDED);
        assert_eq!(d.attrs[2] >> 8 & 0xff, FLAG_GHOST);
        assert_eq!(colors.palette[(d.attrs[1] >> 16) as usize], crate::model::elements::element(8).color);
        assert_eq!(d.bonds, vec![[0, 1]]);
        assert!(d.gpu_bytes() / 3 <= 64, "{} bytes per atom", d.gpu_bytes() / 3);
        let ball = looks(AtomStyle::BallAndStick, AtomSizes::default(), &colors);
        let fill = looks(AtomStyle::SpaceFilling, AtomSizes::default(), &colors);
        let bigger = looks(AtomStyle::BallAndStick, AtomSizes { ball: 1.5, stick: 1.0 }, &colors);
        assert!((bigger[6][0] - 1.5 * ball[6][0]).abs() < 1e-6, "the ball scale multiplies every radius");
        assert!(fill[6][0] > 3.0 * ball[6][0]);
        assert_eq!(looks(AtomStyle::Hidden, AtomSizes::default(), &colors)[6][0], 0.0);
        assert_eq!(ball.len(), PALETTE_AT + colors.palette.len());
        assert_eq!(style_flags(AtomStyle::Lines).1, STYLE_UNBONDED_ONLY);
    }

    #[test]
    fn cells_hold_every_atom_once_and_order_nearest_first() {
        let m = crate::model::synthetic::atom_box(5_000);
        let positions: Vec<[f32; 4]> = m.atoms.iter().map(|a| a.position.as_vec3().extend(0.0).to_array()).collect();
        let cells = Cells::new(&positions);
        let k = cells.len();
        // Three orders of the same atoms, each along its axis within every cell.
        for (axis, view) in [(0, Vec3::X), (1, Vec3::NEG_Y), (2, Vec3::Z)] {
            let (at, backwards) = cells.walk(view);
            assert_eq!((at as usize, backwards), (CELL_WORDS * k + axis * 5_000, view[axis] < 0.0));
            let block = &cells.data[at as usize..at as usize + 5_000];
            let mut seen = block.to_vec();
            seen.sort_unstable();
            assert_eq!(seen, (0..5_000).collect::<Vec<u32>>());
            for c in 0..k {
                let (first, count) = (cells.data[CELL_WORDS * c] as usize, cells.data[CELL_WORDS * c + 1] as usize);
                let s = cells.spheres[c];
                assert_eq!(f32::from_bits(cells.data[CELL_WORDS * c + 5]), s[3]);
                let run = &block[first..first + count];
                for &i in run {
                    let p = Vec3::from_slice(&positions[i as usize][..3]);
                    assert!(p.distance(Vec3::new(s[0], s[1], s[2])) <= s[3] * 1.0001, "atom {i} outside its cell");
                }
                assert!(run.windows(2).all(|w| positions[w[0] as usize][axis] <= positions[w[1] as usize][axis]));
            }
        }
        let eye = Vec3::new(0.0, 0.0, 200.0);
        let clip = glam::camera::rh::proj::directx::perspective(0.8, 1.0, 1.0, 500.0)
            * glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y);
        let order = cells.visible_order(clip, eye, Vec3::NEG_Z);
        assert_eq!(order.len(), k, "the whole box is in view");
        let depth = |c: u32| -cells.spheres[c as usize][2];
        assert!(order.windows(2).all(|w| depth(w[0]) <= depth(w[1])), "nearest first");
        let behind = glam::camera::rh::proj::directx::perspective(0.8, 1.0, 1.0, 500.0)
            * glam::camera::rh::view::look_at_mat4(eye, eye + Vec3::Z, Vec3::Y);
        assert!(cells.visible_order(behind, eye, Vec3::Z).is_empty(), "nothing behind the eye");
    }

    #[test]
    fn dispatch_covers_every_atom_within_limits() {
        for n in [1u32, 63, 64, 65, 4_194_240, 4_194_305, 16_000_000] {
            let ([x, y], row) = dispatch(n);
            assert!(x <= 65_535 && y <= 65_535);
            assert!(row as u64 * y as u64 >= n as u64);
        }
    }
}
