//! Non-covalent interactions (Johnson et al., JACS 132, 6498 (2010); NCIPLOT 4: Boto et al.,
//! JCTC 16, 4150 (2020)): the density with its gradient and Hessian at points, from a
//! wavefunction (analytic second derivatives of the basis functions) or from a promolecule
//! ([`super::promolecular`]); from them the reduced density gradient
//! s = |∇ρ| / (2(3π²)^{1/3} ρ^{4/3}), λ₂ (the Hessian's middle eigenvalue) and sign(λ₂)ρ, and
//! NCIPLOT's two grids (`-dens`: 100·sign(λ₂)ρ, `-grad`: s) for fragments whose densities add.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use super::cartesian::CartesianDensity;
use super::eigen::symmetric_eigen;
use super::grid::GridSpec;
use super::gto::{BLOCK, BlockScratch, DerivativeBlock, PreparedBasis};
use super::orbital_sums::{COMPONENTS, OccupiedOrbitals};
use super::orbitals::{Quantity, Wavefunction};

/// What NCIPLOT's cubes hold where a point is cut (ρ above the cut, or an intermolecular
/// point that one fragment owns): both `-dens` and `-grad` say 100, beyond any isosurface.
pub const CUT_VALUE: f32 = 100.0;

/// The reduced density gradient an NCI cloud fades out at (NCIPLOT's surface level for SCF
/// densities): [`Quantity::NciCloud`].
pub const NCI_CLOUD_LEVEL: f64 = 0.5;

/// The density cut of a wavefunction's density (NCIPLOT's default for SCF densities).
pub const WAVEFUNCTION_DENSITY_CUT: f64 = 0.05;

/// The density cut of a promolecular density (NCIPLOT's).
pub const PROMOLECULAR_DENSITY_CUT: f64 = 0.07;

/// NCIPLOT's intermolecular rule: a point belongs to the interaction between fragments when no
/// fragment holds more than this share of its density.
pub const INTERMOLECULAR_SHARE: f64 = 0.95;

/// 2(3π²)^{1/3}: s = |∇ρ| / (this · ρ^{4/3}).
pub fn rdg_factor() -> f64 {
    2.0 * (3.0 * std::f64::consts::PI * std::f64::consts::PI).cbrt()
}

/// ρ, ∇ρ and the Hessian of ρ at a point (a.u.).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DensityDerivatives {
    pub rho: f64,
    pub gradient: DVec3,
    pub hessian: [[f64; 3]; 3],
}

impl DensityDerivatives {
    /// The sum of two densities (fragments' densities add, and so do their derivatives).
    pub fn add(&mut self, other: &Self) {
        self.rho += other.rho;
        self.gradient += other.gradient;
        for (row, o) in self.hessian.iter_mut().zip(&other.hessian) {
            for (h, o) in row.iter_mut().zip(o) {
                *h += o;
            }
        }
    }

    /// The derivatives as the GPU writes them, in single precision: ρ, ∂xρ, ∂yρ, ∂zρ, then the
    /// Hessian's xx, xy, xz, yy, yz, zz.
    pub fn from_single(v: &[f32; 10]) -> Self {
        let h: [f64; 6] = std::array::from_fn(|k| v[4 + k] as f64);
        Self { rho: v[0] as f64, gradient: DVec3::new(v[1] as f64, v[2] as f64, v[3] as f64), hessian: symmetric(h) }
    }

    /// The reduced density gradient s; infinite where ρ ≤ 0 (s grows without bound as ρ → 0).
    pub fn reduced_gradient(&self) -> f64 {
        if self.rho <= 0.0 {
            return f64::INFINITY;
        }
        self.gradient.length() / (rdg_factor() * self.rho.powf(4.0 / 3.0))
    }

    /// The Hessian's eigenvalues, ascending.
    pub fn eigenvalues(&self) -> [f64; 3] {
        let (mut e, _) = symmetric_eigen(self.hessian, 50);
        e.sort_by(f64::total_cmp);
        e
    }

    /// λ₂, the middle eigenvalue of the Hessian.
    pub fn lambda2(&self) -> f64 {
        self.eigenvalues()[1]
    }

    /// Whether λ₂ < 0, without the eigenvalues where that is safe. The Hessian's eigenvalues
    /// are the roots of x³ − e₁x² + e₂x − e₃ (e₁ the trace, e₂ the sum of the principal 2×2
    /// minors, e₃ the determinant); all three are real, so by Descartes' rule as many are
    /// positive as the coefficients change sign, and λ₂ < 0 when at most one is. Where a
    /// coefficient is too close to 0 for its rounding to be sure of its sign (λ₂ near 0 among
    /// them), the eigenvalues decide.
    pub fn lambda2_is_negative(&self) -> bool {
        let [[a, b, c], [_, d, e], [_, _, f]] = self.hessian;
        let e1 = a + d + f;
        let e2 = a * d - b * b + a * f - c * c + d * f - e * e;
        let e3 = a * (d * f - e * e) - b * (b * f - e * c) + c * (b * e - d * c);
        let norm = (a * a + d * d + f * f + 2.0 * (b * b + c * c + e * e)).sqrt();
        let sure = |v: f64, scale: f64| v.abs() > 1e-8 * scale;
        if !(sure(e1, norm) && sure(e2, norm * norm) && sure(e3, norm * norm * norm)) {
            return self.lambda2() < 0.0;
        }
        let coefficients = [1.0, -e1, e2, -e3];
        coefficients.windows(2).filter(|w| (w[0] < 0.0) != (w[1] < 0.0)).count() <= 1
    }

