//! Rendering a document to an image without a window: the CLI's `render`, the benchmarks and
//! the golden-image tests use this, through the same [`Renderer`] as the viewer.

pub mod scan;

use std::sync::atomic::{AtomicBool, AtomicU32};

use glam::DVec3;

use crate::gpu::gto::{GtoFillPass, read_volume, volume_from_texture};
use crate::gpu::oit::FragmentStats;
use crate::gpu::renderer::Layer;
use crate::gpu::volume::VolumeTexture;
use crate::gpu::{FrameInput, GpuContext, GpuError, OffscreenTarget, Renderer};
use crate::model::cartesian::CartesianExpansion;
use crate::model::extent::quantity_box;
use crate::model::grid::ValueKind;
use crate::model::gto::{GridSpec, PreparedBasis};
use crate::model::isosurface::{self, Level, Mesh};
use crate::model::orbitals::Quantity;
use crate::model::surface::{self, Sphere, SurfaceError};
use crate::model::units::ANGSTROM_PER_BOHR;
use crate::model::{Document, VolumeGrid};
use crate::scene::coloring::{AtomColors, atom_colors};
use crate::scene::objects::{Part, layer_parts};
use crate::scene::selection::Selection;
use crate::scene::translucency::SurfaceLook;
use crate::scene::{
    AtomLook, Camera, Evaluation, IsosurfaceSettings, ObjectState, RenderSettings, Source, SurfaceSettings, ViewPreset,
};

/// Space (bohr) around the atoms in which orbitals are evaluated.
pub const ORBITAL_MARGIN: f64 = 4.5;

/// A camera that frames everything in the document from the default direction: its grids, or
/// for a wavefunction the box its orbitals are evaluated in.
pub fn default_camera(doc: &Document) -> Camera {
    match framing_box(doc) {
        Some((lo, hi)) => Camera::framing(lo, hi),
        None => Camera::default(),
    }
}

/// The camera a new file opens with: [`default_camera`]'s framing, looking along `preset`'s
/// direction (the principal axes, tilted, for [`ViewPreset::Auto`]).
pub fn camera_for(doc: &Document, preset: ViewPreset) -> Result<Camera, String> {
    let view = preset.direction(&doc.molecule)?;
    let mut camera = default_camera(doc);
    camera.look_along(view.direction, view.up);
    Ok(camera)
}

/// The box a camera frames to show `doc` whole (bohr, the document's own frame).
pub fn framing_box(doc: &Document) -> Option<(glam::Vec3, glam::Vec3)> {
    let bounds = match (&doc.wavefunction, doc.molecule.bounds()) {
        (Some(_), Some((lo, hi))) => Some((lo - DVec3::splat(ORBITAL_MARGIN), hi + DVec3::splat(ORBITAL_MARGIN))),
        _ => doc.bounds(),
    };
    bounds.map(|(lo, hi)| (lo.as_vec3(), hi.as_vec3()))
}

/// [`framing_box`], or the box of the atoms `selection` shows (padded by the largest atom's
/// radius) when it names some of them.
pub fn framing_box_of(doc: &Document, selection: &str) -> Option<(glam::Vec3, glam::Vec3)> {
    let Some(mask) = shown_atoms(doc, selection) else { return framing_box(doc) };
    let shown = doc.molecule.atoms.iter().zip(&mask).filter(|(_, m)| **m).map(|(a, _)| a.position.as_vec3());
    let (lo, hi) = shown.fold(None, |b: Option<(glam::Vec3, glam::Vec3)>, p| {
        Some(b.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))))
    })?;
    Some((lo - glam::Vec3::splat(4.0), hi + glam::Vec3::splat(4.0)))
}

/// The grid a wavefunction's `quantity` is evaluated on, `points` per axis: the box where it
/// decays to 1 % of its largest |value| ([`crate::model::extent::quantity_box`]).
pub fn orbital_geometry(doc: &Document, quantity: Quantity, points: usize) -> Option<GridSpec> {
    let (lo, hi) = quantity_box(doc.wavefunction.as_ref()?, &doc.molecule, quantity)?;
    Some(GridSpec::cube(lo, hi, points))
}

