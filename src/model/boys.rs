//! The Boys function F_n(T) = ∫₀¹ t²ⁿ exp(−T t²) dt, which every Coulomb integral over Gaussians
//! reduces to.
//!
//! Below [`T_TABLE`]: a table of F_n at T_i = i·[`STEP`] for n ≤ [`MAX_N`] + [`TAYLOR`], built once
//! from the convergent series; F_m(T) for the highest m wanted is the Taylor expansion about the
//! nearest T_i (dF_n/dT = −F_{n+1}), the lower orders follow by the stable downward recursion
//! F_n = (2T F_{n+1} + e^{−T}) / (2n + 1). Above it: the asymptotic form F_0 = √(π/T)/2,
//! F_n = F_{n−1}(2n − 1)/(2T), whose relative error is below e^{−T} < 1e-17.

use std::sync::OnceLock;

/// Highest order served.
pub const MAX_N: usize = 16;
/// Largest T of the table; above it the asymptotic form is exact to double precision.
pub const T_TABLE: f64 = 40.0;
pub(super) const STEP: f64 = 0.05;
/// Terms of the Taylor expansion between table points: error ≤ (STEP/2)^TAYLOR / TAYLOR! ≈ 3e-13.
pub(super) const TAYLOR: usize = 6;
pub(super) const ORDERS: usize = MAX_N + TAYLOR + 1;
/// Up to this order every F_n comes from the table directly.
pub(super) const DIRECT: usize = 3;

pub(super) fn table() -> &'static Vec<[f64; ORDERS]> {
    static TABLE: OnceLock<Vec<[f64; ORDERS]>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let points = (T_TABLE / STEP).round() as usize + 1;
        (0..points).map(|i| series(i as f64 * STEP)).collect()
    })
}

/// F_0..F_{ORDERS−1} at `t` from the series F_n(T) = e^{−T} Σ_k (2T)^k / ((2n+1)(2n+3)…(2n+2k+1))
/// for the highest order (all terms positive: no cancellation), then downward recursion.
fn series(t: f64) -> [f64; ORDERS] {
    let top = ORDERS - 1;
    let e = (-t).exp();
    let (mut term, mut sum) = (1.0 / (2 * top + 1) as f64, 0.0);
    let mut k = 0;
    while term > sum * 1e-18 || k < 4 {
        sum += term;
        k += 1;
        term *= 2.0 * t / (2 * top + 2 * k + 1) as f64;
    }
    let mut f = [0.0; ORDERS];
    f[top] = e * sum;
    for n in (0..top).rev() {
        f[n] = (2.0 * t * f[n + 1] + e) / (2 * n + 1) as f64;
    }
    f
}

/// Index of the table point nearest `t` (0 ≤ t < [`T_TABLE`]); adding ½ and truncating is
/// `round` without the library call.
#[inline]
fn nearest(t: f64) -> usize {
    (t * (1.0 / STEP) + 0.5) as usize
}

/// Writes F_0(t)..F_m(t) into `out[..=m]` (m ≤ [`MAX_N`], t ≥ 0).
#[inline]
pub fn boys(m: usize, t: f64, out: &mut [f64]) {
    debug_assert!(m <= MAX_N);
    if t >= T_TABLE {
        asymptotic(m, t, out);
        return;
    }
    let i = nearest(t);
    let row = &table()[i];
    let dt = t - i as f64 * STEP;
    if m <= DIRECT {
        // A few orders: each by its own Taylor series, cheaper than the exponential the
        // recursion needs.
        let mut factors = [1.0; TAYLOR];
        for k in 1..TAYLOR {
            factors[k] = factors[k - 1] * -dt / k as f64;
        }
        for (n, o) in out.iter_mut().enumerate().take(m + 1) {
            *o = row[n..n + TAYLOR].iter().zip(&factors).map(|(v, f)| v * f).sum();
        }
        return;
    }
    // Taylor series of F_m about T_i: Σ_k F_{m+k}(T_i) (−dt)^k / k!.
    let mut fm = 0.0;
    let mut factor = 1.0;
    for (k, value) in row[m..m + TAYLOR].iter().enumerate() {
        fm += value * factor;
        factor *= -dt / (k + 1) as f64;
    }
    out[m] = fm;
    if m > 0 {
        let e = (-t).exp();
        for n in (0..m).rev() {
            out[n] = (2.0 * t * out[n + 1] + e) / (2 * n + 1) as f64;
        }
    }
}

/// F_0(t) alone: the one order a pair of s functions needs.
#[inline]
pub fn f0(t: f64) -> f64 {
    if t >= T_TABLE {
        return 0.5 * (std::f64::consts::PI / t).sqrt();
    }
    let i = nearest(t);
    let row = &table()[i];
    let dt = -(t - i as f64 * STEP);
    // Σ_k F_k(T_i) (−dt)^k / k!, by Horner.
    let mut sum = row[TAYLOR - 1];
    for k in (0..TAYLOR - 1).rev() {
        sum = row[k] + sum * dt / (k + 1) as f64;
    }
    sum
}

/// The large-T form: what a Gaussian charge looks like from far away (a point multipole).
#[inline]
pub fn asymptotic(m: usize, t: f64, out: &mut [f64]) {
    out[0] = 0.5 * (std::f64::consts::PI / t).sqrt();
    let half_over_t = 0.5 / t;
    for n in 1..=m {
        out[n] = out[n - 1] * (2 * n - 1) as f64 * half_over_t;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// F_n(T) by composite Simpson quadrature of the defining integral: independent of the
    /// series, the table and the recursions.
    fn quadrature(n: usize, t: f64) -> f64 {
        let steps = 20_000;
        let h = 1.0 / steps as f64;
        let f = |x: f64| x.powi(2 * n as i32) * (-t * x * x).exp();
        let mut sum = f(0.0) + f(1.0);
        for k in 1..steps {
            sum += f(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        sum * h / 3.0
    }

    #[test]
    fn agrees_with_quadrature_over_orders_and_arguments() {
        let mut out = [0.0; MAX_N + 1];
        for &t in &[0.0, 1e-9, 0.013, 0.5, 1.234_567, 7.77, 19.99, 25.0, 39.97, 40.0, 55.5, 300.0] {
            boys(MAX_N, t, &mut out);
            for (n, &value) in out.iter().enumerate() {
                let want = quadrature(n, t);
                assert!(
                    (value - want).abs() <= 1e-12 * want.max(1e-30) + 1e-15,
                    "F_{n}({t}) = {value}, quadrature {want}"
                );
            }
        }
    }

    #[test]
    fn f0_alone_agrees_with_quadrature() {
        for &t in &[0.0, 0.02, 0.5, 3.3, 17.0, 39.99, 41.0] {
            let want = quadrature(0, t);
            assert!((f0(t) - want).abs() <= 1e-13 * want, "F_0({t}) = {}, quadrature {want}", f0(t));
        }
    }

    #[test]
    fn lower_orders_do_not_depend_on_the_highest_asked() {
        let (mut a, mut b) = ([0.0; MAX_N + 1], [0.0; MAX_N + 1]);
        boys(2, 3.3, &mut a);
        boys(MAX_N, 3.3, &mut b);
        for n in 0..=2 {
            assert!((a[n] - b[n]).abs() < 1e-14 * b[n]);
        }
    }
}