    /// sign(λ₂)·ρ: negative in bonding regions (hydrogen bonds), positive in steric clashes.
    pub fn sign_lambda2_rho(&self) -> f64 {
        if self.lambda2_is_negative() { -self.rho } else { self.rho }
    }

    /// ∇²ρ, the Hessian's trace.
    pub fn laplacian(&self) -> f64 {
        self.hessian[0][0] + self.hessian[1][1] + self.hessian[2][2]
    }

    /// The quantity among those made of ρ's derivatives (NaN for any other).
    pub fn quantity(&self, quantity: Quantity) -> f64 {
        match quantity {
            Quantity::ReducedGradient => self.reduced_gradient(),
            Quantity::NciGradient => match self.rho > WAVEFUNCTION_DENSITY_CUT {
                true => CUT_VALUE as f64,
                false => self.reduced_gradient().min(CUT_VALUE as f64),
            },
            Quantity::NciCloud => {
                let depth = 1.0 - self.reduced_gradient() / NCI_CLOUD_LEVEL;
                match self.rho > WAVEFUNCTION_DENSITY_CUT || depth.is_nan() || depth <= 0.0 {
                    true => 0.0,
                    false => self.sign_lambda2_rho() * depth,
                }
            }
            Quantity::SignLambda2Rho => self.sign_lambda2_rho(),
            Quantity::DensityLaplacian => self.laplacian(),
            Quantity::Density => self.rho,
            _ => f64::NAN,
        }
    }
}

/// A density whose value and first and second derivatives can be had at points.
pub trait DensitySource: Sync {
    /// ρ and its derivatives at each of `points` (bohr), written to `out` (as long as `points`).
    /// Callers pass nearby points together (a few grid rows, in tiles: [`nci_grid`]): sources
    /// screen their centres once per call.
    fn derivatives_at(&self, points: &[DVec3], out: &mut [DensityDerivatives]);
}

/// A wavefunction's total density as a [`DensitySource`].
pub struct WavefunctionDensity<'a> {
    /// The wavefunction's basis as it is.
    pub basis: PreparedBasis,
    pub wavefunction: &'a Wavefunction,
    /// What the density is evaluated over: the basis contracted for the occupied orbitals
    /// ([`occupied_contraction`]).
    contracted: PreparedBasis,
    /// The occupied orbitals over `contracted`.
    orbitals: OccupiedOrbitals,
}

impl<'a> WavefunctionDensity<'a> {
    pub fn new(wavefunction: &'a Wavefunction) -> Self {
        Self::with_basis(PreparedBasis::new(&wavefunction.basis), wavefunction)
    }

    /// With `basis` already prepared for `wavefunction`'s basis.
    pub fn with_basis(basis: PreparedBasis, wavefunction: &'a Wavefunction) -> Self {
        let (coefficients, occupations) = occupied_matrix(&basis, wavefunction);
        let (contracted, coefficients) = occupied_contraction(&basis, &coefficients, occupations.len());
        let orbitals = OccupiedOrbitals::new(&coefficients, occupations);
        Self { basis, wavefunction, contracted, orbitals }
    }

    /// Basis functions the density is evaluated over (at most the basis's).
    pub fn contracted_functions(&self) -> usize {
        self.contracted.n_functions()
    }

    /// The occupied orbitals over the contracted basis written out as cartesian Gaussians
    /// (what the GPU evaluates; its density is this source's).
    pub fn cartesian(&self) -> CartesianDensity {
        let occupations = &self.orbitals.occupations;
        let columns: Vec<Vec<f64>> = (0..occupations.len())
            .map(|i| (0..self.contracted.n_functions()).map(|k| self.orbitals.coefficient(k, i)).collect())
            .collect();
        let sets: Vec<(&[f64], f64)> = columns.iter().map(Vec::as_slice).zip(occupations.iter().copied()).collect();
        CartesianDensity::new(&self.contracted, &sets)
    }
}

impl DensitySource for WavefunctionDensity<'_> {
    fn derivatives_at(&self, points: &[DVec3], out: &mut [DensityDerivatives]) {
        self.contracted.occupied_derivatives_into(&self.orbitals, points, out);
    }
}

/// Two shells' coefficient blocks are taken as proportional when they differ by no more than
/// this fraction of the larger block's largest coefficient after scaling: far below the 8–10
/// digits wavefunction files print.
pub const PROPORTIONAL: f64 = 1e-7;