/// How to show a quantity of a wavefunction.
#[derive(Debug, Clone, PartialEq)]
pub struct WavefunctionView {
    pub quantity: Quantity,
    /// Seed 004's direct mode (orbitals only): evaluate per slice sample, no grid.
    pub direct: bool,
    /// Points per axis of the evaluation grid.
    pub points: usize,
    /// Per shell, whether it contributes (the atomic-orbital selector); `None`: all.
    pub shells: Option<Vec<bool>>,
}

/// A wavefunction's quantity evaluated for display, ready for a layer. Made by
/// [`evaluate_wavefunction`], which may run on any thread (the viewer's jobs); shown with
/// [`Evaluated::show`] on the thread that owns the renderer.
pub struct Evaluated {
    /// The values on the evaluation grid: what isosurfaces are cut from and what scales the
    /// opacity.
    pub grid: VolumeGrid,
    cloud: Cloud,
}

enum Cloud {
    /// An orbital filled on the GPU, already a texture.
    Texture(VolumeTexture),
    /// Seed 004's direct mode: the orbital evaluated per slice sample.
    Direct(CartesianExpansion, GridSpec),
    /// Values computed on the CPU (densities), uploaded when shown.
    Values,
}

/// Evaluates what `view` asks for of `doc`'s wavefunction: orbitals on the GPU (a filled
/// texture, read back once for the grid's values), densities on the CPU. `None` when the
/// document has no wavefunction.
pub fn evaluate_wavefunction(
    ctx: &GpuContext,
    fill: &GtoFillPass,
    doc: &Document,
    view: &WavefunctionView,
) -> Result<Option<Evaluated>, GpuError> {
    let (Some(wf), Some(geometry)) = (&doc.wavefunction, orbital_geometry(doc, view.quantity, view.points)) else {
        return Ok(None);
    };
    let prepared = PreparedBasis::new(&wf.basis);
    match view.quantity {
        Quantity::Orbital(i) => {
            let mut coefficients = wf.orbitals[i].coefficients.clone();
            if let Some(mask) = &view.shells {
                for ((shell, offset), &keep) in wf.basis.shells.iter().zip(wf.basis.shell_offsets()).zip(mask) {
                    if !keep {
                        coefficients[offset..offset + shell.n_functions()].fill(0.0);
                    }
                }
            }
            let expansion = CartesianExpansion::from_coefficients(&prepared, &coefficients);
            let texture = fill.fill(ctx, &expansion, &geometry)?;
            // The filled values give the range that scales the opacity (and the gradient scale).
            let grid = VolumeGrid::new("orbital", geometry.dims, geometry.world_from_grid, read_volume(ctx, &texture)?);
            let cloud = if view.direct {
                Cloud::Direct(expansion, geometry)
            } else {
                let mut volume = volume_from_texture(texture, &geometry, grid.stats.max_abs);
                volume.max_grad = grid.max_gradient().max(1e-30) as f32;
                Cloud::Texture(volume)
            };
            Ok(Some(Evaluated { grid, cloud }))
        }
        Quantity::Density | Quantity::SpinDensity => {
            let label = if view.quantity == Quantity::Density { "total density" } else { "spin density" };
            let values = prepared.quantity_grid_f32(wf, view.quantity, &geometry);
            let grid = VolumeGrid::new(label, geometry.dims, geometry.world_from_grid, values);
            Ok(Some(Evaluated { grid, cloud: Cloud::Values }))
        }
    }
}

