//! Isosurfaces on lavapipe (golden images: an orbital's ± pair, a density, a surface inside its
//! cloud, a non-orthogonal grid), their area against a finer grid, mesh files read back, and
//! picking: render, read the id under a pixel, get the atom drawn there.

mod common;

use common::{assert_golden, coverage, lavapipe, p_orbital, scene};
use glam::DVec3;
use orbcloud::formats::mesh_write::{self, MeshFormat, NamedMesh};
use orbcloud::gpu::frame::PickId;
use orbcloud::layers::show_isosurfaces;
use orbcloud::model::isosurface::{self, Level, Mesh};
use orbcloud::model::{Document, VolumeGrid};
use orbcloud::pictures::headless::Headless;
use orbcloud::scene::framing::default_camera;
use orbcloud::scene::{AtomStyle, Camera, IsoLevel, RenderSettings};

const SIZE: [u32; 2] = [192, 144];

fn iso_settings(level: IsoLevel, cloud: bool) -> RenderSettings {
    let mut s = RenderSettings::default();
    s.volume.visible = cloud;
    s.volume.slices = 96;
    s.iso.visible = true;
    s.iso.level = level;
    s
}

fn camera(doc: &Document, yaw: f32, pitch: f32) -> Camera {
    let mut cam = default_camera(doc);
    cam.orbit(yaw.to_radians(), pitch.to_radians());
    cam
}

fn render(doc: &Document, s: &RenderSettings, cam: &Camera) -> (Headless, image::RgbaImage, orbcloud::gpu::GpuContext) {
    let ctx = lavapipe();
    let mut h = Headless::new(&ctx, doc, (!doc.volumes.is_empty()).then_some(0), s, SIZE).expect("renderer");
    let img = h.render(&ctx, cam, s).expect("render");
    (h, img, ctx)
}

/// Pixels that are clearly red (ψ > 0) and clearly blue (ψ < 0).
fn red_blue(img: &image::RgbaImage) -> (usize, usize) {
    let red = img.pixels().filter(|p| p[0] as i32 > p[2] as i32 + 40).count();
    let blue = img.pixels().filter(|p| p[2] as i32 > p[0] as i32 + 40).count();
    (red, blue)
}

/// ρ = exp(−r²/2) around the C=O midpoint: a density's one surface.
fn density_grid(n: usize) -> VolumeGrid {
    let h = 9.0 / (n - 1) as f64;
    let world = VolumeGrid::affine(DVec3::splat(-4.5), [DVec3::X * h, DVec3::Y * h, DVec3::Z * h]);
    let mut values = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = world.transform_point3(DVec3::new(i as f64, j as f64, k as f64));
                values.push((-(p - DVec3::new(0.3, 0.0, 0.0)).length_squared() / 2.0).exp() as f32);
            }
        }
    }
    VolumeGrid::new("density", [n, n, n], world, values)
}

#[test]
fn an_orbital_shows_both_signs_as_lit_surfaces() {
    let doc = scene(Some(p_orbital(48, false)));
    let s = iso_settings(IsoLevel::Absolute(0.3), false);
    let (_, img, _) = render(&doc, &s, &camera(&doc, 75.0, 15.0));
    assert_golden("iso_orbital_pm", &img);
    let (red, blue) = red_blue(&img);
    assert!(red > 800 && blue > 800, "red {red}, blue {blue}");
}

#[test]
fn a_density_has_one_surface_and_sigma_levels_resolve() {
    let grid = density_grid(40);
    let sigma = grid.stats.sigma;
    let doc = scene(Some(grid));
    // 2σ of this grid, given in σ.
    let s = iso_settings(IsoLevel::Sigma(2.0), false);
    let (h, img, _) = render(&doc, &s, &camera(&doc, 20.0, 20.0));
    assert!(coverage(&img, [3, 3, 4]) > 0.2);
    let (red, blue) = red_blue(&img);
    assert!(red < 50 && blue < 50, "a density is not coloured by sign: red {red}, blue {blue}");
    assert!(!h.renderer.layer(0).expect("one layer").surfaces.is_empty());
    assert!((IsoLevel::Sigma(2.0).value(sigma) as f64 - 2.0 * sigma).abs() < 1e-6);
    assert_golden("iso_density", &img);
}