/// `wf`'s occupied orbitals as a function-major matrix (row k: function k's coefficient in
/// each occupied orbital) and their occupations.
fn occupied_matrix(basis: &PreparedBasis, wf: &Wavefunction) -> (Vec<f64>, Vec<f64>) {
    let occupied: Vec<_> = wf.orbitals.iter().filter(|o| o.occupation != 0.0).collect();
    let n = occupied.len();
    let mut matrix = vec![0.0; basis.n_functions() * n];
    for (o, orbital) in occupied.iter().enumerate() {
        for (k, &c) in orbital.coefficients.iter().enumerate().take(basis.n_functions()) {
            matrix[k * n + o] = c;
        }
    }
    (matrix, occupied.iter().map(|o| o.occupation).collect())
}

/// The basis contracted for the occupied orbitals, and their coefficients over it: shells of
/// one centre, l and kind whose coefficient blocks (every function in every occupied orbital)
/// are proportional become one function set, Σ f_s χ_s with the block of the first shell
/// (within [`PROPORTIONAL`]), and shells no occupied orbital uses are left out. AIM files
/// (.wfn, .wfx) write each contraction's primitives as functions of their own whose
/// coefficients are the contraction's times the primitive's: this contracts them again, the
/// density unchanged (to the files' digits) at a third of the cost or less.
pub fn occupied_contraction(
    basis: &PreparedBasis,
    coefficients: &[f64],
    n_occupied: usize,
) -> (PreparedBasis, Vec<f64>) {
    let n = n_occupied;
    let block = |s: usize| {
        let shell = &basis.shells[s];
        &coefficients[shell.first_function as usize * n..(shell.first_function + shell.n_functions) as usize * n]
    };
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let mut groups: Vec<Vec<(usize, f64)>> = Vec::new();
    let mut by_kind: HashMap<([u64; 3], u32, bool), Vec<usize>> = HashMap::new();
    for (s, shell) in basis.shells.iter().enumerate() {
        let b = block(s);
        let largest = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if largest == 0.0 || !largest.is_finite() {
            continue;
        }
        let candidates = by_kind.entry((shell.center.map(f64::to_bits), shell.l, shell.pure)).or_default();
        let found = candidates.iter().find_map(|&g| {
            let a = block(groups[g][0].0);
            let f = dot(b, a) / dot(a, a);
            let tolerance = PROPORTIONAL * largest;
            (b.iter().zip(a).all(|(x, y)| (x - f * y).abs() <= tolerance)).then_some((g, f))
        });
        match found {
            Some((g, f)) => groups[g].push((s, f)),
            None => {
                candidates.push(groups.len());
                groups.push(vec![(s, 1.0)]);
            }
        }
    }
    let matrix = groups.iter().flat_map(|g| block(g[0].0).iter().copied()).collect();
    (basis.merged(&groups), matrix)
}

impl PreparedBasis {
    /// ρ, ∇ρ and the Hessian of `wf`'s total density at each of `points`:
    /// ∂a∂bρ = 2 Σ_i n_i (ψ_i ∂a∂bψ_i + ∂aψ_i ∂bψ_i), the orbitals' derivatives from the basis
    /// functions' analytic ones (only the shells within their cutoff of the point).
    pub fn density_derivatives(&self, wf: &Wavefunction, points: &[DVec3]) -> Vec<DensityDerivatives> {
        let mut out = vec![DensityDerivatives::default(); points.len()];
        let (coefficients, occupations) = occupied_matrix(self, wf);
        self.occupied_derivatives_into(&OccupiedOrbitals::new(&coefficients, occupations), points, &mut out);
        out
    }

