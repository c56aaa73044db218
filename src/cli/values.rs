//! `info` (a file described), `eval` (an orbital or density at points) and `cube` (on a grid,
//! written as a Gaussian cube file).

use std::path::Path;
use std::time::Instant;

use super::info;
use crate::formats::{self, cube_write};
use crate::model::GridSpec;
use crate::model::gto::PreparedBasis;
use crate::model::orbitals::Quantity;
use crate::scene::Source;
use anyhow::{Context, Result, bail};
use glam::DVec3;

use super::{WhatArgs, wavefunction_of};

/// `info`: what `file` holds, as text or JSON; with `transitions`, a TD log's printed
/// transitions joined to its states ([`crate::model::Document::join`]).
pub fn info(file: &Path, json: bool, transitions: Option<&Path>) -> Result<()> {
    let mut doc = formats::load(file)?;
    if let Some(log) = transitions {
        let other = formats::load(log)?;
        if !other.carries_transitions() {
            anyhow::bail!("{}: it lists no excited states' transitions to join {}", log.display(), file.display());
        }
        doc.join(other).map_err(anyhow::Error::msg)?;
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&info::describe(&doc))?);
    } else {
        print!("{}", info::text(&doc));
    }
    Ok(())
}

/// `eval`: the quantity `what` asks for at each point of `points` (`x y z` in bohr per line).
/// Several `files` are fragments whose densities add ([`fragments_at`]). With `minus`, that
/// file's same quantity is subtracted ([`other_values`]).
pub fn eval(files: &[std::path::PathBuf], what: &WhatArgs, points: &Path, minus: Option<&Path>) -> Result<()> {
    let mut values;
    let points = match files {
        [file] => {
            let doc = what.load(file)?;
            let q = what.resolve(&doc)?;
            let wf = wavefunction_of(&doc)?;
            let prepared = PreparedBasis::new(&wf.basis);
            let points = read_points(points)?;
            values = match q {
                Quantity::TransitionDensity(n) => crate::model::transition::TransitionDensity::of_state(&doc, n)
                    .context("no transition density")?
                    .at_points(wf, &prepared, &points),
                _ => prepared.quantity_at_points(wf, &doc.molecule, q, &points),
            };
            points
        }
        _ => {
            if minus.is_some() {
                bail!("--minus subtracts from one file's quantity: give one file, or leave --minus out");
            }
            let docs: Vec<_> = files.iter().map(|f| formats::load(f)).collect::<Result<_, _>>()?;
            let q = what.resolve(&docs[0])?;
            if !matches!(
                q,
                Quantity::Density | Quantity::ReducedGradient | Quantity::SignLambda2Rho | Quantity::DensityLaplacian
            ) {
                bail!(
                    "{} files are fragments whose densities add: eval gives --density, --rdg, --sign-lambda2-rho or --laplacian of their sum, not {}",
                    files.len(),
                    what.describe()
                );
            }
            let points = read_points(points)?;
            values = fragments_at(&docs, q, &points)?;
            points
        }
    };
    if let Some(other) = minus {
        for (v, o) in values.iter_mut().zip(other_values(other, what, &points)?) {
            *v -= o;
        }
    }
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    use std::io::Write;
    for (p, v) in points.iter().zip(values) {
        writeln!(out, "{:.10} {:.10} {:.10} {:.15e}", p.x, p.y, p.z, v)?;
    }
    Ok(())
}

/// `quantity` (one of ρ's derivatives) of the summed density of `docs` (fragments, each with a
/// wavefunction) at `points`.
pub fn fragments_at(docs: &[crate::model::Document], quantity: Quantity, points: &[DVec3]) -> Result<Vec<f64>> {
    use crate::model::nci::{DensitySource, WavefunctionDensity, summed_quantity_at};
    let sources: Vec<WavefunctionDensity> =
        docs.iter().map(|d| wavefunction_of(d).map(WavefunctionDensity::new)).collect::<Result<_>>()?;
    let sources: Vec<&dyn DensitySource> = sources.iter().map(|s| s as &dyn DensitySource).collect();
    Ok(summed_quantity_at(&sources, quantity, points))
}

