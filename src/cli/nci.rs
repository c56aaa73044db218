//! `nci`: NCIPLOT's two cubes (`PREFIX-dens.cube`: 100·sign(λ₂)ρ, `PREFIX-grad.cube`: the
//! reduced density gradient s; both 100 at the points cut) of one or more files whose densities
//! add: wavefunctions, or promolecular sums of spherical atoms for any structure.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Args;
use glam::DVec3;

use crate::formats::{self, cube_write};
use crate::model::nci::{self, DensitySource, NciSettings, WavefunctionDensity};
use crate::model::promolecular::Promolecule;
use crate::model::units::{ANGSTROM_PER_BOHR, BOHR_PER_ANGSTROM};
use crate::model::{Document, GridSpec, Molecule, VolumeGrid};
use crate::scene::limits::{self, within};

/// NCIPLOT's grid step, bohr.
const DEFAULT_STEP_BOHR: f64 = 0.1;
/// Space around the atoms, bohr (what the box adds on each side unless --margin says).
const DEFAULT_MARGIN_BOHR: f64 = 2.0;

#[derive(Args)]
pub struct NciArgs {
    /// Files whose densities add (fragments): wavefunctions (Molden, fchk, wfn, wfx, MKL), or
    /// with --promolecular any file with atoms (XYZ, PDB, mmCIF, cube, a wavefunction's atoms).
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Sums of spherical atoms instead of the files' wavefunctions (elements H–Cm).
    #[arg(long)]
    promolecular: bool,
    /// Grid step in Å, 0.001 to 10 (default 0.1 bohr, NCIPLOT's: 0.0529 Å).
    #[arg(long, value_parser = within(limits::SPACING))]
    step: Option<f64>,
    /// Space around the atoms in Å, 0 to 100 (default 2 bohr: 1.058 Å).
    #[arg(long, value_parser = within(limits::MARGIN))]
    margin: Option<f64>,
    /// Points whose density is above this (a.u.) are cut: 1e-6 to 10 (default 0.05 for
    /// wavefunctions, 0.07 promolecular).
    #[arg(long, value_parser = within(limits::DENSITY_CUT))]
    cut: Option<f64>,
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
    Wavefunction(WavefunctionDensity<'a>),
    Promolecular(Promolecule),
}

impl Fragment<'_> {
    fn source(&self) -> &dyn DensitySource {
        match self {
            Fragment::Wavefunction(w) => w,
            Fragment::Promolecular(p) => p,
        }
    }
}

pub fn nci(args: &NciArgs) -> Result<()> {
    if args.intermolecular && args.files.len() < 2 {
        bail!("--intermolecular needs two files or more (the fragments), got {}", args.files.len());
    }
    let docs: Vec<Document> = args.files.iter().map(|f| formats::load(f)).collect::<Result<_, _>>()?;
    let mut fragments = Vec::with_capacity(docs.len());
    for (doc, file) in docs.iter().zip(&args.files) {
        if doc.molecule.atoms.is_empty() {
            bail!("{}: no atoms, so no density for nci", file.display());
        }
        let fragment = if args.promolecular {
            Fragment::Promolecular(
                Promolecule::new(&doc.molecule).map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?,
            )
        } else {
            match &doc.wavefunction {
                Some(wf) => Fragment::Wavefunction(WavefunctionDensity::new(wf)),
                None => bail!(
                    "{}: no wavefunction (Molden, fchk, wfn, wfx or MKL) for nci: --promolecular sums spherical atoms instead",
                    file.display()
                ),
            }
        };
        fragments.push(fragment);
    }
    let step = args.step.map_or(DEFAULT_STEP_BOHR, |s| s * BOHR_PER_ANGSTROM);
    let margin = args.margin.map_or(DEFAULT_MARGIN_BOHR, |m| m * BOHR_PER_ANGSTROM);
    let atoms: Vec<_> = docs.iter().flat_map(|d| d.molecule.atoms.iter().cloned()).collect();
    let molecule = Molecule::new(atoms);
    let (lo, hi) = molecule.bounds().context("no atoms")?;
    let (lo, hi) = (lo - DVec3::splat(margin), hi + DVec3::splat(margin));
    // Counted in floating point first: far-flung atoms must not overflow the count.
    let sides = ((hi - lo) / step).ceil().max(DVec3::ONE) + DVec3::ONE;
    let points = sides.x * sides.y * sides.z;
    if points.is_nan() || points > limits::NCI_POINTS as f64 {
        bail!(
            "a {:.0}×{:.0}×{:.0} grid ({points:.3e} points) is more than nci holds ({}): a larger --step (now {:.4} Å) or a smaller --margin makes it fit",
            sides.x,
            sides.y,
            sides.z,
            limits::NCI_POINTS,
            step * ANGSTROM_PER_BOHR
        );
    }
    let spec = GridSpec::spaced(lo, hi, step);
    let settings = NciSettings {
        density_cut: args.cut.unwrap_or(if args.promolecular {
            nci::PROMOLECULAR_DENSITY_CUT
        } else {
            nci::WAVEFUNCTION_DENSITY_CUT
        }),
        intermolecular: args.intermolecular.then_some(nci::INTERMOLECULAR_SHARE),
    };
    let sources: Vec<&dyn DensitySource> = fragments.iter().map(Fragment::source).collect();
    let start = Instant::now();
    let grids = nci::nci_grid(&sources, &spec, settings);
    let seconds = start.elapsed().as_secs_f64();
    let kind = if args.promolecular { "promolecular" } else { "wavefunction" };
    let names: Vec<String> = args.files.iter().map(|f| f.display().to_string()).collect();
    let dens_path = with_suffix(&args.output, "-dens.cube");
    let grad_path = with_suffix(&args.output, "-grad.cube");
    let dens = VolumeGrid::new("100*sign(lambda2)*rho", spec.dims, spec.world_from_grid, grids.dens);
    let grad = VolumeGrid::new("reduced density gradient", spec.dims, spec.world_from_grid, grids.grad);
    for (path, grid, what) in
        [(&dens_path, &dens, "100*sign(lambda2)*rho"), (&grad_path, &grad, "reduced density gradient")]
    {
        let title = format!("orbcloud nci ({kind}) {}", names.join(" + "));
        let file = std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
        let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
        cube_write::write_to(&mut w, &title, what, &molecule, &[(grid, 0)])
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

/// `prefix` with `suffix` appended to its file name (`out/dimer` → `out/dimer-dens.cube`).
fn with_suffix(prefix: &Path, suffix: &str) -> PathBuf {
    let mut name = prefix.as_os_str().to_owned();
    name.push(suffix);
    PathBuf::from(name)
}
