//! Several objects in one scene on lavapipe: each placed with its own rigid transform, each with
//! its own atoms, cloud and isosurfaces, composited in one frame; picks name the object.

mod common;

use common::{assert_golden, lavapipe, p_orbital, scene};
use glam::{DVec3, Vec3};
use orbcloud::gpu::frame::PickId;
use orbcloud::gpu::{FrameInput, GpuContext, OffscreenTarget, Renderer};
use orbcloud::layers::show_object;
use orbcloud::model::Document;
use orbcloud::scene::{Camera, IsoLevel, ObjectState, Placement, RenderSettings, Source, VolumeSettings};

const SIZE: [u32; 2] = [256, 144];

/// The p orbital with its ± isosurfaces, and a copy of it as a cloud placed 14 bohr along x and
/// turned 90° about y.
fn two_objects() -> (Document, [ObjectState; 2]) {
    let doc = scene(Some(p_orbital(40, false)));
    let mut s = RenderSettings::default();
    s.volume.visible = false;
    s.iso.visible = true;
    s.iso.level = IsoLevel::Absolute(0.3);
    let surfaces = ObjectState::of_settings(Some(Source::Volume(0)), &s);
    let mut s = RenderSettings::default();
    s.volume.slices = 96;
    let mut cloud = ObjectState::of_settings(Some(Source::Volume(0)), &s);
    cloud.placement = Placement { offset: [14.0, 0.0, 0.0], rotation_deg: [0.0, 90.0, 0.0] };
    (doc, [surfaces, cloud])
}

fn camera() -> Camera {
    let mut cam = Camera::framing(Vec3::new(-4.0, -3.0, -3.0), Vec3::new(18.0, 3.0, 3.0));
    cam.orbit(0.35, 0.3);
    cam
}

fn draw(ctx: &GpuContext, renderer: &mut Renderer, clouds: &[VolumeSettings]) -> image::RgbaImage {
    let target = OffscreenTarget::new(&ctx.device, SIZE);
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let frame = FrameInput {
        camera: &camera(),
        background: RenderSettings::default().background,
        clouds,
        size: SIZE,
        tile: None,
    };
    renderer.render(ctx, &mut encoder, &target.color_view, &frame);
    ctx.queue.submit([encoder.finish()]);
    target.read_rgba(&ctx.device, &ctx.queue).unwrap()
}

fn pixel_of(renderer: &Renderer, p: Vec3) -> [u32; 2] {
    let c = renderer.clip_from_world(&camera(), SIZE) * p.extend(1.0);
    let ndc = c.truncate() / c.w;
    [((ndc.x * 0.5 + 0.5) * SIZE[0] as f32) as u32, ((0.5 - ndc.y * 0.5) * SIZE[1] as f32) as u32]
}

/// Pixels of `img` that differ from the background (its corner), in the left and the right half.
fn halves(img: &image::RgbaImage) -> (usize, usize) {
    let bg = img.get_pixel(0, 0).0;
    let lit = |x0: u32, x1: u32| {
        (x0..x1)
            .flat_map(|x| (0..SIZE[1]).map(move |y| (x, y)))
            .filter(|&(x, y)| (0..3).any(|c| img.get_pixel(x, y).0[c].abs_diff(bg[c]) > 12))
            .count()
    };
    (lit(0, SIZE[0] / 2), lit(SIZE[0] / 2, SIZE[0]))
}

