//! Analytic overlap matrix of a basis and the orthonormality check of orbitals.
//!
//! Cartesian primitive overlaps come from the Obara–Saika recurrences (one dimension at a
//! time); contracted blocks use the same normalised coefficients and unit-normalised components
//! as the evaluator ([`PreparedBasis`]), then pure shells are transformed with the
//! cartesian → pure matrices. So S describes exactly the functions `gto` evaluates.

use rayon::prelude::*;

use super::basis::Basis;
use super::gto::{PreparedBasis, PreparedShell};
use super::orbitals::{Spin, Wavefunction};

/// Primitive pairs with exp(−μ R²) below this contribute nothing to S.
const PAIR_SCREEN: f64 = 1e-17;

/// 1D overlaps s[i][j] = ∫ (x−A)^i (x−B)^j exp(−p (x−P)²) dx / sqrt(π/p), i ≤ la, j ≤ lb.
fn overlap_1d(la: usize, lb: usize, xpa: f64, xpb: f64, p: f64) -> [[f64; 8]; 8] {
    let mut s = [[0.0; 8]; 8];
    let h = 0.5 / p;
    s[0][0] = 1.0;
    for i in 0..la {
        s[i + 1][0] = xpa * s[i][0] + if i > 0 { i as f64 * h * s[i - 1][0] } else { 0.0 };
    }
    for j in 0..lb {
        for i in 0..=la {
            let mut v = xpb * s[i][j];
            if i > 0 {
                v += i as f64 * h * s[i - 1][j];
            }
            if j > 0 {
                v += j as f64 * h * s[i][j - 1];
            }
            s[i][j + 1] = v;
        }
    }
    s
}

/// Block of S between shell `a` of basis `ba` and shell `b` of basis `bb`, row-major
/// n_functions(a) × n_functions(b).
fn shell_pair(ba: &PreparedBasis, a: &PreparedShell, bb: &PreparedBasis, b: &PreparedShell) -> Vec<f64> {
    shell_pair_moment(ba, a, bb, b, None)
}

/// [`shell_pair`] of the operator 1 (`axis` `None`) or of the coordinate x, y or z (`axis`
/// 0, 1, 2; origin at 0): x χ_b = (x − B_x) χ_b + B_x χ_b raises b's power along the axis,
/// which the one-dimensional recurrence already holds one step further.
fn shell_pair_moment(
    ba: &PreparedBasis,
    a: &PreparedShell,
    bb: &PreparedBasis,
    b: &PreparedShell,
    axis: Option<usize>,
) -> Vec<f64> {
    let (la, lb) = (a.l as usize, b.l as usize);
    let raised = |d: usize| lb + usize::from(axis == Some(d));
    let (pa, pbw) = (&ba.powers[la], &bb.powers[lb]);
    let (fa, fb) = (&ba.component_factors[la], &bb.component_factors[lb]);
    let (na, nb) = (pa.len(), pbw.len());
    let mut cart = vec![0.0; na * nb];
    let ab = a.center() - b.center();
    let r2 = ab.length_squared();
    for i in a.primitives() {
        let (alpha, ca) = (ba.exponents[i], ba.coefficients[i]);
        for j in b.primitives() {
            let (beta, cb) = (bb.exponents[j], bb.coefficients[j]);
            let p = alpha + beta;
            let e = (-alpha * beta / p * r2).exp();
            if e < PAIR_SCREEN {
                continue;
            }
            let pref = ca * cb * e * (std::f64::consts::PI / p).powf(1.5);
            let pc = (alpha * a.center() + beta * b.center()) / p;
            let xpa = pc - a.center();
            let xpb = pc - b.center();
            let sx = overlap_1d(la, raised(0), xpa.x, xpb.x, p);
            let sy = overlap_1d(la, raised(1), xpa.y, xpb.y, p);
            let sz = overlap_1d(la, raised(2), xpa.z, xpb.z, p);
            let centre = b.center().to_array();
            let factor = |d: usize, s: &[[f64; 8]; 8], i: usize, j: usize| match axis {
                Some(m) if m == d => s[i][j + 1] + centre[d] * s[i][j],
                _ => s[i][j],
            };
            for (u, pu) in pa.iter().enumerate() {
                for (v, pv) in pbw.iter().enumerate() {
                    let [(i0, j0), (i1, j1), (i2, j2)] = [0, 1, 2].map(|d| (pu[d] as usize, pv[d] as usize));
                    cart[u * nb + v] += pref * factor(0, &sx, i0, j0) * factor(1, &sy, i1, j1) * factor(2, &sz, i2, j2);
                }
            }
        }
    }
    for u in 0..na {
        for v in 0..nb {
            cart[u * nb + v] *= fa[u] * fb[v];
        }
    }
    // Pure transformations: left T_a, right T_bᵀ.
    let left = if a.pure {
        let t = &ba.pure_matrices[la];
        let m = a.n_functions as usize;
        let mut out = vec![0.0; m * nb];
        for k in 0..m {
            for u in 0..na {
                let tk = t[k * na + u];
                if tk != 0.0 {
                    for v in 0..nb {
                        out[k * nb + v] += tk * cart[u * nb + v];
                    }
                }
            }
        }
        out
    } else {
        cart
    };
    if b.pure {
        let t = &bb.pure_matrices[lb];
        let m = a.n_functions as usize;
        let n = b.n_functions as usize;
        let mut out = vec![0.0; m * n];
        for r in 0..m {
            for k in 0..n {
                out[r * n + k] = (0..nb).map(|v| left[r * nb + v] * t[k * nb + v]).sum();
            }
        }
        out
    } else {
        left
    }
}

