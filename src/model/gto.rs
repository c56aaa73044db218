//! Evaluation of Gaussian basis functions, orbitals and densities at points and on grids.
//!
//! [`PreparedBasis`] is a [`Basis`] turned into plain flat arrays, ready to evaluate (here on the
//! CPU, and as the data a GPU kernel uploads):
//! - per primitive the exponent and a coefficient that already folds in the primitive's
//!   normalisation (for the x^l component) and the renormalisation of the contraction, so that
//!   every contracted function has unit norm whatever the file's contraction;
//! - per angular momentum the factor that makes each cartesian component unit-normalised and the
//!   cartesian → pure matrix ([`super::solid_harmonics`]);
//! - per primitive and per shell a cutoff radius.
//!
//! Cutoffs: with ε = [`PreparedBasis::threshold`] (default [`DEFAULT_THRESHOLD`] = 1e-12), the
//! primitive j of a shell is dropped at distances r where a bound of its contribution to any
//! function of the shell, |c_j| · A_l · r^l · exp(−α_j r²), is below ε / n_primitives (A_l bounds
//! the angular factor of the unit-normalised functions). So beyond the shell's cutoff radius (the
//! largest of its primitives') every function of the shell is exactly 0, and everywhere the value
//! differs from the uncut one by less than ε in absolute terms (bohr^−3/2). Cost therefore grows
//! linearly with the size of the molecule.
//!
//! Grids are evaluated row by row (a row is the fastest axis, z in cube order): along a row the
//! squared distance to a centre is a quadratic in the point index, so exp(−α r²) follows from a
//! two-multiplication recurrence (re-seeded with an exact `exp` every [`RESEED`] points), and the
//! angular part of a shell contracted with the orbital's coefficients is a polynomial of degree l
//! in the index, evaluated by Horner's rule.
//!
//! That is the path for grids of any shape; grids whose steps run along x, y and z (all the
//! grids orbcloud lays out itself) go through `separable.rs` instead, an order of magnitude faster,
//! with the same cutoffs.

use glam::DVec3;
use rayon::prelude::*;

use super::basis::{Basis, ShellKind, cartesian_powers, n_cartesian};
use super::orbitals::{Quantity, Spin, Wavefunction};
use super::solid_harmonics::{cart_to_pure, component_factor, double_factorial_m1};

/// Default absolute cutoff threshold for basis-function values (bohr^−3/2).
pub const DEFAULT_THRESHOLD: f64 = 1e-12;

/// Highest angular momentum the evaluator's fixed-size tables hold.
pub const MAX_EVAL_L: u32 = 6;

/// Points between exact re-evaluations of exp(−α r²) along a grid row.
pub const RESEED: usize = 64;

/// Points whose basis-function derivatives are evaluated together
/// ([`PreparedBasis::shell_second_derivatives_block`]).
pub const BLOCK: usize = 16;

/// One function's `[v, ∂x, ∂y, ∂z, ∂xx, ∂xy, ∂xz, ∂yy, ∂yz, ∂zz]`, each at the [`BLOCK`]
/// points of a block.
pub type DerivativeBlock = [[f64; BLOCK]; 10];

/// Scratch of [`PreparedBasis::shell_second_derivatives_block`]: a pure shell's cartesian
/// components, and per axis and power p the points' x^p, p x^(p−1) and p(p−1) x^(p−2).
pub struct BlockScratch {
    cart: Vec<DerivativeBlock>,
    powers: Box<[[[[f64; BLOCK]; 3]; MAX_EVAL_L as usize + 1]; 3]>,
}

impl Default for BlockScratch {
    fn default() -> Self {
        Self { cart: Vec::new(), powers: Box::new([[[[0.0; BLOCK]; 3]; MAX_EVAL_L as usize + 1]; 3]) }
    }
}

/// The Hessian's six independent components' (row, column): xx, xy, xz, yy, yz, zz.
pub const HESSIAN_PAIRS: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// One shell in evaluation-ready form; indices point into [`PreparedBasis`]'s flat arrays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreparedShell {
    /// Centre in bohr.
    pub center: [f64; 3],
    pub l: u32,
    pub pure: bool,
    /// Index of the shell's first basis function.
    pub first_function: u32,
    pub n_functions: u32,
    /// Index of the shell's first cartesian component in a flat per-shell cartesian array.
    pub first_cartesian: u32,
    pub first_primitive: u32,
    pub n_primitives: u32,
    /// Beyond this distance (bohr) every function of the shell is 0.
    pub cutoff: f64,
}

impl PreparedShell {
    pub fn center(&self) -> DVec3 {
        DVec3::from_array(self.center)
    }

    pub fn primitives(&self) -> std::ops::Range<usize> {
        self.first_primitive as usize..(self.first_primitive + self.n_primitives) as usize
    }

    pub fn functions(&self) -> std::ops::Range<usize> {
        self.first_function as usize..(self.first_function + self.n_functions) as usize
    }

    fn cartesians(&self) -> std::ops::Range<usize> {
        let n = n_cartesian(self.l);
        self.first_cartesian as usize..self.first_cartesian as usize + n
    }
}

/// A basis in flat, evaluation-ready form (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct PreparedBasis {
    pub shells: Vec<PreparedShell>,
    /// Per primitive: exponent.
    pub exponents: Vec<f64>,
    /// Per primitive: contraction coefficient × primitive normalisation (x^l component) ×
    /// contraction renormalisation.
    pub coefficients: Vec<f64>,
    /// Per primitive: squared radius beyond which the primitive is dropped.
    pub primitive_cutoffs2: Vec<f64>,
    /// Per l (0..=max l): cartesian powers in orbcloud order.
    pub powers: Vec<Vec<[u32; 3]>>,
    /// Per l: the factor making each cartesian component unit-normalised.
    pub component_factors: Vec<Vec<f64>>,
    /// Per l: cartesian → pure matrix, row-major (2l+1) × n_cart.
    pub pure_matrices: Vec<Vec<f64>>,
    /// Absolute value threshold the cutoffs were built for.
    pub threshold: f64,
    n_functions: usize,
    n_cartesians: usize,
}

pub use super::grid::GridSpec;

/// Normalisation of a primitive x^l exp(−α r²).
fn primitive_norm(alpha: f64, l: u32) -> f64 {
    (2.0 * alpha / std::f64::consts::PI).powf(0.75) * (4.0 * alpha).powf(l as f64 / 2.0)
        / double_factorial_m1(2 * l as i64).sqrt()
}

