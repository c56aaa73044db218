//! `movie`: a scan's coordinate swept, a turntable, or a vibration's period, frame after frame
//! through the same renderer as `render` and `scan render`, written as PNG frames, a GIF, an
//! animated PNG or (through ffmpeg) a video.

use crate::scene::limits::{self, within};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use crate::formats::scan::load_scan;
use crate::model::Document;
use crate::pictures::movie::{MovieFormat, MovieWriter, sweep};
use crate::pictures::shots::{Motion, Progress, ScanShots, SceneShots, ShotError, record};
use crate::scene::{Camera, ObjectState};
use anyhow::{Context, Result, bail};
use clap::Args;

use super::scan::{InterpolationArg, KeyArgs, build};
use super::{FigureArgs, ViewArgs, WavefunctionArgs, gpu, quantities, surface};

#[derive(Args)]
pub struct MovieArgs {
    /// A scan manifest (.scan.toml: its coordinate is swept), a file of any format `render`
    /// reads, or a session (.orbcloud.toml); the bundled scan when omitted.
    input: Option<PathBuf>,
    /// Where the movie goes: a folder (`DIR/`, numbered PNG frames), `.gif`, `.apng` (or
    /// `.png`), or `.mp4`/`.webm` through ffmpeg.
    #[arg(short, long)]
    output: PathBuf,
    /// Frames: over the scan's range (ends included), over a full turn, or over one period.
    #[arg(long, default_value_t = 24, value_parser = within(limits::FRAMES))]
    frames: usize,
    /// Frames per second, 0.1 to 240.
    #[arg(long, default_value_t = 12.0, value_parser = within(limits::FPS))]
    fps: f64,
    /// Turn the view a full circle about the screen's vertical axis.
    #[arg(long)]
    turntable: bool,
    /// Where a scan's sweep starts (the coordinate's unit; default: the first key frame).
    #[arg(long, allow_hyphen_values = true, value_parser = within(-1e9..=1e9))]
    from: Option<f64>,
    /// Where a scan's sweep ends (default: the last key frame).
    #[arg(long, allow_hyphen_values = true, value_parser = within(-1e9..=1e9))]
    to: Option<f64>,
    /// Sweep there and back, so the movie loops.
    #[arg(long)]
    bounce: bool,
    #[arg(long = "interpolation", value_enum, default_value_t = InterpolationArg::Exact)]
    interpolation: InterpolationArg,
    #[command(flatten)]
    keys: KeyArgs,
    #[command(flatten)]
    figure: FigureArgs,
    #[command(flatten)]
    view: ViewArgs,
    #[command(flatten)]
    wavefunction: WavefunctionArgs,
    #[command(flatten)]
    iso: surface::IsoArgs,
    /// One period of this normal mode (1-based, as `info` lists them), the atoms moving along it.
    #[arg(long)]
    normal_mode: Option<usize>,
    /// The largest atom's displacement at the turning points, bohr (0 to 10).
    #[arg(long, default_value_t = 0.4, value_parser = within(limits::wide(limits::AMPLITUDE)))]
    amplitude: f64,
    /// Draw each atom's displacement along the mode as an arrow.
    #[arg(long, requires = "normal_mode")]
    arrows: bool,
    /// Use the CPU Vulkan adapter (lavapipe) even when a GPU is present.
    #[arg(long)]
    lavapipe: bool,
}

fn is_scan(path: &Path) -> bool {
    path.to_string_lossy().to_lowercase().ends_with(".scan.toml")
}

fn is_session(path: &Path) -> bool {
    path.to_string_lossy().to_lowercase().ends_with(crate::scene::objects::SESSION_SUFFIX)
}

pub fn movie(args: MovieArgs) -> Result<()> {
    // Everything that can be refused is, before any frame is drawn.
    MovieFormat::of(&args.output)?.check(&args.output)?;
    let scan_input = args.input.as_deref().is_none_or(is_scan);
    match (scan_input, args.turntable, args.normal_mode) {
        (true, _, Some(_)) => bail!("--normal-mode animates a file's vibration; a scan sweeps its coordinate"),
        (false, false, None) => {
            bail!("a file or session moves with --turntable or --normal-mode K (a scan manifest sweeps its coordinate)")
        }
        (false, true, Some(_)) => bail!("choose one: --turntable or --normal-mode"),
        _ => {}
    }
    let started = Instant::now();
    let (written, drawing) =
        if scan_input && !args.turntable { scan_sweep(&args)? } else { file_movie(&args, scan_input)? };
    let setup = started.elapsed().as_secs_f64() - drawing;
    eprintln!(
        "wrote {} ({written} frames, {:.3} s per frame drawn and written; setup {setup:.1} s)",
        args.output.display(),
        drawing / written.max(1) as f64
    );
    Ok(())
}

