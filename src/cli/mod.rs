//! The orbcloud command line as a library: the arguments (clap), each command's body in a module
//! of its own, and [`run_words`] that runs a line. `main.rs` calls it; the Python package runs
//! `render`'s options and `compute` through it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::evaluate::{Values, WavefunctionView};
use crate::formats;
use crate::gpu::{AdapterPreference, GpuContext};
use crate::layers::show_wavefunction;
use crate::model::Document;
use crate::model::orbitals::{OrbitalSpec, Quantity, Spin, Wavefunction};
use crate::pictures::headless::Headless;
use crate::scene::framing::camera_for;
use crate::scene::limits::{self, within};
use crate::scene::transfer::PRESETS;
use crate::scene::{
    AtomColoring, AtomStyle, Camera, ClipPlane, RenderSettings, Shape, SliceMode, TransferKind, ViewPreset,
};
use crate::sources::demo;
use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand, ValueEnum};

mod bench_orbital;
mod bench_scene;
mod compute;
pub mod info;
mod modes;
mod molsurface;
mod movie;
mod nci;
mod plane;
mod quantities;
mod render;
mod scan;
mod structure;
mod surface;
mod values;

/// The viewer's files argument: every format ([`formats::FORMATS`]) and scan manifests.
fn files_help(lead: &str) -> String {
    format!("{lead}: {}, or a scan manifest (.scan.toml); the bundled demo when none", formats::described())
}

#[derive(Parser)]
#[command(name = "orbcloud", version, about = "Molecular orbitals and densities as GPU-rendered clouds")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[arg(help = files_help("Files to open in the viewer"))]
    files: Vec<PathBuf>,
    /// Open a bundled demo instead of files.
    #[arg(long, value_enum)]
    demo: Option<DemoArg>,
}

#[derive(Clone, Copy, ValueEnum)]
enum DemoArg {
    /// The PSB3 twist scan (what opens with no file).
    Scan,
    /// Formaldehyde's HOMO as a cube.
    Cube,
    /// Butadiene's HOMO meeting SO₂'s LUMO, translucent and glowing where they overlap.
    Cycloaddition,
}

impl DemoArg {
    fn demo(self) -> crate::app::Demo {
        match self {
            DemoArg::Scan => crate::app::Demo::Scan,
            DemoArg::Cube => crate::app::Demo::Cube,
            DemoArg::Cycloaddition => crate::app::Demo::Cycloaddition,
        }
    }
}

