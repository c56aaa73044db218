//! `orbcloud scan …` and `orbcloud bench keyvolumes`: scans of a distance, angle, dihedral or path from the command line.

use crate::scene::limits::{self, within};
use std::path::PathBuf;
use std::time::Instant;

use crate::formats::cube_write;
use crate::formats::scan::{Follow, ScanFile, init, load_scan};
use crate::gpu::volume::{VolumeTexture, residency_budget, texel_bytes};
use crate::gpu::{GpuContext, OffscreenTarget, Renderer};
use crate::layers::key_volumes::{DEFAULT_SCAN_POINTS, KeyOptions, ScanScene};
use crate::model::VolumeGrid;
use crate::model::scan::{Coordinate, PathMeasure, Scan};
use crate::pictures::shots::ScanShots;
use crate::scene::Interpolation;
use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand, ValueEnum};

use super::{FigureArgs, ViewArgs, gpu};

#[derive(Subcommand)]
pub enum ScanCommand {
    /// Compute a scan with PySCF: one Molden file per value of a distance, angle or dihedral
    /// (rigid, or --relaxed), or per frame of a trajectory (--frames), and its manifest.
    /// Rerun into the same directory to resume.
    Compute(Box<super::compute::ScanComputeArgs>),
    /// Write DIR/<name>.scan.toml from a directory of Molden/fchk files, one per point of a
    /// scan: a bond length, a bond angle, a dihedral, or a path (an IRC, a relaxed scan).
    Init {
        dir: PathBuf,
        /// Default: the bonded distance, angle or dihedral that explains the change across the
        /// frames best, or a path.
        #[command(flatten)]
        coordinate: CoordinateArgs,
        /// The frames as a path, in the order of their file names (or of a multi-frame XYZ file
        /// beside them), measured by the length travelled in Å as IRCs measure it.
        #[arg(long, group = "coordinate")]
        path: bool,
        /// A path's length with each atom's displacement weighted by √(mass), amu½·Å.
        #[arg(long, requires = "path")]
        mass_weighted: bool,
        /// Print the manifest instead of writing it.
        #[arg(long)]
        dry_run: bool,
    },
    /// Frames, orbitals, energies, sign flips and character swaps of a scan.
    Info {
        scan: PathBuf,
        #[arg(long, value_enum)]
        follow: Option<FollowArg>,
        /// The correlation diagram as CSV instead: HOMO−K … LUMO+K each followed by its
        /// character, energy (Eh) and orbital number per frame.
        #[arg(long)]
        csv: bool,
        /// K of --csv.
        #[arg(long, default_value_t = 2)]
        window: usize,
    },
    /// Render the scan's orbitals at an angle, side by side, to a PNG.
    Render(Box<ScanRenderArgs>),
    /// Write the exactly interpolated orbital at an angle as a cube file.
    Export {
        scan: PathBuf,
        /// The coordinate's value (degrees for a dihedral).
        #[arg(long, alias = "angle", allow_hyphen_values = true, value_parser = within(-1e9..=1e9))]
        at: f64,
        /// Which of the scan's orbitals (as the manifest names them).
        #[arg(long, default_value = "homo", allow_hyphen_values = true)]
        orbital: String,
        #[command(flatten)]
        keys: KeyArgs,
        #[arg(short, long)]
        output: PathBuf,
    },
}

/// A scan's coordinate by its atoms (1-based), one of the `coordinate` group.
#[derive(Args)]
pub struct CoordinateArgs {
    /// The bond length between these atoms (Å).
    #[arg(long, value_parser = parse_atoms::<2>, group = "coordinate")]
    distance: Option<[usize; 2]>,
    /// The angle i-j-k at j (degrees).
    #[arg(long, value_parser = parse_atoms::<3>, group = "coordinate")]
    angle: Option<[usize; 3]>,
    /// The dihedral i-j-k-l about the j-k bond (degrees).
    #[arg(long, value_parser = parse_atoms::<4>, group = "coordinate")]
    dihedral: Option<[usize; 4]>,
}

impl CoordinateArgs {
    /// The coordinate given (0-based atoms), if any.
    pub fn coordinate(&self) -> Option<Coordinate> {
        (self.distance.map(Coordinate::Distance))
            .or(self.angle.map(Coordinate::Angle))
            .or(self.dihedral.map(Coordinate::Dihedral))
    }
}

