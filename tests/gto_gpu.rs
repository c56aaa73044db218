//! The GPU's GTO kernel against its CPU reference (`CartesianExpansion::value`), on lavapipe.

mod common;

use glam::DVec3;
use orbcloud::gpu::gto::{GtoFillPass, read_volume};
use orbcloud::model::GridSpec;
use orbcloud::model::VolumeGrid;
use orbcloud::model::basis::n_cartesian;
use orbcloud::model::cartesian::{CartesianExpansion, CartesianShell};

fn expansion() -> CartesianExpansion {
    // A deterministic mix of shells, l = 0..5, with contracted primitives and signed weights.
    let mut seed = 7u64;
    let mut rnd = move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let shells = (0..12)
        .map(|i| {
            let l = (i % 6) as u32;
            CartesianShell {
                center: DVec3::new(rnd() * 4.0 - 2.0, rnd() * 4.0 - 2.0, rnd() * 3.0 - 1.5),
                l,
                cutoff: 9.0,
                primitives: (0..1 + i % 3).map(|_| [0.3 + 2.0 * rnd(), rnd() - 0.3]).collect(),
                weights: (0..n_cartesian(l)).map(|_| rnd() * 2.0 - 1.0).collect(),
            }
        })
        .collect();
    CartesianExpansion { shells }
}

#[test]
fn gpu_fill_matches_the_cpu_reference() {
    let ctx = common::lavapipe();
    let e = expansion();
    // Odd, unequal dimensions and a sheared grid catch any mix-up of axes.
    let dims = [21, 17, 13];
    let world_from_grid = VolumeGrid::affine(
        DVec3::new(-3.0, -2.5, -2.0),
        [DVec3::new(0.3, 0.0, 0.0), DVec3::new(0.05, 0.31, 0.0), DVec3::new(0.0, 0.02, 0.33)],
    );
    let grid = GridSpec { dims, world_from_grid };
    let texture = GtoFillPass::new(&ctx).fill(&ctx, &e, &grid).unwrap();
    let gpu = read_volume(&ctx, &texture).unwrap();
    assert_eq!(gpu.len(), dims.iter().product::<usize>());
    let mut cpu = Vec::with_capacity(gpu.len());
    for i in 0..dims[0] {
        for j in 0..dims[1] {
            for k in 0..dims[2] {
                cpu.push(e.value(world_from_grid.transform_point3(DVec3::new(i as f64, j as f64, k as f64))));
            }
        }
    }
    let max = cpu.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = gpu.iter().zip(&cpu).map(|(g, c)| (*g as f64 - c).abs()).fold(0.0, f64::max);
    eprintln!("max |ψ| {max:.4}, worst |gpu − cpu| {worst:.3e} ({:.2e} of max)", worst / max);
    assert!(max > 0.1, "the test expansion is not trivial");
    // f32 arithmetic: 1e-4 of the largest value.
    assert!(worst <= 1e-4 * max, "GPU differs from CPU by {worst:e} (max {max})");
}

#[test]
fn an_empty_expansion_fills_zeros() {
    let ctx = common::lavapipe();
    let grid = GridSpec::cube(DVec3::splat(-1.0), DVec3::splat(1.0), 5);
    let texture = GtoFillPass::new(&ctx).fill(&ctx, &CartesianExpansion::default(), &grid).unwrap();
    assert!(read_volume(&ctx, &texture).unwrap().iter().all(|&v| v == 0.0));
}

