//! Golden images on lavapipe: both slice modes, atoms only, atoms with a cloud, a sheared grid.
//! References live in tests/golden; see `common::assert_golden` for the tolerance.

mod common;

use common::{assert_golden, compact_p_orbital, coverage, lavapipe, p_orbital, scene};
use orbcloud::pictures::headless::render_document;
use orbcloud::scene::framing::default_camera;
use orbcloud::scene::{AtomStyle, RenderSettings, SliceMode};

const SIZE: [u32; 2] = [192, 144];

fn settings(mode: SliceMode, atoms: AtomStyle) -> RenderSettings {
    let mut s = RenderSettings::default();
    s.volume.mode = mode;
    s.volume.slices = 96;
    s.atoms = atoms;
    s
}

fn render(doc: &orbcloud::model::Document, s: &RenderSettings, yaw: f32, pitch: f32) -> image::RgbaImage {
    let ctx = lavapipe();
    let mut cam = default_camera(doc);
    cam.orbit(yaw.to_radians(), pitch.to_radians());
    let index = (!doc.volumes.is_empty()).then_some(0);
    render_document(&ctx, doc, index, &cam, s, SIZE).expect("render")
}

fn background(s: &RenderSettings) -> [u8; 3] {
    // sRGB encoding of the linear background colour.
    s.background.map(|c| {
        let v = if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
        (v * 255.0).round() as u8
    })
}

#[test]
fn atoms_only() {
    let s = settings(SliceMode::ViewAligned, AtomStyle::BallAndStick);
    let img = render(&scene(None), &s, 20.0, 25.0);
    let c = coverage(&img, background(&s));
    assert!(c > 0.02 && c < 0.5, "atoms cover {c}");
    assert_golden("atoms_only", &img);
}

#[test]
fn space_filling() {
    let s = settings(SliceMode::ViewAligned, AtomStyle::SpaceFilling);
    let img = render(&scene(None), &s, 20.0, 25.0);
    let ball = render(&scene(None), &settings(SliceMode::ViewAligned, AtomStyle::BallAndStick), 20.0, 25.0);
    assert!(coverage(&img, background(&s)) > 1.5 * coverage(&ball, background(&s)));
    assert_golden("space_filling", &img);
}

#[test]
fn cloud_view_aligned() {
    let s = settings(SliceMode::ViewAligned, AtomStyle::Hidden);
    let img = render(&scene(Some(p_orbital(40, false))), &s, 65.0, 20.0);
    assert_two_coloured_lobes(&img);
    assert_golden("cloud_view_aligned", &img);
}

#[test]
fn cloud_axis_aligned() {
    let s = settings(SliceMode::AxisAligned, AtomStyle::Hidden);
    let img = render(&scene(Some(p_orbital(40, false))), &s, 65.0, 20.0);
    assert_two_coloured_lobes(&img);
    assert_golden("cloud_axis_aligned", &img);
}

#[test]
fn atoms_and_cloud() {
    let s = settings(SliceMode::ViewAligned, AtomStyle::BallAndStick);
    let img = render(&scene(Some(p_orbital(40, false))), &s, 65.0, 20.0);
    assert_two_coloured_lobes(&img);
    assert_golden("atoms_and_cloud", &img);
}

#[test]
fn sheared_grid() {
    let s = settings(SliceMode::ViewAligned, AtomStyle::BallAndStick);
    let img = render(&scene(Some(p_orbital(40, true))), &s, -60.0, 15.0);
    assert_two_coloured_lobes(&img);
    assert_golden("sheared_grid", &img);
}

/// The p orbital is positive above the molecular plane (z > 0) and negative below: both the red
/// and the blue colour must show.
fn assert_two_coloured_lobes(img: &image::RgbaImage) {
    let red = img.pixels().filter(|p| p[0] as i32 > p[2] as i32 + 30).count();
    let blue = img.pixels().filter(|p| p[2] as i32 > p[0] as i32 + 30).count();
    let n = (img.width() * img.height()) as usize;
    assert!(red * 50 > n && blue * 50 > n, "red {red} blue {blue} of {n} pixels");
}

fn shaped(shape: orbcloud::scene::Shape, shading: bool) -> RenderSettings {
    use orbcloud::scene::TransferKind;
    let mut s = settings(SliceMode::ViewAligned, AtomStyle::BallAndStick);
    let t = &mut s.volume.transfer;
    t.kind = TransferKind::Shaped;
    t.positive.shape = shape;
    t.negative.shape = shape;
    t.shading = shading;
    s
}

