//! The occupied orbitals' value, gradient and Hessian at a point from its basis functions':
//! ψ[t][i] = Σ_k φ_k[t] · C[k][i] over the functions k within reach, for the ten components t
//! (value, ∂x, ∂y, ∂z, ∂xx, ∂xy, ∂xz, ∂yy, ∂yz, ∂zz) and every occupied orbital i. This is most
//! of the work of a density's derivatives ([`super::nci`]).
//!
//! A plain loop over the functions reads and writes all 10 × n sums once per function: loads
//! and stores, not arithmetic, bound it. With AVX-512 the 10 × 16 sums of a block of 16 orbitals
//! stay in registers while the functions stream past (with AVX2, 5 × 8 of them). Every way adds
//! the same products in the same order, without fused multiply-adds, so their results are
//! identical to the bit.

use super::gto::{DerivativeBlock, HESSIAN_PAIRS};

/// Value, gradient and the Hessian's six components.
pub const COMPONENTS: usize = 10;

/// Orbitals per SIMD register: each coefficient row is padded with zeros to a multiple of this.
pub const LANES: usize = 8;

/// The occupied orbitals laid out for the sums: per basis function a row of its coefficient
/// in each orbital, `stride` apart (the orbitals padded with zeros to whole registers).
#[derive(Debug, Clone, PartialEq)]
pub struct OccupiedOrbitals {
    rows: Vec<f64>,
    stride: usize,
    pub occupations: Vec<f64>,
}

impl OccupiedOrbitals {
    /// From a function-major matrix (`matrix[k · n + i]`: function k in orbital i, n the
    /// number of `occupations`).
    pub fn new(matrix: &[f64], occupations: Vec<f64>) -> Self {
        let n = occupations.len();
        let stride = n.div_ceil(LANES) * LANES;
        let functions = matrix.len().checked_div(n).unwrap_or(0);
        let mut rows = vec![0.0; functions * stride];
        for (row, from) in rows.chunks_exact_mut(stride.max(1)).zip(matrix.chunks_exact(n.max(1))) {
            row[..n].copy_from_slice(from);
        }
        Self { rows, stride, occupations }
    }

    /// Function `k`'s coefficient in occupied orbital `i`.
    pub fn coefficient(&self, k: usize, i: usize) -> f64 {
        self.rows[k * self.stride + i]
    }

    /// Occupied orbitals.
    fn len(&self) -> usize {
        self.occupations.len()
    }

    /// Sums' scratch length: [`COMPONENTS`] rows of `stride`.
    pub fn scratch_len(&self) -> usize {
        COMPONENTS * self.stride
    }

