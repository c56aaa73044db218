//! Building the surfaces a layer draws: isosurfaces of a grid (both signs of an orbital, a
//! density's shells) within a GPU buffer's size, and a document's molecular surface, coloured
//! by atoms or by a grid's values.

use std::sync::atomic::{AtomicBool, AtomicU32};

use crate::model::grid::ValueKind;
use crate::model::isosurface::{self, Level, Mesh};
use crate::model::surface::{self, Sphere, SurfaceError};
use crate::model::units::ANGSTROM_PER_BOHR;
use crate::model::{Document, VolumeGrid};
use crate::scene::coloring::atom_colors;
use crate::scene::coloring::{ColorScheme, ValueMap};
use crate::scene::quantity::Source;
use crate::scene::selection::shown_atoms;
use crate::scene::translucency::SurfaceLook;
use crate::scene::{Fragments, IsosurfaceSettings, SurfaceSettings};

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

/// What a quantity's values at points are evaluated from: its document, and the fragments an
/// NCI quantity adds to its density (other open documents, or its atoms split in two).
#[derive(Clone, Copy)]
pub struct Evaluating<'a> {
    pub doc: &'a Document,
    pub fragments: &'a Fragments,
    /// The open documents `fragments` may name.
    pub others: &'a [std::sync::Arc<Document>],
}

static NO_FRAGMENTS: Fragments = Fragments { selection: None, files: Vec::new(), between_only: false };

impl<'a> Evaluating<'a> {
    /// The document's own quantities.
    pub fn alone(doc: &'a Document) -> Self {
        Self { doc, fragments: &NO_FRAGMENTS, others: &[] }
    }
}

/// Colours the meshes [`isosurfaces_within`] cut at `levels` (one per sign of a `signed` grid
/// for each visible level, in order) by the quantity each level's `color_by` names, one map for
/// all of them; returns that map and the quantity's name, when any level asks for it.
pub fn color_isosurfaces(
    of: Evaluating,
    levels: &[IsosurfaceSettings],
    signed: bool,
    meshes: &mut [(Mesh, SurfaceLook)],
) -> Option<(ValueMap, String)> {
    let per_level = if signed { 2 } else { 1 };
    let owners = levels.iter().filter(|l| l.visible).flat_map(|l| std::iter::repeat_n(l, per_level));
    let asking: Vec<(usize, Source)> =
        owners.zip(0..meshes.len()).filter_map(|(level, k)| level.color_by.map(|s| (k, s))).collect();
    let last = (levels.iter().rev().filter(|l| l.visible))
        .find_map(|l| l.color_by.map(|s| (s, l.color_range, l.color_scheme, l.color_window)))?;
    // Each quantity evaluated once, over the vertices of every mesh it colours.
    let mut per_mesh: Vec<Option<Vec<Option<f64>>>> = vec![None; meshes.len()];
    let mut sources: Vec<Source> = asking.iter().map(|&(_, s)| s).collect();
    sources.dedup();
    for source in sources {
        let ks: Vec<usize> = asking.iter().filter(|(_, s)| *s == source).map(|&(k, _)| k).collect();
        let meshes_of: Vec<&Mesh> = ks.iter().map(|&k| &meshes[k].0).collect();
        for (k, v) in ks.iter().zip(values_on(of, source, &meshes_of)) {
            per_mesh[*k] = Some(v);
        }
    }
    let (mut colored, values): (Vec<&mut Mesh>, Vec<Vec<Option<f64>>>) =
        meshes.iter_mut().zip(per_mesh).filter_map(|((m, _), v)| Some((m, v?))).unzip();
    let map = color_meshes(&mut colored, &values, last.1.map(f64::from), last.2);
    if let Some([lo, hi]) = last.3 {
        for (mesh, v) in colored.iter_mut().zip(&values) {
            for (c, v) in mesh.colors.iter_mut().zip(v) {
                if v.is_none_or(|v| v < f64::from(lo) || v > f64::from(hi)) {
                    *c = OUTSIDE_WINDOW;
                }
            }
        }
    }
    Some((map, color_name(of.doc, last.0)))
}

/// The grey of a coloured surface's vertices outside its colour window.
const OUTSIDE_WINDOW: [f32; 3] = [0.3, 0.3, 0.3];

/// How a colour bar names `source`: "ESP" for an electrostatic potential (the wavefunction's or a
/// data set that says it is one), else its name, cut to fit the bar.
pub fn color_name(doc: &Document, source: Source) -> String {
    const LONGEST: usize = 28;
    if source.is_potential(doc) {
        return "ESP".to_string();
    }
    let name = source.name(doc);
    match name.char_indices().nth(LONGEST) {
        Some((end, _)) => format!("{}…", name[..end].trim_end()),
        None => name,
    }
}

/// `source`'s values at the vertices of each of `meshes` ([`values_at`]), evaluated in one pass
/// over all of them (one potential built, one basis prepared).
pub fn values_on(of: Evaluating, source: Source, meshes: &[&Mesh]) -> Vec<Vec<Option<f64>>> {
    let points: Vec<glam::Vec3> = meshes.iter().flat_map(|m| m.positions.iter().copied()).collect();
    let mut all = values_at(of, source, &points).into_iter();
    meshes.iter().map(|m| all.by_ref().take(m.positions.len()).collect()).collect()
}

