//! `plane`: a quantity on a plane through the molecule, exact from the wavefunction, as a
//! contoured map (PNG or SVG) and as numbers (CSV).

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::formats;
use crate::model::Document;
use crate::model::units::{ANGSTROM_PER_BOHR, BOHR_PER_ANGSTROM};
use crate::plane::{self, Frame, Levels, MapPicture, PlaneMap};
use crate::scene::Source;
use anyhow::{Context, Result, bail};
use clap::Args;
use glam::DVec3;

use super::WhatArgs;

#[derive(Args)]
pub struct PlaneArgs {
    /// A wavefunction (Molden, fchk, wfn, wfx, MKL, JSON), whose quantity is evaluated exactly at
    /// every point, or a cube file, whose values are interpolated trilinearly.
    file: PathBuf,
    #[command(flatten)]
    what: WhatArgs,
    /// Which data set of a cube file (0-based, in file order; see `info`).
    #[arg(long, default_value_t = 0)]
    volume: usize,
    /// Subtract the same quantity of another file (a density difference): its
    /// wavefunction's at each point, or its first data set's, interpolated trilinearly.
    #[arg(long, value_name = "FILE")]
    minus: Option<PathBuf>,
    /// Draw gradient lines from the atoms near the plane over the contours (for the density,
    /// the paths that outline each atom's basin).
    #[arg(long)]
    gradient_lines: bool,
    /// Label the axes in bohr (ångström by default).
    #[arg(long)]
    bohr: bool,
    /// The plane through three atoms A,B,C (counted from 1): u along A→B, v towards C.
    #[arg(long, value_name = "A,B,C", value_parser = parse_indices::<3>)]
    through: Option<[usize; 3]>,
    /// The plane that holds the bond A–B (u along it) and the direction --toward: with
    /// --offset, a plane parallel to the bond.
    #[arg(long, value_name = "A,B", value_parser = parse_indices::<2>, conflicts_with = "through")]
    bond: Option<[usize; 2]>,
    /// With --bond: the direction (X,Y,Z) that, with the bond, spans the plane.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vector, allow_hyphen_values = true, requires = "bond")]
    toward: Option<[f64; 3]>,
    /// The plane through this point (Å), perpendicular to --normal; the map is centred on it.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vector, allow_hyphen_values = true, conflicts_with_all = ["through", "bond"])]
    origin: Option<[f64; 3]>,
    /// The plane's normal (X,Y,Z), with --origin (the molecule's centre when --origin is left
    /// out).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vector, allow_hyphen_values = true, conflicts_with_all = ["through", "bond"])]
    normal: Option<[f64; 3]>,
    /// Move the plane this far (Å) along its normal: 0.529 (1 bohr) above a ring shows its π
    /// orbitals.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    offset: f64,
    /// Points along each side of the map (2 to 4000).
    #[arg(long, default_value_t = 200)]
    points: usize,
    /// The map's side L, or its sides WxH along u and v (Å); by default a square holding the
    /// atoms near the plane with 2 Å to spare.
    #[arg(long, value_name = "L|WxH", value_parser = parse_extent)]
    extent: Option<[f64; 2]>,
    /// Contour levels: `auto` (±0.001·2^k up to the largest value, and 0 for quantities of both
    /// signs) or values separated by commas.
    #[arg(long, default_value = "auto", allow_hyphen_values = true)]
    levels: Levels,
    /// The figure: PNG or SVG, by its extension.
    #[arg(short, long)]
    output: PathBuf,
    /// Also write the numbers as CSV: `x,y,z,value` per point, bohr.
    #[arg(long, value_name = "FILE.csv")]
    values: Option<PathBuf>,
}

/// Comma-separated atom numbers (from 1).
fn parse_indices<const N: usize>(s: &str) -> Result<[usize; N], String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|t| t.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected {N} atom numbers separated by commas, got {s:?}"))?;
    v.try_into().map_err(|_| format!("expected {N} atom numbers separated by commas, got {s:?}"))
}

