//! `render`/`mesh --surface gaussian|ses` and `bench surface`: molecular surfaces from the
//! command line.

use crate::scene::limits::{self, within};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use crate::evaluate::meshes::molecular_surface;
use crate::model::Document;
use crate::model::isosurface::Mesh;
use crate::model::surface::{self, Sphere, SurfaceParams};
use crate::model::units::BOHR_PER_ANGSTROM;
use crate::scene::coloring::ValueMap;
use crate::scene::translucency::SurfaceLook;
use crate::scene::{AtomColoring, SurfaceChoice, SurfaceSettings};
use anyhow::{Context, Result};
use clap::{Args, ValueEnum};

#[derive(Clone, Copy, ValueEnum)]
pub enum SurfaceArg {
    /// Gaussian density of the atoms (VMD's QuickSurf, Mol*'s default).
    Gaussian,
    /// Solvent-excluded surface: where a probe of radius --probe rolled over the atoms cannot
    /// reach.
    Ses,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum SurfaceColorArg {
    Uniform,
    Element,
    Chain,
    Residue,
    BFactor,
    Secondary,
    /// The volume's values sampled on the surface (a cube's, or the orbital or density asked
    /// for): negative red, positive blue.
    Volume,
}

impl SurfaceColorArg {
    fn coloring(self) -> Option<AtomColoring> {
        match self {
            SurfaceColorArg::Uniform => None,
            SurfaceColorArg::Element => Some(AtomColoring::Element),
            SurfaceColorArg::Chain => Some(AtomColoring::Chain),
            SurfaceColorArg::Residue => Some(AtomColoring::Residue),
            SurfaceColorArg::BFactor => Some(AtomColoring::BFactor),
            SurfaceColorArg::Secondary => Some(AtomColoring::Secondary),
            SurfaceColorArg::Volume => None,
        }
    }
}

/// The molecular surface options of `render` and `mesh`.
#[derive(Args, Clone)]
pub struct MolSurfaceArgs {
    /// A molecular surface around the atoms.
    #[arg(long, value_enum)]
    pub surface: Option<SurfaceArg>,
    /// Grid spacing of the molecular surface, Å (default 0.25 Å, coarser for big molecules).
    // Finer than the viewer allows is left to the surface's own check, which knows the
    // molecule's size and says how coarse a grid fits.
    #[arg(long, value_parser = within(1e-6..=*limits::wide(limits::SURFACE_RESOLUTION).end()))]
    pub surface_resolution: Option<f64>,
    /// Probe radius of the solvent-excluded surface, Å (0 to 10).
    #[arg(long, default_value_t = 1.4, value_parser = within(limits::wide(limits::PROBE)))]
    pub probe: f64,
    /// Smoothness α of the Gaussian surface (larger hugs the atoms tighter), 0.1 to 20.
    #[arg(long, default_value_t = SurfaceParams::SMOOTHNESS, value_parser = within(limits::wide(limits::SMOOTHNESS)))]
    pub smoothness: f64,
    /// What colours the molecular surface: one colour, or the nearest atom's element, chain,
    /// residue, B-factor or secondary structure.
    #[arg(long, value_enum, default_value_t = SurfaceColorArg::Uniform)]
    pub surface_color: SurfaceColorArg,
    /// Level of detail: parts smaller than this many pixels are drawn as points
    /// (0: every triangle).
    #[arg(long, default_value_t = SurfaceSettings::LOD_PX, value_parser = within(limits::LOD_PX))]
    pub lod_px: f32,
}

impl MolSurfaceArgs {
    /// The surface these options ask for (off without `--surface`).
    pub fn settings(&self, translucent: bool) -> SurfaceSettings {
        SurfaceSettings {
            choice: match self.surface {
                None => SurfaceChoice::Off,
                Some(SurfaceArg::Gaussian) => SurfaceChoice::Gaussian,
                Some(SurfaceArg::Ses) => SurfaceChoice::SolventExcluded,
            },
            resolution: self.surface_resolution.map(|r| r as f32),
            probe: self.probe as f32,
            smoothness: self.smoothness as f32,
            translucent,
            lod_px: self.lod_px,
            color_by: self.surface_color.coloring(),
            color_by_volume: matches!(self.surface_color, SurfaceColorArg::Volume),
            ..Default::default()
        }
    }