#[test]
fn direct_mode_matches_slicing_the_filled_grid() {
    use orbcloud::gpu::gto::volume_from_texture;
    use orbcloud::model::{Document, Molecule};
    use orbcloud::pictures::headless::Headless;
    use orbcloud::scene::{AtomStyle, Camera, RenderSettings};

    let ctx = common::lavapipe();
    let e = expansion();
    let grid = GridSpec::cube(DVec3::new(-4.0, -4.0, -3.5), DVec3::new(4.0, 4.0, 3.5), 48);
    let texture = GtoFillPass::new(&ctx).fill(&ctx, &e, &grid).unwrap();
    let values = read_volume(&ctx, &texture).unwrap();
    let max_abs = values.iter().fold(0.0f64, |m, v| m.max(v.abs() as f64));
    let settings = RenderSettings { atoms: AtomStyle::Hidden, ..Default::default() };
    let doc = Document { molecule: Molecule::default(), ..Default::default() };
    let mut camera = Camera::framing(DVec3::splat(-4.0).as_vec3(), DVec3::splat(4.0).as_vec3());
    camera.orbit(0.6, 0.3);
    let mut h = Headless::new(&ctx, &doc, None, &settings, [96, 72]).unwrap();

    h.renderer.main().set_volume_texture(&ctx, volume_from_texture(texture, &grid, max_abs));
    let sliced = h.render(&ctx, &camera, &settings).unwrap();
    // The gradient scale the slice path's texture gets without one measured (unused here).
    h.renderer.main().set_direct(&ctx, &e, &grid, (max_abs, 2.0 * max_abs));
    let direct = h.render(&ctx, &camera, &settings).unwrap();

    let covered = direct.pixels().filter(|p| p[0].abs_diff(p[2]) > 20).count();
    assert!(covered > 500, "direct mode shows the orbital ({covered} pixels)");
    let (mut worst, mut sum) = (0u8, 0u64);
    for (a, b) in sliced.pixels().zip(direct.pixels()) {
        let d = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap();
        worst = worst.max(d);
        sum += d as u64;
    }
    let mean = sum as f64 / sliced.pixels().len() as f64;
    eprintln!("direct vs grid: mean {mean:.3}/255, worst {worst}/255");
    // The grid path interpolates trilinearly between points 0.17 bohr apart; the direct path is
    // exact. The pictures agree to a few counts (measured: mean 0.13/255, worst 2/255).
    assert!(mean < 0.5 && worst <= 6, "mean {mean}, worst {worst}");
}

#[test]
fn gpu_fill_of_real_orbitals_matches_the_cpu_evaluator() {
    let Some(dir) = common::refdata("gto_gpu::gpu_fill_of_real_orbitals_matches_the_cpu_evaluator") else {
        return;
    };
    use orbcloud::model::gto::PreparedBasis;
    let ctx = common::lavapipe();
    let fill = GtoFillPass::new(&ctx);
    // ORCA (pure d and f after its repair), Gaussian cartesian d/f, a ghost basis.
    for name in ["nh3_orca.molden", "o2_cc_pvtz_cart.fchk", "water_dimer_ghost.fchk"] {
        let doc = orbcloud::formats::load(&dir.join(name)).unwrap_or_else(|e| panic!("{e}"));
        let wf = doc.wavefunction.as_ref().unwrap();
        let prepared = PreparedBasis::new(&wf.basis);
        for i in [wf.homo(orbcloud::model::Spin::Alpha).unwrap(), wf.lumo(orbcloud::model::Spin::Alpha).unwrap()] {
            let quantity = orbcloud::model::orbitals::Quantity::Orbital(i);
            let geometry = orbcloud::evaluate::orbital_geometry(&doc, quantity, 28).unwrap();
            let spec = geometry;
            let c = &wf.orbitals[i].coefficients;
            let e = CartesianExpansion::from_coefficients(&prepared, c);
            let gpu = read_volume(&ctx, &fill.fill(&ctx, &e, &geometry).unwrap()).unwrap();
            let cpu = prepared.eval_grid(c, &spec);
            let max = cpu.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = gpu.iter().zip(&cpu).map(|(g, c)| (*g as f64 - c).abs()).fold(0.0, f64::max);
            eprintln!("{name} MO {i}: worst |gpu − cpu| {:.2e} of max|ψ| {max:.3}", worst / max);
            assert!(worst <= 1e-4 * max, "{name} MO {i}: GPU differs by {worst:e} (max {max})");
        }
    }
}

