//! A structure's non-covalent interactions without a wavefunction: the promolecular density
//! (spherical atoms, [`Promolecule`]) and the NCI quantities made of its derivatives, on a grid
//! around the atoms — or, between a selection and the rest of the structure (a ligand and its
//! pocket), around the selection only, keeping the points where neither part holds almost all
//! of the density (NCIPLOT's intermolecular mode).

use glam::DVec3;

use crate::model::nci::{
    self, CUT_VALUE, DensitySource, INTERMOLECULAR_SHARE, NciSettings, PROMOLECULAR_DENSITY_CUT,
};
use crate::model::orbitals::Quantity;
use crate::model::promolecular::Promolecule;
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::model::{Document, GridSpec, Molecule, VolumeGrid};
use crate::scene::quantity::PROMOLECULAR_NCI_LEVEL;
use crate::scene::selection::Selection;

/// Space around all the atoms (NCIPLOT's 0.75 Å), and around a selection between which and
/// the rest the interactions are wanted: contacts reach ~4 Å, so their surfaces lie within
/// 2.5 Å of the selection's atoms.
const MARGIN_ANGSTROM: f64 = nci::NCIPLOT_MARGIN_ANGSTROM;
const BETWEEN_MARGIN_ANGSTROM: f64 = 2.5;

/// The grid step the surfaces need at most (Å): a hydrogen bond's disc of low s is about 0.5 Å
/// across, and a coarser grid misses it (NCIPLOT's coarse grid is 0.15 Å).
const STEP_ANGSTROM: f64 = 0.2;

/// Points along a grid's longest side at most: a whole protein's box is evaluated at a coarser
/// step rather than with more than ~7·10⁶ points.
const MAX_SIDE: usize = 192;

/// The parts whose densities add: the whole structure, or the selection and the rest.
struct Parts {
    fragments: Vec<Promolecule>,
    /// The box the grid covers (bohr).
    lo: DVec3,
    hi: DVec3,
}

impl Parts {
    fn sources(&self) -> Vec<&dyn DensitySource> {
        self.fragments.iter().map(|p| p as &dyn DensitySource).collect()
    }

    /// NCIPLOT's two grids of the parts' summed density on `spec`: every s kept (capped at
    /// [`CUT_VALUE`]) where ρ is below the promolecular cut and, between two parts, neither holds
    /// almost all of it.
    fn nci_grids(&self, spec: &GridSpec) -> nci::NciGrids {
        let sources = self.sources();
        let settings = NciSettings {
            density_cut: PROMOLECULAR_DENSITY_CUT,
            rdg_cut: CUT_VALUE as f64,
            intermolecular: (sources.len() > 1).then_some(INTERMOLECULAR_SHARE),
        };
        nci::nci_grid(&sources, spec, settings)
    }
}

/// NCIPLOT's two grids ([`nci::NciGrids`]: 100·sign(λ₂)ρ and s) of `doc`'s spherical atoms, as
/// [`grid`] cuts them, on cubic voxels `side` points along the box's longest side: what the NCI
/// plot shows.
pub fn nci_grids(doc: &Document, between: Option<&str>, side: usize) -> Result<nci::NciGrids, String> {
    let parts = parts(doc, between)?;
    Ok(parts.nci_grids(&GridSpec::cubic_voxels(parts.lo, parts.hi, side)))
}

/// The parts of `doc` for `between` (a selection query, [`Selection`]); errors name what is
/// wrong (a query that does not parse, one that picks no atom or every atom, an element with
/// no atomic density).
fn parts(doc: &Document, between: Option<&str>) -> Result<Parts, String> {
    let molecule = &doc.molecule;
    let mask = match between.map(str::trim).filter(|q| !q.is_empty()) {
        None => None,
        Some(query) => {
            let selection = Selection::parse(query).map_err(|e| format!("between `{query}`: expected {e}"))?;
            let mask = selection.mask(molecule, doc.structure.as_ref());
            let picked = mask.iter().filter(|&&m| m).count();
            if selection.is_everything() || picked == 0 || picked == mask.len() {
                return Err(format!(
                    "between `{query}`: it picks {picked} of {} atoms; the interaction needs atoms on both sides",
                    mask.len()
                ));
            }
            Some(mask)
        }
    };
    let part = |keep: &dyn Fn(usize) -> bool| Molecule {
        atoms: molecule.atoms.iter().enumerate().filter(|(i, _)| keep(*i)).map(|(_, a)| a.clone()).collect(),
        ..Molecule::default()
    };
    let (molecules, boxed, margin) = match &mask {
        None => (vec![part(&|_| true)], part(&|_| true), MARGIN_ANGSTROM),
        Some(mask) => {
            let selected = part(&|i| mask[i]);
            (vec![selected.clone(), part(&|i| !mask[i])], selected, BETWEEN_MARGIN_ANGSTROM)
        }
    };
    let (lo, hi) = boxed.bounds().ok_or_else(|| format!("{}: no atoms", doc.source))?;
    let fragments = molecules
        .iter()
        .map(Promolecule::new)
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| format!("{}: {e}", doc.source))?;
    let margin = DVec3::splat(margin * BOHR_PER_ANGSTROM);
    Ok(Parts { fragments, lo: lo - margin, hi: hi + margin })
}

