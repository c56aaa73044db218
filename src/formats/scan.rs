//! Scan manifests (`*.scan.toml`): key frames, each a value of the scan's coordinate and the
//! file(s) holding that frame's orbitals. Paths are relative to the manifest.
//!
//! ```toml
//! title = "water bending"
//! coordinate = "angle"             # distance (Å) | angle (°) | dihedral (°) | path
//! atoms = [2, 1, 3]                # atom numbers, 1-based; none for a path
//! orbitals = ["homo", "lumo"]      # default; also "homo-1", "lumo+2", an index
//! follow = "index"                 # or "overlap": follow each orbital's character
//! captions = ["RHF", "B3LYP"]      # optional, one per view
//!
//! [[frame]]
//! at = 95.0
//! file = "h2o_a095.molden"         # Molden or fchk, for every view; or one per view:
//! # files = ["rhf/a095.molden", "b3lyp/a095.molden"]
//!
//! [[frame]]
//! at = 105.0
//! cubes = ["homo_a105.cube", "lumo_a105.cube"]   # or one cube per orbital
//! ```
//!
//! Older manifests name a dihedral scan `dihedral = [i, j, k, l]` with frames at `angle = A`;
//! they read as before.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::{LoadError, ParseError};
pub use crate::model::scan::Follow;
use crate::model::scan::{
    ANGLE_TOLERANCE, Coordinate, FrameContent, KeyFrame, MAX_KEY_FRAMES, MAX_SCAN_ORBITALS, PathMeasure, Scan,
    best_coordinate, path_values,
};
use crate::model::{Document, Molecule};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    title: Option<String>,
    /// distance | angle | dihedral | path.
    coordinate: Option<toml::Spanned<String>>,
    /// The coordinate's atoms, 1-based.
    atoms: Option<toml::Spanned<Vec<usize>>>,
    /// A path's frames rotated onto each other.
    align: Option<toml::Spanned<bool>>,
    /// What a path's values count: "frame" (the default), "arc length" or "mass-weighted arc
    /// length".
    measure: Option<toml::Spanned<String>>,
    /// The older way to name a dihedral scan.
    dihedral: Option<toml::Spanned<Vec<usize>>>,
    /// The orbitals shown side by side (default: HOMO and LUMO).
    orbitals: Option<toml::Spanned<Vec<String>>>,
    #[serde(default)]
    follow: Follow,
    /// A caption per view, e.g. ["RHF", "B3LYP"] when each view reads its own files.
    #[serde(default)]
    captions: Vec<String>,
    #[serde(rename = "frame", default)]
    frames: Vec<toml::Spanned<FrameEntry>>,
    /// How `scan compute` made the frames: a record, never acted on when read.
    computed: Option<Computed>,
}

/// How a computed scan was made (`scan compute`): the level of theory, rigid or relaxed, the
/// input, the programs' versions and the values whose frames failed. Reading a manifest never
/// recomputes anything: this is a record for the user.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Computed {
    pub method: String,
    pub basis: String,
    #[serde(default)]
    pub charge: i32,
    #[serde(default)]
    pub spin: u32,
    #[serde(default)]
    pub relaxed: bool,
    /// The input geometry's file, as given.
    #[serde(default)]
    pub input: String,
    #[serde(default)]
    pub versions: std::collections::BTreeMap<String, String>,
    /// Values whose frame did not converge (left out of the scan).
    #[serde(default)]
    pub failed: Vec<f64>,
}

