//! `nci`: NCIPLOT's two cubes (`PREFIX-dens.cube`: 100·sign(λ₂)ρ, `PREFIX-grad.cube`: the
//! reduced density gradient s; both 100 at the points cut) of one or more files whose densities
//! add: wavefunctions, or promolecular sums of spherical atoms for any structure ([`nci_of`],
//! which the Python package's `nci` runs too).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Args;

use crate::formats::{self, cube_write};
use crate::model::nci::{self, DensitySource, NciSettings, WavefunctionDensity};
use crate::model::promolecular::Promolecule;
use crate::model::units::{ANGSTROM_PER_BOHR, BOHR_PER_ANGSTROM};
use crate::model::{Document, GridSpec, Molecule, VolumeGrid};
use crate::scene::limits::{self, within};

#[derive(Args)]
pub struct NciArgs {
    /// Files whose densities add (fragments): wavefunctions (Molden, fchk, wfn, wfx, MKL, JSON), or
    /// with --promolecular any file with atoms (XYZ, PDB, mmCIF, cube, a wavefunction's atoms).
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Sums of spherical atoms instead of the files' wavefunctions (elements H–Cm).
    #[arg(long)]
    promolecular: bool,
    /// Grid step in Å, 0.001 to 10 (default 0.1 Å, NCIPLOT's).
    #[arg(long, value_parser = within(limits::SPACING))]
    step: Option<f64>,
    /// Space around the atoms in Å, 0 to 100 (default 0.75 Å, NCIPLOT's).
    #[arg(long, value_parser = within(limits::MARGIN))]
    margin: Option<f64>,
    /// Take the grid (origin, step vectors and point counts) from this cube file, e.g. one
    /// NCIPLOT wrote, instead of building a box around the atoms.
    #[arg(long, value_name = "CUBE", conflicts_with_all = ["step", "margin"])]
    grid_like: Option<PathBuf>,
    /// Points whose density is above this (a.u.) are cut: 1e-6 to 10 (default 0.05 for
    /// wavefunctions, 0.07 promolecular).
    #[arg(long, value_parser = within(limits::DENSITY_CUT))]
    cut: Option<f64>,
    /// The -grad cube holds 100 where s is above this (default 1, NCIPLOT's RDG cutoff; 100
    /// keeps every s).
    #[arg(long, value_name = "S", value_parser = within(limits::RDG_CUT))]
    rdg_cut: Option<f64>,
    /// Keep only the points between fragments: those where no file holds more than 95 % of
    /// the density (needs two files or more).
    #[arg(long)]
    intermolecular: bool,
    /// The cubes' prefix: PREFIX-dens.cube and PREFIX-grad.cube.
    #[arg(short, long, value_name = "PREFIX")]
    output: PathBuf,
}

/// One fragment's density, kept alive beside the document it came from.
enum Fragment<'a> {
    Wavefunction(Box<WavefunctionDensity<'a>>),
    Promolecular(Promolecule),
}

impl Fragment<'_> {
    fn source(&self) -> &dyn DensitySource {
        match self {
            Fragment::Wavefunction(w) => w.as_ref(),
            Fragment::Promolecular(p) => p,
        }
    }
}

/// How NCIPLOT's grids are asked for: `nci`'s options, and the Python package's `nci(...)`.
#[derive(Debug, Clone, Default)]
pub struct NciOptions {
    /// Sums of spherical atoms instead of the documents' wavefunctions.
    pub promolecular: bool,
    /// Grid step, Å (NCIPLOT's 0.1 when `None`).
    pub step: Option<f64>,
    /// Space around the atoms, Å (NCIPLOT's 0.75 when `None`).
    pub margin: Option<f64>,
    /// This grid instead of a box around the atoms.
    pub grid: Option<GridSpec>,
    /// The density cut, a.u. (0.05 for wavefunctions, 0.07 promolecular, when `None`).
    pub cut: Option<f64>,
    /// The `-grad` grid's RDG cutoff (NCIPLOT's 1 when `None`).
    pub rdg_cut: Option<f64>,
    /// Only the points between fragments (needs two documents or more).
    pub intermolecular: bool,
}

