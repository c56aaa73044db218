//! `orbcloud mesh`, `render --iso/--pick` and `bench isosurface`: isosurfaces and picking from
//! the command line.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use orbcloud::formats::mesh_write::{self, MeshFormat, NamedMesh};
use orbcloud::gpu::frame::PickId;
use orbcloud::gpu::{GpuContext, Renderer};
use orbcloud::headless::{isosurfaces, orbital_geometry, show_meshes};
use orbcloud::model::gto::PreparedBasis;
use orbcloud::model::isosurface::{self, Level, Mesh};
use orbcloud::model::units::BOHR_PER_ANGSTROM;
use orbcloud::model::{Document, VolumeGrid};
use orbcloud::scene::translucency::SurfaceLook;
use orbcloud::scene::{IsoLevel, IsosurfaceSettings, OpticsPreset};

use super::{WhatArgs, load, wavefunction_of};

/// Isosurface levels: `--iso` values and `--iso-sigma` multiples of the grid's σ.
#[derive(Args, Clone, Default)]
pub struct IsoArgs {
    /// Isosurface value in atomic units (ψ = ±V for an orbital, ρ = V for a density); repeat
    /// for nested surfaces.
    #[arg(long = "iso", allow_hyphen_values = true)]
    pub values: Vec<f32>,
    /// Isosurface at S standard deviations of the grid's values; repeatable.
    #[arg(long = "iso-sigma")]
    pub sigmas: Vec<f32>,
    /// Draw the isosurfaces translucent (seed 003's optics, composited in exact depth order).
    #[arg(long)]
    pub translucent: bool,
    /// The look of translucent surfaces.
    #[arg(long, value_enum, default_value_t = OpticsArg::Koide)]
    pub optics: OpticsArg,
}

#[derive(Clone, Copy, Default, ValueEnum)]
pub enum OpticsArg {
    /// Seed 003's pictures: tinted glass with an emitting rim; overlaps glow.
    #[default]
    Koide,
    /// Clear glass with strong highlights.
    Glassy,
    /// Emitting, absorbing smoke.
    Smoke,
}

impl OpticsArg {
    pub fn preset(self) -> OpticsPreset {
        match self {
            OpticsArg::Koide => OpticsPreset::Koide,
            OpticsArg::Glassy => OpticsPreset::Glassy,
            OpticsArg::Smoke => OpticsPreset::Smoke,
        }
    }
}

impl IsoArgs {
    pub fn levels(&self) -> Vec<IsoLevel> {
        let abs = self.values.iter().map(|&v| IsoLevel::Absolute(v));
        abs.chain(self.sigmas.iter().map(|&s| IsoLevel::Sigma(s))).collect()
    }

    /// The settings every level starts from: translucent or not.
    pub fn base(&self) -> IsosurfaceSettings {
        IsosurfaceSettings { translucent: self.translucent, optics: self.optics.preset(), ..Default::default() }
    }

    /// Each level's surfaces with their colours, larger values paler so nested ones tell
    /// apart; the order the levels were given in changes nothing.
    pub fn meshes(&self, grid: &VolumeGrid, base: &IsosurfaceSettings) -> Vec<(Mesh, SurfaceLook)> {
        let sigma = grid.stats.sigma;
        let mut levels = self.levels();
        levels.sort_by(|a, b| a.value(sigma).total_cmp(&b.value(sigma)));
        levels.dedup_by(|a, b| a.value(sigma) == b.value(sigma));
        let mut out = Vec::new();
        for (n, level) in levels.into_iter().enumerate() {
            let pale = |c: [f32; 3]| c.map(|v| v + (1.0 - v) * (1.0 - 0.6f32.powi(n as i32)));
            let iso = IsosurfaceSettings {
                visible: true,
                level,
                positive_color: pale(base.positive_color),
                negative_color: pale(base.negative_color),
                density_color: pale(base.density_color),
                ..*base
            };
            out.extend(isosurfaces(grid, &iso));
        }
        out
    }
}

/// Puts `--iso` surfaces of `grid` into the renderer (nothing when none were asked for).
pub fn show(ctx: &GpuContext, renderer: &mut Renderer, grid: &VolumeGrid, iso: &IsoArgs) {
    if iso.levels().is_empty() {
        return;
    }
    let meshes = iso.meshes(grid, &iso.base());
    let triangles = show_meshes(ctx, renderer.main(), &meshes);
    let how = if iso.translucent { ", translucent" } else { "" };
    eprintln!("isosurfaces: {} surface(s), {triangles} triangles{how}", meshes.len());
}

/// Prints what the rendered frame shows at `pixel`, and how long the pick took.
pub fn print_pick(ctx: &GpuContext, renderer: &Renderer, doc: &Document, pixel: [u32; 2]) -> Result<()> {
    let t = Instant::now();
    let picked = renderer.pick(ctx, pixel)?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let [x, y] = pixel;
    match picked {
        Some(PickId::Atom { index, .. }) => {
            let atom = doc
                .molecule
                .atoms
                .get(index as usize)
                .with_context(|| format!("picked atom {index} is not in the molecule"))?;
            let p = atom.position / BOHR_PER_ANGSTROM;
            println!(
                "pick {x},{y}: atom {} {} at {:.4} {:.4} {:.4} Å ({ms:.2} ms)",
                index + 1,
                atom.element().symbol,
                p.x,
                p.y,
                p.z
            );
        }
        Some(PickId::Surface { index, .. }) => println!("pick {x},{y}: isosurface {} ({ms:.2} ms)", index + 1),
        None => println!("pick {x},{y}: nothing ({ms:.2} ms)"),
    }
    Ok(())
}

