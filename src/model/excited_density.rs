//! An excited state's density beside the ground state's, and what Head-Gordon et al. (J. Phys.
//! Chem. 99, 14261 (1995)) make of their difference: ΔP = P_exc − P_gs, written in the Löwdin
//! basis (S^½ ΔP S^½) and diagonalised. Its eigenvectors taken back to the basis functions
//! (C = S^−½ U) are orbitals; the positive eigenvalues weigh the attachment density, the
//! negative ones the detachment density, and both integrate to the electrons moved.
//!
//! Every density here is therefore a set of orbitals with weights, Σ w |φ|², which is what the
//! density evaluators already sum: the difference density is the signed set, the attachment
//! and detachment densities its two halves, the excited state's density its natural orbitals.

use glam::DVec3;

use super::basis::Basis;
use super::eigen::symmetric_eigen_dense;
use super::gto::{GridSpec, PreparedBasis};
use super::molecule::Molecule;
use super::overlap::{moment_matrices, overlap_matrix};

/// Eigenvalues of S below this mark the basis as (nearly) linearly dependent: S^−½ would amplify
/// rounding noise, so those directions are left out.
const LINEAR_DEPENDENCE: f64 = 1e-10;

/// Natural orbitals below this weight contribute nothing worth evaluating.
const NEGLIGIBLE_WEIGHT: f64 = 1e-12;

/// Orbitals (coefficients over the basis functions) with weights: a density Σ w |φ|².
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WeightedOrbitals {
    pub weights: Vec<f64>,
    pub coefficients: Vec<Vec<f64>>,
}

impl WeightedOrbitals {
    /// The orbitals whose weight `keep` accepts, with the weight it returns: what the grid and
    /// point evaluators take.
    pub fn sets(&self, keep: impl Fn(f64) -> Option<f64>) -> Vec<(&[f64], f64)> {
        self.weights
            .iter()
            .zip(&self.coefficients)
            .filter_map(|(&w, c)| keep(w).filter(|v| v.abs() > NEGLIGIBLE_WEIGHT).map(|v| (c.as_slice(), v)))
            .collect()
    }
}

/// Which density of an excited state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StatePart {
    /// ρ_exc − ρ_gs (signed).
    Difference,
    /// Where the electrons go: the positive eigenvalues of the difference.
    Attachment,
    /// Where they come from: the negative eigenvalues, as a positive density.
    Detachment,
    /// The excited state's own density.
    Excited,
}

/// An excited state's density matrix with the ground state's, and their natural orbitals.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExcitedDensity {
    /// The state (1-based, as the program numbers it).
    pub state: usize,
    /// Where the density comes from ("Total CI Rho(1) Density").
    pub source: String,
    /// Basis functions.
    pub n: usize,
    /// P_gs and P_exc, full symmetric n × n, row-major, in the model's function order.
    pub ground: Vec<f64>,
    pub excited: Vec<f64>,
    /// The difference density's natural orbitals: weights λ (ascending), signed.
    pub difference: WeightedOrbitals,
    /// The excited state's natural orbitals, weights its occupations.
    pub natural: WeightedOrbitals,
}

impl ExcitedDensity {
    /// Builds the natural orbitals of P_exc − P_gs and of P_exc over `basis` (the matrices
    /// full, row-major, in the basis's function order).
    pub fn new(state: usize, source: &str, basis: &Basis, ground: Vec<f64>, excited: Vec<f64>) -> Result<Self, String> {
        let n = basis.n_functions();
        if ground.len() != n * n || excited.len() != n * n {
            return Err(format!(
                "density matrices of {} and {} values for {n} basis functions",
                ground.len(),
                excited.len()
            ));
        }
        let s = overlap_matrix(basis);
        let (half, inverse_half) = lowdin(&s, n);
        let delta: Vec<f64> = excited.iter().zip(&ground).map(|(e, g)| e - g).collect();
        let difference = natural_orbitals(&delta, &half, &inverse_half, n);
        let natural = natural_orbitals(&excited, &half, &inverse_half, n);
        Ok(Self { state, source: source.to_string(), n, ground, excited, difference, natural })
    }

