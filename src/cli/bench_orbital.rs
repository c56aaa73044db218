//! `orbcloud bench orbital`: grid points per second of one orbital evaluated from its basis, by
//! the CPU evaluator (every thread) and by the GPU's fill pass (what the viewer fills its clouds
//! with), with the largest difference of the two.

use std::time::Instant;

use crate::gpu::gto::{GtoFillPass, read_volume};
use crate::model::cartesian::CartesianExpansion;
use crate::model::gto::PreparedBasis;
use crate::model::orbitals::Quantity;
use anyhow::{Context, Result, bail};
use clap::Args;

use super::WhatArgs;
use crate::scene::limits::{self, within};

#[derive(Args)]
pub struct OrbitalBench {
    /// A wavefunction (Molden, fchk, wfn, wfx, MKL, JSON).
    file: std::path::PathBuf,
    #[command(flatten)]
    what: WhatArgs,
    /// Points along the longest side of the grid: the viewer's box for the orbital.
    #[arg(long, default_value_t = 128, value_parser = within(limits::GRID_POINTS))]
    points: usize,
    #[command(flatten)]
    bench: super::BenchRuns,
}

pub fn bench(args: &OrbitalBench) -> Result<()> {
    let doc = super::load(Some(&args.file))?;
    let wf = super::wavefunction_of(&doc)?;
    let quantity = args.what.resolve(&doc)?;
    let Quantity::Orbital(i) = quantity else { bail!("bench orbital times an orbital; {quantity:?} is not one") };
    let grid = crate::evaluate::orbital_geometry(&doc, quantity, args.points).context("the file has no grid box")?;
    let ctx = super::gpu(args.bench.lavapipe)?;
    let points = grid.len() as f64;
    println!("adapter: {}", ctx.describe());
    println!(
        "{}: {}, {} basis functions, grid {:?} = {} points, {} threads",
        doc.source,
        super::quantity_label(&quantity, &doc),
        wf.basis.n_functions(),
        grid.dims,
        grid.len(),
        rayon::current_num_threads()
    );
    let best = |times: &[f64]| times.iter().copied().fold(f64::INFINITY, f64::min);
    let coefficients = &wf.orbitals[i].coefficients;

    let (mut cpu_ms, mut cpu) = (Vec::new(), Vec::new());
    for _ in 0..args.bench.runs {
        let t = Instant::now();
        cpu = PreparedBasis::new(&wf.basis).quantity_grid_f32(wf, &doc.molecule, quantity, &grid);
        cpu_ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let t = Instant::now();
    let pass = GtoFillPass::new(&ctx);
    let pipeline_ms = t.elapsed().as_secs_f64() * 1e3;
    let prepared = PreparedBasis::new(&wf.basis);
    let (mut fill_ms, mut read_ms, mut gpu) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..args.bench.runs + 1 {
        // The first run warms the driver's caches and is not counted.
        let t = Instant::now();
        let expansion = CartesianExpansion::from_coefficients(&prepared, coefficients);
        let texture = pass.fill(&ctx, &expansion, &grid)?;
        ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
        fill_ms.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        gpu = read_volume(&ctx, &texture)?;
        read_ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let (fill_ms, read_ms) = (&fill_ms[1..], &read_ms[1..]);
    let max_abs = cpu.iter().fold(0.0f32, |m, v| m.max(v.abs())).max(f32::MIN_POSITIVE);
    let worst = cpu.iter().zip(&gpu).map(|(c, g)| (c - g).abs()).fold(0.0f32, f32::max) / max_abs;
    let rate = |ms: f64| points / (ms * 1e-3);
    println!(
        "cpu_ms={:.1} ({:.3e} points/s) gpu_fill_ms={:.2} ({:.3e} points/s) readback_ms={:.1} \
         (pipeline built once in {pipeline_ms:.1} ms) runs={}",
        best(&cpu_ms),
        rate(best(&cpu_ms)),
        best(fill_ms),
        rate(best(fill_ms)),
        best(read_ms),
        args.bench.runs
    );
    println!("largest difference GPU − CPU: {worst:.2e} of max |ψ|");
    Ok(())
}