/// NCIPLOT's grids of documents whose densities add, with the grid and the settings used and
/// every document's atoms (what the cubes' headers list).
pub struct NciResult {
    pub spec: GridSpec,
    pub grids: nci::NciGrids,
    pub settings: NciSettings,
    pub molecule: Molecule,
    /// Seconds the grids took.
    pub seconds: f64,
}

/// [`NciResult`] of `docs` (each named by `names`, for messages) as `options` ask: the grids
/// `orbcloud nci` writes as cubes.
pub fn nci_of(docs: &[&Document], names: &[String], options: &NciOptions) -> Result<NciResult> {
    let ranges = [
        ("step", options.step, &limits::SPACING),
        ("margin", options.margin, &limits::MARGIN),
        ("cut", options.cut, &limits::DENSITY_CUT),
        ("rdg_cut", options.rdg_cut, &limits::RDG_CUT),
    ];
    for (name, value, range) in ranges {
        if let Some(v) = value.filter(|v| !range.contains(v)) {
            bail!("{name} {v}: expected {} to {}", range.start(), range.end());
        }
    }
    if docs.is_empty() {
        bail!("nci needs one file or more (fragments whose densities add)");
    }
    if options.intermolecular && docs.len() < 2 {
        bail!("--intermolecular needs two files or more (the fragments), got {}", docs.len());
    }
    let mut fragments = Vec::with_capacity(docs.len());
    for (doc, name) in docs.iter().zip(names) {
        if doc.molecule.atoms.is_empty() {
            bail!("{name}: no atoms, so no density for nci");
        }
        let fragment = if options.promolecular {
            Fragment::Promolecular(Promolecule::new(&doc.molecule).map_err(|e| anyhow::anyhow!("{name}: {e}"))?)
        } else {
            match &doc.wavefunction {
                Some(wf) => Fragment::Wavefunction(Box::new(WavefunctionDensity::new(wf))),
                None => bail!(
                    "{name}: no wavefunction (Molden, fchk, wfn, wfx, MKL or JSON) for nci: --promolecular sums spherical atoms instead"
                ),
            }
        };
        fragments.push(fragment);
    }
    let atoms: Vec<_> = docs.iter().flat_map(|d| d.molecule.atoms.iter().cloned()).collect();
    let molecule = Molecule::new(atoms);
    let spec = match options.grid {
        Some(spec) => spec,
        None => {
            let (lo, hi) = molecule.bounds().context("no atoms")?;
            let step = options.step.unwrap_or(nci::NCIPLOT_STEP_ANGSTROM) * BOHR_PER_ANGSTROM;
            let margin = options.margin.unwrap_or(nci::NCIPLOT_MARGIN_ANGSTROM) * BOHR_PER_ANGSTROM;
            nci::nciplot_grid(lo, hi, margin, step)
        }
    };
    let step = spec.step(0).length();
    // Counted in floating point: far-flung atoms must not overflow the count.
    let points: f64 = spec.dims.iter().map(|&n| n as f64).product();
    if points > limits::NCI_POINTS as f64 {
        let [nx, ny, nz] = spec.dims;
        bail!(
            "a {nx}×{ny}×{nz} grid ({points:.3e} points) is more than nci holds ({}): a larger --step (now {:.4} Å) or a smaller --margin makes it fit",
            limits::NCI_POINTS,
            step * ANGSTROM_PER_BOHR
        );
    }
    let settings = NciSettings {
        density_cut: options.cut.unwrap_or(if options.promolecular {
            nci::PROMOLECULAR_DENSITY_CUT
        } else {
            nci::WAVEFUNCTION_DENSITY_CUT
        }),
        rdg_cut: options.rdg_cut.unwrap_or(nci::NCIPLOT_RDG_CUT),
        intermolecular: options.intermolecular.then_some(nci::INTERMOLECULAR_SHARE),
    };
    let sources: Vec<&dyn DensitySource> = fragments.iter().map(Fragment::source).collect();
    let start = Instant::now();
    let grids = nci::nci_grid(&sources, &spec, settings);
    Ok(NciResult { spec, grids, settings, molecule, seconds: start.elapsed().as_secs_f64() })
}

