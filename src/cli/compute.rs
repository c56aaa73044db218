//! `orbcloud compute` and `orbcloud scan compute`: wavefunctions computed with PySCF
//! ([`crate::sources::compute`]), written as Molden files, and a scan's manifest.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use crate::formats::scan::Computed;
use crate::model::Document;
use crate::model::scan::{Coordinate, PathMeasure};
use crate::sources::compute::{self, Event, FrameJob, Held, Job, Settings};
use anyhow::{Context, Result, bail};
use clap::Args;

use super::scan::CoordinateArgs;

/// How to compute: method, basis, charge and spin.
#[derive(Args, Clone)]
pub struct LevelArgs {
    /// HF or any functional PySCF knows (b3lyp, pbe0, wb97x-d, …).
    #[arg(long, default_value = "b3lyp")]
    method: String,
    /// A basis set by name (sto-3g, 6-31g*, def2-svp, cc-pvdz, …).
    #[arg(long, default_value = "6-31g*")]
    basis: String,
    #[arg(long, default_value_t = 0, allow_hyphen_values = true)]
    charge: i32,
    /// 2S, the number of unpaired electrons; open shells are unrestricted.
    #[arg(long, default_value_t = 0)]
    spin: u32,
    /// SCF cycles before a frame counts as not converged.
    #[arg(long, default_value_t = 100)]
    max_cycles: u32,
    /// Compute on a CUDA GPU with gpu4pyscf.
    #[arg(long)]
    gpu: bool,
}

impl LevelArgs {
    fn settings(&self) -> Settings {
        Settings {
            method: self.method.clone(),
            basis: self.basis.clone(),
            charge: self.charge,
            spin: self.spin,
            max_cycles: self.max_cycles,
            gpu: self.gpu,
            ..Settings::default()
        }
    }
}

/// `orbcloud compute FILE`.
#[derive(Args)]
pub struct ComputeArgs {
    /// A geometry: XYZ, PDB, mmCIF, or any file orbcloud reads.
    file: PathBuf,
    #[command(flatten)]
    level: LevelArgs,
    /// Add the Hessian's normal modes (vibrations; small molecules: minutes for 20 atoms).
    #[arg(long)]
    freq: bool,
    /// Compute as a task of this Dask scheduler (tcp://host:port).
    #[arg(long)]
    dask: Option<String>,
    /// The Molden file to write (default: beside the input, `.molden`).
    #[arg(short, long)]
    output: Option<PathBuf>,
}

/// `orbcloud scan compute FILE`.
#[derive(Args)]
pub struct ScanComputeArgs {
    /// The geometry to start from (any file orbcloud reads), or with --frames a multi-frame
    /// XYZ file whose every frame is computed, or a scan job's log (a Gaussian or ORCA relaxed
    /// scan), its frames computed at the values of the coordinate it scanned.
    file: PathBuf,
    #[command(flatten)]
    coordinate: CoordinateArgs,
    /// Every frame of FILE: a scan job's at its coordinate's values, any other's (a trajectory,
    /// an IRC) as a path.
    #[arg(long, group = "coordinate")]
    frames: bool,
    /// The first value (Å or degrees).
    #[arg(long, allow_hyphen_values = true)]
    from: Option<f64>,
    /// The last value.
    #[arg(long, allow_hyphen_values = true)]
    to: Option<f64>,
    /// The step between values.
    #[arg(long)]
    step: Option<f64>,
    /// At each value a constrained optimisation (geomeTRIC), the coordinate held.
    #[arg(long)]
    relaxed: bool,
    #[command(flatten)]
    level: LevelArgs,
    /// Cores to compute on (default: all): frames in as many processes, one core each (a
    /// relaxed scan's two chains share them as threads).
    #[arg(long)]
    workers: Option<usize>,
    /// Send the frames as tasks to this Dask scheduler (tcp://host:port).
    #[arg(long)]
    dask: Option<String>,
    /// The directory the frames and the manifest go to.
    #[arg(short, long)]
    output: PathBuf,
}

fn load(path: &Path) -> Result<Document> {
    let doc = crate::formats::load(path)?;
    if doc.molecule.atoms.iter().any(|a| a.z == 0) {
        bail!("{}: dummy atoms or unknown elements cannot be computed", path.display());
    }
    Ok(doc)
}

/// Runs a job, printing each frame as it ends; Ctrl-C ends it (frames written so far stay).
fn run(job: &Job) -> Result<(Vec<compute::FrameReport>, std::collections::BTreeMap<String, String>)> {
    let cancel = AtomicBool::new(false);
    let mut versions = Default::default();
    let total = job.frames.len();
    let reports = compute::run(job, &cancel, &mut |event| match event {
        Event::Start { frames, kept, versions: v } => {
            versions = v.clone();
            let level = job.settings.level();
            let place = job.dask.as_deref().map_or_else(
                || format!("{} local core{}", job.workers, plural(job.workers)),
                |a| format!("the Dask scheduler at {a}"),
            );
            eprintln!("{level}, {frames} frame{}, {kept} kept from an earlier run, on {place}", plural(*frames));
        }
        Event::Frame(r) if r.ok => eprintln!(
            "{:>3}/{total}  {:>10}  {}  E = {:.8} Eh  {:>3} SCF cycles  {:.2} s{}",
            r.index + 1,
            format!("{:.3}", r.at),
            r.file,
            r.energy.unwrap_or(f64::NAN),
            r.cycles.unwrap_or(0),
            r.seconds,
            if r.kept { "  (kept)" } else { "" }
        ),
        Event::Frame(r) => eprintln!(
            "{:>3}/{total}  {:>10}  failed: {}",
            r.index + 1,
            format!("{:.3}", r.at),
            r.error.as_deref().unwrap_or("?")
        ),
        Event::Done { computed, kept, failed } => {
            eprintln!("{computed} computed, {kept} kept, {failed} failed");
        }
        Event::Error { .. } => {}
    })?;
    Ok((reports, versions))
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

pub fn compute(args: ComputeArgs) -> Result<()> {
    let doc = load(&args.file)?;
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| args.file.with_file_name(format!("{}.molden", compute::stem(&args.file))));
    let dir = output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")).to_path_buf();
    let file = output.file_name().context("-o names no file")?.to_string_lossy().into_owned();
    let job = Job {
        settings: Settings { freq: args.freq, ..args.level.settings() },
        coordinate: None,
        start: 0,
        dir,
        output: None,
        // Every core, as threads of the one process.
        workers: compute::cores(),
        dask: args.dask.clone(),
        frames: vec![FrameJob::new(file, 0.0, &doc.molecule)],
    };
    let (reports, _) = run(&job)?;
    match reports.last() {
        Some(r) if r.ok => {
            println!("{}", output.display());
            Ok(())
        }
        Some(r) => bail!("{}: {}", args.file.display(), r.error.as_deref().unwrap_or("failed")),
        None => bail!("{}: the computation ended without a result", args.file.display()),
    }
}

