//! `orbcloud bench scene`: how long a scene of several molecules with clouds and translucent
//! surfaces takes to show after a change, as the window shows it on a slow adapter: the coarse
//! preview at once, then the full picture.

use std::time::Instant;

use crate::app::progressive::{Progressive, Turn};
use crate::gpu::{FrameInput, OffscreenTarget, Renderer, Tile};
use crate::layers::show_scene;
use crate::pictures::headless::draw_exact;
use crate::scene::detail::Detail;
use crate::scene::{Camera, ObjectState, Placement};
use anyhow::{Context, Result};
use clap::Args;

#[derive(Args)]
pub struct SceneBench {
    /// Files of the molecules, each shown with its density and HOMO; the bundled diene + SO₂
    /// demo's molecules when none are given.
    files: Vec<std::path::PathBuf>,
    /// Molecules in the scene: the files (or the demo's) in turn, copies placed beside.
    #[arg(long, default_value_t = 3)]
    molecules: usize,
    /// Also write the scene as a session the viewer opens (its files given by path).
    #[arg(long)]
    session: Option<std::path::PathBuf>,
    /// Grid points per side of each evaluated quantity.
    #[arg(long, default_value_t = 64)]
    points: usize,
    #[command(flatten)]
    bench: super::BenchFrames,
    /// Write the last preview and full picture here (preview.png, full.png).
    #[arg(long)]
    images: Option<std::path::PathBuf>,
}

/// The molecules of `files` (each with its density and HOMO) or of the demo, each quantity with
/// its cloud shown beside its translucent surface, repeated to `count` molecules in a row along
/// x, 4 bohr apart.
fn molecules(files: &[std::path::PathBuf], count: usize) -> Result<Vec<(crate::model::Document, ObjectState)>> {
    const COLOURS: [([f32; 3], [f32; 3]); 3] = [
        ([0.9, 0.2, 0.12], [0.15, 0.35, 0.95]),
        ([0.95, 0.7, 0.15], [0.2, 0.8, 0.4]),
        ([0.85, 0.3, 0.8], [0.2, 0.75, 0.75]),
    ];
    let demo = match files {
        [] => crate::sources::demo::cycloaddition()?,
        _ => (files.iter().zip(COLOURS.iter().cycle()))
            .map(|(path, &(positive, negative))| {
                let doc = crate::formats::load(path)?;
                let homo = doc.wavefunction.as_ref().and_then(|wf| wf.homo(crate::model::orbitals::Spin::Alpha));
                let state = ObjectState {
                    path: Some(std::fs::canonicalize(path)?),
                    ..crate::sources::demo::density_and_orbital(homo, positive, negative)
                };
                Ok((doc, state))
            })
            .collect::<Result<_>>()?,
    };
    let mut scene = Vec::new();
    let mut right = f32::NEG_INFINITY;
    for n in 0..count {
        let (doc, mut state) = demo[n % demo.len()].clone();
        for q in &mut state.quantities {
            q.cloud.visible = true;
        }
        let (lo, hi) = doc.bounds().context("the demo has atoms")?;
        // The demo's two molecules stand as the demo places them; any other beside the last.
        if n > 0 && (!files.is_empty() || n >= demo.len()) {
            state.placement = Placement::beside(right, lo.as_vec3(), 4.0);
        }
        right = right.max(state.placement.world_from_object().transform_point3(hi.as_vec3()).x);
        scene.push((doc, state));
    }
    Ok(scene)
}

/// The placed atoms' bounds over the scene.
fn scene_bounds(scene: &[(crate::model::Document, ObjectState)]) -> Option<(glam::Vec3, glam::Vec3)> {
    scene
        .iter()
        .filter_map(|(doc, state)| {
            let (lo, hi) = doc.bounds()?;
            Some(state.placement.placed_box(lo.as_vec3(), hi.as_vec3()))
        })
        .reduce(|(l, h), (a, b)| (l.min(a), h.max(b)))
}

/// What of the scene a timed picture draws.
#[derive(Clone, Copy, PartialEq)]
enum Part {
    Whole,
    Clouds,
    Surfaces,
}

