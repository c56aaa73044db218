//! Molecular surfaces against analytic references: a lone atom (both kinds give its sphere), and
//! the solvent-excluded surface of two atoms (two spherical caps joined by the probe's toroidal
//! saddle, or the union of the spheres when the probe is a point), areas and enclosed volumes.

use std::f64::consts::PI;
use std::sync::atomic::AtomicBool;

use glam::DVec3;
use orbcloud::model::surface::{self, Sphere, SurfaceKind, SurfaceParams};
use orbcloud::model::units::BOHR_PER_ANGSTROM as A;

fn params(kind: SurfaceKind, resolution_angstrom: f64, probe_angstrom: f64) -> SurfaceParams {
    SurfaceParams {
        kind,
        resolution: resolution_angstrom * A,
        probe: probe_angstrom * A,
        smoothness: SurfaceParams::SMOOTHNESS,
    }
}

fn build(spheres: &[Sphere], p: &SurfaceParams) -> (f64, f64, orbcloud::model::isosurface::Mesh) {
    let s = surface::build(spheres, p, &AtomicBool::new(false)).expect("surface");
    (s.mesh.area(), s.mesh.volume(), s.mesh)
}

fn relative(got: f64, want: f64) -> f64 {
    (got - want).abs() / want
}

/// A closed surface encloses the same volume whatever point the divergence theorem's cones
/// start from; a hole makes the sum depend on it. (Welding by position cannot show it: where a
/// grid value lies within rounding of the level, marching cubes puts several vertices on one
/// grid point.)
fn assert_closed(mesh: &orbcloud::model::isosurface::Mesh) {
    let cones = |o: DVec3| -> f64 { mesh.triangles().map(|[a, b, c]| (a - o).dot((b - o).cross(c - o)) / 6.0).sum() };
    let v = cones(DVec3::ZERO);
    for o in [DVec3::new(40.0, -25.0, 10.0), DVec3::new(-30.0, 60.0, -45.0)] {
        assert!((cones(o) - v).abs() < 1e-6 * v.abs(), "volume {v} from the origin, {} from {o}", cones(o));
    }
}

#[test]
fn a_lone_atom_is_its_sphere_for_both_kinds() {
    let r = 1.7 * A;
    let atom = [Sphere { centre: DVec3::new(0.3, -0.2, 0.1), radius: r }];
    let (area, volume) = (4.0 * PI * r * r, 4.0 / 3.0 * PI * r.powi(3));
    for kind in [SurfaceKind::Gaussian, SurfaceKind::SolventExcluded] {
        let (a, v, mesh) = build(&atom, &params(kind, 0.15, 1.4));
        println!("{kind:?}: area {:.3}% volume {:.3}% off", 100.0 * (a / area - 1.0), 100.0 * (v / volume - 1.0));
        assert!(
            relative(a, area) < 0.01 && relative(v, volume) < 0.01,
            "{kind:?}: area {a} vs {area}, volume {v} vs {volume}"
        );
        assert_closed(&mesh);
        // Outward normals: each points away from the centre.
        let outward = mesh
            .positions
            .iter()
            .zip(&mesh.normals)
            .filter(|(p, n)| (p.as_dvec3() - atom[0].centre).dot(n.as_dvec3()) > 0.0);
        assert_eq!(outward.count(), mesh.positions.len(), "{kind:?}");
    }
}

