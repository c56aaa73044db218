//! `bench load`: how fast a structure file (PDB, mmCIF, XYZ; any file the viewer opens) is read.

use std::path::PathBuf;
use std::time::Instant;

use crate::formats;
use anyhow::Result;
use clap::Args;

#[derive(Args)]
pub struct LoadBench {
    /// The file to read.
    pub file: PathBuf,
    /// Times to read it; the fastest counts.
    #[arg(long, default_value_t = 3)]
    pub repeat: u32,
}

/// Prints the time to read the file into the model (bounded read, gunzip, parse, bonds), the
/// atoms per second, and the time bond perception alone takes.
pub fn bench_load(args: &LoadBench) -> Result<()> {
    let mut best = f64::INFINITY;
    let mut doc = None;
    for _ in 0..args.repeat.max(1) {
        drop(doc.take());
        let t = Instant::now();
        doc = Some(formats::load(&args.file)?);
        best = best.min(t.elapsed().as_secs_f64());
    }
    let doc = doc.expect("read at least once");
    let atoms = doc.structure.as_ref().map_or(doc.molecule.atoms.len(), |v| v.structure.len());
    println!("file: {} ({} bytes)", args.file.display(), std::fs::metadata(&args.file)?.len());
    println!(
        "load_ms={:.0} atoms={atoms} atoms_per_s={:.3e} shown_atoms={} bonds={}",
        best * 1e3,
        atoms as f64 / best,
        doc.molecule.atoms.len(),
        doc.molecule.bonds.len()
    );
    if let Some(view) = &doc.structure {
        let t = Instant::now();
        let molecule = view.structure.molecule(&view.atoms);
        println!(
            "bonds_ms={:.0} ({} bonds of {} atoms; residues={} chains={} models={})",
            t.elapsed().as_secs_f64() * 1e3,
            molecule.bonds.len(),
            molecule.atoms.len(),
            view.structure.residues.len(),
            view.structure.chains.len(),
            view.structure.models.len()
        );
    }
    Ok(())
}

#[derive(Args)]
pub struct SpheresBench {
    /// A structure (or any file with atoms) to draw instead of synthetic atoms.
    pub file: Option<PathBuf>,
    /// Synthetic atoms packed as densely as in a protein (ignored with a file).
    #[arg(long, default_value_t = 1_000_000)]
    pub atoms: usize,
    #[arg(long, value_enum, default_value_t = super::AtomsArg::SpaceFilling)]
    pub style: super::AtomsArg,
    /// Spheres up to this projected radius (pixels) are rasterised in compute; 0 draws every
    /// sphere as an impostor quad.
    #[arg(long, default_value_t = crate::gpu::atoms::SPLAT_RADIUS_PX)]
    pub splat_px: f32,
    #[command(flatten)]
    bench: super::BenchFrames,
}

/// Prints ms per frame of atoms alone, the whole structure in view and turning a little each
/// frame as in the viewer, and the GPU memory per atom.
pub fn bench_spheres(args: &SpheresBench) -> Result<()> {
    use crate::gpu::Renderer;
    use crate::scene::Camera;
    let (molecule, what) = match &args.file {
        Some(path) => {
            let doc = formats::load(path)?;
            (doc.molecule, path.display().to_string())
        }
        None => (crate::model::synthetic::atom_box(args.atoms), "synthetic protein-dense box".to_string()),
    };
    let Some((lo, hi)) = molecule.bounds() else { anyhow::bail!("{what}: no atoms to draw") };
    let ctx = super::gpu(args.bench.lavapipe)?;
    let style = args.style.style();
    let mut renderer = Renderer::new(&ctx);
    renderer.main().set_molecule(&ctx, &molecule, style);
    renderer.main().atoms.splat_radius_px = args.splat_px;
    let gpu_bytes = renderer.main().atoms.gpu_bytes();
    let camera = Camera::framing(lo.as_vec3(), hi.as_vec3());
    let times = super::render::time_frames(&ctx, &mut renderer, &camera, args.bench.size, args.bench.frames)?;
    let n = molecule.atoms.len();
    println!("adapter: {}", ctx.describe());
    println!(
        "scene: {what}, {n} atoms, {} bonds, {:?}, {}x{}, splat radius {} px",
        molecule.bonds.len(),
        style,
        args.bench.size[0],
        args.bench.size[1],
        args.splat_px
    );
    println!("gpu_bytes_per_atom={:.1}", gpu_bytes as f64 / n as f64);
    let c = renderer.main().atoms.cell_counts(&ctx)?;
    println!(
        "cells (last frame): {} of {} in view, {} drawn first (seen the frame before), {} of the {} others drawn after the occlusion test, {} may show",
        c.in_view, c.total, c.first, c.rest, c.tested, c.shown
    );
    println!(
        "ms_per_frame_median={:.1} min={:.1} max={:.1} frames={}",
        times[times.len() / 2],
        times[0],
        times[times.len() - 1],
        times.len()
    );
    Ok(())
}
