//! A protein (PDB 4E43, residues 30–50 with waters and acetates) in every representation and
//! colouring on lavapipe: golden images, and checks that each colouring shows what it says.

mod common;

use common::{assert_golden, lavapipe};
use orbcloud::model::Document;
use orbcloud::pictures::headless::render_document;
use orbcloud::scene::framing::default_camera;
use orbcloud::scene::{AtomColoring, AtomStyle, RenderSettings};

const SIZE: [u32; 2] = [200, 160];

fn protein() -> Document {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/structures/4e43_excerpt.pdb");
    orbcloud::formats::load(std::path::Path::new(path)).unwrap()
}

fn render(doc: &Document, atoms: AtomStyle, colors: AtomColoring) -> image::RgbaImage {
    let s = RenderSettings { atoms, atom_colors: colors, ..RenderSettings::default() };
    render_document(&lavapipe(), doc, None, &default_camera(doc), &s, SIZE).expect("render")
}

/// Distinct colours among the lit pixels (quantised), a rough count of what a colouring shows.
fn hues(img: &image::RgbaImage) -> usize {
    let bg = img.get_pixel(0, 0).0;
    let mut seen = std::collections::HashSet::new();
    for p in img.pixels().filter(|p| (0..3).any(|c| p.0[c].abs_diff(bg[c]) > 30)) {
        let max = p.0[..3].iter().copied().max().unwrap_or(1).max(1) as u32;
        // Hue-like: each channel relative to the brightest, in fifths (shading cancels out).
        seen.insert(p.0[..3].iter().map(|&c| c as u32 * 5 / max).collect::<Vec<u32>>());
    }
    seen.len()
}

#[test]
fn every_representation() {
    let doc = protein();
    let mut covered = Vec::new();
    for (style, name) in [
        (AtomStyle::BallAndStick, "protein_ball_and_stick"),
        (AtomStyle::SpaceFilling, "protein_space_filling"),
        (AtomStyle::Licorice, "protein_licorice"),
        (AtomStyle::Lines, "protein_lines"),
    ] {
        let img = render(&doc, style, AtomColoring::Element);
        let bg = img.get_pixel(0, 0).0;
        covered.push(common::coverage(&img, [bg[0], bg[1], bg[2]]));
        assert_golden(name, &img);
    }
    // Space filling covers most, lines least.
    assert!(covered[1] > covered[0] && covered[0] > covered[3] && covered[2] > covered[3], "{covered:?}");
}

#[test]
fn every_colouring() {
    let doc = protein();
    let element = hues(&render(&doc, AtomStyle::Licorice, AtomColoring::Element));
    for (coloring, name) in [
        (AtomColoring::Residue, "protein_by_residue"),
        (AtomColoring::BFactor, "protein_by_b_factor"),
        (AtomColoring::Secondary, "protein_by_secondary_structure"),
    ] {
        let img = render(&doc, AtomStyle::Licorice, coloring);
        assert_golden(name, &img);
        assert_ne!(hues(&img), 0, "{coloring:?}");
        if coloring == AtomColoring::Residue {
            assert!(hues(&img) > element, "residues show more colours than elements");
        }
    }
}

/// A selection hides the atoms it leaves out, and their bonds: only the waters remain, and
/// every atom a pixel shows is a water's.
#[test]
fn a_selection_shows_only_what_it_names() {
    use orbcloud::gpu::frame::PickId;
    use orbcloud::gpu::{FrameInput, OffscreenTarget, Renderer};
    use orbcloud::scene::ObjectState;
    let ctx = lavapipe();
    let doc = protein();
    let draw = |selection: &str| {
        let state = ObjectState { selection: selection.into(), ..ObjectState::default() };
        let mut r = Renderer::new(&ctx);
        orbcloud::layers::show_object(&ctx, r.main(), &doc, &state).unwrap();
        let target = OffscreenTarget::new(&ctx.device, SIZE);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let cam = default_camera(&doc);
        r.render(
            &ctx,
            &mut encoder,
            &target.color_view,
            &FrameInput::single(
                &cam,
                &state.render_settings(0, orbcloud::scene::RenderSettings::default().background),
                SIZE,
            ),
        );
        ctx.queue.submit([encoder.finish()]);
        (target.read_rgba(&ctx.device, &ctx.queue).unwrap(), r)
    };
    let (all, _) = draw("");
    let (waters, r) = draw("resn HOH");
    let bg = all.get_pixel(0, 0).0;
    let (c_all, c_waters) =
        (common::coverage(&all, [bg[0], bg[1], bg[2]]), common::coverage(&waters, [bg[0], bg[1], bg[2]]));
    assert!(c_waters > 0.0 && c_waters * 10.0 < c_all, "waters {c_waters}, all {c_all}");
    let view = doc.structure.as_ref().unwrap();
    let s = &view.structure;
    let mut picked = 0;
    for y in (0..SIZE[1]).step_by(4) {
        for x in (0..SIZE[0]).step_by(4) {
            if let Some(PickId::Atom { index, .. }) = r.pick(&ctx, [x, y]).unwrap() {
                let residue = &s.residues[s.residue[view.atoms[index as usize] as usize] as usize];
                assert_eq!(residue.name.as_str(), "HOH", "pixel {x},{y} shows atom {index}");
                picked += 1;
            }
        }
    }
    assert!(picked > 0, "the waters are picked");
}

/// Depth cueing darkens with depth only: no pixel brightens, the front stays as it was and the
/// back darkens to about (1 − strength) in linear light.
#[test]
fn depth_cue_darkens_the_back() {
    let doc = protein();
    let plain = render(&doc, AtomStyle::SpaceFilling, AtomColoring::Element);
    let s = RenderSettings { atoms: AtomStyle::SpaceFilling, depth_cue: 0.8, ..RenderSettings::default() };
    let cued = render_document(&lavapipe(), &doc, None, &default_camera(&doc), &s, SIZE).expect("render");
    assert_golden("protein_depth_cue", &cued);
    let linear = |v: u8| (v as f32 / 255.0).powf(2.2);
    let mut ratios = Vec::new();
    for (p, c) in plain.pixels().zip(cued.pixels()) {
        assert!((0..3).all(|k| c.0[k] <= p.0[k].saturating_add(2)), "a pixel brightened: {p:?} → {c:?}");
        let (lp, lc) =
            (linear(p.0[0]) + linear(p.0[1]) + linear(p.0[2]), linear(c.0[0]) + linear(c.0[1]) + linear(c.0[2]));
        if lp > 0.1 {
            ratios.push(lc / lp);
        }
    }
    ratios.sort_by(f32::total_cmp);
    let (darkest, brightest) = (ratios[ratios.len() / 100], ratios[ratios.len() * 99 / 100]);
    assert!(brightest > 0.85, "the front darkened: {brightest}");
    assert!(darkest < 0.45 && darkest > 0.15, "the back: {darkest}");
}