/// Smallest r such that c · r^l · exp(−α r²) < eps for every r' ≥ r (c > 0).
fn primitive_radius(c: f64, alpha: f64, l: u32, eps: f64) -> f64 {
    if c <= 0.0 || alpha <= 0.0 {
        return if c <= 0.0 { 0.0 } else { f64::INFINITY };
    }
    let g = |r: f64| c.ln() + l as f64 * r.max(1e-300).ln() - alpha * r * r - eps.ln();
    let peak = (l as f64 / (2.0 * alpha)).sqrt();
    if g(peak) < 0.0 {
        return 0.0;
    }
    let (mut lo, mut hi) = (peak, peak + 1.0 / alpha.sqrt());
    while g(hi) >= 0.0 {
        lo = hi;
        hi *= 2.0;
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if g(mid) >= 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

impl PreparedBasis {
    pub fn new(basis: &Basis) -> Self {
        Self::with_threshold(basis, DEFAULT_THRESHOLD)
    }

    /// Prepares `basis` with cutoffs for an absolute value threshold `threshold` (0 keeps every
    /// primitive everywhere).
    ///
    /// Panics when a shell has l > [`MAX_EVAL_L`] (readers reject those: `basis::MAX_L`).
    pub fn with_threshold(basis: &Basis, threshold: f64) -> Self {
        assert!(basis.shells.iter().all(|s| s.l <= MAX_EVAL_L), "angular momentum above {MAX_EVAL_L}");
        let max_l = basis.shells.iter().map(|s| s.l).max().unwrap_or(0);
        let powers: Vec<_> = (0..=max_l).map(cartesian_powers).collect();
        let component_factors: Vec<Vec<f64>> =
            powers.iter().map(|ps| ps.iter().map(|p| component_factor(*p)).collect()).collect();
        let pure_matrices: Vec<Vec<f64>> = (0..=max_l).map(cart_to_pure).collect();
        // Bounds of |angular part| / r^l over the functions of a shell.
        let angular_bound = |l: u32, pure: bool| -> f64 {
            let f = &component_factors[l as usize];
            if pure {
                let t = &pure_matrices[l as usize];
                let nc = f.len();
                (0..2 * l as usize + 1)
                    .map(|k| (0..nc).map(|i| (t[k * nc + i] * f[i]).abs()).sum::<f64>())
                    .fold(0.0, f64::max)
            } else {
                f.iter().cloned().fold(0.0, f64::max)
            }
        };

        let mut out = Self {
            shells: Vec::with_capacity(basis.shells.len()),
            exponents: Vec::new(),
            coefficients: Vec::new(),
            primitive_cutoffs2: Vec::new(),
            powers,
            component_factors: component_factors.clone(),
            pure_matrices: pure_matrices.clone(),
            threshold,
            n_functions: 0,
            n_cartesians: 0,
        };
        for shell in &basis.shells {
            let l = shell.l;
            let pure = shell.kind == ShellKind::Pure;
            let n_prim = shell.exponents.len().min(shell.coefficients.len());
            let mut coefs: Vec<f64> =
                (0..n_prim).map(|j| shell.coefficients[j] * primitive_norm(shell.exponents[j], l)).collect();
            // Norm² of the contracted x^l component.
            let mut norm2 = 0.0;
            for a in 0..n_prim {
                for b in 0..n_prim {
                    let p = shell.exponents[a] + shell.exponents[b];
                    norm2 +=
                        coefs[a] * coefs[b] * (std::f64::consts::PI / p).powf(1.5) * double_factorial_m1(2 * l as i64)
                            / (2.0 * p).powi(l as i32);
                }
            }
            if norm2 > 0.0 && norm2.is_finite() {
                let s = 1.0 / norm2.sqrt();
                coefs.iter_mut().for_each(|c| *c *= s);
            }
            let bound = angular_bound(l, pure);
            let first_primitive = out.exponents.len() as u32;
            let mut cutoff: f64 = 0.0;
            for (&alpha, &c) in shell.exponents.iter().zip(&coefs) {
                let r = if threshold > 0.0 {
                    primitive_radius(c.abs() * bound, alpha, l, threshold / n_prim as f64)
                } else {
                    f64::INFINITY
                };
                cutoff = cutoff.max(r);
                out.exponents.push(alpha);
                out.coefficients.push(c);
                out.primitive_cutoffs2.push(r * r);
            }
            let n_functions = shell.n_functions() as u32;
            out.shells.push(PreparedShell {
                center: shell.center.to_array(),
                l,
                pure,
                first_function: out.n_functions as u32,
                n_functions,
                first_cartesian: out.n_cartesians as u32,
                first_primitive,
                n_primitives: n_prim as u32,
                cutoff,
            });
            out.n_functions += n_functions as usize;
            out.n_cartesians += n_cartesian(l);
        }
        out
    }

    pub fn n_functions(&self) -> usize {
        self.n_functions
    }

    /// A basis with one shell per group: group g's function k is Σ f · (function k of shell s)
    /// over its (s, f), the shells' primitives side by side with f folded into their
    /// coefficients (each primitive keeps its cutoff, so the same terms are dropped as in the
    /// shells it came from). The shells of a group share centre, l and kind.
    ///
    /// Panics when a group is empty or mixes centres, l or kinds.
    pub fn merged(&self, groups: &[Vec<(usize, f64)>]) -> Self {
        let mut out = Self {
            shells: Vec::with_capacity(groups.len()),
            exponents: Vec::new(),
            coefficients: Vec::new(),
            primitive_cutoffs2: Vec::new(),
            powers: self.powers.clone(),
            component_factors: self.component_factors.clone(),
            pure_matrices: self.pure_matrices.clone(),
            threshold: self.threshold,
            n_functions: 0,
            n_cartesians: 0,
        };
        for group in groups {
            let first = &self.shells[group[0].0];
            let first_primitive = out.exponents.len() as u32;
            let mut cutoff: f64 = 0.0;
            for &(s, f) in group {
                let shell = &self.shells[s];
                assert!(
                    shell.center == first.center && shell.l == first.l && shell.pure == first.pure,
                    "merged shells share centre, l and kind"
                );
                cutoff = cutoff.max(shell.cutoff);
                for j in shell.primitives() {
                    out.exponents.push(self.exponents[j]);
                    out.coefficients.push(self.coefficients[j] * f);
                    out.primitive_cutoffs2.push(self.primitive_cutoffs2[j]);
                }
            }
            out.shells.push(PreparedShell {
                first_function: out.n_functions as u32,
                first_cartesian: out.n_cartesians as u32,
                first_primitive,
                n_primitives: out.exponents.len() as u32 - first_primitive,
                cutoff,
                ..*first
            });
            out.n_functions += first.n_functions as usize;
            out.n_cartesians += n_cartesian(first.l);
        }
        out
    }

    /// Radial part Σ c_j exp(−α_j r²) and, when `with_derivative`, Σ −2α_j c_j exp(−α_j r²).
    fn radial(&self, shell: &PreparedShell, r2: f64) -> (f64, f64) {
        let (mut v, mut dv) = (0.0, 0.0);
        for j in shell.primitives() {
            if r2 <= self.primitive_cutoffs2[j] {
                let e = self.coefficients[j] * (-self.exponents[j] * r2).exp();
                v += e;
                dv -= 2.0 * self.exponents[j] * e;
            }
        }
        (v, dv)
    }

    /// Values (and gradients when `grads` is given) of one shell's functions at `d` = point −
    /// centre, written to `out[..n_functions]`; `cart` is scratch for the cartesian components.
    fn shell_values(
        &self,
        shell: &PreparedShell,
        d: DVec3,
        out: &mut [f64],
        mut grads: Option<&mut [DVec3]>,
        cart: &mut Vec<f64>,
        cart_grad: &mut Vec<DVec3>,
    ) {
        let n = shell.n_functions as usize;
        let r2 = d.length_squared();
        if r2 > shell.cutoff * shell.cutoff {
            out[..n].fill(0.0);
            if let Some(g) = grads {
                g[..n].fill(DVec3::ZERO);
            }
            return;
        }
        let l = shell.l as usize;
        let (rad, drad) = self.radial(shell, r2);
        let mut pw = [[1.0f64; 8]; 3];
        for axis in 0..3 {
            for k in 1..=l + 1 {
                pw[axis][k] = pw[axis][k - 1] * d[axis];
            }
        }
        let powers = &self.powers[l];
        let factors = &self.component_factors[l];
        cart.clear();
        cart_grad.clear();
        for (p, f) in powers.iter().zip(factors) {
            let [a, b, c] = [p[0] as usize, p[1] as usize, p[2] as usize];
            let mono = pw[0][a] * pw[1][b] * pw[2][c];
            cart.push(f * mono * rad);
            if grads.is_some() {
                let dm = |axis: usize, e: usize| -> f64 {
                    // ∂/∂axis of x^a y^b z^c without the other two factors.
                    if e == 0 { 0.0 } else { e as f64 * pw[axis][e - 1] }
                };
                let gx = dm(0, a) * pw[1][b] * pw[2][c] * rad + pw[0][a + 1] * pw[1][b] * pw[2][c] * drad;
                let gy = pw[0][a] * dm(1, b) * pw[2][c] * rad + pw[0][a] * pw[1][b + 1] * pw[2][c] * drad;
                let gz = pw[0][a] * pw[1][b] * dm(2, c) * rad + pw[0][a] * pw[1][b] * pw[2][c + 1] * drad;
                cart_grad.push(*f * DVec3::new(gx, gy, gz));
            }
        }
        if shell.pure {
            let t = &self.pure_matrices[l];
            let nc = cart.len();
            for k in 0..n {
                let row = &t[k * nc..(k + 1) * nc];
                out[k] = row.iter().zip(cart.iter()).map(|(a, b)| a * b).sum();
                if let Some(g) = grads.as_deref_mut() {
                    g[k] = row.iter().zip(cart_grad.iter()).fold(DVec3::ZERO, |acc, (a, b)| acc + *a * *b);
                }
            }
        } else {
            out[..n].copy_from_slice(cart);
            if let Some(g) = grads {
                g[..n].copy_from_slice(cart_grad);
            }
        }
    }

    /// Values, gradients and second derivatives of one shell's functions at `d` = point −
    /// centre: per function `[v, ∂x, ∂y, ∂z, ∂xx, ∂xy, ∂xz, ∂yy, ∂yz, ∂zz]` in
    /// `out[..n_functions]`; `cart` is scratch for the cartesian components. With the radial
    /// part R(r²) = Σ c_j exp(−α_j r²) and a monomial M,
    /// ∂a∂b(M R) = (∂a∂b M) R + (∂a M x_b + ∂b M x_a) R₁ + M (x_a x_b R₂ + δ_ab R₁),
    /// with R₁ = Σ −2α_j c_j e_j and R₂ = Σ 4α_j² c_j e_j.
    #[inline(always)]
    pub(super) fn shell_second_derivatives(
        &self,
        shell: &PreparedShell,
        d: DVec3,
        out: &mut [[f64; 10]],
        cart: &mut Vec<[f64; 10]>,
    ) {
        let n = shell.n_functions as usize;
        let r2 = d.length_squared();
        if r2 > shell.cutoff * shell.cutoff {
            out[..n].fill([0.0; 10]);
            return;
        }
        let l = shell.l as usize;
        let (mut rad, mut rad1, mut rad2) = (0.0, 0.0, 0.0);
        for j in shell.primitives() {
            if r2 <= self.primitive_cutoffs2[j] {
                let alpha = self.exponents[j];
                let e = self.coefficients[j] * (-alpha * r2).exp();
                rad += e;
                rad1 -= 2.0 * alpha * e;
                rad2 += 4.0 * alpha * alpha * e;
            }
        }
        // Per axis and power p: x^p, p x^(p−1) and p(p−1) x^(p−2).
        let mut pw = [[[0.0f64; 3]; 8]; 3];
        for axis in 0..3 {
            let x = d[axis];
            pw[axis][0] = [1.0, 0.0, 0.0];
            for p in 1..=l {
                let [v, d1, _] = pw[axis][p - 1];
                pw[axis][p] = [v * x, p as f64 * v, p as f64 * d1];
            }
        }
        const PAIRS: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
        cart.clear();
        for (p, f) in self.powers[l].iter().zip(&self.component_factors[l]) {
            let [x, y, z] = [pw[0][p[0] as usize], pw[1][p[1] as usize], pw[2][p[2] as usize]];
            let m = x[0] * y[0] * z[0];
            let dm = [x[1] * y[0] * z[0], x[0] * y[1] * z[0], x[0] * y[0] * z[1]];
            let ddm = [
                x[2] * y[0] * z[0],
                x[1] * y[1] * z[0],
                x[1] * y[0] * z[1],
                x[0] * y[2] * z[0],
                x[0] * y[1] * z[1],
                x[0] * y[0] * z[2],
            ];
            let mut c = [0.0; 10];
            c[0] = m * rad;
            for a in 0..3 {
                c[1 + a] = dm[a] * rad + m * d[a] * rad1;
            }
            for (k, &(a, b)) in PAIRS.iter().enumerate() {
                let delta = if a == b { rad1 } else { 0.0 };
                c[4 + k] = ddm[k] * rad + (dm[a] * d[b] + dm[b] * d[a]) * rad1 + m * (d[a] * d[b] * rad2 + delta);
            }
            cart.push(c.map(|v| v * f));
        }
        if shell.pure {
            let t = &self.pure_matrices[l];
            let nc = cart.len();
            for (k, o) in out[..n].iter_mut().enumerate() {
                *o = [0.0; 10];
                for (w, c) in t[k * nc..(k + 1) * nc].iter().zip(cart.iter()) {
                    if *w != 0.0 {
                        for (o, c) in o.iter_mut().zip(c) {
                            *o += w * c;
                        }
                    }
                }
            }
        } else {
            out[..n].copy_from_slice(cart);
        }
    }

    /// [`Self::shell_second_derivatives`] at [`BLOCK`] points at once, `d` their offsets from
    /// the centre per axis and `r2` their squared distances: per function and component its
    /// value at each point, in `out[..n_functions]`. The same operations in the same order
    /// as at one point, so the same bits, but in loops over the points that the compiler
    /// vectorises; a primitive beyond its cutoff adds zeros. Points beyond the shell's cutoff
    /// get values all the same: callers leave them out.
    #[inline(always)]
    pub(super) fn shell_second_derivatives_block(
        &self,
        shell: &PreparedShell,
        d: &[[f64; BLOCK]; 3],
        r2: &[f64; BLOCK],
        out: &mut [DerivativeBlock],
        scratch: &mut BlockScratch,
    ) {
        let l = shell.l as usize;
        let (rad, rad1, rad2) = self.radial_block(shell, r2);
        let BlockScratch { cart, powers: pw } = scratch;
        for (axis, pw) in pw.iter_mut().enumerate() {
            pw[0] = [[1.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]];
            for p in 1..=l {
                let (lower, upper) = pw.split_at_mut(p);
                let ([v, d1, _], [vn, d1n, d2n]) = (&lower[p - 1], &mut upper[0]);
                for i in 0..BLOCK {
                    (vn[i], d1n[i], d2n[i]) = (v[i] * d[axis][i], p as f64 * v[i], p as f64 * d1[i]);
                }
            }
        }
        let cartesian = !shell.pure;
        if !cartesian {
            cart.clear();
            cart.resize(self.powers[l].len(), [[0.0; BLOCK]; 10]);
        }
        let target: &mut [DerivativeBlock] = if cartesian { out } else { cart };
        for ((p, f), c) in self.powers[l].iter().zip(&self.component_factors[l]).zip(target.iter_mut()) {
            let [x, y, z] = [&pw[0][p[0] as usize], &pw[1][p[1] as usize], &pw[2][p[2] as usize]];
            for i in 0..BLOCK {
                let m = x[0][i] * y[0][i] * z[0][i];
                let dm = [x[1][i] * y[0][i] * z[0][i], x[0][i] * y[1][i] * z[0][i], x[0][i] * y[0][i] * z[1][i]];
                let ddm = [
                    x[2][i] * y[0][i] * z[0][i],
                    x[1][i] * y[1][i] * z[0][i],
                    x[1][i] * y[0][i] * z[1][i],
                    x[0][i] * y[2][i] * z[0][i],
                    x[0][i] * y[1][i] * z[1][i],
                    x[0][i] * y[0][i] * z[2][i],
                ];
                let da = [d[0][i], d[1][i], d[2][i]];
                c[0][i] = m * rad[i] * f;
                for a in 0..3 {
                    c[1 + a][i] = (dm[a] * rad[i] + m * da[a] * rad1[i]) * f;
                }
                for (k, &(a, b)) in HESSIAN_PAIRS.iter().enumerate() {
                    let delta = if a == b { rad1[i] } else { 0.0 };
                    c[4 + k][i] = (ddm[k] * rad[i]
                        + (dm[a] * da[b] + dm[b] * da[a]) * rad1[i]
                        + m * (da[a] * da[b] * rad2[i] + delta))
                        * f;
                }
            }
        }
        if !cartesian {
            let t = &self.pure_matrices[l];
            let nc = cart.len();
            for (k, o) in out[..shell.n_functions as usize].iter_mut().enumerate() {
                *o = [[0.0; BLOCK]; 10];
                for (w, c) in t[k * nc..(k + 1) * nc].iter().zip(cart.iter()) {
                    if *w != 0.0 {
                        for (o, c) in o.iter_mut().zip(c) {
                            for i in 0..BLOCK {
                                o[i] += w * c[i];
                            }
                        }
                    }
                }
            }
        }
    }

    /// The radial part R = Σ c_j e_j (e_j = exp(−α_j r²)), R₁ = Σ −2α_j c_j e_j and
    /// R₂ = Σ 4α_j² c_j e_j at each point of a block, each primitive within its cutoff.
    #[inline(always)]
    fn radial_block(&self, shell: &PreparedShell, r2: &[f64; BLOCK]) -> ([f64; BLOCK], [f64; BLOCK], [f64; BLOCK]) {
        let (mut rad, mut rad1, mut rad2) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
        for j in shell.primitives() {
            let (alpha, c, cut) = (self.exponents[j], self.coefficients[j], self.primitive_cutoffs2[j]);
            let mut e = [0.0; BLOCK];
            for (e, &r2) in e.iter_mut().zip(r2) {
                if r2 <= cut {
                    *e = c * (-alpha * r2).exp();
                }
            }
            for i in 0..BLOCK {
                rad[i] += e[i];
                rad1[i] -= 2.0 * alpha * e[i];
                rad2[i] += 4.0 * alpha * alpha * e[i];
            }
        }
        (rad, rad1, rad2)
    }

    /// Every basis function's `[v, ∂x, ∂y, ∂z, ∂xx, ∂xy, ∂xz, ∂yy, ∂yz, ∂zz]` at `point`
    /// (bohr), in the basis's order.
    pub fn basis_second_derivatives(&self, point: DVec3) -> Vec<[f64; 10]> {
        let mut out = vec![[0.0; 10]; self.n_functions];
        let mut cart = Vec::new();
        for s in &self.shells {
            self.shell_second_derivatives(s, point - s.center(), &mut out[s.functions()], &mut cart);
        }
        out
    }

    /// All basis-function values at `point` (bohr), in the basis's order.
    pub fn basis_values(&self, point: DVec3) -> Vec<f64> {
        let mut out = vec![0.0; self.n_functions];
        let (mut c, mut cg) = (Vec::new(), Vec::new());
        for s in &self.shells {
            let r = s.functions();
            self.shell_values(s, point - s.center(), &mut out[r], None, &mut c, &mut cg);
        }
        out
    }

    /// All basis-function values and gradients at `point`.
    pub fn basis_values_and_gradients(&self, point: DVec3) -> (Vec<f64>, Vec<DVec3>) {
        let mut out = vec![0.0; self.n_functions];
        let mut grads = vec![DVec3::ZERO; self.n_functions];
        let (mut c, mut cg) = (Vec::new(), Vec::new());
        for s in &self.shells {
            let r = s.functions();
            self.shell_values(s, point - s.center(), &mut out[r.clone()], Some(&mut grads[r]), &mut c, &mut cg);
        }
        (out, grads)
    }

    /// ψ(point) = Σ_k c_k χ_k(point).
    pub fn orbital_value(&self, coefficients: &[f64], point: DVec3) -> f64 {
        dot(coefficients, &self.basis_values(point))
    }

    /// ψ(point) and ∇ψ(point).
    pub fn orbital_value_and_gradient(&self, coefficients: &[f64], point: DVec3) -> (f64, DVec3) {
        let (v, g) = self.basis_values_and_gradients(point);
        let grad = coefficients.iter().zip(&g).fold(DVec3::ZERO, |acc, (c, g)| acc + *c * *g);
        (dot(coefficients, &v), grad)
    }

    /// Electron density Σ n_i |ψ_i|² over all orbitals (alpha and beta; a restricted orbital
    /// carries its occupation up to 2).
    pub fn density(&self, wf: &Wavefunction, point: DVec3) -> f64 {
        density_of(wf, &self.basis_values(point))
    }

    /// Spin density ρα − ρβ (see [`spin_weight`]).
    pub fn spin_density(&self, wf: &Wavefunction, point: DVec3) -> f64 {
        spin_density_of(wf, &self.basis_values(point))
    }

    /// An orbital, a bare basis function, the total density or the spin density of `wf` at each
    /// of `points` (what [`Self::orbital_value`], [`Self::density`]… give), one scratch for all;
    /// NaN for the potential, which needs the nuclei, and for the quantities of the density's
    /// derivatives ([`Self::quantity_at_points`] serves both).
    pub(super) fn quantity_at(&self, wf: &Wavefunction, quantity: Quantity, points: &[DVec3]) -> Vec<f64> {
        let mut values = vec![0.0; self.n_functions];
        let (mut c, mut cg) = (Vec::new(), Vec::new());
        // An excited state's density: its natural orbitals with their weights.
        let state = super::evaluation::state_sets(wf, quantity);
        points
            .iter()
            .map(|&p| {
                for s in &self.shells {
                    self.shell_values(s, p - s.center(), &mut values[s.functions()], None, &mut c, &mut cg);
                }
                match quantity {
                    Quantity::Orbital(i) => dot(&wf.orbitals[i].coefficients, &values),
                    Quantity::BasisFunction(k) => values[k],
                    Quantity::Density => density_of(wf, &values),
                    Quantity::SpinDensity => spin_density_of(wf, &values),
                    Quantity::DifferenceDensity
                    | Quantity::Attachment
                    | Quantity::Detachment
                    | Quantity::ExcitedDensity => state.iter().map(|(c, w)| w * dot(c, &values).powi(2)).sum(),
                    Quantity::Potential
                    | Quantity::ReducedGradient
                    | Quantity::NciGradient
                    | Quantity::NciCloud
                    | Quantity::SignLambda2Rho
                    | Quantity::DensityLaplacian
                    // Of the document's transitions: `crate::evaluate::meshes::values_at`.
                    | Quantity::TransitionDensity(_) => f64::NAN,
                }
            })
            .collect()
    }

    /// Coefficients restricted to the basis functions in `subset` (others set to 0): the
    /// "atomic orbital selector" view of an orbital, or a single basis function with a
    /// coefficient of 1.
    pub fn masked_coefficients(&self, coefficients: &[f64], subset: &[usize]) -> Vec<f64> {
        let mut out = vec![0.0; self.n_functions];
        for &i in subset {
            if i < out.len() {
                out[i] = coefficients.get(i).copied().unwrap_or(0.0);
            }
        }
        out
    }

    /// The coefficients of basis function `k` alone: 1 on it, 0 elsewhere (none past the last).
    pub fn unit_coefficients(&self, k: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.n_functions];
        if let Some(c) = out.get_mut(k) {
            *c = 1.0;
        }
        out
    }

    /// Per shell, the orbital's coefficients on the shell's cartesian monomials x^a y^b z^c
    /// (component factors and pure transformation folded in); flat, indexed by
    /// `first_cartesian`. Also returns which shells have any non-zero coefficient.
    pub fn monomial_coefficients(&self, coefficients: &[f64]) -> (Vec<f64>, Vec<bool>) {
        let mut d = vec![0.0; self.n_cartesians];
        let mut active = vec![false; self.shells.len()];
        for (si, s) in self.shells.iter().enumerate() {
            let l = s.l as usize;
            let f = &self.component_factors[l];
            let nc = f.len();
            let c = |k: usize| coefficients.get(s.first_function as usize + k).copied();
            let out = &mut d[s.cartesians()];
            if s.pure {
                let t = &self.pure_matrices[l];
                for k in 0..s.n_functions as usize {
                    let ck = c(k).unwrap_or(0.0);
                    if ck != 0.0 {
                        for i in 0..nc {
                            out[i] += ck * t[k * nc + i];
                        }
                    }
                }
            } else {
                for (i, o) in out.iter_mut().enumerate() {
                    *o = c(i).unwrap_or(0.0);
                }
            }
            for i in 0..nc {
                out[i] *= f[i];
            }
            active[si] = out.iter().any(|v| *v != 0.0);
        }
        (d, active)
    }

    /// [`Self::grid_sum`] on any grid, row by row.
    pub(super) fn grid_sum_rows(&self, sets: &[(&[f64], f64)], square: bool, grid: &GridSpec) -> Vec<f64> {
        let [nx, ny, nz] = grid.dims;
        let mut out = vec![0.0; grid.len()];
        if out.is_empty() || sets.is_empty() {
            return out;
        }
        let prepared: Vec<(Vec<f64>, Vec<bool>, f64)> = sets
            .iter()
            .map(|(c, w)| {
                let (d, a) = self.monomial_coefficients(c);
                (d, a, *w)
            })
            .collect();
        let any_active: Vec<bool> = (0..self.shells.len()).map(|s| prepared.iter().any(|p| p.1[s])).collect();
        const BLOCK: usize = 8;
        let v = grid.step(2);
        let _ = nx;
        out.par_chunks_mut(ny * nz).enumerate().for_each(|(ix, slab)| {
            let mut scratch = RowScratch::new(nz, prepared.len());
            let mut candidates = Vec::new();
            for iy0 in (0..ny).step_by(BLOCK) {
                let iy1 = (iy0 + BLOCK).min(ny);
                // Bounding sphere of the block's points.
                let corner = grid.point(ix, iy0, 0);
                let ey = (iy1 - iy0 - 1) as f64 * grid.step(1);
                let ez = (nz - 1) as f64 * v;
                let centre = corner + 0.5 * (ey + ez);
                let radius = (0.5 * (ey + ez)).length().max((0.5 * (ey - ez)).length());
                candidates.clear();
                for (si, s) in self.shells.iter().enumerate() {
                    if any_active[si] && s.center().distance(centre) <= s.cutoff + radius {
                        candidates.push(si);
                    }
                }
                for iy in iy0..iy1 {
                    let row = &mut slab[iy * nz..(iy + 1) * nz];
                    let p0 = grid.point(ix, iy, 0);
                    self.row(&prepared, &candidates, p0, v, square, row, &mut scratch);
                }
            }
        });
        out
    }

    /// One grid row: points p0 + k·v, k = 0..out.len().
    #[allow(
        clippy::too_many_arguments,
        reason = "the inner loop's row: scratch buffers passed in to avoid allocating per row"
    )]
    fn row(
        &self,
        sets: &[(Vec<f64>, Vec<bool>, f64)],
        candidates: &[usize],
        p0: DVec3,
        v: DVec3,
        square: bool,
        out: &mut [f64],
        scratch: &mut RowScratch,
    ) {
        let n = out.len();
        let single = sets.len() == 1 && !square;
        if !single {
            for acc in &mut scratch.psi {
                acc.fill(0.0);
            }
        }
        let a = v.length_squared();
        for &si in candidates {
            let s = &self.shells[si];
            let u = p0 - s.center();
            let b = u.dot(v);
            let c0 = u.length_squared();
            let Some((k0, k1)) = interval(a, b, c0, s.cutoff * s.cutoff, n) else {
                continue;
            };
            // Radial part along the row.
            let rad = &mut scratch.radial[k0..k1];
            rad.fill(0.0);
            let mut any = false;
            for j in s.primitives() {
                let r2max = primitive_reach2(self, j);
                let Some((j0, j1)) = interval(a, b, c0, r2max, n) else {
                    continue;
                };
                let (j0, j1) = (j0.max(k0), j1.min(k1));
                if j0 >= j1 {
                    continue;
                }
                any = true;
                accumulate_gaussian(
                    &mut rad[j0 - k0..j1 - k0],
                    j0,
                    self.coefficients[j],
                    self.exponents[j],
                    [a, b, c0],
                );
            }
            if !any {
                continue;
            }
            // Angular polynomial in t = k − km, expanded around the point nearest the centre.
            let km = if a > 0.0 { (-b / a).round().clamp(k0 as f64, (k1 - 1) as f64) } else { k0 as f64 };
            let uc = u + km * v;
            let l = s.l as usize;
            let powers = &self.powers[l];
            let binom = axis_polynomials(uc, v, l);
            for (set, (d, active, _)) in sets.iter().enumerate() {
                if !active[si] {
                    continue;
                }
                let d = &d[s.cartesians()];
                let mut poly = [0.0f64; 8];
                for (i, p) in powers.iter().enumerate() {
                    if d[i] == 0.0 {
                        continue;
                    }
                    let mut term = [0.0f64; 8];
                    let bx = &binom[0][p[0] as usize];
                    let by = &binom[1][p[1] as usize];
                    let bz = &binom[2][p[2] as usize];
                    // (x-poly · y-poly) · z-poly.
                    let mut xy = [0.0f64; 8];
                    for (i1, cx) in bx.iter().enumerate().take(p[0] as usize + 1) {
                        for (i2, cy) in by.iter().enumerate().take(p[1] as usize + 1) {
                            xy[i1 + i2] += cx * cy;
                        }
                    }
                    for (i1, cxy) in xy.iter().enumerate().take((p[0] + p[1]) as usize + 1) {
                        for (i2, cz) in bz.iter().enumerate().take(p[2] as usize + 1) {
                            term[i1 + i2] += cxy * cz;
                        }
                    }
                    for e in 0..=l {
                        poly[e] += d[i] * term[e];
                    }
                }
                let target: &mut [f64] = if single { &mut out[..] } else { &mut scratch.psi[set][..] };
                if l == 0 {
                    let c = poly[0];
                    for (o, r) in target[k0..k1].iter_mut().zip(rad.iter()) {
                        *o += c * r;
                    }
                } else {
                    for (idx, (o, r)) in target[k0..k1].iter_mut().zip(rad.iter()).enumerate() {
                        let t = (k0 + idx) as f64 - km;
                        let mut h = poly[l];
                        for e in (0..l).rev() {
                            h = h * t + poly[e];
                        }
                        *o += h * r;
                    }
                }
            }
        }
        if !single {
            for (set, (_, _, w)) in sets.iter().enumerate() {
                let psi = &scratch.psi[set];
                if square {
                    for (o, p) in out.iter_mut().zip(psi) {
                        *o += w * p * p;
                    }
                } else {
                    for (o, p) in out.iter_mut().zip(psi) {
                        *o += w * p;
                    }
                }
            }
        }
    }
}

