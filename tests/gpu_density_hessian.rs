//! The GPU pass of the density's derivatives (ρ, ∇ρ, the Hessian) against the CPU reference
//! (`model::nci`, f64), on lavapipe: pure d (the water dimer), pure d–h (H₂ in an spdfgh basis),
//! cartesian d, pure f from an fchk, and an unrestricted cation; then NCI's quantities made
//! from them (s, sign(λ₂)ρ, the cut fields), with NCIPLOT's cuts.
//!
//! Tolerances: the pass works in f32 (a relative rounding of 6e-8 per operation); a derivative
//! is a sum of products of basis functions whose terms may be far larger than the sum (the
//! Hessian's components cancel near λ = 0, ∇ρ near critical points), so each component is
//! compared against the largest term's size, measured by the component's largest |value| over
//! the grid, times 1e-5, plus 1e-5 of the component itself, where ρ ≤ 1 (valence and beyond,
//! where NCI's features lie). Near the nuclei (ρ > 1) the core functions' exponents (up to
//! 5·10³ in 6-31G*) amplify the f32 rounding of the point's position (~5e-7 bohr) by 2αr, and
//! the Hessian's large terms cancel: there the tolerance is 1e-4. ρ is a sum of positive terms and
//! agrees to 2e-5 relative wherever ρ > 1e-6 (measured: under 1e-5; e^(−αr²) in f32 is off by
//! ~αr²·6e-8 relative, and αr² reaches 20–40 in the tails where ρ ~ 1e-6). s = |∇ρ|/(2(3π²)^{1/3} ρ^{4/3}), finished in f64
//! from the f32 derivatives, is compared where ρ > 1e-6 at 1e-4 relative (measured: under
//! 1e-5), and sign(λ₂)ρ at 1e-4 of ρ; sign(λ₂) flips where λ₂ crosses zero, so it is compared
//! only where |λ₂| is ten times the Hessian's tolerance.

mod common;

use glam::DVec3;
use orbcloud::formats;
use orbcloud::gpu::density_hessian::DensityHessianPass;
use orbcloud::model::GridSpec;
use orbcloud::model::nci::{DensityDerivatives, DensitySource, WavefunctionDensity};
use orbcloud::model::orbitals::Quantity;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures");

fn load(path: &str) -> orbcloud::model::Document {
    formats::load(std::path::Path::new(&format!("{DIR}/{path}"))).unwrap()
}

/// A grid over the atoms with `margin` bohr around them, `n` points per side; its steps are
/// not along the axes' multiples of each other (unequal sides).
fn grid_over(doc: &orbcloud::model::Document, margin: f64, n: usize) -> GridSpec {
    let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
    for a in &doc.molecule.atoms {
        lo = lo.min(a.position);
        hi = hi.max(a.position);
    }
    GridSpec::cube(lo - DVec3::splat(margin), hi + DVec3::splat(margin) + DVec3::new(0.13, 0.07, 0.0), n)
}

fn cpu_derivatives(source: &WavefunctionDensity, grid: &GridSpec) -> Vec<DensityDerivatives> {
    let [nx, ny, nz] = grid.dims;
    let points: Vec<DVec3> = (0..nx)
        .flat_map(|i| (0..ny).flat_map(move |j| (0..nz).map(move |k| (i, j, k))))
        .map(|(i, j, k)| grid.point(i, j, k))
        .collect();
    let mut out = vec![DensityDerivatives::default(); points.len()];
    for (p, o) in points.chunks(nz).zip(out.chunks_mut(nz)) {
        source.derivatives_at(p, o);
    }
    out
}

fn components(d: &DensityDerivatives) -> [f64; 10] {
    let h = d.hessian;
    [d.rho, d.gradient.x, d.gradient.y, d.gradient.z, h[0][0], h[0][1], h[0][2], h[1][1], h[1][2], h[2][2]]
}

const NAMES: [&str; 10] = ["ρ", "∂xρ", "∂yρ", "∂zρ", "∂xxρ", "∂xyρ", "∂xzρ", "∂yyρ", "∂yzρ", "∂zzρ"];

