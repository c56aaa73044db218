//! Wavefunctions computed with PySCF: the jobs orbcloud hands to Python and the events Python
//! reports back.
//!
//! The computing lives in the Python package (`python/orbcloud/_compute.py`, embedded here):
//! the `compute` and `scan compute` commands and the viewer run it with the interpreter that
//! `ORBCLOUD_PYTHON` names (default `python3`), which needs PySCF (geomeTRIC for relaxed scans,
//! Dask for a cluster). Nothing here runs unless asked: opening a file, a manifest or a session
//! never computes, and the only scheduler contacted is the address a user typed.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::formats::scan::{Computed, manifest_text};
use crate::model::scan::{Coordinate, ScanError, rigid_frames, wrap_degrees};
use crate::model::units::ANGSTROM_PER_BOHR;
use crate::model::{Document, Molecule};

/// The Python side: a module of the `orbcloud` package and the script the commands run.
pub const SCRIPT: &str = include_str!("../../python/orbcloud/_compute.py");

/// What every computing error that lacks a package tells the user to install.
pub const INSTALL: &str = "pip install pyscf geometric 'dask[distributed]'";

/// How a wavefunction is computed: the method (HF or any functional PySCF knows), the basis by
/// name, charge and spin (2S; open shells are unrestricted).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    pub method: String,
    pub basis: String,
    pub charge: i32,
    pub spin: u32,
    /// SCF cycles before a frame counts as not converged.
    pub max_cycles: u32,
    /// Each frame a constrained optimisation with the coordinate held (geomeTRIC).
    pub relaxed: bool,
    /// The Hessian's normal modes written with the orbitals.
    pub freq: bool,
    /// gpu4pyscf on a CUDA GPU.
    pub gpu: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            method: "b3lyp".into(),
            basis: "6-31g*".into(),
            charge: 0,
            spin: 0,
            max_cycles: 100,
            relaxed: false,
            freq: false,
            gpu: false,
        }
    }
}

impl Settings {
    /// "B3LYP/6-31G*", "UHF/STO-3G" — as chemists write a level of theory.
    pub fn level(&self) -> String {
        let method = self.method.to_uppercase();
        let method = match method.as_str() {
            "HF" if self.spin > 0 => "UHF".to_string(),
            _ => method,
        };
        format!("{method}/{}", self.basis.to_uppercase())
    }
}

/// One geometry to compute: the file it becomes and the coordinate's value there.
#[derive(Debug, Clone, Serialize)]
pub struct FrameJob {
    pub file: String,
    pub at: f64,
    pub symbols: Vec<String>,
    pub angstrom: Vec<[f64; 3]>,
}

impl FrameJob {
    /// `molecule` (bohr) as a frame named `file` at `at`.
    pub fn new(file: String, at: f64, molecule: &Molecule) -> Self {
        Self {
            file,
            at,
            symbols: molecule.atoms.iter().map(|a| a.element().symbol.to_string()).collect(),
            angstrom: molecule.atoms.iter().map(|a| (a.position * ANGSTROM_PER_BOHR).to_array()).collect(),
        }
    }
}

/// The coordinate a relaxed scan holds, as geomeTRIC's constraints name it (1-based atoms).
#[derive(Debug, Clone, Serialize)]
pub struct Held {
    pub kind: &'static str,
    pub atoms: Vec<usize>,
}

impl Held {
    pub fn of(coordinate: &Coordinate) -> Option<Self> {
        (!coordinate.atoms().is_empty())
            .then(|| Self { kind: coordinate.kind(), atoms: coordinate.atoms().iter().map(|a| a + 1).collect() })
    }
}

/// A job for the Python side: settings, frames and where they go.
#[derive(Debug, Clone, Serialize)]
pub struct Job {
    #[serde(flatten)]
    pub settings: Settings,
    pub coordinate: Option<Held>,
    /// The frame nearest the input geometry: chains of frames run outward from it.
    pub start: usize,
    /// Where the frames' Molden files are written.
    pub dir: PathBuf,
    /// Where what PySCF and geomeTRIC print goes (none: nowhere).
    pub output: Option<PathBuf>,
    /// Local cores: frames run in as many processes, one core each, or fewer processes with
    /// more threads when fewer chains of frames can run at once (ignored with a Dask scheduler).
    pub workers: usize,
    /// A Dask scheduler's address.
    pub dask: Option<String>,
    pub frames: Vec<FrameJob>,
}