pub fn bench(args: &SceneBench) -> Result<()> {
    let ctx = super::gpu(args.bench.lavapipe)?;
    let scene = molecules(&args.files, args.molecules.max(1))?;
    let (lo, hi) = scene_bounds(&scene).context("the scene has no atoms")?;
    if let Some(path) = &args.session {
        let session = crate::scene::Session {
            camera: Camera::framing(lo, hi),
            objects: scene.iter().map(|(_, s)| s.clone()).collect(),
            ..Default::default()
        };
        crate::sources::session::write(path, &session).map_err(anyhow::Error::msg)?;
    }
    let mut renderer = Renderer::new(&ctx);
    let shown = show_scene(&ctx, &mut renderer, &scene, args.points)?;
    // The same scene without its surfaces, to tell the clouds' share of the time from theirs.
    let bare: Vec<_> = scene
        .iter()
        .map(|(doc, state)| {
            let mut state = state.clone();
            state.quantities.iter_mut().flat_map(|q| &mut q.isosurfaces).for_each(|iso| iso.visible = false);
            (doc, state)
        })
        .collect();
    let mut clouds_renderer = Renderer::new(&ctx);
    show_scene(&ctx, &mut clouds_renderer, &bare, args.points)?;
    let camera = Camera::framing(lo, hi);
    let size = args.bench.size;
    let quantities: usize = scene.iter().map(|(_, s)| s.quantities.len()).sum();
    println!("adapter: {}", ctx.describe());
    println!(
        "scene: {} molecules, {quantities} quantities (clouds with translucent surfaces), {}³ points each, {}x{}",
        scene.len(),
        args.points,
        size[0],
        size[1]
    );
    // One picture at `detail` after the camera moved by `f` steps: ms from the change to the
    // picture done, and the picture.
    // `bands`: drawn as the window draws a picture after a change: in bands (each waited for)
    // or at once, as its schedule decides ([`Progressive`]), the coarse preview first where it
    // would stand in.
    // `part`: the whole scene, its surfaces alone or its clouds alone.
    let cpu = ctx.info.device_type == wgpu::DeviceType::Cpu;
    let mut part_picture = |part: Part,
                            detail: Detail,
                            f: u32,
                            schedule: Option<&mut Progressive>|
     -> Result<(f64, image::RgbaImage)> {
        let mut cam = camera;
        cam.orbit(0.05 * f as f32, 0.02 * f as f32);
        let render_size = detail.render_size(size);
        let cloud_settings = |detail: Detail| -> Vec<_> {
            (shown.clouds.iter())
                .map(|&c| crate::scene::VolumeSettings {
                    visible: c.visible && part != Part::Surfaces,
                    ..detail.cloud(c)
                })
                .collect()
        };
        let clouds = cloud_settings(detail);
        let renderer = if part == Part::Clouds { &mut clouds_renderer } else { &mut renderer };
        let target = OffscreenTarget::new(&ctx.device, render_size);
        renderer.set_detail(&detail);
        let start = Instant::now();
        let frame =
            FrameInput { camera: &cam, background: [0.02, 0.02, 0.03], clouds: &clouds, size: render_size, tile: None };
        match schedule {
            None => {
                draw_exact(&ctx, renderer, &target.color_view, &frame);
            }
            Some(schedule) => {
                let preview_clouds = cloud_settings(Detail::PREVIEW);
                let preview_size = Detail::PREVIEW.render_size(size);
                let preview_target = OffscreenTarget::new(&ctx.device, preview_size);
                let preview = |renderer: &mut Renderer| {
                    renderer.set_detail(&Detail::PREVIEW);
                    let frame = FrameInput { clouds: &preview_clouds, size: preview_size, ..frame };
                    let mut encoder = ctx.device.create_command_encoder(&Default::default());
                    renderer.render(&ctx, &mut encoder, &preview_target.color_view, &frame);
                    ctx.queue.submit([encoder.finish()]);
                    let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
                    renderer.set_detail(&detail);
                };
                let costly = renderer.is_costly();
                let banded = schedule.bands_needed(cpu, costly);
                if schedule.start(banded, true, costly) {
                    preview(renderer);
                }
                let draw = |renderer: &mut Renderer, tile: Option<Tile>| {
                    let mut encoder = ctx.device.create_command_encoder(&Default::default());
                    renderer.render(&ctx, &mut encoder, &target.color_view, &FrameInput { tile, ..frame });
                    ctx.queue.submit([encoder.finish()]);
                    let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
                };
                if banded {
                    loop {
                        match schedule.turn(render_size, true, |tile| draw(renderer, Some(tile))) {
                            Turn::Done => break,
                            Turn::More => {}
                            Turn::WantPreview => {
                                preview(renderer);
                                schedule.preview_drawn();
                            }
                        }
                    }
                } else {
                    draw(renderer, None);
                    schedule.finished_whole();
                }
            }
        }
        ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        Ok((ms, target.read_rgba(&ctx.device, &ctx.queue)?))
    };
    let mut picture =
        |detail: Detail, f: u32, schedule: Option<&mut Progressive>| part_picture(Part::Whole, detail, f, schedule);
    // Warm up: every pipeline built once, at both sizes, and the window's schedule given a
    // picture to measure (as the window's first picture after opening).
    let mut schedule = Progressive::default();
    picture(Detail::PREVIEW, 0, None)?;
    picture(Detail::FULL, 0, None)?;
    picture(Detail::FULL, 0, Some(&mut schedule))?;
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (mut previews, mut fulls, mut banded) = (Vec::new(), Vec::new(), Vec::new());
    // Whether the window would band the next picture, after each.
    let mut bands_used = Vec::new();
    let mut last = None;
    for f in 1..=args.bench.frames.max(1) {
        let (preview_ms, preview) = picture(Detail::PREVIEW, f, None)?;
        let (full_ms, full) = picture(Detail::FULL, f, None)?;
        banded.push(picture(Detail::FULL, f, Some(&mut schedule))?.0);
        bands_used.push(schedule.bands_needed(cpu, false));
        previews.push(preview_ms);
        fulls.push(preview_ms + full_ms);
        last = Some((preview, full));
    }
    let preview_size = Detail::PREVIEW.render_size(size);
    println!(
        "preview ({}x{}, at most {} slices a cloud): {:.0} ms after a change",
        preview_size[0],
        preview_size[1],
        Detail::PREVIEW.max_slices,
        median(previews)
    );
    println!("full picture: {:.0} ms after a change (the preview's time included)", median(fulls));
    let how = match (cpu, bands_used.iter().all(|&b| b), bands_used.iter().any(|&b| b)) {
        (true, _, _) => "in bands (a CPU adapter)".to_string(),
        (false, true, _) => {
            format!("in bands (drawn at once it took over {:.0} ms)", crate::app::progressive::AT_ONCE_MS)
        }
        (false, false, false) => format!("at once (it takes under {:.0} ms)", crate::app::progressive::AT_ONCE_MS),
        (false, false, true) => "at once and in bands, in turn".to_string(),
    };
    println!(
        "full picture as the window draws it, {how}: {:.0} ms (at once, estimated from its bands or measured: {:.0} ms)",
        median(banded),
        schedule.whole_ms().unwrap_or(f64::NAN)
    );
    let parts = [Part::Clouds, Part::Surfaces].map(|part| {
        let times: Result<Vec<f64>> =
            (1..=args.bench.frames.max(1)).map(|f| Ok(part_picture(part, Detail::FULL, f, None)?.0)).collect();
        times.map(median)
    });
    let [clouds_ms, surfaces_ms] = parts;
    println!("of which: the clouds alone {:.0} ms, the surfaces alone {:.0} ms", clouds_ms?, surfaces_ms?);
    if let (Some(dir), Some((preview, full))) = (&args.images, last) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        for (name, img) in [("preview", preview), ("full", full)] {
            let path = dir.join(format!("{name}.png"));
            img.save(&path).with_context(|| format!("writing {}", path.display()))?;
        }
    }
    Ok(())
}