    /// The orbitals and weights whose Σ w |φ|² is `part`.
    pub fn sets(&self, part: StatePart) -> Vec<(&[f64], f64)> {
        match part {
            StatePart::Difference => self.difference.sets(Some),
            StatePart::Attachment => self.difference.sets(|w| (w > 0.0).then_some(w)),
            StatePart::Detachment => self.difference.sets(|w| (w < 0.0).then_some(-w)),
            StatePart::Excited => self.natural.sets(Some),
        }
    }

    /// Electrons the excitation moves: the attachment's integral, Σ λ over λ > 0.
    pub fn electrons_moved(&self) -> f64 {
        self.difference.weights.iter().filter(|&&w| w > 0.0).sum()
    }

    /// The detachment's integral, −Σ λ over λ < 0 (equal to [`Self::electrons_moved`] when
    /// both densities hold the same electrons).
    pub fn electrons_detached(&self) -> f64 {
        -self.difference.weights.iter().filter(|&&w| w < 0.0).sum::<f64>()
    }
}

/// S^½ and S^−½ (row-major) from S's eigenvectors; directions of S below
/// [`LINEAR_DEPENDENCE`] are dropped from both.
fn lowdin(s: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let (values, vectors) = symmetric_eigen_dense(s, n);
    let mut half = vec![0.0; n * n];
    let mut inverse = vec![0.0; n * n];
    for (&value, u) in values.iter().zip(&vectors) {
        if value < LINEAR_DEPENDENCE {
            continue;
        }
        let (r, ri) = (value.sqrt(), 1.0 / value.sqrt());
        for i in 0..n {
            for j in 0..n {
                let uu = u[i] * u[j];
                half[i * n + j] += r * uu;
                inverse[i * n + j] += ri * uu;
            }
        }
    }
    (half, inverse)
}

/// a · b for row-major n × n matrices.
fn multiply(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut out = vec![0.0; n * n];
    for i in 0..n {
        for k in 0..n {
            let aik = a[i * n + k];
            if aik == 0.0 {
                continue;
            }
            for (o, &bkj) in out[i * n..(i + 1) * n].iter_mut().zip(&b[k * n..(k + 1) * n]) {
                *o += aik * bkj;
            }
        }
    }
    out
}

/// The eigenpairs of S^½ P S^½, the eigenvectors taken back to the basis functions by S^−½:
/// orbitals orthonormal over S whose weighted sum of outer products is P.
fn natural_orbitals(p: &[f64], half: &[f64], inverse_half: &[f64], n: usize) -> WeightedOrbitals {
    let orthonormal = multiply(&multiply(half, p, n), half, n);
    let (weights, vectors) = symmetric_eigen_dense(&orthonormal, n);
    let coefficients = vectors
        .iter()
        .map(|u| (0..n).map(|i| (0..n).map(|j| inverse_half[i * n + j] * u[j]).sum()).collect())
        .collect();
    WeightedOrbitals { weights, coefficients }
}

/// What the attachment and detachment densities tell of an excitation.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Descriptors {
    /// The state they belong to.
    pub state: usize,
    /// Σ λ over λ > 0: the attachment's electrons, the electrons the excitation moves.
    pub electrons_moved: f64,
    /// −Σ λ over λ < 0: the detachment's electrons (the same number: tr(ΔP S) = 0).
    pub electrons_detached: f64,
    /// Centroids ∫ r ρ / ∫ ρ of the attachment and detachment densities (bohr), from the
    /// basis functions' dipole integrals (exact), and the distance between them.
    pub attachment_centroid_bohr: [f64; 3],
    pub detachment_centroid_bohr: [f64; 3],
    pub centroid_distance_bohr: f64,
    /// ∫ √(ρ_att ρ_det) over the electrons moved, and the grid's own integrals (see
    /// [`GridDescriptors`]).
    pub grid: GridDescriptors,
}

/// What a grid over the attachment and detachment densities tells of an excitation.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct GridDescriptors {
    /// ∫ ρ_att and ∫ ρ_det on the grid (each should be the electrons moved).
    pub attachment_integral: f64,
    pub detachment_integral: f64,
    /// Their centroids ∫ r ρ / ∫ ρ (bohr) and the distance between them.
    pub attachment_centroid: [f64; 3],
    pub detachment_centroid: [f64; 3],
    pub centroid_distance_bohr: f64,
    /// ∫ √(ρ_att ρ_det) over the electrons moved: 1 when both densities coincide, 0 when they
    /// never meet (Multiwfn's Sr of hole and electron, for attachment and detachment).
    pub overlap: f64,
    /// The grid: points per axis and spacing (bohr).
    pub grid_points: [usize; 3],
    pub spacing_bohr: f64,
}

