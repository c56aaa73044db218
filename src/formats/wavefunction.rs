//! What the Molden and fchk readers share once a file has been read: conversion of the file's
//! basis-function order into orbcloud's, the orthonormality check of the orbitals, and the
//! repairs for writers whose coefficients do not follow the format's normalisation.
//!
//! The readers hand over a [`Wavefunction`] already in orbcloud's function order but with the
//! file's numbers as written: contraction coefficients taken literally (they multiply
//! normalised primitives), orbital coefficients for those literal functions.
//! [`check_and_repair`] then
//! 1. measures the residual max |CᵀSC − I| of the orbitals as read (alpha and beta separately),
//! 2. if it exceeds [`AS_READ_TOLERANCE`], tries every [`Repair`] and keeps the one with the
//!    smallest residual, provided it is below [`REPAIRED_TOLERANCE`] and clearly better than the
//!    file as read; otherwise the file is kept as read and its residual recorded,
//! 3. normalises every contraction, folding the norm into the orbital coefficients, so that the
//!    model's basis functions have unit norm as `model::basis` promises. This changes no orbital.
//!
//! The residual is a property of the orbitals as functions (the overlaps of the orbitals), so it
//! does not depend on how the contractions are scaled as long as `overlap` treats the
//! coefficients literally.

use crate::model::basis::{Basis, ShellKind, cartesian_powers};
use crate::model::orbitals::{MolecularOrbital, Normalization, Spin, Wavefunction};
use crate::model::overlap::orthonormality_error;

/// The analytic overlap matrix of a basis (n × n, row-major): contraction coefficients multiply
/// normalised primitives, each cartesian component and each pure function on its own.
pub type OverlapFn<'a> = &'a (dyn Fn(&Basis) -> Vec<f64> + Sync);

/// Orbitals whose residual max |CᵀSC − I| is at most this are taken as written.
pub const AS_READ_TOLERANCE: f64 = 1e-5;
/// A repair is accepted when it brings the residual to at most this (and to a tenth of the
/// residual as read or less).
pub const REPAIRED_TOLERANCE: f64 = 1e-4;

/// The writer quirks the readers know how to undo.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Repair {
    /// ORCA: primitive normalisation folded into the contraction coefficients (for pure shells
    /// that of the xy, xyz, xxyz and, for h, the x⁵ component, as IOData reads ORCA), opposite
    /// signs for the f±3, g±3, g±4, h±3 and h±4 functions.
    Orca,
    /// Psi4 before 1.0: primitive normalisation folded into the coefficients, pure d and f
    /// scaled like the xx and xxx components.
    Psi4Pre10,
    /// Turbomole: cartesian d, f, g, h functions too small by √3, √15, √105, √945.
    Turbomole,
    /// CFOUR 2.1: cartesian components normalised without the (2a−1)!!(2b−1)!!(2c−1)!! factor.
    Cfour,
    /// Contractions written without normalisation.
    Contractions,
    /// Psi4 up to 1.3.2: unnormalised contractions, cartesian components normalised like x^l.
    Psi4Upto132,
}

impl Repair {
    pub const ALL: [Repair; 6] =
        [Repair::Orca, Repair::Psi4Pre10, Repair::Turbomole, Repair::Cfour, Repair::Contractions, Repair::Psi4Upto132];

