//! Translucent isosurfaces (seed 003) on lavapipe: the GPU's sorted fragment lists against a
//! CPU reference that sorts every fragment, independence of the order surfaces are given in,
//! frames over the fragment budget drawn in bands, and the glow where surfaces of two objects
//! overlap.

mod common;

use common::{formaldehyde, lavapipe, p_orbital};
use glam::{DVec3, Vec3};
use orbcloud::gpu::{FrameInput, GpuContext, OffscreenTarget, Renderer};
use orbcloud::headless::{draw_exact, isosurfaces, show_meshes, show_object};
use orbcloud::model::{Document, VolumeGrid};
use orbcloud::scene::translucency::{composite, sort_fragments};
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
    let mut state = ObjectState::default();
    state.settings.iso = iso;
    state.settings.volume.visible = false;
    state.settings.atoms = atoms;
    state
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

fn mean_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    let sum: u64 =
        a.pixels().zip(b.pixels()).map(|(p, q)| (0..3).map(|k| p[k].abs_diff(q[k]) as u64).sum::<u64>()).sum();
    sum as f64 / (3 * a.width() * a.height()) as f64
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
    let mean = mean_difference(&img, &reference);
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