    /// [`Self::density_derivatives`] of `orbitals` over this basis.
    fn occupied_derivatives_into(&self, orbitals: &OccupiedOrbitals, points: &[DVec3], out: &mut [DensityDerivatives]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has the features the function is compiled for.
            unsafe { self.occupied_derivatives_avx512(orbitals, points, out) };
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU has the features the function is compiled for.
            unsafe { self.occupied_derivatives_avx2(orbitals, points, out) };
            return;
        }
        self.occupied_derivatives_kernel(orbitals, points, out);
    }

    /// [`Self::occupied_derivatives_kernel`] compiled for AVX-512: the blocks' loops over
    /// points in 8-wide registers. The same operations, so the same bits (Rust never fuses a
    /// multiply and an add on its own).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx2,fma")]
    fn occupied_derivatives_avx512(
        &self,
        orbitals: &OccupiedOrbitals,
        points: &[DVec3],
        out: &mut [DensityDerivatives],
    ) {
        self.occupied_derivatives_kernel(orbitals, points, out);
    }

    /// [`Self::occupied_derivatives_kernel`] compiled for AVX2 (4-wide registers).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn occupied_derivatives_avx2(&self, orbitals: &OccupiedOrbitals, points: &[DVec3], out: &mut [DensityDerivatives]) {
        self.occupied_derivatives_kernel(orbitals, points, out);
    }

    /// ρ and its derivatives at `points`, [`BLOCK`] points at a time: the basis functions'
    /// derivatives over the block for every shell within reach of one of its points, then per
    /// point the orbitals' sums over the functions within reach of that point.
    #[inline(always)]
    fn occupied_derivatives_kernel(
        &self,
        orbitals: &OccupiedOrbitals,
        points: &[DVec3],
        out: &mut [DensityDerivatives],
    ) {
        let mut phi = vec![[[0.0; BLOCK]; COMPONENTS]; self.n_functions()];
        let mut psi = vec![0.0; orbitals.scratch_len()];
        let mut scratch = BlockScratch::default();
        let mut active: Vec<usize> = Vec::new();
        // Per shell that reaches a point of the block: the points it reaches, as bits.
        let mut reached: Vec<(usize, u32)> = Vec::new();
        // Shells that can reach any of the points: the rest are never looked at.
        let (lo, hi) = bounds(points);
        let (centre, half) = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
        let near: Vec<usize> = (0..self.shells.len())
            .filter(|&s| self.shells[s].center().distance(centre) <= self.shells[s].cutoff + half)
            .collect();
        for (points, out) in points.chunks(BLOCK).zip(out.chunks_mut(BLOCK)) {
            self.block_derivatives(&near, points, &mut phi, &mut scratch, &mut reached);
            for (i, o) in out.iter_mut().enumerate() {
                active.clear();
                for &(si, bits) in &reached {
                    if bits >> i & 1 != 0 {
                        active.extend(self.shells[si].functions());
                    }
                }
                orbitals.sums(&phi, i, &active, &mut psi);
                let (rho, g, h) = orbitals.density_derivatives(&psi);
                *o = DensityDerivatives { rho, gradient: DVec3::from_array(g), hessian: symmetric(h) };
            }
        }
    }
}

impl PreparedBasis {
    /// The derivatives of the functions of each of the `near` shells that reaches one of the
    /// block's `points`, into `phi` (indexed by function); `reached` gets those shells, each
    /// with the points it reaches as bits.
    #[inline(always)]
    fn block_derivatives(
        &self,
        near: &[usize],
        points: &[DVec3],
        phi: &mut [DerivativeBlock],
        scratch: &mut BlockScratch,
        reached: &mut Vec<(usize, u32)>,
    ) {
        reached.clear();
        let axes = block_axes(points);
        for &si in near {
            let s = &self.shells[si];
            let (d, r2, bits) = offsets(&axes, points.len(), s.center(), s.cutoff);
            if bits != 0 {
                self.shell_second_derivatives_block(s, &d, &r2, &mut phi[s.functions()], scratch);
                reached.push((si, bits));
            }
        }
    }
}

// A block's points are bits of a u32.
const _: () = assert!(BLOCK <= 32);

/// A block's points by axis, the last point repeated to fill the block.
#[inline(always)]
fn block_axes(points: &[DVec3]) -> [[f64; BLOCK]; 3] {
    let mut axes = [[0.0; BLOCK]; 3];
    for i in 0..BLOCK {
        let p = points[i.min(points.len() - 1)];
        (axes[0][i], axes[1][i], axes[2][i]) = (p.x, p.y, p.z);
    }
    axes
}

/// A block's offsets from `centre` per axis, their squared lengths (as `DVec3` computes
/// them), and which of the block's first `n` points lie within `cutoff` (bits).
#[inline(always)]
fn offsets(axes: &[[f64; BLOCK]; 3], n: usize, centre: DVec3, cutoff: f64) -> ([[f64; BLOCK]; 3], [f64; BLOCK], u32) {
    let mut d = [[0.0; BLOCK]; 3];
    for (d, (axis, c)) in d.iter_mut().zip(axes.iter().zip(centre.to_array())) {
        for (d, x) in d.iter_mut().zip(axis) {
            *d = x - c;
        }
    }
    let mut r2 = [0.0; BLOCK];
    let mut bits = 0u32;
    for (i, r2) in r2.iter_mut().enumerate() {
        *r2 = d[0][i] * d[0][i] + d[1][i] * d[1][i] + d[2][i] * d[2][i];
        bits |= u32::from(*r2 <= cutoff * cutoff) << i;
    }
    (d, r2, bits & (u32::MAX >> (32 - n)))
}

fn symmetric(h: [f64; 6]) -> [[f64; 3]; 3] {
    [[h[0], h[1], h[2]], [h[1], h[3], h[4]], [h[2], h[4], h[5]]]
}

/// The box of `points` (a point box at the origin when there are none).
pub(super) fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    match points.first() {
        None => (DVec3::ZERO, DVec3::ZERO),
        Some(&first) => points.iter().fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))),
    }
}

/// The quantities of ρ's derivatives at `points` for one source, in parallel.
pub fn quantity_at_points(source: &dyn DensitySource, quantity: Quantity, points: &[DVec3]) -> Vec<f64> {
    summed_quantity_at(&[source], quantity, points)
}