/// Colours each mesh by its `values` on one diverging map ([`color_values`]: `range`, or robust
/// over all of them); returns the map.
pub fn color_meshes(
    meshes: &mut [&mut Mesh],
    values: &[Vec<Option<f64>>],
    range: Option<f64>,
    scheme: ColorScheme,
) -> ValueMap {
    let all: Vec<Option<f64>> = values.iter().flatten().copied().collect();
    let (_, map) = color_values(&all, range, scheme);
    for (mesh, v) in meshes.iter_mut().zip(values) {
        mesh.colors = color_values(v, Some(map.range), scheme).0;
    }
    map
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
/// With `s.color_by_volume`, the colours are `grid`'s values instead ([`color_by_values`]), and
/// the map they were coloured with is returned (for its colour bar).
pub fn color_surface(
    mesh: &mut Mesh,
    doc: &Document,
    s: &SurfaceSettings,
    selection: &str,
    grid: Option<&VolumeGrid>,
) -> Option<ValueMap> {
    mesh.colors.clear();
    if s.color_by_volume {
        let (colors, map) = color_by_values(&mesh.positions, grid?);
        mesh.colors = colors;
        return Some(map);
    }
    let coloring = s.color_by?;
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
    None
}

/// `grid`'s value at each point (bohr), trilinear; `None` where a point lies outside the grid.
pub fn sample_grid(points: &[glam::Vec3], grid: &VolumeGrid) -> Vec<Option<f64>> {
    let grid_from_world = grid.world_from_grid.inverse();
    points
        .iter()
        .map(|p| {
            let g = grid_from_world.transform_point3(p.as_dvec3());
            let inside = (0..3).all(|a| g[a] >= -1e-9 && g[a] <= (grid.dims[a].max(1) - 1) as f64 + 1e-9);
            inside.then(|| grid.sample(g))
        })
        .collect()
}

/// The values of `source`, a quantity of `of`'s document, at each point (bohr): a
/// wavefunction's quantity evaluated exactly there (of the fragments' summed density for those
/// of the density, when `of` has fragments), a data set sampled trilinearly (`None` outside its
/// grid), a quantity of the spherical atoms.
pub fn values_at(of: Evaluating, source: Source, points: &[glam::Vec3]) -> Vec<Option<f64>> {
    use super::interaction;
    let doc = of.doc;
    if let Some((kind, q)) = interaction::of_source(source, of.fragments) {
        let points: Vec<glam::DVec3> = points.iter().map(|p| p.as_dvec3()).collect();
        return interaction::values_at(doc, kind, of.fragments, of.others, q, &points);
    }
    match (source, &doc.wavefunction) {
        (Source::Wavefunction(crate::model::orbitals::Quantity::TransitionDensity(n)), Some(wf)) => {
            let points: Vec<glam::DVec3> = points.iter().map(|p| p.as_dvec3()).collect();
            let prepared = crate::model::gto::PreparedBasis::new(&wf.basis);
            match crate::model::transition::TransitionDensity::of_state(doc, n) {
                Some(t) => t.at_points(wf, &prepared, &points).into_iter().map(Some).collect(),
                None => vec![None; points.len()],
            }
        }
        (Source::Wavefunction(q), Some(wf)) => {
            let points: Vec<glam::DVec3> = points.iter().map(|p| p.as_dvec3()).collect();
            let prepared = crate::model::gto::PreparedBasis::new(&wf.basis);
            prepared.quantity_at_points(wf, &doc.molecule, q, &points).into_iter().map(Some).collect()
        }
        (Source::Volume(i), _) if i < doc.volumes.len() => sample_grid(points, &doc.volumes[i]),
        _ => vec![None; points.len()],
    }
}

/// Linear RGB for each value on a diverging map ([`ValueMap`]) of range `range`, or when that
/// is `None` the 98th percentile of |value| (robust to a few points near a nucleus); grey where
/// there is no value. Returns the map too.
pub fn color_values(values: &[Option<f64>], range: Option<f64>, scheme: ColorScheme) -> (Vec<[f32; 3]>, ValueMap) {
    let range = range.filter(|r| *r > 0.0).unwrap_or_else(|| {
        let mut magnitudes: Vec<f64> = values.iter().flatten().map(|v| v.abs()).collect();
        magnitudes.sort_by(f64::total_cmp);
        magnitudes.get(magnitudes.len() * 98 / 100).copied().unwrap_or(0.0)
    });
    let map = ValueMap { range: range.max(1e-30), scheme };
    let colors = values.iter().map(|v| v.map_or([0.5; 3], |v| map.color(v))).collect();
    (colors, map)
}

/// Linear RGB for `grid`'s value at each point on a diverging map ([`color_values`], range
/// automatic). Returns the map too.
pub fn color_by_values(points: &[glam::Vec3], grid: &VolumeGrid) -> (Vec<[f32; 3]>, ValueMap) {
    color_values(&sample_grid(points, grid), None, ColorScheme::RedWhiteBlue)
}