/// [`evaluate_wavefunction`] on a grid this device holds: `view.points` per side, or fewer when
/// that many are over `limits` or the device refuses the memory, with a note saying so. Runs
/// its GPU work in error scopes on the calling thread.
pub fn evaluate_within(
    ctx: &GpuContext,
    fill: &GtoFillPass,
    doc: &Document,
    view: &WavefunctionView,
    limits: &wgpu::Limits,
) -> Result<(Option<Evaluated>, Option<String>), GpuError> {
    let requested = view.points;
    // p³ R32Float values must fit both the 3D texture's side and the memory budget.
    let mut points = requested;
    while points > 8 && crate::gpu::volume::fitting_step([points; 3], 4, limits) > 1 {
        points = points * 7 / 8;
    }
    loop {
        let attempt = WavefunctionView { points, ..view.clone() };
        match crate::gpu::context::guarded(&ctx.device, || evaluate_wavefunction(ctx, fill, doc, &attempt)) {
            Err(GpuError::Rejected(_) | GpuError::VolumeTooLarge { .. }) if points > 16 => points = points * 3 / 4,
            result => {
                let note = (points < requested).then(|| {
                    format!(
                        "{}: {requested} points per side are more than this GPU holds; evaluated on {points}",
                        doc.source
                    )
                });
                return result.map(|e| (e, note));
            }
        }
    }
}

impl Evaluated {
    /// Shows the cloud in `layer`; returns the values on the grid.
    pub fn show(self, ctx: &GpuContext, layer: &mut Layer) -> Result<VolumeGrid, GpuError> {
        match self.cloud {
            Cloud::Texture(volume) => layer.set_volume_texture(ctx, volume),
            Cloud::Direct(expansion, geometry) => layer.set_direct(ctx, &expansion, &geometry, self.grid.stats.max_abs),
            Cloud::Values => {
                layer.set_volume(ctx, Some(&self.grid))?;
            }
        }
        Ok(self.grid)
    }
}

/// Puts a wavefunction's orbital or density into `layer` ([`evaluate_wavefunction`], then
/// [`Evaluated::show`]). `fill` caches the compute pipeline between calls. Returns the values on
/// the grid (what isosurfaces are cut from), or `None` when the document has no wavefunction.
pub fn show_wavefunction(
    ctx: &GpuContext,
    layer: &mut Layer,
    fill: &mut Option<GtoFillPass>,
    doc: &Document,
    view: &WavefunctionView,
) -> Result<Option<VolumeGrid>, GpuError> {
    let fill = fill.get_or_insert_with(|| GtoFillPass::new(ctx));
    evaluate_wavefunction(ctx, fill, doc, view)?.map(|e| e.show(ctx, layer)).transpose()
}

/// Sets `volume.k1` from `grid` ([`crate::scene::opacity::auto_k1`]) when `volume.auto_k1`
/// asks for it: the first picture of any grid has contrast.
pub fn auto_opacity(volume: &mut crate::scene::VolumeSettings, grid: &VolumeGrid) {
    if volume.auto_k1 {
        let signed = grid.kind == ValueKind::Signed;
        let max = grid.stats.max_abs as f32;
        volume.k1 =
            crate::scene::opacity::auto_k1(&grid.values, grid.dims, signed, max, volume.density_scale, volume.k2);
    }
}

/// The isosurfaces `iso` asks for on `grid`, each with its colour: ψ = +v and ψ = −v for a
/// signed grid, ρ = v for a density. Empty when `iso` is hidden.
pub fn isosurfaces(grid: &VolumeGrid, iso: &IsosurfaceSettings) -> Vec<(Mesh, SurfaceLook)> {
    if !iso.visible {
        return Vec::new();
    }
    let signed = grid.kind == ValueKind::Signed;
    let levels = Level::pair(iso.level.value(grid.stats.sigma), signed);
    let colors = if signed { vec![iso.positive_color, iso.negative_color] } else { vec![iso.density_color] };
    isosurface::extract(grid, &levels).into_iter().zip(colors.into_iter().map(|c| iso.look(c))).collect()
}

