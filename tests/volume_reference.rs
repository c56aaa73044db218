//! The slice pass on lavapipe against an independent CPU compositor: the same slice polygons,
//! ray–triangle intersection per pixel, trilinear sampling in f64, the same opacity law, and
//! back-to-front "over" compositing.

mod common;

use common::{lavapipe, p_orbital, scene};
use glam::{DVec3, Vec3};
use orbcloud::headless::{default_camera, render_document};
use orbcloud::model::VolumeGrid;
use orbcloud::model::grid::ValueKind;
use orbcloud::scene::slicing::GridBox;
use orbcloud::scene::{AtomStyle, Camera, RenderSettings, Shape, SliceMode, TransferKind};

const SIZE: [u32; 2] = [96, 72];

fn srgb_encode(c: f64) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let v = if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (v * 255.0).round() as u8
}

fn ray_triangle(o: DVec3, d: DVec3, t: [DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-14 {
        return None;
    }
    let s = o - t[0];
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0).then(|| e2.dot(q) / det)
}

fn reference(grid: &VolumeGrid, cam: &Camera, s: &RenderSettings) -> image::RgbaImage {
    let e = grid.box_edges();
    let gbox = GridBox {
        origin: grid.origin().as_vec3(),
        edges: [e.x_axis.as_vec3(), e.y_axis.as_vec3(), e.z_axis.as_vec3()],
    };
    let eye = cam.eye();
    let view_dir = (cam.target - eye).normalize();
    let slices = gbox.slices(s.volume.mode, s.volume.slices, eye, view_dir);
    let tris: Vec<[DVec3; 3]> =
        slices.vertices.chunks(3).map(|t| [t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3()]).collect();
    let aspect = SIZE[0] as f32 / SIZE[1] as f32;
    let world_from_clip = cam.clip_from_world(aspect, 20.0).inverse().as_dmat4();
    let grid_from_world = grid.world_from_grid.inverse();
    let vs = &s.volume;
    let (k1, k2) = (vs.k1 as f64, vs.k2 as f64);
    let inv = 1.0 / grid.stats.max_abs;
    let step = grid.voxel_volume().cbrt();
    let pos = vs.positive_color.map(|c| c as f64);
    let neg = vs.negative_color.map(|c| c as f64);
    let eye = eye.as_dvec3();
    let clip_n = Vec3::from(vs.clip.normal).normalize().as_dvec3();
    let centre = (gbox.origin + 0.5 * (gbox.edges[0] + gbox.edges[1] + gbox.edges[2])).as_dvec3();
    let clip_offset = clip_n.dot(centre) + vs.clip.offset as f64;
    // A density's t: on its scale (log by default), the shader's `transfer_value`.
    let signed = grid.kind == ValueKind::Signed;
    let density_t = |v: f64| vs.density_scale.t(v as f32, grid.stats.max_abs as f32) as f64;
    // Extinction of one reference step for a value: seed 000's k1·ρ^k2 or seed 004's shapes.
    let extinction = |v: f64| -> f64 {
        let t = if signed { (v * inv).abs() } else { density_t(v) };
        match vs.transfer.kind {
            TransferKind::PowerLaw if signed => k1 * (t * t).powf(k2),
            TransferKind::PowerLaw => k1 * t.powf(k2),
            TransferKind::Shaped => {
                let lobe = if v >= 0.0 { vs.transfer.positive } else { vs.transfer.negative };
                lobe.opacity as f64 * lobe.shape.factor(t as f32, lobe.center, lobe.width) as f64
            }
        }
    };
    image::RgbaImage::from_fn(SIZE[0], SIZE[1], |px, py| {
        let ndc_x = (px as f64 + 0.5) / SIZE[0] as f64 * 2.0 - 1.0;
        let ndc_y = 1.0 - (py as f64 + 0.5) / SIZE[1] as f64 * 2.0;
        let far = world_from_clip.project_point3(DVec3::new(ndc_x, ndc_y, 0.9));
        let d = (far - eye).normalize();
        let mut hits: Vec<f64> = tris.iter().filter_map(|&t| ray_triangle(eye, d, t)).collect();
        hits.sort_by(|a, b| b.total_cmp(a));
        let mut c = s.background.map(|c| c as f64);
        for t in hits {
            let p = eye + d * t;
            if vs.clip.enabled && clip_n.dot(p) > clip_offset {
                continue;
            }
            let v = grid.sample(grid_from_world.transform_point3(p));
            let path = slices.spacing as f64 / d.dot(slices.normal.as_dvec3()).abs().max(0.05);
            let alpha = 1.0 - (-extinction(v) * path / step).exp();
            let col = match (signed, v >= 0.0) {
                (true, true) => pos,
                (true, false) => neg,
                // A density's colour runs from the thin to the dense end.
                (false, _) => {
                    let w = density_t(v).min(1.0).sqrt();
                    [0, 1, 2].map(|i| neg[i] + (pos[i] - neg[i]) * w)
                }
            };
            for i in 0..3 {
                c[i] = col[i] * alpha + c[i] * (1.0 - alpha);
            }
        }
        image::Rgba([srgb_encode(c[0]), srgb_encode(c[1]), srgb_encode(c[2]), 255])
    })
}

fn compare(mode: SliceMode, adjust: impl Fn(&mut RenderSettings)) {
    compare_grid(p_orbital(24, true), mode, adjust);
}

