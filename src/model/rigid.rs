//! A wavefunction moved rigidly: its shells' centres rotated and shifted, and each shell's
//! coefficients mixed so the orbitals turn with them, ψ′(R·r + t) = ψ(r). A path's frames are
//! laid on each other this way before their orbitals are blended.
//!
//! How a shell's functions mix under a rotation is measured rather than derived: a shell's
//! angular functions of one l (cartesian monomials or real solid harmonics, with this crate's
//! normalisation and order) span a space that rotations keep, so sampling them at points and
//! at the rotated points and solving the least-squares system gives the mixing matrix exactly,
//! for every l and both kinds, whatever the conventions.

use glam::{DQuat, DVec3};

use super::basis::{Basis, Shell, ShellKind};
use super::gto::PreparedBasis;
use super::orbitals::Wavefunction;

/// `wf` moved by `rotation` then `shift`.
pub fn moved(wf: &Wavefunction, rotation: DQuat, shift: DVec3) -> Wavefunction {
    let mut out = wf.clone();
    let offsets = wf.basis.shell_offsets();
    let mut mixing: Vec<((u32, ShellKind), Vec<f64>)> = Vec::new();
    for (s, shell) in out.basis.shells.iter_mut().enumerate() {
        shell.center = rotation * shell.center + shift;
        let key = (shell.l, shell.kind);
        let d = match mixing.iter().find(|(k, _)| *k == key) {
            Some((_, d)) => d.clone(),
            None => {
                let d = mixing_matrix(shell.l, shell.kind, rotation);
                mixing.push((key, d.clone()));
                d
            }
        };
        let (start, n) = (offsets[s], shell.n_functions());
        for orbital in &mut out.orbitals {
            let c: Vec<f64> = orbital.coefficients[start..start + n].to_vec();
            for (j, target) in orbital.coefficients[start..start + n].iter_mut().enumerate() {
                *target = (0..n).map(|m| c[m] * d[m * n + j]).sum();
            }
        }
    }
    out
}

/// D (row-major, n×n) with Y_m(R⁻¹·r) = Σ_j D[m][j]·Y_j(r) for a shell of `l` and `kind`: the
/// coefficients c′_j = Σ_m c_m·D[m][j] draw the shell's function turned by R.
fn mixing_matrix(l: u32, kind: ShellKind, rotation: DQuat) -> Vec<f64> {
    let shell = Shell { atom: 0, center: DVec3::ZERO, l, kind, exponents: vec![0.5], coefficients: vec![1.0] };
    let n = shell.n_functions();
    let basis = PreparedBasis::with_threshold(&Basis { shells: vec![shell] }, 0.0);
    // Points spread over the unit sphere (a Fibonacci lattice): the radial factor is the same at
    // a point and its rotation, so only the angular parts are compared.
    let count = 4 * n + 8;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let points: Vec<DVec3> = (0..count)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect();
    let inverse = rotation.inverse();
    let at: Vec<Vec<f64>> = points.iter().map(|&p| basis.basis_values(p)).collect();
    let turned: Vec<Vec<f64>> = points.iter().map(|&p| basis.basis_values(inverse * p)).collect();
    // Normal equations (AᵀA) X = AᵀB with A = at (count×n), B = turned; X = Dᵀ.
    let mut ata = vec![0.0; n * n];
    let mut atb = vec![0.0; n * n];
    for (a, b) in at.iter().zip(&turned) {
        for i in 0..n {
            for j in 0..n {
                ata[i * n + j] += a[i] * a[j];
                atb[i * n + j] += a[i] * b[j];
            }
        }
    }
    let x = solve(ata, atb, n);
    // X[j][m] = D[m][j].
    let mut d = vec![0.0; n * n];
    for j in 0..n {
        for m in 0..n {
            d[m * n + j] = x[j * n + m];
        }
    }
    d
}

/// Solves A·X = B for n×n row-major A and B by Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, n: usize) -> Vec<f64> {
    for col in 0..n {
        let pivot = (col..n).max_by(|&p, &q| a[p * n + col].abs().total_cmp(&a[q * n + col].abs())).unwrap_or(col);
        if pivot != col {
            for k in 0..n {
                a.swap(pivot * n + k, col * n + k);
                b.swap(pivot * n + k, col * n + k);
            }
        }
        let diag = a[col * n + col];
        if diag.abs() < 1e-300 {
            continue;
        }
        for row in 0..n {
            if row == col {
                continue;
            }
            let f = a[row * n + col] / diag;
            if f == 0.0 {
                continue;
            }
            for k in 0..n {
                a[row * n + k] -= f * a[col * n + k];
                b[row * n + k] -= f * b[col * n + k];
            }
        }
    }
    for row in 0..n {
        let diag = a[row * n + row];
        for k in 0..n {
            b[row * n + k] /= if diag.abs() < 1e-300 { 1.0 } else { diag };
        }
    }
    b
}