    /// The surface asked for, if any, with its look (coloured by `grid` when asked, with the
    /// map of its values), telling what was built and how long it took.
    pub fn mesh(
        &self,
        doc: &Document,
        translucent: bool,
        grid: Option<&crate::model::VolumeGrid>,
    ) -> Result<Option<(Mesh, SurfaceLook, Option<ValueMap>)>> {
        let settings = self.settings(translucent);
        let t = Instant::now();
        let built = molecular_surface(doc, &settings, "", u64::MAX, (&AtomicBool::new(false), &Default::default()))
            .with_context(|| format!("{}: the molecular surface", doc.source))?;
        let Some((mut mesh, _)) = built else { return Ok(None) };
        if settings.color_by_volume && grid.is_none() {
            anyhow::bail!(
                "{}: --surface-color volume needs a volume (a cube file, or a Molden/fchk orbital)",
                doc.source
            );
        }
        let map = crate::evaluate::meshes::color_surface(&mut mesh, doc, &settings, "", grid);
        eprintln!(
            "{} surface: {} triangles, area {:.1} Å², volume {:.1} Å³, {:.0} ms",
            settings.choice.name(),
            mesh.triangle_count(),
            mesh.area() / BOHR_PER_ANGSTROM.powi(2),
            mesh.volume() / BOHR_PER_ANGSTROM.powi(3),
            t.elapsed().as_secs_f64() * 1e3
        );
        Ok(Some((mesh, settings.look(), map)))
    }

    /// What mesh files call it.
    pub fn name(&self) -> &'static str {
        match self.surface {
            Some(SurfaceArg::Gaussian) => "gaussian_surface",
            Some(SurfaceArg::Ses) => "solvent_excluded_surface",
            None => "surface",
        }
    }
}

#[derive(Args)]
pub struct SurfaceBench {
    /// A structure or molecule file (PDB, mmCIF, XYZ, cube, Molden, fchk).
    file: std::path::PathBuf,
    #[command(flatten)]
    surface: MolSurfaceArgs,
    /// Timed builds per kind (the median is reported).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    #[command(flatten)]
    bench: super::BenchFrames,
    /// Zoom factor (> 1 comes closer; < 1 moves away, where the level of detail draws more
    /// points).
    #[arg(long, default_value_t = 1.0)]
    zoom: f32,
    /// Write each surface's last frame with and without the level of detail here.
    #[arg(long)]
    images: Option<std::path::PathBuf>,
    /// Draw the level of detail's triangles without occlusion culling (the picture is the same).
    #[arg(long)]
    no_occlusion: bool,
    /// Draw the level of detail with the mesh's own triangles only, no coarser versions.
    #[arg(long)]
    no_coarser: bool,
}