// Parsed once per process: boxing the larger variants would save nothing worth the noise.
#[allow(clippy::large_enum_variant, reason = "parsed once per process")]
#[derive(Subcommand)]
enum Command {
    /// Open the interactive viewer (the default).
    Viewer {
        #[arg(help = files_help("Files to open"))]
        files: Vec<PathBuf>,
        /// Open a bundled demo instead of files.
        #[arg(long, value_enum)]
        demo: Option<DemoArg>,
    },
    /// Render a file to a PNG without a window.
    Render(RenderArgs),
    /// Print atoms and grids of a file.
    Info {
        #[arg(help = formats::described())]
        file: PathBuf,
        /// Machine-readable JSON instead of text.
        #[arg(long)]
        json: bool,
        /// A TD log whose printed transitions join the file's states (the same molecule, in any
        /// orientation): each state's natural transition orbitals' weights, and how far its
        /// electron moves (the hole's and electron's centroid distance D and their overlap Sr).
        #[arg(long, value_name = "LOG")]
        transitions: Option<PathBuf>,
    },
    /// Evaluate an orbital or the density at points (bohr in, `x y z value` out). Several files
    /// are fragments whose densities add: --density, --rdg, --sign-lambda2-rho and --laplacian
    /// of the sum (as `nci` computes them).
    Eval {
        #[arg(required = true)]
        files: Vec<PathBuf>,
        #[command(flatten)]
        what: WhatArgs,
        /// File of points, one `x y z` (bohr) per line; `-` reads standard input.
        #[arg(long)]
        points: PathBuf,
        /// Subtract the same quantity of another file (two states, two methods, a complex
        /// minus a part): its wavefunction's, or its first data set's, resampled trilinearly.
        #[arg(long, value_name = "FILE")]
        minus: Option<PathBuf>,
    },
    /// Write an orbital or the density on a grid as a Gaussian cube file (like cubegen).
    Cube {
        file: PathBuf,
        #[command(flatten)]
        what: WhatArgs,
        /// Points per axis, 8 to 512 (ignored with --spacing).
        #[arg(long, default_value_t = 80, value_parser = within(limits::GRID_POINTS))]
        grid: usize,
        /// Grid spacing in bohr (same on every axis), 0.001 to 10.
        #[arg(long, value_parser = within(limits::SPACING))]
        spacing: Option<f64>,
        /// Space around the atoms, bohr, 0 to 100 (default: the box where the orbital decays to
        /// 1 % of its largest value, a density to 1e-4 a.u.).
        #[arg(long, value_parser = within(limits::MARGIN))]
        margin: Option<f64>,
        /// Subtract the same quantity of another file on this grid: its wavefunction's, or its
        /// first data set's, resampled trilinearly (refused when the grids do not overlap).
        #[arg(long, value_name = "FILE")]
        minus: Option<PathBuf>,
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Map a quantity on a plane through the molecule (exact from the wavefunction) with
    /// contour lines, as a PNG or SVG figure and, on request, its numbers as CSV.
    Plane(Box<plane::PlaneArgs>),
    /// Non-covalent interactions as NCIPLOT writes them: PREFIX-dens.cube (100·sign(λ₂)ρ) and
    /// PREFIX-grad.cube (the reduced density gradient) of files whose densities add.
    Nci(nci::NciArgs),
    /// Write isosurfaces (both signs of an orbital, or a density's) or a molecular surface
    /// (--surface) as OBJ, PLY or glTF.
    Mesh(surface::MeshArgs),
    /// Write one period of a normal mode as a multi-frame XYZ file (Å).
    Modes(modes::ModesArgs),
    /// A movie: a scan's coordinate swept, a file or session turning (--turntable), or a
    /// vibration (--normal-mode K), as PNG frames, GIF, animated PNG, MP4 or WebM.
    Movie(Box<movie::MovieArgs>),
    /// Compute a wavefunction with PySCF (HF or DFT) and write it as a Molden file, with the
    /// normal modes on request (--freq).
    Compute(compute::ComputeArgs),
    /// Scans of a distance, an angle, a dihedral or a path: compute one with PySCF, make a
    /// manifest from files, inspect, render or export a value.
    #[command(subcommand)]
    Scan(scan::ScanCommand),
    /// Print performance figures.
    #[command(subcommand)]
    Bench(BenchCommand),
}

#[derive(Args, Clone)]
struct WhatArgs {
    /// homo, lumo, homo-N, lumo+N, or a 1-based orbital number of the chosen spin.
    #[arg(long, default_value = "homo", allow_hyphen_values = true)]
    orbital: OrbitalSpec,
    /// Spin of the orbital (unrestricted wavefunctions).
    #[arg(long, value_enum, default_value_t = SpinArg::Alpha)]
    spin: SpinArg,
    /// The total electron density instead of an orbital.
    #[arg(long, conflicts_with = "spin_density")]
    density: bool,
    /// The spin density (α − β) instead of an orbital.
    #[arg(long)]
    spin_density: bool,
    /// The electrostatic potential of the nuclei and electrons (a.u.) instead of an orbital.
    #[arg(long, conflicts_with_all = ["density", "spin_density", "basis_function"])]
    esp: bool,
    /// The reduced density gradient s = |∇ρ| / (2(3π²)^{1/3} ρ^{4/3}) instead of an orbital.
    #[arg(long, conflicts_with_all = ["density", "spin_density", "esp", "basis_function", "sign_lambda2_rho", "laplacian"])]
    rdg: bool,
    /// sign(λ₂)·ρ (λ₂ the middle eigenvalue of the density's Hessian, a.u.) instead of an orbital.
    #[arg(long, conflicts_with_all = ["density", "spin_density", "esp", "basis_function", "laplacian"])]
    sign_lambda2_rho: bool,
    /// The Laplacian of the total density ∇²ρ (a.u.) instead of an orbital.
    #[arg(long, conflicts_with_all = ["density", "spin_density", "esp", "basis_function"])]
    laplacian: bool,
    /// A bare basis function (atomic orbital) instead of an orbital, named as the viewer's
    /// atomic-orbital selector names it: "C3 2pz", "O1 3dz2", "O1 3dxy", "H2 3dxx".
    #[arg(long, conflicts_with_all = ["density", "spin_density"])]
    basis_function: Option<String>,
    /// The difference density ρ_exc − ρ_gs of the file's excited state (a Gaussian TD fchk).
    #[arg(long, conflicts_with_all = &EXCITED_CONFLICTS[..7])]
    difference_density: bool,
    /// The attachment density of the file's excited state: where the excitation's electrons go
    /// (the positive eigenvalues of the difference density matrix, Head-Gordon 1995).
    #[arg(long, conflicts_with_all = &EXCITED_CONFLICTS[..8])]
    attachment: bool,
    /// The detachment density: where the excitation's electrons come from.
    #[arg(long, conflicts_with_all = &EXCITED_CONFLICTS[..9])]
    detachment: bool,
    /// The excited state's own density.
    #[arg(long, conflicts_with_all = &EXCITED_CONFLICTS[..10])]
    excited_density: bool,
    /// State N's transition density (--state N) from the amplitudes the file lists: where the
    /// density oscillates as light drives the transition (signed, like an orbital). Needs the
    /// orbitals and the printed transitions together (a log with both, or PySCF's).
    #[arg(long, requires = "state", conflicts_with_all = &EXCITED_CONFLICTS[..11])]
    transition_density: bool,
    /// A TD log whose printed transitions join the file (its checkpoint, the same molecule in
    /// any orientation): what --transition-density and --orbital "hole N" read.
    #[arg(long, value_name = "LOG", requires = "state")]
    transitions: Option<PathBuf>,
    /// The excited state (numbered as the program numbers them) whose density the options
    /// above show; a Gaussian TD fchk holds one state's density, and another is refused.
    #[arg(long, value_name = "N", value_parser = within(1..=100_000usize))]
    state: Option<usize>,
}

/// What an excited state's densities exclude: every other quantity. Each of the five conflicts
/// with what comes before its own name (clap makes conflicts mutual, and refuses an option that
/// conflicts with itself), so they take the first 7, 8, 9, 10 and 11 names.
const EXCITED_CONFLICTS: [&str; 11] = [
    "density",
    "spin_density",
    "esp",
    "rdg",
    "sign_lambda2_rho",
    "laplacian",
    "basis_function",
    "difference_density",
    "attachment",
    "detachment",
    "excited_density",
];

/// What `render --nci` excludes: the other quantities, and the isosurface and colouring options
/// its surface sets itself.
const NCI_CONFLICTS: [&str; 15] = [
    "density",
    "spin_density",
    "esp",
    "rdg",
    "sign_lambda2_rho",
    "laplacian",
    "basis_function",
    "difference_density",
    "attachment",
    "detachment",
    "excited_density",
    "values",
    "sigmas",
    "color_by",
    "demo",
];

#[derive(Clone, Copy, ValueEnum)]
enum SpinArg {
    Alpha,
    Beta,
}

/// How `render` and `bench` show a wavefunction (Molden, fchk).
#[derive(Args)]
struct WavefunctionArgs {
    #[command(flatten)]
    what: WhatArgs,
    /// Evaluate the orbital per slice sample from the basis functions (direct mode)
    /// instead of on a GPU-filled grid.
    #[arg(long)]
    direct: bool,
    /// Points per axis of the grid orbitals are evaluated on, 8 to 512.
    #[arg(long, default_value_t = 72, value_parser = within(limits::GRID_POINTS))]
    grid_points: usize,
}

impl WavefunctionArgs {
    /// Puts the requested quantity into the headless renderer, when the document has a
    /// wavefunction; returns how long that took (GPU fill and read-back included) and the values
    /// behind it. In direct mode a grid is filled only when `grid` says its values are wanted.
    fn apply(&self, ctx: &GpuContext, h: &mut Headless, doc: &Document, grid: bool) -> Result<Option<(f64, Values)>> {
        if doc.wavefunction.is_none() {
            // A quantity only a wavefunction has, asked of atoms alone, is an error, not a
            // picture of the atoms.
            let w = &self.what;
            let asked = [
                (w.density, "--density"),
                (w.spin_density, "--spin-density"),
                (w.esp, "--esp"),
                (w.rdg, "--rdg"),
                (w.sign_lambda2_rho, "--sign-lambda2-rho"),
                (w.laplacian, "--laplacian"),
                (w.difference_density, "--difference-density"),
                (w.attachment, "--attachment"),
                (w.detachment, "--detachment"),
                (w.excited_density, "--excited-density"),
            ]
            .into_iter()
            .find(|(on, _)| *on)
            .map(|(_, flag)| flag)
            .or(w.basis_function.as_ref().map(|_| "--basis-function"));
            if let Some((_, flag)) = w.state_quantity() {
                return Err(no_state_density(doc, flag));
            }
            if let Some(flag) = asked {
                bail!(
                    "{}: {flag} needs a wavefunction (Molden, fchk, wfn, wfx, MKL or JSON), and this file has none: `orbcloud compute {}` computes one with PySCF",
                    doc.source,
                    doc.source
                );
            }
            return Ok(None);
        }
        let start = Instant::now();
        let view = WavefunctionView {
            quantity: self.what.resolve(doc)?,
            direct: self.direct,
            points: self.grid_points,
            functions: None,
            grid,
        };
        let mut fill = None;
        let values = show_wavefunction(ctx, h.renderer.main(), &mut fill, doc, &view)?;
        Ok(values.map(|v| (start.elapsed().as_secs_f64(), v)))
    }
}

impl WhatArgs {
    /// `file`, with the TD log `--transitions` names joined to it; for `--orbital "hole N"` or
    /// `"particle N"`, `--state`'s natural transition orbitals as a document of their own.
    fn load(&self, file: &std::path::Path) -> Result<Document> {
        let mut doc = formats::load(file)?;
        if let Some(log) = &self.transitions {
            doc.join(formats::load(log)?).map_err(anyhow::Error::msg)?;
        }
        if matches!(self.orbital, OrbitalSpec::Hole(_) | OrbitalSpec::Particle(_)) {
            let n = self.state.with_context(|| {
                format!(
                    "--orbital {:?} is a natural transition orbital: --state N names the state",
                    self.orbital.to_string()
                )
            })?;
            let state = (doc.excited.as_ref().and_then(|e| e.states.iter().find(|s| s.number == n)))
                .with_context(|| format!("{}: no excited state {n} is listed", doc.source))?;
            let ntos = (doc.wavefunction.as_ref().and_then(|wf| crate::model::nto::from_transitions(wf, state)))
                .with_context(|| format!("{}: state {n} prints no transition between orbitals the file has (a TD log joins its checkpoint with --transitions)", doc.source))?;
            doc = ntos.document(&doc).context("no wavefunction")?;
        }
        Ok(doc)
    }