pub fn parse_pixel(s: &str) -> Result<[u32; 2], String> {
    let (x, y) = s.split_once(',').ok_or_else(|| format!("expected X,Y in pixels, got {s:?}"))?;
    match (x.trim().parse(), y.trim().parse()) {
        (Ok(x), Ok(y)) => Ok([x, y]),
        _ => Err(format!("expected X,Y in pixels, got {s:?}")),
    }
}

/// What `mesh` and `bench isosurface` cut surfaces from.
#[derive(Args)]
pub struct GridArgs {
    /// Which volume of a cube file with several.
    #[arg(long, default_value_t = 0)]
    volume: usize,
    #[command(flatten)]
    what: WhatArgs,
    /// Points per axis of the grid a wavefunction is evaluated on.
    #[arg(long, default_value_t = 80)]
    grid_points: usize,
}

impl GridArgs {
    /// A cube file's volume, or the orbital or density of a Molden/fchk file evaluated on the
    /// CPU over the box the viewer uses.
    pub fn grid(&self, doc: &Document) -> Result<VolumeGrid> {
        if doc.wavefunction.is_none() {
            return doc.volumes.get(self.volume).cloned().with_context(|| {
                format!("{}: no volume {} (the file has {})", doc.source, self.volume, doc.volumes.len())
            });
        }
        let wf = wavefunction_of(doc)?;
        let q = self.what.resolve(wf)?;
        let g = orbital_geometry(doc, q, self.grid_points.clamp(8, 512)).context("the file has no atoms")?;
        let spec = g;
        let prepared = PreparedBasis::new(&wf.basis);
        let values = prepared.quantity_grid_f32(wf, q, &spec);
        Ok(VolumeGrid::new(self.what.label(&q, wf), g.dims, g.world_from_grid, values))
    }
}

#[derive(Args)]
pub struct MeshArgs {
    file: PathBuf,
    #[command(flatten)]
    iso: IsoArgs,
    #[command(flatten)]
    grid: GridArgs,
    /// Output: .obj (Wavefront), .ply (binary) or .glb (glTF binary); positions in ångström.
    #[arg(short, long)]
    output: PathBuf,
}

pub fn mesh(args: &MeshArgs) -> Result<()> {
    let format = MeshFormat::from_path(&args.output)
        .with_context(|| format!("{}: the extension must be .obj, .ply or .glb", args.output.display()))?;
    if args.iso.levels().is_empty() {
        bail!("give at least one --iso VALUE or --iso-sigma S");
    }
    let doc = load(Some(&args.file))?;
    let grid = args.grid.grid(&doc)?;
    let meshes: Vec<(Mesh, SurfaceLook)> =
        args.iso.meshes(&grid, &IsosurfaceSettings::default()).into_iter().map(|(m, c)| (m.welded(), c)).collect();
    let names = surface_names(&grid, &args.iso);
    let named: Vec<NamedMesh> =
        meshes.iter().zip(&names).map(|((mesh, color), name)| NamedMesh { name, mesh, color: color.color }).collect();
    let file = std::fs::File::create(&args.output).with_context(|| format!("creating {}", args.output.display()))?;
    let mut w = std::io::BufWriter::new(file);
    mesh_write::write(&mut w, format, &named).with_context(|| format!("writing {}", args.output.display()))?;
    for m in &named {
        eprintln!(
            "{}: {} vertices, {} triangles, area {:.3} Å²",
            m.name,
            m.mesh.positions.len(),
            m.mesh.triangle_count(),
            m.mesh.area() / BOHR_PER_ANGSTROM.powi(2)
        );
    }
    eprintln!("wrote {}", args.output.display());
    Ok(())
}

/// Object names in mesh files: `psi_plus_0.05`, `psi_minus_0.05`, `density_0.002`.
fn surface_names(grid: &VolumeGrid, iso: &IsoArgs) -> Vec<String> {
    let signed = grid.kind == orbcloud::model::grid::ValueKind::Signed;
    let mut names = Vec::new();
    for level in iso.levels() {
        let v = level.value(grid.stats.sigma);
        if signed {
            names.push(format!("psi_plus_{v}"));
            names.push(format!("psi_minus_{v}"));
        } else {
            names.push(format!("density_{v}"));
        }
    }
    names
}

#[derive(Args)]
pub struct IsoBench {
    /// A cube, Molden or fchk file.
    file: PathBuf,
    #[command(flatten)]
    iso: IsoArgs,
    #[command(flatten)]
    grid: GridArgs,
    /// Timed extractions (the median is reported).
    #[arg(long, default_value_t = 20)]
    runs: usize,
}

/// `orbcloud bench isosurface`: extraction time of both signs (or a density's one surface).
pub fn bench(args: &IsoBench) -> Result<()> {
    let doc = load(Some(&args.file))?;
    let grid = args.grid.grid(&doc)?;
    let level = args.iso.levels().first().copied().unwrap_or(IsoLevel::Absolute(0.05));
    let levels = Level::pair(level.value(grid.stats.sigma), grid.kind == orbcloud::model::grid::ValueKind::Signed);
    let mut times = Vec::new();
    let mut meshes = isosurface::extract(&grid, &levels);
    for _ in 0..args.runs.max(1) {
        let t = Instant::now();
        meshes = isosurface::extract(&grid, &levels);
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    let triangles: usize = meshes.iter().map(Mesh::triangle_count).sum();
    let area: f64 = meshes.iter().map(Mesh::area).sum();
    println!(
        "grid {:?}, {} surface(s) at {}, {triangles} triangles, area {:.4} bohr², {} threads",
        grid.dims,
        levels.len(),
        levels[0].value,
        area,
        rayon::current_num_threads()
    );
    println!(
        "extract_ms_median={:.2} min={:.2} max={:.2} runs={}",
        times[times.len() / 2],
        times[0],
        times[times.len() - 1],
        times.len()
    );
    Ok(())
}