    /// The program known to write files that need this repair.
    pub fn program(self) -> &'static str {
        match self {
            Repair::Orca => "ORCA",
            Repair::Psi4Pre10 => "Psi4 < 1.0",
            Repair::Turbomole => "Turbomole",
            Repair::Cfour => "CFOUR",
            Repair::Contractions => "unknown",
            Repair::Psi4Upto132 => "Psi4 <= 1.3.2",
        }
    }

    /// What the repair does, as recorded in [`Normalization::repair`].
    pub fn describe(self) -> &'static str {
        match self {
            Repair::Orca => {
                "ORCA: primitive normalisation removed from the contraction coefficients, signs of f±3, g±3, g±4, h±3, h±4 flipped"
            }
            Repair::Psi4Pre10 => "Psi4 < 1.0: primitive normalisation removed from the contraction coefficients",
            Repair::Turbomole => "Turbomole: cartesian d, f, g, h functions scaled by √3, √15, √105, √945",
            Repair::Cfour => "CFOUR: cartesian components rescaled by √((2a−1)!!(2b−1)!!(2c−1)!!)",
            Repair::Contractions => "contractions normalised",
            Repair::Psi4Upto132 => {
                "Psi4 <= 1.3.2: contractions normalised, cartesian components rescaled from the x^l normalisation"
            }
        }
    }

    /// Applies the repair to a wavefunction in literal file semantics.
    pub fn apply(self, wf: &Wavefunction) -> Wavefunction {
        let mut out = wf.clone();
        let offsets = out.basis.shell_offsets();
        // Per-function factors on the orbital coefficients (1 where untouched).
        let mut row_factor = vec![1.0; out.basis.n_functions()];
        for (shell, &first) in out.basis.shells.iter_mut().zip(&offsets) {
            let l = shell.l;
            let pure = shell.kind == ShellKind::Pure;
            match self {
                Repair::Orca | Repair::Psi4Pre10 => {
                    let powers = match (l, pure) {
                        (0, _) => Some([0, 0, 0]),
                        (1, _) => Some([1, 0, 0]),
                        (2, true) => Some([1, 1, 0]),
                        (3, true) => Some([1, 1, 1]),
                        (4, true) if self == Repair::Orca => Some([2, 1, 1]),
                        (5, true) if self == Repair::Orca => Some([5, 0, 0]),
                        _ => None,
                    };
                    if let Some(p) = powers {
                        let extra = match (self, l, pure) {
                            (Repair::Psi4Pre10, 2, true) => 3f64.sqrt(),
                            (Repair::Psi4Pre10, 3, true) => 15f64.sqrt(),
                            _ => 1.0,
                        };
                        for (c, &a) in shell.coefficients.iter_mut().zip(&shell.exponents) {
                            *c *= extra / cartesian_norm(a, p);
                        }
                    }
                    if self == Repair::Orca && pure {
                        let flipped = orca_flipped(l);
                        for f in &mut row_factor[first + flipped.start..first + flipped.end] {
                            *f = -1.0;
                        }
                    }
                }
                Repair::Turbomole => {
                    if !pure && (2..=5).contains(&l) {
                        let s = double_factorial(2 * l as i64 - 1).sqrt();
                        shell.coefficients.iter_mut().for_each(|c| *c *= s);
                    }
                }
                Repair::Cfour => {
                    if !pure && (2..=5).contains(&l) {
                        for (k, p) in cartesian_powers(l).iter().enumerate() {
                            row_factor[first + k] = component_double_factorials(*p).sqrt();
                        }
                    }
                }
                Repair::Contractions | Repair::Psi4Upto132 => {
                    let n = contraction_norm(shell.l, &shell.exponents, &shell.coefficients);
                    if n > 0.0 && n.is_finite() {
                        shell.coefficients.iter_mut().for_each(|c| *c /= n);
                    }
                    if self == Repair::Psi4Upto132 && !pure && (2..=5).contains(&l) {
                        let dl = double_factorial(2 * l as i64 - 1);
                        for (k, p) in cartesian_powers(l).iter().enumerate() {
                            row_factor[first + k] = (component_double_factorials(*p) / dl).sqrt();
                        }
                    }
                }
            }
        }
        if row_factor.iter().any(|&f| f != 1.0) {
            for mo in &mut out.orbitals {
                for (c, f) in mo.coefficients.iter_mut().zip(&row_factor) {
                    *c *= f;
                }
            }
        }
        out
    }
}

/// The functions of a pure shell of `l` whose sign ORCA writes opposite to the real solid
/// harmonics' (the m = ±3 and ±4 of f, g and h, which sit after 0, ±1, ±2: positions 5..9 in
/// the shell; h±5 keep their sign), in its Molden files and its printed orbitals alike.
pub(crate) fn orca_flipped(l: u32) -> std::ops::Range<usize> {
    if (3..=5).contains(&l) { 5..(2 * l as usize + 1).min(9) } else { 0..0 }
}