#[derive(Args)]
pub struct KeyArgs {
    /// Points along the longest side of the common grid, 8 to 512.
    #[arg(long, default_value_t = DEFAULT_SCAN_POINTS, value_parser = within(limits::GRID_POINTS))]
    points: usize,
    /// Follow each orbital by index (name) or by overlap (character); default: the manifest's.
    #[arg(long, value_enum)]
    follow: Option<FollowArg>,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum FollowArg {
    Index,
    Overlap,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum InterpolationArg {
    /// Both key volumes mixed per sample (the interpolated orbital).
    Exact,
    /// The real-time approximation: per slice, attenuate by one key volume's opacity, add
    /// (1−k)A and kB (three blends per slice, drawn as one).
    ThreePass,
    /// The reference the three passes approximate: per slice the two samples' colours and
    /// opacities mixed.
    AlphaMix,
}

impl From<InterpolationArg> for Interpolation {
    fn from(m: InterpolationArg) -> Self {
        match m {
            InterpolationArg::Exact => Interpolation::Exact,
            InterpolationArg::ThreePass => Interpolation::ThreePass,
            InterpolationArg::AlphaMix => Interpolation::AlphaMix,
        }
    }
}

#[derive(Args)]
pub struct ScanRenderArgs {
    scan: PathBuf,
    /// The coordinate's value (degrees for a dihedral).
    #[arg(long, alias = "angle", allow_hyphen_values = true, value_parser = within(-1e9..=1e9))]
    at: f64,
    #[arg(long = "interpolation", value_enum, default_value_t = InterpolationArg::Exact)]
    interpolation: InterpolationArg,
    /// Only this orbital (as the manifest names it); default: all, left to right.
    #[arg(long, allow_hyphen_values = true)]
    orbital: Option<String>,
    #[command(flatten)]
    keys: KeyArgs,
    #[command(flatten)]
    view: ViewArgs,
    #[command(flatten)]
    figure: FigureArgs,
    /// Leave out the captions (each view's orbital and energy, the coordinate's value).
    #[arg(long)]
    no_captions: bool,
    /// Use the CPU Vulkan adapter (lavapipe) even when a GPU is present.
    #[arg(long)]
    lavapipe: bool,
    #[arg(short, long)]
    output: PathBuf,
}

/// N 1-based atom numbers `i,j,…`, returned 0-based.
fn parse_atoms<const N: usize>(s: &str) -> Result<[usize; N], String> {
    let v: Vec<usize> =
        s.split(',').map(|t| t.trim().parse::<usize>()).collect::<Result<_, _>>().map_err(|e| e.to_string())?;
    if v.len() != N || v.contains(&0) {
        return Err(format!("expected {N} atom numbers counted from 1, separated by commas, got {s:?}"));
    }
    Ok(std::array::from_fn(|i| v[i] - 1))
}

fn follow_of(arg: Option<FollowArg>, file: &ScanFile) -> Follow {
    match arg {
        Some(FollowArg::Index) => Follow::Index,
        Some(FollowArg::Overlap) => Follow::Overlap,
        None => file.follow,
    }
}

/// Loads a scan and makes its key volumes, reporting progress on stderr.
pub fn build(ctx: &GpuContext, file: ScanFile, keys: &KeyArgs) -> Result<ScanScene> {
    let options = KeyOptions {
        points: keys.points.clamp(8, 512),
        follow: follow_of(keys.follow, &file),
        ..KeyOptions::default()
    };
    let t = Instant::now();
    let scene = ScanScene::build(ctx, file.scan, &options, &mut |done, total| {
        eprint!("\rkey volumes {done}/{total}");
        true
    })?;
    eprintln!(
        "\rkey volumes: {} of {:?} points, {:.1} MiB ({:.1} s)",
        scene.slots() * scene.scan.frames.len(),
        scene.grid.dims,
        scene.bytes as f64 / 1048576.0,
        t.elapsed().as_secs_f64()
    );
    for s in &scene.tracks.swaps {
        eprintln!(
            "note: at {} {} overlaps the previous frame's orbital {:.3}, orbital {} overlaps it {:.3} (character swap{})",
            scene.scan.coordinate.value_text(scene.scan.frames[s.frame].at),
            scene.scan.orbitals[s.slot],
            s.by_name_overlap,
            s.by_overlap + 1,
            s.best_overlap,
            if scene.tracks.follow == Follow::Overlap { ", followed" } else { "; --follow overlap follows it" }
        );
    }
    Ok(scene)
}

fn slot_of(scan: &Scan, name: &str) -> Result<usize> {
    scan.slot(name).with_context(|| {
        format!("--orbital {name}: the scan shows {} (as its manifest names them)", scan.orbitals.join(", "))
    })
}

/// Refuses a value outside the scan's range (it would be drawn at the nearest end).
fn check_angle(scan: &Scan, at: f64) -> Result<()> {
    let (lo, hi) = scan.range();
    if !(lo..=hi).contains(&at) {
        let unit = scan.coordinate.unit();
        bail!("--at {at} is outside the scan's {lo}{unit}..{hi}{unit}");
    }
    Ok(())
}

pub fn run(command: ScanCommand) -> Result<()> {
    match command {
        ScanCommand::Compute(args) => super::compute::scan_compute(*args),
        ScanCommand::Init { dir, coordinate, path, mass_weighted, dry_run } => {
            let measure = if mass_weighted { PathMeasure::MassWeighted } else { PathMeasure::ArcLength };
            let chosen = coordinate.coordinate().or(path.then_some(Coordinate::Path(measure)));
            let made = init(&dir, chosen)?;
            let c = made.coordinate;
            let (lo, hi) = (made.frames[0].1, made.frames[made.frames.len() - 1].1);
            let how = if made.found { " (the coordinate that explains the change best)" } else { "" };
            eprintln!(
                "{}{how}; {} frames from {} to {}",
                c.label(),
                made.frames.len(),
                c.value_text(lo),
                c.value_text(hi)
            );
            if dry_run {
                print!("{}", made.text);
            } else {
                std::fs::write(&made.path, &made.text).with_context(|| format!("writing {}", made.path.display()))?;
                println!("{}", made.path.display());
            }
            Ok(())
        }
        ScanCommand::Info { scan, follow, csv, window } => {
            let file = load_scan(&scan)?;
            if csv {
                let s = &file.scan;
                let diagram = crate::model::correlation::correlation(s, window, window)
                    .context("a correlation diagram needs Molden/fchk frames with orbital energies")?;
                let unit = match s.coordinate.unit().trim() {
                    "" => String::new(),
                    "°" => " / deg".into(),
                    u => format!(" / {u}"),
                };
                print!("{}", diagram.csv(&format!("{}{unit}", s.coordinate.label())));
                return Ok(());
            }
            let tracks = file.scan.track(follow_of(follow, &file))?;
            let s = &file.scan;
            let moving = match s.moving.len() {
                1 => "1 atom moves".to_string(),
                n => format!("{n} atoms move"),
            };
            println!("{}\n{}, {} frames, {moving}", s.title, s.coordinate.label(), s.frames.len());
            if let Some(c) = &file.computed {
                let how = if c.relaxed { "relaxed" } else { "rigid" };
                let versions: Vec<String> = c.versions.iter().map(|(k, v)| format!("{k} {v}")).collect();
                println!("computed: {}/{} {how} from {} ({})", c.method, c.basis, c.input, versions.join(", "));
            }
            print!("{:>9}  {:<28}", s.coordinate.kind(), "file");
            for o in &s.orbitals {
                print!("  {:>12} {:>5}", format!("E({o})"), "sign");
            }
            println!();
            for (f, frame) in s.frames.iter().enumerate() {
                print!("{:>9.3}  {:<28}", frame.at, frame.source);
                for slot in 0..s.orbitals.len() {
                    let p = tracks.points[slot][f];
                    let e = p.energy.map_or("-".into(), |e| format!("{e:.5}"));
                    print!("  {e:>12} {:>5}", if p.flipped { "flip" } else { "" });
                }
                println!();
            }
            for slot in 0..s.orbitals.len() {
                println!("{}: {} of {} steps flipped", s.orbitals[slot], tracks.flips(slot), s.frames.len() - 1);
            }
            for w in &tracks.swaps {
                println!(
                    "swap at {}: {} (|overlap| {:.3}) vs orbital {} (|overlap| {:.3})",
                    s.coordinate.value_text(s.frames[w.frame].at),
                    s.orbitals[w.slot],
                    w.by_name_overlap,
                    w.by_overlap + 1,
                    w.best_overlap
                );
            }
            Ok(())
        }
        ScanCommand::Render(args) => {
            // Arguments are checked before the key volumes are made.
            let file = load_scan(&args.scan)?;
            let slots: Vec<usize> = match &args.orbital {
                Some(name) => vec![slot_of(&file.scan, name)?],
                None => (0..file.scan.orbitals.len()).collect(),
            };
            check_angle(&file.scan, args.at)?;
            let ctx = gpu(args.lavapipe)?;
            let scene = build(&ctx, file, &args.keys)?;
            let camera = args.view.orbit(scene.camera());
            let scene = std::sync::Arc::new(scene);
            let (settings, mode) = (args.view.settings(), args.interpolation.into());
            let figure = args.figure.figure();
            let mut shots =
                ScanShots::new(&ctx, scene.clone(), vec![args.at], camera, settings, mode, figure, args.view.size);
            shots.captions = !args.no_captions;
            shots.slots = slots.clone();
            let image = shots.at(&ctx, args.at)?;
            image.save(&args.output).with_context(|| format!("writing {}", args.output.display()))?;
            for &slot in &slots {
                eprintln!("{}", scene.label(slot, args.at));
            }
            eprintln!("wrote {}", args.output.display());
            Ok(())
        }
        ScanCommand::Export { scan, at: angle, orbital, keys, output } => {
            let file = load_scan(&scan)?;
            let follow = follow_of(keys.follow, &file);
            let s = &file.scan;
            let slot = slot_of(s, &orbital)?;
            check_angle(s, angle)?;
            let tracks = s.track(follow)?;
            let grid = s.key_grid(&tracks, crate::scene::framing::ORBITAL_MARGIN, keys.points.clamp(8, 512));
            let label = format!("{orbital} at {} (interpolated)", s.coordinate.value_text(angle));
            let volume = s.interpolated_grid(&tracks, slot, angle, &grid, &label);
            let molecule = s.geometry_at(angle);
            let title = format!("{}: {label}", s.title);
            std::fs::write(&output, cube_write::write(&title, &label, &molecule, &[(&volume, 0)]))
                .with_context(|| format!("writing {}", output.display()))?;
            eprintln!("wrote {} ({:?} points)", output.display(), grid.dims);
            Ok(())
        }
    }
}

/// `bench keyvolumes`: frame time against the number of resident key volumes K (the analogue
/// of Naka et al.'s Figure 6), and the largest K that fits the memory budget.
#[derive(Args)]
pub struct KeyVolumeBench {
    /// A scan manifest; the bundled PSB3 demo when omitted.
    scan: Option<PathBuf>,
    /// Resident key volume counts to time.
    #[arg(long, value_delimiter = ',', default_value = "2,8,32,128,512")]
    counts: Vec<usize>,
    /// Points along the longest side of the grid, 8 to 512.
    #[arg(long, default_value_t = DEFAULT_SCAN_POINTS, value_parser = within(limits::GRID_POINTS))]
    points: usize,
    /// Frames to time per K (each at a different value, so a different pair of volumes).
    #[arg(long, default_value_t = 8, value_parser = within(limits::FRAMES))]
    frames: usize,
    #[arg(long, default_value = "400x300", value_parser = super::parse_size)]
    size: [u32; 2],
    /// View-aligned slices per frame (the viewer draws 64 at most while the value is dragged).
    #[arg(long, default_value_t = crate::scene::RenderSettings::default().volume.slices, value_parser = within(limits::SLICES))]
    slices: u32,
    #[arg(long)]
    lavapipe: bool,
}

pub fn bench_keyvolumes(args: KeyVolumeBench) -> Result<()> {
    let ctx = gpu(args.lavapipe)?;
    let file = match &args.scan {
        Some(path) => load_scan(path)?,
        None => crate::sources::demo::scan()?,
    };
    let s = &file.scan;
    let tracks = s.track(file.follow)?;
    let grid = s.key_grid(&tracks, crate::scene::framing::ORBITAL_MARGIN, args.points.clamp(8, 512));
    // The real key volumes of the first orbital, cycled to make K distinct textures.
    let sources: Vec<VolumeGrid> = (0..s.frames.len())
        .map(|f| {
            VolumeGrid::new(format!("key {f}"), grid.dims, grid.world_from_grid, s.key_values(&tracks, 0, f, &grid))
        })
        .collect();
    let max_abs = sources.iter().map(|g| g.stats.max_abs).fold(1e-30, f64::max) as f32;
    let format = wgpu::TextureFormat::R16Float;
    let per_volume = grid.len() as u64 * texel_bytes(format);
    let budget = residency_budget(&ctx.device.limits());
    println!("adapter: {}", ctx.describe());
    println!(
        "grid {:?} ({:.2} MiB per key volume as {format:?}); budget {:.0} MiB (from max_buffer_size {} MiB); largest K = {}",
        grid.dims,
        per_volume as f64 / 1048576.0,
        budget as f64 / 1048576.0,
        ctx.device.limits().max_buffer_size >> 20,
        budget / per_volume
    );
    let mut settings = crate::scene::RenderSettings::default();
    settings.volume.slices = args.slices.clamp(1, 4096);
    let (lo, hi) = grid.bounds();
    let camera = crate::scene::Camera::framing(lo.as_vec3(), hi.as_vec3());
    let molecule = s.geometry_at(s.frames[0].at);
    let target = OffscreenTarget::new(&ctx.device, args.size);
    println!(
        "K,resident_MiB,exact_ms_median,three_pass_ms_median,alpha_mix_ms_median,three_pass_vs_alpha_mix_mean_255,\
         three_pass_vs_alpha_mix_max_255,upload_s"
    );
    for &k in &args.counts {
        if k < 2 || k as u64 > budget / per_volume {
            println!("{k},skipped (needs 2..={} to fit)", budget / per_volume);
            continue;
        }
        let t = Instant::now();
        let mut keys = Vec::with_capacity(k);
        for i in 0..k {
            let mut v = VolumeTexture::upload_as(&ctx, &sources[i % sources.len()], format)?;
            v.max_abs = max_abs;
            keys.push(v);
        }
        ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
        let upload = t.elapsed().as_secs_f64();
        let mut renderer = Renderer::new(&ctx);
        renderer.main().set_molecule(&ctx, &molecule, settings.atoms);
        // The modes take turns frame by frame, each at the same value: whatever else slows the
        // machine or the driver down for a while (on a fast GPU a frame is mostly its CPU side
        // and the wait for the GPU) falls on all three alike, not on the mode timed then.
        const MODES: [Interpolation; 3] = [Interpolation::Exact, Interpolation::ThreePass, Interpolation::AlphaMix];
        let mut times: [Vec<f64>; 3] = Default::default();
        let mut last_frames = Vec::new();
        for f in 0..args.frames.max(1) + 1 {
            // Spread the frames over all K volumes, as a drag across the whole range would.
            let i = (f * (k - 1)) / args.frames.max(1);
            let (a, b) = (i.min(k - 2), i.min(k - 2) + 1);
            for (m, &mode) in MODES.iter().enumerate() {
                renderer.main().set_morph(&ctx, keys[a].clone(), keys[b].clone(), 0.37, mode);
                let t = Instant::now();
                let mut encoder =
                    ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("bench") });
                let frame = crate::gpu::FrameInput::single(&camera, &settings, args.size);
                renderer.render(&ctx, &mut encoder, &target.color_view, &frame);
                ctx.queue.submit([encoder.finish()]);
                ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
                // The first round builds each mode's pipelines.
                if f > 0 {
                    times[m].push(t.elapsed().as_secs_f64() * 1e3);
                }
                if f == args.frames.max(1) {
                    last_frames.push(target.read_rgba(&ctx.device, &ctx.queue)?);
                }
            }
        }
        let medians: Vec<f64> = times
            .iter_mut()
            .map(|t| {
                t.sort_by(f64::total_cmp);
                t[t.len() / 2]
            })
            .collect();
        // The three-pass approximation against the α-mix it approximates, on the last frame.
        let (mut sum, mut worst) = (0u64, 0u8);
        for (p, q) in last_frames[1].pixels().zip(last_frames[2].pixels()) {
            for c in 0..3 {
                let d = p[c].abs_diff(q[c]);
                sum += d as u64;
                worst = worst.max(d);
            }
        }
        let mean = sum as f64 / (3 * last_frames[1].pixels().len()) as f64;
        println!(
            "{k},{:.1},{:.1},{:.1},{:.1},{mean:.2},{worst},{upload:.2}",
            (k as u64 * per_volume) as f64 / 1048576.0,
            medians[0],
            medians[1],
            medians[2]
        );
    }
    Ok(())
}
