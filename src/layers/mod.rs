//! Putting a document into the renderer's layers as an object's state says: its atoms (style,
//! colours, the atoms a selection shows), each quantity in a layer of its own (a data set, or an
//! orbital or density evaluated), their isosurfaces, placement and visibility.

pub mod key_volumes;

use crate::evaluate::meshes::{color_isosurfaces, isosurfaces};
use crate::evaluate::{Values, WavefunctionView, evaluate_wavefunction};
use crate::gpu::atoms::AtomSizes;
use crate::gpu::gto::GtoFillPass;
use crate::gpu::renderer::Layer;
use crate::gpu::{GpuContext, GpuError, Renderer};
use crate::model::isosurface::Mesh;
use crate::model::{Document, VolumeGrid};
use crate::scene::coloring::{AtomColors, ValueMap, atom_colors};
use crate::scene::objects::{Part, layer_parts};
use crate::scene::selection::shown_atoms;
use crate::scene::translucency::SurfaceLook;
use crate::scene::{AtomLook, Evaluation, IsosurfaceSettings, ObjectState, Source};

/// Puts a wavefunction's orbital or density into `layer` ([`evaluate_wavefunction`], then
/// [`Evaluated::show`]). `fill` caches the compute pipeline between calls. Returns the values
/// behind the picture (the grid isosurfaces are cut from, when one was filled), or `None` when
/// the document has no wavefunction.
pub fn show_wavefunction(
    ctx: &GpuContext,
    layer: &mut Layer,
    fill: &mut Option<GtoFillPass>,
    doc: &Document,
    view: &WavefunctionView,
) -> Result<Option<Values>, GpuError> {
    let fill = fill.get_or_insert_with(|| GtoFillPass::new(ctx));
    evaluate_wavefunction(ctx, fill, doc, view)?.map(|e| e.show(ctx, layer)).transpose()
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
    layer.atoms.sizes = sizes(look);
    layer.set_atoms(ctx, &doc.molecule, look.style, Some(&atom_look(doc, look, selection)));
    layer.atoms.depth_cue = look.depth_cue;
}

/// The factors on the ball and stick radii `look` asks for.
pub fn sizes(look: &AtomLook) -> AtomSizes {
    AtomSizes { ball: look.ball_scale, stick: look.stick_scale }
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
    layer.clip_centre = object_centre(doc);
    layer.volume.set_texture(ctx, None);
    layer.surfaces.clear();
    place_layer(layer, state, Part::Atoms);
}

/// The point an object's clipping plane is measured from: the centre of `doc`'s bounds (its
/// atoms and grids), in the object's frame.
pub fn object_centre(doc: &Document) -> glam::Vec3 {
    doc.bounds().map_or(glam::Vec3::ZERO, |(lo, hi)| (0.5 * (lo + hi)).as_vec3())
}

/// Gives `layer`, which draws `part` of the object `state` describes, the object's placement,
/// its clipping plane and whether it is drawn (the object's visibility, and the quantity's).
pub fn place_layer(layer: &mut Layer, state: &ObjectState, part: Part) {
    layer.world_from_object = state.placement.world_from_object();
    layer.clip = state.clip;
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
        Source::Wavefunction(_) | Source::Scan(_) | Source::Promolecular(_) => None,
    });
    layer.set_volume(ctx, grid)?;
    let meshes: Vec<_> = match (grid, quantity) {
        (Some(grid), Some(q)) => q.isosurfaces.iter().flat_map(|iso| isosurfaces(grid, iso)).collect(),
        _ => Vec::new(),
    };
    Ok(show_meshes(ctx, layer, &meshes))
}

/// What [`show_quantity`] put into a layer.
#[derive(Default)]
pub struct ShownQuantity {
    /// The values shown (what the cloud's opacity is scaled to); `None` when the document does
    /// not hold the quantity.
    pub values: Option<Values>,
    /// The map its isosurfaces are coloured with by another quantity, and that one's name.
    pub color_map: Option<(ValueMap, String)>,
}