/// The overlap matrix of `basis`, row-major n × n.
pub fn overlap_matrix(basis: &Basis) -> Vec<f64> {
    PreparedBasis::with_threshold(basis, 0.0).overlap_matrix()
}

/// The first-moment (dipole) matrices ⟨χ_μ|x|χ_ν⟩, ⟨χ_μ|y|χ_ν⟩, ⟨χ_μ|z|χ_ν⟩ of `basis`
/// (origin at 0, bohr), each row-major n × n: tr(P X) is a density's ∫ x ρ.
pub fn moment_matrices(basis: &Basis) -> [Vec<f64>; 3] {
    let prepared = PreparedBasis::with_threshold(basis, 0.0);
    [0, 1, 2].map(|axis| prepared.symmetric_matrix(Some(axis)))
}

impl PreparedBasis {
    /// The overlap matrix of the prepared functions, row-major n × n.
    pub fn overlap_matrix(&self) -> Vec<f64> {
        self.symmetric_matrix(None)
    }

    /// The matrix of 1 or of a coordinate (see [`shell_pair_moment`]) over the prepared
    /// functions, row-major n × n; both operators are symmetric, so one triangle of shell
    /// pairs is computed.
    fn symmetric_matrix(&self, axis: Option<usize>) -> Vec<f64> {
        let n = self.n_functions();
        let blocks: Vec<(usize, usize, Vec<f64>)> = (0..self.shells.len())
            .into_par_iter()
            .flat_map_iter(|ia| {
                (0..=ia).map(move |ib| {
                    let (a, b) = (&self.shells[ia], &self.shells[ib]);
                    (ia, ib, shell_pair_moment(self, a, self, b, axis))
                })
            })
            .collect();
        let mut s = vec![0.0; n * n];
        for (ia, ib, block) in blocks {
            let (a, b) = (&self.shells[ia], &self.shells[ib]);
            let nb = b.n_functions as usize;
            for (u, i) in a.functions().enumerate() {
                for (v, j) in b.functions().enumerate() {
                    s[i * n + j] = block[u * nb + v];
                    s[j * n + i] = block[u * nb + v];
                }
            }
        }
        s
    }
}

/// The overlap ⟨χ_μ|χ'_ν⟩ between the functions of two bases (for instance one molecule at two
/// geometries), row-major n(a) × n(b).
pub fn cross_overlap(a: &PreparedBasis, b: &PreparedBasis) -> Vec<f64> {
    let nb = b.n_functions();
    let rows: Vec<Vec<f64>> = a
        .shells
        .par_iter()
        .map(|sa| {
            let mut rows = vec![0.0; sa.n_functions as usize * nb];
            for sb in &b.shells {
                let block = shell_pair(a, sa, b, sb);
                let n = sb.n_functions as usize;
                for u in 0..sa.n_functions as usize {
                    for (v, j) in sb.functions().enumerate() {
                        rows[u * nb + j] = block[u * n + v];
                    }
                }
            }
            rows
        })
        .collect();
    rows.concat()
}