impl Computed {
    /// The `[computed]` table as a manifest holds it.
    fn toml(&self) -> String {
        let q = |s: &str| format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""));
        let mut out = format!(
            "\n[computed]\nmethod = {}\nbasis = {}\ncharge = {}\nspin = {}\nrelaxed = {}\ninput = {}\n",
            q(&self.method),
            q(&self.basis),
            self.charge,
            self.spin,
            self.relaxed,
            q(&self.input)
        );
        let failed: Vec<String> = self.failed.iter().map(|v| format!("{v:.4}")).collect();
        out.push_str(&format!("failed = [{}]\n", failed.join(", ")));
        let versions: Vec<String> = self.versions.iter().map(|(k, v)| format!("{k} = {}", q(v))).collect();
        out.push_str(&format!("versions = {{ {} }}\n", versions.join(", ")));
        out
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameEntry {
    /// The coordinate's value (`angle` in older manifests).
    #[serde(alias = "angle")]
    at: f64,
    file: Option<String>,
    /// One Molden/fchk file per orbital slot: the same orbital from two methods side by side.
    files: Option<Vec<String>>,
    cubes: Option<Vec<String>>,
}

fn default_orbitals() -> Vec<String> {
    vec!["homo".into(), "lumo".into()]
}

/// A scan as its manifest asks for it.
#[derive(Debug, Clone)]
pub struct ScanFile {
    pub scan: Scan,
    pub follow: Follow,
    /// How `scan compute` made it, when it did.
    pub computed: Option<Computed>,
}

fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

fn error(file: &str, line: usize, expected: impl Into<String>, found: impl Into<String>) -> ParseError {
    ParseError { file: file.into(), line, expected: expected.into(), found: found.into() }
}

/// Whether two molecules have the same elements in the same order.
fn same_atoms(a: &Molecule, b: &Molecule) -> bool {
    a.atoms.len() == b.atoms.len() && a.atoms.iter().zip(&b.atoms).all(|(x, y)| x.z == y.z)
}

/// "C5H8N, 14 atoms" — enough to tell two molecules apart in a message.
fn describe(m: &Molecule) -> String {
    format!("{}, {} atoms", m.formula(), m.atoms.len())
}

/// Reads a manifest and every frame it names.
pub fn load_scan(path: &Path) -> Result<ScanFile, LoadError> {
    let text = super::read_text(path)?;
    parse_scan(path, &text, &mut |p| super::load(p))
}