struct RowScratch {
    radial: Vec<f64>,
    psi: Vec<Vec<f64>>,
}

impl RowScratch {
    fn new(n: usize, sets: usize) -> Self {
        Self { radial: vec![0.0; n], psi: vec![vec![0.0; n]; if sets > 1 { sets } else { 1 }] }
    }
}

/// Adds c·exp(−α r²(k)) to `rad[k − k_start]` for k = k_start.., where
/// r²(k) = a k² + 2b k + c0 (`quad` = [a, b, c0]).
///
/// Four interleaved recurrences (points k, k+1, k+2, k+3 of each group of four) keep the
/// multiplications independent; each segment of [`RESEED`] points starts from exact `exp`s.
fn accumulate_gaussian(rad: &mut [f64], k_start: usize, c: f64, alpha: f64, quad: [f64; 3]) {
    let [a, b, c0] = quad;
    // Ratio between the stride-4 ratios of consecutive groups: exp(−32 α a).
    let big_w = (-32.0 * alpha * a).exp();
    // Ratio between the stride-4 ratios of neighbouring lanes: exp(−8 α a).
    let lane_w = (-8.0 * alpha * a).exp();
    let step_w = (-2.0 * alpha * a).exp();
    let n = rad.len();
    let mut start = 0;
    while start < n {
        let end = (start + RESEED).min(n);
        let kf = (k_start + start) as f64;
        let r2 = (a * kf + 2.0 * b) * kf + c0;
        let mut g = [0.0f64; 4];
        g[0] = c * (-alpha * r2).exp();
        let mut q = (-alpha * (2.0 * (b + a * kf) + a)).exp();
        for lane in 1..4 {
            g[lane] = g[lane - 1] * q;
            q *= step_w;
        }
        let mut big_q = [0.0f64; 4];
        big_q[0] = (-alpha * (8.0 * (a * kf + b) + 16.0 * a)).exp();
        for lane in 1..4 {
            big_q[lane] = big_q[lane - 1] * lane_w;
        }
        let seg = &mut rad[start..end];
        let mut chunks = seg.chunks_exact_mut(4);
        for chunk in &mut chunks {
            for lane in 0..4 {
                chunk[lane] += g[lane];
                g[lane] *= big_q[lane];
                big_q[lane] *= big_w;
            }
        }
        for (r, gl) in chunks.into_remainder().iter_mut().zip(g) {
            *r += gl;
        }
        start = end;
    }
}