    /// Component t of every orbital, from the sums [`Self::sums`] wrote (`len()` values).
    pub fn component<'a>(&self, psi: &'a [f64], t: usize) -> &'a [f64] {
        &psi[t * self.stride..t * self.stride + self.len()]
    }

    /// ρ = Σ_i n_i ψ_i², ∇ρ = 2 Σ_i n_i ψ_i ∇ψ_i and the Hessian's six components
    /// ∂a∂bρ = 2 Σ_i n_i (ψ_i ∂a∂bψ_i + ∂aψ_i ∂bψ_i) (xx, xy, xz, yy, yz, zz) from the sums
    /// [`Self::sums`] wrote: the sixteen sums in one pass over the orbitals, each in the
    /// orbitals' order, independent of one another (no chain of additions to wait on).
    pub fn density_derivatives(&self, psi: &[f64]) -> (f64, [f64; 3], [f64; 6]) {
        let c: [&[f64]; COMPONENTS] = std::array::from_fn(|t| self.component(psi, t));
        let mut s = [-0.0f64; 16];
        for (i, &w) in self.occupations.iter().enumerate() {
            let x: [f64; COMPONENTS] = std::array::from_fn(|t| c[t][i]);
            let wv = w * x[0];
            s[0] += wv * x[0];
            for a in 0..3 {
                s[1 + a] += wv * x[1 + a];
            }
            for (k, &(a, b)) in HESSIAN_PAIRS.iter().enumerate() {
                s[4 + k] += wv * x[4 + k];
                s[10 + k] += w * x[1 + a] * x[1 + b];
            }
        }
        (s[0], std::array::from_fn(|a| 2.0 * s[1 + a]), std::array::from_fn(|k| 2.0 * (s[4 + k] + s[10 + k])))
    }

    /// ψ[t][i] = Σ_{k ∈ active} φ[k][t] · C[k][i] into `psi` (at least [`Self::scratch_len`]),
    /// the products added in the order of `active`; φ[k][t] is `phi[k][t][point]`.
    pub fn sums(&self, phi: &[DerivativeBlock], point: usize, active: &[usize], psi: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has the feature the function is compiled for.
            unsafe { self.sums_avx512(phi, point, active, psi) };
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has the feature the function is compiled for.
            unsafe { self.sums_avx2(phi, point, active, psi) };
            return;
        }
        self.sums_plain(phi, point, active, psi);
    }

    /// [`Self::sums`] one function at a time, each sum read and written back per function.
    #[inline]
    pub fn sums_plain(&self, phi: &[DerivativeBlock], point: usize, active: &[usize], psi: &mut [f64]) {
        let (n, stride) = (self.len(), self.stride);
        psi[..COMPONENTS * stride].fill(0.0);
        for &k in active {
            let row = &self.rows[k * stride..k * stride + n];
            for (t, v) in phi[k].iter().enumerate() {
                let v = v[point];
                for (p, c) in psi[t * stride..t * stride + n].iter_mut().zip(row) {
                    *p += v * c;
                }
            }
        }
    }

    /// [`Self::sums`] with AVX2's 16 registers: 8 orbitals and 5 components at a time, the
    /// 40 sums in 10 registers.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn sums_avx2(&self, phi: &[DerivativeBlock], point: usize, active: &[usize], psi: &mut [f64]) {
        for start in (0..self.stride).step_by(LANES) {
            for first in [0, COMPONENTS / 2] {
                self.block_avx2(phi, point, active, start, first, psi);
            }
        }
    }

    /// The sums of orbitals `start .. start + 8`, components `first .. first + 5`.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    fn block_avx2(
        &self,
        phi: &[DerivativeBlock],
        point: usize,
        active: &[usize],
        start: usize,
        first: usize,
        psi: &mut [f64],
    ) {
        use std::arch::x86_64::{_mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_set1_pd};
        use std::arch::x86_64::{_mm256_setzero_pd, _mm256_storeu_pd};
        const HALF: usize = COMPONENTS / 2;
        let stride = self.stride;
        let mut acc = [[_mm256_setzero_pd(); 2]; HALF];
        for &k in active {
            let row = &self.rows[k * stride + start..k * stride + start + LANES];
            // SAFETY: `row` holds 8 values.
            let b = unsafe { [_mm256_loadu_pd(row.as_ptr()), _mm256_loadu_pd(row.as_ptr().add(4))] };
            for (acc, a) in acc.iter_mut().zip(&phi[k][first..first + HALF]) {
                let a = _mm256_set1_pd(a[point]);
                for (acc, &b) in acc.iter_mut().zip(&b) {
                    *acc = _mm256_add_pd(*acc, _mm256_mul_pd(a, b));
                }
            }
        }
        for (t, acc) in acc.iter().enumerate() {
            let at = (first + t) * stride + start;
            let out = &mut psi[at..at + LANES];
            for (v, acc) in acc.iter().enumerate() {
                // SAFETY: `out` holds 8 values.
                unsafe { _mm256_storeu_pd(out.as_mut_ptr().add(4 * v), *acc) };
            }
        }
    }

    /// [`Self::sums`] a block of 16 orbitals at a time (8 for the last when 8 are left), its
    /// 10 × 16 sums held in 20 of AVX-512's 32 registers.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    fn sums_avx512(&self, phi: &[DerivativeBlock], point: usize, active: &[usize], psi: &mut [f64]) {
        let mut start = 0;
        while start + 2 * LANES <= self.stride {
            self.block_avx512::<2>(phi, point, active, start, psi);
            start += 2 * LANES;
        }
        if start < self.stride {
            self.block_avx512::<1>(phi, point, active, start, psi);
        }
    }

    /// The sums of orbitals `start .. start + V·8`.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    #[inline]
    fn block_avx512<const V: usize>(
        &self,
        phi: &[DerivativeBlock],
        point: usize,
        active: &[usize],
        start: usize,
        psi: &mut [f64],
    ) {
        use std::arch::x86_64::{__m512d, _mm512_add_pd, _mm512_loadu_pd, _mm512_mul_pd, _mm512_set1_pd};
        use std::arch::x86_64::{_mm512_setzero_pd, _mm512_storeu_pd};
        let stride = self.stride;
        let width = V * LANES;
        let mut acc = [[_mm512_setzero_pd(); V]; COMPONENTS];
        for &k in active {
            let row = &self.rows[k * stride + start..k * stride + start + width];
            let mut b: [__m512d; V] = [_mm512_setzero_pd(); V];
            for (v, b) in b.iter_mut().enumerate() {
                // SAFETY: `row` holds V·8 values.
                *b = unsafe { _mm512_loadu_pd(row.as_ptr().add(v * LANES)) };
            }
            for (acc, a) in acc.iter_mut().zip(&phi[k]) {
                let a = _mm512_set1_pd(a[point]);
                for (acc, &b) in acc.iter_mut().zip(&b) {
                    *acc = _mm512_add_pd(*acc, _mm512_mul_pd(a, b));
                }
            }
        }
        for (t, acc) in acc.iter().enumerate() {
            let out = &mut psi[t * stride + start..t * stride + start + width];
            for (v, acc) in acc.iter().enumerate() {
                // SAFETY: `out` holds V·8 values.
                unsafe { _mm512_storeu_pd(out.as_mut_ptr().add(v * LANES), *acc) };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::gto::BLOCK;
    use crate::model::gto::tests::pseudo_random;

    #[test]
    fn blocked_sums_equal_plain_sums_to_the_bit() {
        // Orbital counts around the block sizes, active functions skipping some.
        for n in [1, 7, 8, 9, 16, 21, 24, 33] {
            let functions = 13;
            let orbitals = OccupiedOrbitals::new(&pseudo_random(functions * n, n as u64), vec![2.0; n]);
            let flat = pseudo_random(functions * COMPONENTS * BLOCK, 7);
            let phi: Vec<DerivativeBlock> = flat
                .chunks_exact(COMPONENTS * BLOCK)
                .map(|c| std::array::from_fn(|t| std::array::from_fn(|i| c[t * BLOCK + i])))
                .collect();
            let point = n % BLOCK;
            let active: Vec<usize> = (0..functions).filter(|k| k % 4 != 1).collect();
            let (mut a, mut b) = (vec![f64::NAN; orbitals.scratch_len()], vec![f64::NAN; orbitals.scratch_len()]);
            orbitals.sums(&phi, point, &active, &mut a);
            orbitals.sums_plain(&phi, point, &active, &mut b);
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                let mut c = vec![f64::NAN; orbitals.scratch_len()];
                // SAFETY: the CPU has AVX2.
                unsafe { orbitals.sums_avx2(&phi, point, &active, &mut c) };
                for t in 0..COMPONENTS {
                    let (x, y) = (orbitals.component(&c, t), orbitals.component(&b, t));
                    assert!(x.iter().zip(y).all(|(x, y)| x.to_bits() == y.to_bits()), "AVX2, {n} orbitals");
                }
            }
            let at = |k: usize, t: usize| phi[k][t][point];
            for t in 0..COMPONENTS {
                let (x, y) = (orbitals.component(&a, t), orbitals.component(&b, t));
                assert_eq!(
                    x.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    y.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
                );
                let want: f64 = active.iter().map(|&k| at(k, t) * orbitals.rows[k * orbitals.stride + n - 1]).sum();
                assert!((x[n - 1] - want).abs() < 1e-12);
            }
        }
    }
}