/// Isosurfaces of `grid` at every level of `levels` (each as [`isosurfaces`] cuts it), every
/// mesh's vertex and index data within `max_bytes` (a GPU buffer's limit): when the whole
/// grid's meshes would not fit, they are cut from every 2nd, 4th, … point, with a note.
pub fn isosurfaces_within(
    grid: &VolumeGrid,
    levels: &[IsosurfaceSettings],
    max_bytes: u64,
) -> (Vec<(Mesh, SurfaceLook)>, Option<String>) {
    let mut step = 1;
    loop {
        let coarse = (step > 1).then(|| grid.subsampled(step));
        let g = coarse.as_ref().unwrap_or(grid);
        let meshes: Vec<_> = levels.iter().flat_map(|iso| isosurfaces(g, iso)).collect();
        let fits = meshes.iter().all(|(m, _)| mesh_fits(m, max_bytes));
        if fits || step >= 64 {
            let note = (step > 1).then(|| {
                format!("isosurfaces cut from one point in {step} along each axis: the whole grid's are more than a GPU buffer holds")
            });
            return (meshes, note);
        }
        step *= 2;
    }
}

/// Which of `doc`'s atoms `selection` shows; `None` for all of them (an empty query, or one that
/// does not parse: the panel says why).
fn shown_atoms(doc: &Document, selection: &str) -> Option<Vec<bool>> {
    let query = Selection::parse(selection).ok().filter(|q| !q.is_everything())?;
    Some(query.mask(&doc.molecule, doc.structure.as_ref()))
}

/// Whether a mesh fits the GPU buffers of `max_bytes` (24-byte vertices, 4-byte indices).
fn mesh_fits(m: &Mesh, max_bytes: u64) -> bool {
    (m.positions.len() as u64 * 24).max(m.indices.len() as u64 * 4) <= max_bytes
}

/// `doc`'s molecular surface as `s` asks (`None` when it is off), built around the atoms
/// `selection` shows (all when it is empty or does not parse); built again at twice the
/// spacing, with a note saying so, while its mesh would not fit a GPU buffer of `max_bytes`.
/// `cancel` stops it between grid planes; `progress` gets the thousandths built.
pub fn molecular_surface(
    doc: &Document,
    s: &SurfaceSettings,
    selection: &str,
    max_bytes: u64,
    (cancel, progress): (&AtomicBool, &AtomicU32),
) -> Result<Option<(Mesh, Option<String>)>, SurfaceError> {
    let mask = shown_atoms(doc, selection);
    let spheres = Sphere::of_molecule(&doc.molecule, mask.as_deref());
    let Some(mut params) = s.params(&spheres) else { return Ok(None) };
    let asked = params.resolution;
    loop {
        let built = surface::build_reporting(&spheres, &params, cancel, progress)?;
        if mesh_fits(&built.mesh, max_bytes) || params.resolution >= 16.0 * asked {
            let note = (params.resolution > asked).then(|| {
                format!(
                    "molecular surface built at {:.2} Å: at {:.2} Å its mesh is more than a GPU buffer holds",
                    params.resolution * ANGSTROM_PER_BOHR,
                    asked * ANGSTROM_PER_BOHR
                )
            });
            return Ok(Some((built.mesh, note)));
        }
        params.resolution *= 2.0;
    }
}

/// Colours `mesh`, `doc`'s molecular surface built around the atoms `selection` shows, by the
/// atom nearest each vertex as `s.color_by` says (no colours when it says none).
/// With `s.color_by_volume`, the colours are `grid`'s values instead ([`color_by_values`]).
pub fn color_surface(mesh: &mut Mesh, doc: &Document, s: &SurfaceSettings, selection: &str, grid: Option<&VolumeGrid>) {
    mesh.colors.clear();
    if s.color_by_volume {
        if let Some(grid) = grid {
            mesh.colors = color_by_values(&mesh.positions, grid);
        }
        return;
    }
    let Some(coloring) = s.color_by else { return };
    let mask = shown_atoms(doc, selection);
    let (spheres, atoms) = Sphere::of_atoms(&doc.molecule, mask.as_deref());
    let colors = atom_colors(&doc.molecule, doc.structure.as_ref(), coloring);
    let reach = s.probe as f64 * crate::model::units::BOHR_PER_ANGSTROM + 2.0;
    let nearest = surface::nearest_spheres(&spheres, &mesh.positions, reach);
    mesh.colors = nearest
        .iter()
        .map(|&n| match atoms.get(n as usize).and_then(|&a| colors.index.get(a as usize)) {
            Some(&i) => crate::scene::coloring::linear(colors.palette[i as usize]),
            None => s.color,
        })
        .collect();
}

