//! Atoms at scale on lavapipe: the compute rasteriser (small spheres) against the impostor
//! quads (the reference it must match), and picking among a million atoms against a CPU ray
//! cast through every atom.

mod common;

use common::lavapipe;
use glam::Vec3;
use orbcloud::gpu::frame::PickId;
use orbcloud::gpu::{FrameInput, GpuContext, OffscreenTarget, Renderer};
use orbcloud::model::Molecule;
use orbcloud::model::synthetic::atom_box;
use orbcloud::scene::{AtomStyle, Camera, RenderSettings};

fn draw(ctx: &GpuContext, renderer: &mut Renderer, camera: &Camera, size: [u32; 2]) -> image::RgbaImage {
    let settings = RenderSettings::default();
    let target = OffscreenTarget::new(&ctx.device, size);
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    renderer.render(ctx, &mut encoder, &target.color_view, &FrameInput::single(camera, &settings, size));
    ctx.queue.submit([encoder.finish()]);
    target.read_rgba(&ctx.device, &ctx.queue).unwrap()
}

fn framing(m: &Molecule) -> Camera {
    let (lo, hi) = m.bounds().unwrap();
    let mut cam = Camera::framing(lo.as_vec3(), hi.as_vec3());
    cam.orbit(0.5, 0.35);
    cam
}

fn mean_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    let sum: u64 = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| x.abs_diff(*y) as u64).sum();
    sum as f64 / a.as_raw().len() as f64
}

/// The same spheres drawn all by the compute rasteriser and all as impostor quads agree.
#[test]
fn splatted_spheres_match_impostor_quads() {
    let ctx = lavapipe();
    let m = atom_box(8_000);
    let cam = framing(&m);
    let size = [200, 160];
    for style in [AtomStyle::BallAndStick, AtomStyle::SpaceFilling] {
        let mut r = Renderer::new(&ctx);
        r.main().set_molecule(&ctx, &m, style);
        r.main().atoms.splat_radius_px = 0.0;
        let quads = draw(&ctx, &mut r, &cam, size);
        r.main().atoms.splat_radius_px = 1e6;
        let splats = draw(&ctx, &mut r, &cam, size);
        let mean = mean_difference(&quads, &splats);
        let differing =
            quads.pixels().zip(splats.pixels()).filter(|(a, b)| (0..3).any(|c| a.0[c].abs_diff(b.0[c]) > 24)).count();
        assert!(mean < 1.0, "{style:?}: mean difference {mean:.3}/255");
        assert!(differing * 200 < (size[0] * size[1]) as usize, "{style:?}: {differing} pixels differ");
    }
}

/// The first atom a pixel's ray hits, by brute force over every atom.
fn cpu_pick(m: &Molecule, radius: &dyn Fn(u32) -> f32, eye: Vec3, dir: Vec3) -> Option<u32> {
    let mut best = (f32::INFINITY, None);
    for (i, a) in m.atoms.iter().enumerate() {
        let oc = eye - a.position.as_vec3();
        let b = oc.dot(dir);
        let r = radius(a.z);
        let disc = b * b - (oc.dot(oc) - r * r);
        if disc >= 0.0 {
            let t = -b - disc.sqrt();
            if t > 0.0 && t < best.0 {
                best = (t, Some(i as u32));
            }
        }
    }
    best.1
}

#[test]
fn a_million_atoms_draw_and_pick() {
    let ctx = lavapipe();
    let m = atom_box(1_000_000);
    let mut cam = framing(&m);
    cam.zoom(0.45);
    let size = [240, 180];
    let mut r = Renderer::new(&ctx);
    r.main().set_molecule(&ctx, &m, AtomStyle::SpaceFilling);
    let img = draw(&ctx, &mut r, &cam, size);
    let bg = img.get_pixel(0, 0).0;
    let covered = common::coverage(&img, [bg[0], bg[1], bg[2]]);
    assert!(covered > 0.3 && covered < 0.99, "the box fills much of the view: {covered}");
    let clip = r.clip_from_world(&cam, size);
    let world_from_clip = clip.inverse();
    let eye = cam.eye();
    let vdw =
        |z: u32| orbcloud::model::elements::element(z).vdw_radius * orbcloud::model::units::BOHR_PER_ANGSTROM as f32;
    let mut agree = 0;
    let pixels: Vec<[u32; 2]> = (0..24).map(|k| [20 + (k * 37) % 200, 15 + (k * 53) % 150]).collect();
    for &px in &pixels {
        let ndc =
            [2.0 * (px[0] as f32 + 0.5) / size[0] as f32 - 1.0, 1.0 - 2.0 * (px[1] as f32 + 0.5) / size[1] as f32];
        let far = world_from_clip * glam::Vec4::new(ndc[0], ndc[1], 1.0, 1.0);
        let dir = (far.truncate() / far.w - eye).normalize();
        let want = cpu_pick(&m, &vdw, eye, dir);
        let got = r.pick(&ctx, px).unwrap();
        let got = match got {
            Some(PickId::Atom { object: 0, index }) => Some(index),
            None => None,
            other => panic!("{other:?}"),
        };
        agree += (got == want) as usize;
    }
    // Rounding decides a pixel exactly on the rim between two spheres either way.
    assert!(agree >= pixels.len() - 1, "{agree} of {} picks agree with the CPU ray cast", pixels.len());
}