/// Norm of the contraction Σ cᵢ gᵢ of normalised primitives of angular momentum `l` (the same
/// for every cartesian component and every pure function of the shell).
pub fn contraction_norm(l: u32, exponents: &[f64], coefficients: &[f64]) -> f64 {
    let power = l as f64 + 1.5;
    let mut sum = 0.0;
    for (&a, &ca) in exponents.iter().zip(coefficients) {
        for (&b, &cb) in exponents.iter().zip(coefficients) {
            sum += ca * cb * (2.0 * (a * b).sqrt() / (a + b)).powf(power);
        }
    }
    sum.max(0.0).sqrt()
}

/// Normalisation constant of the cartesian primitive x^a y^b z^c exp(−α r²).
pub fn cartesian_norm(alpha: f64, powers: [u32; 3]) -> f64 {
    let l: u32 = powers.iter().sum();
    let pre = (2.0 * alpha / std::f64::consts::PI).powf(1.5) * (4.0 * alpha).powi(l as i32);
    (pre / component_double_factorials(powers)).sqrt()
}

/// (2a−1)!! (2b−1)!! (2c−1)!!
fn component_double_factorials(p: [u32; 3]) -> f64 {
    p.iter().map(|&n| double_factorial(2 * n as i64 - 1)).product()
}

/// n!! with (−1)!! = 1.
fn double_factorial(n: i64) -> f64 {
    let mut out = 1.0;
    let mut k = n;
    while k > 1 {
        out *= k as f64;
        k -= 2;
    }
    out
}

/// Scales every contraction to unit norm and folds the norm into the orbital coefficients: the
/// orbitals stay the same functions, the basis functions become unit-normalised.
pub fn normalize_contractions(wf: &mut Wavefunction) {
    let offsets = wf.basis.shell_offsets();
    let mut row_factor = vec![1.0; wf.basis.n_functions()];
    for (shell, &first) in wf.basis.shells.iter_mut().zip(&offsets) {
        let n = contraction_norm(shell.l, &shell.exponents, &shell.coefficients);
        if n > 0.0 && n.is_finite() && n != 1.0 {
            shell.coefficients.iter_mut().for_each(|c| *c /= n);
            row_factor[first..first + shell.n_functions()].fill(n);
        }
    }
    if row_factor.iter().any(|&f| f != 1.0) {
        for mo in &mut wf.orbitals {
            for (c, f) in mo.coefficients.iter_mut().zip(&row_factor) {
                *c *= f;
            }
        }
    }
}

/// max |CᵀSC − I| over the orbitals of each spin, with `s` the n × n overlap matrix
/// (orbitals whose length is not n are left out).
pub fn residual(orbitals: &[MolecularOrbital], s: &[f64]) -> f64 {
    let n = (s.len() as f64).sqrt().round() as usize;
    [Spin::Alpha, Spin::Beta]
        .iter()
        .map(|&spin| {
            let c: Vec<&[f64]> = orbitals
                .iter()
                .filter(|o| o.spin == spin && o.coefficients.len() == n)
                .map(|o| o.coefficients.as_slice())
                .collect();
            orthonormality_error(s, n, &c)
        })
        .fold(0.0, f64::max)
}

/// The document a wavefunction file gives: its atoms and its checked (and if need be repaired)
/// orbitals. The title falls back to the source's name.
pub fn wavefunction_document(
    source: &str,
    title: &str,
    atoms: Vec<crate::model::Atom>,
    wf: Wavefunction,
    program: Option<&str>,
    overlap: Option<OverlapFn>,
) -> crate::model::Document {
    crate::model::Document {
        source: source.to_string(),
        title: if title.is_empty() { source.to_string() } else { title.to_string() },
        molecule: crate::model::Molecule::new(atoms),
        wavefunction: Some(check_and_repair(wf, program, overlap)),
        ..Default::default()
    }
}

