//! Real solid harmonics as combinations of cartesian Gaussian components.
//!
//! [`cart_to_pure`] gives, for one angular momentum `l`, the matrix T of shape
//! (2l+1) × (l+1)(l+2)/2 with pure_k = Σ_i T[k][i] · cart_i, where
//! - cart_i are the *unit-normalised* cartesian components in orbcloud's order
//!   ([`cartesian_powers`]),
//! - pure_k are unit-normalised real solid harmonics in the order m = 0, +1, −1, +2, −2, …,
//!   without the Condon–Shortley phase (Gaussian's and Molden's convention:
//!   d0 ∝ 2z² − x² − y², d+1 ∝ xz, d−1 ∝ yz, d+2 ∝ x² − y², d−2 ∝ xy, f+3 ∝ x³ − 3xy²,
//!   f−3 ∝ 3x²y − y³).
//!
//! The one exception is l = 1: every file format writes p functions as x, y, z whether or not
//! the shell is called pure, so a pure p shell is the cartesian one (T = identity).
//!
//! The polynomial of each harmonic comes from the closed formula (Schlegel & Frisch 1995;
//! Helgaker, Jørgensen & Olsen eq. 6.4.48)
//!
//! S_lm ∝ Σ_t Σ_u Σ_v (−1)^(t+v−v_m) (1/4)^t C(l,t) C(l−t,|m|+t) C(t,u) C(|m|,2v)
//!        · x^(2t+|m|−2(u+v)) y^(2(u+v)) z^(l−2t−|m|),
//!
//! with v_m = 0 for m ≥ 0 and ½ for m < 0 (so 2v runs over even or odd integers); the row is then
//! scaled so that the harmonic has unit norm under the overlap of the unit-normalised cartesian
//! components ([`cartesian_overlap`]), which keeps the formula's sign.

use super::basis::{cartesian_powers, n_cartesian};

/// (n − 1)!! for n ≥ −1 as f64, with (−1)!! = 1.
pub fn double_factorial_m1(n: i64) -> f64 {
    let mut k = n - 1;
    let mut out = 1.0;
    while k > 1 {
        out *= k as f64;
        k -= 2;
    }
    out
}

fn binomial(n: i64, k: i64) -> f64 {
    if k < 0 || k > n {
        return 0.0;
    }
    let mut out = 1.0;
    for i in 0..k {
        out = out * (n - i) as f64 / (i + 1) as f64;
    }
    out
}

/// ∏ (2p − 1)!! over the three powers: the squared norm of x^a y^b z^c e^(−αr²) relative to
/// the common radial factor shared by all components of a shell.
fn monomial_norm2(p: [u32; 3]) -> f64 {
    p.iter().map(|&a| double_factorial_m1(2 * a as i64)).product()
}

/// Factor that turns the component x^a y^b z^c of a primitive normalised for x^l into a
/// unit-normalised component: sqrt((2l−1)!! / ((2a−1)!! (2b−1)!! (2c−1)!!)).
pub fn component_factor(p: [u32; 3]) -> f64 {
    let l = p[0] + p[1] + p[2];
    (double_factorial_m1(2 * l as i64) / monomial_norm2(p)).sqrt()
}

/// Overlap of two unit-normalised cartesian components of the same l on the same centre and
/// exponent, in orbcloud's order; row-major n_cart × n_cart.
pub fn cartesian_overlap(l: u32) -> Vec<f64> {
    let powers = cartesian_powers(l);
    let n = powers.len();
    let mut s = vec![0.0; n * n];
    for (i, p) in powers.iter().enumerate() {
        for (j, q) in powers.iter().enumerate() {
            let sum = [p[0] + q[0], p[1] + q[1], p[2] + q[2]];
            if sum.iter().any(|a| a % 2 == 1) {
                continue;
            }
            let num: f64 = sum.iter().map(|&a| double_factorial_m1(a as i64)).product();
            s[i * n + j] = num / (monomial_norm2(*p) * monomial_norm2(*q)).sqrt();
        }
    }
    s
}

/// Signed order m of the k-th pure function (0, +1, −1, +2, −2, …).
pub fn pure_m(k: usize) -> i32 {
    if k == 0 {
        0
    } else if k % 2 == 1 {
        k.div_ceil(2) as i32
    } else {
        -((k / 2) as i32)
    }
}