    /// Whether `--state` names the state of a natural transition orbital (`--orbital hole N`).
    fn names_nto(&self) -> bool {
        matches!(self.orbital, OrbitalSpec::Hole(_) | OrbitalSpec::Particle(_))
    }

    /// The excited-state quantity asked for, with its option's name.
    fn state_quantity(&self) -> Option<(Quantity, &'static str)> {
        [
            (self.difference_density, Quantity::DifferenceDensity, "--difference-density"),
            (self.attachment, Quantity::Attachment, "--attachment"),
            (self.detachment, Quantity::Detachment, "--detachment"),
            (self.excited_density, Quantity::ExcitedDensity, "--excited-density"),
        ]
        .into_iter()
        .find(|(on, ..)| *on)
        .map(|(_, q, flag)| (q, flag))
    }

    fn resolve(&self, doc: &Document) -> Result<Quantity> {
        if self.transition_density {
            let n = self.state.context("--transition-density needs --state N")?;
            return match crate::model::transition::TransitionDensity::of_state(doc, n) {
                Some(_) => Ok(Quantity::TransitionDensity(n)),
                None => bail!("{}", crate::model::transition::why_none(doc, n)),
            };
        }
        if let Some((quantity, flag)) = self.state_quantity() {
            let excited = doc.wavefunction.as_ref().and_then(|wf| wf.excited.as_ref());
            let Some(excited) = excited else { return Err(no_state_density(doc, flag)) };
            if let Some(n) = self.state
                && n != excited.state
            {
                bail!(
                    "{}: --state {n}: the file holds the density of state {} only (a Gaussian TD fchk keeps the state its job chose with root=)",
                    doc.source,
                    excited.state
                );
            }
            return Ok(quantity);
        }
        let wf = wavefunction_of(doc)?;
        if let Some(n) = self.state.filter(|_| !self.names_nto()) {
            bail!(
                "--state {n} picks the excited state of --difference-density, --attachment, --detachment, --excited-density or --transition-density; none is asked for"
            );
        }
        if let Some(name) = &self.basis_function {
            return crate::model::basis_labels::find_function(&doc.molecule, &wf.basis, name)
                .map(Quantity::BasisFunction)
                .ok_or_else(|| {
                    anyhow::anyhow!("no basis function {name:?} in this file (names look like \"C3 2pz\")")
                });
        }
        if self.density {
            return Ok(Quantity::Density);
        }
        if self.rdg {
            return Ok(Quantity::ReducedGradient);
        }
        if self.sign_lambda2_rho {
            return Ok(Quantity::SignLambda2Rho);
        }
        if self.laplacian {
            return Ok(Quantity::DensityLaplacian);
        }
        if self.esp {
            return Ok(Quantity::Potential);
        }
        if self.spin_density {
            return Ok(Quantity::SpinDensity);
        }
        let spin = match self.spin {
            SpinArg::Alpha => Spin::Alpha,
            SpinArg::Beta => Spin::Beta,
        };
        wf.resolve(self.orbital, spin)
            .map(Quantity::Orbital)
            .ok_or_else(|| anyhow::anyhow!("--orbital {}: {}", self.orbital, wf.available(spin)))
    }