/// Parses manifest `text` (read from `path`), loading frames through `load` (tests substitute
/// their own).
pub fn parse_scan(
    path: &Path,
    text: &str,
    load: &mut dyn FnMut(&Path) -> Result<Document, LoadError>,
) -> Result<ScanFile, LoadError> {
    let name = path.display().to_string();
    let manifest: Manifest = toml::from_str(text).map_err(|e| {
        let line = e.span().map_or(1, |s| line_of(text, s.start));
        error(&name, line, "a scan manifest (title, dihedral, orbitals, [[frame]] angle + file or cubes)", e.message())
    })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let (coordinate, coordinate_line) = coordinate_of(&name, text, &manifest)?;
    if manifest.frames.len() < 2 {
        return Err(error(
            &name,
            line_of(text, text.len()),
            "at least two [[frame]] entries",
            manifest.frames.len().to_string(),
        )
        .into());
    }
    if let Some(extra) = manifest.frames.get(MAX_KEY_FRAMES) {
        let found = format!("{} frames", manifest.frames.len());
        return Err(error(
            &name,
            line_of(text, extra.span().start),
            format!("at most {MAX_KEY_FRAMES} [[frame]] entries"),
            found,
        )
        .into());
    }
    let (orbitals, orbitals_line) = match &manifest.orbitals {
        Some(o) => (o.get_ref().clone(), line_of(text, o.span().start)),
        None => (default_orbitals(), 1),
    };
    if !(1..=MAX_SCAN_ORBITALS).contains(&orbitals.len()) {
        let expected = format!("1 to {MAX_SCAN_ORBITALS} orbitals = [\"homo\", …]");
        return Err(error(&name, orbitals_line, expected, format!("{} orbitals", orbitals.len())).into());
    }
    let range = coordinate.value_range();
    let mut frames: Vec<(usize, KeyFrame)> = Vec::with_capacity(manifest.frames.len());
    let mut first_kind: Option<bool> = None;
    for spanned in &manifest.frames {
        let line = line_of(text, spanned.span().start);
        let entry = spanned.get_ref();
        let named = |e| LoadError::Named { manifest: name.clone(), line, inner: Box::new(e) };
        if !range.contains(&entry.at) {
            let expected = format!(
                "a value of the {} in {}..={}{} (at = …)",
                coordinate.kind(),
                range.start(),
                range.end(),
                coordinate.unit()
            );
            return Err(error(&name, line, expected, format!("at = {:?}", entry.at)).into());
        }
        let single = entry.file.as_ref().map(std::slice::from_ref);
        let files =
            if entry.file.is_some() && entry.files.is_some() { None } else { single.or(entry.files.as_deref()) };
        let (molecule, content, source) = match (files, &entry.cubes) {
            (Some(files), None) if !files.is_empty() => {
                if entry.file.is_none() && files.len() != orbitals.len() {
                    return Err(error(
                        &name,
                        line,
                        format!("one file per orbital ({})", orbitals.len()),
                        format!("{} files", files.len()),
                    )
                    .into());
                }
                let mut molecule: Option<Molecule> = None;
                let mut wavefunctions = Vec::with_capacity(files.len());
                for file in files {
                    let doc = load(&dir.join(file)).map_err(named)?;
                    let Some(wf) = doc.wavefunction else {
                        return Err(error(&name, line, "a Molden or fchk file with orbitals", file.clone()).into());
                    };
                    if let Some(m) = &molecule
                        && !same_atoms(m, &doc.molecule)
                    {
                        return Err(error(&name, line, format!("the atoms of {}", files[0]), file.clone()).into());
                    }
                    molecule.get_or_insert(doc.molecule);
                    wavefunctions.push(wf);
                }
                (molecule.unwrap_or_default(), FrameContent::Wavefunctions(wavefunctions), files.join(", "))
            }
            (None, Some(cubes)) if !cubes.is_empty() && entry.files.is_none() => {
                let mut molecule = None;
                let mut volumes = Vec::new();
                for cube in cubes {
                    let doc = load(&dir.join(cube)).map_err(named)?;
                    molecule.get_or_insert(doc.molecule);
                    volumes.extend(doc.volumes);
                }
                (molecule.unwrap_or_default(), FrameContent::Volumes(volumes), cubes.join(", "))
            }
            _ => {
                return Err(error(
                    &name,
                    line,
                    "a frame with one of file = \"…\", files = [\"…\", …] or cubes = [\"…\", …]",
                    "both or neither",
                )
                .into());
            }
        };
        let is_cube = matches!(content, FrameContent::Volumes(_));
        if *first_kind.get_or_insert(is_cube) != is_cube {
            return Err(error(
                &name,
                line,
                "every frame from the same kind of file (all Molden/fchk or all cubes)",
                source,
            )
            .into());
        }
        frames.push((line, KeyFrame { at: entry.at, source, molecule, content }));
    }
    check_frames(&name, &frames)?;
    frames.sort_by(|a, b| a.1.at.total_cmp(&b.1.at));
    if manifest.align.as_ref().is_some_and(|a| *a.get_ref()) {
        let line = manifest.align.as_ref().map_or(1, |a| line_of(text, a.span().start));
        let mut keys: Vec<&mut KeyFrame> = frames.iter_mut().map(|(_, f)| f).collect();
        crate::model::scan::align_frames(&mut keys)
            .map_err(|e| error(&name, line, "Molden or fchk frames to align", e.to_string()))?;
    }
    for pair in frames.windows(2) {
        let ((l0, f0), (l1, f1)) = (&pair[0], &pair[1]);
        if (f1.at - f0.at).abs() < ANGLE_TOLERANCE {
            let (first, second) = if l0 < l1 { (l0, l1) } else { (l1, l0) };
            return Err(error(
                &name,
                *second,
                format!("a value different from the frame on line {first}"),
                format!("at = {}", f1.at),
            )
            .into());
        }
    }
    let title = manifest
        .title
        .unwrap_or_else(|| path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default());
    let mut scan =
        Scan::new(title, coordinate, orbitals, frames.into_iter().map(|(_, f)| f).collect()).map_err(|e| {
            let expected = format!("a {} whose atoms can move on one side of a bond", coordinate.kind());
            error(&name, coordinate_line, expected, e.to_string())
        })?;
    scan.captions = manifest.captions;
    // Resolving the orbitals of every frame reports a missing one before anything is evaluated.
    scan.check_orbitals().map_err(|e| error(&name, 1, "the orbitals the manifest names", e.to_string()))?;
    Ok(ScanFile { scan, follow: manifest.follow, computed: manifest.computed })
}