#[test]
fn lit_gaussian_shells() {
    let mut s = shaped(orbcloud::scene::Shape::Gaussian, true);
    s.volume.transfer.boundary = 0.5;
    let img = render(&scene(Some(p_orbital(40, false))), &s, 65.0, 20.0);
    assert_two_coloured_lobes(&img);
    assert_golden("lit_gaussian_shells", &img);
}

#[test]
fn contour_shells() {
    let mut s = shaped(orbcloud::scene::Shape::Sinusoidal, false);
    for lobe in [&mut s.volume.transfer.positive, &mut s.volume.transfer.negative] {
        lobe.center = 0.15;
        lobe.width = 0.25;
        lobe.opacity = 0.6;
    }
    let img = render(&scene(Some(p_orbital(40, false))), &s, 65.0, 20.0);
    assert_two_coloured_lobes(&img);
    assert_golden("contour_shells", &img);
}

#[test]
fn clipped_cloud() {
    let mut s = settings(SliceMode::ViewAligned, AtomStyle::BallAndStick);
    s.clip.enabled = true;
    s.clip.normal = [0.0, 0.0, 1.0];
    let doc = scene(Some(p_orbital(40, false)));
    let clipped = render(&doc, &s, 65.0, 20.0);
    s.clip.enabled = false;
    let whole = render(&doc, &s, 65.0, 20.0);
    // The plane z = 0 removes the positive (red, z > 0) lobe and keeps the negative one.
    let red = |img: &image::RgbaImage| img.pixels().filter(|p| p[0] as i32 > p[2] as i32 + 30).count();
    assert!(red(&clipped) * 4 < red(&whole), "clipping left {} of {} red pixels", red(&clipped), red(&whole));
    assert_golden("clipped_cloud", &clipped);
}

/// Jang and Varetto's pairing for nested cores: opacity grows from the empty space to each lobe's
/// extreme value, lit so the nested shells show.
#[test]
fn nested_cores() {
    let mut s = settings(SliceMode::ViewAligned, AtomStyle::BallAndStick);
    s.volume.transfer.nested_cores();
    s.volume.transfer.shading = true;
    let img = render(&scene(Some(p_orbital(40, false))), &s, 65.0, 20.0);
    assert_two_coloured_lobes(&img);
    assert_golden("nested_cores", &img);
}

/// Jang and Varetto's half Gaussians are drawn on the signed value, so far from the molecule (ψ ≈ 0)
/// they are clear: with the box filling the frame, the border of the picture is exactly what it
/// is with the cloud hidden, while the lobes show.
#[test]
fn half_gaussians_leave_empty_space_clear() {
    use orbcloud::scene::Shape;
    let doc = scene(Some(compact_p_orbital(40, 2)));
    let ctx = lavapipe();
    let mut cam = default_camera(&doc);
    cam.orbit(65f32.to_radians(), 20f32.to_radians());
    // Close enough that every pixel's ray crosses the grid's box.
    cam.distance *= 0.45;
    let hidden = {
        let mut s = settings(SliceMode::ViewAligned, AtomStyle::Hidden);
        s.volume.visible = false;
        render_document(&ctx, &doc, Some(0), &cam, &s, SIZE).expect("render")
    };
    let (w, h) = hidden.dimensions();
    let border = |x: u32, y: u32| x < w / 10 || x >= w - w / 10 || y < h / 10 || y >= h - h / 10;
    for shape in [Shape::RightHalfGaussian, Shape::LeftHalfGaussian] {
        let mut s = shaped(shape, false);
        s.atoms = AtomStyle::Hidden;
        for lobe in [&mut s.volume.transfer.positive, &mut s.volume.transfer.negative] {
            lobe.center = 0.5;
            lobe.width = 0.1;
        }
        let img = render_document(&ctx, &doc, Some(0), &cam, &s, SIZE).expect("render");
        let (mut fogged, mut n) = (0, 0);
        for (x, y, p) in img.enumerate_pixels().filter(|(x, y, _)| border(*x, *y)) {
            n += 1;
            fogged += usize::from(p != hidden.get_pixel(x, y));
        }
        assert_eq!(fogged, 0, "{shape:?}: {fogged} of {n} border pixels are not the background");
        let shown = img.pixels().zip(hidden.pixels()).filter(|(a, b)| (0..3).any(|c| a[c].abs_diff(b[c]) > 20)).count();
        assert!(shown * 20 > (w * h) as usize, "{shape:?}: the lobes show ({shown} pixels)");
    }
}
