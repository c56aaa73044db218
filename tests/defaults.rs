//! The first picture has contrast: a density on its default (log) scale and any grid with the
//! automatic opacity show clearly more structure than a density scaled to its maximum with a
//! fixed opacity did (the luma standard deviation of the frame, on a few molecules).

mod common;

use orbcloud::evaluate::{WavefunctionView, auto_opacity, evaluate_wavefunction};
use orbcloud::gpu::gto::GtoFillPass;
use orbcloud::model::orbitals::{Quantity, Spin};
use orbcloud::pictures::headless::Headless;
use orbcloud::scene::framing::camera_for;
use orbcloud::scene::{AtomStyle, DensityScale, RenderSettings, ViewPreset};

const SIZE: [u32; 2] = [160, 120];
const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/wavefunctions");

fn luma_std(img: &image::RgbaImage) -> f64 {
    let luma: Vec<f64> =
        img.pixels().map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64).collect();
    let mean = luma.iter().sum::<f64>() / luma.len() as f64;
    (luma.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / luma.len() as f64).sqrt()
}

/// Renders `quantity` of `file` (atoms hidden: the cloud alone) with settings `adjust` makes
/// from the defaults, then the automatic opacity where they ask for it.
fn render(
    file: &str,
    quantity: impl Fn(&orbcloud::model::orbitals::Wavefunction) -> Quantity,
    adjust: impl Fn(&mut RenderSettings),
) -> f64 {
    let ctx = common::lavapipe();
    let doc = orbcloud::formats::load(&std::path::Path::new(FIXTURES).join(file)).unwrap();
    let mut s = RenderSettings { atoms: AtomStyle::Hidden, ..Default::default() };
    s.volume.slices = 96;
    adjust(&mut s);
    let view = WavefunctionView {
        quantity: quantity(doc.wavefunction.as_ref().unwrap()),
        direct: false,
        points: 48,
        functions: None,
        grid: true,
    };
    let evaluated = evaluate_wavefunction(&ctx, &GtoFillPass::new(&ctx), &doc, &view).unwrap().unwrap();
    let mut h = Headless::new(&ctx, &doc, None, &s, SIZE).unwrap();
    let values = evaluated.show(&ctx, h.renderer.main()).unwrap();
    auto_opacity(&mut s.volume, values.grid.as_ref().unwrap());
    let camera = camera_for(&doc, ViewPreset::Auto).unwrap();
    luma_std(&h.render(&ctx, &camera, &s).unwrap())
}

fn before(s: &mut RenderSettings) {
    s.volume.density_scale = DensityScale::Linear;
    s.volume.auto_k1 = false;
    s.volume.k1 = 0.2;
}

#[test]
fn densities_and_orbitals_open_with_contrast() {
    for file in ["h2o_ccpvtz.molden", "benzene_631gs.molden", "h3o_cation_631gss.molden"] {
        let density = |_: &_| Quantity::Density;
        let (old, new) = (render(file, density, before), render(file, density, |_| {}));
        eprintln!("{file} density: luma σ {old:.1} scaled to its maximum, {new:.1} by default");
        assert!(new >= 2.0 * old && new >= 10.0, "{file}: density σ {new:.1} (before {old:.1})");
        let homo = |wf: &orbcloud::model::orbitals::Wavefunction| Quantity::Orbital(wf.homo(Spin::Alpha).unwrap());
        let (old, new) = (render(file, homo, before), render(file, homo, |_| {}));
        eprintln!("{file} HOMO: luma σ {old:.1} with k1 = 0.2, {new:.1} with the automatic k1");
        assert!(new >= 10.0 && new >= 0.8 * old, "{file}: HOMO σ {new:.1} (before {old:.1})");
    }
}