    /// A short name for what is asked for: `homo`, `lumo+1`, `mo12_beta`, `density`, `ao_C3_2pz`.
    fn short_name(&self) -> String {
        if let Some(name) = &self.basis_function {
            let name: String = name.split_whitespace().collect::<Vec<_>>().join("_");
            return format!("ao_{name}");
        }
        if self.density {
            return "density".into();
        }
        if let (true, Some(n)) = (self.transition_density, self.state) {
            return format!("transition_density_{n}");
        }
        if let Some((_, flag)) = self.state_quantity() {
            return flag.trim_start_matches("--").replace('-', "_");
        }
        if self.rdg {
            return "rdg".into();
        }
        if self.sign_lambda2_rho {
            return "sign_lambda2_rho".into();
        }
        if self.laplacian {
            return "laplacian".into();
        }
        if self.esp {
            return "esp".into();
        }
        if self.spin_density {
            return "spin_density".into();
        }
        let name = match self.orbital {
            OrbitalSpec::Homo(0) => "homo".to_string(),
            OrbitalSpec::Homo(n) => format!("homo-{n}"),
            OrbitalSpec::Lumo(0) => "lumo".to_string(),
            OrbitalSpec::Lumo(n) => format!("lumo+{n}"),
            OrbitalSpec::Index(n) => format!("mo{n}"),
            OrbitalSpec::Hole(n) => format!("hole{n}"),
            OrbitalSpec::Particle(n) => format!("particle{n}"),
        };
        match self.spin {
            SpinArg::Alpha => name,
            SpinArg::Beta => format!("{name}_beta"),
        }
    }