/// Orbitals as a program's log prints them, to `decimals` places: measured, but not repaired: a
/// residual of the print's size is no writer's quirk, and a repair chosen by rounding noise would
/// change good orbitals. The precision is recorded with the residual so that it is reported, not
/// hidden. The programs compute with unit-normalised contractions and print the orbitals over
/// them, whatever scale the basis they echo has: each contraction is scaled to unit norm and the
/// orbital coefficients are kept as printed.
pub fn check_printed(wf: Wavefunction, program: &str, overlap: Option<OverlapFn>, decimals: u32) -> Wavefunction {
    let mut wf = wf;
    for shell in &mut wf.basis.shells {
        let n = contraction_norm(shell.l, &shell.exponents, &shell.coefficients);
        if n > 0.0 && n.is_finite() {
            shell.coefficients.iter_mut().for_each(|c| *c /= n);
        }
    }
    let (repair, residual) = match overlap {
        Some(overlap) => ("none", residual(&wf.orbitals, &overlap(&wf.basis))),
        None => ("unchecked", f64::NAN),
    };
    wf.normalization = Normalization {
        program: program.to_string(),
        repair: repair.into(),
        residual,
        printed_decimals: Some(decimals),
    };
    wf
}

/// Checks the orbitals of a freshly read wavefunction and undoes a known writer quirk when the
/// check fails (see the module documentation). `program` is the writer the file names, if any.
/// Without an overlap function nothing is checked: the file is kept as read, residual NaN.
pub fn check_and_repair(wf: Wavefunction, program: Option<&str>, overlap: Option<OverlapFn>) -> Wavefunction {
    let named = program.unwrap_or("unknown").to_string();
    let Some(overlap) = overlap else {
        let mut wf = wf;
        normalize_contractions(&mut wf);
        wf.normalization =
            Normalization { program: named, repair: "unchecked".into(), residual: f64::NAN, printed_decimals: None };
        return wf;
    };
    let measure = |wf: &Wavefunction| {
        let mut canonical = wf.clone();
        normalize_contractions(&mut canonical);
        let s = overlap(&canonical.basis);
        let r = residual(&canonical.orbitals, &s);
        (canonical, if r.is_nan() { f64::INFINITY } else { r })
    };
    let (as_read, raw) = measure(&wf);
    let mut passing: Vec<(Repair, Wavefunction, f64)> = Vec::new();
    if raw > AS_READ_TOLERANCE {
        for repair in Repair::ALL {
            let (fixed, r) = measure(&repair.apply(&wf));
            if r <= REPAIRED_TOLERANCE && r <= 0.1 * raw {
                passing.push((repair, fixed, r));
            }
        }
    }
    // The smallest residual wins; among residuals within a factor 2 of it, the program the file
    // names, then the order of [`Repair::ALL`].
    let min = passing.iter().map(|p| p.2).fold(f64::INFINITY, f64::min);
    let pick = passing
        .iter()
        .position(|p| p.2 <= 2.0 * min && named_program(p.0, program))
        .or_else(|| passing.iter().position(|p| p.2 <= 2.0 * min));
    let best = pick.map(|i| passing.swap_remove(i));
    match best {
        Some((repair, mut fixed, r)) => {
            fixed.normalization = Normalization {
                program: repair.program().to_string(),
                repair: repair.describe().to_string(),
                residual: r,
                printed_decimals: None,
            };
            fixed
        }
        None => {
            let mut wf = as_read;
            wf.normalization =
                Normalization { program: named, repair: "none".into(), residual: raw, printed_decimals: None };
            wf
        }
    }
}

/// Whether the file itself names the program that needs `repair`.
fn named_program(repair: Repair, program: Option<&str>) -> bool {
    program.is_some_and(|p| {
        let p = p.to_ascii_lowercase();
        let r = repair.program().to_ascii_lowercase();
        r.split_whitespace().next().is_some_and(|w| p.starts_with(w))
    })
}

/// Guesses the writer from free text (a title, a comment): the first program named in it.
pub fn program_named_in(text: &str) -> Option<&'static str> {
    let t = text.to_ascii_lowercase();
    [
        ("orca", "ORCA"),
        ("psi4", "Psi4"),
        ("turbomole", "Turbomole"),
        ("cfour", "CFOUR"),
        ("molpro", "Molpro"),
        ("pyscf", "PySCF"),
        ("q-chem", "Q-Chem"),
        ("qchem", "Q-Chem"),
        ("gaussian", "Gaussian"),
        ("molden", "Molden"),
    ]
    .into_iter()
    .find(|(key, _)| t.contains(key))
    .map(|(_, name)| name)
}

/// Component powers written as letters ("xxy") → [2, 1, 0].
pub(crate) fn powers(letters: &str) -> [u32; 3] {
    let count = |ch| letters.chars().filter(|&c| c == ch).count() as u32;
    [count('x'), count('y'), count('z')]
}

