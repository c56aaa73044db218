//! Slabs: a fragment of a texture's slices samples up to eight planes along its pixel's ray.
//! The picture must be the one a slice per plane gives, for every transfer function, with the
//! clipping plane, in both slicing modes, for a scan's frame mixed from two key volumes each
//! way, and where opaque atoms stand inside the cloud (their
//! depth ends a slab's samples, which the depth test alone would not); with the eye among the
//! planes the slices stay one per plane.

mod common;

use common::{lavapipe, p_orbital, scene};
use orbcloud::gpu::GpuContext;
use orbcloud::gpu::volume::{SLAB_PLANES, VolumeTexture};
use orbcloud::model::{Document, VolumeGrid};
use orbcloud::pictures::headless::Headless;
use orbcloud::scene::framing::default_camera;
use orbcloud::scene::{AtomStyle, Camera, DensityScale, Interpolation, RenderSettings, SliceMode, TransferKind};

const SIZE: [u32; 2] = [160, 120];

/// The picture with at most `planes` planes per fragment, and how many each fragment took;
/// `morph` mixes the document's grid with a second key volume.
fn draw(
    ctx: &GpuContext,
    doc: &Document,
    s: &RenderSettings,
    camera: &Camera,
    planes: usize,
    morph: Option<(&VolumeGrid, Interpolation)>,
) -> (image::RgbaImage, usize) {
    let mut h = Headless::new(ctx, doc, Some(0), s, SIZE).expect("renderer");
    if let Some((b, mode)) = morph {
        let a = VolumeTexture::upload(ctx, &doc.volumes[0]).expect("upload");
        let b = VolumeTexture::upload(ctx, b).expect("upload");
        h.renderer.main().volume.set_morph(ctx, a, b, 0.37, mode);
    }
    h.renderer.main().volume.set_slab_planes(planes);
    let img = h.render(ctx, camera, s).expect("render");
    (img, h.renderer.main().volume.planes_per_fragment())
}

/// Largest channel difference, mean difference (/255) and pixels that differ by more than 2.
fn difference(a: &image::RgbaImage, b: &image::RgbaImage) -> (u8, f64, usize) {
    let per_pixel: Vec<u8> =
        a.pixels().zip(b.pixels()).map(|(p, q)| (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap_or(0)).collect();
    let max = per_pixel.iter().copied().max().unwrap_or(0);
    let mean = per_pixel.iter().map(|&d| d as f64).sum::<f64>() / per_pixel.len() as f64;
    (max, mean, per_pixel.iter().filter(|&&d| d > 2).count())
}

#[test]
fn slabs_give_the_picture_of_one_slice_per_plane() {
    let ctx = lavapipe();
    let orbital = scene(Some(p_orbital(40, true)));
    let mut density = p_orbital(40, false);
    density.values.iter_mut().for_each(|v| *v = v.abs() + 1e-6);
    density.kind = orbcloud::model::grid::ValueKind::Density;
    let density = scene(Some(density));
    let mut camera = default_camera(&orbital);
    camera.orbit(35f32.to_radians(), 20f32.to_radians());
    let base = RenderSettings { atoms: AtomStyle::Hidden, ..Default::default() };
    let mut cases: Vec<(&str, &Document, RenderSettings, Option<Interpolation>)> =
        vec![("power law", &orbital, base, None)];
    let mut axis = base;
    axis.volume.mode = SliceMode::AxisAligned;
    cases.push(("axis-aligned", &orbital, axis, None));
    let mut lit = base;
    lit.volume.transfer.kind = TransferKind::Shaped;
    lit.volume.transfer.shading = true;
    lit.volume.transfer.boundary = 0.5;
    cases.push(("lit shells", &orbital, lit, None));
    let mut clipped = base;
    clipped.clip.enabled = true;
    clipped.clip.normal = [1.0, 0.3, 0.2];
    cases.push(("clipped", &orbital, clipped, None));
    cases.push(("atoms inside the cloud", &orbital, RenderSettings::default(), None));
    // A scan's frame between two key volumes, each way of mixing them.
    for mode in [Interpolation::Exact, Interpolation::ThreePass, Interpolation::AlphaMix] {
        cases.push(("key volumes mixed", &orbital, base, Some(mode)));
    }
    let mut linear = base;
    linear.volume.density_scale = DensityScale::Linear;
    cases.push(("density", &density, linear, None));
    let mut log = base;
    log.volume.density_scale = DensityScale::Log { lo: 1e-4, hi: 1.0 };
    cases.push(("density on a log scale", &density, log, None));
    let other = p_orbital(40, false);
    for (name, doc, s, mode) in cases {
        let morph = mode.map(|m| (&other, m));
        let (slabs, planes) = draw(&ctx, doc, &s, &camera, SLAB_PLANES, morph);
        assert_eq!(planes, SLAB_PLANES, "{name}: the eye is before every plane");
        let (slices, one) = draw(&ctx, doc, &s, &camera, 1, morph);
        assert_eq!(one, 1);
        let (max, mean, over) = difference(&slabs, &slices);
        eprintln!("{name} {mode:?}: slabs against slices: worst {max}/255, mean {mean:.4}/255, {over} pixels > 2/255");
        assert!(max <= 6 && mean < 0.5, "{name}: worst {max}/255, mean {mean:.4}, {over} pixels > 2");
        let mut hidden = s;
        hidden.volume.visible = false;
        let (without, _) = draw(&ctx, doc, &hidden, &camera, SLAB_PLANES, None);
        assert!(difference(&slabs, &without).0 > 40, "{name}: the cloud shows");
    }
}

#[test]
fn with_the_eye_among_the_planes_each_fragment_takes_one() {
    let ctx = lavapipe();
    let doc = scene(Some(p_orbital(32, false)));
    let mut camera = default_camera(&doc);
    camera.distance = 1.0;
    let s = RenderSettings { atoms: AtomStyle::Hidden, ..Default::default() };
    let (img, planes) = draw(&ctx, &doc, &s, &camera, SLAB_PLANES, None);
    assert_eq!(planes, 1);
    let mut hidden = s;
    hidden.volume.visible = false;
    assert!(difference(&img, &draw(&ctx, &doc, &hidden, &camera, SLAB_PLANES, None).0).0 > 40, "the cloud shows");
}