/// Occlusion culling (the cells seen last frame drawn first, the others tested against their
/// coarse depth) changes how much is drawn, never the picture: a frame drawn after another
/// view matches the same frame drawn with no history, and most cells of a dense box are culled.
#[test]
fn occlusion_culling_keeps_the_picture() {
    let ctx = lavapipe();
    let m = atom_box(200_000);
    let size = [320, 240];
    let before = framing(&m);
    let mut after = before;
    after.orbit(0.3, -0.2);
    let mut warm = Renderer::new(&ctx);
    warm.main().set_molecule(&ctx, &m, AtomStyle::SpaceFilling);
    draw(&ctx, &mut warm, &before, size);
    let culled = draw(&ctx, &mut warm, &after, size);
    let counts = warm.main().atoms.cell_counts(&ctx).unwrap();
    let mut cold = Renderer::new(&ctx);
    cold.main().set_molecule(&ctx, &m, AtomStyle::SpaceFilling);
    let fresh = draw(&ctx, &mut cold, &after, size);
    let first = cold.main().atoms.cell_counts(&ctx).unwrap();
    assert_eq!(mean_difference(&culled, &fresh), 0.0, "the picture changed with the history");
    for px in [[160, 120], [100, 80], [220, 170], [60, 200]] {
        assert_eq!(warm.pick(&ctx, px).unwrap(), cold.pick(&ctx, px).unwrap(), "pick at {px:?}");
    }
    // The first frame has no history: everything in view is drawn, nearest first.
    assert_eq!(first.first, first.in_view, "{first:?}");
    // After one frame: a few cells drawn first, most of the others culled.
    assert!(counts.first > 0 && counts.first < counts.in_view / 2, "{counts:?}");
    assert!(counts.rest < counts.tested / 4, "{counts:?}");
    assert!(counts.shown < counts.in_view / 2, "{counts:?}");
}

/// Depth and id in one 64-bit word (one pass) and in two words (a second pass for the ids)
/// draw and pick the same atoms. Lavapipe has 64-bit atomics, so both run here.
#[test]
fn packed_and_paired_splat_words_agree() {
    use orbcloud::gpu::atoms::{AtomsPass, SplatWords};
    let ctx = lavapipe();
    assert_eq!(SplatWords::best(&ctx.device), SplatWords::Packed, "lavapipe has 64-bit storage atomics");
    let m = atom_box(50_000);
    let cam = framing(&m);
    let size = [240, 180];
    let mut drawn = Vec::new();
    for words in [SplatWords::Pair, SplatWords::Packed] {
        let mut r = Renderer::new(&ctx);
        r.main().atoms = AtomsPass::with_words(&ctx, words);
        r.main().set_molecule(&ctx, &m, AtomStyle::SpaceFilling);
        let img = draw(&ctx, &mut r, &cam, size);
        let picks: Vec<_> = (0..12).map(|k| r.pick(&ctx, [30 + k * 15, 20 + k * 12]).unwrap()).collect();
        drawn.push((img, picks));
    }
    assert!(drawn[0].1.iter().filter(|p| p.is_some()).count() >= 8, "{:?}", drawn[0].1);
    assert_eq!(drawn[0].1, drawn[1].1, "picks differ");
    assert_eq!(mean_difference(&drawn[0].0, &drawn[1].0), 0.0, "pictures differ");
}