/// How a frame ended.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct FrameReport {
    pub index: usize,
    pub at: f64,
    pub file: String,
    pub ok: bool,
    #[serde(default)]
    pub energy: Option<f64>,
    #[serde(default)]
    pub cycles: Option<u32>,
    #[serde(default)]
    pub seconds: f64,
    #[serde(default)]
    pub error: Option<String>,
    /// Computed by an earlier run with the same settings and kept.
    #[serde(default)]
    pub kept: bool,
}

/// What the Python side reports, a line each.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "event", rename_all = "lowercase")]
pub enum Event {
    Start { frames: usize, kept: usize, versions: BTreeMap<String, String> },
    Frame(FrameReport),
    Done { computed: usize, kept: usize, failed: usize },
    Error { message: String },
}

#[derive(Debug, Error)]
pub enum ComputeError {
    #[error(
        "no Python at `{python}` ({source}): install python3 and {INSTALL}, or name an interpreter in ORBCLOUD_PYTHON"
    )]
    NoPython { python: String, source: std::io::Error },
    #[error("{0}")]
    Failed(String),
    #[error("the computation was cancelled")]
    Cancelled,
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
}

/// This machine's cores: what computing uses unless told otherwise.
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZero::get)
}

/// The interpreter that computes: `ORBCLOUD_PYTHON`, or `python3`.
pub fn python() -> String {
    std::env::var("ORBCLOUD_PYTHON").ok().filter(|s| !s.trim().is_empty()).unwrap_or_else(|| "python3".into())
}

/// A fresh folder for one run's script and job, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new() -> Result<Self, ComputeError> {
        static RUNS: AtomicU64 = AtomicU64::new(0);
        let n = RUNS.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("orbcloud-compute-{}-{n}", std::process::id()));
        std::fs::create_dir_all(&dir).map_err(|source| io(&dir, source))?;
        Ok(Self(dir))
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn io(path: &Path, source: std::io::Error) -> ComputeError {
    ComputeError::Io { path: path.display().to_string(), source }
}

/// Runs `job` in Python, calling `on_event` with each event as it comes; `cancel` set ends the
/// run (its processes killed) with [`ComputeError::Cancelled`], keeping the frames already
/// written. Returns each frame's report (computed, kept or failed) in the order they came.
pub fn run(job: &Job, cancel: &AtomicBool, on_event: &mut dyn FnMut(&Event)) -> Result<Vec<FrameReport>, ComputeError> {
    let scratch = Scratch::new()?;
    let script = scratch.0.join("orbcloud_compute.py");
    std::fs::write(&script, SCRIPT).map_err(|source| io(&script, source))?;
    let job_path = scratch.0.join("job.json");
    let text = serde_json::to_string(job).map_err(|e| ComputeError::Failed(e.to_string()))?;
    std::fs::write(&job_path, text).map_err(|source| io(&job_path, source))?;
    let python = python();
    let mut command = Command::new(&python);
    command.arg(&script).arg(&job_path).stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::piped());
    // Its own process group, so a cancel reaches the worker processes too; its standard input
    // is a pipe never written, which closes when this process ends however it ends (Ctrl-C,
    // killed), and the script then ends its group.
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(&mut command, 0);
    let mut child = command.spawn().map_err(|source| ComputeError::NoPython { python: python.clone(), source })?;
    let _keep_open = child.stdin.take();
    let stdout = child.stdout.take().expect("piped");
    let mut stderr = child.stderr.take().expect("piped");
    let errors = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = stderr.read_to_string(&mut text);
        text
    });
    let (send, lines) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            if send.send(line).is_err() {
                break;
            }
        }
    });
    let mut reports = Vec::new();
    let mut failure = None;
    loop {
        if cancel.load(Ordering::Relaxed) {
            kill(&mut child);
            return Err(ComputeError::Cancelled);
        }
        match lines.recv_timeout(Duration::from_millis(100)) {
            Ok(Ok(line)) => match serde_json::from_str::<Event>(&line) {
                Ok(event) => {
                    match &event {
                        Event::Frame(r) => reports.push(r.clone()),
                        Event::Error { message } => failure = Some(message.clone()),
                        _ => {}
                    }
                    on_event(&event);
                }
                // Something a package printed before the script took the output over.
                Err(_) => log::info!("python: {line}"),
            },
            Ok(Err(_)) | Err(mpsc::RecvTimeoutError::Disconnected) => break,
            Err(mpsc::RecvTimeoutError::Timeout) => {}
        }
    }
    let status = child.wait().map_err(|source| ComputeError::NoPython { python: python.clone(), source })?;
    let stderr = errors.join().unwrap_or_default();
    if let Some(message) = failure {
        return Err(ComputeError::Failed(message));
    }
    if !status.success() {
        let tail: Vec<&str> = stderr.lines().rev().take(8).collect::<Vec<_>>().into_iter().rev().collect();
        return Err(ComputeError::Failed(format!("{python} ended with {status}: {}", tail.join("\n"))));
    }
    Ok(reports)
}

