//! Translucent isosurfaces (Koide and Miyata, docs/references.md) on lavapipe: the GPU's sorted fragment lists against a
//! CPU reference that sorts every fragment, independence of the order surfaces are given in,
//! frames over the fragment budget drawn in bands, the glow where surfaces of two objects
//! overlap, surfaces inside a cloud against a CPU reference that walks both, and overlapping
//! clouds composited in one depth order whichever is listed first.

mod common;

use common::cloud::{CloudReference, srgb_encode};
use common::{formaldehyde, lavapipe, p_orbital};
use glam::{DVec3, Vec3};
use orbcloud::evaluate::meshes::isosurfaces;
use orbcloud::gpu::{FrameInput, GpuContext, OffscreenTarget, Renderer};
use orbcloud::layers::{show_meshes, show_object, show_scene};
use orbcloud::model::{Document, VolumeGrid};
use orbcloud::pictures::headless::draw_exact;
use orbcloud::scene::translucency::{Walk, composite, sort_fragments};
use orbcloud::scene::{AtomStyle, Camera, IsoLevel, IsosurfaceSettings, ObjectState, OpticsPreset, VolumeSettings};

const SIZE: [u32; 2] = [160, 120];
const BACKGROUND: [f32; 3] = [0.02, 0.02, 0.03];

/// ρ = exp(−|r − centre|²/2) on a 40³ grid around it.
fn blob(centre: DVec3) -> VolumeGrid {
    let n = 40;
    let h = 10.0 / (n - 1) as f64;
    let world = VolumeGrid::affine(centre - 5.0, [DVec3::X * h, DVec3::Y * h, DVec3::Z * h]);
    let mut values = Vec::with_capacity(n * n * n);
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = world.transform_point3(DVec3::new(i as f64, j as f64, k as f64));
                values.push((-(p - centre).length_squared() / 2.0).exp() as f32);
            }
        }
    }
    VolumeGrid::new("blob", [n, n, n], world, values)
}

fn translucent(level: f32, color: [f32; 3]) -> IsosurfaceSettings {
    IsosurfaceSettings {
        visible: true,
        level: IsoLevel::Absolute(level),
        translucent: true,
        optics: OpticsPreset::Koide,
        positive_color: color,
        density_color: color,
        ..Default::default()
    }
}

fn object(iso: IsosurfaceSettings, atoms: AtomStyle) -> ObjectState {
    let mut settings = orbcloud::scene::RenderSettings { atoms, iso, ..Default::default() };
    settings.volume.visible = false;
    ObjectState::of_settings(Some(orbcloud::scene::Source::Volume(0)), &settings)
}

fn camera() -> Camera {
    let mut cam = Camera::framing(Vec3::splat(-3.5), Vec3::splat(3.5));
    cam.orbit(0.5, 0.35);
    cam
}

fn draw(ctx: &GpuContext, renderer: &mut Renderer) -> (image::RgbaImage, orbcloud::gpu::oit::FragmentStats) {
    let target = OffscreenTarget::new(&ctx.device, SIZE);
    let cam = camera();
    let hidden = [VolumeSettings { visible: false, ..Default::default() }; 4];
    let frame = FrameInput { camera: &cam, background: BACKGROUND, clouds: &hidden, size: SIZE, tile: None };
    let stats = draw_exact(ctx, renderer, &target.color_view, &frame).expect("translucent surfaces drawn");
    (target.read_rgba(&ctx.device, &ctx.queue).expect("read back"), stats)
}

/// An orbital's ± lobes with the molecule's atoms inside them (object 0), and a density blob
/// overlapping the + lobe (object 1).
fn two_objects(ctx: &GpuContext, renderer: &mut Renderer) {
    let orbital = Document { molecule: formaldehyde(), volumes: vec![p_orbital(48, false)], ..Default::default() };
    let mut iso = translucent(0.08, [0.85, 0.1, 0.08]);
    iso.negative_color = [0.08, 0.25, 0.85];
    show_object(ctx, renderer.layer_mut(ctx, 0), &orbital, &object(iso, AtomStyle::BallAndStick)).expect("orbital");
    let density = Document { volumes: vec![blob(DVec3::new(0.5, 0.3, 1.6))], ..Default::default() };
    let state = object(translucent(0.25, [0.9, 0.8, 0.2]), AtomStyle::Hidden);
    show_object(ctx, renderer.layer_mut(ctx, 1), &density, &state).expect("density");
}