/// The frames a scan computes, in order of value, and the index of the one nearest the input
/// geometry.
fn scan_frames(args: &ScanComputeArgs, doc: &Document) -> Result<(Coordinate, Vec<FrameJob>, usize)> {
    let stem = compute::stem(&args.file);
    if args.frames {
        if args.relaxed {
            bail!("--relaxed holds a coordinate: give --distance, --angle or --dihedral, not --frames");
        }
        // A scan job's frames (a Gaussian or ORCA relaxed scan's log) keep the coordinate it scanned.
        if let Some(job) = compute::job_scan_frames(doc, &stem) {
            let (c, frames) = job.map_err(anyhow::Error::msg)?;
            return Ok((c, frames, 0));
        }
        let models = compute::frame_molecules(doc);
        if models.len() < 2 {
            bail!(
                "{}: --frames needs a file of several geometries (a multi-frame XYZ), found {}",
                args.file.display(),
                models.len()
            );
        }
        // Files named by frame number, frames placed by the length travelled along the path.
        let c = Coordinate::Path(PathMeasure::ArcLength);
        let lengths = crate::model::scan::path_values(&models, PathMeasure::ArcLength);
        let frames = (models.iter().zip(lengths).enumerate())
            .map(|(i, (m, at))| FrameJob::new(compute::frame_file(&stem, &c, i as f64), at, m))
            .collect();
        return Ok((c, frames, 0));
    }
    let coordinate = (args.coordinate.coordinate())
        .context("say what to scan: --distance i,j, --angle i,j,k, --dihedral i,j,k,l, or --frames")?;
    let n = doc.molecule.atoms.len();
    if let Some(&bad) = coordinate.atoms().iter().find(|&&i| i >= n) {
        bail!("{}: atom {} of --{}: the molecule has {n} atoms", args.file.display(), bad + 1, coordinate.kind());
    }
    let (Some(from), Some(to), Some(step)) = (args.from, args.to, args.step) else {
        bail!("--from, --to and --step give the values to compute ({})", coordinate.unit().trim());
    };
    let values = compute::values(from, to, step).map_err(anyhow::Error::msg)?;
    if matches!(coordinate, Coordinate::Distance(_)) && values.iter().any(|&v| v <= 0.1) {
        bail!("--from {from} --to {to}: distances above 0.1 Å");
    }
    if matches!(coordinate, Coordinate::Angle(_)) && values.iter().any(|&v| !(0.5..=179.5).contains(&v)) {
        bail!("--from {from} --to {to}: angles between 0.5° and 179.5°");
    }
    let (frames, start) = compute::rigid_scan(&doc.molecule, &coordinate, &values, &stem)?;
    Ok((coordinate, frames, start))
}

pub fn scan_compute(args: ScanComputeArgs) -> Result<()> {
    let doc = load(&args.file)?;
    let (coordinate, frames, start) = scan_frames(&args, &doc)?;
    let workers = args.workers.unwrap_or_else(compute::cores).clamp(1, frames.len().max(1));
    let settings = Settings { relaxed: args.relaxed, ..args.level.settings() };
    let job = Job {
        settings: settings.clone(),
        coordinate: Held::of(&coordinate),
        start,
        dir: args.output.clone(),
        output: Some(args.output.join("compute-output.txt")),
        workers,
        dask: args.dask.clone(),
        frames,
    };
    let (reports, versions) = run(&job)?;
    let done: Vec<(String, f64)> = reports.iter().filter(|r| r.ok).map(|r| (r.file.clone(), r.at)).collect();
    let failed: Vec<f64> = reports.iter().filter(|r| !r.ok).map(|r| r.at).collect();
    for r in reports.iter().filter(|r| !r.ok) {
        eprintln!("frame at {} left out: {}", coordinate.value_text(r.at), r.error.as_deref().unwrap_or("failed"));
    }
    if done.len() < 2 {
        bail!("{} of {} frames computed: a scan needs two", done.len(), job.frames.len());
    }
    // A relaxed scan job's frames are relaxed geometries, though each is computed as a single
    // point here: the record says what the frames are.
    let settings = Settings { relaxed: settings.relaxed || (args.frames && doc.job_scan.is_some()), ..settings };
    let computed = Computed::of(&settings, &args.file.display().to_string(), versions, failed);
    let title = compute::stem(&args.file);
    let path = compute::write_manifest(&args.output, &title, &coordinate, &settings, &done, computed)?;
    println!("{}", path.display());
    Ok(())
}