/// For each axis and power e ≤ l, the coefficients of (u + t·v)^e as a polynomial in t.
fn axis_polynomials(u: DVec3, v: DVec3, l: usize) -> [[[f64; 8]; 8]; 3] {
    let mut out = [[[0.0; 8]; 8]; 3];
    for axis in 0..3 {
        out[axis][0][0] = 1.0;
        for e in 1..=l {
            let (prev, cur) = out[axis].split_at_mut(e);
            let prev = &prev[e - 1];
            for j in 0..=e {
                let mut c = 0.0;
                if j < e {
                    c += prev[j] * u[axis];
                }
                if j > 0 {
                    c += prev[j - 1] * v[axis];
                }
                cur[0][j] = c;
            }
        }
    }
    out
}

/// Squared radius within which primitive `p` is evaluated: its cutoff, and at most α r² = 690,
/// where the exponential underflows anyway (bounding the recurrence ratios too, so nothing
/// overflows without a threshold).
pub(super) fn primitive_reach2(basis: &PreparedBasis, p: usize) -> f64 {
    basis.primitive_cutoffs2[p].min(690.0 / basis.exponents[p])
}

/// Indices k in 0..n with a·k² + 2b·k + c0 ≤ r2max, as a half-open range.
pub(super) fn interval(a: f64, b: f64, c0: f64, r2max: f64, n: usize) -> Option<(usize, usize)> {
    if r2max.is_infinite() {
        return Some((0, n));
    }
    if a <= 0.0 {
        return (c0 <= r2max).then_some((0, n));
    }
    let disc = b * b - a * (c0 - r2max);
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    let lo = ceil((-b - sq) / a).max(0.0);
    let hi = floor((-b + sq) / a);
    if hi < lo || hi < 0.0 {
        return None;
    }
    let lo = lo as usize;
    let hi = (hi as usize + 1).min(n);
    (lo < hi).then_some((lo, hi))
}