    /// The quantity option as given, for messages: `--orbital lumo+1`, `--density`.
    fn describe(&self) -> String {
        if let Some(name) = &self.basis_function {
            return format!("--basis-function {name:?}");
        }
        match self.short_name().as_str() {
            "density" => "--density".into(),
            "esp" => "--esp".into(),
            "rdg" => "--rdg".into(),
            "sign_lambda2_rho" => "--sign-lambda2-rho".into(),
            "laplacian" => "--laplacian".into(),
            "spin_density" => "--spin-density".into(),
            "difference_density" | "attachment" | "detachment" | "excited_density" => {
                format!("--{}", self.short_name().replace('_', "-"))
            }
            name if name.starts_with("transition_density") => "--transition-density".into(),
            name => format!("--orbital {name}"),
        }
    }
}

/// What the grid of `q` holds, for a cube file's title line and `eval`'s header.
fn quantity_label(q: &Quantity, doc: &Document) -> String {
    let Some(wf) = &doc.wavefunction else { return String::new() };
    match q {
        Quantity::Density => "total electron density".into(),
        Quantity::SpinDensity => "spin density".into(),
        Quantity::Potential => "electrostatic potential (a.u.)".into(),
        Quantity::ReducedGradient => "reduced density gradient".into(),
        Quantity::NciGradient => "NCI reduced density gradient (ρ ≤ 0.05)".into(),
        Quantity::NciCloud => "NCI cloud, sign(λ₂)ρ (1 − s/0.5)".into(),
        Quantity::SignLambda2Rho => "sign(lambda2)*rho (a.u.)".into(),
        Quantity::DensityLaplacian => "Laplacian of the electron density (a.u.)".into(),
        Quantity::DifferenceDensity => format!("difference density (state {} minus ground)", state_of(wf)),
        Quantity::Attachment => format!("attachment density (state {})", state_of(wf)),
        Quantity::Detachment => format!("detachment density (state {})", state_of(wf)),
        Quantity::ExcitedDensity => format!("excited-state density (state {})", state_of(wf)),
        Quantity::TransitionDensity(n) => format!("transition density (state {n})"),
        Quantity::BasisFunction(k) => {
            let name = crate::model::basis_labels::function_name(&doc.molecule, &wf.basis, *k);
            format!("basis function {}", name.unwrap_or_default())
        }
        Quantity::Orbital(i) => {
            let o = &wf.orbitals[*i];
            let n = wf.of_spin(o.spin).position(|(j, _)| j == *i).map_or(0, |p| p + 1);
            format!("MO {n} ({:?}) E={:.6} Eh occ={:.3} {}", o.spin, o.energy, o.occupation, o.symmetry)
        }
    }
}

/// The refusal of an excited state's density (`flag`) by a file that holds none.
fn no_state_density(doc: &Document, flag: &str) -> anyhow::Error {
    let listed = doc.excited.as_ref().map_or(String::new(), |s| {
        format!(" (it lists {} excited states, but no excited state's density)", s.states.len())
    });
    anyhow::anyhow!(
        "{}: {flag} needs an excited state's density (a Gaussian TD fchk's `Total CI Rho(1) Density`), and this file has none{listed}",
        doc.source
    )
}

/// The excited state whose density `wf` holds, in words ("1", "?" when none).
fn state_of(wf: &Wavefunction) -> String {
    wf.excited.as_ref().map_or_else(|| "?".to_string(), |e| e.state.to_string())
}

fn wavefunction_of(doc: &Document) -> Result<&Wavefunction> {
    doc.wavefunction.as_ref().ok_or_else(|| {
        anyhow::anyhow!(
            "{} holds no basis set or orbitals (a Molden, fchk, wfn, wfx, MKL or JSON file is needed)",
            doc.source
        )
    })
}

#[derive(Subcommand)]
enum BenchCommand {
    /// ms per frame of the scene (atoms + volume slices) at a given size and slice count.
    Render {
        /// A cube file; the bundled demo when omitted.
        file: Option<PathBuf>,
        #[command(flatten)]
        view: ViewArgs,
        /// Frames to time (after two warm-up frames).
        #[arg(long, default_value_t = 10, value_parser = within(1..=100_000u32))]
        frames: u32,
        /// Use the CPU Vulkan adapter (lavapipe) even when a GPU is present.
        #[arg(long)]
        lavapipe: bool,
        #[command(flatten)]
        wavefunction: WavefunctionArgs,
    },
    /// Frame time against the number of resident key volumes K of a scan.
    Keyvolumes(scan::KeyVolumeBench),
    /// ms to extract an isosurface (both signs of an orbital) from a grid.
    Isosurface(surface::IsoBench),
    /// ms to read a file (PDB, mmCIF, XYZ, or any other the viewer opens) and atoms per second.
    Load(structure::LoadBench),
    /// ms per frame of many atoms (synthetic, or a file's) and GPU bytes per atom.
    Spheres(structure::SpheresBench),
    /// ms per frame of 2, 4 and 16 translucent surfaces, exact order against weighted blending,
    /// with the fragment memory and weighted blending's image error.
    Surfaces(surface::TranslucentBench),
    /// ms to build a molecular surface (Gaussian, solvent-excluded) of a file's atoms, and ms
    /// per frame drawing it.
    Surface(molsurface::SurfaceBench),
    /// ms from a change to the coarse preview and to the full picture of several molecules
    /// with clouds and translucent surfaces.
    Scene(bench_scene::SceneBench),
    /// ms to evaluate a wavefunction's NCI field on a grid, on the CPU and by the GPU pass of
    /// the density's derivatives.
    Nci(nci::NciBench),
    /// Grid points per second of an orbital evaluated on the CPU and by the GPU's fill pass.
    Orbital(bench_orbital::OrbitalBench),
}

#[derive(Args)]
struct RenderArgs {
    #[arg(help = format!("{}; the bundled demo when omitted", formats::described()))]
    file: Option<PathBuf>,
    /// Output PNG.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    view: ViewArgs,
    /// Use the CPU Vulkan adapter (lavapipe) even when a GPU is present.
    #[arg(long)]
    lavapipe: bool,
    #[command(flatten)]
    figure: FigureArgs,
    #[command(flatten)]
    wavefunction: WavefunctionArgs,
    #[command(flatten)]
    iso: surface::IsoArgs,
    #[command(flatten)]
    molsurface: molsurface::MolSurfaceArgs,
    /// Print what is drawn at pixel X,Y of the image (an atom, a surface, or nothing).
    #[arg(long, value_parser = surface::parse_pixel)]
    pick: Option<[u32; 2]>,
    /// Leave out the captions of panes side by side (--beside): each pane's quantities and an
    /// orbital's energy.
    #[arg(long)]
    no_captions: bool,
    /// The NCI surface as the viewer draws it (Johnson et al., 2010): the reduced density
    /// gradient's surface s = 0.5 where ρ ≤ 0.05 a.u., opaque, coloured by sign(λ₂)ρ from blue
    /// (−0.05, attraction: hydrogen bonds) through green (van der Waals) to red (+0.05,
    /// repulsion), with its colour bar. A structure without a wavefunction (PDB, mmCIF, XYZ)
    /// shows that of its spherical atoms (the promolecular density, s = 0.3 where ρ ≤ 0.07).
    #[arg(long, conflicts_with_all = NCI_CONFLICTS)]
    nci: bool,
    /// The reduced density gradient the NCI surface is drawn at, 0.01 to 2 (default 0.5).
    #[arg(long, value_name = "S", requires = "nci", value_parser = within(limits::NCI_LEVEL))]
    nci_level: Option<f32>,
    /// The |sign(λ₂)ρ| (a.u.) where the NCI surface's colours saturate, 0.001 to 1 (default 0.05).
    #[arg(long, value_name = "R", requires = "nci", value_parser = within(limits::NCI_RANGE))]
    nci_range: Option<f32>,
    /// A structure's NCI between the atoms this selection picks and all the others, e.g. a
    /// ligand and its pocket: `resn LIG` (also `chain A`, `resi 30-50`, `not …`). The surface is drawn
    /// around the selection where neither part holds 95 % of the density.
    #[arg(long, value_name = "SELECTION", requires = "nci")]
    nci_between: Option<String>,
    /// Render a bundled demo scene instead of a file (cycloaddition: several objects).
    #[arg(long, value_enum)]
    demo: Option<DemoArg>,
    #[command(flatten)]
    vibration: modes::ModeArgs,
}

/// How a picture is made: supersampled, with a transparent background.
#[derive(Args, Clone, Copy)]
struct FigureArgs {
    /// Draw at K× the size and filter down (1 to 4): smooth edges on atoms and thin sticks.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4))]
    scale: u32,
    /// A transparent background (PNG alpha), for figures laid over other material.
    #[arg(long)]
    transparent: bool,
}

impl FigureArgs {
    fn figure(&self) -> crate::pictures::figure::Figure {
        crate::pictures::figure::Figure { scale: self.scale, transparent: self.transparent }
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum ModeArg {
    /// Slices perpendicular to the view direction.
    View,
    /// Three stacks of slices along the grid's axes, the one facing the viewer drawn.
    Axis,
}

#[derive(Clone, Copy, ValueEnum)]
enum AtomsArg {
    BallAndStick,
    SpaceFilling,
    Sticks,
    Licorice,
    Lines,
    Hidden,
}

impl AtomsArg {
    fn style(self) -> AtomStyle {
        match self {
            AtomsArg::BallAndStick => AtomStyle::BallAndStick,
            AtomsArg::SpaceFilling => AtomStyle::SpaceFilling,
            AtomsArg::Sticks => AtomStyle::Sticks,
            AtomsArg::Licorice => AtomStyle::Licorice,
            AtomsArg::Lines => AtomStyle::Lines,
            AtomsArg::Hidden => AtomStyle::Hidden,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum ColorArg {
    Element,
    Chain,
    Residue,
    BFactor,
    Secondary,
}

#[derive(Args)]
struct ViewArgs {
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "800x600", value_parser = parse_size)]
    size: [u32; 2],
    /// Which volume of a multi-orbital cube (0-based, in file order; see `info`).
    #[arg(long, default_value_t = 0)]
    volume: usize,
    /// Which way to look: `auto` (the molecule's principal axes, tilted so no bond points at
    /// the viewer), `x`, `y`, `z` (along the file's axis), `bond:I,J` (from atom I down the bond
    /// to J) or `plane:I,J,K` (perpendicular to three atoms' plane); atoms count from 1.
    #[arg(long, default_value = "auto", value_parser = ViewPreset::parse)]
    view: ViewPreset,
    /// Camera rotation about the vertical axis, degrees (after `--view`).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = within(limits::ANGLE_DEG))]
    yaw: f32,
    /// Camera elevation, degrees.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = within(limits::ANGLE_DEG))]
    pitch: f32,
    /// Zoom factor (> 1 comes closer), 0.001 to 1000.
    #[arg(long, default_value_t = 1.0, value_parser = within(limits::ZOOM))]
    zoom: f32,
    #[arg(long, value_enum, default_value_t = ModeArg::View)]
    mode: ModeArg,
    /// Number of slices, 1 to 4096.
    #[arg(long, value_parser = within(limits::SLICES))]
    slices: Option<u32>,
    /// Opacity scale k1 in α = k1·ρ^k2, 0 to 1000 (default: chosen from the grid so its densest
    /// lines of sight reach an optical depth of 2.5).
    #[arg(long, value_parser = within(limits::K1))]
    k1: Option<f32>,
    /// Opacity exponent k2 in α = k1·ρ^k2, 0 to 16.
    #[arg(long, value_parser = within(limits::K2))]
    k2: Option<f32>,
    #[arg(long, value_enum, default_value_t = AtomsArg::BallAndStick)]
    atoms: AtomsArg,
    /// What colours the atoms (chains, residues, B-factors and secondary structure come from
    /// PDB and mmCIF files; other files are coloured by element).
    #[arg(long, value_enum, default_value_t = ColorArg::Element)]
    color: ColorArg,
    /// Darken atoms with depth by up to this fraction (0 to 1; the viewer opens big structures
    /// at 0.6): the front of a big structure reads from its back.
    #[arg(long, default_value_t = 0.0, value_parser = within(limits::FRACTION))]
    depth_cue: f32,
    /// Factor on the style's ball radii (0.3 to 3).
    #[arg(long, default_value_t = 1.0, value_parser = within(limits::ATOM_SCALE))]
    ball_scale: f32,
    /// Factor on the style's stick radius (0.3 to 3).
    #[arg(long, default_value_t = 1.0, value_parser = within(limits::ATOM_SCALE))]
    stick_scale: f32,
    /// Hide the volume (atoms only).
    #[arg(long)]
    no_volume: bool,
    /// Draw every slice whole, also through the bricks where the transfer function shows
    /// nothing (the same picture, more fragments: to compare).
    #[arg(long)]
    full_slices: bool,
    /// Transfer function: the power law α = k1·ρ^k2, a shape of the value (both signs), or
    /// nested-cores (left half on ψ > 0, right half on ψ < 0, peaked at the extremes).
    #[arg(long, value_enum, default_value_t = TfArg::Power)]
    tf: TfArg,
    /// Shape centre (iso-value), a fraction of max|value| (0 to 1).
    #[arg(long, value_parser = within(limits::FRACTION))]
    tf_center: Option<f32>,
    /// Shape width, a fraction of max|value| (the contour spacing for `sinusoidal`), 0.0001 to 1.
    #[arg(long, value_parser = within(limits::LOBE_WIDTH))]
    tf_width: Option<f32>,
    /// Shape peak opacity per grid step, 0 to 100.
    #[arg(long, value_parser = within(limits::LOBE_OPACITY))]
    tf_opacity: Option<f32>,
    /// Light the cloud with the gradient as the normal.
    #[arg(long)]
    shading: bool,
    /// Boundary enhancement 0..1 (opacity rises with the gradient magnitude).
    #[arg(long, value_parser = within(limits::FRACTION))]
    boundary: Option<f32>,
    /// 2D transfer function: opacity × (|∇|/max|∇|)^P, P 0 to 16.
    #[arg(long, value_parser = within(limits::GRADIENT_POWER))]
    gradient_power: Option<f32>,
    /// Clipping plane NX,NY,NZ[,OFFSET]: cut away what lies beyond it from the clouds,
    /// isosurfaces and molecular surface (offset in bohr from the centre of the molecule's and
    /// grids' bounds, along the normal).
    #[arg(long, value_parser = parse_clip, allow_hyphen_values = true)]
    clip: Option<[f32; 4]>,
    /// Let the clipping plane cut the atoms and bonds too (a cut sphere or stick shows its flat
    /// face).
    #[arg(long, requires = "clip")]
    clip_atoms: bool,
    /// Colours for ψ > 0 and ψ < 0: red-blue, red-white, orange-teal, gold-purple or
    /// green-magenta.
    #[arg(long, value_parser = parse_preset)]
    colors: Option<([f32; 3], [f32; 3])>,
}

#[derive(Clone, Copy, ValueEnum)]
enum TfArg {
    Power,
    Uniform,
    Gaussian,
    LeftHalf,
    RightHalf,
    Sinusoidal,
    NestedCores,
}

fn parse_preset(s: &str) -> Result<([f32; 3], [f32; 3]), String> {
    let key = |n: &str| n.chars().filter(|c| c.is_alphanumeric()).collect::<String>().to_lowercase();
    PRESETS
        .iter()
        .find(|(n, _, _)| key(n).starts_with(&key(s)))
        .map(|(_, pos, neg)| (*pos, *neg))
        .ok_or_else(|| format!("unknown colour preset {s:?}"))
}

fn parse_clip(s: &str) -> Result<[f32; 4], String> {
    let v: Vec<f32> = s.split(',').map(|t| limits::parse_in(t, &limits::POSITION)).collect::<Result<_, _>>()?;
    let plane = match v[..] {
        [x, y, z] => [x, y, z, 0.0],
        [x, y, z, o] => [x, y, z, o],
        _ => return Err(format!("expected NX,NY,NZ[,OFFSET], got {s:?}")),
    };
    if plane[..3].iter().all(|&c| c == 0.0) {
        return Err(format!("expected a normal NX,NY,NZ that is not zero, got {s:?}"));
    }
    Ok(plane)
}

fn parse_size(s: &str) -> Result<[u32; 2], String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WIDTHxHEIGHT, got {s:?}"))?;
    let parse = |v: &str| v.trim().parse::<u32>().ok().filter(|&n| (1..=16384).contains(&n));
    match (parse(w), parse(h)) {
        (Some(w), Some(h)) => Ok([w, h]),
        _ => Err(format!("expected WIDTHxHEIGHT with sides 1..16384, got {s:?}")),
    }
}

impl ViewArgs {
    fn settings(&self) -> RenderSettings {
        let mut s = RenderSettings::default();
        s.volume.mode = match self.mode {
            ModeArg::View => SliceMode::ViewAligned,
            ModeArg::Axis => SliceMode::AxisAligned,
        };
        s.volume.visible = !self.no_volume;
        s.volume.skip_empty = !self.full_slices;
        if let Some(n) = self.slices {
            s.volume.slices = n;
        }
        s.volume.auto_k1 = self.k1.is_none();
        if let Some(k1) = self.k1 {
            s.volume.k1 = k1;
        }
        if let Some(k2) = self.k2 {
            s.volume.k2 = k2;
        }
        let t = &mut s.volume.transfer;
        if matches!(self.tf, TfArg::NestedCores) {
            t.nested_cores();
        }
        let shape = match self.tf {
            TfArg::Power | TfArg::NestedCores => None,
            TfArg::Uniform => Some(Shape::Uniform),
            TfArg::Gaussian => Some(Shape::Gaussian),
            TfArg::LeftHalf => Some(Shape::LeftHalfGaussian),
            TfArg::RightHalf => Some(Shape::RightHalfGaussian),
            TfArg::Sinusoidal => Some(Shape::Sinusoidal),
        };
        if let Some(shape) = shape {
            t.kind = TransferKind::Shaped;
            t.positive.shape = shape;
            t.negative.shape = shape;
        }
        if t.kind == TransferKind::Shaped {
            for lobe in [&mut t.positive, &mut t.negative] {
                lobe.center = self.tf_center.unwrap_or(lobe.center);
                lobe.width = self.tf_width.unwrap_or(lobe.width);
                lobe.opacity = self.tf_opacity.unwrap_or(lobe.opacity);
            }
        }
        t.shading = self.shading;
        t.boundary = self.boundary.unwrap_or(0.0);
        t.gradient_power = self.gradient_power.unwrap_or(0.0);
        if let Some([x, y, z, offset]) = self.clip {
            s.clip = ClipPlane { enabled: true, normal: [x, y, z], offset, atoms: self.clip_atoms };
        }
        if let Some((pos, neg)) = self.colors {
            s.volume.positive_color = pos;
            s.volume.negative_color = neg;
        }
        s.atoms = self.atoms.style();
        s.atom_colors = match self.color {
            ColorArg::Element => AtomColoring::Element,
            ColorArg::Chain => AtomColoring::Chain,
            ColorArg::Residue => AtomColoring::Residue,
            ColorArg::BFactor => AtomColoring::BFactor,
            ColorArg::Secondary => AtomColoring::Secondary,
        };
        s.depth_cue = self.depth_cue;
        s.ball_scale = self.ball_scale;
        s.stick_scale = self.stick_scale;
        s
    }

    fn camera(&self, doc: &Document) -> Result<Camera> {
        let cam = camera_for(doc, self.view).map_err(|e| anyhow::anyhow!("--view {e}"))?;
        Ok(self.orbit(cam))
    }

    /// `camera` turned by `--yaw` and `--pitch` and zoomed by `--zoom`.
    fn orbit(&self, mut camera: Camera) -> Camera {
        camera.orbit(self.yaw.to_radians(), self.pitch.to_radians());
        camera.zoom(1.0 / self.zoom);
        camera
    }

    fn volume_index(&self, doc: &Document) -> Result<Option<usize>> {
        if doc.volumes.is_empty() {
            return Ok(None);
        }
        if self.volume >= doc.volumes.len() {
            bail!("--volume {} is out of range: the file has {} volume(s)", self.volume, doc.volumes.len());
        }
        Ok(Some(self.volume))
    }
}

fn load(file: Option<&Path>) -> Result<Document> {
    match file {
        Some(p) => formats::load(p).map_err(anyhow::Error::from),
        None => demo::document().context("the bundled demo did not load"),
    }
}

/// What `render` makes of its options, given as words after `orbcloud render` (a file or not,
/// `--orbital lumo --iso 0.05`, …), without a file written; `doc` replaces the file they name.
/// The Python package takes `render`'s options this way.
pub fn render_drawing(doc: Option<Document>, words: &[String]) -> Result<render::Drawing> {
    let head = ["orbcloud", "render", "--output", "unused.png"].map(String::from);
    let line = head.into_iter().chain(words.iter().cloned()).map(std::ffi::OsString::from).collect();
    let (line, later) = quantities::split(line)?;
    match Cli::try_parse_from(line) {
        Ok(Cli { command: Some(Command::Render(args)), .. }) => render::drawing(&args, doc, &later),
        Ok(_) => bail!("expected the options of `render`"),
        Err(e) => bail!("{}", e.to_string().trim()),
    }
}

pub use nci::{NciOptions, NciResult, nci_of};
pub use render::{Drawing, Picture};

/// Image size, frame count and adapter of a frame-time benchmark.
#[derive(Args)]
struct BenchFrames {
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "800x600", value_parser = parse_size)]
    size: [u32; 2],
    /// Frames to time (after two warm-up frames).
    #[arg(long, default_value_t = 10, value_parser = within(1..=100_000u32))]
    frames: u32,
    /// Use the CPU Vulkan adapter (lavapipe) even when a GPU is present.
    #[arg(long)]
    lavapipe: bool,
}

/// How often a computation's benchmark times each path, and on which adapter.
#[derive(Args)]
struct BenchRuns {
    /// Timed runs of each path (the best is reported).
    #[arg(long, default_value_t = 3, value_parser = within(1..=1000usize))]
    runs: usize,
    /// Use the CPU Vulkan adapter (lavapipe) even when a GPU is present.
    #[arg(long)]
    lavapipe: bool,
}

fn gpu(lavapipe: bool) -> Result<GpuContext> {
    let pref = if lavapipe { AdapterPreference::LavapipeOnly } else { AdapterPreference::HighPerformance };
    Ok(GpuContext::headless(pref)?)
}

/// Runs the process's command line (`words[0]` the program's name): a usage error, `--help` or
/// `--version` print clap's answer and end the process, as a command does.
pub fn run(words: Vec<std::ffi::OsString>) -> Result<()> {
    // Each quantity after the first comes with its own options ([`quantities`]).
    let (line, later) = quantities::split(words)?;
    dispatch(Cli::parse_from(line), &later)
}

/// Runs a command line (`words[0]` the program's name) as the `orbcloud` command does, its
/// usage errors returned rather than ending the process: the Python package calls it for
/// `orbcloud.compute` and `orbcloud.scan_compute`.
pub fn run_words(words: Vec<std::ffi::OsString>) -> Result<()> {
    let (line, later) = quantities::split(words)?;
    match Cli::try_parse_from(line) {
        Ok(cli) => dispatch(cli, &later),
        // --help and --version are answers, not errors.
        Err(e) if !e.use_stderr() => {
            print!("{e}");
            Ok(())
        }
        Err(e) => Err(e.into()),
    }
}

fn dispatch(cli: Cli, later: &[quantities::Later]) -> Result<()> {
    match cli.command {
        None => Ok(crate::app::run(cli.files, cli.demo.map(DemoArg::demo))?),
        Some(Command::Viewer { files, demo }) => Ok(crate::app::run(files, demo.map(DemoArg::demo))?),
        Some(Command::Render(args)) => render::render(args, later),
        Some(Command::Info { file, json, transitions }) => values::info(&file, json, transitions.as_deref()),
        Some(Command::Eval { files, what, points, minus }) => values::eval(&files, &what, &points, minus.as_deref()),
        Some(Command::Cube { file, what, grid, spacing, margin, minus, output }) => {
            values::cube(&file, &what, (grid, spacing, margin), minus.as_deref(), &output)
        }
        Some(Command::Plane(args)) => plane::plane(&args),
        Some(Command::Compute(args)) => compute::compute(args),
        Some(Command::Nci(args)) => nci::nci(&args),
        Some(Command::Scan(command)) => scan::run(command),
        Some(Command::Modes(args)) => modes::write_xyz(&args),
        Some(Command::Movie(args)) => movie::movie(*args),
        Some(Command::Mesh(args)) => surface::mesh(&args, &quantities::parse_later_meshes(later)?),
        Some(Command::Bench(BenchCommand::Keyvolumes(args))) => scan::bench_keyvolumes(args),
        Some(Command::Bench(BenchCommand::Isosurface(args))) => surface::bench(&args),
        Some(Command::Bench(BenchCommand::Load(args))) => structure::bench_load(&args),
        Some(Command::Bench(BenchCommand::Spheres(args))) => structure::bench_spheres(&args),
        Some(Command::Bench(BenchCommand::Surfaces(args))) => surface::bench_translucent(&args),
        Some(Command::Bench(BenchCommand::Surface(args))) => molsurface::bench(&args),
        Some(Command::Bench(BenchCommand::Scene(args))) => bench_scene::bench(&args),
        Some(Command::Bench(BenchCommand::Nci(args))) => nci::bench(&args),
        Some(Command::Bench(BenchCommand::Orbital(args))) => bench_orbital::bench(&args),
        Some(Command::Bench(BenchCommand::Render { file, view, frames, lavapipe, wavefunction })) => {
            render::bench(file.as_deref(), &view, frames, lavapipe, &wavefunction)
        }
    }
}