fn fixture(name: &str) -> orbcloud::model::Document {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions").join(name);
    orbcloud::formats::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_analytic_gpu_gradient_matches_the_cpu_gradient() {
    use orbcloud::gpu::gto::Component;
    use orbcloud::model::gto::PreparedBasis;
    let ctx = common::lavapipe();
    let fill = GtoFillPass::new(&ctx);
    // Cartesian d (6-31G*) and pure d, f (cc-pVTZ): every branch of the angular derivative.
    for name in ["h2o_cart_631gs.molden", "h2o_ccpvtz.molden"] {
        let doc = fixture(name);
        let wf = doc.wavefunction.as_ref().unwrap();
        let prepared = PreparedBasis::new(&wf.basis);
        let homo = wf.homo(orbcloud::model::Spin::Alpha).unwrap();
        let c = &wf.orbitals[homo].coefficients;
        let quantity = orbcloud::model::orbitals::Quantity::Orbital(homo);
        let geometry = orbcloud::evaluate::orbital_geometry(&doc, quantity, 19).unwrap();
        let e = CartesianExpansion::from_coefficients(&prepared, c);
        let components = [Component::GradientX, Component::GradientY, Component::GradientZ];
        let gpu: Vec<Vec<f32>> = components
            .iter()
            .map(|&a| read_volume(&ctx, &fill.fill_component(&ctx, &e, &geometry, a).unwrap()).unwrap())
            .collect();
        let [nx, ny, nz] = geometry.dims;
        let (mut worst, mut max) = (0f64, 0f64);
        for i in 0..nx {
            for j in 0..ny {
                for k in 0..nz {
                    let p = geometry.world_from_grid.transform_point3(DVec3::new(i as f64, j as f64, k as f64));
                    let (_, cpu) = prepared.orbital_value_and_gradient(c, p);
                    let m = (i * ny + j) * nz + k;
                    let got = DVec3::new(gpu[0][m] as f64, gpu[1][m] as f64, gpu[2][m] as f64);
                    worst = worst.max((got - cpu).length());
                    max = max.max(cpu.length());
                }
            }
        }
        eprintln!("{name}: max |∇ψ| {max:.4}, worst |gpu − cpu| {worst:.2e} ({:.1e} of max)", worst / max);
        assert!(max > 0.05, "{name}: the gradient is not trivial");
        assert!(worst <= 2e-4 * max, "{name}: GPU gradient differs by {worst:e} (max {max})");
    }
    assert_eq!(fill.fills(), 6, "every fill is counted");
}

/// An object showing `doc`'s HOMO per sample (direct mode) on 24 points per side.
fn direct_homo(doc: &orbcloud::model::Document, iso: bool) -> orbcloud::scene::ObjectState {
    use orbcloud::scene::{Evaluation, IsoLevel, ObjectState, QuantityState, RenderSettings, Source};
    let homo = doc.wavefunction.as_ref().unwrap().homo(orbcloud::model::Spin::Alpha).unwrap();
    let source = Source::Wavefunction(orbcloud::model::orbitals::Quantity::Orbital(homo));
    let mut q = QuantityState::new(source, &RenderSettings::default());
    q.isosurfaces[0].visible = iso;
    q.isosurfaces[0].level = IsoLevel::Absolute(0.05);
    let evaluation = Evaluation { direct: true, grid_points: 24, ..Default::default() };
    ObjectState { quantities: vec![q], evaluation, ..Default::default() }
}

#[test]
fn direct_mode_fills_no_grid_unless_isosurfaces_are_shown() {
    use orbcloud::gpu::Renderer;
    use orbcloud::layers::show_quantity;
    let ctx = common::lavapipe();
    let doc = fixture("h2o_cart_631gs.molden");
    let mut renderer = Renderer::new(&ctx);
    let mut fill = None;
    let fills = |f: &Option<GtoFillPass>| f.as_ref().map_or(0, GtoFillPass::fills);

    let state = direct_homo(&doc, false);
    let values = show_quantity(&ctx, renderer.main(), &mut fill, &doc, &state, 0).unwrap().values.unwrap();
    assert_eq!(fills(&fill), 0, "no grid filled for a direct-mode cloud alone");
    assert!(values.grid.is_none() && values.sampled.is_some());
    assert!(renderer.main().volume.is_direct());
    assert!(renderer.main().surfaces.is_empty());

    // An isosurface shown: one grid, read back and cut; the cloud stays direct.
    let state = direct_homo(&doc, true);
    let values = show_quantity(&ctx, renderer.main(), &mut fill, &doc, &state, 0).unwrap().values.unwrap();
    assert_eq!(fills(&fill), 1);
    assert_eq!(values.grid.as_ref().map(|g| g.dims), Some([24; 3]));
    assert!(renderer.main().volume.is_direct());
    assert!(!renderer.main().surfaces.is_empty(), "the isosurfaces are shown");

    // Grid mode fills one whatever is shown.
    let mut state = direct_homo(&doc, false);
    state.evaluation.direct = false;
    show_quantity(&ctx, renderer.main(), &mut fill, &doc, &state, 0).unwrap();
    assert_eq!(fills(&fill), 2);
    assert!(!renderer.main().volume.is_direct());
}

#[test]
fn direct_mode_measures_the_range_and_gradient_scale() {
    use orbcloud::evaluate::{WavefunctionView, evaluate_wavefunction};
    use orbcloud::model::gto::PreparedBasis;
    let ctx = common::lavapipe();
    let fill = GtoFillPass::new(&ctx);
    for name in ["h2o_cart_631gs.molden", "benzene_631gs.molden"] {
        let doc = fixture(name);
        let wf = doc.wavefunction.as_ref().unwrap();
        let homo = wf.homo(orbcloud::model::Spin::Alpha).unwrap();
        let quantity = orbcloud::model::orbitals::Quantity::Orbital(homo);
        let view = WavefunctionView { quantity, direct: true, points: 48, functions: None, grid: false };
        let before = fill.fills();
        let values = evaluate_wavefunction(&ctx, &fill, &doc, &view).unwrap().unwrap().values;
        assert_eq!(fill.fills(), before, "{name}: measured without a grid");
        let range = values.sampled.unwrap().range;
        // Reference: a dense CPU lattice over the same box plus the nuclei inside it (where
        // p-type gradients peak), ψ and ∇ψ from the CPU evaluator.
        let prepared = PreparedBasis::new(&wf.basis);
        let c = &wf.orbitals[homo].coefficients;
        let geometry = orbcloud::evaluate::orbital_geometry(&doc, quantity, 41).unwrap();
        let grid_from_world = geometry.world_from_grid.inverse();
        let inside = |p: DVec3| {
            let g = grid_from_world.transform_point3(p);
            (0..3).all(|a| g[a] >= 0.0 && g[a] <= 40.0)
        };
        let lattice = (0..41 * 41 * 41).map(|m| {
            let u = DVec3::new((m / 1681) as f64, (m / 41 % 41) as f64, (m % 41) as f64);
            geometry.world_from_grid.transform_point3(u)
        });
        let nuclei = doc.molecule.atoms.iter().map(|a| a.position).filter(|&p| inside(p));
        let (mut max_abs, mut max_grad) = (0f64, 0f64);
        for p in lattice.chain(nuclei) {
            let (v, g) = prepared.orbital_value_and_gradient(c, p);
            max_abs = max_abs.max(v.abs());
            max_grad = max_grad.max(g.length());
        }
        eprintln!(
            "{name}: measured max |ψ| {:.4} |∇ψ| {:.4}; dense lattice {max_abs:.4} {max_grad:.4}",
            range.max_abs, range.max_grad
        );
        // Measured values are values of ψ, never above the truth; they must not fall short of
        // what a search 17 times denser finds.
        assert!(range.max_abs >= 0.99 * max_abs, "{name}: max |ψ| {} vs {max_abs}", range.max_abs);
        assert!(range.max_grad >= 0.97 * max_grad, "{name}: max |∇ψ| {} vs {max_grad}", range.max_grad);
        assert!(range.samples.values.len() >= 1000, "a few thousand samples");
    }
}