/// ⌈x⌉ by integer conversion (`ceil` is a library call on baseline x86-64; this runs per row).
fn ceil(x: f64) -> f64 {
    -floor(-x)
}

/// ⌊x⌋ by integer conversion; magnitudes from 2^52 up are integers already.
fn floor(x: f64) -> f64 {
    if x.abs() >= 4_503_599_627_370_496.0 {
        return x;
    }
    let t = x as i64 as f64;
    if t > x { t - 1.0 } else { t }
}

/// An orbital's scale measured from samples, without a grid: its largest |ψ| and |∇ψ| over a
/// box, and its values on a coarse lattice of the box.
#[derive(Debug, Clone)]
pub struct SampledRange {
    pub max_abs: f64,
    /// Largest analytic gradient magnitude (per bohr).
    pub max_grad: f64,
    /// ψ on the lattice (`n`³ points spanning the box, cube order).
    pub samples: super::VolumeGrid,
}

/// Starting points kept for the climbs to the peaks of |ψ| and of |∇ψ|.
const CLIMBS: usize = 6;

impl PreparedBasis {
    /// Measures the combination `coefficients` of basis functions over the box `grid` spans: ψ
    /// and ∇ψ (analytic) at a lattice of `n`³ points, then, since lattice points miss the peaks
    /// between them, a climb from the largest lattice maxima of |ψ| and of |∇ψ| to the peaks
    /// themselves (staying inside the box).
    pub fn sampled_range(&self, coefficients: &[f64], grid: &GridSpec, n: usize) -> SampledRange {
        let n = n.max(2);
        let scale = DVec3::from_array(std::array::from_fn(|a| (grid.dims[a].max(2) - 1) as f64 / (n - 1) as f64));
        let world_from_lattice = grid.world_from_grid * glam::DMat4::from_scale(scale);
        let at = |u: DVec3| self.orbital_value_and_gradient(coefficients, world_from_lattice.transform_point3(u));
        let index = |m: usize| DVec3::new((m / (n * n)) as f64, (m / n % n) as f64, (m % n) as f64);
        let sampled: Vec<(f64, DVec3)> = (0..n * n * n).into_par_iter().map(|m| at(index(m))).collect();
        let abs: Vec<f64> = sampled.iter().map(|s| s.0.abs()).collect();
        let grad: Vec<f64> = sampled.iter().map(|s| s.1.length()).collect();
        let mut max_abs = abs.iter().fold(0.0f64, |m, &v| m.max(v));
        let mut max_grad = grad.iter().fold(0.0f64, |m, &v| m.max(v));
        let top = |f: &[f64]| {
            let mut peaks: Vec<usize> = (0..f.len()).filter(|&m| f[m] > 0.0 && lattice_peak(f, n, m)).collect();
            peaks.sort_by(|&a, &b| f[b].total_cmp(&f[a]));
            peaks.truncate(CLIMBS);
            peaks
        };
        let hi = DVec3::splat((n - 1) as f64);
        for m in top(&abs) {
            max_abs = max_abs.max(climb(|u| at(u).0.abs(), index(m), hi));
        }
        for m in top(&grad) {
            max_grad = max_grad.max(climb(|u| at(u).1.length(), index(m), hi));
        }
        let values = sampled.iter().map(|s| s.0 as f32).collect();
        SampledRange {
            max_abs,
            max_grad,
            samples: super::VolumeGrid::new("orbital samples", [n; 3], world_from_lattice, values),
        }
    }
}

