//! `orbcloud mesh`, `render --iso/--pick` and `bench isosurface`: isosurfaces and picking from
//! the command line.

use crate::scene::coloring::ColorScheme;
use crate::scene::limits::{self, within};
use std::path::PathBuf;
use std::time::Instant;

use crate::evaluate::meshes::{color_meshes, color_name, isosurfaces, values_on};
use crate::evaluate::orbital_geometry;
use crate::formats::mesh_write::{self, MeshFormat, NamedMesh};
use crate::gpu::frame::PickId;
use crate::gpu::{GpuContext, Renderer};
use crate::layers::show_meshes;
use crate::model::gto::PreparedBasis;
use crate::model::isosurface::{self, Level, Mesh};
use crate::model::orbitals::{OrbitalSpec, Quantity, Spin};
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::model::{Document, VolumeGrid};
use crate::scene::Source;
use crate::scene::coloring::ValueMap;
use crate::scene::translucency::{OpticsTuning, SurfaceLook};
use crate::scene::{IsoLevel, IsosurfaceSettings, OpticsPreset};
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};

use super::{WhatArgs, load, wavefunction_of};

/// Isosurface levels: `--iso` values and `--iso-sigma` multiples of the grid's σ.
#[derive(Args, Clone, Default)]
pub struct IsoArgs {
    /// Isosurface value in atomic units (ψ = ±V for an orbital, ρ = V for a density); repeat
    /// for nested surfaces.
    #[arg(long = "iso", allow_hyphen_values = true, value_parser = within(-*limits::ISOVALUE.end()..=*limits::ISOVALUE.end()))]
    pub values: Vec<f32>,
    /// Isosurface at S standard deviations of the grid's values (0 to 1000); repeatable.
    #[arg(long = "iso-sigma", value_parser = within(limits::SIGMA))]
    pub sigmas: Vec<f32>,
    /// Draw the isosurfaces translucent (each shining and letting light through, composited in
    /// exact depth order; where one lies inside another object's surface it glows).
    #[arg(long)]
    pub translucent: bool,
    /// The look of translucent surfaces.
    #[arg(long, value_enum, default_value_t = OpticsArg::Tinted)]
    pub optics: OpticsArg,
    /// Multiply a coefficient of the preset (a, b, c, n, d, f, g, glow_d, glow_f, glow_g) by
    /// R,G,B factors or one factor, e.g. `g=0.5` or `d=1,0.5,0.5`; repeatable.
    #[arg(long = "optics-scale", value_parser = parse_tuning)]
    pub tuning: Vec<(String, Vec<f32>)>,
    /// Colour the isosurfaces by another quantity's value at each vertex, on a map from red
    /// (negative) through white to blue (positive): `esp` (the electrostatic potential),
    /// `density`, `spin-density`, an orbital (`homo`, `lumo+1`, a number) or a cube file
    /// (sampled trilinearly, grey outside its grid).
    #[arg(long, value_name = "QUANTITY|FILE.cube", allow_hyphen_values = true)]
    pub color_by: Option<String>,
    /// The |value| at which `--color-by` colours saturate (a.u.); by default the 98th
    /// percentile of |value| over the vertices.
    #[arg(long, requires = "color_by", value_parser = within(1e-30..=f64::from(*limits::ISOVALUE.end())))]
    pub color_range: Option<f64>,
}

/// Surfaces coloured by a quantity's values: the map, the quantity's name, and each mesh's
/// values at its vertices (`None` outside a cube file's grid).
pub struct Colored {
    pub map: ValueMap,
    pub name: String,
    pub values: Vec<Vec<Option<f64>>>,
}

impl IsoArgs {
    /// What `--color-by` names: a quantity of `doc`'s wavefunction, or a cube file's first data
    /// set added to `doc` as one of its volumes.
    pub fn color_source(&self, doc: &mut Document) -> Result<Option<Source>> {
        let Some(what) = &self.color_by else { return Ok(None) };
        let word = what.trim().to_ascii_lowercase();
        let quantity = match word.as_str() {
            "esp" | "potential" => Some(Quantity::Potential),
            "density" => Some(Quantity::Density),
            "spin-density" | "spin_density" => Some(Quantity::SpinDensity),
            _ => word.parse::<OrbitalSpec>().ok().and_then(|spec| {
                doc.wavefunction.as_ref().and_then(|wf| wf.resolve(spec, Spin::Alpha)).map(Quantity::Orbital)
            }),
        };
        if let Some(q) = quantity {
            if doc.wavefunction.is_none() {
                bail!(
                    "--color-by {what}: {} holds no wavefunction (a Molden, fchk, wfn, wfx, MKL or JSON file)",
                    doc.source
                );
            }
            return Ok(Some(Source::Wavefunction(q)));
        }
        let path = std::path::Path::new(what);
        if !path.exists() {
            bail!(
                "--color-by {what:?}: expected esp, density, spin-density, an orbital (homo, lumo+1, a number) or a cube file"
            );
        }
        let other = load(Some(path))?;
        let grid =
            other.volumes.into_iter().next().with_context(|| format!("--color-by {what}: the file holds no volume"))?;
        doc.volumes.push(grid);
        Ok(Some(Source::Volume(doc.volumes.len() - 1)))
    }