/// Space around the atoms the descriptors' grid covers (bohr): the densities of valence
/// excitations have decayed by 10⁻⁵ of their peak there.
pub const DESCRIPTOR_MARGIN: f64 = 6.0;

/// The descriptors' grid spacing (bohr), made coarser when a large molecule would need more than
/// [`DESCRIPTOR_POINTS`] points.
pub const DESCRIPTOR_SPACING: f64 = 0.2;
pub const DESCRIPTOR_POINTS: usize = 4_000_000;

impl ExcitedDensity {
    /// ∫ r ρ / ∫ ρ of `part` (bohr) from the dipole matrices `moments` of the basis.
    pub fn centroid(&self, part: StatePart, moments: &[Vec<f64>; 3]) -> DVec3 {
        weighted_centroid(&self.sets(part), moments, self.n)
    }

    /// Every descriptor of the excitation: electrons moved, exact centroids from the dipole
    /// integrals of `basis`, and the grid's overlap ([`Self::grid_descriptors`]). `None`
    /// without atoms.
    pub fn descriptors(&self, basis: &Basis, molecule: &Molecule) -> Option<Descriptors> {
        let grid = self.grid_descriptors(&PreparedBasis::new(basis), molecule)?;
        let moments = moment_matrices(basis);
        let (a, d) = (self.centroid(StatePart::Attachment, &moments), self.centroid(StatePart::Detachment, &moments));
        Some(Descriptors {
            state: self.state,
            electrons_moved: self.electrons_moved(),
            electrons_detached: self.electrons_detached(),
            attachment_centroid_bohr: a.to_array(),
            detachment_centroid_bohr: d.to_array(),
            centroid_distance_bohr: a.distance(d),
            grid,
        })
    }

    /// Integrals of the attachment and detachment densities on a grid over `molecule` (the
    /// atoms' box plus [`DESCRIPTOR_MARGIN`], spacing [`DESCRIPTOR_SPACING`] or coarser):
    /// their electrons, centroids, the centroids' distance and the densities' overlap. `None`
    /// without atoms.
    pub fn grid_descriptors(&self, basis: &PreparedBasis, molecule: &Molecule) -> Option<GridDescriptors> {
        let (att, det) = (self.sets(StatePart::Attachment), self.sets(StatePart::Detachment));
        pair_descriptors(basis, molecule, &att, &det, self.electrons_moved())
    }
}

/// ∫ r ρ / ∫ ρ (bohr) of the density Σ w |φ|² of `sets` (coefficients over `n` basis functions
/// with their weights), from the basis's dipole matrices `moments`.
pub fn weighted_centroid(sets: &[(&[f64], f64)], moments: &[Vec<f64>; 3], n: usize) -> DVec3 {
    let electrons: f64 = sets.iter().map(|(_, w)| w).sum();
    let first = moments.each_ref().map(|x| {
        (sets.iter())
            .map(|(c, w)| {
                let quadratic: f64 = (0..n).map(|i| c[i] * (0..n).map(|j| x[i * n + j] * c[j]).sum::<f64>()).sum();
                w * quadratic
            })
            .sum::<f64>()
    });
    DVec3::from_array(first) / electrons.max(f64::MIN_POSITIVE)
}

