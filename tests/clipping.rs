//! The clipping plane cuts every representation of an object: its cloud, its opaque and
//! translucent isosurfaces, its molecular surface and, when asked, its atoms and bonds. Each case
//! is a golden image and a check against the same scene drawn whole: a pixel whose ray meets the
//! object's (padded) box only beyond the plane shows the background, and a pixel whose ray meets
//! it only on the kept side is unchanged.

mod common;

use std::sync::atomic::{AtomicBool, AtomicU32};

use common::{assert_golden, lavapipe, p_orbital, scene};
use glam::{DMat4, DVec3, Vec4};
use orbcloud::evaluate::meshes::molecular_surface;
use orbcloud::layers::{object_centre, show_meshes};
use orbcloud::model::isosurface::Mesh;
use orbcloud::model::units::BOHR_PER_ANGSTROM;
use orbcloud::model::{Atom, Document, Molecule};
use orbcloud::pictures::headless::Headless;
use orbcloud::scene::translucency::SurfaceLook;
use orbcloud::scene::{
    AtomStyle, Camera, ClipPlane, IsoLevel, RenderSettings, SurfaceChoice, SurfaceSettings, VolumeSettings,
};

const SIZE: [u32; 2] = [192, 144];

/// A 3×3×3 block of carbons 1.54 Å apart, bonded to their neighbours, centred on the origin.
fn block() -> Document {
    let mut atoms = Vec::new();
    for i in -1..=1 {
        for j in -1..=1 {
            for k in -1..=1 {
                let ang = DVec3::new(i as f64, j as f64, k as f64) * 1.54;
                atoms.push(Atom { z: 6, charge: 6.0, position: ang * BOHR_PER_ANGSTROM, ghost: false });
            }
        }
    }
    Document { source: "synthetic".into(), molecule: Molecule::new(atoms), ..Document::default() }
}

/// Nothing but what the case adds: no cloud, no atoms.
fn bare() -> RenderSettings {
    let mut s = RenderSettings {
        volume: VolumeSettings { visible: false, slices: 96, ..VolumeSettings::default() },
        atoms: AtomStyle::Hidden,
        ..RenderSettings::default()
    };
    s.iso.visible = false;
    s
}

/// The camera of every case, framing `doc`'s bounds grown by `pad` (bohr), and a plane through
/// the object's centre that faces right and a little towards the eye: the right half of the
/// picture is cut, and the cut is seen into.
fn view(doc: &Document, pad: f64) -> (Camera, ClipPlane) {
    let (lo, hi) = doc.bounds().expect("bounds");
    let mut camera = Camera::framing((lo - pad).as_vec3(), (hi + pad).as_vec3());
    camera.orbit(50f32.to_radians(), 25f32.to_radians());
    let (right, _) = camera.screen_axes();
    let normal = (right + 0.3 * camera.backward()).normalize();
    (camera, ClipPlane { enabled: true, normal: normal.to_array(), offset: 0.0, atoms: false })
}

/// `doc` (its first data set, if any) drawn as `s` says, with `meshes` as its surfaces when
/// given; the picture and the projection it was drawn with.
fn draw(
    doc: &Document,
    s: &RenderSettings,
    camera: &Camera,
    meshes: &[(Mesh, SurfaceLook)],
) -> (image::RgbaImage, DMat4) {
    let ctx = lavapipe();
    let index = (!doc.volumes.is_empty()).then_some(0);
    let mut h = Headless::new(&ctx, doc, index, s, SIZE).expect("scene");
    if !meshes.is_empty() {
        show_meshes(&ctx, h.renderer.main(), meshes);
    }
    let img = h.render(&ctx, camera, s).expect("render");
    (img, h.renderer.clip_from_world(camera, SIZE).as_dmat4())
}

/// Pixels, as (x, y).
type Pixels = Vec<(u32, u32)>;

