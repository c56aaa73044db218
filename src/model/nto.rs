//! Natural transition orbitals (Martin, JCP 118, 4775 (2003)) from the transition amplitudes a
//! program prints for a state: the amplitudes T (occupied × virtual) = U Σ Vᵀ; hole k = C_occ U_k,
//! particle k = C_virt V_k, weight σ_k² over Σσ² (as PySCF's `get_nto` renormalises X). A log
//! prints only the amplitudes above its threshold (Gaussian: |c| ≥ 0.1 by default, lower with
//! IOp(9/40)), so these are the NTOs of the printed part, which [`Ntos::printed_norm`] measures.
//! The hole and electron densities of the hole–electron analysis are Σ_k σ_k² |h_k|² and
//! Σ_k σ_k² |p_k|²: the NTO document's orbitals carry their weights as occupations.

use super::Document;
use super::eigen::symmetric_eigen_dense;
use super::excited::ExcitedState;
use super::orbitals::{MolecularOrbital, Spin, Wavefunction};

/// Pairs kept: beyond these the weights of printed amplitudes are noise.
pub const MAX_PAIRS: usize = 5;

/// Weights below this are left out (a state of one transition has one pair).
const SMALLEST_WEIGHT: f64 = 1e-4;

/// One hole–particle pair.
#[derive(Debug, Clone, PartialEq)]
pub struct NtoPair {
    /// σ² over Σσ² (both spins of an unrestricted state together).
    pub weight: f64,
    pub spin: Spin,
    /// Coefficients over the basis functions.
    pub hole: Vec<f64>,
    pub particle: Vec<f64>,
}

/// A state's natural transition orbitals, heaviest first.
#[derive(Debug, Clone, PartialEq)]
pub struct Ntos {
    /// The state's number, as the program numbers it.
    pub state: usize,
    pub pairs: Vec<NtoPair>,
    /// Σ of the printed de-excitation-free amplitudes squared (Gaussian's singlets: 0.5 when
    /// every amplitude is printed; less where small ones are left out).
    pub printed_norm: f64,
}

/// The natural transition orbitals of `state` from its printed amplitudes (the excitations,
/// `->`; PySCF's `get_nto` uses X alone too) over `wf`'s orbitals, numbered within their spin.
/// `None` when the state prints no transition or names an orbital the wavefunction lacks.
pub fn from_transitions(wf: &Wavefunction, state: &ExcitedState) -> Option<Ntos> {
    let excitations: Vec<_> = state.transitions.iter().filter(|t| !t.deexcitation).collect();
    if excitations.is_empty() {
        return None;
    }
    let spins: &[Spin] = if wf.restricted { &[Spin::Alpha] } else { &[Spin::Alpha, Spin::Beta] };
    let mut pairs = Vec::new();
    let mut total = 0.0;
    for &spin in spins {
        let label = if wf.restricted { None } else { Some(if spin == Spin::Alpha { "alpha" } else { "beta" }) };
        let ours: Vec<_> = excitations.iter().filter(|t| label.is_none_or(|l| t.spin == l)).collect();
        if ours.is_empty() {
            continue;
        }
        // Orbitals of this spin in the program's numbering (1-based within the spin).
        let orbitals: Vec<usize> = wf.of_spin(spin).map(|(i, _)| i).collect();
        let mut occupied: Vec<usize> = ours.iter().map(|t| t.from).collect();
        let mut virtuals: Vec<usize> = ours.iter().map(|t| t.to).collect();
        for list in [&mut occupied, &mut virtuals] {
            list.sort_unstable();
            list.dedup();
        }
        if occupied.iter().chain(&virtuals).any(|&n| n == 0 || n > orbitals.len()) {
            return None;
        }
        let (no, nv) = (occupied.len(), virtuals.len());
        let mut t = vec![0.0; no * nv];
        for tr in &ours {
            let i = occupied.binary_search(&tr.from).ok()?;
            let a = virtuals.binary_search(&tr.to).ok()?;
            t[i * nv + a] += tr.coefficient;
        }
        total += t.iter().map(|x| x * x).sum::<f64>();
        // T Tᵀ = U Σ² Uᵀ; V_k = Tᵀ U_k / σ_k.
        let mut ttt = vec![0.0; no * no];
        for i in 0..no {
            for j in 0..=i {
                ttt[i * no + j] = (0..nv).map(|a| t[i * nv + a] * t[j * nv + a]).sum();
            }
        }
        let (values, vectors) = symmetric_eigen_dense(&ttt, no);
        for (s2, u) in values.iter().zip(&vectors).rev() {
            if *s2 <= 0.0 {
                continue;
            }
            let sigma = s2.sqrt();
            let v: Vec<f64> = (0..nv).map(|a| (0..no).map(|i| t[i * nv + a] * u[i]).sum::<f64>() / sigma).collect();
            let combine = |weights: &[f64], numbers: &[usize]| -> Vec<f64> {
                let n = wf.basis.n_functions();
                let mut c = vec![0.0; n];
                for (w, &k) in weights.iter().zip(numbers) {
                    for (ci, x) in c.iter_mut().zip(&wf.orbitals[orbitals[k - 1]].coefficients) {
                        *ci += w * x;
                    }
                }
                c
            };
            // Signs fixed as PySCF's get_nto fixes them: each vector's largest MO coefficient
            // positive.
            let positive = |w: &[f64]| {
                let largest = w.iter().copied().fold(0.0f64, |m, x| if x.abs() > m.abs() { x } else { m });
                let sign = if largest < 0.0 { -1.0 } else { 1.0 };
                w.iter().map(|x| sign * x).collect::<Vec<f64>>()
            };
            let (hole, particle) = (combine(&positive(u), &occupied), combine(&positive(&v), &virtuals));
            pairs.push(NtoPair { weight: *s2, spin, hole, particle });
        }
    }
    if total <= 0.0 || pairs.is_empty() {
        return None;
    }
    for p in &mut pairs {
        p.weight /= total;
    }
    pairs.sort_by(|a, b| b.weight.total_cmp(&a.weight));
    pairs.retain(|p| p.weight >= SMALLEST_WEIGHT);
    pairs.truncate(MAX_PAIRS);
    Some(Ntos { state: state.number, pairs, printed_norm: total })
}