pub fn nci(args: &NciArgs) -> Result<()> {
    if args.intermolecular && args.files.len() < 2 {
        bail!("--intermolecular needs two files or more (the fragments), got {}", args.files.len());
    }
    let docs: Vec<Document> = args.files.iter().map(|f| formats::load(f)).collect::<Result<_, _>>()?;
    let names: Vec<String> = args.files.iter().map(|f| f.display().to_string()).collect();
    let options = NciOptions {
        promolecular: args.promolecular,
        step: args.step,
        margin: args.margin,
        grid: args.grid_like.as_deref().map(grid_of).transpose()?,
        cut: args.cut,
        rdg_cut: args.rdg_cut,
        intermolecular: args.intermolecular,
    };
    let NciResult { spec, grids, settings, molecule, seconds } =
        nci_of(&docs.iter().collect::<Vec<_>>(), &names, &options)?;
    let step = spec.step(0).length();
    let kind = if args.promolecular { "promolecular" } else { "wavefunction" };
    let dens_path = with_suffix(&args.output, "-dens.cube");
    let grad_path = with_suffix(&args.output, "-grad.cube");
    for (path, values, what) in
        [(&dens_path, &grids.dens, "100*sign(lambda2)*rho"), (&grad_path, &grids.grad, "reduced density gradient")]
    {
        let title = format!("orbcloud nci ({kind}) {}", names.join(" + "));
        let file = std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
        // Smaller than the writer's blocks, which then go to the file without a copy.
        let mut w = std::io::BufWriter::with_capacity(cube_write::BLOCK / 4, file);
        cube_write::write_values_to(&mut w, &title, what, &molecule, &spec, &[(values, 0)])
            .with_context(|| format!("writing {}", path.display()))?;
        use std::io::Write;
        w.flush().with_context(|| format!("writing {}", path.display()))?;
    }
    let [nx, ny, nz] = spec.dims;
    eprintln!(
        "wrote {} and {} ({nx}×{ny}×{nz}, step {:.4} bohr, {kind} density of {} atoms; {} points below ρ = {}{}; evaluated in {seconds:.3} s)",
        dens_path.display(),
        grad_path.display(),
        step,
        molecule.atoms.len(),
        grids.kept,
        settings.density_cut,
        if args.intermolecular { ", between fragments" } else { "" },
    );
    Ok(())
}

/// The grid of the first volume of the cube file `path`.
fn grid_of(path: &Path) -> Result<GridSpec> {
    let doc = formats::load(path).with_context(|| format!("reading the grid of {}", path.display()))?;
    let grid = doc.volumes.first().with_context(|| format!("{}: no grid in it", path.display()))?;
    Ok(GridSpec { dims: grid.dims, world_from_grid: grid.world_from_grid })
}

/// `prefix` with `suffix` appended to its file name (`out/dimer` → `out/dimer-dens.cube`).
fn with_suffix(prefix: &Path, suffix: &str) -> PathBuf {
    let mut name = prefix.as_os_str().to_owned();
    name.push(suffix);
    PathBuf::from(name)
}

#[derive(Args)]
pub struct NciBench {
    /// A wavefunction (Molden, fchk, wfn, wfx, MKL, JSON).
    file: PathBuf,
    /// Points per side of the grid: the viewer's box for the NCI field.
    #[arg(long, default_value_t = 80, value_parser = within(limits::GRID_POINTS))]
    points: usize,
    #[command(flatten)]
    bench: super::BenchRuns,
}