/// Integrals of two densities made of weighted orbitals (`gain`: where electrons go, `loss`:
/// whence they come: attachment and detachment, or an excitation's electron and hole) on a grid
/// over `molecule` (the atoms' box plus [`DESCRIPTOR_MARGIN`], spacing [`DESCRIPTOR_SPACING`] or
/// coarser): their electrons, centroids, the centroids' distance and their overlap
/// ∫√(ρ₁ρ₂) over `electrons`. `None` without atoms.
pub fn pair_descriptors(
    basis: &PreparedBasis,
    molecule: &Molecule,
    gain: &[(&[f64], f64)],
    loss: &[(&[f64], f64)],
    electrons: f64,
) -> Option<GridDescriptors> {
    let (lo, hi) = molecule.bounds()?;
    let (lo, hi) = (lo - DVec3::splat(DESCRIPTOR_MARGIN), hi + DVec3::splat(DESCRIPTOR_MARGIN));
    let extent = hi - lo;
    let mut h = DESCRIPTOR_SPACING;
    while ((extent.x / h) as usize + 1) * ((extent.y / h) as usize + 1) * ((extent.z / h) as usize + 1)
        > DESCRIPTOR_POINTS
    {
        h *= 1.25;
    }
    let spec = GridSpec::spaced(lo, hi, h);
    let att = basis.weighted_density_grid(gain, &spec);
    let det = basis.weighted_density_grid(loss, &spec);
    let volume = h * h * h;
    let (mut na, mut nd, mut overlap) = (0.0, 0.0, 0.0);
    let (mut ra, mut rd) = (DVec3::ZERO, DVec3::ZERO);
    let d = spec.dims;
    for i in 0..d[0] {
        for j in 0..d[1] {
            for k in 0..d[2] {
                let idx = (i * d[1] + j) * d[2] + k;
                let p = spec.point(i, j, k);
                let (a, b) = (att[idx].max(0.0), det[idx].max(0.0));
                na += a;
                nd += b;
                ra += a * p;
                rd += b * p;
                overlap += (a * b).sqrt();
            }
        }
    }
    let (ca, cd) = (ra / na.max(f64::MIN_POSITIVE), rd / nd.max(f64::MIN_POSITIVE));
    Some(GridDescriptors {
        attachment_integral: na * volume,
        detachment_integral: nd * volume,
        attachment_centroid: ca.to_array(),
        detachment_centroid: cd.to_array(),
        centroid_distance_bohr: ca.distance(cd),
        overlap: overlap * volume / electrons.max(f64::MIN_POSITIVE),
        grid_points: d,
        spacing_bohr: h,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::basis::{Shell, ShellKind};

    /// Two s functions on two centres: a ground state with one orbital doubly occupied, an
    /// "excited" state with one electron moved to the other: ΔP's natural orbitals carry +1 and
    /// −1, tr(ΔP S) = 0, and the matrices rebuild from the orbitals.
    #[test]
    fn one_electron_moved_between_two_centres() {
        let s = |x: f64| Shell {
            atom: 0,
            center: DVec3::new(x, 0.0, 0.0),
            l: 0,
            kind: ShellKind::Cartesian,
            exponents: vec![0.8],
            coefficients: vec![1.0],
        };
        let basis = Basis { shells: vec![s(0.0), s(1.4)] };
        let sm = overlap_matrix(&basis);
        let s12 = sm[1];
        // Bonding and antibonding orbitals, normalised over S.
        let b = 1.0 / (2.0 + 2.0 * s12).sqrt();
        let a = 1.0 / (2.0 - 2.0 * s12).sqrt();
        let (bond, anti) = ([b, b], [a, -a]);
        let outer = |c: [f64; 2], w: f64| -> Vec<f64> { (0..4).map(|k| w * c[k / 2] * c[k % 2]).collect() };
        let ground = outer(bond, 2.0);
        let excited: Vec<f64> = outer(bond, 1.0).iter().zip(outer(anti, 1.0)).map(|(x, y)| x + y).collect();
        let d = ExcitedDensity::new(1, "test", &basis, ground.clone(), excited.clone()).unwrap();
        assert!((d.electrons_moved() - 1.0).abs() < 1e-12, "{:?}", d.difference.weights);
        assert!((d.electrons_detached() - 1.0).abs() < 1e-12);
        let trace: f64 = (0..4).map(|k| (excited[k] - ground[k]) * sm[k]).sum();
        assert!(trace.abs() < 1e-12);
        // The attachment's one orbital is the antibonding one (up to sign).
        let att = d.sets(StatePart::Attachment);
        assert_eq!(att.len(), 1);
        assert!((att[0].0[0].abs() - a).abs() < 1e-10 && (att[0].0[0] + att[0].0[1]).abs() < 1e-10, "{att:?}");
        // The excited density's natural orbitals rebuild P_exc.
        for i in 0..2 {
            for j in 0..2 {
                let p: f64 = d.sets(StatePart::Excited).iter().map(|(c, w)| w * c[i] * c[j]).sum();
                assert!((p - excited[i * 2 + j]).abs() < 1e-12);
            }
        }
    }
}