/// Compares the GPU's derivatives and quantities with the CPU's on `grid`.
fn check(name: &str, doc: &orbcloud::model::Document, grid: &GridSpec, chunk: usize) {
    let ctx = common::lavapipe();
    let wf = doc.wavefunction.as_ref().unwrap();
    let source = WavefunctionDensity::new(wf);
    let pass = DensityHessianPass::new(&ctx);
    let gpu = pass.derivatives_in_chunks(&ctx, &source.cartesian(), grid, chunk).unwrap();
    let cpu = cpu_derivatives(&source, grid);
    assert_eq!(gpu.len(), cpu.len());

    // Valence and beyond (ρ ≤ 1, where every NCI feature lies), and the cores.
    for (region, core, tolerance) in [("valence", false, 1e-5), ("core", true, 1e-4)] {
        let inside = |c: &DensityDerivatives| (c.rho > 1.0) == core;
        let mut largest = [0.0f64; 10];
        for c in cpu.iter().filter(|c| inside(c)) {
            for (l, v) in largest.iter_mut().zip(components(c)) {
                *l = l.max(v.abs());
            }
        }
        let mut worst = [0.0f64; 10];
        for (g, c) in gpu.iter().zip(&cpu).filter(|(_, c)| inside(c)) {
            for (t, want) in components(c).into_iter().enumerate() {
                worst[t] = worst[t].max((g[t] as f64 - want).abs() / (tolerance * (largest[t] + want.abs())));
            }
        }
        eprintln!("{name}, {region}: worst error per component, in units of its tolerance: {worst:.3?}");
        for t in 0..10 {
            assert!(worst[t] <= 1.0, "{name}, {region}: {} differs by {:.3} of its tolerance", NAMES[t], worst[t]);
        }
    }
    let largest_hessian = cpu
        .iter()
        .filter(|c| c.rho <= 1.0)
        .flat_map(|c| c.hessian.into_iter().flatten())
        .fold(0.0f64, |m, v| m.max(v.abs()));

    // The quantities, finished from the GPU's f32 derivatives as the CPU finishes its own.
    let mut compared = [0usize; 2];
    let (mut worst_rho, mut worst_s, mut worst_sl) = (0.0f64, 0.0f64, 0.0f64);
    let hessian_error = 1e-5 * largest_hessian;
    for (g, c) in gpu.iter().zip(&cpu) {
        let g = DensityDerivatives::from_single(g);
        if c.rho > 1e-6 {
            worst_rho = worst_rho.max((g.rho - c.rho).abs() / c.rho);
            let (a, b) = (g.reduced_gradient(), c.reduced_gradient());
            worst_s = worst_s.max((a - b).abs() / b.max(1e-3));
            compared[0] += 1;
        }
        if c.lambda2().abs() > 10.0 * hessian_error {
            worst_sl = worst_sl.max((g.sign_lambda2_rho() - c.sign_lambda2_rho()).abs() / c.rho.max(1e-30));
            compared[1] += 1;
        }
        for q in [Quantity::NciGradient, Quantity::NciCloud] {
            let (a, b) = (g.quantity(q), c.quantity(q));
            // Where ρ lies at the cut (0.05) the two may fall either side of it; elsewhere
            // they agree as s does.
            if (c.rho - 0.05).abs() > 1e-5 * c.rho && c.lambda2().abs() > 10.0 * hessian_error {
                assert!((a - b).abs() <= 1e-3 * (1.0 + b.abs()), "{name}: {q:?} {a} vs {b}");
            }
        }
    }
    eprintln!(
        "{name}: ρ and s at {} points, worst relative {worst_rho:.2e} and {worst_s:.2e}; sign(λ₂)ρ at {} points, \
         worst relative {worst_sl:.2e}",
        compared[0], compared[1]
    );
    assert!(worst_rho <= 2e-5, "{name}: ρ differs by {worst_rho:e} relative");
    assert!(compared[0] > 100 && compared[1] > 100, "{name}: too few points compared: {compared:?}");
    assert!(worst_s <= 1e-4, "{name}: s differs by {worst_s:e} relative");
    assert!(worst_sl <= 1e-4, "{name}: sign(λ₂)ρ differs by {worst_sl:e} relative");
}

#[test]
fn water_dimer_pure_d() {
    let doc = load("nci/water_dimer_631gs.molden");
    check("water dimer", &doc, &grid_over(&doc, 2.5, 26), 1000);
}

#[test]
fn h2_pure_d_to_h() {
    let doc = load("wavefunctions/h2_spdfgh.molden");
    check("H2 spdfgh", &doc, &grid_over(&doc, 3.0, 24), 1000);
}

#[test]
fn water_pure_f_from_fchk() {
    let doc = load("wavefunctions/h2o_ccpvtz.fchk");
    check("H2O cc-pVTZ", &doc, &grid_over(&doc, 2.5, 20), 1 << 20);
}