/// max |CᵀSC − I| over a set of orbitals (coefficient vectors) given the overlap matrix `s`
/// (n × n). Vectors shorter than n count as zero-padded.
pub fn orthonormality_error(s: &[f64], n: usize, orbitals: &[&[f64]]) -> f64 {
    let sc: Vec<Vec<f64>> = orbitals
        .par_iter()
        .map(|c| {
            let rows: Vec<&[f64]> = s.chunks_exact(n.max(1)).take(n).collect();
            rows.chunks(4).flat_map(|four| dots(four, c)).collect()
        })
        .collect();
    (0..orbitals.len())
        .into_par_iter()
        .map(|p| {
            let mut worst: f64 = 0.0;
            let columns: Vec<&[f64]> = sc.iter().map(Vec::as_slice).collect();
            for (first, four) in columns.chunks(4).enumerate() {
                for (k, v) in dots(four, orbitals[p]).into_iter().enumerate() {
                    let want = if p == 4 * first + k { 1.0 } else { 0.0 };
                    worst = worst.max((v - want).abs());
                }
            }
            worst
        })
        .reduce(|| 0.0, f64::max)
}

/// The dot products of up to four `rows` with `c`, each summed in order as `Iterator::sum`
/// sums (so the same bits), side by side: four chains of additions that overlap, where one at a
/// time waits on each addition's latency. Reading a file's orbitals checks CᵀSC with them.
fn dots(rows: &[&[f64]], c: &[f64]) -> Vec<f64> {
    let mut sums = [-0.0f64; 4];
    let lanes = rows.len().min(4);
    if lanes == 4 {
        let len = rows.iter().map(|r| r.len()).min().unwrap_or(0).min(c.len());
        let (r0, r1, r2, r3) = (&rows[0][..len], &rows[1][..len], &rows[2][..len], &rows[3][..len]);
        for (k, &ck) in c[..len].iter().enumerate() {
            sums[0] += r0[k] * ck;
            sums[1] += r1[k] * ck;
            sums[2] += r2[k] * ck;
            sums[3] += r3[k] * ck;
        }
    } else {
        for (sum, row) in sums.iter_mut().zip(rows) {
            *sum = row.iter().zip(c).map(|(a, b)| a * b).sum();
        }
    }
    sums[..lanes].to_vec()
}

/// max |CᵀSC − I| over each spin's orbitals of a wavefunction, with S from its basis.
pub fn orthonormality_residual(wf: &Wavefunction) -> f64 {
    let s = overlap_matrix(&wf.basis);
    let n = wf.basis.n_functions();
    [Spin::Alpha, Spin::Beta]
        .iter()
        .map(|&spin| {
            let c: Vec<&[f64]> = wf.of_spin(spin).map(|(_, o)| o.coefficients.as_slice()).collect();
            orthonormality_error(&s, n, &c)
        })
        .fold(0.0, f64::max)
}

/// Norm of a shell's contraction as written: √(Σ_pq d_p d_q ⟨g_p|g_q⟩) for coefficients d of
/// normalised primitives g of angular momentum l, ⟨g_p|g_q⟩ = (2√(α_p α_q)/(α_p + α_q))^(l + 3/2).
pub fn contraction_norm(shell: &super::basis::Shell) -> f64 {
    let e = &shell.exponents;
    let d = &shell.coefficients;
    let power = shell.l as f64 + 1.5;
    let mut sum = 0.0;
    for p in 0..e.len() {
        for q in 0..e.len() {
            sum += d[p] * d[q] * (2.0 * (e[p] * e[q]).sqrt() / (e[p] + e[q])).powf(power);
        }
    }
    sum.max(0.0).sqrt()
}

/// The overlap matrix of the functions exactly as a file writes them: contractions *not*
/// renormalised (what the orbitals' coefficients refer to before a reader normalises them).
pub fn overlap_matrix_as_written(basis: &Basis) -> Vec<f64> {
    let mut s = overlap_matrix(basis);
    let n = basis.n_functions();
    let mut scale = Vec::with_capacity(n);
    for shell in &basis.shells {
        let norm = contraction_norm(shell);
        scale.extend(std::iter::repeat_n(norm, shell.n_functions()));
    }
    for i in 0..n {
        for j in 0..n {
            s[i * n + j] *= scale[i] * scale[j];
        }
    }
    s
}
