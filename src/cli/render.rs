//! `render` (an image of a file's quantities, or of a bundled demo scene) and `bench render`
//! (frame times of one file's scene), and the frame timing the other benchmarks share.

use std::path::Path;
use std::time::Instant;

use crate::gpu::GpuContext;
use crate::model::Document;
use crate::pictures::figure::Figure;
use crate::pictures::headless::Headless;
use crate::scene::coloring::ValueMap;
use crate::scene::{Camera, RenderSettings};
use crate::sources::demo;
use anyhow::{Context, Result, bail};

use super::quantities::{self, Later};
use super::{DemoArg, RenderArgs, ViewArgs, WavefunctionArgs, gpu, load, surface};

/// `render`: `args`'s file (or the bundled demo) to a PNG; `later` are further quantities of the
/// file, each with its options ([`quantities`]).
pub fn render(args: RenderArgs, later: &[Later]) -> Result<()> {
    match drawing(&args, None, later)? {
        Drawing::Drawn(img, ctx) => save(&img, &args.output, &ctx),
        Drawing::Scene(mut picture) => {
            if let Some(said) = &picture.said {
                eprintln!("{said}");
            }
            let img = picture.draw(&picture.camera.clone())?;
            save(&img, &args.output, &picture.ctx)?;
            if let Some(pixel) = args.pick {
                surface::print_pick(&picture.ctx, &picture.headless.renderer, &picture.doc, pixel)?;
            }
            Ok(())
        }
    }
}

/// What `render` makes of its options: one quantity's scene, ready to be drawn from any camera,
/// or a picture already drawn (several quantities, a demo scene).
pub enum Drawing {
    Scene(Box<Picture>),
    Drawn(image::RgbaImage, Box<GpuContext>),
}

/// The scene `args` and `later` ask for, of `doc`, or else of the file (or demo) `args` names.
pub fn drawing(args: &RenderArgs, doc: Option<Document>, later: &[Later]) -> Result<Drawing> {
    let figure = args.figure.figure();
    let size = figure.drawn_size(args.view.size);
    match (args.demo, &doc) {
        (Some(DemoArg::Cycloaddition), None) => {
            let ctx = gpu(args.lavapipe)?;
            let scene = demo::cycloaddition().context("the bundled demo did not load")?;
            let background = RenderSettings::default().background;
            let mut shown = surface::SceneShown::new(&ctx, scene, &args.iso, size)?;
            let img = figure.draw(background, |bg| shown.draw(&ctx, bg))?;
            return Ok(Drawing::Drawn(img, Box::new(ctx)));
        }
        (Some(DemoArg::Scan), None) => bail!("the scan demo renders with `orbcloud scan render`"),
        _ => {}
    }
    let mut doc = match (doc, &args.file) {
        (Some(doc), _) => doc,
        // A TD log's transitions join the file (`--transitions`).
        (None, Some(file)) => args.wavefunction.what.load(file)?,
        (None, None) => load(None)?,
    };
    // Arguments that depend on the file are checked before any GPU work. The camera frames the
    // file's geometry, so pictures of a vibration's phases line up.
    let camera = args.view.camera(&doc)?;
    args.vibration.apply(&mut doc)?;
    args.view.volume_index(&doc)?;
    if !later.is_empty() || args.nci {
        let later = quantities::parse_later(later)?;
        for a in std::iter::once(args).chain(later.iter().map(|(_, a)| a)) {
            quantities::check_nci(a, &doc)?;
        }
        if args.pick.is_some() {
            bail!("--pick reads one quantity's picture: give one quantity option, other than --nci");
        }
        let ctx = gpu(args.lavapipe)?;
        let background = RenderSettings::default().background;
        let img = figure.draw(background, |bg| quantities::render(&ctx, &doc, args, &later, &camera, size, bg))?;
        return Ok(Drawing::Drawn(img, Box::new(ctx)));
    }
    if args.pick.is_some() && figure != Figure::default() {
        bail!("--pick reads the picture as drawn: leave out --scale and --transparent");
    }
    Ok(Drawing::Scene(Box::new(Picture::new(args, doc, camera)?)))
}