/// Whether lattice point `m` of `f` (`n`³ values, cube order) is at least its six neighbours.
fn lattice_peak(f: &[f64], n: usize, m: usize) -> bool {
    let (i, j, k) = (m / (n * n), m / n % n, m % n);
    let strides = [n * n, n, 1];
    [i, j, k].iter().zip(strides).all(|(&c, s)| (c == 0 || f[m - s] <= f[m]) && (c + 1 == n || f[m + s] <= f[m]))
}

/// The largest value of `f` a compass search reaches from `start` within the box 0..`hi` (steps
/// from half a lattice spacing down to 1/256 of one); at least `f(start)`.
fn climb(f: impl Fn(DVec3) -> f64, start: DVec3, hi: DVec3) -> f64 {
    let (mut u, mut best, mut h) = (start, f(start), 0.5);
    for _ in 0..200 {
        if h < 1.0 / 256.0 {
            break;
        }
        let moves = (0..6).map(|d| {
            let mut v = u;
            v[d / 2] = (v[d / 2] + if d % 2 == 0 { h } else { -h }).clamp(0.0, hi[d / 2]);
            v
        });
        match moves.map(|v| (f(v), v)).max_by(|a, b| a.0.total_cmp(&b.0)) {
            Some((value, v)) if value > best => (best, u) = (value, v),
            _ => h *= 0.5,
        }
    }
    best
}

/// Weight of an orbital in the spin density: +n for alpha and −n for beta orbitals of an
/// unrestricted wavefunction; for a restricted one, the unpaired part min(n, 2 − n) (an
/// open-shell orbital with occupation 1 counts as alpha).
pub fn spin_weight(wf: &Wavefunction, occupation: f64, spin: Spin) -> f64 {
    if wf.restricted {
        occupation.min(2.0 - occupation).max(0.0)
    } else {
        match spin {
            Spin::Alpha => occupation,
            Spin::Beta => -occupation,
        }
    }
}

/// Σ n_i ψ_i² from the basis-function values at a point.
fn density_of(wf: &Wavefunction, values: &[f64]) -> f64 {
    wf.orbitals
        .iter()
        .filter(|o| o.occupation != 0.0)
        .map(|o| {
            let psi = dot(&o.coefficients, values);
            o.occupation * psi * psi
        })
        .sum()
}