#[test]
fn water_cartesian_d() {
    let doc = load("wavefunctions/h2o_cart_631gs.molden");
    check("H2O cartesian 6-31G*", &doc, &grid_over(&doc, 2.5, 20), 777);
}

#[test]
fn unrestricted_cation() {
    let doc = load("wavefunctions/h2o_cation_uhf_631gs.molden");
    assert!(!doc.wavefunction.as_ref().unwrap().restricted);
    check("H2O+ UHF", &doc, &grid_over(&doc, 2.5, 20), 1000);
}

#[test]
fn the_viewer_grid_of_each_nci_quantity_matches_the_cpu() {
    use orbcloud::model::gto::PreparedBasis;
    let ctx = common::lavapipe();
    let doc = load("nci/water_dimer_631gs.molden");
    let wf = doc.wavefunction.as_ref().unwrap();
    let pass = DensityHessianPass::new(&ctx);
    let prepared = PreparedBasis::new(&wf.basis);
    let source = WavefunctionDensity::new(wf);
    for quantity in [
        Quantity::NciGradient,
        Quantity::NciCloud,
        Quantity::SignLambda2Rho,
        Quantity::ReducedGradient,
        Quantity::DensityLaplacian,
    ] {
        let grid = orbcloud::evaluate::orbital_geometry(&doc, quantity, 28).unwrap();
        let gpu = pass.quantity_grid(&ctx, wf, quantity, &grid).unwrap();
        // What the window evaluates on a GPU (on lavapipe it takes the CPU's path).
        assert!(!orbcloud::evaluate::derivatives_on_gpu(&ctx));
        assert_eq!(orbcloud::evaluate::derivative_quantity_on_gpu(&ctx, &doc, quantity, &grid), gpu);
        let cpu = prepared.quantity_grid_f32(wf, &doc.molecule, quantity, &grid);
        let derivatives = cpu_derivatives(&source, &grid);
        let largest = cpu.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        let largest_hessian =
            derivatives.iter().flat_map(|d| d.hessian.into_iter().flatten()).fold(0.0f64, |m, v| m.max(v.abs()));
        let mut ambiguous = 0;
        for ((g, c), d) in gpu.iter().zip(&cpu).zip(&derivatives) {
            let close = match quantity {
                // ∇²ρ: the Hessian's tolerance (see the top of this file).
                Quantity::DensityLaplacian => (g - c).abs() <= 1e-5 * (largest + c.abs()),
                // s grows without bound where ρ → 0: relative.
                Quantity::ReducedGradient => (g - c).abs() <= 1e-4 * c.abs().max(1e-3) || d.rho < 1e-6,
                _ => (g - c).abs() <= 1e-4 * (c.abs() + 1e-3 * largest),
            };
            if !close {
                // Only where the two sides of a cut or of λ₂ = 0 are within rounding.
                let at_cut = (d.rho - 0.05).abs() < 1e-4 * d.rho;
                let at_zero = d.lambda2().abs() < 1e-4 * largest_hessian;
                assert!(at_cut || at_zero, "{quantity:?}: GPU {g} vs CPU {c} at ρ = {}, λ₂ = {}", d.rho, d.lambda2());
                ambiguous += 1;
            }
        }
        eprintln!("{quantity:?}: {} points, {ambiguous} on either side of a cut or of λ₂ = 0", gpu.len());
    }
}

#[test]
fn no_occupied_orbitals_and_no_points() {
    let ctx = common::lavapipe();
    let pass = DensityHessianPass::new(&ctx);
    let grid = GridSpec::cube(DVec3::splat(-1.0), DVec3::splat(1.0), 5);
    let empty = orbcloud::model::cartesian::CartesianDensity::default();
    let values = pass.derivatives(&ctx, &empty, &grid).unwrap();
    assert_eq!(values.len(), 125);
    assert!(values.iter().all(|v| v.iter().all(|x| *x == 0.0)));
    let none = GridSpec { dims: [0, 4, 4], ..grid };
    assert!(pass.derivatives(&ctx, &empty, &none).unwrap().is_empty());
}

#[test]
fn benzene_in_two_batches_of_orbitals() {
    // 21 occupied orbitals: more than one dispatch's 16, so the second batch adds to the first.
    let doc = load("wavefunctions/benzene_631gs.molden");
    let occupied = doc.wavefunction.as_ref().unwrap().orbitals.iter().filter(|o| o.occupation != 0.0).count();
    assert!(occupied > 4 * orbcloud::gpu::density_hessian::BATCH, "{occupied} occupied orbitals");
    check("benzene", &doc, &grid_over(&doc, 2.0, 18), 1000);
}