/// What a picture of `doc`'s promolecular NCI should say beside it: a structure without
/// hydrogens (most crystal structures) has only its heavy atoms' contacts, whose surfaces at
/// s = 0.3 are small.
pub fn note(doc: &Document) -> Option<String> {
    let atoms = &doc.molecule.atoms;
    (atoms.len() > 2 && atoms.iter().all(|a| a.z != 1)).then(|| {
        format!(
            "{}: the structure has no hydrogens, so its NCI surfaces (spherical atoms) are those of heavy atoms alone and small; add hydrogens, or raise the level of s",
            doc.source
        )
    })
}

/// Whether [`grid`] can be made for `doc` and `between`: the error it would give, without
/// evaluating anything.
pub fn check(doc: &Document, between: Option<&str>) -> Result<(), String> {
    parts(doc, between).map(|_| ())
}

/// `quantity` ([`crate::scene::quantity::is_promolecular`]) of `doc`'s spherical atoms on a
/// grid of cubic voxels, `points` along its longest side or [`STEP_ANGSTROM`] apart, whichever
/// is finer (but no more than [`MAX_SIDE`] points along a side): the NCI surface's s (where ρ is
/// above NCIPLOT's promolecular cut or, between two parts, where one part holds nearly all
/// of it: [`CUT_VALUE`]), the NCI cloud (sign(λ₂)ρ weighted by how far s lies below
/// [`PROMOLECULAR_NCI_LEVEL`], 0 where cut), sign(λ₂)ρ, s, or ρ.
pub fn grid(doc: &Document, quantity: Quantity, between: Option<&str>, points: usize) -> Result<VolumeGrid, String> {
    let parts = parts(doc, between)?;
    let longest = (parts.hi - parts.lo).max_element();
    let side = (longest / (STEP_ANGSTROM * BOHR_PER_ANGSTROM)).ceil() as usize + 1;
    let spec = GridSpec::cubic_voxels(parts.lo, parts.hi, side.max(points).min(MAX_SIDE));
    let values = match quantity {
        Quantity::NciGradient | Quantity::NciCloud => {
            let grids = parts.nci_grids(&spec);
            match quantity {
                Quantity::NciGradient => grids.grad,
                _ => {
                    let level = PROMOLECULAR_NCI_LEVEL;
                    let cloud = |(&dens, &s): (&f32, &f32)| match s < level {
                        true => dens / 100.0 * (1.0 - s / level),
                        false => 0.0,
                    };
                    grids.dens.iter().zip(&grids.grad).map(cloud).collect()
                }
            }
        }
        _ => {
            let points = super::arithmetic::grid_points(spec.dims, |i, j, k| spec.point(i, j, k));
            summed_at(&parts.sources(), quantity, &points).into_iter().map(|v| v as f32).collect()
        }
    };
    let label = crate::scene::Source::Promolecular(quantity).name(doc);
    Ok(VolumeGrid::new(label, spec.dims, spec.world_from_grid, values))
}

/// ρ's derivatives of the whole structure's spherical atoms at `point` (bohr); `None` when an
/// element has no atomic density.
pub fn derivatives_at(doc: &Document, point: DVec3) -> Option<nci::DensityDerivatives> {
    let mut d = [nci::DensityDerivatives::default()];
    Promolecule::new(&doc.molecule).ok()?.derivatives_at(&[point], &mut d);
    Some(d[0])
}

/// `quantity` of the whole structure's spherical atoms at `points` (bohr): what colours a
/// promolecular NCI surface by sign(λ₂)ρ. `None` at every point when an element has no
/// atomic density.
pub fn values_at(doc: &Document, quantity: Quantity, points: &[DVec3]) -> Vec<Option<f64>> {
    match Promolecule::new(&doc.molecule) {
        Ok(p) => summed_at(&[&p], quantity, points).into_iter().map(Some).collect(),
        Err(_) => vec![None; points.len()],
    }
}

/// `quantity` of the sum of `sources` at `points`.
fn summed_at(sources: &[&dyn DensitySource], quantity: Quantity, points: &[DVec3]) -> Vec<f64> {
    use rayon::prelude::*;
    points
        .par_chunks(256)
        .flat_map_iter(|chunk| {
            let mut total = vec![nci::DensityDerivatives::default(); chunk.len()];
            let mut part = total.clone();
            for s in sources {
                s.derivatives_at(chunk, &mut part);
                total.iter_mut().zip(&part).for_each(|(t, p)| t.add(p));
            }
            total.into_iter().map(move |d| d.quantity(quantity))
        })
        .collect()
}