/// The pixels whose ray meets the box `lo..hi` only beyond `plane` (cut), and those whose ray
/// meets it only on the kept side.
fn sides(clip_from_world: DMat4, plane: Vec4, (lo, hi): (DVec3, DVec3)) -> (Pixels, Pixels) {
    let world_from_clip = clip_from_world.inverse();
    let plane = plane.as_dvec4();
    let (mut cut, mut kept) = (Vec::new(), Vec::new());
    for y in 0..SIZE[1] {
        for x in 0..SIZE[0] {
            let ndc = |z| {
                let nx = (x as f64 + 0.5) / SIZE[0] as f64 * 2.0 - 1.0;
                let ny = 1.0 - (y as f64 + 0.5) / SIZE[1] as f64 * 2.0;
                world_from_clip.project_point3(DVec3::new(nx, ny, z))
            };
            let (a, b) = (ndc(0.0), ndc(1.0));
            let d = b - a;
            let (mut t0, mut t1) = (0.0f64, 1.0f64);
            for k in 0..3 {
                if d[k].abs() < 1e-12 {
                    if a[k] < lo[k] || a[k] > hi[k] {
                        t0 = 2.0;
                    }
                    continue;
                }
                let (u, v) = ((lo[k] - a[k]) / d[k], (hi[k] - a[k]) / d[k]);
                t0 = t0.max(u.min(v));
                t1 = t1.min(u.max(v));
            }
            if t0 > t1 {
                continue;
            }
            let beyond = |t: f64| plane.truncate().dot(a + d * t) > plane.w;
            match (beyond(t0), beyond(t1)) {
                (true, true) => cut.push((x, y)),
                (false, false) => kept.push((x, y)),
                _ => {}
            }
        }
    }
    (cut, kept)
}

/// sRGB bytes of the linear background colour.
fn background(s: &RenderSettings) -> [u8; 3] {
    s.background.map(|c| {
        let v = if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
        (v * 255.0).round() as u8
    })
}

/// Draws `doc` whole and clipped by `clip` and checks both sides of the plane, the rays tested
/// against the object's bounds grown by `pad` (bohr: what stands out of the atoms' covalent
/// radii); returns the clipped picture.
fn check(
    name: &str,
    doc: &Document,
    s: &RenderSettings,
    (clip, pad): (ClipPlane, f64),
    meshes: &[(Mesh, SurfaceLook)],
) -> image::RgbaImage {
    let (camera, _) = view(doc, pad);
    let (whole, clip_from_world) = draw(doc, s, &camera, meshes);
    let (clipped, _) = draw(doc, &RenderSettings { clip, ..*s }, &camera, meshes);
    let centre = object_centre(doc);
    let (lo, hi) = doc.bounds().expect("bounds");
    let plane = clip.plane(centre).expect("the plane is on");
    let (cut, kept) = sides(clip_from_world, plane, (lo - pad, hi + pad));
    let bg = background(s);
    let shows = |img: &image::RgbaImage, &(x, y): &(u32, u32)| {
        let p = img.get_pixel(x, y);
        (0..3).any(|c| (p[c] as i32 - bg[c] as i32).abs() > 1)
    };
    let cut_shown = cut.iter().filter(|p| shows(&whole, p)).count();
    let kept_shown = kept.iter().filter(|p| shows(&whole, p)).count();
    assert!(
        cut_shown > 300 && kept_shown > 300,
        "{name}: drawn whole it shows {cut_shown} pixels beyond the plane and {kept_shown} before it"
    );
    let left = cut.iter().filter(|p| shows(&clipped, p)).count();
    assert_eq!(left, 0, "{name}: {left} of the {cut_shown} pixels beyond the plane still show");
    let changed = kept
        .iter()
        .filter(|&&(x, y)| {
            let (a, b) = (clipped.get_pixel(x, y), whole.get_pixel(x, y));
            (0..3).any(|c| (a[c] as i32 - b[c] as i32).abs() > 2)
        })
        .count();
    assert_eq!(changed, 0, "{name}: {changed} of the {} pixels before the plane changed", kept.len());
    eprintln!("{name}: {cut_shown} pixels cut away, {kept_shown} kept as they were");
    clipped
}