impl Ntos {
    /// A document of these orbitals, as `doc`'s atoms and basis: hole 1, particle 1, hole 2, …
    /// (their labels), each occupied by its pair's weight, so that its density is the hole plus
    /// the electron density of the hole–electron analysis.
    pub fn document(&self, doc: &Document) -> Option<Document> {
        let wf = doc.wavefunction.as_ref()?;
        let mut orbitals = Vec::with_capacity(2 * self.pairs.len());
        let restricted = self.pairs.iter().all(|p| p.spin == Spin::Alpha);
        for (k, p) in self.pairs.iter().enumerate() {
            for (kind, coefficients) in [("hole", &p.hole), ("particle", &p.particle)] {
                orbitals.push(MolecularOrbital {
                    energy: f64::NAN,
                    occupation: p.weight,
                    spin: if restricted { Spin::Alpha } else { p.spin },
                    symmetry: format!("{kind} {}", k + 1),
                    coefficients: coefficients.clone(),
                });
            }
        }
        // Unrestricted: alpha orbitals first, as every reader keeps them.
        orbitals.sort_by_key(|o| o.spin == Spin::Beta);
        let wavefunction = Wavefunction {
            basis: wf.basis.clone(),
            orbitals,
            restricted: wf.restricted,
            normalization: wf.normalization.clone(),
            excited: None,
        };
        Some(Document {
            source: format!("{} (state {} NTOs)", doc.source, self.state),
            title: format!("state {}: natural transition orbitals", self.state),
            molecule: doc.molecule.clone(),
            wavefunction: Some(wavefunction),
            ..Document::default()
        })
    }
}

/// Whether an orbital is a natural transition orbital by its label ("hole 1", "particle 2").
pub fn is_nto_label(label: &str) -> bool {
    label.strip_prefix("hole ").or_else(|| label.strip_prefix("particle ")).is_some_and(|n| n.parse::<usize>().is_ok())
}

/// Where an excitation's hole and electron lie, from its natural transition orbitals: the hole
/// density Σ_k w_k |h_k|² and the electron density Σ_k w_k |p_k|² (Multiwfn's hole–electron
/// analysis, exact in the NTO basis where the amplitudes are whole).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct HoleElectron {
    /// ∫ r ρ / ∫ ρ of each (bohr), from the basis functions' dipole integrals.
    pub hole_centroid_bohr: [f64; 3],
    pub electron_centroid_bohr: [f64; 3],
    /// D: the distance between the centroids (bohr).
    pub distance_bohr: f64,
    /// Sr: ∫ √(ρ_hole ρ_electron), 1 when they coincide, 0 when they never meet, on the grid of
    /// [`super::excited_density::pair_descriptors`], and that grid's own centroids and integrals.
    pub overlap: f64,
    pub grid: super::excited_density::GridDescriptors,
}

impl Ntos {
    /// The hole and electron densities' centroids ∫ r ρ / ∫ ρ (bohr), from the dipole integrals
    /// of `basis` (the NTOs' own).
    pub fn centroids(&self, basis: &super::basis::Basis) -> (glam::DVec3, glam::DVec3) {
        let moments = super::overlap::moment_matrices(basis);
        let n = basis.n_functions();
        let of = |particle: bool| {
            let sets: Vec<(&[f64], f64)> = (self.pairs.iter())
                .map(|p| (if particle { p.particle.as_slice() } else { p.hole.as_slice() }, p.weight))
                .collect();
            super::excited_density::weighted_centroid(&sets, &moments, n)
        };
        (of(false), of(true))
    }

    /// The hole and electron densities' centroids, their distance and overlap, over `basis`
    /// (the NTOs' own) and `molecule`. `None` without atoms.
    pub fn hole_electron(&self, basis: &super::basis::Basis, molecule: &super::Molecule) -> Option<HoleElectron> {
        let holes: Vec<(&[f64], f64)> = self.pairs.iter().map(|p| (p.hole.as_slice(), p.weight)).collect();
        let electrons: Vec<(&[f64], f64)> = self.pairs.iter().map(|p| (p.particle.as_slice(), p.weight)).collect();
        let total: f64 = self.pairs.iter().map(|p| p.weight).sum();
        let prepared = super::gto::PreparedBasis::new(basis);
        let grid = super::excited_density::pair_descriptors(&prepared, molecule, &electrons, &holes, total)?;
        let (h, e) = self.centroids(basis);
        Some(HoleElectron {
            hole_centroid_bohr: h.to_array(),
            electron_centroid_bohr: e.to_array(),
            distance_bohr: h.distance(e),
            overlap: grid.overlap,
            grid,
        })
    }
}