/// `quantity` of the summed density of `sources` (fragments) at `points`, in parallel.
pub fn summed_quantity_at(sources: &[&dyn DensitySource], quantity: Quantity, points: &[DVec3]) -> Vec<f64> {
    points
        .par_chunks(256)
        .flat_map_iter(|chunk| {
            let mut total = vec![DensityDerivatives::default(); chunk.len()];
            let mut part = total.clone();
            for s in sources {
                s.derivatives_at(chunk, &mut part);
                total.iter_mut().zip(&part).for_each(|(t, p)| t.add(p));
            }
            total.into_iter().map(move |d| d.quantity(quantity))
        })
        .collect()
}

/// `quantity` of derivatives given in single precision ([`DensityDerivatives::from_single`]:
/// what the GPU's pass writes), finished in double precision by
/// [`DensityDerivatives::quantity`] (λ₂ by Jacobi, the same cuts as the CPU's), in parallel.
pub fn quantity_of_single(derivatives: &[[f32; 10]], quantity: Quantity) -> Vec<f32> {
    derivatives.par_iter().map(|d| DensityDerivatives::from_single(d).quantity(quantity) as f32).collect()
}

/// NCIPLOT's RDG cutoff (its `dimcut`, CUTOFFS' second number): its `-grad` cube holds 100
/// where s is above it.
pub const NCIPLOT_RDG_CUT: f64 = 1.0;

/// NCIPLOT's default grid step, Å (its `xinc`: 0.1 Å; FINE 0.05, ULTRAFINE 0.025, COARSE 0.15).
pub const NCIPLOT_STEP_ANGSTROM: f64 = 0.1;

/// NCIPLOT's default space around the atoms, Å (its `rthres`; COARSE without INTERMOLECULAR
/// uses 0.5).
pub const NCIPLOT_MARGIN_ANGSTROM: f64 = 0.75;

/// NCIPLOT's automatic grid over atoms whose box is `lo..hi` (bohr): from `lo − margin`,
/// `step` apart, ⌈(hi − lo + 2·margin)/step⌉ points per axis (its `nstep`), so the last point
/// may stop short of `hi + margin`. At least one point per axis; counts beyond `usize` saturate
/// (callers check the product before allocating).
pub fn nciplot_grid(lo: DVec3, hi: DVec3, margin: f64, step: f64) -> GridSpec {
    let (lo, hi) = (lo - DVec3::splat(margin), hi + DVec3::splat(margin));
    let dims = ((hi - lo) / step).ceil().to_array().map(|n| if n >= 1.0 { n as usize } else { 1 });
    GridSpec::new(lo, [DVec3::X * step, DVec3::Y * step, DVec3::Z * step], dims)
}

/// How NCIPLOT's grids are made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NciSettings {
    /// Points whose total ρ is above this are cut.
    pub density_cut: f64,
    /// The `-grad` grid holds [`CUT_VALUE`] where s is above this (NCIPLOT's RDG cutoff,
    /// [`NCIPLOT_RDG_CUT`]; [`CUT_VALUE`] keeps every s, capped at 100).
    pub rdg_cut: f64,
    /// With several fragments, the largest share of a point's density one fragment may hold
    /// for the point to be kept (`None`: every point is kept).
    pub intermolecular: Option<f64>,
}

/// NCIPLOT's two grids, cube order: `dens` holds 100·sign(λ₂)ρ, `grad` holds s, both
/// [`CUT_VALUE`] at the points cut.
#[derive(Debug, Clone, PartialEq)]
pub struct NciGrids {
    pub dens: Vec<f32>,
    pub grad: Vec<f32>,
    /// Points not cut.
    pub kept: usize,
}

/// Rows of an x-slab whose points are evaluated together.
const GROUP_ROWS: usize = 4;

/// Points along z per tile: a group's points go to the sources tile by tile, [`GROUP_ROWS`]
/// rows × this many points, so that a block of [`BLOCK`] points (what a wavefunction's basis
/// functions are evaluated over at once) is a compact square rather than a long stretch of a
/// row, and rows' ends fill blocks together instead of each leaving one mostly empty.
const TILE_COLUMNS: usize = BLOCK / GROUP_ROWS;

/// The (row within the group, z index) of each point of a group of `rows` rows of `nz`
/// points, tile by tile.
fn tile_order(rows: usize, nz: usize) -> Vec<(usize, usize)> {
    let mut order = Vec::with_capacity(rows * nz);
    for z0 in (0..nz).step_by(TILE_COLUMNS) {
        for r in 0..rows {
            order.extend((z0..nz.min(z0 + TILE_COLUMNS)).map(|iz| (r, iz)));
        }
    }
    order
}