fn srgb(linear: f32) -> f32 {
    let c = linear.clamp(0.0, 1.0);
    if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

fn max_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> u8 {
    a.pixels().zip(b.pixels()).flat_map(|(p, q)| (0..3).map(move |k| p[k].abs_diff(q[k]))).max().unwrap_or(0)
}

#[test]
fn exact_order_matches_a_cpu_reference_that_sorts_every_fragment() {
    let ctx = lavapipe();
    let mut renderer = Renderer::new(&ctx);
    two_objects(&ctx, &mut renderer);
    let (img, stats) = draw(&ctx, &mut renderer);
    assert!(stats.fits() && stats.bands == 1, "{stats:?}");
    assert_eq!(stats.deep_pixels, 0);
    let (dump, behind) = renderer.read_translucency(&ctx).expect("fragments read back");
    assert_eq!(dump.surfaces.len(), 3, "two lobes and a blob");
    let total: usize = dump.lists.iter().map(Vec::len).sum();
    let deepest = dump.lists.iter().map(Vec::len).max().unwrap_or(0);
    assert_eq!(total as u32, stats.needed, "every fragment counted was stored");
    assert!(total > 5_000 && deepest >= 4, "{total} fragments, at most {deepest} in a pixel");
    // The atoms are opaque: no fragment behind them was kept.
    let mut reference = image::RgbaImage::new(SIZE[0], SIZE[1]);
    for (n, (list, back)) in dump.lists.iter().zip(&behind).enumerate() {
        let mut list = list.clone();
        // The GPU appends in whatever order its rasteriser ran; shuffle ours too.
        list.reverse();
        sort_fragments(&mut list);
        let c = composite(&list, &dump.surfaces, *back);
        let px = c.map(|v| (srgb(v) * 255.0).round() as u8);
        reference.put_pixel(n as u32 % SIZE[0], n as u32 / SIZE[0], image::Rgba([px[0], px[1], px[2], 255]));
    }
    let mean = common::mean_difference(&img, &reference);
    let max = max_difference(&img, &reference);
    eprintln!("GPU against the CPU-sorted reference: mean {mean:.4}/255, max {max}/255");
    assert!(mean < 1.0, "mean difference {mean}/255");
    assert!(max <= 3, "max difference {max}/255");
}

#[test]
fn any_order_of_the_surfaces_gives_the_same_image() {
    let ctx = lavapipe();
    let grid = blob(DVec3::ZERO);
    let shells: Vec<_> = [0.1, 0.3, 0.5, 0.7]
        .iter()
        .zip([[0.9, 0.2, 0.1], [0.9, 0.8, 0.2], [0.2, 0.8, 0.3], [0.2, 0.4, 0.9]])
        .flat_map(|(&v, c)| isosurfaces(&grid, &translucent(v, c)))
        .collect();
    assert_eq!(shells.len(), 4);
    let mut images = Vec::new();
    for order in [[0, 1, 2, 3], [3, 2, 1, 0], [2, 0, 3, 1]] {
        let mut renderer = Renderer::new(&ctx);
        let meshes: Vec<_> = order.iter().map(|&k| shells[k].clone()).collect();
        show_meshes(&ctx, renderer.main(), &meshes);
        images.push(draw(&ctx, &mut renderer).0);
    }
    // Nested shells: each seen through the others, so every pixel of the outer disc holds 8.
    for other in &images[1..] {
        assert!(max_difference(&images[0], other) <= 1, "max {}", max_difference(&images[0], other));
    }
    let lit = images[0].pixels().filter(|p| p[0] as f32 > 40.0).count();
    assert!(lit > 2_000, "{lit} pixels show the shells");
}

#[test]
fn a_frame_over_the_fragment_budget_is_drawn_in_bands_with_the_same_result() {
    let ctx = lavapipe();
    let mut whole = Renderer::new(&ctx);
    two_objects(&ctx, &mut whole);
    let (expected, one) = draw(&ctx, &mut whole);
    let capacity = one.needed / 5;
    let mut banded = Renderer::with_fragment_capacity(&ctx, capacity);
    two_objects(&ctx, &mut banded);
    let (img, stats) = draw(&ctx, &mut banded);
    eprintln!("{} fragments; budget {capacity}: {stats:?}", one.needed);
    assert!(stats.fits(), "{stats:?}");
    assert!(stats.bands >= 5, "{stats:?}");
    assert!(max_difference(&expected, &img) <= 1, "max {}", max_difference(&expected, &img));
}

#[test]
fn surfaces_of_two_objects_glow_where_they_overlap_and_only_there() {
    let ctx = lavapipe();
    let (a, b) = (blob(DVec3::new(-1.2, 0.0, 0.0)), blob(DVec3::new(1.2, 0.0, 0.0)));
    let red = isosurfaces(&a, &translucent(0.2, [0.9, 0.15, 0.1]));
    let blue = isosurfaces(&b, &translucent(0.2, [0.1, 0.3, 0.9]));
    let render = |layers: &[&[_]]| {
        let mut renderer = Renderer::new(&ctx);
        for (n, meshes) in layers.iter().enumerate() {
            show_meshes(&ctx, renderer.layer_mut(&ctx, n), meshes);
        }
        draw(&ctx, &mut renderer).0
    };
    let both: Vec<_> = red.iter().chain(&blue).cloned().collect();
    let one_object = render(&[&both]);
    let two_objects = render(&[&red, &blue]);
    let covered = |img: &image::RgbaImage| -> Vec<bool> {
        let bg = BACKGROUND.map(|v| (srgb(v) * 255.0).round() as i32);
        img.pixels().map(|p| (0..3).any(|k| (p[k] as i32 - bg[k]).abs() > 2)).collect()
    };
    let (in_red, in_blue) = (covered(&render(&[&red])), covered(&render(&[&blue])));
    let mut glowing = 0;
    for (n, (p, q)) in one_object.pixels().zip(two_objects.pixels()).enumerate() {
        if p != q {
            assert!(in_red[n] && in_blue[n], "pixel {n} changed outside the overlap");
            glowing += 1;
            // The glow is brighter.
            let sum = |c: &image::Rgba<u8>| c[0] as u32 + c[1] as u32 + c[2] as u32;
            assert!(sum(q) + 3 >= sum(p), "pixel {n}: {p:?} -> {q:?}");
        }
    }
    let overlap = in_red.iter().zip(&in_blue).filter(|(r, b)| **r && **b).count();
    eprintln!("{glowing} of {overlap} pixels covered by both glow");
    assert!(glowing > 200 && glowing <= overlap, "{glowing} glowing of {overlap}");
}

/// One object holding two quantities, a density and an orbital, each a translucent surface: the
/// orbital's surface glows inside the density's (they are different quantities), while the same
/// surfaces as shells of one quantity do not.
#[test]
fn an_orbitals_surface_glows_inside_its_own_molecules_density_surface() {
    let ctx = lavapipe();
    let density = blob(DVec3::ZERO);
    let orbital = p_orbital(48, false);
    let doc = Document { volumes: vec![density.clone(), orbital.clone()], ..Default::default() };
    let (density_look, orbital_look) = (translucent(0.3, [0.62, 0.66, 0.72]), translucent(0.08, [0.9, 0.15, 0.1]));
    let mut state = object(density_look, AtomStyle::Hidden);
    let mut second = state.quantities[0].clone();
    second.source = orbcloud::scene::Source::Volume(1);
    second.isosurfaces = vec![orbital_look];
    state.quantities.push(second);
    let mut renderer = Renderer::new(&ctx);
    show_scene(&ctx, &mut renderer, &[(&doc, state)], 48).expect("object shown");
    let (own_object, _) = draw(&ctx, &mut renderer);
    // The same surfaces as one quantity's shells: no glow.
    let shells: Vec<_> =
        isosurfaces(&density, &density_look).into_iter().chain(isosurfaces(&orbital, &orbital_look)).collect();
    let mut one = Renderer::new(&ctx);
    show_meshes(&ctx, one.layer_mut(&ctx, 1), &shells);
    let (one_quantity, _) = draw(&ctx, &mut one);
    let changed = own_object.pixels().zip(one_quantity.pixels()).filter(|(p, q)| p != q).count();
    let brighter = own_object
        .pixels()
        .zip(one_quantity.pixels())
        .filter(|(p, q)| (0..3).map(|k| p[k] as u32).sum::<u32>() > (0..3).map(|k| q[k] as u32).sum::<u32>() + 3)
        .count();
    eprintln!("{changed} pixels differ from one quantity's shells, {brighter} of them brighter");
    assert!(brighter > 300, "the orbital glows inside the density: {brighter} brighter pixels");
    assert!(brighter * 10 >= changed * 9, "the difference is the glow: {brighter} of {changed} brighter");
}

#[test]
fn surfaces_inside_a_cloud_match_a_cpu_reference_that_walks_both() {
    let ctx = lavapipe();
    let grid = p_orbital(32, false);
    let doc = Document { volumes: vec![grid.clone()], ..Default::default() };
    let max = grid.stats.max_abs as f32;
    let mut iso = translucent(0.3 * max, [0.85, 0.1, 0.08]);
    iso.negative_color = [0.08, 0.25, 0.85];
    let mut state = object(iso, AtomStyle::Hidden);
    let cloud = &mut state.quantities[0].cloud;
    cloud.visible = true;
    cloud.slices = 48;
    cloud.k1 = 0.5;
    let mut renderer = Renderer::new(&ctx);
    show_object(&ctx, renderer.main(), &doc, &state).expect("orbital");
    let cam = camera();
    let target = OffscreenTarget::new(&ctx.device, SIZE);
    let frame = FrameInput {
        camera: &cam,
        background: BACKGROUND,
        clouds: std::slice::from_ref(&state.quantities[0].cloud),
        size: SIZE,
        tile: None,
    };
    draw_exact(&ctx, &mut renderer, &target.color_view, &frame).expect("translucent surfaces drawn");
    let gpu = target.read_rgba(&ctx.device, &ctx.queue).expect("read back");
    let (dump, _) = renderer.read_translucency(&ctx).expect("fragments read back");
    let clip = renderer.clip_from_world(&cam, SIZE).as_dmat4();
    let settings = state.render_settings(0, BACKGROUND);
    let cloud = CloudReference::new(&grid, &cam, &settings);
    // `interleaved`: each sample after the fragments nearer than it; else every fragment in
    // front of the cloud (what compositing the surfaces over the finished cloud would give).
    let reference = |interleaved: bool| {
        image::RgbaImage::from_fn(SIZE[0], SIZE[1], |px, py| {
            let mut fragments = dump.lists[(py * SIZE[0] + px) as usize].clone();
            sort_fragments(&mut fragments);
            let d = cloud.ray(&cam, SIZE, px, py);
            let mut walk = Walk::new(&fragments);
            let mut next = fragments.iter().peekable();
            for sample in cloud.samples(d).into_iter().rev() {
                let z = clip.project_point3(cloud.eye + d * sample.t).z as f32;
                while let Some(frag) = next.next_if(|f| f.depth < z || !interleaved) {
                    walk.fragment(frag, &dump.surfaces);
                }
                walk.sample(sample.color.map(|c| c as f32), sample.alpha as f32);
            }
            for frag in next {
                walk.fragment(frag, &dump.surfaces);
            }
            let c = walk.finish(BACKGROUND);
            image::Rgba([srgb_encode(c[0] as f64), srgb_encode(c[1] as f64), srgb_encode(c[2] as f64), 255])
        })
    };
    let cpu = reference(true);
    let inside = dump.lists.iter().filter(|l| !l.is_empty()).count();
    let mean = common::mean_difference(&gpu, &cpu);
    let over = gpu.pixels().zip(cpu.pixels()).filter(|(p, q)| (0..3).any(|k| p[k].abs_diff(q[k]) > 3)).count();
    let n = gpu.pixels().len();
    eprintln!(
        "cloud and surfaces against the CPU walk: mean {mean:.3}/255, {over} of {n} pixels > 3/255; {inside} pixels hold fragments"
    );
    assert!(inside > 1_000, "{inside} pixels show surfaces");
    // The tolerance of the cloud's own reference (tests/volume_reference.rs): the f16 scene
    // buffer rounds every blend, and a ray grazing a slice's edge may see one slice more.
    assert!(mean < 1.0 && over * 100 < n, "mean {mean:.3}/255, {over} pixels > 3/255");
    // Surfaces merely laid over the cloud would be far off.
    let over_the_cloud = common::mean_difference(&gpu, &reference(false));
    assert!(over_the_cloud > 5.0 * mean.max(0.2), "surfaces over the cloud: {over_the_cloud:.3}/255");
    // The cloud veils the surfaces: without it they would look different.
    let mut bare = Renderer::new(&ctx);
    show_object(&ctx, bare.main(), &doc, &object(iso, AtomStyle::Hidden)).expect("orbital");
    let (alone, _) = draw(&ctx, &mut bare);
    assert!(common::mean_difference(&alone, &gpu) > 3.0, "the cloud changes the picture");
}

/// ψ = (z − c_z)·exp(−|r − c|²/12) (signed) or ρ = exp(−|r − c|²/6) on a 32³ grid of ±4 bohr
/// around `centre`: no margin the slices would trim, so a reference slicing the whole box
/// samples where the GPU does.
fn wide_cloud(centre: DVec3, signed: bool) -> VolumeGrid {
    let n = 32;
    let h = 8.0 / (n - 1) as f64;
    let world = VolumeGrid::affine(centre - 4.0, [DVec3::X * h, DVec3::Y * h, DVec3::Z * h]);
    let values = (0..n * n * n)
        .map(|m| {
            let p = world.transform_point3(DVec3::new((m / (n * n)) as f64, ((m / n) % n) as f64, (m % n) as f64));
            let d = p - centre;
            let v = if signed { d.z * (-d.length_squared() / 12.0).exp() } else { (-d.length_squared() / 6.0).exp() };
            v as f32
        })
        .collect();
    VolumeGrid::new(if signed { "orbital" } else { "density" }, [n, n, n], world, values)
}

/// Two clouds that overlap on screen, an orbital's and a density's (with translucent
/// isosurfaces when `surfaces`), drawn with the orbital in layer `orbital_layer`.
fn two_clouds(
    ctx: &GpuContext,
    orbital_layer: usize,
    surfaces: bool,
) -> (image::RgbaImage, Vec<(VolumeGrid, ObjectState)>) {
    cloud_pairs(ctx, &[DVec3::ZERO], orbital_layer == 1, surfaces, &camera())
}

/// An orbital and a density overlapping around each of `centres`, each quantity its own layer
/// (the last pair listed density first when `swap_last`), drawn from `cam`.
fn cloud_pairs(
    ctx: &GpuContext,
    centres: &[DVec3],
    swap_last: bool,
    surfaces: bool,
    cam: &Camera,
) -> (image::RgbaImage, Vec<(VolumeGrid, ObjectState)>) {
    let look = |grid: VolumeGrid, color: [f32; 3], level: f32| {
        let mut iso = translucent(level, color);
        iso.visible = surfaces;
        let mut state = object(iso, AtomStyle::Hidden);
        let cloud = &mut state.quantities[0].cloud;
        cloud.visible = true;
        cloud.slices = 48;
        cloud.k1 = 0.3;
        // A blob that fades out, not a box filled to its edges.
        cloud.density_scale = orbcloud::scene::DensityScale::Linear;
        cloud.positive_color = color;
        (grid, state)
    };
    let mut layers = Vec::new();
    for (n, &centre) in centres.iter().enumerate() {
        let orbital = look(wide_cloud(centre + DVec3::new(-0.8, 0.0, 0.0), true), [0.9, 0.3, 0.1], 0.3);
        let density = look(wide_cloud(centre + DVec3::new(1.0, 0.4, 0.3), false), [0.2, 0.5, 0.95], 0.5);
        match swap_last && n + 1 == centres.len() {
            true => layers.extend([density, orbital]),
            false => layers.extend([orbital, density]),
        }
    }
    let mut renderer = Renderer::new(ctx);
    for (n, (grid, state)) in layers.iter().enumerate() {
        let doc = Document { volumes: vec![grid.clone()], ..Default::default() };
        show_object(ctx, renderer.layer_mut(ctx, n), &doc, state).expect("cloud shown");
    }
    let target = OffscreenTarget::new(&ctx.device, SIZE);
    let clouds: Vec<VolumeSettings> = layers.iter().map(|(_, s)| s.quantities[0].cloud).collect();
    let frame = FrameInput { camera: cam, background: BACKGROUND, clouds: &clouds, size: SIZE, tile: None };
    // Counts come back only with translucent surfaces.
    let _ = draw_exact(ctx, &mut renderer, &target.color_view, &frame);
    (target.read_rgba(&ctx.device, &ctx.queue).expect("read back"), layers)
}

#[test]
fn pairs_of_clouds_apart_on_screen_are_each_walked_in_one_depth_order() {
    // Three molecules' worth of clouds (six, more than one walk takes): the pairs lie apart on
    // screen, so each pair is walked on its own and the order of the last pair's quantities
    // changes nothing, with translucent surfaces or without.
    let ctx = lavapipe();
    let centres = [DVec3::new(-20.0, 0.0, 0.0), DVec3::ZERO, DVec3::new(20.0, 0.0, 0.0)];
    let mut cam = Camera::framing(Vec3::new(-26.0, -5.0, -5.0), Vec3::new(26.0, 5.0, 5.0));
    cam.orbit(0.15, 0.3);
    for surfaces in [false, true] {
        let (first, _) = cloud_pairs(&ctx, &centres, false, surfaces, &cam);
        let (second, _) = cloud_pairs(&ctx, &centres, true, surfaces, &cam);
        let swapped = max_difference(&first, &second);
        // The last pair alone: its pixels are the same in the scene of three.
        let (alone, _) = cloud_pairs(&ctx, &centres[2..], false, surfaces, &cam);
        let footprint: Vec<usize> = (alone.pixels().enumerate())
            .filter(|(_, p)| (0..3).any(|k| p[k].abs_diff((BACKGROUND[k].powf(1.0 / 2.2) * 255.0) as u8) > 8))
            .map(|(n, _)| n)
            .collect();
        let pixels: Vec<_> = first.pixels().collect();
        let apart = footprint
            .iter()
            .map(|&n| (0..3).map(|k| pixels[n][k].abs_diff(alone.pixels().nth(n).unwrap()[k])).max().unwrap_or(0))
            .max()
            .unwrap_or(0);
        eprintln!(
            "three pairs (surfaces {surfaces}): last pair swapped {swapped}/255; its {} pixels against it alone {apart}/255",
            footprint.len()
        );
        assert!(swapped <= 1, "swapping the last pair's quantities changed the picture by {swapped}/255");
        assert!(footprint.len() > 500, "the last pair shows");
        assert!(apart <= 2, "the last pair differs from itself alone by {apart}/255");
    }
}

#[test]
fn overlapping_clouds_are_composited_in_one_depth_order_whichever_is_listed_first() {
    let ctx = lavapipe();
    let (first, layers) = two_clouds(&ctx, 0, false);
    let (second, _) = two_clouds(&ctx, 1, false);
    let swapped = max_difference(&first, &second);
    eprintln!("two clouds, listed either way: max difference {swapped}/255");
    assert!(swapped <= 1, "swapping the clouds changed the picture by {swapped}/255");
    // A CPU reference: every sample of both clouds, merged by distance along the ray.
    let cam = camera();
    let references: Vec<CloudReference> = layers
        .iter()
        .map(|(grid, state)| CloudReference::new(grid, &cam, &state.render_settings(0, BACKGROUND)))
        .collect();
    let reference = |merged: bool| {
        image::RgbaImage::from_fn(SIZE[0], SIZE[1], |px, py| {
            let d = references[0].ray(&cam, SIZE, px, py);
            let mut samples: Vec<_> = references.iter().map(|r| r.samples(d)).collect();
            if merged {
                let mut all: Vec<_> = samples.drain(..).flatten().collect();
                all.sort_by(|a, b| b.t.total_cmp(&a.t));
                samples = vec![all];
            }
            // Back to front: each cloud over what is behind it (unmerged: the second over the first).
            let mut c = BACKGROUND.map(f64::from);
            for sample in samples.iter().flatten() {
                c = [0, 1, 2].map(|k| sample.color[k] * sample.alpha + (1.0 - sample.alpha) * c[k]);
            }
            image::Rgba([srgb_encode(c[0]), srgb_encode(c[1]), srgb_encode(c[2]), 255])
        })
    };
    let cpu = reference(true);
    let mean = common::mean_difference(&first, &cpu);
    let over = first.pixels().zip(cpu.pixels()).filter(|(p, q)| (0..3).any(|k| p[k].abs_diff(q[k]) > 3)).count();
    let n = first.pixels().len();
    let in_layer_order = common::mean_difference(&first, &reference(false));
    eprintln!(
        "against the CPU merge: mean {mean:.3}/255, {over} of {n} pixels > 3/255; one cloud over the other: {in_layer_order:.3}/255"
    );
    assert!(mean < 1.0 && over * 100 < n, "mean {mean:.3}/255, {over} pixels > 3/255");
    // Drawing one cloud over the other would be far off.
    assert!(in_layer_order > 5.0 * mean.max(0.2), "one over the other: {in_layer_order:.3}/255");
}

#[test]
fn overlapping_clouds_with_translucent_surfaces_give_one_picture_whichever_is_listed_first() {
    let ctx = lavapipe();
    let (first, _) = two_clouds(&ctx, 0, true);
    let (second, _) = two_clouds(&ctx, 1, true);
    let (bare, _) = two_clouds(&ctx, 0, false);
    let swapped = max_difference(&first, &second);
    eprintln!("two clouds and their surfaces, listed either way: max difference {swapped}/255");
    assert!(swapped <= 1, "swapping the quantities changed the picture by {swapped}/255");
    let surfaces = common::mean_difference(&first, &bare);
    eprintln!("the surfaces change the picture by {surfaces:.2}/255 on average");
    if std::env::var_os("ORBCLOUD_SAVE").is_some() {
        first.save("/tmp/two_clouds_surfaces.png").unwrap();
        bare.save("/tmp/two_clouds.png").unwrap();
    }
    assert!(surfaces > 2.0, "the surfaces are in the picture");
}

#[test]
fn the_diene_so2_demo_and_nested_shells_match_their_golden_images() {
    let ctx = lavapipe();
    let size = [240, 180];
    let scene = orbcloud::sources::demo::cycloaddition().expect("the bundled demo loads");
    let quantities: Vec<Vec<_>> = scene.iter().map(|(_, s)| s.quantities.iter().map(|q| q.source).collect()).collect();
    // Butadiene's HOMO is MO 15, SO₂'s LUMO MO 17 (scripts/make_cycloaddition_demo.py); each
    // inside its molecule's total density.
    use orbcloud::model::orbitals::Quantity::{Density, Orbital};
    use orbcloud::scene::Source::Wavefunction;
    assert_eq!(
        quantities,
        [[Wavefunction(Density), Wavefunction(Orbital(14))], [Wavefunction(Density), Wavefunction(Orbital(16))]]
    );
    let mut renderer = Renderer::new(&ctx);
    let shown = show_scene(&ctx, &mut renderer, &scene, 48).expect("scene shown");
    let (clouds, (lo, hi)) = (shown.clouds, shown.bounds.expect("bounds"));
    let mut cam = Camera::framing(lo.as_vec3(), hi.as_vec3());
    let (yaw, pitch) = orbcloud::sources::demo::CYCLOADDITION_VIEW;
    cam.orbit(yaw, pitch);
    let target = OffscreenTarget::new(&ctx.device, size);
    let frame = FrameInput { camera: &cam, background: BACKGROUND, clouds: &clouds, size, tile: None };
    let stats = draw_exact(&ctx, &mut renderer, &target.color_view, &frame).expect("translucent surfaces");
    let (dump, _) = renderer.read_translucency(&ctx).expect("fragments");
    assert_eq!(dump.surfaces.len(), 6, "two densities, and the ± lobes of two orbitals");
    assert!(stats.fits() && stats.deep_pixels == 0, "{stats:?}");
    common::assert_golden("translucent_diene_so2", &target.read_rgba(&ctx.device, &ctx.queue).expect("read back"));

    let grid = blob(DVec3::ZERO);
    let shells: Vec<_> = [0.05, 0.2, 0.45, 0.8]
        .iter()
        .zip([[0.2, 0.4, 0.9], [0.2, 0.8, 0.4], [0.9, 0.8, 0.2], [0.9, 0.2, 0.1]])
        .flat_map(|(&v, c)| isosurfaces(&grid, &translucent(v, c)))
        .collect();
    let mut renderer = Renderer::new(&ctx);
    show_meshes(&ctx, renderer.main(), &shells);
    common::assert_golden("translucent_density_shells", &draw(&ctx, &mut renderer).0);
}