/// For each component of a file's cartesian order, its index in orbcloud's order.
pub(crate) fn to_model_order(file_order: &[[u32; 3]]) -> Vec<usize> {
    let l = file_order.first().map_or(0, |p| p.iter().sum());
    let model = cartesian_powers(l);
    file_order.iter().map(|p| model.iter().position(|q| q == p).unwrap_or(0)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn double_factorials() {
        assert_eq!(double_factorial(-1), 1.0);
        assert_eq!(double_factorial(0), 1.0);
        assert_eq!(double_factorial(5), 15.0);
        assert_eq!(double_factorial(7), 105.0);
        assert_eq!(component_double_factorials([2, 1, 1]), 3.0);
    }

    #[test]
    fn contraction_of_one_primitive_is_normalised() {
        assert!((contraction_norm(2, &[0.8], &[1.0]) - 1.0).abs() < 1e-15);
        assert!((contraction_norm(0, &[1.0, 1.0], &[0.5, 0.5]) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn orders_map_to_alphabetical() {
        let molden_d: Vec<_> = "xx yy zz xy xz yz".split(' ').map(powers).collect();
        assert_eq!(to_model_order(&molden_d), vec![0, 3, 5, 1, 2, 4]);
    }

    #[test]
    fn program_names() {
        assert_eq!(program_named_in("Molden file created by orca_2mkl"), Some("ORCA"));
        assert_eq!(program_named_in("water"), None);
    }
}

#[cfg(test)]
mod repair_tests {
    use glam::DVec3;

    use super::super::ref_overlap::reference_overlap;
    use super::*;
    use crate::model::basis::Shell;

    fn shell(atom: usize, z: f64, l: u32, kind: ShellKind, exps: &[f64], coefs: &[f64]) -> Shell {
        Shell { atom, center: DVec3::new(0.0, 0.0, z), l, kind, exponents: exps.to_vec(), coefficients: coefs.to_vec() }
    }

    /// Two centres with s, p and a d (and f) shell each; orbitals orthonormal (Gram–Schmidt in
    /// the overlap metric), normalised contractions.
    fn correct(kind: ShellKind) -> Wavefunction {
        correct_to(kind, 3)
    }

    /// [`correct`] with shells of every l from 2 to `max_l` (h at most) on each centre.
    fn correct_to(kind: ShellKind, max_l: u32) -> Wavefunction {
        let mut shells = Vec::new();
        for (atom, z) in [(0, 0.0), (1, 1.6)] {
            shells.push(shell(atom, z, 0, ShellKind::Cartesian, &[3.0, 0.6], &[0.4, 0.7]));
            shells.push(shell(atom, z, 1, ShellKind::Cartesian, &[1.2, 0.3], &[0.5, 0.6]));
            for l in 2..=max_l {
                shells.push(shell(atom, z, l, kind, &[1.1 - 0.2 * (l - 2) as f64], &[1.0]));
            }
        }
        let mut wf = Wavefunction { basis: Basis { shells }, restricted: true, ..Default::default() };
        normalize_contractions(&mut wf);
        let cols = super::super::orthonormal_orbitals(&wf.basis, |i, k| if i == k { 1.0 } else { 0.1 });
        wf.orbitals = cols
            .into_iter()
            .enumerate()
            .map(|(i, coefficients)| MolecularOrbital {
                energy: i as f64,
                occupation: if i < 3 { 2.0 } else { 0.0 },
                spin: Spin::Alpha,
                symmetry: String::new(),
                coefficients,
            })
            .collect();
        wf
    }

    fn run(wf: Wavefunction, program: Option<&str>) -> Normalization {
        check_and_repair(wf, program, Some(&reference_overlap)).normalization
    }

    /// The rows of the cartesian l = 2..4 functions scaled by `f(powers, l)`.
    fn scale_rows(wf: &mut Wavefunction, f: impl Fn([u32; 3], u32) -> f64) {
        let offsets = wf.basis.shell_offsets();
        for (s, &first) in wf.basis.shells.iter().zip(&offsets) {
            if s.kind == ShellKind::Cartesian && s.l >= 2 {
                for (k, p) in cartesian_powers(s.l).into_iter().enumerate() {
                    for o in &mut wf.orbitals {
                        o.coefficients[first + k] *= f(p, s.l);
                    }
                }
            }
        }
    }

    #[test]
    fn correct_orbitals_need_no_repair() {
        for kind in [ShellKind::Cartesian, ShellKind::Pure] {
            let n = run(correct(kind), None);
            assert_eq!(n.repair, "none");
            assert!(n.residual < 1e-10, "{n:?}");
        }
    }

    #[test]
    fn turbomole_cfour_and_psi4_quirks_are_undone() {
        // Turbomole: the orbitals are written for d, f functions √3, √15 times too small.
        let mut wf = correct(ShellKind::Cartesian);
        scale_rows(&mut wf, |_, l| 1.0 / double_factorial(2 * l as i64 - 1).sqrt());
        let n = run(wf, None);
        assert_eq!(n.program, "Turbomole", "{n:?}");
        assert!(n.residual < 1e-10);
        // CFOUR: components written without their double-factorial normalisation.
        let mut wf = correct(ShellKind::Cartesian);
        scale_rows(&mut wf, |p, _| 1.0 / component_double_factorials(p).sqrt());
        let n = run(wf, None);
        assert_eq!(n.program, "CFOUR", "{n:?}");
        assert!(n.residual < 1e-10);
        // Psi4 <= 1.3.2: components normalised like x^l.
        let mut wf = correct(ShellKind::Cartesian);
        scale_rows(&mut wf, |p, l| (double_factorial(2 * l as i64 - 1) / component_double_factorials(p)).sqrt());
        let n = run(wf, Some("Psi4"));
        assert_eq!(n.program, "Psi4 <= 1.3.2", "{n:?}");
        assert!(n.residual < 1e-10);
    }

    /// What ORCA does to a correct file with pure shells: primitive normalisation (of the x,
    /// xy, xyz, xxyz, x⁵ component) folded into the contraction coefficients, and the signs of
    /// the m = ±3 and ±4 functions of f, g and h flipped.
    fn orca_quirk(wf: &mut Wavefunction) {
        let offsets = wf.basis.shell_offsets();
        for (s, &first) in wf.basis.shells.iter_mut().zip(&offsets) {
            let p = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 1], [2, 1, 1], [5, 0, 0]][s.l as usize];
            for (c, &a) in s.coefficients.iter_mut().zip(&s.exponents) {
                *c *= cartesian_norm(a, p);
            }
            if s.l >= 3 && s.kind == ShellKind::Pure {
                for o in &mut wf.orbitals {
                    for k in 5..(2 * s.l as usize + 1).min(9) {
                        o.coefficients[first + k] *= -1.0;
                    }
                }
            }
        }
    }

    /// Every writer quirk on a basis with d, f, g and h shells is found and undone exactly.
    #[test]
    fn every_repair_covers_l_up_to_h() {
        type Quirk = fn(&mut Wavefunction);
        let turbomole: Quirk = |wf| scale_rows(wf, |_, l| 1.0 / double_factorial(2 * l as i64 - 1).sqrt());
        let cfour: Quirk = |wf| scale_rows(wf, |p, _| 1.0 / component_double_factorials(p).sqrt());
        let psi4: Quirk =
            |wf| scale_rows(wf, |p, l| (double_factorial(2 * l as i64 - 1) / component_double_factorials(p)).sqrt());
        for (kind, quirk, named, expected) in [
            (ShellKind::Cartesian, turbomole, None, "Turbomole"),
            (ShellKind::Cartesian, cfour, None, "CFOUR"),
            (ShellKind::Cartesian, psi4, Some("Psi4"), "Psi4 <= 1.3.2"),
            (ShellKind::Pure, orca_quirk as Quirk, None, "ORCA"),
        ] {
            for max_l in 2..=5 {
                let mut wf = correct_to(kind, max_l);
                quirk(&mut wf);
                let n = run(wf, named);
                assert_eq!(n.program, expected, "l ≤ {max_l}: {n:?}");
                assert!(n.residual <= 1e-10, "l ≤ {max_l}: {n:?}");
            }
        }
    }

    #[test]
    fn orca_quirks_are_undone() {
        let mut wf = correct(ShellKind::Pure);
        orca_quirk(&mut wf);
        let n = run(wf, None);
        assert_eq!(n.program, "ORCA", "{n:?}");
        assert!(n.residual < 1e-10, "{n:?}");
    }

    /// The project's own PySCF Molden fixtures, written back the way each program's quirk would
    /// write them: the repair must find the program and give back the same orbitals.
    #[test]
    fn quirks_applied_to_pyscf_molden_files_are_undone() {
        use crate::model::gto::PreparedBasis;
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions");
        let load = |name: &str| {
            let text = std::fs::read_to_string(format!("{dir}/{name}")).unwrap_or_else(|e| {
                panic!(
                    "{dir}/{name}: {e} (run scripts/make_wavefunction_fixtures.py and scripts/make_h_molden_fixture.py)"
                )
            });
            let doc = super::super::molden::parse(name, &text, Some(&reference_overlap)).expect("fixture parses");
            doc.wavefunction.expect("a wavefunction")
        };
        let points: Vec<DVec3> = (0..25)
            .map(|k| DVec3::new((k as f64 * 0.7).sin() * 2.0, (k as f64 * 1.3).cos() * 2.0, k as f64 * 0.1 - 1.2))
            .collect();
        let values = |wf: &Wavefunction| -> Vec<f64> {
            let pb = PreparedBasis::new(&wf.basis);
            wf.orbitals
                .iter()
                .take(8)
                .flat_map(|o| points.iter().map(|&p| pb.orbital_value(&o.coefficients, p)).collect::<Vec<_>>())
                .collect()
        };
        type Quirk = fn(&mut Wavefunction);
        let turbomole: Quirk = |wf| scale_rows(wf, |_, l| 1.0 / double_factorial(2 * l as i64 - 1).sqrt());
        let cfour: Quirk = |wf| scale_rows(wf, |p, _| 1.0 / component_double_factorials(p).sqrt());
        let psi4: Quirk =
            |wf| scale_rows(wf, |p, l| (double_factorial(2 * l as i64 - 1) / component_double_factorials(p)).sqrt());
        let orca: Quirk = orca_quirk;
        for (name, quirk, named, expected) in [
            ("h2o_cart_631gs.molden", turbomole, None, "Turbomole"),
            ("h2o_cart_631gs.molden", cfour, None, "CFOUR"),
            ("h2o_cart_631gs.molden", psi4, Some("Psi4"), "Psi4 <= 1.3.2"),
            ("h2o_ccpvtz.molden", orca, None, "ORCA"),
            ("h2_spdfgh.molden", orca, None, "ORCA"),
        ] {
            let good = load(name);
            assert_eq!(good.normalization.repair, "none", "{name}");
            let mut bad = good.clone();
            quirk(&mut bad);
            bad.normalization = Normalization::default();
            let fixed = check_and_repair(bad, named, Some(&reference_overlap));
            assert_eq!(fixed.normalization.program, expected, "{name}: {:?}", fixed.normalization);
            assert!(fixed.normalization.residual < 1e-8, "{name}: {:?}", fixed.normalization);
            if name == "h2_spdfgh.molden" {
                // h functions (l = 5): as read and repaired, orthonormal to 1e-10.
                assert!(good.normalization.residual <= 1e-10, "{name}: {:?}", good.normalization);
                assert!(fixed.normalization.residual <= 1e-10, "{name}: {:?}", fixed.normalization);
            }
            let worst = values(&good).iter().zip(values(&fixed)).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(worst < 1e-10, "{name} as {expected}: orbitals differ by {worst:e} after the repair");
        }
    }

    #[test]
    fn unrepairable_files_are_kept_with_their_residual() {
        let mut wf = correct(ShellKind::Cartesian);
        wf.orbitals[0].coefficients[0] += 0.3;
        let n = run(wf, Some("ORCA"));
        assert_eq!((n.repair.as_str(), n.program.as_str()), ("none", "ORCA"));
        assert!(n.residual > 1e-3, "{n:?}");
    }

    #[test]
    fn without_an_overlap_nothing_is_checked() {
        let wf = check_and_repair(correct(ShellKind::Pure), Some("ORCA"), None);
        assert_eq!(wf.normalization.repair, "unchecked");
        assert!(wf.normalization.residual.is_nan());
    }
}