/// `cube`: the quantity on a grid of `grid` points per side (or `spacing` bohr), over the box
/// where it decays (or the atoms' box plus `margin`), written to `output`.
pub fn cube(
    file: &Path,
    what: &WhatArgs,
    (grid, spacing, margin): (usize, Option<f64>, Option<f64>),
    minus: Option<&Path>,
    output: &Path,
) -> Result<()> {
    // `ORBCLOUD_TIMINGS=1` prints where the command's time goes, phase by phase.
    let mut phases = Phases::new();
    let doc = what.load(file)?;
    phases.done("read and check the file");
    let q = what.resolve(&doc)?;
    let wf = wavefunction_of(&doc)?;
    let (lo, hi) = match margin {
        Some(m) => doc.molecule.bounds().map(|(lo, hi)| (lo - DVec3::splat(m), hi + DVec3::splat(m))),
        None => crate::model::extent::quantity_box(wf, &doc.molecule, q),
    }
    .ok_or_else(|| anyhow::anyhow!("{}: no atoms", doc.source))?;
    let spec = match spacing {
        Some(h) if h > 0.0 => GridSpec::spaced(lo, hi, h),
        Some(h) => bail!("--spacing must be positive, got {h}"),
        // cubegen's convention: the grid spans the box exactly, spacing = extent / (n − 1).
        None => GridSpec::cube(lo, hi, grid),
    };
    let dims = spec.dims;
    if dims.iter().map(|&d| d as u64).product::<u64>() > formats::MAX_GRID_VALUES {
        bail!("a {dims:?} grid is too large");
    }
    let prepared = PreparedBasis::new(&wf.basis);
    phases.done("box and basis prepared");
    let t = Instant::now();
    let mut values = crate::evaluate::quantity_grid(&doc, &prepared, q, &spec);
    let mut label = super::quantity_label(&q, &doc);
    if let Some(other) = minus {
        let points = crate::evaluate::arithmetic::grid_points(dims, |i, j, k| spec.point(i, j, k));
        for (v, o) in values.iter_mut().zip(other_values(other, what, &points)?) {
            *v -= o as f32;
        }
        label = format!("{label} minus {}", other.display());
    }
    let seconds = t.elapsed().as_secs_f64();
    phases.done("evaluate");
    let id = match q {
        Quantity::Orbital(i) => wf.of_spin(wf.orbitals[i].spin).position(|(j, _)| j == i).map_or(0, |p| p + 1),
        _ => 0,
    };
    let file = std::fs::File::create(output).with_context(|| format!("creating {}", output.display()))?;
    // Smaller than the writer's blocks, which then go to the file without a copy.
    let mut w = std::io::BufWriter::with_capacity(cube_write::BLOCK / 4, file);
    let title = format!("{} {}", doc.source, label);
    cube_write::write_values_to(&mut w, &title, &label, &doc.molecule, &spec, &[(&values, id as i64)])
        .with_context(|| format!("writing {}", output.display()))?;
    phases.done("format and write");
    drop(w);
    phases.done("close");
    eprintln!("wrote {} ({}×{}×{}, {label}; evaluated in {seconds:.3} s)", output.display(), dims[0], dims[1], dims[2]);
    Ok(())
}

/// Milliseconds since the previous phase, printed to stderr when `ORBCLOUD_TIMINGS` is set.
struct Phases(Option<Instant>);

impl Phases {
    fn new() -> Self {
        Self(std::env::var_os("ORBCLOUD_TIMINGS").map(|_| Instant::now()))
    }

    fn done(&mut self, phase: &str) {
        if let Some(t) = &mut self.0 {
            eprintln!("{phase}: {:.2} ms", t.elapsed().as_secs_f64() * 1e3);
            *t = Instant::now();
        }
    }
}

/// The quantity `what` asks for, of the file `other`, at `points` (bohr): evaluated from its
/// wavefunction, or its first data set sampled trilinearly (0 outside its grid, with a warning;
/// refused when no point lies inside).
pub fn other_values(other: &Path, what: &WhatArgs, points: &[DVec3]) -> Result<Vec<f64>> {
    let doc = formats::load(other)?;
    let source = match &doc.wavefunction {
        Some(_) => Source::Wavefunction(what.resolve(&doc)?),
        None if doc.volumes.is_empty() => bail!("{}: no wavefunction and no data set to subtract", doc.source),
        None => Source::Volume(0),
    };
    let (values, outside) = crate::evaluate::arithmetic::values_of(&doc, source, points).map_err(anyhow::Error::msg)?;
    if outside > 0 {
        eprintln!(
            "{}: {outside} of {} points lie outside its grid; its value there is taken as 0",
            doc.source,
            values.len()
        );
    }
    Ok(values)
}

fn read_points(path: &Path) -> Result<Vec<DVec3>> {
    let text = if path.as_os_str() == "-" {
        std::io::read_to_string(std::io::stdin())?
    } else {
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?
    };
    let mut points = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let v: Vec<f64> =
            line.split_whitespace().take(3).map(str::parse).collect::<Result<_, _>>().map_err(|_| {
                anyhow::anyhow!("{}:{}: expected `x y z` in bohr, found {line:?}", path.display(), n + 1)
            })?;
        if v.len() < 3 || v.iter().any(|x| !x.is_finite()) {
            bail!("{}:{}: expected `x y z` in bohr, found {line:?}", path.display(), n + 1);
        }
        points.push(DVec3::new(v[0], v[1], v[2]));
    }
    if points.is_empty() {
        bail!("{}: expected lines of `x y z` in bohr, found none", path.display());
    }
    Ok(points)
}
