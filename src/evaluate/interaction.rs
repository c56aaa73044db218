//! Non-covalent interactions of several densities, and of structures without a wavefunction:
//! an object's density (its wavefunction's, or its spherical atoms' — the promolecular
//! density, [`Promolecule`]) with other files' added as fragments, or split into a selection
//! of its atoms and the rest (a ligand and its pocket); the NCI quantities made of the sum's
//! derivatives, on a grid around the atoms, or around the smaller part when only what lies
//! between the fragments is kept (NCIPLOT's intermolecular mode).

use glam::DVec3;

use crate::model::nci::{
    self, CUT_VALUE, DensityDerivatives, DensitySource, INTERMOLECULAR_SHARE, NCI_CLOUD_LEVEL, NciSettings,
    PROMOLECULAR_DENSITY_CUT, WAVEFUNCTION_DENSITY_CUT, WavefunctionDensity,
};
use crate::model::orbitals::Quantity;
use crate::model::promolecular::Promolecule;
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::model::{Document, GridSpec, Molecule, VolumeGrid};
use crate::scene::quantity::{Fragments, PROMOLECULAR_NCI_LEVEL};
use crate::scene::selection::Selection;

/// Space around all the atoms (NCIPLOT's 0.75 Å), and around the smaller part when only what
/// lies between the parts is kept: contacts reach ~4 Å, so their surfaces lie within 2.5 Å of
/// its atoms.
const MARGIN_ANGSTROM: f64 = nci::NCIPLOT_MARGIN_ANGSTROM;
const BETWEEN_MARGIN_ANGSTROM: f64 = 2.5;

/// The grid step spherical atoms' surfaces need at most (Å): a hydrogen bond's disc of low s
/// is about 0.5 Å across, and a coarser grid misses it (NCIPLOT's coarse grid is 0.15 Å).
const STEP_ANGSTROM: f64 = 0.2;

/// Points along a grid's longest side at most: a whole protein's box is evaluated at a coarser
/// step rather than with more than ~7·10⁶ points.
const MAX_SIDE: usize = 192;

/// Whose densities an interaction sums: the files' wavefunctions, or their spherical atoms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Wavefunction,
    Spherical,
}

impl Kind {
    /// Points whose summed ρ is above this are cut (NCIPLOT's choices).
    fn density_cut(self) -> f64 {
        match self {
            Kind::Wavefunction => WAVEFUNCTION_DENSITY_CUT,
            Kind::Spherical => PROMOLECULAR_DENSITY_CUT,
        }
    }

    /// The s below which the NCI cloud shows.
    fn cloud_level(self) -> f32 {
        match self {
            Kind::Wavefunction => NCI_CLOUD_LEVEL as f32,
            Kind::Spherical => PROMOLECULAR_NCI_LEVEL,
        }
    }
}

/// Which interaction `source` of an object whose NCI quantities add `fragments` is, and its
/// quantity: a structure's spherical atoms, or a wavefunction's density quantity with other
/// fragments. `None` for every other source (the document's own evaluation).
pub fn of_source(source: crate::scene::Source, fragments: &Fragments) -> Option<(Kind, Quantity)> {
    use crate::scene::Source;
    match source {
        Source::Promolecular(q) => Some((Kind::Spherical, q)),
        Source::Wavefunction(q) if !fragments.is_empty() && crate::scene::quantity::is_promolecular(q) => {
            Some((Kind::Wavefunction, q))
        }
        _ => None,
    }
}

/// One part's density.
enum Density<'a> {
    Spherical(Promolecule),
    Wavefunction(Box<WavefunctionDensity<'a>>),
}

impl DensitySource for Density<'_> {
    fn derivatives_at(&self, points: &[DVec3], out: &mut [DensityDerivatives]) {
        match self {
            Density::Spherical(p) => p.derivatives_at(points, out),
            Density::Wavefunction(w) => w.derivatives_at(points, out),
        }
    }
}

/// The parts whose densities add, and the box the grid covers (bohr).
struct Parts<'a> {
    kind: Kind,
    densities: Vec<Density<'a>>,
    /// Only the points where no part holds almost all of the density are kept.
    between_only: bool,
    lo: DVec3,
    hi: DVec3,
}