fn compare_grid(grid: VolumeGrid, mode: SliceMode, adjust: impl Fn(&mut RenderSettings)) {
    let doc = scene(Some(grid.clone()));
    let mut s = RenderSettings { atoms: AtomStyle::Hidden, ..Default::default() };
    s.volume.mode = mode;
    s.volume.slices = 40;
    s.volume.k1 = 0.35;
    adjust(&mut s);
    let mut cam = default_camera(&doc);
    cam.orbit(50f32.to_radians(), 25f32.to_radians());
    let ctx = lavapipe();
    let gpu = render_document(&ctx, &doc, Some(0), &cam, &s, SIZE).unwrap();
    let cpu = reference(&grid, &cam, &s);
    let (mut worst, mut sum, mut over) = (0u32, 0u64, 0usize);
    for (a, b) in gpu.pixels().zip(cpu.pixels()) {
        let d = (0..3).map(|c| (a[c] as i32 - b[c] as i32).unsigned_abs()).max().unwrap();
        worst = worst.max(d);
        sum += d as u64;
        over += (d > 3) as usize;
    }
    let n = gpu.pixels().len();
    let mean = sum as f64 / n as f64;
    eprintln!("{mode:?}: mean |gpu − cpu| {mean:.3}/255, worst {worst}/255, {over} of {n} pixels > 3/255");
    // Tolerance: the f16 scene buffer rounds every one of ~40 blends and the output is 8-bit, so
    // pixels drift by about a count (measured: mean 0.6–0.8/255, worst 1–3/255). A ray that grazes
    // a slice polygon's edge may see one slice more or less, which a sharp transfer function
    // (contours) shows: one pixel in 6912 differs by 16/255 there. So: ≤ 1% of pixels beyond
    // 3/255 and none beyond 32/255.
    assert!(worst <= 32, "{mode:?}: worst pixel differs by {worst}/255");
    let cloud = cpu.pixels().filter(|p| p[0].abs_diff(p[2]) > 20).count();
    assert!(cloud * 10 > n, "the reference image shows the cloud ({cloud} of {n} pixels)");
    assert!(mean < 1.0 && over * 100 < n, "{mode:?}: GPU and CPU disagree (mean {mean:.3}, {over} pixels > 3)");
}

#[test]
fn view_aligned_slices_match_the_cpu_compositor() {
    compare(SliceMode::ViewAligned, |_| {});
}

#[test]
fn axis_aligned_stacks_match_the_cpu_compositor() {
    compare(SliceMode::AxisAligned, |_| {});
}

#[test]
fn shaped_transfer_functions_match_the_cpu_compositor() {
    compare(SliceMode::ViewAligned, |s| {
        let t = &mut s.volume.transfer;
        t.kind = TransferKind::Shaped;
        t.positive.shape = Shape::Gaussian;
        t.positive.center = 0.4;
        t.positive.width = 0.15;
        t.negative.shape = Shape::LeftHalfGaussian;
        t.negative.center = 0.5;
    });
    compare(SliceMode::AxisAligned, |s| {
        let t = &mut s.volume.transfer;
        t.kind = TransferKind::Shaped;
        t.positive.shape = Shape::Sinusoidal;
        t.positive.width = 0.25;
        t.negative.shape = Shape::RightHalfGaussian;
        t.negative.center = 0.2;
    });
}

#[test]
fn a_density_on_its_log_scale_matches_the_cpu_compositor() {
    // ρ = 50·exp(−2r): six decades inside the box, as a molecule's density has.
    let p = p_orbital(24, false);
    let values = (0..p.values.len())
        .map(|n| {
            let (i, j, k) = (n / (24 * 24), (n / 24) % 24, n % 24);
            let r = p.world_from_grid.transform_point3(DVec3::new(i as f64, j as f64, k as f64)).length();
            (50.0 * (-2.0 * r).exp()) as f32
        })
        .collect();
    let density = VolumeGrid::new("density", p.dims, p.world_from_grid, values);
    assert_eq!(density.kind, ValueKind::Density);
    compare_grid(density, SliceMode::ViewAligned, |s| s.volume.k1 = 0.3);
}

#[test]
fn the_clipping_plane_matches_the_cpu_compositor() {
    compare(SliceMode::ViewAligned, |s| {
        s.volume.clip.enabled = true;
        s.volume.clip.normal = [0.3, 1.0, 0.2];
        s.volume.clip.offset = -0.5;
    });
}

#[test]
fn r16float_fallback_matches_r32float() {
    // Adapters without FLOAT32_FILTERABLE get R16Float volumes; the picture must not change
    // beyond the rounding of 16-bit values.
    let doc = scene(Some(p_orbital(24, false)));
    let s = RenderSettings { atoms: AtomStyle::Hidden, ..Default::default() };
    let cam = default_camera(&doc);
    let mut ctx = lavapipe();
    assert_eq!(ctx.volume_format, wgpu::TextureFormat::R32Float, "lavapipe filters R32Float");
    let full = render_document(&ctx, &doc, Some(0), &cam, &s, SIZE).unwrap();
    ctx.volume_format = wgpu::TextureFormat::R16Float;
    let half = render_document(&ctx, &doc, Some(0), &cam, &s, SIZE).unwrap();
    let worst = full
        .pixels()
        .zip(half.pixels())
        .map(|(a, b)| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap())
        .max()
        .unwrap();
    assert!(worst <= 3, "R16Float differs from R32Float by up to {worst}/255");
}