fn parse_vector(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("expected X,Y,Z, got {s:?}"))?;
    v.try_into().map_err(|_| format!("expected X,Y,Z, got {s:?}"))
}

fn parse_extent(s: &str) -> Result<[f64; 2], String> {
    let parse = |t: &str| t.trim().parse::<f64>().ok().filter(|x| x.is_finite() && *x > 0.0);
    let sides = match s.split_once(['x', 'X']) {
        Some((w, h)) => parse(w).zip(parse(h)).map(|(w, h)| [w, h]),
        None => parse(s).map(|l| [l, l]),
    };
    sides.ok_or_else(|| format!("expected a positive side L or sides WxH in Å, got {s:?}"))
}

/// What a figure says of the file and its quantity: the caption's first line and the colour
/// bar's title.
struct Described {
    label: String,
    unit: String,
}

pub fn plane(args: &PlaneArgs) -> Result<()> {
    let format = Format::of(&args.output)?;
    let doc = formats::load(&args.file)?;
    let (source, mut described) = source(args, &doc)?;
    let (frame, keep_origin, how) = frame(args, &doc)?;
    let size = args.extent.map(|e| e.map(|l| l * BOHR_PER_ANGSTROM));
    let plane =
        frame.offset(args.offset * BOHR_PER_ANGSTROM).rectangle(&doc.molecule, size, args.points, keep_origin)?;
    let start = Instant::now();
    let mut map = plane::evaluate(&doc, source, &plane)?;
    if let Some(other) = &args.minus {
        let points = plane.points();
        for (v, o) in map.values.iter_mut().zip(super::values::other_values(other, &args.what, &points)?) {
            *v -= o;
        }
        map.signed = true;
        described.label = format!("{} minus {}", described.label, file_name(other));
        described.unit = format!("Δ{}", described.unit);
    }
    let seconds = start.elapsed().as_secs_f64();
    if let plane::Sampling::Trilinear { outside } = map.sampling {
        eprintln!(
            "{}: a cube file's values, interpolated trilinearly between its grid points (not exact){}",
            doc.source,
            if outside > 0 { format!("; {outside} points lie outside its grid (no value)") } else { String::new() }
        );
    }
    let levels = if map.vanishes() {
        eprintln!("{}: zero on this plane but for rounding (a nodal plane): no contours", described.label);
        Vec::new()
    } else {
        args.levels.resolve(map.max_abs(), map.signed)
    };
    let caption =
        vec![format!("{} · {}", file_name(&args.file), described.label), plane::where_text(&how, &plane, args.offset)];
    let scale = args.minus.is_none().then(|| plane::scale_for(source, &map)).flatten();
    let picture = MapPicture {
        map: &map,
        molecule: &doc.molecule,
        levels: &levels,
        caption,
        unit: described.unit,
        scale,
        gradient_lines: args.gradient_lines,
        bohr: args.bohr,
    };
    write_figure(&picture, format, &args.output)?;
    if let Some(path) = &args.values {
        std::fs::write(path, map.csv()).with_context(|| format!("writing {}", path.display()))?;
    }
    report(&map, &levels, seconds, args);
    Ok(())
}

fn report(map: &PlaneMap, levels: &[f64], seconds: f64, args: &PlaneArgs) {
    let n = map.plane.points;
    let [w, h] = map.plane.size.map(|s| s * ANGSTROM_PER_BOHR);
    let values = args.values.as_ref().map_or(String::new(), |p| format!(" and {}", p.display()));
    eprintln!(
        "wrote {}{values} ({n}×{n} points over {w:.2} × {h:.2} Å, {} contour levels; evaluated in {seconds:.3} s)",
        args.output.display(),
        levels.len()
    );
}

#[derive(Clone, Copy)]
enum Format {
    Png,
    Svg,
}