/// The manifest's coordinate (0-based atoms) and the line that names it: `coordinate` and
/// `atoms`, or an older manifest's `dihedral`.
fn coordinate_of(name: &str, text: &str, m: &Manifest) -> Result<(Coordinate, usize), ParseError> {
    let line_at = |span: std::ops::Range<usize>| line_of(text, span.start);
    let (kind, kind_line) = match (&m.coordinate, &m.dihedral) {
        (Some(c), None) => (c.get_ref().as_str(), line_at(c.span())),
        (None, Some(d)) => ("dihedral", line_at(d.span())),
        (Some(c), Some(_)) => {
            return Err(error(name, line_at(c.span()), "coordinate = … with atoms = […], or dihedral = […]", "both"));
        }
        (None, None) => {
            return Err(error(
                name,
                1,
                "coordinate = \"distance\" | \"angle\" | \"dihedral\" | \"path\" (with atoms = […])",
                "no coordinate",
            ));
        }
    };
    let atoms = match (&m.atoms, &m.dihedral) {
        (Some(a), _) => Some((a.get_ref().clone(), line_at(a.span()))),
        (None, Some(d)) => Some((d.get_ref().clone(), line_at(d.span()))),
        (None, None) => None,
    };
    let wanted = match kind {
        "distance" => 2,
        "angle" => 3,
        "dihedral" => 4,
        "path" => 0,
        other => {
            return Err(error(name, kind_line, "distance, angle, dihedral or path", format!("{other:?}")));
        }
    };
    if let Some(align) = &m.align
        && *align.get_ref()
        && kind != "path"
    {
        return Err(error(name, line_at(align.span()), "align only for a path", format!("align with a {kind}")));
    }
    let measure = match &m.measure {
        None => PathMeasure::Frame,
        Some(_) if kind != "path" => {
            return Err(error(name, kind_line, "measure only for a path", format!("measure with a {kind}")));
        }
        Some(v) => PathMeasure::from_name(v.get_ref()).ok_or_else(|| {
            error(
                name,
                line_at(v.span()),
                "measure = \"frame\", \"arc length\" or \"mass-weighted arc length\"",
                format!("{:?}", v.get_ref()),
            )
        })?,
    };
    let (list, line) = atoms.unwrap_or((Vec::new(), kind_line));
    if list.len() != wanted || list.contains(&0) {
        let expected = match wanted {
            0 => "no atoms for a path".to_string(),
            n => format!("{n} atom numbers counted from 1 for a {kind}"),
        };
        return Err(error(name, line, expected, format!("{list:?}")));
    }
    let a: Vec<usize> = list.iter().map(|i| i - 1).collect();
    let coordinate = match wanted {
        2 => Coordinate::Distance([a[0], a[1]]),
        3 => Coordinate::Angle([a[0], a[1], a[2]]),
        4 => Coordinate::Dihedral([a[0], a[1], a[2], a[3]]),
        _ => Coordinate::Path(measure),
    };
    Ok((coordinate, line))
}