#[test]
fn two_placed_objects_draw_and_pick_in_one_frame() {
    let ctx = lavapipe();
    let (doc, states) = two_objects();
    let mut renderer = Renderer::new(&ctx);
    for (n, state) in states.iter().enumerate() {
        let triangles = show_object(&ctx, renderer.layer_mut(&ctx, n), &doc, state).unwrap();
        assert_eq!(triangles > 0, n == 0, "object {n}: isosurfaces only where asked");
    }
    assert_eq!(renderer.layer_count(), 2);
    let clouds = [states[0].quantities[0].cloud, states[1].quantities[0].cloud];
    let img = draw(&ctx, &mut renderer, &clouds);
    assert_golden("scene_two_objects", &img);
    let (left, right) = halves(&img);
    assert!(left > 600 && right > 2000, "both objects drawn: {left} left, {right} right");

    // Every atom of both objects picks as its object where its placement puts it (as itself,
    // unless another atom of that object or a surface is in front).
    for (n, state) in states.iter().enumerate() {
        let m = state.placement.world_from_object().as_dmat4();
        let mut exact = 0;
        for (i, atom) in doc.molecule.atoms.iter().enumerate() {
            let px = pixel_of(&renderer, m.transform_point3(atom.position).as_vec3());
            let picked = renderer.pick(&ctx, px).unwrap();
            let object = match picked {
                Some(PickId::Atom { object, index }) => {
                    exact += usize::from(index == i as u32);
                    object
                }
                Some(PickId::Surface { object, .. }) => object,
                None => panic!("object {n} atom {i}: nothing at {px:?}"),
            };
            assert_eq!(object, n as u32, "object {n} atom {i}");
        }
        assert!(exact >= 1, "object {n}: {exact} atoms picked as themselves");
    }
    // Object 0's +lobe centre (0.3, 0, +2) is a surface of object 0.
    let lobe = pixel_of(&renderer, Vec3::new(0.3, 0.0, 2.0));
    assert!(matches!(renderer.pick(&ctx, lobe).unwrap(), Some(PickId::Surface { object: 0, .. })));

    // Hiding object 1 leaves the right half empty; removing object 0 leaves object 1 as layer 0.
    renderer.layer_mut(&ctx, 1).visible = false;
    let hidden = draw(&ctx, &mut renderer, &clouds);
    hidden.save(std::env::temp_dir().join("hidden.png")).ok();
    assert!(halves(&hidden).1 < right / 10, "object 1 hidden: {:?} vs {right}", halves(&hidden));
    renderer.layer_mut(&ctx, 1).visible = true;
    renderer.remove(&ctx, 0);
    assert_eq!(renderer.layer_count(), 1);
    let only_cloud = draw(&ctx, &mut renderer, &clouds[1..]);
    let (l, r) = halves(&only_cloud);
    assert!(r > right / 2 && l < left, "object 1 alone: {l} left, {r} right");
    let moved = states[1].placement.world_from_object().as_dmat4().transform_point3(doc.molecule.atoms[0].position);
    assert_eq!(
        renderer.pick(&ctx, pixel_of(&renderer, moved.as_vec3())).unwrap(),
        Some(PickId::Atom { object: 0, index: 0 }),
        "after the removal, the cloud's object picks as object 0"
    );
}

#[test]
fn a_placed_cloud_matches_the_same_cloud_moved_in_its_grid() {
    // Placing an object moves its whole picture: a cloud placed 3 bohr along x renders like the
    // same grid whose origin moved 3 bohr (within the slices' sampling).
    let ctx = lavapipe();
    let (mut doc, mut states) = two_objects();
    doc.molecule = orbcloud::model::Molecule::default();
    states[1].placement = Placement { offset: [3.0, 0.0, 0.0], rotation_deg: [0.0; 3] };
    let mut placed = Renderer::new(&ctx);
    show_object(&ctx, placed.main(), &doc, &states[1]).unwrap();
    let mut shifted_doc = doc.clone();
    let g = &mut shifted_doc.volumes[0];
    *g = orbcloud::model::VolumeGrid::new(
        "shifted",
        g.dims,
        glam::DMat4::from_translation(DVec3::new(3.0, 0.0, 0.0)) * g.world_from_grid,
        g.values.clone(),
    );
    let mut moved = Renderer::new(&ctx);
    let plain = ObjectState { placement: Placement::default(), ..states[1].clone() };
    show_object(&ctx, moved.main(), &shifted_doc, &plain).unwrap();
    let clouds = [states[1].quantities[0].cloud];
    let (a, b) = (draw(&ctx, &mut placed, &clouds), draw(&ctx, &mut moved, &clouds));
    let diff: f64 =
        a.pixels().zip(b.pixels()).map(|(p, q)| (0..3).map(|c| p[c].abs_diff(q[c]) as f64).sum::<f64>()).sum::<f64>()
            / (3.0 * a.len() as f64 / 4.0);
    assert!(diff < 1.0, "mean difference {diff:.3}/255");
    assert!(halves(&a).0 + halves(&a).1 > 2000, "the cloud is drawn");
}