/// One file's scene as `render` draws it (one quantity), kept so that it can be drawn again from
/// other cameras: `render` draws it once, the Python package's notebook viewer as the mouse turns
/// it.
pub struct Picture {
    pub ctx: GpuContext,
    pub doc: Document,
    /// The camera the options ask for.
    pub camera: Camera,
    headless: Headless,
    settings: RenderSettings,
    figure: Figure,
    /// A surface coloured by a quantity's values: the map and the quantity's name, for the colour
    /// bar.
    bar: Option<(ValueMap, String)>,
    /// What was put into the scene, in words, for the command to print (a notebook does not).
    pub said: Option<String>,
}

impl Picture {
    /// `doc` shown as `args` asks (`doc` already displaced by `--normal-mode`), seen by `camera`.
    pub(super) fn new(args: &RenderArgs, mut doc: Document, camera: Camera) -> Result<Self> {
        let figure = args.figure.figure();
        let size = figure.drawn_size(args.view.size);
        let volume = args.view.volume_index(&doc)?;
        // A cube file to colour by joins the document's volumes last: the shown one's index stays.
        let color = args.iso.color_source(&mut doc)?;
        let ctx = gpu(args.lavapipe)?;
        let mut settings = args.view.settings();
        let mut h = Headless::new(&ctx, &doc, volume, &settings, size)?;
        // Direct mode fills a grid only for isosurfaces or a surface coloured by its values.
        let wants_grid = !args.iso.levels().is_empty() || args.molsurface.settings(false).color_by_volume;
        let computed = args.wavefunction.apply(&ctx, &mut h, &doc, wants_grid)?.map(|(_, v)| v);
        let grid = computed.as_ref().and_then(|v| v.grid.as_ref()).or(volume.and_then(|i| doc.volumes.get(i)));
        match (&computed, grid) {
            (Some(values), _) => values.auto_opacity(&mut settings.volume),
            (None, Some(grid)) => crate::evaluate::auto_opacity(&mut settings.volume, grid),
            (None, None) => {}
        }
        let molsurface = args.molsurface.mesh(&doc, args.iso.translucent, grid)?;
        let map = molsurface.as_ref().and_then(|(_, _, map)| *map);
        let meshes = molsurface.into_iter().map(|(mesh, look, _)| (mesh, look)).collect();
        let (colored, said) = surface::show(&ctx, &mut h.renderer, (grid, &doc), &args.iso, color, meshes);
        let arrows = args.vibration.arrows(&doc)?;
        h.renderer.main().arrows.set_arrows(&ctx, &arrows, crate::scene::vibration::ARROW_COLOR);
        let bar = match colored {
            Some(c) => Some((c.map, c.name)),
            None => map.zip(grid.map(|g| g.label.clone())),
        };
        Ok(Self { ctx, doc, camera, headless: h, settings, figure, bar, said })
    }

    /// The scene seen by `camera`, as `render` writes it.
    pub fn draw(&mut self, camera: &Camera) -> Result<image::RgbaImage> {
        let Self { ctx, headless, settings, .. } = self;
        let mut img = self.figure.draw(settings.background, |bg| {
            let settings = RenderSettings { background: bg, ..*settings };
            headless.render(ctx, camera, &settings)
        })?;
        if let Some((map, name)) = &self.bar {
            crate::pictures::shots::value_bar(&mut img, map, name);
        }
        Ok(img)
    }
}

/// Writes `img` to `path` and says so, with the adapter that drew it.
fn save(img: &image::RgbaImage, path: &Path, ctx: &GpuContext) -> Result<()> {
    img.save(path).with_context(|| format!("writing {}", path.display()))?;
    eprintln!("wrote {} ({}x{}, {})", path.display(), img.width(), img.height(), ctx.describe());
    Ok(())
}