/// Every frame must hold the first frame's atoms; cube series must share one grid.
fn check_frames(name: &str, frames: &[(usize, KeyFrame)]) -> Result<(), ParseError> {
    let Some((_, first)) = frames.first() else { return Ok(()) };
    let same_atoms = |m: &Molecule| same_atoms(m, &first.molecule);
    let first_grid = match &first.content {
        FrameContent::Volumes(v) => v.first(),
        FrameContent::Wavefunctions(_) => None,
    };
    for (line, frame) in frames {
        if !same_atoms(&frame.molecule) {
            return Err(error(
                name,
                *line,
                format!("the atoms of the first frame, in its order ({}: {})", first.source, describe(&first.molecule)),
                format!("{}: {}", frame.source, describe(&frame.molecule)),
            ));
        }
        if let (Some(g0), FrameContent::Volumes(volumes)) = (first_grid, &frame.content) {
            for g in volumes {
                let same = g.dims == g0.dims && g.world_from_grid.abs_diff_eq(g0.world_from_grid, 1e-6);
                if !same {
                    return Err(error(
                        name,
                        *line,
                        format!(
                            "the grid of {} ({:?} points, origin {:.4})",
                            first.source,
                            g0.dims,
                            g0.world_from_grid.w_axis.truncate()
                        ),
                        format!(
                            "{} on {:?} points, origin {:.4}",
                            frame.source,
                            g.dims,
                            g.world_from_grid.w_axis.truncate()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// A manifest written by [`init`].
#[derive(Debug, Clone)]
pub struct ScanInit {
    pub path: PathBuf,
    pub text: String,
    /// The coordinate chosen (0-based atoms).
    pub coordinate: Coordinate,
    /// Whether it was found (not given).
    pub found: bool,
    /// (file name, value) in scan order.
    pub frames: Vec<(String, f64)>,
}

/// Whether a file name is a wavefunction the readers take as a scan's frame (Molden or fchk,
/// maybe gzipped), by the endings the format table gives them.
fn is_wavefunction_file(name: &str) -> bool {
    super::is_molden_or_fchk(name)
}

/// Builds `DIR/<dir name>.scan.toml` from the Molden/fchk files in `dir`: each frame's value is
/// the coordinate measured in its geometry — the one given (0-based atoms), or the bonded
/// distance, angle or dihedral that explains the change across the frames best, or a path
/// (frames in file-name order) when none does ([`best_coordinate`]) — frames sorted by value.
/// The text is returned, not written.
pub fn init(dir: &Path, coordinate: Option<Coordinate>) -> Result<ScanInit, LoadError> {
    let io = |source| LoadError::Io { path: dir.display().to_string(), source };
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map_err(io)?
        .filter_map(std::result::Result::ok)
        .filter(|e| e.path().is_file())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| is_wavefunction_file(n))
        .collect();
    names.sort();
    let dir_name = dir
        .canonicalize()
        .ok()
        .and_then(|d| d.file_name().map(|s| s.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "scan".into());
    let manifest_path = dir.join(format!("{dir_name}.scan.toml"));
    let name = dir.display().to_string();
    if names.len() < 2 {
        // A Gaussian scan job's fchk holds every point's geometry but orbitals for the last
        // only: say so rather than "one file".
        if let [only] = names.as_slice()
            && only.to_ascii_lowercase().contains(".fch")
        {
            let path = dir.join(only);
            let text = super::read_text(&path)?;
            let n = super::fchk::geometries(&path.display().to_string(), &text)?.len();
            if n > 1 {
                return Err(error(
                    &path.display().to_string(),
                    0,
                    "one Molden or fchk file per angle (a scan job's fchk holds orbitals for its last geometry \
                     only: keep a checkpoint per point and run formchk on each, or compute the frames' orbitals \
                     with `orbcloud scan compute FILE --frames`)",
                    format!("{n} geometries in one file"),
                )
                .into());
            }
        }
        return Err(error(
            &name,
            0,
            "a directory with at least two Molden or fchk files",
            format!("{} such files", names.len()),
        )
        .into());
    }
    let mut molecules = Vec::with_capacity(names.len());
    for n in &names {
        let doc = super::load(&dir.join(n))?;
        if let Some(m0) = molecules.first() {
            let m0: &Molecule = m0;
            if !same_atoms(m0, &doc.molecule) {
                return Err(error(
                    &dir.join(n).display().to_string(),
                    0,
                    format!("the atoms of {} ({})", names[0], describe(m0)),
                    describe(&doc.molecule),
                )
                .into());
            }
        }
        molecules.push(doc.molecule);
    }
    let n_atoms = molecules[0].atoms.len();
    let found = coordinate.is_none();
    let coordinate = match coordinate {
        Some(c) => {
            if let Some(&bad) = c.atoms().iter().find(|&&i| i >= n_atoms) {
                let expected = format!("{} atoms between 1 and {n_atoms}", c.kind());
                return Err(error(&name, 0, expected, (bad + 1).to_string()).into());
            }
            c
        }
        None => best_coordinate(&molecules)
            .ok_or_else(|| error(&name, 0, "frames whose geometries differ", "the same geometry in every file"))?,
    };
    let values: Vec<f64> = match coordinate {
        // A path's frames in the order a multi-frame XYZ file beside them gives (each file at
        // the frame of the path it matches), or of their names; then measured along it.
        Coordinate::Path(measure) => {
            let order =
                path_order(dir, &molecules)?.unwrap_or_else(|| (0..molecules.len()).map(|i| i as f64).collect());
            let mut in_order: Vec<usize> = (0..molecules.len()).collect();
            in_order.sort_by(|&a, &b| order[a].total_cmp(&order[b]));
            let along = path_values(&in_order.iter().map(|&i| molecules[i].clone()).collect::<Vec<_>>(), measure);
            let mut values = vec![0.0; molecules.len()];
            for (&file, value) in in_order.iter().zip(along) {
                values[file] = value;
            }
            values
        }
        Coordinate::Dihedral(_) => {
            unwrap_angles(&molecules.iter().filter_map(|m| coordinate.measure(m)).collect::<Vec<_>>())
        }
        _ => molecules.iter().filter_map(|m| coordinate.measure(m)).collect(),
    };
    let mut frames: Vec<(String, f64)> = names.into_iter().zip(values).collect();
    frames.sort_by(|a, b| a.1.total_cmp(&b.1));
    for w in frames.windows(2) {
        if (w[1].1 - w[0].1).abs() < ANGLE_TOLERANCE {
            return Err(error(
                &dir.join(&w[1].0).display().to_string(),
                0,
                format!("a {} different from {}'s", coordinate.kind(), w[0].0),
                format!("{} in both", coordinate.value_text(w[1].1)),
            )
            .into());
        }
    }
    let how = if found { "the coordinate that explains the change best" } else { "the coordinate given" };
    let header = format!("Written by `orbcloud scan init`: {how}, measured in each file's geometry.");
    let text = manifest_text(&header, &dir_name, &coordinate, &frames, None);
    Ok(ScanInit { path: manifest_path, text, coordinate, found, frames })
}

/// A manifest's text: a comment, the title, the coordinate, HOMO and LUMO, one `[[frame]]` per
/// (file, value), and how the frames were computed when they were.
pub fn manifest_text(
    header: &str,
    title: &str,
    coordinate: &Coordinate,
    frames: &[(String, f64)],
    computed: Option<&Computed>,
) -> String {
    let q = |s: &str| s.replace('\\', "\\\\").replace('"', "\\\"");
    let mut text = format!("# {header}\ntitle = \"{}\"\ncoordinate = \"{}\"\n", q(title), coordinate.kind());
    if !coordinate.atoms().is_empty() {
        let atoms: Vec<String> = coordinate.atoms().iter().map(|i| (i + 1).to_string()).collect();
        text.push_str(&format!("atoms = [{}]\n", atoms.join(", ")));
    }
    if let Coordinate::Path(measure @ (PathMeasure::ArcLength | PathMeasure::MassWeighted)) = coordinate {
        text.push_str(&format!("measure = \"{}\"\n", measure.name()));
    }
    text.push_str("orbitals = [\"homo\", \"lumo\"]\n");
    for (file, value) in frames {
        text.push_str(&format!("\n[[frame]]\nat = {value:.4}\nfile = \"{}\"\n", q(file)));
    }
    if let Some(c) = computed {
        text.push_str(&c.toml());
    }
    text
}

/// Where each of `molecules` lies along the path a multi-frame XYZ file in `dir` traces (the
/// frame whose geometry it matches, by interatomic distances, whatever the orientation); None
/// when `dir` holds no such file. Two files matching one frame, or a file matching none (within
/// 0.05 Å RMS), are errors.
fn path_order(dir: &Path, molecules: &[Molecule]) -> Result<Option<Vec<f64>>, LoadError> {
    let xyz = std::fs::read_dir(dir)
        .map_err(|source| LoadError::Io { path: dir.display().to_string(), source })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.to_string_lossy().to_ascii_lowercase().trim_end_matches(".gz").ends_with(".xyz"));
    let n = molecules.first().map_or(0, |m| m.atoms.len());
    for path in xyz {
        let doc = super::load(&path)?;
        let Some(s) = doc.structure.as_ref().map(|v| &v.structure).filter(|s| s.models.len() > 1) else { continue };
        let frames = s.model_positions(n);
        if frames.len() < 2 {
            continue;
        }
        let name = path.display().to_string();
        let mut order = Vec::with_capacity(molecules.len());
        for (i, m) in molecules.iter().enumerate() {
            let here: Vec<glam::DVec3> = m.atoms.iter().map(|a| a.position).collect();
            let (frame, off) = (frames.iter().enumerate())
                .map(|(f, p)| (f, crate::model::scan::distance_change(&here, p)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap_or((0, f64::INFINITY));
            if off > 0.05 {
                return Err(error(
                    &name,
                    0,
                    format!("a frame matching file {} of the path", i + 1),
                    format!("{off:.3} Å RMS from the nearest"),
                )
                .into());
            }
            if order.contains(&(frame as f64)) {
                return Err(error(&name, 0, "one frame per file", format!("two files at frame {}", frame + 1)).into());
            }
            order.push(frame as f64);
        }
        return Ok(Some(order));
    }
    Ok(None)
}

/// Dihedrals measured in (−180, 180] made continuous: the sequence starts after the largest gap
/// around the circle, so a scan from −180 to 0 is not split at ±180.
fn unwrap_angles(measured: &[f64]) -> Vec<f64> {
    let mut sorted: Vec<f64> = measured.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    if n < 2 {
        return measured.to_vec();
    }
    // Gap after sorted[i] (the last one wraps around).
    let gap = |i: usize| if i + 1 < n { sorted[i + 1] - sorted[i] } else { sorted[0] + 360.0 - sorted[n - 1] };
    let widest = (0..n).max_by(|&a, &b| gap(a).total_cmp(&gap(b))).unwrap_or(n - 1);
    if widest == n - 1 {
        return measured.to_vec();
    }
    // Angles at or below the gap's start go round once; then centre the range on zero.
    let cut = sorted[widest];
    let shifted: Vec<f64> = measured.iter().map(|&a| if a <= cut { a + 360.0 } else { a }).collect();
    let mid = (sorted[widest + 1] + cut + 360.0) / 2.0;
    if mid > 180.0 { shifted.iter().map(|a| a - 360.0).collect() } else { shifted }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unwrapping_keeps_a_scan_through_180_together() {
        let u = unwrap_angles(&[180.0, -150.0, -90.0, 0.0]);
        assert_eq!(u, vec![-180.0, -150.0, -90.0, 0.0]);
        assert_eq!(unwrap_angles(&[-60.0, 0.0, 60.0]), vec![-60.0, 0.0, 60.0]);
        let u = unwrap_angles(&[170.0, -170.0, 150.0]);
        assert_eq!(u, vec![170.0, 190.0, 150.0]);
    }

    /// The error `text` gives as a manifest whose files all load as H–O–O–H atoms, counting the
    /// frames it loaded.
    fn refused(text: &str) -> (ParseError, usize) {
        let atom =
            |z, x, y, w| crate::model::Atom { z, charge: z as f64, position: glam::DVec3::new(x, y, w), ghost: false };
        let frame = Document {
            molecule: Molecule::new(vec![
                atom(1, -1.8, 1.5, 0.0),
                atom(8, -1.4, 0.0, 0.0),
                atom(8, 1.4, 0.0, 0.0),
                atom(1, 1.8, 1.5, 0.5),
            ]),
            ..Document::default()
        };
        let mut loaded = 0;
        let e = parse_scan(Path::new("m.scan.toml"), text, &mut |_| {
            loaded += 1;
            Ok(frame.clone())
        });
        match e {
            Err(LoadError::Parse(e)) => (e, loaded),
            Err(other) => panic!("{other}"),
            Ok(_) => panic!("accepted:\n{text}"),
        }
    }

    #[test]
    fn values_and_counts_out_of_range_are_refused_at_their_line() {
        let frames = |values: &[&str]| -> String {
            values.iter().map(|v| format!("\n[[frame]]\nat = {v}\ncubes = [\"f.cube\"]\n")).collect()
        };
        let cases = [
            ("coordinate = \"dihedral\"\natoms = [1, 2, 3, 4]\n", ["-90", "1e300"], "the dihedral in -720..=720°"),
            ("coordinate = \"distance\"\natoms = [2, 3]\n", ["1.4", "-1.0"], "the distance in 0..=1000 Å"),
            ("coordinate = \"angle\"\natoms = [1, 2, 3]\n", ["100", "200"], "the angle in 0..=180°"),
            ("coordinate = \"path\"\n", ["0", "nan"], "the path in"),
        ];
        for (head, values, expected) in cases {
            let text = format!("{head}{}", frames(&values));
            let (e, _) = refused(&text);
            let line = text.lines().position(|l| l == format!("at = {}", values[1])).unwrap();
            assert_eq!((e.file.as_str(), e.line), ("m.scan.toml", line), "{e}");
            let at: f64 = values[1].parse().unwrap();
            assert!(e.expected.contains(expected) && e.found == format!("at = {at:?}"), "{e}");
        }
        let head = "coordinate = \"dihedral\"\natoms = [1, 2, 3, 4]\n";
        let (e, _) = refused(&format!("{head}orbitals = []\n{}", frames(&["0", "90"])));
        assert_eq!(e.line, 3, "{e}");
        assert!(e.expected.contains("1 to 16 orbitals") && e.found == "0 orbitals", "{e}");
        let many: Vec<String> = (0..17).map(|k| format!("\"homo-{k}\"")).collect();
        let (e, _) = refused(&format!("{head}orbitals = [{}]\n{}", many.join(", "), frames(&["0", "90"])));
        assert!(e.line == 3 && e.found == "17 orbitals", "{e}");
        // Too many frames are refused before any file is loaded.
        let values: Vec<String> = (0..=MAX_KEY_FRAMES).map(|k| format!("{}", k as f64 * 0.1)).collect();
        let text = format!("{head}{}", frames(&values.iter().map(String::as_str).collect::<Vec<_>>()));
        let (e, loaded) = refused(&text);
        assert_eq!(loaded, 0);
        assert_eq!(e.line, 3 + 4 * MAX_KEY_FRAMES + 1, "{e}");
        assert!(e.expected.contains("at most 1000 [[frame]]"), "{e}");
    }

    #[test]
    fn wavefunction_files_are_recognised() {
        assert!(is_wavefunction_file("a.molden.gz"));
        assert!(is_wavefunction_file("B.FCHK"));
        assert!(!is_wavefunction_file("a.cube"));
        assert!(!is_wavefunction_file("a.scan.toml"));
    }
}
