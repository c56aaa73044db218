//! Volume arithmetic: a quantity minus another file's same quantity on the first one's grid
//! (two states, two methods, a complex minus its parts), for `cube --minus` and the viewer.

use glam::DVec3;

use crate::evaluate::meshes::sample_grid;
use crate::evaluate::orbital_geometry;
use crate::model::gto::PreparedBasis;
use crate::model::orbitals::Quantity;
use crate::model::{Document, VolumeGrid};
use crate::scene::Source;

/// What `other` holds of the quantity `source` names in `doc`: the same density or potential
/// of its wavefunction, else its first data set. Orbitals have none (their phases and order
/// differ from file to file).
pub fn counterpart(doc: &Document, source: Source, other: &Document) -> Option<Source> {
    // An excited state's densities too: another TD file's are their counterpart.
    let density_like = |q: Quantity| {
        matches!(q, Quantity::Density | Quantity::SpinDensity | Quantity::Potential) || q.state_part().is_some()
    };
    let own = match source {
        Source::Wavefunction(q) if density_like(q) => Some(q),
        Source::Wavefunction(_) | Source::Scan(_) | Source::Promolecular(_) => return None,
        Source::Volume(i) if i < doc.volumes.len() => None,
        Source::Volume(_) => return None,
    };
    match (own, &other.wavefunction) {
        (Some(q), Some(_)) => Some(Source::Wavefunction(q)).filter(|s| s.exists_in(other)),
        (None, Some(_)) => Some(Source::Wavefunction(Quantity::Density)),
        _ => (!other.volumes.is_empty()).then_some(Source::Volume(0)),
    }
}

/// `source` of `other` at `points` (bohr): evaluated from its wavefunction, or its data set
/// sampled trilinearly with 0 outside its grid. Also how many points lay outside; refused when
/// every point does (the grids do not overlap).
pub fn values_of(other: &Document, source: Source, points: &[DVec3]) -> Result<(Vec<f64>, usize), String> {
    match (source, &other.wavefunction) {
        (Source::Wavefunction(q), Some(wf)) => {
            let values = PreparedBasis::new(&wf.basis).quantity_at_points(wf, &other.molecule, q, points);
            Ok((values, 0))
        }
        (Source::Volume(i), _) if i < other.volumes.len() => {
            let at: Vec<glam::Vec3> = points.iter().map(|p| p.as_vec3()).collect();
            let values = sample_grid(&at, &other.volumes[i]);
            let outside = values.iter().filter(|v| v.is_none()).count();
            if outside == values.len() {
                return Err(format!(
                    "{}: its grid does not overlap the points asked for (no point lies inside it)",
                    other.source
                ));
            }
            Ok((values.into_iter().map(|v| v.unwrap_or(0.0)).collect(), outside))
        }
        _ => Err(format!("{}: it holds no {}", other.source, source.name(other))),
    }
}

/// Every point of a grid of `dims` in the order its values are stored (the last index fastest).
pub fn grid_points(dims: [usize; 3], point: impl Fn(usize, usize, usize) -> DVec3 + Copy) -> Vec<DVec3> {
    (0..dims[0]).flat_map(|i| (0..dims[1]).flat_map(move |j| (0..dims[2]).map(move |k| point(i, j, k)))).collect()
}

/// `source` of `doc` minus its [`counterpart`] in `other`, on `source`'s grid: a data set's own,
/// or a wavefunction quantity's evaluation grid of `points` per axis. Labelled "A − B".
pub fn difference(doc: &Document, source: Source, points: usize, other: &Document) -> Result<VolumeGrid, String> {
    let theirs = counterpart(doc, source, other)
        .ok_or_else(|| format!("{} holds nothing to subtract from {}", other.source, source.name(doc)))?;
    let mine = match (source, &doc.wavefunction) {
        (Source::Volume(i), _) => doc.volumes[i].clone(),
        (Source::Wavefunction(q), Some(wf)) => {
            let spec = orbital_geometry(doc, q, points).ok_or_else(|| format!("{}: no atoms", doc.source))?;
            let values = PreparedBasis::new(&wf.basis).quantity_grid_f32(wf, &doc.molecule, q, &spec);
            VolumeGrid::new(source.name(doc), spec.dims, spec.world_from_grid, values)
        }
        (Source::Wavefunction(_), None) => return Err(format!("{}: no wavefunction", doc.source)),
        (Source::Scan(_), _) => return Err(format!("{}: a scan's orbital changes with its coordinate", doc.source)),
        (Source::Promolecular(q), _) => {
            use super::interaction::{Kind, grid};
            grid(doc, Kind::Spherical, &Default::default(), &[], q, points)?
        }
    };
    let at = grid_points(mine.dims, |i, j, k| mine.point(i, j, k));
    let (subtract, _) = values_of(other, theirs, &at)?;
    let values = mine.values.iter().zip(&subtract).map(|(&a, &b)| (a as f64 - b) as f32).collect();
    let label = format!("{} − {}", source.name(doc), file_name(&other.source));
    Ok(VolumeGrid::new(label, mine.dims, mine.world_from_grid, values))
}

/// The last part of a path, for labels.
fn file_name(source: &str) -> &str {
    source.rsplit(['/', '\\']).next().unwrap_or(source)
}
