//! Molecular surfaces on the GPU (lavapipe): the solvent-excluded surface of a protein fragment
//! against its golden image, and Lee et al.'s level of detail against every triangle: parts far
//! away become points, the picture stays within 2/255, picking still finds the surface.

mod common;

use std::sync::atomic::AtomicBool;

use orbcloud::evaluate::meshes::molecular_surface;
use orbcloud::gpu::frame::PickId;
use orbcloud::gpu::{FrameInput, OffscreenTarget, Renderer};
use orbcloud::model::isosurface::Mesh;
use orbcloud::model::octree::{LodLevel, SurfaceOctree};
use orbcloud::scene::translucency::SurfaceLook;
use orbcloud::scene::{AtomStyle, Camera, RenderSettings, SurfaceChoice, SurfaceSettings};

const SIZE: [u32; 2] = [256, 192];

/// A threshold at which this small fragment has parts drawn as points.
const POINTS_PX: f32 = 3.0;

fn fragment() -> (orbcloud::model::Document, Mesh) {
    let pdb = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/structures/4e43_excerpt.pdb");
    let doc = orbcloud::formats::load(std::path::Path::new(pdb)).unwrap();
    let settings =
        SurfaceSettings { choice: SurfaceChoice::SolventExcluded, resolution: Some(0.35), ..Default::default() };
    let (mesh, note) =
        molecular_surface(&doc, &settings, "not resn HOH", u64::MAX, (&AtomicBool::new(false), &Default::default()))
            .unwrap()
            .unwrap();
    assert!(note.is_none(), "{note:?}");
    (doc, mesh)
}

fn draw(
    ctx: &orbcloud::gpu::GpuContext,
    renderer: &mut Renderer,
    camera: &Camera,
) -> (image::RgbaImage, orbcloud::gpu::isosurface::LodStats) {
    let target = OffscreenTarget::new(&ctx.device, SIZE);
    let settings = RenderSettings::default();
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    renderer.render(ctx, &mut encoder, &target.color_view, &FrameInput::single(camera, &settings, SIZE));
    ctx.queue.submit([encoder.finish()]);
    (target.read_rgba(&ctx.device, &ctx.queue).unwrap(), renderer.main().surfaces.lod_stats())
}

#[test]
fn far_parts_become_points_within_two_levels_of_every_triangle() {
    let ctx = common::lavapipe();
    let (doc, mesh) = fragment();
    let mut renderer = Renderer::new(&ctx);
    renderer.main().set_molecule(&ctx, &doc.molecule, AtomStyle::Hidden);
    let (lo, hi) = doc.molecule.bounds().unwrap();
    let mut camera = Camera::framing(lo.as_vec3(), hi.as_vec3());
    camera.orbit(0.6, 0.3);
    let color = SurfaceSettings::default().color;

    // Every triangle: the golden picture.
    orbcloud::layers::show_meshes(&ctx, renderer.main(), &[(mesh.clone(), color.into())]);
    let (full, stats) = draw(&ctx, &mut renderer, &camera);
    assert_eq!(stats.total_triangles, 0, "no level of detail asked for");
    common::assert_golden("surface_ses_fragment", &full);

    // Lee et al.'s level of detail at 3 px: some cells are points, the rest
    // triangles, the picture within 2/255.
    let look = SurfaceLook { lod_px: Some(POINTS_PX), ..color.into() };
    orbcloud::layers::show_meshes(&ctx, renderer.main(), &[(mesh.clone(), look)]);
    let (lod, stats) = draw(&ctx, &mut renderer, &camera);
    let n = mesh.triangle_count() as u64;
    assert_eq!(stats.total_triangles, n);
    assert!(stats.splats > 0 && stats.triangles < n, "{stats:?}");
    // Framed small, it draws a coarser version of the mesh.
    assert!(stats.level > 0, "{stats:?}");
    let mean = common::mean_difference(&full, &lod);
    eprintln!("level of detail at {POINTS_PX} px: {stats:?}, mean difference {mean:.3}/255");
    assert!(mean < 2.0, "mean difference {mean}/255");
    // Where the frame shows the surface, picking says so, points included.
    let covered = full.enumerate_pixels().filter(|(_, _, p)| p[0] > 100).count();
    assert!(covered > (SIZE[0] * SIZE[1] / 10) as usize, "the surface fills the view: {covered} pixels");
    let picked = renderer.pick(&ctx, [SIZE[0] / 2, SIZE[1] / 2]).unwrap();
    assert!(matches!(picked, Some(PickId::Surface { object: 0, index: 0 })), "{picked:?}");

    // While the view is dragged the threshold is four times larger: more points, fewer
    // triangles, and still the same surface at a glance.
    renderer.set_lod_scale(4.0);
    let (dragged, coarse) = draw(&ctx, &mut renderer, &camera);
    assert!(coarse.splats > stats.splats && coarse.triangles < stats.triangles, "{coarse:?} vs {stats:?}");
    let mean = common::mean_difference(&full, &dragged);
    assert!(mean < 8.0, "while dragging: mean difference {mean}/255");
    // Far away, the whole fragment is a handful of points.
    camera.distance *= 40.0;
    renderer.set_lod_scale(1.0);
    let (_, far) = draw(&ctx, &mut renderer, &camera);
    assert!(far.triangles == 0 && (1..64).contains(&far.splats), "{far:?}");
}