    /// Every isosurface of `object` coloured by what `--color-by` names (a cube file's data set
    /// joins `doc`), saturating at `--color-range`.
    pub fn color_object(&self, doc: &mut Document, object: &mut crate::scene::ObjectState) -> Result<()> {
        let Some(source) = self.color_source(doc)? else { return Ok(()) };
        for iso in object.quantities.iter_mut().flat_map(|q| &mut q.isosurfaces) {
            (iso.color_by, iso.color_range) = (Some(source), self.color_range.map(|r| r as f32));
        }
        Ok(())
    }

    /// Colours `meshes` by `source` of `doc` ([`Self::color_source`]), one map for all of them.
    pub fn color(&self, doc: &Document, source: Source, meshes: &mut [(Mesh, SurfaceLook)]) -> Colored {
        let values = values_on(
            crate::evaluate::meshes::Evaluating::alone(doc),
            source,
            &meshes.iter().map(|(m, _)| m).collect::<Vec<_>>(),
        );
        let mut colored: Vec<&mut Mesh> = meshes.iter_mut().map(|(m, _)| m).collect();
        let map = color_meshes(&mut colored, &values, self.color_range, ColorScheme::RedWhiteBlue);
        let name = color_name(doc, source);
        Colored { map, name, values }
    }
}

/// `NAME=X` or `NAME=R,G,B`, NAME a coefficient of [`OpticsTuning::NAMES`].
fn parse_tuning(s: &str) -> Result<(String, Vec<f32>), String> {
    let (name, values) = s.split_once('=').ok_or_else(|| format!("expected NAME=R,G,B or NAME=X, got {s:?}"))?;
    if !OpticsTuning::NAMES.contains(&name) {
        return Err(format!("{name:?} is not a coefficient: one of {}", OpticsTuning::NAMES.join(", ")));
    }
    let factors: Vec<f32> = values
        .split(',')
        .map(|v| limits::parse_in(v, &limits::OPTICS_FACTOR).ok())
        .collect::<Option<_>>()
        .ok_or_else(|| format!("{name}: expected factors 0 to 100, got {values:?}"))?;
    match (name, factors.len()) {
        (_, 1) | ("a" | "b" | "c" | "d" | "f" | "g" | "glow_d" | "glow_f" | "glow_g", 3) => {
            Ok((name.to_string(), factors))
        }
        _ => Err(format!("{name}: expected {} factor(s), got {}", if name == "n" { 1 } else { 3 }, factors.len())),
    }
}

#[derive(Clone, Copy, Default, ValueEnum)]
pub enum OpticsArg {
    /// Tinted glass with an emitting rim; overlaps glow.
    #[default]
    #[value(alias = "koide")]
    Tinted,
    /// Clear glass with strong highlights.
    Glassy,
    /// Emitting, absorbing smoke.
    Smoke,
}