/// Linear RGB for `grid`'s value at each point: negative red, zero white, positive blue (the
/// convention of electrostatic potentials on surfaces), scaled to the 98th percentile of |value|
/// over the points; grey where a point lies outside the grid.
pub fn color_by_values(points: &[glam::Vec3], grid: &VolumeGrid) -> Vec<[f32; 3]> {
    let grid_from_world = grid.world_from_grid.inverse();
    let values: Vec<Option<f64>> = points
        .iter()
        .map(|p| {
            let g = grid_from_world.transform_point3(p.as_dvec3());
            let inside = (0..3).all(|a| g[a] >= -1e-9 && g[a] <= (grid.dims[a].max(1) - 1) as f64 + 1e-9);
            inside.then(|| grid.sample(g))
        })
        .collect();
    let mut magnitudes: Vec<f64> = values.iter().flatten().map(|v| v.abs()).collect();
    magnitudes.sort_by(f64::total_cmp);
    let scale = magnitudes.get(magnitudes.len() * 98 / 100).copied().unwrap_or(0.0).max(1e-30);
    let (red, blue) = ([0.85, 0.08, 0.06], [0.06, 0.2, 0.85]);
    values
        .iter()
        .map(|v| match v {
            None => [0.5; 3],
            Some(v) => {
                let t = (v / scale).clamp(-1.0, 1.0) as f32;
                let end = if t < 0.0 { red } else { blue };
                std::array::from_fn(|k| 1.0 + (end[k] - 1.0) * t.abs())
            }
        })
        .collect()
}

/// Extracts the isosurfaces of `grid` and shows them in `layer` (none when `iso` is hidden).
/// Returns the number of triangles.
pub fn show_isosurfaces(ctx: &GpuContext, layer: &mut Layer, grid: &VolumeGrid, iso: &IsosurfaceSettings) -> usize {
    show_meshes(ctx, layer, &isosurfaces(grid, iso))
}

/// Shows `meshes`, each in its colour, as the layer's isosurfaces; returns the triangle count.
pub fn show_meshes(ctx: &GpuContext, layer: &mut Layer, meshes: &[(Mesh, SurfaceLook)]) -> usize {
    layer.surfaces.set_meshes(ctx, meshes);
    meshes.iter().map(|(m, _)| m.triangle_count()).sum()
}

/// What to tell the user when a grid of `dims` is shown at every `step`-th point.
pub fn coarser_note(what: &str, dims: [usize; 3], step: usize) -> String {
    let coarse = dims.map(|d| d.div_ceil(step));
    format!(
        "{what}: the grid of {}×{}×{} points is more than this GPU holds; shown with one point in {step} along each axis ({}×{}×{})",
        dims[0], dims[1], dims[2], coarse[0], coarse[1], coarse[2]
    )
}

/// Puts `doc`'s atoms into `layer` as `look` says, those `selection` leaves out hidden.
pub fn show_atoms(ctx: &GpuContext, layer: &mut Layer, doc: &Document, look: &AtomLook, selection: &str) {
    layer.set_atoms(ctx, &doc.molecule, look.style, Some(&atom_look(doc, look, selection)));
    layer.atoms.depth_cue = look.depth_cue;
}

/// The colours of `doc`'s atoms, and which are shown: all when `selection` does not parse (the
/// panel says why).
pub fn atom_look(doc: &Document, look: &AtomLook, selection: &str) -> AtomColors {
    let mut colors = atom_colors(&doc.molecule, doc.structure.as_ref(), look.colors);
    if let Some(mask) = shown_atoms(doc, selection) {
        colors.shown = mask;
    }
    colors
}

/// Puts `doc`'s atoms into `layer` as `state` shows them, with its placement and visibility;
/// the layer's cloud and surfaces are emptied (an object's atoms layer: its molecular surface
/// is added when built, its quantities have layers of their own).
pub fn show_object_atoms(ctx: &GpuContext, layer: &mut Layer, doc: &Document, state: &ObjectState) {
    show_atoms(ctx, layer, doc, &state.atoms, &state.selection);
    layer.volume.set_texture(ctx, None);
    layer.surfaces.clear();
    place_layer(layer, state, Part::Atoms);
}