/// Writes `count` frames drawn by `frame(k)`, saying how far it got; returns the count and the
/// seconds they took.
fn write_frames(
    args: &MovieArgs,
    size: [u32; 2],
    count: usize,
    mut frame: impl FnMut(usize) -> Result<image::RgbaImage, ShotError>,
) -> Result<(usize, f64)> {
    let started = Instant::now();
    let writer = MovieWriter::create(&args.output, size, args.fps, count)?;
    let progress = Progress::default();
    record(writer, count, &progress, |k| {
        eprint!("\rframe {}/{count}", k + 1);
        frame(k)
    })?;
    eprintln!();
    Ok((count, started.elapsed().as_secs_f64()))
}

/// A scan's coordinate swept from `--from` to `--to`: every view side by side, each captioned,
/// frame k equal to `scan render --at VALUEk`.
fn scan_sweep(args: &MovieArgs) -> Result<(usize, f64)> {
    let file = match &args.input {
        Some(path) => load_scan(path)?,
        None => crate::sources::demo::scan()?,
    };
    let (lo, hi) = file.scan.range();
    let (from, to) = (args.from.unwrap_or(lo), args.to.unwrap_or(hi));
    for (name, v) in [("--from", from), ("--to", to)] {
        if !(lo..=hi).contains(&v) {
            bail!("{name} {v} is outside the scan's {lo}..{hi}");
        }
    }
    let values = sweep(from, to, args.frames, args.bounce);
    let ctx = gpu(args.lavapipe)?;
    let scene = Arc::new(build(&ctx, file, &args.keys)?);
    let camera = args.view.orbit(scene.camera());
    let views = scene.slots() as u32;
    let size = args.view.size;
    let settings = args.view.settings();
    let figure = args.figure.figure();
    let mut shots = ScanShots::new(&ctx, scene, values, camera, settings, args.interpolation.into(), figure, size);
    let count = shots.values.len();
    write_frames(args, [size[0] * views, size[1]], count, |k| Ok(shots.at(&ctx, shots.values[k])?))
}

/// A file or session turning a full circle, or a file's vibration over one period.
fn file_movie(args: &MovieArgs, scan_input: bool) -> Result<(usize, f64)> {
    if scan_input {
        bail!("--turntable turns a file or session; a scan manifest sweeps its coordinate (leave out --turntable)");
    }
    let input = args.input.as_deref().context("a file or session is needed")?;
    let (scene, camera, background) = if is_session(input) {
        let (scene, camera, background) = session_scene(input)?;
        (scene, args.view.orbit(camera), background)
    } else {
        let mut doc = crate::formats::load(input)?;
        let camera = args.view.camera(&doc)?;
        let mut object = quantities::object_of(&doc, &args.view, &args.wavefunction, &args.iso)?;
        args.iso.color_object(&mut doc, &mut object)?;
        (vec![(doc, object)], camera, args.view.settings().background)
    };
    let motion = match args.normal_mode {
        Some(0) => bail!("--normal-mode counts from 1, as `info` lists the modes"),
        Some(n) => Motion::Vibration { mode: n - 1, amplitude: args.amplitude },
        None => Motion::Turntable,
    };
    let ctx = gpu(args.lavapipe)?;
    let points = args.wavefunction.grid_points.clamp(8, 512);
    let figure = args.figure.figure();
    let mut shots =
        SceneShots::new(&ctx, scene, camera, background, motion, args.frames, figure, args.view.size, points)?;
    if args.arrows {
        shots.show_arrows(&ctx);
    }
    let count = shots.len();
    write_frames(args, args.view.size, count, |k| Ok(shots.frame(&ctx, k)?))
}

/// A scene's objects, each a document and what it shows.
type Objects = Vec<(Document, ObjectState)>;

/// A session's objects (each file loaded), its camera and background.
fn session_scene(path: &Path) -> Result<(Objects, Camera, [f32; 3])> {
    let read = crate::sources::session::read(path).map_err(anyhow::Error::msg)?;
    for note in &read.notes {
        eprintln!("warning: {note}");
    }
    let session = read.session;
    let mut scene = Vec::new();
    for mut state in session.objects {
        if let Some(scan) = &state.scan {
            let manifest =
                scan.manifest.as_ref().map_or("(none: the bundled scan)".into(), |m| m.display().to_string());
            bail!("{}: the session holds a scan; `orbcloud movie {manifest}` sweeps it", path.display());
        }
        let Some(file) = state.path.clone() else { continue };
        let mut doc =
            crate::formats::load(&file).with_context(|| format!("{}: opening {}", path.display(), file.display()))?;
        for added in &state.added {
            crate::sources::session::add_volume(&mut doc, added)
                .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        }
        state.fit_to(&doc, &crate::scene::RenderSettings::default());
        scene.push((doc, state));
    }
    if scene.is_empty() {
        bail!("{}: the session opens no files", path.display());
    }
    let background = session.background.unwrap_or(crate::scene::RenderSettings::default().background);
    Ok((scene, session.camera, background))
}