fn kill(child: &mut std::process::Child) {
    #[cfg(unix)]
    // SAFETY: kill(2) on the process group this module started; no memory is touched.
    unsafe {
        libc::kill(-(child.id() as i32), libc::SIGKILL);
    }
    let _ = child.kill();
    let _ = child.wait();
}

/// `values` from `from` to `to` by `step` (its sign taken from the direction), both ends kept
/// when the step divides the range (to a thousandth of a step).
pub fn values(from: f64, to: f64, step: f64) -> Result<Vec<f64>, String> {
    if !(from.is_finite() && to.is_finite() && step.is_finite()) || step == 0.0 {
        return Err(format!("--step {step}: a step other than zero"));
    }
    let step = step.abs() * if to < from { -1.0 } else { 1.0 };
    let n = ((to - from) / step + 1e-3).floor() as i64 + 1;
    if n > 1000 {
        return Err(format!("{n} frames from {from} to {to} by {step}: at most 1000"));
    }
    Ok((0..n).map(|i| from + i as f64 * step).collect())
}

/// The frames of a rigid scan of `coordinate` over `values` from `molecule`, named after
/// `stem`, and the index of the one nearest the input geometry (chains start there).
pub fn rigid_scan(
    molecule: &Molecule,
    coordinate: &Coordinate,
    values: &[f64],
    stem: &str,
) -> Result<(Vec<FrameJob>, usize), ScanError> {
    let molecules = rigid_frames(molecule, coordinate, values)?;
    let now = coordinate.measure(molecule).unwrap_or(0.0);
    let distance = |v: f64| match coordinate {
        Coordinate::Dihedral(_) => wrap_degrees(v - now).abs(),
        _ => (v - now).abs(),
    };
    let start = (0..values.len()).min_by(|&a, &b| distance(values[a]).total_cmp(&distance(values[b]))).unwrap_or(0);
    let frames =
        values.iter().zip(&molecules).map(|(&v, m)| FrameJob::new(frame_file(stem, coordinate, v), v, m)).collect();
    Ok((frames, start))
}

/// Every geometry of a multi-frame document (a trajectory, a program log's steps, an XYZ file's
/// frames) as a molecule with the document's atoms; the document's one geometry for any other.
pub fn frame_molecules(doc: &Document) -> Vec<Molecule> {
    let Some(s) = doc.structure.as_ref().map(|v| &v.structure).filter(|s| s.models.len() > 1) else {
        return vec![doc.molecule.clone()];
    };
    (s.model_positions(doc.molecule.atoms.len()).into_iter())
        .map(|positions| {
            let atoms = doc
                .molecule
                .atoms
                .iter()
                .zip(positions)
                .map(|(a, position)| crate::model::Atom { position, ..a.clone() });
            Molecule { atoms: atoms.collect(), bonds: doc.molecule.bonds.clone() }
        })
        .collect()
}

/// The frames of a scan job the document read ([`Document::job_scan`]: a Gaussian or ORCA relaxed
/// scan) as frames to compute, each at the job's value of its coordinate and named after it:
/// the geometries are the job's own, so each frame is a single point and nothing is moved or
/// optimised again. `None` when the document holds no scan job; an error when two frames would
/// share a value (and a file).
pub fn job_scan_frames(doc: &Document, stem: &str) -> Option<Result<(Coordinate, Vec<FrameJob>), String>> {
    let job = doc.job_scan.as_ref()?;
    let molecules = frame_molecules(doc);
    if molecules.len() != job.values.len() {
        return Some(Err(format!(
            "{}: {} frames and {} values of {}",
            doc.source,
            molecules.len(),
            job.values.len(),
            job.coordinate.label()
        )));
    }
    let mut frames: Vec<FrameJob> = Vec::with_capacity(molecules.len());
    for (m, &at) in molecules.iter().zip(&job.values) {
        let file = frame_file(stem, &job.coordinate, at);
        if frames.iter().any(|f| f.file == file) {
            return Some(Err(format!(
                "{}: two frames at {} of {}: a scan's frames lie at different values",
                doc.source,
                job.coordinate.value_text(at),
                job.coordinate.label()
            )));
        }
        frames.push(FrameJob::new(file, at, m));
    }
    frames.sort_by(|a, b| a.at.total_cmp(&b.at));
    Some(Ok((job.coordinate, frames)))
}