/// ρα − ρβ from the basis-function values at a point.
fn spin_density_of(wf: &Wavefunction, values: &[f64]) -> f64 {
    wf.orbitals
        .iter()
        .map(|o| (spin_weight(wf, o.occupation, o.spin), o))
        .filter(|(w, _)| *w != 0.0)
        .map(|(w, o)| {
            let psi = dot(&o.coefficients, values);
            w * psi * psi
        })
        .sum()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::model::basis::Shell;
    use crate::model::orbitals::MolecularOrbital;
    use crate::model::overlap::overlap_matrix;
    use crate::model::solid_harmonics::cartesian_overlap;

    fn shell(center: DVec3, l: u32, kind: ShellKind, scale: f64) -> Shell {
        Shell {
            atom: 0,
            center,
            l,
            kind,
            exponents: vec![4.0 * scale, 1.1 * scale, 0.3 * scale],
            coefficients: vec![0.3, 0.5, 0.4],
        }
    }

    /// Shells up to h on three centres, cartesian and pure.
    fn test_basis() -> Basis {
        let centres = [DVec3::ZERO, DVec3::new(1.2, -0.4, 0.7), DVec3::new(-0.9, 1.5, -0.3)];
        let mut shells = Vec::new();
        for l in 0..=5 {
            shells.push(shell(centres[l as usize % 3], l, ShellKind::Pure, 1.0));
            shells.push(shell(centres[(l as usize + 1) % 3], l, ShellKind::Cartesian, 0.7));
        }
        Basis { shells }
    }

    /// Reproducible values in −1..1 (a linear congruential sequence).
    pub(crate) fn pseudo_random(n: usize, seed: u64) -> Vec<f64> {
        let mut x = seed;
        (0..n)
            .map(|_| {
                x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
            })
            .collect()
    }

    fn points(n: usize, seed: u64, half: f64) -> Vec<DVec3> {
        let r = pseudo_random(3 * n, seed);
        r.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2]) * half).collect()
    }

    #[test]
    fn floor_and_ceil_match_the_library() {
        let mut values = pseudo_random(2000, 17).iter().map(|v| v * 300.0).collect::<Vec<_>>();
        values.extend([0.0, -0.0, 1.0, -1.0, 2.5, -2.5, 1e17, -1e17, 4503599627370495.5, f64::MAX]);
        for v in values {
            assert_eq!(floor(v), v.floor(), "{v}");
            assert_eq!(ceil(v), v.ceil(), "{v}");
        }
    }

    #[test]
    fn self_overlap_is_unit_for_every_l() {
        for l in 0..=5 {
            for kind in [ShellKind::Cartesian, ShellKind::Pure] {
                let basis = Basis { shells: vec![shell(DVec3::new(0.3, 0.1, -0.2), l, kind, 1.0)] };
                let s = overlap_matrix(&basis);
                let n = basis.n_functions();
                let want = match kind {
                    ShellKind::Cartesian => cartesian_overlap(l),
                    ShellKind::Pure if l == 1 => cartesian_overlap(1),
                    ShellKind::Pure => {
                        let mut id = vec![0.0; n * n];
                        (0..n).for_each(|i| id[i * n + i] = 1.0);
                        id
                    }
                };
                for (i, (a, b)) in s.iter().zip(&want).enumerate() {
                    assert!((a - b).abs() < 1e-12, "l={l} {kind:?} [{i}] {a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn overlap_matches_numerical_quadrature() {
        // Two displaced d and f shells: a brute-force sum on a fine grid.
        let basis = Basis {
            shells: vec![
                shell(DVec3::new(0.0, 0.0, 0.0), 2, ShellKind::Pure, 1.0),
                shell(DVec3::new(0.6, -0.3, 0.4), 3, ShellKind::Cartesian, 1.0),
            ],
        };
        let pb = PreparedBasis::with_threshold(&basis, 0.0);
        let s = overlap_matrix(&basis);
        let n = pb.n_functions();
        let (h, m) = (0.15, 56i32);
        let mut num = vec![0.0; n * n];
        for i in -m..m {
            for j in -m..m {
                for k in -m..m {
                    let p = DVec3::new(i as f64, j as f64, k as f64) * h + DVec3::splat(0.3 * h);
                    let v = pb.basis_values(p);
                    for a in 0..n {
                        if v[a] == 0.0 {
                            continue;
                        }
                        for b in 0..n {
                            num[a * n + b] += v[a] * v[b] * h * h * h;
                        }
                    }
                }
            }
        }
        for (a, b) in s.iter().zip(&num) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
    }

    #[test]
    fn gradients_match_finite_differences() {
        let pb = PreparedBasis::new(&test_basis());
        let h = 1e-5;
        for p in points(20, 7, 2.0) {
            let (v, g) = pb.basis_values_and_gradients(p);
            assert_eq!(v, pb.basis_values(p));
            for axis in 0..3 {
                let mut e = DVec3::ZERO;
                e[axis] = h;
                let (vp, vm) = (pb.basis_values(p + e), pb.basis_values(p - e));
                for f in 0..v.len() {
                    let fd = (vp[f] - vm[f]) / (2.0 * h);
                    assert!(
                        (fd - g[f][axis]).abs() < 1e-6 * (1.0 + fd.abs()),
                        "function {f} axis {axis}: {fd} vs {}",
                        g[f][axis]
                    );
                }
            }
            let c = pseudo_random(v.len(), 3);
            let (psi, grad) = pb.orbital_value_and_gradient(&c, p);
            assert!((psi - pb.orbital_value(&c, p)).abs() < 1e-14);
            let want = g.iter().zip(&c).fold(DVec3::ZERO, |a, (g, c)| a + *c * *g);
            assert!((grad - want).length() < 1e-12);
        }
    }

    #[test]
    fn second_derivatives_match_finite_differences_of_the_gradients() {
        // Up to h, pure and cartesian, on three centres, with and without cutoffs.
        for threshold in [DEFAULT_THRESHOLD, 0.0] {
            let pb = PreparedBasis::with_threshold(&test_basis(), threshold);
            let h = 1e-5;
            let mut checked = 0;
            for p in points(25, 11, 2.0) {
                let all = pb.basis_second_derivatives(p);
                let (v, g) = pb.basis_values_and_gradients(p);
                for f in 0..v.len() {
                    assert!((all[f][0] - v[f]).abs() < 1e-14 * (1.0 + v[f].abs()), "value of {f}");
                    for a in 0..3 {
                        assert!((all[f][1 + a] - g[f][a]).abs() < 1e-13 * (1.0 + g[f][a].abs()), "∂{a} of {f}");
                    }
                }
                for (k, (a, b)) in [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)].into_iter().enumerate() {
                    let mut e = DVec3::ZERO;
                    e[b] = h;
                    let (gp, gm) = (pb.basis_values_and_gradients(p + e).1, pb.basis_values_and_gradients(p - e).1);
                    for f in 0..v.len() {
                        let fd = (gp[f][a] - gm[f][a]) / (2.0 * h);
                        let got = all[f][4 + k];
                        assert!(
                            (fd - got).abs() < 1e-6 * (1.0 + fd.abs()),
                            "function {f} ∂{a}∂{b} at {p}: {fd} vs {got}"
                        );
                        checked += (fd.abs() > 1e-3) as usize;
                    }
                }
            }
            assert!(checked > 1000, "most second derivatives are not negligible: {checked}");
        }
    }

    #[test]
    fn block_second_derivatives_equal_the_point_ones_to_the_bit() {
        // Pure and cartesian up to l = 5, a block of points of which some are beyond the
        // tighter primitives' cutoffs.
        let pb = PreparedBasis::new(&test_basis());
        let block = points(BLOCK, 5, 4.0);
        let mut scratch = BlockScratch::default();
        let mut cart = Vec::new();
        for s in &pb.shells {
            let mut d = [[0.0; BLOCK]; 3];
            let mut r2 = [0.0; BLOCK];
            for (i, p) in block.iter().enumerate() {
                let v = *p - s.center();
                (d[0][i], d[1][i], d[2][i], r2[i]) = (v.x, v.y, v.z, v.length_squared());
            }
            let mut got = vec![[[0.0; BLOCK]; 10]; s.n_functions as usize];
            pb.shell_second_derivatives_block(s, &d, &r2, &mut got, &mut scratch);
            for (i, p) in block.iter().enumerate() {
                let mut want = vec![[0.0; 10]; s.n_functions as usize];
                pb.shell_second_derivatives(s, *p - s.center(), &mut want, &mut cart);
                for (g, w) in got.iter().zip(&want) {
                    for t in 0..10 {
                        let beyond = r2[i] > s.cutoff * s.cutoff;
                        assert!(beyond || g[t][i].to_bits() == w[t].to_bits(), "l {} point {i}", s.l);
                    }
                }
            }
        }
    }

    #[test]
    fn grid_equals_point_evaluation() {
        let pb = PreparedBasis::new(&test_basis());
        let c = pseudo_random(pb.n_functions(), 11);
        let grid = GridSpec::new(
            DVec3::new(-4.0, -3.5, -4.2),
            [DVec3::new(0.9, 0.1, 0.0), DVec3::new(0.05, 0.7, 0.1), DVec3::new(0.02, -0.03, 0.13)],
            [9, 11, 67],
        );
        let values = pb.eval_grid(&c, &grid);
        let f32s = pb.eval_grid_f32(&c, &grid);
        let [nx, ny, nz] = grid.dims;
        let mut worst: f64 = 0.0;
        for i in 0..nx {
            for j in 0..ny {
                for k in 0..nz {
                    let idx = (i * ny + j) * nz + k;
                    let want = pb.orbital_value(&c, grid.point(i, j, k));
                    worst = worst.max((values[idx] - want).abs());
                    assert!((f32s[idx] as f64 - want).abs() <= 1e-6 * (1.0 + want.abs()));
                }
            }
        }
        assert!(worst < 1e-11, "worst {worst}");
        // Without cutoffs, tight primitives far along a row must neither underflow nor overflow.
        let mut tight = test_basis();
        tight.shells.push(Shell {
            atom: 0,
            center: DVec3::new(0.1, 0.2, 0.3),
            l: 1,
            kind: ShellKind::Cartesian,
            exponents: vec![9.0e4, 5.0e3, 800.0],
            coefficients: vec![0.2, 0.5, 0.6],
        });
        let uncut = PreparedBasis::with_threshold(&tight, 0.0);
        let c = pseudo_random(uncut.n_functions(), 13);
        let values = uncut.eval_grid(&c, &grid);
        for (idx, v) in values.iter().enumerate().step_by(5) {
            let (i, j, k) = (idx / (ny * nz), idx / nz % ny, idx % nz);
            let want = uncut.orbital_value(&c, grid.point(i, j, k));
            assert!((v - want).abs() < 1e-11, "uncut: {v} vs {want}");
        }
        // Orthogonal steps along z only, a long row.
        let grid = GridSpec::new(
            DVec3::new(-5.0, -5.0, -6.0),
            [DVec3::X * 1.1, DVec3::Y * 0.9, DVec3::Z * 0.04],
            [10, 12, 300],
        );
        let values = pb.eval_grid(&c, &grid);
        for (idx, v) in values.iter().enumerate().step_by(7) {
            let (i, j, k) = (idx / (12 * 300), idx / 300 % 12, idx % 300);
            let want = pb.orbital_value(&c, grid.point(i, j, k));
            assert!((v - want).abs() < 1e-11, "{v} vs {want}");
        }
    }

    #[test]
    fn subset_and_density_grids_match_points() {
        let basis = test_basis();
        let pb = PreparedBasis::new(&basis);
        let n = pb.n_functions();
        let orbital = |seed, occupation, spin| MolecularOrbital {
            energy: -0.5,
            occupation,
            spin,
            symmetry: String::new(),
            coefficients: pseudo_random(n, seed),
        };
        let wf = Wavefunction {
            basis: basis.clone(),
            orbitals: vec![
                orbital(1, 1.0, Spin::Alpha),
                orbital(2, 1.0, Spin::Alpha),
                orbital(3, 1.0, Spin::Beta),
                orbital(4, 0.0, Spin::Beta),
            ],
            restricted: false,
            ..Default::default()
        };
        let grid = GridSpec::new(
            DVec3::splat(-3.0),
            [DVec3::X * 0.6, DVec3::Y * 0.55, DVec3::new(0.0, 0.01, 0.2)],
            [11, 12, 31],
        );
        let rho = pb.density_grid(&wf, &grid);
        let spin = pb.spin_density_grid(&wf, &grid);
        let subset = [0usize, 3, 7, 20, n - 1];
        let c = &wf.orbitals[0].coefficients;
        let part = pb.eval_grid_subset(c, &subset, &grid);
        let single = pb.eval_grid_subset(&vec![1.0; n], &[5], &grid);
        for i in 0..11 {
            for j in 0..12 {
                for k in 0..31 {
                    let idx = (i * 12 + j) * 31 + k;
                    let p = grid.point(i, j, k);
                    let r = pb.density(&wf, p);
                    assert!((rho[idx] - r).abs() <= 1e-11 * (1.0 + r));
                    let s = pb.spin_density(&wf, p);
                    assert!((spin[idx] - s).abs() <= 1e-11 * (1.0 + s.abs()));
                    let v = pb.basis_values(p);
                    let want: f64 = subset.iter().map(|&f| c[f] * v[f]).sum();
                    assert!((part[idx] - want).abs() < 1e-11);
                    assert!((single[idx] - v[5]).abs() < 1e-11);
                }
            }
        }
        // The same quantities at scattered points, one scratch for all of them.
        let scattered = points(50, 9, 3.0);
        for q in [Quantity::Orbital(1), Quantity::BasisFunction(7), Quantity::Density, Quantity::SpinDensity] {
            let at = |p| match q {
                Quantity::Orbital(i) => pb.orbital_value(&wf.orbitals[i].coefficients, p),
                Quantity::BasisFunction(k) => pb.basis_values(p)[k],
                Quantity::Density => pb.density(&wf, p),
                Quantity::SpinDensity => pb.spin_density(&wf, p),
                _ => f64::NAN,
            };
            for (v, &p) in pb.quantity_at(&wf, q, &scattered).iter().zip(&scattered) {
                assert_eq!(*v, at(p), "{q:?} at {p}");
            }
        }
    }

    #[test]
    fn cutoff_gives_exact_zero_far_away_and_stays_within_threshold() {
        let basis = test_basis();
        let cut = PreparedBasis::new(&basis);
        let full = PreparedBasis::with_threshold(&basis, 0.0);
        for s in &cut.shells {
            assert!(s.cutoff.is_finite() && s.cutoff > 1.0 && s.cutoff < 30.0);
        }
        let far = DVec3::new(40.0, -35.0, 20.0);
        assert!(cut.basis_values(far).iter().all(|v| *v == 0.0));
        let mut worst: f64 = 0.0;
        for p in points(400, 5, 14.0) {
            let (a, b) = (cut.basis_values(p), full.basis_values(p));
            for (x, y) in a.iter().zip(&b) {
                worst = worst.max((x - y).abs());
            }
        }
        assert!(worst <= DEFAULT_THRESHOLD, "worst {worst}");
        // Just outside each shell's radius, its functions are 0 in the cut basis and tiny in full.
        for s in &cut.shells {
            let p = s.center() + DVec3::new(1.0, 2.0, 2.0) / 3.0 * (s.cutoff * 1.0001);
            let (a, b) = (cut.basis_values(p), full.basis_values(p));
            for f in s.functions() {
                assert_eq!(a[f], 0.0);
                assert!(b[f].abs() <= DEFAULT_THRESHOLD);
            }
        }
    }

    #[test]
    fn sampled_range_finds_the_peaks_between_lattice_points() {
        // One normalised s Gaussian N·exp(−α r²): |ψ| peaks at the centre at N, |∇ψ| = 2αrψ
        // peaks at r = 1/√(2α) at N·√(2α)·e^(−½). The lattice (9 points over an off-centre box)
        // passes 0.36 bohr from the centre.
        let alpha = 1.3;
        let shell = Shell {
            atom: 0,
            center: DVec3::ZERO,
            l: 0,
            kind: ShellKind::Cartesian,
            exponents: vec![alpha],
            coefficients: vec![1.0],
        };
        let prepared = PreparedBasis::new(&Basis { shells: vec![shell] });
        let grid = GridSpec::cube(DVec3::new(-3.3, -2.8, -3.05), DVec3::new(2.9, 3.4, 3.15), 40);
        let range = prepared.sampled_range(&[1.0], &grid, 9);
        let n = (2.0 * alpha / std::f64::consts::PI).powf(0.75);
        let lattice_max = range.samples.stats.max_abs;
        assert!(lattice_max < 0.9 * n, "the lattice alone misses the peak ({lattice_max} vs {n})");
        assert!((range.max_abs / n - 1.0).abs() < 1e-4, "max |ψ| {} vs {n}", range.max_abs);
        let max_grad = n * (2.0 * alpha).sqrt() * (-0.5f64).exp();
        assert!((range.max_grad / max_grad - 1.0).abs() < 1e-4, "max |∇ψ| {} vs {max_grad}", range.max_grad);
        assert_eq!(range.samples.dims, [9; 3]);
        // The lattice spans the grid's box.
        let corner = range.samples.world_from_grid.transform_point3(DVec3::splat(8.0));
        assert!((corner - DVec3::new(2.9, 3.4, 3.15)).length() < 1e-9);
    }
}