/// [`NciGrids`] of the fragments' summed density on `grid`, x-slabs in parallel, a few rows
/// of points at a time.
pub fn nci_grid(fragments: &[&dyn DensitySource], grid: &GridSpec, settings: NciSettings) -> NciGrids {
    let [_, ny, nz] = grid.dims;
    let slab = ny * nz;
    let mut dens = vec![CUT_VALUE; grid.len()];
    let mut grad = vec![CUT_VALUE; grid.len()];
    if grid.is_empty() {
        return NciGrids { dens, grad, kept: 0 };
    }
    let group = GROUP_ROWS * nz;
    let kept: usize = dens
        .par_chunks_mut(slab)
        .zip(grad.par_chunks_mut(slab))
        .enumerate()
        .map(|(ix, (dens, grad))| {
            let mut points = Vec::with_capacity(group);
            let mut total = vec![DensityDerivatives::default(); group];
            let mut part = vec![DensityDerivatives::default(); group];
            let mut largest = vec![0.0f64; group];
            let mut kept = 0;
            for y0 in (0..ny).step_by(GROUP_ROWS) {
                let order = tile_order(GROUP_ROWS.min(ny - y0), nz);
                let n = order.len();
                points.clear();
                points.extend(order.iter().map(|&(r, iz)| grid.point(ix, y0 + r, iz)));
                total[..n].fill(DensityDerivatives::default());
                largest[..n].fill(0.0);
                for f in fragments {
                    f.derivatives_at(&points, &mut part[..n]);
                    for ((t, p), l) in total.iter_mut().zip(&part[..n]).zip(largest.iter_mut()) {
                        t.add(p);
                        *l = l.max(p.rho);
                    }
                }
                for (&(r, iz), (t, l)) in order.iter().zip(total.iter().zip(&largest)) {
                    let own = settings.intermolecular.is_some_and(|share| *l > share * t.rho);
                    if t.rho > settings.density_cut || own || t.rho.is_nan() || t.rho <= 0.0 {
                        continue;
                    }
                    let s = t.reduced_gradient();
                    let k = (y0 + r) * nz + iz;
                    dens[k] = (100.0 * t.sign_lambda2_rho()) as f32;
                    grad[k] =
                        if s.is_finite() && s <= settings.rdg_cut { s.min(CUT_VALUE as f64) as f32 } else { CUT_VALUE };
                    kept += 1;
                }
            }
            kept
        })
        .sum();
    NciGrids { dens, grad, kept }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::basis::{Basis, Shell, ShellKind};
    use crate::model::orbitals::{MolecularOrbital, Spin};

    /// Two centres with s, p, d (pure) and f (cartesian) shells, two occupied orbitals.
    fn wavefunction() -> Wavefunction {
        let shell = |center: DVec3, l: u32, kind: ShellKind| Shell {
            atom: 0,
            center,
            l,
            kind,
            exponents: vec![3.0, 0.8, 0.25],
            coefficients: vec![0.2, 0.5, 0.5],
        };
        let (a, b) = (DVec3::ZERO, DVec3::new(2.2, 0.4, -0.3));
        let basis = Basis {
            shells: vec![
                shell(a, 0, ShellKind::Pure),
                shell(a, 1, ShellKind::Pure),
                shell(b, 0, ShellKind::Pure),
                shell(b, 2, ShellKind::Pure),
                shell(a, 3, ShellKind::Cartesian),
            ],
        };
        let n = basis.n_functions();
        let orbital = |seed: u64, occupation: f64| MolecularOrbital {
            energy: -0.5,
            occupation,
            spin: Spin::Alpha,
            symmetry: String::new(),
            coefficients: crate::model::gto::tests::pseudo_random(n, seed),
        };
        Wavefunction { basis, orbitals: vec![orbital(1, 2.0), orbital(2, 1.5)], restricted: true, ..Default::default() }
    }

    #[test]
    fn density_derivatives_match_finite_differences() {
        let wf = wavefunction();
        let pb = PreparedBasis::new(&wf.basis);
        let points: Vec<DVec3> = (0..40)
            .map(|i| {
                let t = i as f64 * 0.37;
                DVec3::new(1.1 * t.sin() + 0.8, 1.3 * (1.7 * t).cos(), 0.9 * (0.6 * t).sin())
            })
            .collect();
        let d = pb.density_derivatives(&wf, &points);
        let h = 1e-4;
        for (p, d) in points.iter().zip(&d) {
            assert!((d.rho - pb.density(&wf, *p)).abs() < 1e-13 * (1.0 + d.rho));
            for a in 0..3 {
                let mut e = DVec3::ZERO;
                e[a] = h;
                let (dp, dm) = (pb.density_derivatives(&wf, &[*p + e])[0], pb.density_derivatives(&wf, &[*p - e])[0]);
                let fd = (dp.rho - dm.rho) / (2.0 * h);
                assert!(
                    (fd - d.gradient[a]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "∂{a}ρ at {p}: {fd} vs {}",
                    d.gradient[a]
                );
                for b in 0..3 {
                    let fd = (dp.gradient[b] - dm.gradient[b]) / (2.0 * h);
                    let got = d.hessian[a][b];
                    assert!((fd - got).abs() < 1e-6 * (1.0 + fd.abs()), "∂{a}∂{b}ρ at {p}: {fd} vs {got}");
                }
            }
        }
    }

    #[test]
    fn reduced_gradient_and_lambda2_follow_their_definitions() {
        // A hydrogen-like density e^{-2r}/π: s = (1/(3π²)^{1/3}) ρ^{-1/3} exactly, and the
        // Hessian's eigenvalues are ρ″ = 4ρ (radial) and ρ′/r = −2ρ/r (twice).
        let r: f64 = 1.7;
        let rho = (-2.0 * r).exp() / std::f64::consts::PI;
        let x = DVec3::new(r, 0.0, 0.0);
        let d = DensityDerivatives {
            rho,
            gradient: -2.0 * rho * x / r,
            hessian: [[4.0 * rho, 0.0, 0.0], [0.0, -2.0 * rho / r, 0.0], [0.0, 0.0, -2.0 * rho / r]],
        };
        let want = 2.0 * rho / (rdg_factor() * rho.powf(4.0 / 3.0));
        assert!((d.reduced_gradient() - want).abs() < 1e-12 * want);
        assert!((d.lambda2() + 2.0 * rho / r).abs() < 1e-14);
        assert_eq!(d.sign_lambda2_rho(), -rho);
        assert!((d.laplacian() - (4.0 - 4.0 / r) * rho).abs() < 1e-15);
        let turned = DensityDerivatives { hessian: [[1.0, 2.0, 0.0], [2.0, -3.0, 0.5], [0.0, 0.5, 0.2]], ..d };
        let e = turned.eigenvalues();
        assert!(e[0] < e[1] && e[1] < e[2]);
        assert!((e.iter().sum::<f64>() - turned.laplacian()).abs() < 1e-12);
        assert_eq!(DensityDerivatives::default().reduced_gradient(), f64::INFINITY);
    }

    #[test]
    fn tiles_cover_every_point_of_a_group_once() {
        // A full group's first block is a square: every row, the first few points of each.
        let first = &tile_order(GROUP_ROWS, 51)[..BLOCK];
        assert!(first.iter().all(|&(_, z)| z < TILE_COLUMNS));
        for (rows, nz) in [(4, 51), (1, 3), (3, 8), (4, 1)] {
            let mut order = tile_order(rows, nz);
            order.sort_unstable();
            let all: Vec<_> = (0..rows).flat_map(|r| (0..nz).map(move |z| (r, z))).collect();
            assert_eq!(order, all);
        }
    }

    #[test]
    fn the_sign_of_lambda2_agrees_with_the_eigenvalues() {
        // Random symmetric matrices, matrices with λ₂ near 0 relative to the others, and one
        // with a zero trace (a coefficient the rule cannot trust).
        let r = crate::model::gto::tests::pseudo_random(6 * 400, 3);
        let mut matrices: Vec<[f64; 6]> = r.chunks_exact(6).map(|c| std::array::from_fn(|k| c[k])).collect();
        matrices.push([1.0, 0.0, 0.0, 1e-12, 0.0, -2.0]);
        matrices.push([1.0, 0.0, 0.0, -1e-12, 0.0, 2.0]);
        matrices.push([1.0, 0.3, 0.0, -0.5, 0.2, -0.5]);
        for h in matrices {
            let d = DensityDerivatives { rho: 0.01, hessian: symmetric(h), ..Default::default() };
            assert_eq!(d.lambda2_is_negative(), d.lambda2() < 0.0, "{h:?}");
        }
    }

    #[test]
    fn nci_grid_cuts_dense_points_and_fragments_add() {
        let wf = wavefunction();
        let source = WavefunctionDensity::new(&wf);
        let grid = GridSpec::cube(DVec3::splat(-2.0), DVec3::new(4.0, 2.0, 2.0), 9);
        let settings = NciSettings { density_cut: 0.05, rdg_cut: CUT_VALUE as f64, intermolecular: None };
        let one = nci_grid(&[&source], &grid, settings);
        let two = nci_grid(&[&source, &source], &grid, settings);
        let mut cut = 0;
        for i in 0..grid.dims[0] {
            for j in 0..grid.dims[1] {
                for k in 0..grid.dims[2] {
                    let at = (i * grid.dims[1] + j) * grid.dims[2] + k;
                    let d = pb_point(&source, grid.point(i, j, k));
                    if d.rho > 0.05 {
                        assert_eq!((one.dens[at], one.grad[at]), (CUT_VALUE, CUT_VALUE));
                        cut += 1;
                    } else {
                        assert!((one.dens[at] as f64 - 100.0 * d.sign_lambda2_rho()).abs() < 1e-5);
                        assert!((one.grad[at] as f64 - d.reduced_gradient().min(100.0)).abs() < 1e-4);
                    }
                    // Twice the density: s scales by 2^{-1/3}.
                    if 2.0 * d.rho <= 0.05 && d.reduced_gradient() < 50.0 {
                        let want = d.reduced_gradient() * 2f64.powf(-1.0 / 3.0);
                        assert!((two.grad[at] as f64 - want).abs() < 1e-4 * (1.0 + want));
                    }
                }
            }
        }
        assert!(cut > 0 && one.kept > 0 && one.kept + cut == grid.len());
        // One fragment twice holds half of every point: kept at a share of 0.95, cut at 0.4.
        let inter =
            |share| nci_grid(&[&source, &source], &grid, NciSettings { intermolecular: Some(share), ..settings });
        assert_eq!(inter(0.95).kept, two.kept);
        assert_eq!(inter(0.4).kept, 0);
    }

    #[test]
    fn primitives_written_apart_are_contracted_again_and_give_the_same_density() {
        // The test wavefunction as an AIM file writes it: each contraction's primitives as
        // one-primitive shells, the orbitals' coefficients spread over them in proportion.
        let wf = wavefunction();
        let whole = PreparedBasis::new(&wf.basis);
        let mut shells = Vec::new();
        let mut orbitals: Vec<Vec<f64>> = vec![Vec::new(); wf.orbitals.len()];
        let offsets = wf.basis.shell_offsets();
        for (s, shell) in wf.basis.shells.iter().enumerate() {
            let prepared = &whole.shells[s];
            for j in prepared.primitives() {
                shells.push(Shell { exponents: vec![whole.exponents[j]], coefficients: vec![1.0], ..shell.clone() });
                // The lone primitive normalised to 1: its share of the contraction.
                let lone = PreparedBasis::new(&Basis { shells: vec![shells.last().unwrap().clone()] });
                let share = whole.coefficients[j] / lone.coefficients[0];
                for (o, orbital) in orbitals.iter_mut().zip(&wf.orbitals) {
                    let n = shell.n_functions();
                    o.extend(orbital.coefficients[offsets[s]..offsets[s] + n].iter().map(|c| c * share));
                }
            }
        }
        let split = Wavefunction {
            basis: Basis { shells },
            orbitals: (wf.orbitals.iter().zip(orbitals))
                .map(|(o, c)| MolecularOrbital { coefficients: c, ..o.clone() })
                .collect(),
            ..wf.clone()
        };
        // An orbital with nothing in it is no reason to keep a function.
        let mut with_empty = split.clone();
        with_empty.orbitals.push(MolecularOrbital { occupation: 0.0, ..with_empty.orbitals[0].clone() });
        let (a, b) = (WavefunctionDensity::new(&wf), WavefunctionDensity::new(&with_empty));
        assert_eq!(b.basis.n_functions(), 3 * a.basis.n_functions());
        assert_eq!(b.contracted_functions(), a.basis.n_functions());
        let points: Vec<DVec3> = (0..30).map(|i| DVec3::new(0.1 * i as f64 - 1.0, 0.3, 0.05 * i as f64)).collect();
        let (mut x, mut y) = (vec![DensityDerivatives::default(); 30], vec![DensityDerivatives::default(); 30]);
        a.derivatives_at(&points, &mut x);
        b.derivatives_at(&points, &mut y);
        let direct = b.basis.density_derivatives(&split, &points);
        for ((x, y), z) in x.iter().zip(&y).zip(&direct) {
            for (u, v) in [(x, y), (x, z)] {
                assert!((u.rho - v.rho).abs() < 1e-12 * (1.0 + u.rho));
                assert!((u.gradient - v.gradient).length() < 1e-11);
                for (r, q) in u.hessian.iter().flatten().zip(v.hessian.iter().flatten()) {
                    assert!((r - q).abs() < 1e-10, "{r} vs {q}");
                }
            }
        }
        // Blocks that are not proportional stay apart: a generic wavefunction keeps every shell.
        assert_eq!(a.contracted_functions(), a.basis.n_functions());
    }

    #[test]
    fn nciplot_grid_counts_steps_as_nciplot_does() {
        // NCIPLOT 4.2's header for its benzene + ethene test (two .wfn files) at its default
        // step: origin −6.060647 −5.717942 −1.380388, 65 × 61 × 51 points 0.188973 bohr
        // apart, from atoms spanning these corners (bohr).
        let step = NCIPLOT_STEP_ANGSTROM * crate::model::units::BOHR_PER_ANGSTROM;
        let margin = NCIPLOT_MARGIN_ANGSTROM * crate::model::units::BOHR_PER_ANGSTROM;
        let lo = DVec3::new(-4.64335224, -4.3006473, 0.03690653);
        let hi = DVec3::new(4.64333871, 4.30064909, 6.67217064);
        let grid = nciplot_grid(lo, hi, margin, step);
        assert_eq!(grid.dims, [65, 61, 51]);
        assert!((grid.origin() - DVec3::new(-6.060647, -5.717942, -1.380388)).length() < 2e-6);
        assert!((grid.step(0) - DVec3::X * 0.188973).length() < 1e-6);
        assert_eq!(grid.step(1), DVec3::Y * step);
        // An exact multiple of the step gives that many points, no extra one beyond; a flat
        // box still has one point.
        let exact = nciplot_grid(DVec3::ZERO, DVec3::new(1.0, 0.5, 0.0), 0.0, 0.25);
        assert_eq!(exact.dims, [4, 2, 1]);
    }

    fn pb_point(source: &WavefunctionDensity, p: DVec3) -> DensityDerivatives {
        let mut d = [DensityDerivatives::default()];
        source.derivatives_at(&[p], &mut d);
        d[0]
    }
}