/// Writes `dir/<title>.scan.toml` naming the frames computed so far (file, value), with how
/// they were computed; returns its path.
pub fn write_manifest(
    dir: &Path,
    title: &str,
    coordinate: &Coordinate,
    settings: &Settings,
    done: &[(String, f64)],
    computed: Computed,
) -> Result<PathBuf, ComputeError> {
    let mut frames = done.to_vec();
    frames.sort_by(|a, b| a.1.total_cmp(&b.1));
    let how = if settings.relaxed { "relaxed" } else { "rigid" };
    let header = format!(
        "Written by `orbcloud scan compute`: {} {how} scan of {}, {} frames.",
        settings.level(),
        coordinate.label(),
        frames.len()
    );
    let text = manifest_text(&header, title, coordinate, &frames, Some(&computed));
    let path = dir.join(format!("{title}.scan.toml"));
    // Whole or not at all: the viewer may be reading the previous one.
    let part = dir.join(format!(".{title}.scan.toml.part"));
    std::fs::write(&part, text).map_err(|source| io(&part, source))?;
    std::fs::rename(&part, &path).map_err(|source| io(&path, source))?;
    Ok(path)
}

impl Computed {
    /// The record of a scan computed with `settings` from `input`.
    pub fn of(settings: &Settings, input: &str, versions: BTreeMap<String, String>, failed: Vec<f64>) -> Self {
        Self {
            method: settings.method.clone(),
            basis: settings.basis.clone(),
            charge: settings.charge,
            spin: settings.spin,
            relaxed: settings.relaxed,
            input: input.to_string(),
            versions,
            failed,
        }
    }
}

/// A file name's stem without its extensions: "h2o2" of "h2o2.xyz.gz".
pub fn stem(path: &Path) -> String {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let name = name.strip_suffix(".gz").unwrap_or(&name);
    name.split('.').next().filter(|s| !s.is_empty()).unwrap_or("frame").to_string()
}

/// A frame's file name: `stem_<kind><value>.molden` ("water_angle104.50.molden").
pub fn frame_file(stem: &str, coordinate: &Coordinate, value: f64) -> String {
    let v = match coordinate {
        Coordinate::Distance(_) => format!("{value:.3}"),
        Coordinate::Path(_) => format!("{:04}", value.round() as i64),
        _ => format!("{value:.2}"),
    };
    format!("{stem}_{}{}.molden", coordinate.kind(), v.replace('-', "m"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_keep_both_ends_and_follow_the_direction() {
        assert_eq!(values(0.0, 180.0, 45.0).unwrap(), vec![0.0, 45.0, 90.0, 135.0, 180.0]);
        assert_eq!(values(1.0, 0.5, 0.25).unwrap(), vec![1.0, 0.75, 0.5]);
        assert_eq!(values(0.0, 100.0, 30.0).unwrap(), vec![0.0, 30.0, 60.0, 90.0]);
        assert!(values(0.0, 1.0, 0.0).is_err());
        assert!(values(0.0, 1e6, 1.0).is_err(), "a million frames is refused");
    }

    #[test]
    fn frame_files_sort_by_value_and_name_negative_values() {
        let d = Coordinate::Dihedral([0, 1, 2, 3]);
        assert_eq!(frame_file("b", &d, -90.0), "b_dihedralm90.00.molden");
        assert_eq!(frame_file("w", &Coordinate::Distance([0, 1]), 0.96), "w_distance0.960.molden");
    }

    #[test]
    fn events_parse_as_the_script_writes_them() {
        let e: Event = serde_json::from_str(
            r#"{"event": "frame", "index": 2, "at": 104.5, "file": "w.molden", "ok": true, "energy": -74.96, "cycles": 6, "seconds": 0.4}"#,
        )
        .unwrap();
        assert!(matches!(e, Event::Frame(FrameReport { index: 2, ok: true, cycles: Some(6), .. })));
        let e: Event = serde_json::from_str(r#"{"event": "error", "message": "no pyscf"}"#).unwrap();
        assert_eq!(e, Event::Error { message: "no pyscf".into() });
    }

    #[test]
    fn the_script_is_the_python_package_s_module() {
        assert!(SCRIPT.contains("def compute_frame(task"));
        assert!(SCRIPT.contains("if __name__ == \"__main__\":"));
    }
}