/// Monomial coefficients (orbcloud cartesian order) of the unnormalised solid harmonic S_lm.
fn solid_harmonic_monomials(l: u32, m: i32) -> Vec<f64> {
    let powers = cartesian_powers(l);
    let mut out = vec![0.0; powers.len()];
    let (l, am) = (l as i64, m.unsigned_abs() as i64);
    // Work with 2v to keep the half-integer v of m < 0 integral.
    let two_vm = if m < 0 { 1 } else { 0 };
    for t in 0..=(l - am) / 2 {
        for u in 0..=t {
            let mut two_v = two_vm;
            while two_v <= am {
                let sign_exp = t + (two_v - two_vm) / 2;
                let sign = if sign_exp % 2 == 0 { 1.0 } else { -1.0 };
                let c = sign
                    * 0.25f64.powi(t as i32)
                    * binomial(l, t)
                    * binomial(l - t, am + t)
                    * binomial(t, u)
                    * binomial(am, two_v);
                let py = 2 * u + two_v;
                let px = 2 * t + am - py;
                let pz = l - 2 * t - am;
                let idx = powers
                    .iter()
                    .position(|p| p == &[px as u32, py as u32, pz as u32])
                    .expect("solid harmonic monomial within l");
                out[idx] += c;
                two_v += 2;
            }
        }
    }
    out
}

/// The cartesian → pure matrix for angular momentum `l`, row-major (2l+1) × n_cart.
pub fn cart_to_pure(l: u32) -> Vec<f64> {
    let nc = n_cartesian(l);
    let np = 2 * l as usize + 1;
    if l == 1 {
        let mut t = vec![0.0; 9];
        for i in 0..3 {
            t[i * 3 + i] = 1.0;
        }
        return t;
    }
    let powers = cartesian_powers(l);
    let s = cartesian_overlap(l);
    let mut t = vec![0.0; np * nc];
    for k in 0..np {
        let mono = solid_harmonic_monomials(l, pure_m(k));
        // x^a y^b z^c = sqrt(∏(2p−1)!!) · (unit-normalised component), up to the shell factor.
        let row: Vec<f64> = mono.iter().zip(&powers).map(|(c, p)| c * monomial_norm2(*p).sqrt()).collect();
        let mut norm2 = 0.0;
        for i in 0..nc {
            for j in 0..nc {
                norm2 += row[i] * s[i * nc + j] * row[j];
            }
        }
        let scale = 1.0 / norm2.sqrt();
        for i in 0..nc {
            t[k * nc + i] = row[i] * scale;
        }
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(l: u32, k: usize, p: [u32; 3]) -> f64 {
        let i = cartesian_powers(l).iter().position(|q| *q == p).unwrap();
        cart_to_pure(l)[k * n_cartesian(l) + i]
    }

    #[test]
    fn orders_and_signs_follow_gaussian() {
        assert_eq!((0..7).map(pure_m).collect::<Vec<_>>(), vec![0, 1, -1, 2, -2, 3, -3]);
        // d0 ∝ 2zz − xx − yy in unit-normalised components: (zz − (xx + yy)/2).
        assert!((entry(2, 0, [0, 0, 2]) - 1.0).abs() < 1e-14);
        assert!((entry(2, 0, [2, 0, 0]) + 0.5).abs() < 1e-14);
        assert!((entry(2, 1, [1, 0, 1]) - 1.0).abs() < 1e-14);
        assert!((entry(2, 2, [0, 1, 1]) - 1.0).abs() < 1e-14);
        let h = 0.75f64.sqrt();
        assert!((entry(2, 3, [2, 0, 0]) - h).abs() < 1e-14);
        assert!((entry(2, 3, [0, 2, 0]) + h).abs() < 1e-14);
        assert!((entry(2, 4, [1, 1, 0]) - 1.0).abs() < 1e-14);
        // f+3 ∝ x³ − 3xy², f−3 ∝ 3x²y − y³.
        assert!(entry(3, 5, [3, 0, 0]) > 0.0 && entry(3, 5, [1, 2, 0]) < 0.0);
        assert!(entry(3, 6, [2, 1, 0]) > 0.0 && entry(3, 6, [0, 3, 0]) < 0.0);
    }

    #[test]
    fn pure_functions_are_orthonormal() {
        for l in 0..=6 {
            let nc = n_cartesian(l);
            let np = 2 * l as usize + 1;
            let t = cart_to_pure(l);
            let s = cartesian_overlap(l);
            for a in 0..np {
                for b in 0..np {
                    let mut v = 0.0;
                    for i in 0..nc {
                        for j in 0..nc {
                            v += t[a * nc + i] * s[i * nc + j] * t[b * nc + j];
                        }
                    }
                    let want = if a == b { 1.0 } else { 0.0 };
                    assert!((v - want).abs() < 1e-12, "l={l} a={a} b={b}: {v}");
                }
            }
        }
    }
}