/// Coloured by atoms, each vertex takes the colour of the atom whose van der Waals surface is
/// nearest it (checked by brute force on every 50th vertex).
#[test]
fn a_surface_coloured_by_element_takes_each_vertex_from_its_nearest_atom() {
    use orbcloud::model::surface::Sphere;
    use orbcloud::scene::AtomColoring;
    let (doc, mut mesh) = fragment();
    let settings = SurfaceSettings {
        choice: SurfaceChoice::SolventExcluded,
        color_by: Some(AtomColoring::Element),
        ..Default::default()
    };
    orbcloud::evaluate::meshes::color_surface(&mut mesh, &doc, &settings, "not resn HOH", None);
    assert_eq!(mesh.colors.len(), mesh.positions.len());
    let selection = orbcloud::scene::selection::Selection::parse("not resn HOH").unwrap();
    let mask = selection.mask(&doc.molecule, doc.structure.as_ref());
    let (spheres, atoms) = Sphere::of_atoms(&doc.molecule, Some(&mask));
    let mut elements = std::collections::BTreeSet::new();
    for (v, (p, c)) in mesh.positions.iter().zip(&mesh.colors).enumerate().step_by(50) {
        let p = p.as_dvec3();
        let nearest = (0..spheres.len())
            .min_by(|&a, &b| {
                let d = |k: usize| (p - spheres[k].centre).length() - spheres[k].radius;
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        let atom = &doc.molecule.atoms[atoms[nearest] as usize];
        let expected = orbcloud::scene::coloring::linear(atom.element().color);
        assert_eq!(*c, expected, "vertex {v} at {p}: nearest atom {} ({})", atoms[nearest], atom.element().symbol);
        elements.insert(atom.element().symbol);
    }
    assert!(elements.contains("C") && elements.contains("N") && elements.contains("O"), "{elements:?}");
    // The look carries no colour of its own: the vertices do.
    assert_eq!(settings.look().color, [1.0; 3]);
}

/// Coloured by a volume (a potential on a grid): negative red, positive blue, white near zero,
/// grey outside the grid.
#[test]
fn a_surface_coloured_by_a_volume_shows_the_sign_of_its_values() {
    use glam::{DVec3, Vec3};
    use orbcloud::model::VolumeGrid;
    // f = x on a grid spanning x ∈ [−5, 5] bohr.
    let n = 11;
    let grid = VolumeGrid::new(
        "potential",
        [n, n, n],
        VolumeGrid::affine(DVec3::splat(-5.0), [DVec3::X, DVec3::Y, DVec3::Z]),
        (0..n * n * n).map(|p| (p / (n * n)) as f32 - 5.0).collect(),
    );
    let points =
        [Vec3::new(-4.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(4.0, 0.0, 0.0), Vec3::new(9.0, 0.0, 0.0)];
    let (colors, _) = orbcloud::evaluate::meshes::color_by_values(&points, &grid);
    let [neg, zero, pos, outside] = [colors[0], colors[1], colors[2], colors[3]];
    assert!(neg[0] > 0.8 && neg[2] < 0.3, "negative is red: {neg:?}");
    assert!(pos[2] > 0.8 && pos[0] < 0.3, "positive is blue: {pos:?}");
    assert!(zero.iter().all(|&c| c > 0.99), "zero is white: {zero:?}");
    assert_eq!(outside, [0.5; 3], "outside the grid: grey");
}

/// Occlusion culling of a big surface (two phases, into indirect draws) keeps the picture: three
/// compact blobs one behind another, drawn with every triangle the level of detail chose and
/// with the culling, give the same pixels and picks, cold, warm and after a turn; once the front
/// blob was seen, most of the hidden ones are not drawn at all.
#[test]
fn occlusion_culling_draws_less_and_keeps_the_picture() {
    use glam::DVec3;
    use orbcloud::model::surface::{self, Sphere, SurfaceKind, SurfaceParams};
    let ctx = common::lavapipe();
    // A blob: the solvent-excluded surface of 6×6×6 carbon-sized atoms 2.5 bohr apart.
    let spheres: Vec<Sphere> = (0..216)
        .map(|k| Sphere { centre: DVec3::new((k % 6) as f64, (k / 6 % 6) as f64, (k / 36) as f64) * 2.5, radius: 3.2 })
        .collect();
    let mut params = SurfaceParams::auto(SurfaceKind::SolventExcluded, &spheres);
    params.resolution = 0.3;
    let blob = surface::build(&spheres, &params, &AtomicBool::new(false)).unwrap().mesh;
    let (lo, hi) = blob
        .positions
        .iter()
        .fold((glam::Vec3::INFINITY, glam::Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let camera = Camera::framing(lo, hi);
    // Copies behind the first along the view, each a little to the side so part of it shows.
    let back = (camera.target - camera.eye()).normalize();
    let side = back.cross(camera.up()).normalize();
    let size = (hi - lo).length();
    let lattice = |blobs: usize| {
        let mut lattice = Mesh::default();
        for k in 0..blobs {
            let shift = (back + side * 0.1) * size * k as f32;
            let base = lattice.positions.len() as u32;
            lattice.positions.extend(blob.positions.iter().map(|p| *p + shift));
            lattice.normals.extend_from_slice(&blob.normals);
            lattice.indices.extend(blob.indices.iter().map(|i| i + base));
        }
        lattice
    };
    let mut renderer = Renderer::new(&ctx);
    let look = SurfaceLook { lod_px: Some(0.0), ..SurfaceSettings::default().color.into() };
    // Only the mesh itself as its level of detail: a turn that changed the version drawn would
    // start its batches unseen.
    let show = |renderer: &mut Renderer, mesh: Mesh| {
        let tree = SurfaceOctree::build(&mesh, orbcloud::gpu::isosurface::LEAF_SIZE);
        let levels = vec![Some(vec![LodLevel { tree, error: 0.0 }])];
        renderer.main().surfaces.set_meshes_with_trees(&ctx, &[(mesh, look)], levels);
    };
    show(&mut renderer, lattice(3));
    let center = [SIZE[0] / 2, SIZE[1] / 2];
    let frame = |renderer: &mut Renderer, camera: &Camera, culled: bool| {
        renderer.main().surfaces.set_occlusion_culling(culled);
        let (image, _) = draw(&ctx, renderer, camera);
        let stats = renderer.main().surfaces.occlusion_stats(&ctx).unwrap();
        (image, stats, renderer.pick(&ctx, center).unwrap())
    };
    let (every, _, every_pick) = frame(&mut renderer, &camera, false);
    assert!(matches!(every_pick, Some(PickId::Surface { object: 0, index: 0 })), "{every_pick:?}");
    let (cold, cold_stats, cold_pick) = frame(&mut renderer, &camera, true);
    assert_eq!(common::mean_difference(&every, &cold), 0.0, "the first culled frame");
    assert_eq!(cold_pick, every_pick);
    // Cold, nothing was seen before: every batch waits for the test, and with nothing drawn
    // yet the test hides none.
    assert_eq!((cold_stats.first, cold_stats.second), (0, cold_stats.chosen), "{cold_stats:?}");
    // The same view again: everything was seen, so everything is drawn first, and the test
    // after it marks only what shows. From the third frame on the hidden copies are skipped,
    // and nothing is left to draw after the test.
    let (again, again_stats, _) = frame(&mut renderer, &camera, true);
    assert_eq!(common::mean_difference(&every, &again), 0.0, "the second culled frame");
    assert_eq!((again_stats.first, again_stats.second), (again_stats.chosen, 0), "{again_stats:?}");
    let (warm, warm_stats, _) = frame(&mut renderer, &camera, true);
    assert_eq!(common::mean_difference(&every, &warm), 0.0, "the third culled frame");
    assert_eq!(warm_stats.second, 0, "{warm_stats:?}");
    // Turned a little: the batches that come into view are drawn after the test.
    let mut turned = camera;
    turned.orbit(0.25, 0.1);
    let (culled, turned_stats, culled_pick) = frame(&mut renderer, &turned, true);
    let (every, _, every_pick) = frame(&mut renderer, &turned, false);
    assert_eq!(common::mean_difference(&every, &culled), 0.0, "after a turn");
    assert_eq!(culled_pick, every_pick);
    assert!(
        turned_stats.second > 0 && turned_stats.first + turned_stats.second < turned_stats.chosen,
        "{turned_stats:?}"
    );
    // The front blob alone: its own far side is hidden too, and the two blobs behind it add
    // little to what is drawn.
    show(&mut renderer, lattice(1));
    let alone = (0..3).map(|_| frame(&mut renderer, &camera, true).1).last().unwrap();
    assert!(alone.first * 10 < alone.chosen * 6, "{alone:?}");
    assert!(warm_stats.first * 10 < alone.first * 11, "{warm_stats:?} against the front blob alone {alone:?}");
    eprintln!(
        "occlusion culling: cold {cold_stats:?}, warm {warm_stats:?}, turned {turned_stats:?}, front alone {alone:?}"
    );
}