#[test]
fn the_plane_cuts_a_cloud() {
    let doc = scene(Some(p_orbital(40, false)));
    let mut s = bare();
    s.volume.visible = true;
    let (_, clip) = view(&doc, 0.0);
    assert_golden("clipped_cloud_oblique", &check("cloud", &doc, &s, (clip, 0.0), &[]));
}

#[test]
fn the_plane_cuts_opaque_isosurfaces_open() {
    let doc = scene(Some(p_orbital(40, false)));
    let mut s = bare();
    s.iso.visible = true;
    s.iso.level = IsoLevel::Absolute(0.15);
    let (_, clip) = view(&doc, 0.0);
    assert_golden("clipped_isosurfaces", &check("opaque isosurfaces", &doc, &s, (clip, 0.0), &[]));
}

#[test]
fn the_plane_cuts_translucent_isosurfaces() {
    let doc = scene(Some(p_orbital(40, false)));
    let mut s = bare();
    s.iso.visible = true;
    s.iso.translucent = true;
    s.iso.level = IsoLevel::Absolute(0.15);
    let (_, clip) = view(&doc, 0.0);
    assert_golden("clipped_translucent_isosurfaces", &check("translucent isosurfaces", &doc, &s, (clip, 0.0), &[]));
}

#[test]
fn the_plane_cuts_a_molecular_surface() {
    let doc = block();
    let surface = SurfaceSettings { choice: SurfaceChoice::Gaussian, ..SurfaceSettings::default() };
    let stop = (&AtomicBool::new(false), &AtomicU32::new(0));
    let (mesh, _) = molecular_surface(&doc, &surface, "", u64::MAX, stop).expect("surface").expect("a surface");
    let meshes = [(mesh, surface.look())];
    assert!(meshes[0].1.lod_px.is_some(), "drawn with its level of detail, as the viewer draws it");
    let (_, clip) = view(&doc, 0.0);
    assert_golden("clipped_molecular_surface", &check("molecular surface", &doc, &bare(), (clip, 4.0), &meshes));
}

#[test]
fn the_plane_cuts_atoms_and_bonds_when_asked() {
    let doc = block();
    let s = RenderSettings { atoms: AtomStyle::BallAndStick, ball_scale: 2.0, ..bare() };
    let (camera, clip) = view(&doc, 0.5);
    // Not asked: the atoms stay whole.
    let (whole, _) = draw(&doc, &s, &camera, &[]);
    let (spared, _) = draw(&doc, &RenderSettings { clip, ..s }, &camera, &[]);
    assert_eq!(whole, spared, "a plane that does not cut atoms leaves them as they are");
    let clip = ClipPlane { atoms: true, ..clip };
    assert_golden("clipped_atoms", &check("atoms and bonds", &doc, &s, (clip, 0.5), &[]));
}

/// The same cut whichever way a sphere is drawn: rasterised in compute when small, or as a
/// quad (a sphere crossing the plane is always a quad, its cut face drawn flat).
#[test]
fn small_and_large_spheres_are_cut_alike() {
    let doc = block();
    let s = RenderSettings {
        atoms: AtomStyle::SpaceFilling,
        clip: ClipPlane { atoms: true, ..view(&doc, 0.5).1 },
        ..bare()
    };
    let (mut camera, _) = view(&doc, 0.5);
    // Far enough that every sphere is small enough for the compute rasteriser.
    camera.distance *= 2.5;
    let ctx = lavapipe();
    let mut pictures = Vec::new();
    for splat_px in [0.0, 18.0] {
        let mut h = Headless::new(&ctx, &doc, None, &s, SIZE).expect("scene");
        h.renderer.main().atoms.splat_radius_px = splat_px;
        pictures.push(h.render(&ctx, &camera, &s).expect("render"));
    }
    let differ = pictures[0]
        .pixels()
        .zip(pictures[1].pixels())
        .filter(|(a, b)| (0..3).any(|c| (a[c] as i32 - b[c] as i32).abs() > 2))
        .count();
    assert!(differ < 20, "quads and compute-rasterised spheres differ in {differ} pixels");
}