/// Puts quantity `k` of the object `state` describes into `layer`: a data set of `doc` as it
/// is, or its wavefunction's orbital or density evaluated on a grid of `points` per side
/// (`fill` caches the compute pipeline; in direct mode a grid is filled only for visible
/// isosurfaces), then its isosurfaces, coloured by another quantity where they ask.
pub fn show_quantity(
    ctx: &GpuContext,
    layer: &mut Layer,
    fill: &mut Option<GtoFillPass>,
    doc: &Document,
    state: &ObjectState,
    k: usize,
) -> Result<ShownQuantity, GpuError> {
    layer.clear(ctx);
    place_layer(layer, state, Part::Quantity(k));
    layer.clip_centre = object_centre(doc);
    let Some(q) = state.quantities.get(k) else { return Ok(ShownQuantity::default()) };
    let values = match q.source {
        Source::Volume(i) => {
            let grid = doc.volumes.get(i).cloned();
            layer.set_volume(ctx, grid.as_ref())?;
            grid.map(|grid| Values { grid: Some(grid), sampled: None })
        }
        Source::Wavefunction(quantity) => {
            let e = &state.evaluation;
            let functions = doc.wavefunction.as_ref().and_then(|wf| e.restriction(&wf.basis));
            let grid = q.wants_grid();
            let view = WavefunctionView { quantity, direct: e.direct, points: e.grid_points, functions, grid };
            show_wavefunction(ctx, layer, fill, doc, &view)?
        }
        // Its key volumes live with the window's scan ([`key_volumes::ScanScene`]).
        Source::Scan(_) => None,
        Source::Promolecular(quantity) => {
            use crate::evaluate::interaction::{Kind, grid};
            match grid(doc, Kind::Spherical, &q.fragments, &[], quantity, state.evaluation.grid_points) {
                Ok(grid) => {
                    layer.set_volume(ctx, Some(&grid))?;
                    Some(Values { grid: Some(grid), sampled: None })
                }
                // Callers check first (`interaction::check`, as `render --nci` does) and say why.
                Err(_) => None,
            }
        }
    };
    let mut color_map = None;
    if let Some(grid) = values.as_ref().and_then(|v| v.grid.as_ref()) {
        let mut meshes: Vec<_> = q.isosurfaces.iter().flat_map(|iso| isosurfaces(grid, iso)).collect();
        let signed = grid.kind == crate::model::grid::ValueKind::Signed;
        let of = crate::evaluate::meshes::Evaluating { doc, fragments: &q.fragments, others: &[] };
        color_map = color_isosurfaces(of, &q.isosurfaces, signed, &mut meshes);
        show_meshes(ctx, layer, &meshes);
    }
    Ok(ShownQuantity { values, color_map })
}

/// What [`show_scene`] put into a renderer.
pub struct ShownScene {
    /// Each layer's cloud settings, opacity scaled to its grid.
    pub clouds: Vec<crate::scene::VolumeSettings>,
    /// The scene's bounds (bohr).
    pub bounds: Option<(glam::DVec3, glam::DVec3)>,
    /// The last map a quantity's isosurfaces are coloured with, and what it shows (the colour
    /// bar a picture of the scene carries).
    pub color_map: Option<(ValueMap, String)>,
}

/// Puts each object of `scene` into `renderer`, its layers as [`layer_parts`] orders them (its
/// atoms, then each quantity: a data set, or its wavefunction's orbital or density evaluated on
/// a grid of `points` per side, with every isosurface of it).
pub fn show_scene<D: std::borrow::Borrow<Document>>(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    scene: &[(D, ObjectState)],
    points: usize,
) -> Result<ShownScene, GpuError> {
    let mut fill = None;
    let mut clouds = Vec::new();
    let mut bounds: Option<(glam::DVec3, glam::DVec3)> = None;
    let mut color_map = None;
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
                let shown = show_quantity(ctx, layer, &mut fill, doc, &state, k)?;
                let mut cloud = state.quantities[k].cloud;
                if let Some(values) = &shown.values {
                    values.auto_opacity(&mut cloud);
                }
                clouds.push(cloud);
                color_map = shown.color_map.or(color_map);
            }
        }
    }
    Ok(ShownScene { clouds, bounds, color_map })
}