/// The SES of two spheres (radii r1, r2, centres d apart on the x axis) that a probe of radius
/// p cannot pass between: the far cap of each sphere up to where the probe touches it, and the
/// inner part of the torus the probe's centre sweeps. Returns (area, volume).
fn two_sphere_ses(r1: f64, r2: f64, d: f64, p: f64) -> (f64, f64) {
    let (a1, a2) = (r1 + p, r2 + p);
    // The probe's centre circle: at x0 along the axis, radius rho.
    let x0 = (d * d + a1 * a1 - a2 * a2) / (2.0 * d);
    let rho = (a1 * a1 - x0 * x0).sqrt();
    assert!(rho > p, "the torus must not cut the axis");
    // Where the probe touches each sphere (x along the axis from the first centre).
    let x1 = x0 * r1 / a1;
    let x2 = d - (d - x0) * r2 / a2;
    assert!(x1 <= x2, "the contact circles must not cross");
    let caps = 2.0 * PI * r1 * (r1 + x1) + 2.0 * PI * r2 * (r2 + d - x2);
    let (t1, t2) = (-(x0 / a1).asin(), ((d - x0) / a2).asin());
    let torus = 2.0 * PI * p * (rho * (t2 - t1) - p * (t2.sin() - t1.sin()));
    // Volume of revolution: π ∫ r(x)² dx, caps in closed form, the saddle by Simpson's rule.
    let cap = |r: f64, h: f64| PI * (r * r * h - h.powi(3) / 3.0 + 2.0 * r.powi(3) / 3.0);
    let n = 20_000;
    let step = (x2 - x1) / n as f64;
    let radius2 = |x: f64| (rho - (p * p - (x - x0).powi(2)).max(0.0).sqrt()).powi(2);
    let simpson: f64 = (0..=n)
        .map(|i| {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * radius2(x1 + i as f64 * step)
        })
        .sum::<f64>()
        * step
        / 3.0;
    (caps + torus, cap(r1, x1) + PI * simpson + cap(r2, d - x2))
}

#[test]
fn two_atoms_give_the_analytic_solvent_excluded_surface() {
    for (r1, r2, d) in [(1.7, 1.7, 3.0), (1.7, 1.2, 2.2), (1.52, 1.7, 3.3)] {
        let p = 1.4;
        let (area, volume) = two_sphere_ses(r1 * A, r2 * A, d * A, p * A);
        let spheres = [
            Sphere { centre: DVec3::new(-0.4, 0.1, 0.2), radius: r1 * A },
            Sphere { centre: DVec3::new(-0.4 + d * A, 0.1, 0.2), radius: r2 * A },
        ];
        let (a, v, mesh) = build(&spheres, &params(SurfaceKind::SolventExcluded, 0.15, p));
        println!(
            "r {r1}/{r2} Å, d {d} Å: area {:.2} Å² ({:+.3}%), volume {:.2} Å³ ({:+.3}%)",
            a / (A * A),
            100.0 * (a / area - 1.0),
            v / A.powi(3),
            100.0 * (v / volume - 1.0)
        );
        assert!(relative(a, area) < 0.01, "area {a} vs analytic {area}");
        assert!(relative(v, volume) < 0.01, "volume {v} vs analytic {volume}");
        assert_closed(&mesh);
        // The saddle fills the crevice: more volume than the two spheres' union.
        let union = if d < r1 + r2 {
            two_sphere_ses(r1 * A, r2 * A, d * A, 0.0).1
        } else {
            4.0 / 3.0 * PI * (r1.powi(3) + r2.powi(3)) * A.powi(3)
        };
        assert!(v > union, "SES {v} should exceed the union {union}");
    }
}

#[test]
fn a_point_probe_gives_the_union_of_the_spheres() {
    let (r1, r2, d) = (1.7 * A, 1.55 * A, 2.6 * A);
    let (area, volume) = two_sphere_ses(r1, r2, d, 0.0);
    // The union's lens in closed form, as a check of the reference itself.
    let x = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
    let lens_area = 4.0 * PI * (r1 * r1 + r2 * r2) - 2.0 * PI * r1 * (r1 - x) - 2.0 * PI * r2 * (r2 - (d - x));
    assert!(relative(area, lens_area) < 1e-12);
    let spheres = [Sphere { centre: DVec3::ZERO, radius: r1 }, Sphere { centre: DVec3::X * d, radius: r2 }];
    let (a, v, _) = build(&spheres, &params(SurfaceKind::SolventExcluded, 0.12, 0.0));
    println!("union: area {:+.3}%, volume {:+.3}%", 100.0 * (a / area - 1.0), 100.0 * (v / volume - 1.0));
    // The crease where the spheres meet is cut off by marching cubes: a little area lost there.
    assert!(relative(a, area) < 0.015 && relative(v, volume) < 0.01, "area {a} vs {area}, volume {v} vs {volume}");
}

