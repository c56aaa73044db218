//! Empty space skipped: slices cut only through the bricks the transfer function can show cover
//! fewer pixels than whole slices, and give the same picture, for every program that draws
//! from a grid; where nothing can be skipped the slices stay whole.

mod common;

use common::{compact_p_orbital, lavapipe, scene};
use glam::{Vec2, Vec3};
use orbcloud::gpu::GpuContext;
use orbcloud::gpu::volume::VolumeTexture;
use orbcloud::model::Document;
use orbcloud::pictures::headless::Headless;
use orbcloud::scene::framing::default_camera;
use orbcloud::scene::{AtomStyle, Camera, Interpolation, RenderSettings, Shape, SliceMode, TransferKind};

const SIZE: [u32; 2] = [160, 120];

/// Pixels the slice triangles cover on screen: the fragments they cost.
fn pixels(vertices: &[Vec3], camera: &Camera) -> f32 {
    let m = camera.clip_from_world(SIZE[0] as f32 / SIZE[1] as f32, 10.0);
    let px = |v: Vec3| {
        let c = m * v.extend(1.0);
        Vec2::new(c.x / c.w + 1.0, c.y / c.w + 1.0) * 0.5 * Vec2::new(SIZE[0] as f32, SIZE[1] as f32)
    };
    vertices.chunks(3).map(|t| 0.5 * (px(t[1]) - px(t[0])).perp_dot(px(t[2]) - px(t[0])).abs()).sum()
}

/// The picture and the pixels its slices cover, with empty space skipped or not; `morph`
/// mixes the document's grid with a second one.
fn draw(
    ctx: &GpuContext,
    doc: &Document,
    settings: &RenderSettings,
    camera: &Camera,
    morph: Option<(&orbcloud::model::VolumeGrid, Interpolation)>,
    skip: bool,
) -> (image::RgbaImage, f32) {
    let mut s = *settings;
    s.volume.skip_empty = skip;
    let mut h = Headless::new(ctx, doc, Some(0), &s, SIZE).expect("renderer");
    if let Some((b, mode)) = morph {
        let a = VolumeTexture::upload(ctx, &doc.volumes[0]).expect("upload");
        let b = VolumeTexture::upload(ctx, b).expect("upload");
        h.renderer.main().volume.set_morph(ctx, a, b, 0.4, mode);
    }
    let img = h.render(ctx, camera, &s).expect("render");
    (img, pixels(h.renderer.main().volume.slice_vertices(), camera))
}

/// Largest channel difference and mean difference (per channel, /255).
fn difference(a: &image::RgbaImage, b: &image::RgbaImage) -> (u8, f64) {
    let diffs: Vec<u8> =
        a.pixels().zip(b.pixels()).flat_map(|(p, q)| (0..4).map(move |c| p[c].abs_diff(q[c]))).collect();
    let max = diffs.iter().copied().max().unwrap_or(0);
    (max, diffs.iter().map(|&d| d as f64).sum::<f64>() / diffs.len() as f64)
}

#[test]
fn skipping_empty_bricks_draws_fewer_fragments_and_the_same_picture() {
    let ctx = lavapipe();
    let doc = scene(Some(compact_p_orbital(48, 2)));
    let other = compact_p_orbital(48, 0);
    let mut camera = default_camera(&doc);
    camera.orbit(35f32.to_radians(), 20f32.to_radians());
    let mut base = RenderSettings { atoms: AtomStyle::Hidden, ..Default::default() };
    base.volume.slices = 96;
    let mut cases: Vec<(&str, RenderSettings, Option<Interpolation>)> = vec![("power law", base, None)];
    let mut axis = base;
    axis.volume.mode = SliceMode::AxisAligned;
    cases.push(("axis-aligned", axis, None));
    let mut lit = base;
    lit.volume.transfer.kind = TransferKind::Shaped;
    lit.volume.transfer.shading = true;
    lit.volume.transfer.boundary = 0.5;
    // Shells at ±0.5 of the maximum: clear near ψ = 0 (the default 0.25 is not).
    lit.volume.transfer.positive.center = 0.5;
    lit.volume.transfer.negative.center = 0.5;
    cases.push(("lit Gaussian shells", lit, None));
    let mut cores = base;
    cores.volume.transfer.nested_cores();
    cases.push(("nested cores", cores, None));
    let mut clipped = base;
    clipped.clip.enabled = true;
    clipped.clip.normal = [1.0, 0.3, 0.2];
    cases.push(("clipped", clipped, None));
    for mode in [Interpolation::Exact, Interpolation::ThreePass, Interpolation::AlphaMix] {
        cases.push(("key volumes mixed", base, Some(mode)));
    }
    for (name, settings, morph) in cases {
        let morph = morph.map(|m| (&other, m));
        let (skipped, covered) = draw(&ctx, &doc, &settings, &camera, morph, true);
        let (whole, all) = draw(&ctx, &doc, &settings, &camera, morph, false);
        eprintln!("{name} {:?}: {covered:.0} of {all:.0} pixels drawn", morph.map(|m| m.1));
        assert!(covered < 0.7 * all, "{name}: skipping drew {covered:.0} of {all:.0} pixels");
        let (max, mean) = difference(&skipped, &whole);
        assert!(
            max <= 2 && mean < 0.02,
            "{name} {:?}: pictures differ by up to {max}/255 (mean {mean:.4})",
            morph.map(|m| m.1)
        );
        let (shown, _) = difference(&whole, &draw(&ctx, &doc, &hidden(settings), &camera, None, false).0);
        assert!(shown > 40, "{name}: the cloud shows");
    }
}

fn hidden(mut s: RenderSettings) -> RenderSettings {
    s.volume.visible = false;
    s
}

#[test]
fn transfer_functions_that_show_zero_keep_whole_slices() {
    let ctx = lavapipe();
    let doc = scene(Some(compact_p_orbital(32, 2)));
    let camera = default_camera(&doc);
    let mut s = RenderSettings::default();
    s.volume.slices = 48;
    s.volume.transfer.kind = TransferKind::Shaped;
    s.volume.transfer.positive.shape = Shape::Uniform;
    s.volume.transfer.positive.center = 0.02;
    s.volume.transfer.positive.width = 0.1;
    let (_, covered) = draw(&ctx, &doc, &s, &camera, None, true);
    let (_, all) = draw(&ctx, &doc, &s, &camera, None, false);
    assert_eq!(covered, all);
}