#[test]
fn gpu_errors_inside_a_guard_become_messages() {
    use orbcloud::gpu::GpuError;
    use orbcloud::gpu::context::guarded;
    let ctx = lavapipe();
    let too_wide = ctx.device.limits().max_texture_dimension_2d + 1;
    let result = guarded(&ctx.device, || {
        let _texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("over the limit"),
            size: wgpu::Extent3d { width: too_wide, height: 1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        Ok(())
    });
    match result {
        Err(GpuError::Rejected(message)) => {
            assert!(message.contains("over the limit") || message.contains("imension"), "{message}");
        }
        other => panic!("the texture over the limit was not caught: {other:?}"),
    }
    // The device goes on working after the caught error.
    assert!(guarded(&ctx.device, || Ok(Renderer::new(&ctx).layer_count())).is_ok());
}

#[test]
fn a_frame_drawn_in_bands_equals_the_frame_drawn_at_once() {
    use orbcloud::gpu::Tile;
    let ctx = lavapipe();
    let (doc, states) = two_objects();
    let mut renderer = Renderer::new(&ctx);
    for (n, state) in states.iter().enumerate() {
        show_object(&ctx, renderer.layer_mut(&ctx, n), &doc, state).unwrap();
    }
    let clouds = [states[0].quantities[0].cloud, states[1].quantities[0].cloud];
    let whole = draw(&ctx, &mut renderer, &clouds);
    let target = OffscreenTarget::new(&ctx.device, SIZE);
    let camera = camera();
    let mut partial = None;
    for (n, y) in (0..SIZE[1]).step_by(37).enumerate() {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let tile = Tile { rect: [0, y, SIZE[0], 37], first: n == 0 };
        let frame = FrameInput {
            camera: &camera,
            background: RenderSettings::default().background,
            clouds: &clouds,
            size: SIZE,
            tile: Some(tile),
        };
        renderer.render(&ctx, &mut encoder, &target.color_view, &frame);
        ctx.queue.submit([encoder.finish()]);
        if n == 1 {
            partial = Some(target.read_rgba(&ctx.device, &ctx.queue).unwrap());
        }
    }
    let banded = target.read_rgba(&ctx.device, &ctx.queue).unwrap();
    let worst = whole
        .pixels()
        .zip(banded.pixels())
        .map(|(a, b)| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap())
        .max()
        .unwrap();
    assert!(worst <= 1, "bands differ from the whole frame by {worst}/255");
    // Two bands in, the clouds below them are not drawn yet; the atoms and surfaces are.
    let partial = partial.unwrap();
    let below = |img: &image::RgbaImage| {
        (74..SIZE[1])
            .flat_map(|y| (0..SIZE[0]).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y) != whole.get_pixel(x, y))
            .count()
    };
    assert!(below(&partial) > 100, "the lower bands fill in later");
}

#[test]
fn grids_over_the_gpus_limits_are_shown_coarser_with_a_note() {
    use orbcloud::evaluate::meshes::isosurfaces_within;
    use orbcloud::evaluate::{WavefunctionView, evaluate_within};
    use orbcloud::layers::coarser_note;
    let ctx = lavapipe();
    // One side longer than any 3D texture this device makes: shown with every 2nd point.
    let max = ctx.device.limits().max_texture_dimension_3d as usize;
    let long = orbcloud::model::VolumeGrid::new(
        "long",
        [max + 1, 2, 2],
        orbcloud::model::VolumeGrid::affine(DVec3::ZERO, [DVec3::X * 0.01, DVec3::Y, DVec3::Z]),
        (0..(max + 1) * 4).map(|i| (i % 7) as f32).collect(),
    );
    let mut renderer = Renderer::new(&ctx);
    let step = renderer.main().set_volume(&ctx, Some(&long)).expect("shown coarser, not refused");
    assert_eq!(step, 2);
    let shown = renderer.layer(0).unwrap().volume.volume().unwrap().dims;
    assert_eq!(shown, long.subsampled(2).dims);
    assert!(coarser_note("long.cube", long.dims, 2).contains("one point in 2"));

    // An orbital asked on more points than the limits allow is evaluated on fewer, with a note.
    let doc = orbcloud::formats::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/wavefunctions/h2o_cart_631gs.molden"
    )))
    .unwrap();
    let mut small = ctx.device.limits();
    small.max_texture_dimension_3d = 24;
    let homo = doc.wavefunction.as_ref().unwrap().homo(orbcloud::model::Spin::Alpha).unwrap();
    let view = WavefunctionView {
        quantity: orbcloud::model::orbitals::Quantity::Orbital(homo),
        direct: false,
        points: 64,
        functions: None,
        grid: true,
    };
    let fill = orbcloud::gpu::gto::GtoFillPass::new(&ctx);
    let (evaluated, note) = evaluate_within(&ctx, &fill, &doc, &view, &small).unwrap();
    let grid = evaluated.unwrap().values.grid.unwrap();
    assert!(grid.dims.iter().all(|&d| d <= 24), "{:?}", grid.dims);
    assert!(note.unwrap().contains("64 points per side are more than this GPU holds"));

    // Isosurfaces whose meshes would not fit a buffer are cut from a coarser grid.
    let p = p_orbital(48, false);
    let iso =
        orbcloud::scene::IsosurfaceSettings { visible: true, level: IsoLevel::Absolute(0.2), ..Default::default() };
    let (whole, none) = isosurfaces_within(&p, &[iso], u64::MAX);
    assert!(none.is_none());
    let biggest = whole.iter().map(|(m, _)| m.positions.len() as u64 * 24).max().unwrap();
    let (coarse, note) = isosurfaces_within(&p, &[iso], biggest / 2);
    assert!(note.unwrap().contains("one point in 2"));
    assert!(coarse.iter().all(|(m, _)| m.positions.len() as u64 * 24 <= biggest / 2) && !coarse.is_empty());
}