#[test]
fn the_gaussian_surface_blends_neighbours_and_leaves_distant_atoms_alone() {
    let r = 1.5 * A;
    let lone = 4.0 / 3.0 * PI * r.powi(3);
    let p = params(SurfaceKind::Gaussian, 0.15, 1.4);
    let far = [Sphere { centre: DVec3::ZERO, radius: r }, Sphere { centre: DVec3::X * 12.0 * A, radius: r }];
    let (_, v_far, _) = build(&far, &p);
    assert!(relative(v_far, 2.0 * lone) < 0.01, "two distant atoms: {v_far} vs {}", 2.0 * lone);
    // Bonded atoms: the union's volume and then some (the neck fills in), all of both spheres inside.
    let near = [Sphere { centre: DVec3::ZERO, radius: r }, Sphere { centre: DVec3::X * 1.5 * A, radius: r }];
    let (_, union) = two_sphere_ses(r, r, 1.5 * A, 0.0);
    let (_, v_near, mesh) = build(&near, &p);
    assert!(v_near > union, "blended {v_near} vs union {union}");
    for q in &mesh.positions {
        let q = q.as_dvec3();
        let inside = near.iter().any(|s| (q - s.centre).length() < s.radius * 0.995);
        assert!(!inside, "surface point {q} lies inside an atom's sphere");
    }
}

/// A protein fragment against MSMS (`scripts/make_surface_reference.py`): the same spheres,
/// probe 1.4 Å, MSMS's analytical SES area. Marching cubes reads a little more area where the
/// surface folds tightly between atoms; both kinds of error are bounded here.
/// A reference `scripts/make_surface_reference.py` wrote: the spheres (bohr), MSMS's SES area
/// (Å²) and the probe radius (Å).
fn msms_reference(name: &str) -> (Vec<Sphere>, f64, f64) {
    use std::io::Read;
    let path = format!("{}/tests/fixtures/structures/{name}", env!("CARGO_MANIFEST_DIR"));
    let bytes = std::fs::read(&path).unwrap();
    let mut text = String::new();
    if name.ends_with(".gz") {
        flate2::read::GzDecoder::new(&bytes[..]).read_to_string(&mut text).unwrap();
    } else {
        text = String::from_utf8(bytes).unwrap();
    }
    let reference: serde_json::Value = serde_json::from_str(&text).unwrap();
    let spheres: Vec<Sphere> = reference["spheres_angstrom"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            let v: Vec<f64> = s.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            Sphere { centre: DVec3::new(v[0], v[1], v[2]) * A, radius: v[3] * A }
        })
        .collect();
    (spheres, reference["ses_area_angstrom2"].as_f64().unwrap(), reference["probe_angstrom"].as_f64().unwrap())
}

#[test]
fn a_protein_fragment_matches_msms() {
    let (spheres, msms, probe) = msms_reference("msms_ses.json");
    // The same atoms as the viewer shows from the PDB file, with the radii it gives them.
    let doc = orbcloud::formats::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/structures/4e43_excerpt.pdb"
    )))
    .unwrap();
    let ours = Sphere::of_molecule(&doc.molecule, None);
    assert_eq!(ours.len(), spheres.len());
    for (a, b) in ours.iter().zip(&spheres) {
        assert!((a.centre - b.centre).length() < 1e-3 * A && (a.radius - b.radius).abs() < 1e-6, "{a:?} vs {b:?}");
    }
    let (area, _, mesh) = build(&spheres, &params(SurfaceKind::SolventExcluded, 0.25, probe));
    let area = area / (A * A);
    println!("SES area {area:.1} Å² against MSMS's {msms:.1} Å² ({:+.2}%)", 100.0 * (area / msms - 1.0));
    assert!(relative(area, msms) < 0.015, "area {area} vs MSMS {msms}");
    assert_closed(&mesh);
}

/// A whole protein chain against MSMS: chain A of HIV-1 protease (PDB 4E43, 99 amino acids,
/// 760 atoms, cavities included), the same spheres, probe 1.4 Å, MSMS's analytical SES area.
#[test]
fn a_whole_protein_chain_matches_msms() {
    let (spheres, msms, probe) = msms_reference("msms_ses_protein.json.gz");
    assert_eq!(spheres.len(), 760);
    let (area, volume, mesh) = build(&spheres, &params(SurfaceKind::SolventExcluded, 0.3, probe));
    let area = area / (A * A);
    println!(
        "SES area {area:.1} Å² against MSMS's {msms:.1} Å² ({:+.2}%), volume {:.0} Å³",
        100.0 * (area / msms - 1.0),
        volume / A.powi(3)
    );
    assert!(relative(area, msms) < 0.015, "area {area} vs MSMS {msms}");
    assert_closed(&mesh);
}