/// Gives `layer`, which draws `part` of the object `state` describes, the object's placement
/// and whether it is drawn (the object's visibility, and the quantity's).
pub fn place_layer(layer: &mut Layer, state: &ObjectState, part: Part) {
    layer.world_from_object = state.placement.world_from_object();
    layer.visible = state.visible
        && match part {
            Part::Atoms => true,
            Part::Quantity(k) => state.quantities.get(k).is_some_and(|q| q.visible),
        };
}

/// Puts one layer's worth of `doc` into `layer` as `state` shows it: the atoms, and the
/// selected quantity when it is one of the document's data sets, with its isosurfaces. For
/// hosts that draw an object in one layer (tests, single-file renders); the window and
/// [`show_scene`] give each quantity a layer of its own. Returns the isosurfaces' triangle count.
pub fn show_object(
    ctx: &GpuContext,
    layer: &mut Layer,
    doc: &Document,
    state: &ObjectState,
) -> Result<usize, GpuError> {
    show_object_atoms(ctx, layer, doc, state);
    let quantity = state.selected_quantity();
    let grid = quantity.and_then(|q| match q.source {
        Source::Volume(i) => doc.volumes.get(i),
        Source::Wavefunction(_) => None,
    });
    layer.set_volume(ctx, grid)?;
    let meshes: Vec<_> = match (grid, quantity) {
        (Some(grid), Some(q)) => q.isosurfaces.iter().flat_map(|iso| isosurfaces(grid, iso)).collect(),
        _ => Vec::new(),
    };
    Ok(show_meshes(ctx, layer, &meshes))
}

/// Puts quantity `k` of the object `state` describes into `layer`: a data set of `doc` as it
/// is, or its wavefunction's orbital or density evaluated on a grid of `points` per side
/// (`fill` caches the compute pipeline), then its isosurfaces. Returns the values shown (what
/// the cloud's opacity is scaled to), `None` when `doc` does not hold the quantity.
pub fn show_quantity(
    ctx: &GpuContext,
    layer: &mut Layer,
    fill: &mut Option<GtoFillPass>,
    doc: &Document,
    state: &ObjectState,
    k: usize,
) -> Result<Option<VolumeGrid>, GpuError> {
    layer.clear(ctx);
    place_layer(layer, state, Part::Quantity(k));
    let Some(q) = state.quantities.get(k) else { return Ok(None) };
    let grid = match q.source {
        Source::Volume(i) => {
            let grid = doc.volumes.get(i).cloned();
            layer.set_volume(ctx, grid.as_ref())?;
            grid
        }
        Source::Wavefunction(quantity) => {
            let e = &state.evaluation;
            let view = WavefunctionView { quantity, direct: e.direct, points: e.grid_points, shells: e.shells() };
            show_wavefunction(ctx, layer, fill, doc, &view)?
        }
    };
    if let Some(grid) = &grid {
        let meshes: Vec<_> = q.isosurfaces.iter().flat_map(|iso| isosurfaces(grid, iso)).collect();
        show_meshes(ctx, layer, &meshes);
    }
    Ok(grid)
}

/// Each layer's cloud settings, and the scene's bounds (bohr).
pub type ShownScene = (Vec<crate::scene::VolumeSettings>, Option<(glam::DVec3, glam::DVec3)>);