impl Parts<'_> {
    fn sources(&self) -> Vec<&dyn DensitySource> {
        self.densities.iter().map(|d| d as &dyn DensitySource).collect()
    }

    /// NCIPLOT's two grids of the parts' summed density on `spec`: every s kept (capped at
    /// [`CUT_VALUE`]) where ρ is below the cut and, between parts, no part holds almost all of
    /// it.
    fn nci_grids(&self, spec: &GridSpec) -> nci::NciGrids {
        let settings = NciSettings {
            density_cut: self.kind.density_cut(),
            rdg_cut: CUT_VALUE as f64,
            intermolecular: self.between_only.then_some(INTERMOLECULAR_SHARE),
        };
        nci::nci_grid(&self.sources(), spec, settings)
    }

    /// The grid of [`grid`]: spherical atoms `points` along the box's longest side or
    /// [`STEP_ANGSTROM`] apart, whichever is finer (at most [`MAX_SIDE`] a side); wavefunctions
    /// `points` along it (each point costs every occupied orbital's derivatives).
    fn spec(&self, points: usize) -> GridSpec {
        let side = match self.kind {
            Kind::Spherical => {
                let longest = (self.hi - self.lo).max_element();
                let fine = (longest / (STEP_ANGSTROM * BOHR_PER_ANGSTROM)).ceil() as usize + 1;
                fine.max(points).min(MAX_SIDE)
            }
            Kind::Wavefunction => points,
        };
        GridSpec::cubic_voxels(self.lo, self.hi, side)
    }
}

/// The parts of `doc`'s interaction as `fragments` asks: its density alone, its selection and
/// the rest, or its density and `others`' (the files `fragments.files` names, found open), each
/// of `kind`. Errors name what is wrong: a query that does not parse or picks no atom or every
/// atom, a file that is not open or has no wavefunction, an element with no atomic density.
fn parts<'a>(
    doc: &'a Document,
    kind: Kind,
    fragments: &Fragments,
    others: &'a [std::sync::Arc<Document>],
) -> Result<Parts<'a>, String> {
    let molecule = &doc.molecule;
    let density = |name: &str, d: &'a Document, molecule: Option<Molecule>| -> Result<Density<'a>, String> {
        match (kind, &d.wavefunction) {
            (Kind::Wavefunction, Some(wf)) => Ok(Density::Wavefunction(Box::new(WavefunctionDensity::new(wf)))),
            (Kind::Wavefunction, None) => Err(format!(
                "{name}: no wavefunction, so its density does not add to {}'s (a structure's spherical atoms add to another structure's)",
                doc.source
            )),
            (Kind::Spherical, _) => Promolecule::new(molecule.as_ref().unwrap_or(&d.molecule))
                .map(Density::Spherical)
                .map_err(|e| format!("{name}: {e}")),
        }
    };
    let margin = |m: f64| DVec3::splat(m * BOHR_PER_ANGSTROM);
    if let Some(query) = fragments.selection.as_deref().map(str::trim).filter(|q| !q.is_empty()) {
        if kind == Kind::Wavefunction {
            return Err(format!(
                "{}: a selection splits a structure's spherical atoms; a wavefunction's fragments are files of their own",
                doc.source
            ));
        }
        let selection = Selection::parse(query).map_err(|e| format!("between `{query}`: expected {e}"))?;
        let mask = selection.mask(molecule, doc.structure.as_ref());
        let picked = mask.iter().filter(|&&m| m).count();
        if selection.is_everything() || picked == 0 || picked == mask.len() {
            return Err(format!(
                "between `{query}`: it picks {picked} of {} atoms; the interaction needs atoms on both sides",
                mask.len()
            ));
        }
        let part = |keep: bool| Molecule {
            atoms: (molecule.atoms.iter().zip(&mask)).filter(|(_, m)| **m == keep).map(|(a, _)| a.clone()).collect(),
            ..Molecule::default()
        };
        let (selected, rest) = (part(true), part(false));
        let (lo, hi) = selected.bounds().ok_or_else(|| format!("{}: no atoms", doc.source))?;
        let densities = vec![density(&doc.source, doc, Some(selected))?, density(&doc.source, doc, Some(rest))?];
        let m = margin(BETWEEN_MARGIN_ANGSTROM);
        return Ok(Parts { kind, densities, between_only: true, lo: lo - m, hi: hi + m });
    }
    let mut members = vec![doc];
    for file in &fragments.files {
        let other = others.iter().find(|o| &o.source == file).ok_or_else(|| {
            format!("{file}: the fragment is not open (open it to add its density to {}'s)", doc.source)
        })?;
        members.push(other);
    }
    let densities = members.iter().map(|d| density(&d.source, d, None)).collect::<Result<Vec<_>, String>>()?;
    let bounds = |d: &Document| d.molecule.bounds().ok_or_else(|| format!("{}: no atoms", d.source));
    let between_only = fragments.between_only && members.len() > 1;
    let (lo, hi, m) = if between_only {
        // Around the smallest fragment: what lies between it and the others.
        let smallest = members.iter().min_by_key(|d| d.molecule.atoms.len()).copied().unwrap_or(doc);
        let (lo, hi) = bounds(smallest)?;
        (lo, hi, margin(BETWEEN_MARGIN_ANGSTROM))
    } else {
        let mut all = bounds(doc)?;
        for d in &members[1..] {
            let (lo, hi) = bounds(d)?;
            all = (all.0.min(lo), all.1.max(hi));
        }
        (all.0, all.1, margin(MARGIN_ANGSTROM))
    };
    Ok(Parts { kind, densities, between_only, lo: lo - m, hi: hi + m })
}