#[test]
fn a_surface_inside_its_cloud_and_a_sheared_grid() {
    let doc = scene(Some(p_orbital(48, false)));
    let s = iso_settings(IsoLevel::Absolute(0.45), true);
    let (_, with_cloud, _) = render(&doc, &s, &camera(&doc, 30.0, 15.0));
    let (_, bare, _) = render(&doc, &iso_settings(IsoLevel::Absolute(0.45), false), &camera(&doc, 30.0, 15.0));
    assert_golden("iso_in_cloud", &with_cloud);
    // The cloud adds colour around the surfaces (and veils the parts behind it).
    let changed =
        with_cloud.pixels().zip(bare.pixels()).filter(|(a, b)| (0..3).any(|c| a[c].abs_diff(b[c]) > 10)).count();
    assert!(changed > with_cloud.len() / 4 / 20, "{changed} pixels changed by the cloud");

    let sheared = scene(Some(p_orbital(48, true)));
    let (_, img, _) = render(&sheared, &iso_settings(IsoLevel::Absolute(0.3), false), &camera(&sheared, 75.0, 15.0));
    let (red, blue) = red_blue(&img);
    assert!(red > 800 && blue > 800, "red {red}, blue {blue}");
    assert_golden("iso_sheared_grid", &img);
}

/// The analytic ψ = z·exp(−r²/4) on n³ points over ±4.5 bohr.
fn p_area(n: usize, level: f32) -> f64 {
    let grid = p_orbital(n, false);
    isosurface::extract(&grid, &Level::pair(level, true)).iter().map(Mesh::area).sum()
}

#[test]
fn area_converges_to_the_fine_grid_value() {
    // Marching cubes on a 3× finer grid of the same analytic field is the reference.
    let (coarse, fine) = (p_area(48, 0.2), p_area(142, 0.2));
    let rel = (coarse / fine - 1.0).abs();
    eprintln!("area 48³ {coarse:.4}, 142³ {fine:.4} bohr² ({:.3} %)", 100.0 * rel);
    assert!(rel < 0.01, "48³ area {coarse} vs 142³ {fine}");
}

#[test]
fn mesh_files_read_back() {
    let grid = p_orbital(32, false);
    let meshes: Vec<Mesh> =
        isosurface::extract(&grid, &Level::pair(0.2, true)).into_iter().map(|m| m.welded()).collect();
    let named = [
        NamedMesh { name: "psi_plus", mesh: &meshes[0], color: [1.0, 0.0, 0.0], values: None },
        NamedMesh { name: "psi_minus", mesh: &meshes[1], color: [0.0, 0.0, 1.0], values: None },
    ];
    let (v, f) = (
        meshes[0].positions.len() + meshes[1].positions.len(),
        meshes[0].triangle_count() + meshes[1].triangle_count(),
    );

    let mut obj = Vec::new();
    mesh_write::write(&mut obj, MeshFormat::Obj, &named).unwrap();
    let text = String::from_utf8(obj).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), v);
    assert_eq!(text.lines().filter(|l| l.starts_with("vn ")).count(), v);
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), f);
    assert_eq!(text.lines().filter(|l| l.starts_with("o ")).count(), 2);
    // Faces index existing vertices (1-based); positions are in ångström.
    let max_index = text
        .lines()
        .filter(|l| l.starts_with("f "))
        .flat_map(|l| l.split_whitespace().skip(1).map(|t| t.split("//").next().unwrap().parse::<usize>().unwrap()))
        .max()
        .unwrap();
    assert_eq!(max_index, v);
    let first = text.lines().find(|l| l.starts_with("v ")).unwrap();
    let x: Vec<f64> = first.split_whitespace().skip(1).map(|t| t.parse().unwrap()).collect();
    let bohr = meshes[0].positions[0].as_dvec3() * 0.529_177_210_903;
    assert!((DVec3::from_slice(&x) - bohr).length() < 1e-5);

    let mut ply = Vec::new();
    mesh_write::write(&mut ply, MeshFormat::Ply, &named).unwrap();
    let end = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&ply[..end]).unwrap();
    assert!(header.contains(&format!("element vertex {v}\n")) && header.contains(&format!("element face {f}\n")));
    assert_eq!(ply.len() - end, v * (24 + 3) + f * (1 + 12), "binary body size");

    let mut glb = Vec::new();
    mesh_write::write(&mut glb, MeshFormat::Glb, &named).unwrap();
    assert_eq!(&glb[..4], b"glTF");
    let u32_at = |o: usize| u32::from_le_bytes(glb[o..o + 4].try_into().unwrap()) as usize;
    assert_eq!(u32_at(8), glb.len());
    let json_len = u32_at(12);
    let json: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    assert_eq!(json["meshes"].as_array().unwrap().len(), 2);
    assert_eq!(json["accessors"][0]["count"].as_u64().unwrap() as usize, meshes[0].positions.len());
    assert_eq!(json["accessors"][2]["count"].as_u64().unwrap() as usize, 3 * meshes[0].triangle_count());
    let bin_len = u32_at(20 + json_len);
    assert_eq!(json["buffers"][0]["byteLength"].as_u64().unwrap() as usize, bin_len);
    assert_eq!(glb.len(), 20 + json_len + 8 + bin_len);
}