/// `orbcloud bench nci`: the viewer's NCI field (s where ρ ≤ 0.05) of a wavefunction on its
/// grid, by the CPU reference (every thread) and by the GPU pass of the density's derivatives
/// (the pass, then the quantity finished on the CPU), with the largest difference of the two.
pub fn bench(args: &NciBench) -> Result<()> {
    use crate::gpu::density_hessian::DensityHessianPass;
    use crate::model::gto::PreparedBasis;
    use crate::model::orbitals::Quantity;

    let doc = super::load(Some(&args.file))?;
    let wf = super::wavefunction_of(&doc)?;
    let quantity = Quantity::NciGradient;
    let grid = crate::evaluate::orbital_geometry(&doc, quantity, args.points).context("the file has no grid box")?;
    let ctx = super::gpu(args.bench.lavapipe)?;
    println!("adapter: {}", ctx.describe());
    println!("{}: grid {:?} = {} points, {} threads", doc.source, grid.dims, grid.len(), rayon::current_num_threads());
    let best = |times: &[f64]| times.iter().copied().fold(f64::INFINITY, f64::min);

    let (mut cpu_ms, mut cpu) = (Vec::new(), Vec::new());
    for _ in 0..args.bench.runs {
        let t = Instant::now();
        cpu = PreparedBasis::new(&wf.basis).quantity_grid_f32(wf, &doc.molecule, quantity, &grid);
        cpu_ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let t = Instant::now();
    let pass = DensityHessianPass::new(&ctx);
    let pipeline_ms = t.elapsed().as_secs_f64() * 1e3;
    let (mut pass_ms, mut finish_ms, mut gpu) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..args.bench.runs {
        let t = Instant::now();
        let density = WavefunctionDensity::new(wf).cartesian();
        let derivatives = pass.derivatives(&ctx, &density, &grid)?;
        pass_ms.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        gpu = nci::quantity_of_single(&derivatives, quantity);
        finish_ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let kept = |v: &f32| *v < nci::CUT_VALUE;
    let worst =
        cpu.iter().zip(&gpu).filter(|(c, _)| kept(c)).map(|(c, g)| (c - g).abs() / c.max(1e-3)).fold(0.0f32, f32::max);
    let differ = cpu.iter().zip(&gpu).filter(|(c, g)| kept(c) != kept(g)).count();
    let gpu_ms: Vec<f64> = pass_ms.iter().zip(&finish_ms).map(|(a, b)| a + b).collect();
    println!(
        "cpu_ms={:.1} gpu_ms={:.1} (pass {:.1}, finish {:.1}; pipeline built once in {pipeline_ms:.1}) runs={}",
        best(&cpu_ms),
        best(&gpu_ms),
        best(&pass_ms),
        best(&finish_ms),
        args.bench.runs
    );
    println!(
        "kept points: {}; worst relative difference of s there {worst:.2e}; points cut by one and not the other: {differ}",
        cpu.iter().filter(|v| kept(v)).count()
    );
    // What the window does when the isovalue moves: the surface cut again from the field it
    // keeps, then coloured by sign(λ₂)ρ evaluated at its vertices.
    let field = VolumeGrid::new("s", grid.dims, grid.world_from_grid, cpu);
    let levels = crate::scene::QuantityState::nci_surface(&Default::default()).isosurfaces;
    let mut iso_ms = Vec::new();
    let mut vertices = 0;
    for _ in 0..args.bench.runs {
        let t = Instant::now();
        let (mut meshes, _) = crate::evaluate::meshes::isosurfaces_within(&field, &levels, u64::MAX);
        crate::evaluate::meshes::color_isosurfaces(
            crate::evaluate::meshes::Evaluating::alone(&doc),
            &levels,
            false,
            &mut meshes,
        );
        iso_ms.push(t.elapsed().as_secs_f64() * 1e3);
        vertices = meshes.iter().map(|(m, _)| m.positions.len()).sum::<usize>();
    }
    println!(
        "isovalue change (surface s = {} cut and coloured, {vertices} vertices): {:.1} ms",
        crate::scene::quantity::NCI_LEVEL,
        best(&iso_ms)
    );
    Ok(())
}