/// What a picture of a structure's spherical atoms should say beside it: a structure without
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

/// Whether [`grid`] can be made: the error it would give, without evaluating anything.
pub fn check(
    doc: &Document,
    kind: Kind,
    fragments: &Fragments,
    others: &[std::sync::Arc<Document>],
) -> Result<(), String> {
    parts(doc, kind, fragments, others).map(|_| ())
}

/// `quantity` of the summed densities of `doc`'s interaction (of `kind`, as `fragments` asks,
/// `others` the open files they may name) on a grid of cubic voxels ([`Parts::spec`]): the NCI
/// surface's s ([`CUT_VALUE`] where ρ is above the cut or, between parts, where one part holds
/// nearly all of it), the NCI cloud (sign(λ₂)ρ weighted by how far s lies below the cloud's
/// level, 0 where cut), sign(λ₂)ρ, s, or ρ.
pub fn grid(
    doc: &Document,
    kind: Kind,
    fragments: &Fragments,
    others: &[std::sync::Arc<Document>],
    quantity: Quantity,
    points: usize,
) -> Result<VolumeGrid, String> {
    let parts = parts(doc, kind, fragments, others)?;
    let spec = parts.spec(points);
    let values = match quantity {
        Quantity::NciGradient => parts.nci_grids(&spec).grad,
        Quantity::NciCloud => {
            let grids = parts.nci_grids(&spec);
            let level = kind.cloud_level();
            let cloud = |(&dens, &s): (&f32, &f32)| match s < level {
                true => dens / 100.0 * (1.0 - s / level),
                false => 0.0,
            };
            grids.dens.iter().zip(&grids.grad).map(cloud).collect()
        }
        _ => {
            let points = super::arithmetic::grid_points(spec.dims, |i, j, k| spec.point(i, j, k));
            nci::summed_quantity_at(&parts.sources(), quantity, &points).into_iter().map(|v| v as f32).collect()
        }
    };
    let label = match kind {
        Kind::Spherical => crate::scene::Source::Promolecular(quantity).name(doc),
        Kind::Wavefunction => crate::scene::Source::Wavefunction(quantity).name(doc),
    };
    Ok(VolumeGrid::new(label, spec.dims, spec.world_from_grid, values))
}

/// NCIPLOT's two grids ([`nci::NciGrids`]: 100·sign(λ₂)ρ and s) of the interaction, as
/// [`grid`] cuts them, on cubic voxels `side` points along the box's longest side: what the NCI
/// plot shows.
pub fn nci_grids(
    doc: &Document,
    kind: Kind,
    fragments: &Fragments,
    others: &[std::sync::Arc<Document>],
    side: usize,
) -> Result<nci::NciGrids, String> {
    let parts = parts(doc, kind, fragments, others)?;
    Ok(parts.nci_grids(&GridSpec::cubic_voxels(parts.lo, parts.hi, side)))
}

/// `quantity` of the interaction's summed density at `points` (bohr): what colours its NCI
/// surface by sign(λ₂)ρ. `None` at every point when the parts cannot be made.
pub fn values_at(
    doc: &Document,
    kind: Kind,
    fragments: &Fragments,
    others: &[std::sync::Arc<Document>],
    quantity: Quantity,
    points: &[DVec3],
) -> Vec<Option<f64>> {
    match parts(doc, kind, fragments, others) {
        Ok(parts) => nci::summed_quantity_at(&parts.sources(), quantity, points).into_iter().map(Some).collect(),
        Err(_) => vec![None; points.len()],
    }
}

/// ρ's derivatives of the interaction's summed density at `point` (bohr), when its parts can
/// be made.
pub fn derivatives_at(
    doc: &Document,
    kind: Kind,
    fragments: &Fragments,
    others: &[std::sync::Arc<Document>],
    point: DVec3,
) -> Option<DensityDerivatives> {
    let parts = parts(doc, kind, fragments, others).ok()?;
    let mut total = DensityDerivatives::default();
    for s in parts.sources() {
        let mut d = [DensityDerivatives::default()];
        s.derivatives_at(&[point], &mut d);
        total.add(&d[0]);
    }
    Some(total)
}