/// `orbcloud bench surface`: the build time of each surface (or the one `--surface` names),
/// its size, and ms per frame drawing it at the given size, turning a little each frame, with
/// every triangle and with Lee et al.'s level of detail (occlusion culled unless asked not to), and
/// how far apart the two images are.
pub fn bench(args: &SurfaceBench) -> Result<()> {
    use crate::gpu::{FrameInput, OffscreenTarget, Renderer};
    use crate::scene::{AtomStyle, Camera, RenderSettings};
    let doc = crate::formats::load(&args.file)?;
    let spheres = Sphere::of_molecule(&doc.molecule, None);
    let kinds = match args.surface.surface {
        Some(k) => vec![k],
        None => vec![SurfaceArg::Gaussian, SurfaceArg::Ses],
    };
    let color = SurfaceSettings::default().color;
    let ctx = super::gpu(args.bench.lavapipe)?;
    println!("adapter: {}", ctx.describe());
    println!("file: {}, {} atoms, {} threads", doc.source, spheres.len(), rayon::current_num_threads());
    for arg in kinds {
        let asked = MolSurfaceArgs { surface: Some(arg), ..args.surface.clone() };
        let params = asked.settings(false).params(&spheres).context("a surface kind")?;
        let mut times = Vec::new();
        let mut built = None;
        for _ in 0..args.runs.max(1) {
            let t = Instant::now();
            built = Some(surface::build(&spheres, &params, &AtomicBool::new(false))?);
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        let s = built.context("no surface was built")?;
        // Drawn alone, opaque, as the viewer draws a surface: with every triangle and with
        // Lee et al.'s level of detail, one renderer each, taking turns frame by frame.
        // Building the levels of detail (what the viewer does in the background after the
        // surface): the coarser versions and every level's octree.
        let t = Instant::now();
        let mut levels = crate::gpu::isosurface::lod_levels(&s.mesh);
        let levels_ms = t.elapsed().as_secs_f64() * 1e3;
        if args.no_coarser {
            levels.truncate(1);
        }
        let lod_px = args.surface.lod_px;
        let mut renderers = [None, Some(lod_px)].map(|lod_px| {
            let mut renderer = Renderer::new(&ctx);
            renderer.main().set_molecule(&ctx, &doc.molecule, AtomStyle::Hidden);
            let look = SurfaceLook { lod_px, ..color.into() };
            let meshes = [(s.mesh.clone(), look)];
            let trees = vec![lod_px.map(|_| levels.clone())];
            renderer.main().surfaces.set_meshes_with_trees(&ctx, &meshes, trees);
            renderer.main().surfaces.set_occlusion_culling(!args.no_occlusion);
            renderer
        });
        let (lo, hi) = s.grid.bounds();
        let mut camera = Camera::framing(lo.as_vec3(), hi.as_vec3());
        camera.zoom(1.0 / args.zoom.max(1e-3));
        let [full, lod] = &mut renderers;
        let frames =
            super::render::time_frames_of(&ctx, &mut [full, lod], &camera, args.bench.size, args.bench.frames)?;
        let [full_ms, lod_ms] = [0, 1].map(|k| frames[k][frames[k].len() / 2]);
        // The last frame again, into a target to read.
        let target = OffscreenTarget::new(&ctx.device, args.bench.size);
        let settings = RenderSettings::default();
        let mut last = camera;
        let turns = (args.bench.frames.max(1) + 1) as f32;
        last.orbit(0.02 * turns, 0.01 * turns);
        let image = |renderer: &mut Renderer| -> Result<image::RgbaImage> {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            renderer.render(
                &ctx,
                &mut encoder,
                &target.color_view,
                &FrameInput::single(&last, &settings, args.bench.size),
            );
            ctx.queue.submit([encoder.finish()]);
            Ok(target.read_rgba(&ctx.device, &ctx.queue)?)
        };
        let [full, lod] = [image(&mut renderers[0])?, image(&mut renderers[1])?];
        let renderer = &mut renderers[1];
        let (stats, occlusion) =
            (renderer.main().surfaces.lod_stats(), renderer.main().surfaces.occlusion_stats(&ctx)?);
        // The CPU's share of a frame with the level of detail: walking the octree.
        let tree = &levels[stats.level].tree;
        let view = crate::model::octree::LodView {
            clip_from_object: renderer.clip_from_world(&camera, args.bench.size),
            eye: camera.eye(),
            height_px: args.bench.size[1] as f32,
            threshold_px: lod_px,
            back_faces: true,
        };
        let mut selection = Default::default();
        let walks: Vec<f64> = (0..20)
            .map(|_| {
                let t = Instant::now();
                tree.select(&view, &mut selection);
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        let walk_ms = walks.iter().copied().fold(f64::INFINITY, f64::min);
        let (mean, covered) = super::surface::image_error(&full, &lod, &settings.background);
        if let Some(dir) = &args.images {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
            for (name, img) in [("full", &full), ("lod", &lod)] {
                let path = dir.join(format!("{}_{name}.png", asked.name()));
                img.save(&path).with_context(|| format!("writing {}", path.display()))?;
            }
        }
        let triangles = s.mesh.triangle_count();
        let phases: Vec<String> = s.phases.iter().map(|(name, t)| format!("{name} {:.0}", t * 1e3)).collect();
        println!("phases (ms, last run): {}", phases.join(", "));
        println!(
            "surface={:?} resolution_angstrom={:.2} grid={:?} triangles={triangles} area_angstrom2={:.1} volume_angstrom3={:.1} \
             build_ms_median={:.1} build_ms_min={:.1} ({}x{}) frame_ms_all_triangles={full_ms:.1} \
             frame_ms_lod={lod_ms:.1} lod_px={lod_px} lod_triangles={} lod_points={} speedup={:.2} \
             lod_error_mean={mean:.2}/255 lod_error_covered={covered:.2}/255 lod_walk_ms={walk_ms:.2} \
             lod_drawn_first={} lod_drawn_after_occlusion_test={} lod_level={} lod_levels={} lod_levels_triangles={} \
             lod_levels_build_ms={levels_ms:.0}",
            params.kind,
            params.resolution / BOHR_PER_ANGSTROM,
            s.grid.dims,
            s.mesh.area() / BOHR_PER_ANGSTROM.powi(2),
            s.mesh.volume() / BOHR_PER_ANGSTROM.powi(3),
            times[times.len() / 2],
            times[0],
            args.bench.size[0],
            args.bench.size[1],
            stats.triangles,
            stats.splats,
            full_ms / lod_ms,
            occlusion.first,
            occlusion.second,
            stats.level,
            levels.len(),
            levels.iter().map(|l| (l.tree.indices.len() / 3).to_string()).collect::<Vec<_>>().join("/"),
        );
    }
    Ok(())
}