/// Puts each object of `scene` into `renderer`, its layers as [`layer_parts`] orders them (its
/// atoms, then each quantity: a data set, or its wavefunction's orbital or density evaluated on
/// a grid of `points` per side, with every isosurface of it). Returns each layer's cloud
/// settings (opacity scaled to its grid) and the scene's bounds.
pub fn show_scene<D: std::borrow::Borrow<Document>>(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    scene: &[(D, ObjectState)],
    points: usize,
) -> Result<ShownScene, GpuError> {
    let mut fill = None;
    let mut clouds = Vec::new();
    let mut bounds: Option<(glam::DVec3, glam::DVec3)> = None;
    let parts = layer_parts(scene.iter().map(|(_, s)| s));
    renderer.truncate(parts.len());
    for (n, &(object, part)) in parts.iter().enumerate() {
        let (doc, state) = (scene[object].0.borrow(), &scene[object].1);
        let layer = renderer.layer_mut(ctx, n);
        match part {
            Part::Atoms => {
                show_object_atoms(ctx, layer, doc, state);
                clouds.push(crate::scene::VolumeSettings { visible: false, ..Default::default() });
                if let Some((lo, hi)) = doc.bounds() {
                    bounds = Some(bounds.map_or((lo, hi), |(l, h)| (l.min(lo), h.max(hi))));
                }
            }
            Part::Quantity(k) => {
                let evaluation = Evaluation { grid_points: points, ..state.evaluation.clone() };
                let state = ObjectState { evaluation, ..state.clone() };
                let grid = show_quantity(ctx, layer, &mut fill, doc, &state, k)?;
                let mut cloud = state.quantities[k].cloud;
                if let Some(grid) = &grid {
                    auto_opacity(&mut cloud, grid);
                }
                clouds.push(cloud);
            }
        }
    }
    Ok((clouds, bounds))
}

/// A renderer with an offscreen target of a fixed size.
pub struct Headless {
    pub renderer: Renderer,
    pub target: OffscreenTarget,
}

impl Headless {
    /// Loads `doc` (its volume `volume_index`, if any) into a new renderer.
    pub fn new(
        ctx: &GpuContext,
        doc: &Document,
        volume_index: Option<usize>,
        settings: &RenderSettings,
        size: [u32; 2],
    ) -> Result<Self, GpuError> {
        let mut renderer = Renderer::new(ctx);
        let layer = renderer.main();
        show_atoms(ctx, layer, doc, &AtomLook::of(settings), "");
        let grid = volume_index.and_then(|i| doc.volumes.get(i));
        layer.set_volume(ctx, grid)?;
        if let Some(grid) = grid {
            show_isosurfaces(ctx, layer, grid, &settings.iso);
        }
        Ok(Self { renderer, target: OffscreenTarget::new(&ctx.device, size) })
    }

    /// Records and submits one frame (waits for it only when it has translucent surfaces).
    pub fn draw(&mut self, ctx: &GpuContext, camera: &Camera, settings: &RenderSettings) {
        let frame = FrameInput::single(camera, settings, self.target.size);
        draw_exact(ctx, &mut self.renderer, &self.target.color_view, &frame);
    }

    /// Draws one frame and reads it back.
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        settings: &RenderSettings,
    ) -> Result<image::RgbaImage, GpuError> {
        self.draw(ctx, camera, settings);
        self.target.read_rgba(&ctx.device, &ctx.queue)
    }
}

/// Draws `frame` into `output` and submits it. With translucent surfaces it waits for the
/// fragment counts, and a frame whose lists overflowed is drawn again in more bands until every
/// fragment was kept. Returns the last counts.
pub fn draw_exact(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    output: &wgpu::TextureView,
    frame: &FrameInput,
) -> Option<FragmentStats> {
    let mut last_bands = 0;
    loop {
        let mut encoder = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        renderer.render(ctx, &mut encoder, output, frame);
        ctx.queue.submit([encoder.finish()]);
        let stats = renderer.settle_fragments(ctx)?;
        // No more bands to be had (one per row, or the most there are): the counts say so.
        if stats.fits() || stats.bands == last_bands {
            return Some(stats);
        }
        last_bands = stats.bands;
    }
}

/// Renders a document once: the whole pipeline in one call.
pub fn render_document(
    ctx: &GpuContext,
    doc: &Document,
    volume_index: Option<usize>,
    camera: &Camera,
    settings: &RenderSettings,
    size: [u32; 2],
) -> Result<image::RgbaImage, GpuError> {
    Headless::new(ctx, doc, volume_index, settings, size)?.render(ctx, camera, settings)
}