/// `bench render`: ms per frame of a file's scene (atoms, cloud) at a size and slice count.
pub fn bench(
    file: Option<&Path>,
    view: &ViewArgs,
    frames: u32,
    lavapipe: bool,
    wavefunction: &WavefunctionArgs,
) -> Result<()> {
    let doc = load(file)?;
    let camera = view.camera(&doc)?;
    let ctx = gpu(lavapipe)?;
    let settings = view.settings();
    let mut h = Headless::new(&ctx, &doc, view.volume_index(&doc)?, &settings, view.size)?;
    if let Some((seconds, values)) = wavefunction.apply(&ctx, &mut h, &doc, false)? {
        let n = wavefunction.grid_points;
        let how = match values.grid {
            Some(_) => format!("grid {n}^3: GPU fill and read-back for the value range"),
            None => "direct: range measured at CPU samples, no grid".to_string(),
        };
        println!("wavefunction_setup_ms={:.1} ({how})", seconds * 1e3);
    }
    let wait = |ctx: &GpuContext| ctx.device.poll(wgpu::PollType::wait_indefinitely()).map(|_| ());
    for _ in 0..2 {
        h.draw(&ctx, &camera, &settings);
        wait(&ctx)?;
    }
    let mut times = Vec::new();
    for f in 0..frames.max(1) {
        // Turn the camera a little each frame so the slices are cut anew, as in the viewer.
        let mut cam = camera;
        cam.orbit(0.01 * f as f32, 0.0);
        let t = Instant::now();
        h.draw(&ctx, &cam, &settings);
        wait(&ctx)?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    let grid = doc.volumes.get(view.volume).map_or("none".into(), |g| format!("{:?}", g.dims));
    println!("adapter: {}", ctx.describe());
    println!(
        "scene: {} atoms, grid {grid}, {}x{}, {:?}, {} slices",
        doc.molecule.atoms.len(),
        view.size[0],
        view.size[1],
        settings.volume.mode,
        settings.volume.slices
    );
    let eye = camera.eye();
    println!(
        "camera: eye={:.4},{:.4},{:.4} target={:.4},{:.4},{:.4} fov_deg={:.2}",
        eye.x,
        eye.y,
        eye.z,
        camera.target.x,
        camera.target.y,
        camera.target.z,
        camera.fov_y.to_degrees()
    );
    if let Some(v) = h.renderer.main().volume.volume() {
        let s = v.grid_box.slices(settings.volume.mode, settings.volume.slices, eye, -camera.backward());
        println!("slice_spacing_bohr={:.5}", s.spacing);
        // What the last frame drew against whole slices (cut into the same slabs): the
        // fragments empty space spared.
        let volume = &h.renderer.main().volume;
        let planes = volume.planes_per_fragment();
        let whole = s.slabs(planes, eye).unwrap_or(s.vertices);
        let drawn = volume.slice_vertices();
        let area = |v: &[glam::Vec3]| v.chunks(3).map(|t| (t[1] - t[0]).cross(t[2] - t[0]).length() * 0.5).sum::<f32>();
        println!(
            "planes_per_fragment={planes} slice_triangles={} slice_area_fraction={:.3}",
            drawn.len() / 3,
            area(drawn) / area(&whole).max(1e-30)
        );
    }
    println!(
        "ms_per_frame_median={median:.1} min={:.1} max={:.1} frames={}",
        times[0],
        times[times.len() - 1],
        times.len()
    );
    Ok(())
}

/// ms per frame drawing `camera`'s view at `size`, turning a little each frame, after two
/// warm-up frames; sorted.
pub fn time_frames(
    ctx: &GpuContext,
    renderer: &mut crate::gpu::Renderer,
    camera: &Camera,
    size: [u32; 2],
    frames: u32,
) -> Result<Vec<f64>> {
    Ok(time_frames_of(ctx, &mut [renderer], camera, size, frames)?.remove(0))
}

/// [`time_frames`] for several renderers taking turns frame by frame, so that a machine whose
/// speed drifts slows them alike: one sorted list per renderer.
pub fn time_frames_of(
    ctx: &GpuContext,
    renderers: &mut [&mut crate::gpu::Renderer],
    camera: &Camera,
    size: [u32; 2],
    frames: u32,
) -> Result<Vec<Vec<f64>>> {
    let target = crate::gpu::OffscreenTarget::new(&ctx.device, size);
    let settings = RenderSettings::default();
    let mut times = vec![Vec::new(); renderers.len()];
    for f in 0..frames.max(1) + 2 {
        let mut cam = *camera;
        cam.orbit(0.02 * f as f32, 0.01 * f as f32);
        for (renderer, times) in renderers.iter_mut().zip(&mut times) {
            let t = Instant::now();
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            renderer.render(
                ctx,
                &mut encoder,
                &target.color_view,
                &crate::gpu::FrameInput::single(&cam, &settings, size),
            );
            ctx.queue.submit([encoder.finish()]);
            ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
            if f >= 2 {
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
    }
    for t in &mut times {
        t.sort_by(f64::total_cmp);
    }
    Ok(times)
}
