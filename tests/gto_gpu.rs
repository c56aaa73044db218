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
    use orbcloud::headless::Headless;
    use orbcloud::model::{Document, Molecule};
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
    h.renderer.main().set_direct(&ctx, &e, &grid, max_abs);
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