/// Pixel where world point `p` lands in a frame of `SIZE`.
fn pixel_of(h: &Headless, cam: &Camera, p: DVec3) -> [u32; 2] {
    let c = h.renderer.clip_from_world(cam, SIZE) * p.as_vec3().extend(1.0);
    let ndc = c.truncate() / c.w;
    [((ndc.x * 0.5 + 0.5) * SIZE[0] as f32) as u32, ((0.5 - ndc.y * 0.5) * SIZE[1] as f32) as u32]
}

#[test]
fn picking_returns_the_atom_under_the_pixel() {
    let doc = scene(None);
    let s = RenderSettings { atoms: AtomStyle::BallAndStick, ..Default::default() };
    let cam = camera(&doc, 20.0, 25.0);
    let (h, _, ctx) = render(&doc, &s, &cam);
    for (i, atom) in doc.molecule.atoms.iter().enumerate() {
        let px = pixel_of(&h, &cam, atom.position);
        assert_eq!(
            h.renderer.pick(&ctx, px).unwrap(),
            Some(PickId::Atom { object: 0, index: i as u32 }),
            "atom {i} at {px:?}"
        );
    }
    assert_eq!(h.renderer.pick(&ctx, [1, 1]).unwrap(), None, "the corner is background");
    assert_eq!(h.renderer.pick(&ctx, [SIZE[0], 0]).unwrap(), None, "outside the frame");
    // The C=O bond's midpoint is a half-bond of one of its two atoms.
    let mid = 0.5 * (doc.molecule.atoms[0].position + doc.molecule.atoms[1].position);
    let picked = h.renderer.pick(&ctx, pixel_of(&h, &cam, mid)).unwrap();
    assert!(matches!(picked, Some(PickId::Atom { index: 0 | 1, .. })), "{picked:?}");
}

#[test]
fn picking_finds_a_surface_in_front_of_the_atoms() {
    let mut doc = scene(Some(p_orbital(40, false)));
    doc.molecule = orbcloud::model::Molecule::new(doc.molecule.atoms[..2].to_vec());
    let s = iso_settings(IsoLevel::Absolute(0.2), false);
    let ctx = lavapipe();
    let mut h = Headless::new(&ctx, &doc, None, &s, SIZE).unwrap();
    let triangles = show_isosurfaces(&ctx, h.renderer.main(), &doc.volumes[0], &s.iso);
    assert!(triangles > 500);
    // The default camera looks down −z: the +z lobe hides the atoms in the molecular plane.
    let cam = default_camera(&doc);
    h.render(&ctx, &cam, &s).unwrap();
    let centre = pixel_of(&h, &cam, DVec3::new(0.3, 0.0, 0.0));
    assert_eq!(h.renderer.pick(&ctx, centre).unwrap(), Some(PickId::Surface { object: 0, index: 0 }));
}