impl OpticsArg {
    pub fn preset(self) -> OpticsPreset {
        match self {
            OpticsArg::Tinted => OpticsPreset::Koide,
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

    /// Puts these levels (when any were given) in place of a quantity's isosurfaces, drawn as
    /// its first one is and told apart by colour ([`IsosurfaceSettings::nested`]).
    pub fn apply_to(&self, quantity: &mut crate::scene::QuantityState) {
        let mut levels = self.levels();
        if levels.is_empty() {
            return;
        }
        levels.sort_by(|a, b| a.value(1.0).total_cmp(&b.value(1.0)));
        let own = quantity.isosurfaces.first().copied().unwrap_or_default();
        let tuning = if self.tuning.is_empty() { own.tuning } else { self.tuning() };
        let first = IsosurfaceSettings { translucent: own.translucent || self.translucent, tuning, ..own };
        let count = levels.len();
        quantity.isosurfaces = levels.into_iter().enumerate().map(|(n, level)| first.nested(level, n, count)).collect();
    }

    /// The settings every level starts from: translucent or not.
    pub fn base(&self) -> IsosurfaceSettings {
        IsosurfaceSettings {
            translucent: self.translucent,
            optics: self.optics.preset(),
            tuning: self.tuning(),
            ..Default::default()
        }
    }

    /// The `--optics-scale` factors.
    pub fn tuning(&self) -> OpticsTuning {
        let mut tuning = OpticsTuning::default();
        for (name, factors) in &self.tuning {
            if let Some(slot) = tuning.factors_mut(name) {
                for (k, v) in slot.iter_mut().enumerate() {
                    *v = factors[k.min(factors.len() - 1)];
                }
            }
        }
        tuning
    }

    /// Each level's surfaces with their colours ([`IsosurfaceSettings::nested`]), so nested ones tell
    /// apart; the order the levels were given in changes nothing.
    pub fn meshes(&self, grid: &VolumeGrid, base: &IsosurfaceSettings) -> Vec<(Mesh, SurfaceLook)> {
        self.named_meshes(grid, base, None).into_iter().map(|(_, mesh, look)| (mesh, look)).collect()
    }

    /// [`Self::meshes`], each named for a mesh file: `psi_plus_0.05`, `psi_minus_0.05` (an
    /// orbital's two signs), `density_0.002`; `stem` in place of `psi` or `density` when given
    /// (`homo_plus_0.05`).
    pub fn named_meshes(
        &self,
        grid: &VolumeGrid,
        base: &IsosurfaceSettings,
        stem: Option<&str>,
    ) -> Vec<(String, Mesh, SurfaceLook)> {
        let sigma = grid.stats.sigma;
        let signed = grid.kind == crate::model::grid::ValueKind::Signed;
        let mut levels = self.levels();
        levels.sort_by(|a, b| a.value(sigma).total_cmp(&b.value(sigma)));
        levels.dedup_by(|a, b| a.value(sigma) == b.value(sigma));
        let count = levels.len();
        levels
            .into_iter()
            .enumerate()
            .flat_map(|(n, level)| {
                let v = level.value(sigma);
                let stem = stem.unwrap_or(if signed { "psi" } else { "density" });
                let names = match signed {
                    true => vec![format!("{stem}_plus_{v}"), format!("{stem}_minus_{v}")],
                    false => vec![format!("{stem}_{v}")],
                };
                names
                    .into_iter()
                    .zip(isosurfaces(grid, &base.nested(level, n, count)))
                    .map(|(name, (m, l))| (name, m, l))
            })
            .collect()
    }
}

/// Puts `--iso` surfaces of `grid` (coloured by `color` when given: [`IsoArgs::color_source`])
/// and `more` (a molecular surface, a mode's arrows) into the renderer (nothing when none was
/// asked for). Returns how the isosurfaces were coloured, and what was shown in words
/// ("isosurfaces: 2 surface(s), 11800 triangles") for the command to print.
pub fn show(
    ctx: &GpuContext,
    renderer: &mut Renderer,
    (grid, doc): (Option<&VolumeGrid>, &Document),
    iso: &IsoArgs,
    color: Option<Source>,
    more: Vec<(Mesh, SurfaceLook)>,
) -> (Option<Colored>, Option<String>) {
    let mut meshes = match grid {
        Some(grid) if !iso.levels().is_empty() => iso.meshes(grid, &iso.base()),
        _ => Vec::new(),
    };
    let colored = color.filter(|_| !meshes.is_empty()).map(|c| iso.color(doc, c, &mut meshes));
    let what = if more.is_empty() { "isosurfaces" } else { "surfaces" };
    meshes.extend(more);
    if meshes.is_empty() {
        return (colored, None);
    }
    let triangles = show_meshes(ctx, renderer.main(), &meshes);
    let how = if iso.translucent { ", translucent" } else { "" };
    (colored, Some(format!("{what}: {} surface(s), {triangles} triangles{how}", meshes.len())))
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
#[derive(Args, Clone)]
pub struct GridArgs {
    /// Which volume of a cube file with several.
    #[arg(long, default_value_t = 0)]
    volume: usize,
    #[command(flatten)]
    what: WhatArgs,
    /// Points per axis of the grid a wavefunction is evaluated on, 8 to 512.
    #[arg(long, default_value_t = 80, value_parser = within(limits::GRID_POINTS))]
    grid_points: usize,
}

impl GridArgs {
    /// A cube file's volume, or the orbital or density of a Molden/fchk file evaluated on the
    /// CPU over the box the viewer uses.
    pub fn grid(&self, doc: &Document) -> Result<VolumeGrid> {
        if let (None, Some((_, flag))) = (&doc.wavefunction, self.what.state_quantity()) {
            return Err(super::no_state_density(doc, flag));
        }
        if doc.wavefunction.is_none() {
            return doc.volumes.get(self.volume).cloned().with_context(|| {
                format!("{}: no volume {} (the file has {})", doc.source, self.volume, doc.volumes.len())
            });
        }
        let wf = wavefunction_of(doc)?;
        let q = self.what.resolve(doc)?;
        let g = orbital_geometry(doc, q, self.grid_points.clamp(8, 512)).context("the file has no atoms")?;
        let spec = g;
        let prepared = PreparedBasis::new(&wf.basis);
        let values = prepared.quantity_grid_f32(wf, &doc.molecule, q, &spec);
        Ok(VolumeGrid::new(super::quantity_label(&q, doc), g.dims, g.world_from_grid, values))
    }
}

#[derive(Args)]
pub struct MeshArgs {
    file: PathBuf,
    #[command(flatten)]
    iso: IsoArgs,
    #[command(flatten)]
    grid: GridArgs,
    #[command(flatten)]
    molsurface: super::molsurface::MolSurfaceArgs,
    /// Output: .obj (Wavefront), .ply (binary) or .glb (glTF binary); positions in ångström.
    #[arg(short, long)]
    output: PathBuf,
}

/// Writes the surfaces `args` asks for; `later` are further quantities of the same file
/// ([`super::quantities`]), each with its own levels, their surfaces named after them.
pub fn mesh(args: &MeshArgs, later: &[MeshArgs]) -> Result<()> {
    let format = MeshFormat::from_path(&args.output)
        .with_context(|| format!("{}: the extension must be .obj, .ply or .glb", args.output.display()))?;
    if args.iso.levels().is_empty() && args.molsurface.surface.is_none() {
        bail!("give at least one --iso VALUE or --iso-sigma S, or --surface gaussian|ses");
    }
    if let Some(q) = later.iter().find(|q| q.iso.levels().is_empty()) {
        bail!("{}: each quantity needs its own --iso VALUE or --iso-sigma S", q.grid.what.describe());
    }
    let mut doc = load(Some(&args.file))?;
    let color = args.iso.color_source(&mut doc)?;
    let (meshes, names) = if args.molsurface.surface.is_some() {
        let by_volume = matches!(args.molsurface.surface_color, super::molsurface::SurfaceColorArg::Volume);
        let grid = by_volume.then(|| args.grid.grid(&doc)).transpose()?;
        let built = args.molsurface.mesh(&doc, false, grid.as_ref())?;
        (built.into_iter().map(|(mesh, look, _)| (mesh, look)).collect(), vec![args.molsurface.name().to_string()])
    } else {
        let mut meshes = Vec::new();
        let mut names = Vec::new();
        for q in std::iter::once(args).chain(later) {
            let grid = GridArgs { grid_points: args.grid.grid_points, ..q.grid.clone() }.grid(&doc)?;
            // With several quantities, each surface is named after its quantity; an excited
            // state's difference density is signed, yet no orbital (`difference_density_plus`).
            let stem = match (later.is_empty(), doc.wavefunction.is_some()) {
                (true, _) if q.grid.what.state_quantity().is_some() => Some(q.grid.what.short_name()),
                (true, _) => None,
                (false, true) => Some(q.grid.what.short_name()),
                (false, false) => Some(file_name(&grid.label)),
            };
            for (name, mesh, look) in q.iso.named_meshes(&grid, &IsosurfaceSettings::default(), stem.as_deref()) {
                names.push(name);
                meshes.push((mesh, look));
            }
        }
        (meshes, names)
    };
    let mut meshes: Vec<(Mesh, SurfaceLook)> = meshes.into_iter().map(|(m, c)| (m.welded(), c)).collect();
    let colored = color.map(|c| args.iso.color(&doc, c, &mut meshes));
    let values: Vec<Option<Vec<f32>>> = (0..meshes.len())
        .map(|i| colored.as_ref().map(|c| c.values[i].iter().map(|v| v.map_or(f32::NAN, |v| v as f32)).collect()))
        .collect();
    let named: Vec<NamedMesh> = meshes
        .iter()
        .zip(&names)
        .zip(&values)
        .map(|(((mesh, color), name), values)| NamedMesh { name, mesh, color: color.color, values: values.as_deref() })
        .collect();
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
    if let Some(c) = &colored {
        eprintln!("coloured by {}: ±{:.4} a.u. (red negative, blue positive)", c.name, c.map.range);
    }
    eprintln!("wrote {}", args.output.display());
    Ok(())
}

/// `label` as part of a name in a mesh file: lower case, `_` for anything but letters, digits,
/// `+` and `-` ("LUMO+1" → "lumo+1", "total electron density" → "total_electron_density").
fn file_name(label: &str) -> String {
    label
        .chars()
        .map(|c| if c.is_alphanumeric() || c == '+' || c == '-' { c.to_ascii_lowercase() } else { '_' })
        .collect()
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
    let levels = Level::pair(level.value(grid.stats.sigma), grid.kind == crate::model::grid::ValueKind::Signed);
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

#[derive(Args)]
pub struct TranslucentBench {
    /// A cube file with an orbital; the bundled demo (formaldehyde's HOMO) when omitted.
    file: Option<PathBuf>,
    #[command(flatten)]
    bench: super::BenchFrames,
    /// Write each case's last frames here (exact_N.png, weighted_N.png).
    #[arg(long)]
    images: Option<PathBuf>,
}

/// One timed case of [`bench_translucent`]: the median ms per frame, the last image and, for
/// exact order, the fragment counts.
struct Timed {
    ms: f64,
    image: image::RgbaImage,
    stats: Option<crate::gpu::oit::FragmentStats>,
}

/// `orbcloud bench surfaces`: ms per frame of 2, 4 and 16 translucent surfaces (nested ± shells
/// of an orbital) in exact order and with weighted blending, the fragment memory, and how far
/// weighted blending's image is from the exact one.
pub fn bench_translucent(args: &TranslucentBench) -> Result<()> {
    use crate::gpu::oit::Transparency;
    use crate::gpu::{FrameInput, OffscreenTarget};
    use crate::pictures::headless::draw_exact;
    use crate::scene::RenderSettings;
    use crate::scene::framing::default_camera;
    let doc = load(args.file.as_deref())?;
    let grid = doc.volumes.first().context("the file has no volume")?;
    let ctx = super::gpu(args.bench.lavapipe)?;
    let camera = default_camera(&doc);
    let mut settings = RenderSettings::default();
    settings.volume.visible = false;
    println!("adapter: {}", ctx.describe());
    println!(
        "scene: {}, grid {:?}, atoms ball and stick, {}x{}",
        doc.source, grid.dims, args.bench.size[0], args.bench.size[1]
    );
    let max = grid.stats.max_abs as f32;
    for count in [2usize, 4, 16] {
        // Nested shells of both signs, from a tenth of the largest |ψ| down to a hundredth.
        let levels = count / 2;
        let iso = IsoArgs {
            values: (0..levels).map(|k| max * 0.1 * 0.1f32.powf(k as f32 / (levels.max(2) - 1) as f32)).collect(),
            translucent: true,
            ..Default::default()
        };
        let meshes = iso.meshes(grid, &iso.base());
        let triangles: usize = meshes.iter().map(|(m, _)| m.triangle_count()).sum();
        let mut h = crate::pictures::headless::Headless::new(&ctx, &doc, None, &settings, args.bench.size)?;
        show_meshes(&ctx, h.renderer.main(), &meshes);
        let target = OffscreenTarget::new(&ctx.device, args.bench.size);
        let mut time = |transparency| -> Result<Timed> {
            h.renderer.set_transparency(transparency);
            let mut times = Vec::new();
            let mut stats = None;
            for f in 0..args.bench.frames.max(1) + 2 {
                let mut cam = camera;
                cam.orbit(0.02 * f as f32, 0.01 * f as f32);
                let t = Instant::now();
                let frame = FrameInput::single(&cam, &settings, args.bench.size);
                stats = draw_exact(&ctx, &mut h.renderer, &target.color_view, &frame);
                ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
                if f >= 2 {
                    times.push(t.elapsed().as_secs_f64() * 1e3);
                }
            }
            times.sort_by(f64::total_cmp);
            let image = target.read_rgba(&ctx.device, &ctx.queue)?;
            Ok(Timed { ms: times[times.len() / 2], image, stats })
        };
        let exact = time(Transparency::Exact)?;
        let weighted = time(Transparency::WeightedBlended)?;
        let stats = exact.stats.context("no fragment counts came back")?;
        let [w, hgt] = args.bench.size;
        let heads = w as u64 * hgt as u64 * 4;
        let (mean, covered) = image_error(&exact.image, &weighted.image, &settings.background);
        if let Some(dir) = &args.images {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
            for (name, img) in [("exact", &exact.image), ("weighted", &weighted.image)] {
                let path = dir.join(format!("{name}_{count}.png"));
                img.save(&path).with_context(|| format!("writing {}", path.display()))?;
            }
        }
        println!(
            "surfaces={count} triangles={triangles} exact_ms={:.1} weighted_ms={:.1} fragments={} bands={} deep_pixels={} \
             fragment_mib_used={:.1} fragment_mib_reserved={:.1} weighted_error_mean={mean:.2}/255 weighted_error_covered={covered:.2}/255",
            exact.ms,
            weighted.ms,
            stats.needed,
            stats.bands,
            stats.deep_pixels,
            (heads + stats.needed as u64 * crate::gpu::oit::NODE_BYTES) as f64 / (1u64 << 20) as f64,
            (heads + stats.node_bytes()) as f64 / (1u64 << 20) as f64,
        );
    }
    Ok(())
}

/// Mean |a − b| per channel (of 255) over the whole image, and over the pixels either image
/// draws something in (not the background).
pub fn image_error(a: &image::RgbaImage, b: &image::RgbaImage, background: &[f32; 3]) -> (f64, f64) {
    let srgb = |v: f32| if v <= 0.003_130_8 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
    let bg = background.map(|v| (srgb(v) * 255.0).round() as i32);
    let is_bg = |p: &image::Rgba<u8>| (0..3).all(|k| (p[k] as i32 - bg[k]).abs() <= 1);
    let (mut all, mut covered, mut n_covered) = (0u64, 0u64, 0u64);
    for (p, q) in a.pixels().zip(b.pixels()) {
        let d: u64 = (0..3).map(|k| p[k].abs_diff(q[k]) as u64).sum();
        all += d;
        if !(is_bg(p) && is_bg(q)) {
            covered += d;
            n_covered += 1;
        }
    }
    (all as f64 / (3 * a.width() * a.height()) as f64, covered as f64 / (3 * n_covered.max(1)) as f64)
}

/// A scene of several objects (a bundled demo) shown in a renderer, framed as the demo's view
/// ([`crate::sources::demo::CYCLOADDITION_VIEW`]). `--iso` values, when given, replace each object's
/// isosurface levels (drawn as its first isosurface is, told apart by colour).
pub struct SceneShown {
    renderer: Renderer,
    clouds: Vec<crate::scene::VolumeSettings>,
    color_map: Option<(crate::scene::coloring::ValueMap, String)>,
    camera: crate::scene::Camera,
    target: crate::gpu::OffscreenTarget,
}

impl SceneShown {
    pub fn new(
        ctx: &GpuContext,
        mut scene: Vec<(Document, crate::scene::ObjectState)>,
        iso: &IsoArgs,
        size: [u32; 2],
    ) -> Result<Self> {
        for (_, state) in &mut scene {
            state.quantities.iter_mut().for_each(|q| iso.apply_to(q));
        }
        let mut renderer = Renderer::new(ctx);
        let shown = crate::layers::show_scene(ctx, &mut renderer, &scene, 64)?;
        let (clouds, color_map) = (shown.clouds, shown.color_map);
        let (lo, hi) = shown.bounds.context("the scene is empty")?;
        let mut camera = crate::scene::Camera::framing(lo.as_vec3(), hi.as_vec3());
        let (yaw, pitch) = crate::sources::demo::CYCLOADDITION_VIEW;
        camera.orbit(yaw, pitch);
        let target = crate::gpu::OffscreenTarget::new(&ctx.device, size);
        Ok(Self { renderer, clouds, color_map, camera, target })
    }

    /// The picture over `background`.
    pub fn draw(&mut self, ctx: &GpuContext, background: [f32; 3]) -> Result<image::RgbaImage> {
        let (mut img, stats) = crate::pictures::headless::picture(
            ctx,
            &mut self.renderer,
            &self.target,
            &self.camera,
            background,
            &self.clouds,
        )?;
        if let Some((map, name)) = &self.color_map {
            crate::pictures::shots::value_bar(&mut img, map, name);
        }
        if let Some(s) = stats {
            eprintln!("translucent surfaces: {} fragments in {} band(s), exact order", s.needed, s.bands);
        }
        Ok(img)
    }
}