impl Format {
    fn of(path: &Path) -> Result<Self> {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("png") => Ok(Format::Png),
            Some("svg") => Ok(Format::Svg),
            _ => bail!("{}: the map is written as PNG or SVG (a .png or .svg name)", path.display()),
        }
    }
}

fn write_figure(picture: &MapPicture, format: Format, path: &Path) -> Result<()> {
    match format {
        Format::Png => plane::png(picture).save(path).with_context(|| format!("writing {}", path.display())),
        Format::Svg => std::fs::write(path, plane::svg(picture)).with_context(|| format!("writing {}", path.display())),
    }
}

/// What the map shows of `doc`: a data set of a cube file, else the quantity the options ask
/// of its wavefunction.
fn source(args: &PlaneArgs, doc: &Document) -> Result<(Source, Described)> {
    if doc.wavefunction.is_none() {
        if doc.volumes.is_empty() {
            bail!(
                "{}: no wavefunction and no data set to map (a Molden, fchk, wfn, wfx, MKL or cube file is needed)",
                doc.source
            );
        }
        let w = &args.what;
        if w.density || w.spin_density || w.esp || w.basis_function.is_some() {
            bail!(
                "{}: {} needs a wavefunction, and this file holds only data sets (--volume picks one)",
                doc.source,
                w.describe()
            );
        }
        if args.volume >= doc.volumes.len() {
            bail!("--volume {} is out of range: the file has {} data set(s)", args.volume, doc.volumes.len());
        }
        let label = doc.volumes[args.volume].label.clone();
        return Ok((Source::Volume(args.volume), Described { label, unit: plane::unit(Source::Volume(0)).into() }));
    }
    let q = args.what.resolve(doc)?;
    let source = Source::Wavefunction(q);
    Ok((source, Described { label: super::quantity_label(&q, doc), unit: plane::unit(source).into() }))
}

/// The plane the options name, whether the map keeps its origin at the centre, and how the
/// caption describes it.
fn frame(args: &PlaneArgs, doc: &Document) -> Result<(Frame, bool, String)> {
    let m = &doc.molecule;
    let name =
        |i: usize| m.atoms.get(i.wrapping_sub(1)).map_or(String::new(), |a| format!("{}{i}", a.element().symbol));
    if let Some(atoms) = args.through {
        let frame = Frame::through_atoms(m, atoms)?;
        return Ok((frame, false, format!("plane through {} {} {}", name(atoms[0]), name(atoms[1]), name(atoms[2]))));
    }
    if let Some([a, b]) = args.bond {
        let Some(toward) = args.toward else {
            bail!("--bond A,B needs --toward X,Y,Z: the direction that, with the bond, spans the plane")
        };
        let (pa, pb) = (plane::atom_position(m, a)?, plane::atom_position(m, b)?);
        let frame = Frame::along_bond(pa, pb, DVec3::from_array(toward))?;
        return Ok((frame, false, format!("plane along {}–{}", name(a), name(b))));
    }
    match (args.origin, args.normal) {
        (origin, Some(normal)) => {
            let origin = match origin {
                Some(o) => DVec3::from_array(o) * BOHR_PER_ANGSTROM,
                None => m.bounds().map_or(DVec3::ZERO, |(lo, hi)| 0.5 * (lo + hi)),
            };
            let frame = Frame::from_normal(origin, DVec3::from_array(normal))?;
            let [x, y, z] = normal;
            Ok((frame, args.origin.is_some(), format!("plane with normal ({x}, {y}, {z})")))
        }
        (Some(_), None) => bail!("--origin X,Y,Z needs --normal X,Y,Z"),
        (None, None) => {
            bail!(
                "which plane? --through A,B,C (three atoms), --bond A,B --toward X,Y,Z, or --origin X,Y,Z --normal X,Y,Z"
            )
        }
    }
}

/// The last part of a path, for captions.
fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned())
}
