//! Naka et al.'s two ways of compositing a slice between two key volumes, on lavapipe, against an
//! independent CPU compositor (tests/common/cloud.rs samples each key volume along the same
//! rays): α-mix (their eq. 5: per slice α = (1−k)α_A + kα_B and the colours mixed) and the
//! three-pass method (their eqs. 6–7: attenuate by α_A, or α_B past the middle, then add
//! (1−k)·A and k·B).

mod common;

use common::cloud::{CloudReference, srgb_encode};
use common::{lavapipe, p_orbital, scene};
use orbcloud::gpu::volume::VolumeTexture;
use orbcloud::gpu::{FrameInput, OffscreenTarget, Renderer};
use orbcloud::model::VolumeGrid;
use orbcloud::scene::framing::default_camera;
use orbcloud::scene::slicing::GridBox;
use orbcloud::scene::{AtomStyle, Camera, Interpolation, RenderSettings};

const SIZE: [u32; 2] = [96, 72];

/// A's values mirrored through the grid's middle along x: another cloud on the same grid with
/// the same largest |ψ|.
fn mirrored(a: &VolumeGrid) -> VolumeGrid {
    let [nx, ny, nz] = a.dims;
    let mut values = Vec::with_capacity(a.values.len());
    for i in 0..nx {
        for j in 0..ny {
            for k in 0..nz {
                values.push(a.value(nx - 1 - i, j, k));
            }
        }
    }
    VolumeGrid::new("mirrored p", a.dims, a.world_from_grid, values)
}

/// The CPU picture: each ray's samples of A and B composited back to front by `mode`.
fn reference(
    a: &VolumeGrid,
    b: &VolumeGrid,
    k: f64,
    mode: Interpolation,
    cam: &Camera,
    s: &RenderSettings,
) -> image::RgbaImage {
    let (ra, rb) = (CloudReference::new(a, cam, s), CloudReference::new(b, cam, s));
    image::RgbaImage::from_fn(SIZE[0], SIZE[1], |px, py| {
        let d = ra.ray(cam, SIZE, px, py);
        let (sa, sb) = (ra.samples(d), rb.samples(d));
        assert_eq!(sa.len(), sb.len(), "one set of slices");
        let mut c = s.background.map(|c| c as f64);
        for (x, y) in sa.iter().zip(&sb) {
            let added: [f64; 3] = std::array::from_fn(|i| (1.0 - k) * x.color[i] * x.alpha + k * y.color[i] * y.alpha);
            let attenuation = match mode {
                Interpolation::AlphaMix => (1.0 - k) * x.alpha + k * y.alpha,
                Interpolation::ThreePass if k > 0.5 => y.alpha,
                Interpolation::ThreePass => x.alpha,
                Interpolation::Exact => unreachable!("exact mixes the values, not the slices"),
            };
            c = std::array::from_fn(|i| added[i] + c[i] * (1.0 - attenuation));
        }
        image::Rgba([srgb_encode(c[0]), srgb_encode(c[1]), srgb_encode(c[2]), 255])
    })
}

#[test]
fn alpha_mix_and_three_pass_match_their_cpu_compositors() {
    let a = p_orbital(24, false);
    let b = mirrored(&a);
    let doc = scene(Some(a.clone()));
    let mut s = RenderSettings { atoms: AtomStyle::Hidden, ..Default::default() };
    s.volume.slices = 40;
    s.volume.k1 = 0.35;
    s.volume.auto_k1 = false;
    let mut cam = default_camera(&doc);
    cam.orbit(50f32.to_radians(), 25f32.to_radians());
    let ctx = lavapipe();
    // Both key volumes on the grid's whole box, one scale, as a scan's are.
    let e = a.box_edges();
    let whole =
        GridBox { origin: a.origin().as_vec3(), edges: [e.x_axis.as_vec3(), e.y_axis.as_vec3(), e.z_axis.as_vec3()] };
    let upload = |g: &VolumeGrid| {
        let mut t = VolumeTexture::upload_as(&ctx, g, wgpu::TextureFormat::R32Float).unwrap();
        t.grid_box = whole;
        t.max_abs = a.stats.max_abs as f32;
        t
    };
    let (ta, tb) = (upload(&a), upload(&b));
    let max_grad = ta.max_grad.max(tb.max_grad);
    let target = OffscreenTarget::new(&ctx.device, SIZE);
    let mut renderer = Renderer::new(&ctx);
    for k in [0.3f32, 0.8] {
        let mut pictures = Vec::new();
        for mode in [Interpolation::AlphaMix, Interpolation::ThreePass] {
            let (mut x, mut y) = (ta.clone(), tb.clone());
            x.max_grad = max_grad;
            y.max_grad = max_grad;
            renderer.main().set_morph(&ctx, x, y, k, mode);
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            renderer.render(&ctx, &mut encoder, &target.color_view, &FrameInput::single(&cam, &s, SIZE));
            ctx.queue.submit([encoder.finish()]);
            let gpu = target.read_rgba(&ctx.device, &ctx.queue).unwrap();
            let cpu = reference(&a, &b, k as f64, mode, &cam, &s);
            let (mean, worst) = common::mean_max_difference(&gpu, &cpu);
            eprintln!("k = {k}, {mode:?}: mean |gpu − cpu| {mean:.3}/255, worst {worst}/255");
            // As for one volume (tests/volume_reference.rs): the f16 scene buffer rounds each of
            // ~40 blends; a ray grazing a slice polygon's edge may see one slice more or less.
            assert!(mean < 1.0 && worst <= 32, "k = {k}, {mode:?}: mean {mean}, worst {worst}");
            pictures.push((gpu, cpu));
        }
        // The two ways differ (their CPU pictures), and each GPU picture is nearer its own.
        let (alpha_mix, three_pass) = (&pictures[0], &pictures[1]);
        let apart = common::mean_max_difference(&alpha_mix.1, &three_pass.1).0;
        eprintln!("k = {k}: three-pass against α-mix (CPU): mean {apart:.3}/255");
        assert!(apart > 0.3, "the approximation shows at k = {k}: {apart}");
        assert!(
            common::mean_max_difference(&three_pass.0, &three_pass.1).0
                < common::mean_max_difference(&three_pass.0, &alpha_mix.1).0
        );
        assert!(
            common::mean_max_difference(&alpha_mix.0, &alpha_mix.1).0
                < common::mean_max_difference(&alpha_mix.0, &three_pass.1).0
        );
    }
}
