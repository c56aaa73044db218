//! Scans of a bond angle, a bond length and a path (fixtures from
//! scripts/make_coordinate_scans.py, PySCF): `scan init` finds the coordinate, key frames come
//! back exactly, a withheld frame is interpolated from its neighbours, and the command line
//! draws and exports at any value.

use std::path::{Path, PathBuf};
use std::process::Command;

use orbcloud::formats::scan::{ScanFile, init, load_scan, parse_scan};
use orbcloud::model::scan::{Coordinate, Follow, PathMeasure, Scan};

fn fixture(dir: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/scans").join(dir)
}

fn orbcloud(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_orbcloud")).args(args).env("NODEVICE_SELECT", "1").output().expect("run")
}

/// The manifest `scan init` makes for `dir`, read as a scan.
fn initialised(dir: &str, coordinate: Option<Coordinate>) -> ScanFile {
    let dir = fixture(dir);
    let made = init(&dir, coordinate).unwrap();
    parse_scan(&made.path, &made.text, &mut |p| orbcloud::formats::load(p)).unwrap()
}

fn norm(v: &[f32]) -> f64 {
    v.iter().map(|&x| (x as f64).powi(2)).sum::<f64>().sqrt()
}

/// Relative L2 errors of frame `held` interpolated from its neighbours and of its nearer
/// neighbour shown instead, on a common grid.
fn held_out(scan: &Scan, held: usize, slot: usize) -> (f64, f64) {
    let grid = scan.common_grid(orbcloud::scene::framing::ORBITAL_MARGIN, 40);
    let full = scan.track(Follow::Index).unwrap();
    let mut frames = scan.frames.clone();
    let truth_frame = frames.remove(held);
    let without = Scan::new(scan.title.clone(), scan.coordinate, scan.orbitals.clone(), frames).unwrap();
    let tracks = without.track(Follow::Index).unwrap();
    let interpolated = without.interpolated_values(&tracks, slot, truth_frame.at, &grid);
    let aligned = |mut v: Vec<f32>, to: &[f32]| {
        let dot: f64 = v.iter().zip(to).map(|(&a, &b)| a as f64 * b as f64).sum();
        if dot < 0.0 {
            v.iter_mut().for_each(|x| *x = -*x);
        }
        v
    };
    let truth = aligned(scan.key_values(&full, slot, held, &grid), &interpolated);
    let nearest = aligned(without.key_values(&tracks, slot, without.nearest_frame(truth_frame.at), &grid), &truth);
    let diff = |v: &[f32]| truth.iter().zip(v).map(|(a, b)| a - b).collect::<Vec<f32>>();
    (norm(&diff(&interpolated)) / norm(&truth), norm(&diff(&nearest)) / norm(&truth))
}

/// Every key frame's own geometry at its value.
fn assert_key_frames_reproduced(scan: &Scan) {
    for f in &scan.frames {
        let m = scan.geometry_at(f.at);
        for (a, b) in m.atoms.iter().zip(&f.molecule.atoms) {
            assert!(a.position.distance(b.position) < 1e-9, "{} at {}", scan.coordinate.label(), f.at);
        }
    }
}

#[test]
fn a_bending_scan_opens_from_scan_init_alone() {
    let file = initialised("water_bend", None);
    let scan = &file.scan;
    assert_eq!(scan.coordinate, Coordinate::Angle([1, 0, 2]), "the H-O-H angle, H2's side moving");
    assert_eq!(scan.coordinate.label(), "angle 2-1-3");
    assert_eq!(scan.values(), [80.0, 90.0, 100.0, 110.0, 120.0, 130.0, 140.0, 150.0, 160.0].map(|v: f64| v));
    assert_key_frames_reproduced(scan);
    // Between key frames the molecule keeps its O-H lengths and has the angle asked for.
    for value in [84.0, 117.5, 151.0] {
        let m = scan.geometry_at(value);
        let measured = scan.coordinate.measure(&m).unwrap();
        assert!((measured - value).abs() < 1e-6, "{value}: {measured}");
        let oh = m.atoms[0].position.distance(m.atoms[2].position) * orbcloud::model::units::ANGSTROM_PER_BOHR;
        assert!((oh - 0.96).abs() < 1e-6, "O-H {oh}");
    }
    // The frame at 120° withheld: its neighbours' mix comes close, far closer than either.
    let held = scan.frames.iter().position(|f| f.at == 120.0).unwrap();
    for slot in 0..2 {
        let (err, nearest) = held_out(scan, held, slot);
        eprintln!(
            "{} at 120° from 110°/130°: {:.2}% (nearest {:.2}%)",
            scan.orbitals[slot],
            err * 100.0,
            nearest * 100.0
        );
        assert!(err < 0.05 && err < 0.5 * nearest, "{}: {err} vs nearest {nearest}", scan.orbitals[slot]);
    }
}

#[test]
fn a_bond_length_scan_and_a_path() {
    let file = initialised("water_stretch", None);
    let scan = &file.scan;
    assert_eq!(scan.coordinate, Coordinate::Distance([0, 2]), "O-H2, found");
    let values = scan.values();
    assert!(values.iter().zip([0.8, 1.0, 1.2, 1.4, 1.6]).all(|(a, b)| (a - b).abs() < 1e-4), "{values:?}");
    assert_key_frames_reproduced(scan);
    let m = scan.geometry_at(1.1);
    assert!((scan.coordinate.measure(&m).unwrap() - 1.1).abs() < 1e-6);
    // The LUMO (σ* of the stretched bond) changes most; the HOMO (the O lone pair) hardly.
    let held = 2; // 1.2 Å
    let (err, nearest) = held_out(scan, held, 1);
    eprintln!("LUMO at 1.2 Å from 1.0/1.4 Å: {:.2}% (nearest {:.2}%)", err * 100.0, nearest * 100.0);
    assert!(err < 0.5 * nearest, "{err} vs {nearest}");
    // Given by hand, the same.
    assert_eq!(initialised("water_stretch", Some(Coordinate::Distance([0, 2]))).scan.coordinate, scan.coordinate);

    // The angle and a bond together: no single coordinate explains it, so a path.
    let made = init(&fixture("water_path"), None).unwrap();
    assert_eq!(made.coordinate, Coordinate::Path(PathMeasure::ArcLength));
    let path = load_scan(&fixture("water_path").join("water_path.scan.toml")).unwrap();
    assert_eq!(path.scan.coordinate, Coordinate::Path(PathMeasure::Frame));
    assert_eq!(path.scan.moving.len(), 3, "every atom moves");
    assert_key_frames_reproduced(&path.scan);
}

#[test]
fn manifests_name_their_coordinate_and_errors_their_line() {
    let dir = fixture("water_bend");
    let parse = |text: &str| {
        parse_scan(&dir.join("t.scan.toml"), text, &mut |p| orbcloud::formats::load(p)).map(|f| f.scan.coordinate)
    };
    let frames = "\n[[frame]]\nat = 90.0\nfile = \"h2o_a090.molden.gz\"\n\n[[frame]]\nat = 100.0\nfile = \"h2o_a100.molden.gz\"\n";
    assert_eq!(
        parse(&format!("coordinate = \"angle\"\natoms = [2, 1, 3]\n{frames}")).unwrap(),
        Coordinate::Angle([1, 0, 2])
    );
    // The older keys: dihedral = [...] and angle = per frame.
    let older = format!("dihedral = [1, 2, 3, 4]\n{}", frames.replace("at =", "angle ="));
    let e = parse(&older).unwrap_err().to_string();
    assert!(e.contains("t.scan.toml:1:") && e.contains("beyond the 3 atoms"), "{e}");
    for (text, line, says) in [
        (format!("coordinate = \"angle\"\natoms = [2, 1]\n{frames}"), 2, "3 atom numbers"),
        (format!("coordinate = \"bend\"\natoms = [2, 1, 3]\n{frames}"), 1, "distance, angle, dihedral or path"),
        (format!("coordinate = \"path\"\natoms = [1, 2]\n{frames}"), 2, "no atoms for a path"),
        (format!("coordinate = \"angle\"\natoms = [2, 1, 3]\nalign = true\n{frames}"), 3, "align only for a path"),
        (format!("atoms = [1, 2]\n{frames}"), 1, "no coordinate"),
        (
            format!("coordinate = \"angle\"\natoms = [2, 1, 3]\nmeasure = \"arc length\"\n{frames}"),
            1,
            "measure only for a path",
        ),
        (format!("coordinate = \"path\"\nmeasure = \"arc\"\n{frames}"), 2, "\"mass-weighted arc length\""),
    ] {
        let e = parse(&text).unwrap_err().to_string();
        assert!(e.contains(&format!("t.scan.toml:{line}:")) && e.contains(says), "{text}\n→ {e}");
    }
}

#[test]
fn the_command_line_takes_any_coordinate() {
    let dir = fixture("water_bend");
    let out = orbcloud(&["scan", "init", dir.to_str().unwrap(), "--dry-run"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("angle 2-1-3 (the coordinate that explains the change best)"), "{err}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("coordinate = \"angle\"") && text.contains("atoms = [2, 1, 3]") && text.contains("at = 80.0000")
    );
    let stretch = fixture("water_stretch");
    let out = orbcloud(&["scan", "init", stretch.to_str().unwrap(), "--distance", "1,3", "--dry-run"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("distance 1-3; 5 frames from 0.800 Å to 1.600 Å"));
    // A coordinate that does not change cannot order the frames.
    let out = orbcloud(&["scan", "init", dir.to_str().unwrap(), "--distance", "1,2", "--dry-run"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("a distance different from"), "{err}");
    // A path is measured by the length travelled (Å), or mass-weighted, as IRCs are; the
    // manifest says so and reads back with its unit.
    let path = fixture("water_path");
    for (flags, unit, measure) in [
        (&["--path"][..], "Å", "arc length"),
        (&["--path", "--mass-weighted"][..], "amu½·Å", "mass-weighted arc length"),
    ] {
        let mut args = vec!["scan", "init", path.to_str().unwrap(), "--dry-run"];
        args.extend_from_slice(flags);
        let out = orbcloud(&args);
        let (err, text) = (String::from_utf8_lossy(&out.stderr), String::from_utf8_lossy(&out.stdout));
        assert!(out.status.success() && err.contains(&format!("path; 4 frames from 0.000 {unit} to ")), "{err}");
        assert!(text.contains(&format!("measure = \"{measure}\"")) && text.contains("at = 0.0000"), "{text}");
        let last: f64 = text.rsplit("at = ").next().unwrap().lines().next().unwrap().parse().unwrap();
        assert!(last > 0.05, "the path is {last} {unit} long");
    }

    // A manifest on disk, rendered and exported at a value between key frames.
    let tmp = tempfile::tempdir().unwrap();
    let manifest = tmp.path().join("bend.scan.toml");
    let made = init(&dir, None).unwrap();
    let text = made.text.replace("file = \"", &format!("file = \"{}/", dir.display()));
    std::fs::write(&manifest, text).unwrap();
    let png = tmp.path().join("bend.png");
    let m = manifest.to_str().unwrap();
    let out = orbcloud(&[
        "scan",
        "render",
        m,
        "--at",
        "117",
        "--points",
        "24",
        "--size",
        "96x72",
        "--lavapipe",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(image::open(&png).unwrap().width(), 192);
    let out = orbcloud(&["scan", "render", m, "--at", "170", "-o", "x.png"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--at 170 is outside the scan's 80°..160°"), "{err}");
    let out = orbcloud(&["scan", "info", m]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("angle 2-1-3, 9 frames, 1 atom moves"));
}

#[test]
fn the_correlation_diagram_follows_each_orbital_by_character() {
    use orbcloud::model::correlation::correlation;
    let file = initialised("water_bend", None);
    let scan = &file.scan;
    let diagram = correlation(scan, 2, 2).unwrap();
    let labels: Vec<&str> = diagram.lines.iter().map(|l| l.label.as_str()).collect();
    assert_eq!(labels, ["HOMO−2", "HOMO−1", "HOMO", "LUMO", "LUMO+1", "LUMO+2"]);
    for l in &diagram.lines {
        eprintln!(
            "{:8} {:?} crossings at {:?}",
            l.label,
            l.points.iter().map(|p| (p.2 + 1, (p.1 * 1e3).round() / 1e3)).collect::<Vec<_>>(),
            l.crossings
        );
        // Each point is that frame's orbital's own energy.
        for (f, &(at, e, i)) in l.points.iter().enumerate() {
            assert_eq!(at, scan.frames[f].at);
            assert_eq!(e, scan.frames[f].wavefunction(0).unwrap().orbitals[i].energy);
        }
    }
    assert!(diagram.lines[..3].iter().all(|l| l.occupied) && diagram.lines[3..].iter().all(|l| !l.occupied));

    // An independent witness of character: an orbital's parity under the molecule's two
    // mirror planes (x → −x swaps the hydrogens; z → −z is the molecular plane). Every line
    // keeps its symmetry from frame to frame, and across the crossing the orbital of the same
    // number does not.
    let symmetry = |f: usize, i: usize| {
        let wf = scan.frames[f].wavefunction(0).unwrap();
        let basis = orbcloud::model::PreparedBasis::new(&wf.basis);
        let c = &wf.orbitals[i].coefficients;
        let p = glam::DVec3::new(0.7, 0.9, 0.4);
        let v = basis.orbital_value(c, p);
        let parity = |q: glam::DVec3| (basis.orbital_value(c, q) / v).signum() as i32;
        (parity(p * glam::DVec3::new(-1.0, 1.0, 1.0)), parity(p * glam::DVec3::new(1.0, 1.0, -1.0)))
    };
    for l in &diagram.lines {
        let first = symmetry(0, l.points[0].2);
        for (f, p) in l.points.iter().enumerate() {
            assert_eq!(symmetry(f, p.2), first, "{} at frame {f} (orbital {})", l.label, p.2 + 1);
        }
    }
    // An orbital whose character moves to another orbital number between two frames.
    let (crossing, f) = (diagram.lines.iter())
        .find_map(|l| (1..l.points.len()).find(|&f| l.points[f].2 != l.points[f - 1].2).map(|f| (l, f)))
        .expect("a character swap among the virtuals");
    let (before, after) = (crossing.points[f - 1].2, crossing.points[f].2);
    assert_ne!(before, after, "{} continues into another orbital number", crossing.label);
    assert_ne!(symmetry(f, before), symmetry(f - 1, before), "by number, the character would change");
    // The table, as `scan info --csv` writes it.
    let csv = diagram.csv("angle / deg");
    assert_eq!(csv.lines().count(), 10);
    assert!(csv.starts_with("angle / deg,E(HOMO−2) / Eh,HOMO−2 orbital"));
}

#[test]
fn a_path_written_in_many_orientations_is_aligned_with_its_orbitals() {
    // The same morph twice: each frame in the natural orientation, and each turned and moved
    // as its own file (water_turned/, align = true). Aligned, both give the same scan.
    let natural_dir = fixture("water_path");
    let text = std::fs::read_to_string(natural_dir.join("water_path.scan.toml")).unwrap();
    let aligned_text = text.replace("align = false", "align = true");
    let parse = |text: &str, dir: &Path| {
        parse_scan(&dir.join("m.scan.toml"), text, &mut |p| orbcloud::formats::load(p)).unwrap().scan
    };
    let natural = parse(&aligned_text, &natural_dir);
    let turned = load_scan(&fixture("water_turned").join("water_turned.scan.toml")).unwrap().scan;
    for at in [0.0, 0.5, 1.5, 2.25, 3.0] {
        let (a, b) = (natural.geometry_at(at), turned.geometry_at(at));
        for (p, q) in a.atoms.iter().zip(&b.atoms) {
            assert!(p.position.distance(q.position) < 1e-6, "atoms at {at}");
        }
    }
    let grid = natural.common_grid(orbcloud::scene::framing::ORBITAL_MARGIN, 24);
    let values = |scan: &Scan| {
        let tracks = scan.track(Follow::Index).unwrap();
        scan.interpolated_values(&tracks, 1, 1.5, &grid)
    };
    let (a, b) = (values(&natural), values(&turned));
    let diff: Vec<f32> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
    let rel = norm(&diff) / norm(&a);
    eprintln!(
        "LUMO halfway along the path, turned files aligned vs natural: relative difference {rel:.2e} (norm {:.3}, {} points)",
        norm(&a),
        a.len()
    );
    assert!(rel < 1e-4, "{rel}");
    // Without alignment the turned files' orbitals mix in different orientations.
    let unaligned_text = std::fs::read_to_string(fixture("water_turned").join("water_turned.scan.toml"))
        .unwrap()
        .replace("align = true", "align = false");
    let unaligned = parse(&unaligned_text, &fixture("water_turned"));
    let c = values(&unaligned);
    let off: Vec<f32> = a.iter().zip(&c).map(|(x, y)| x - y).collect();
    assert!(norm(&off) / norm(&a) > 0.3, "unaligned frames blend into something else");
    // Cube series cannot turn their orbitals.
    let e = parse_scan(
        &fixture("water_bend").join("c.scan.toml"),
        "coordinate = \"angle\"\natoms = [2, 1, 3]\nalign = true\n[[frame]]\nat = 1\nfile = \"h2o_a080.molden.gz\"\n[[frame]]\nat = 2\nfile = \"h2o_a090.molden.gz\"\n",
        &mut |p| orbcloud::formats::load(p),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("c.scan.toml:3:") && e.contains("align only for a path"), "{e}");
}

#[test]
fn a_multi_frame_xyz_beside_the_files_orders_a_path() {
    // The morph's files under names whose order is not the path's, and the path as XYZ frames.
    let tmp = tempfile::tempdir().unwrap();
    let names = ["d.molden.gz", "b.molden.gz", "a.molden.gz", "c.molden.gz"]; // path order
    let mut xyz = String::new();
    for (s, name) in names.iter().enumerate() {
        let from = fixture("water_path").join(format!("h2o_p{s}.molden.gz"));
        std::fs::copy(&from, tmp.path().join(name)).unwrap();
        let doc = orbcloud::formats::load(&from).unwrap();
        xyz.push_str(&format!("3\nframe {s}\n"));
        for a in &doc.molecule.atoms {
            let p = a.position * orbcloud::model::units::ANGSTROM_PER_BOHR;
            xyz.push_str(&format!("{} {:.8} {:.8} {:.8}\n", a.element().symbol, p.x, p.y, p.z));
        }
    }
    std::fs::write(tmp.path().join("irc.xyz"), &xyz).unwrap();
    let made = init(tmp.path(), Some(Coordinate::Path(PathMeasure::ArcLength))).unwrap();
    let order: Vec<&str> = made.frames.iter().map(|(f, _)| f.as_str()).collect();
    assert_eq!(order, names, "the XYZ file's order, not the names'");
    // Without it, the names' order.
    std::fs::remove_file(tmp.path().join("irc.xyz")).unwrap();
    let made = init(tmp.path(), Some(Coordinate::Path(PathMeasure::ArcLength))).unwrap();
    let order: Vec<&str> = made.frames.iter().map(|(f, _)| f.as_str()).collect();
    assert_eq!(order, ["a.molden.gz", "b.molden.gz", "c.molden.gz", "d.molden.gz"]);
}

#[test]
fn an_unrestricted_diagram_has_alpha_and_beta_lines() {
    use orbcloud::model::correlation::correlation;
    use orbcloud::model::scan::{FrameContent, KeyFrame};
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/wavefunctions/h2o_cation_uhf_631gs.molden");
    let doc = orbcloud::formats::load(&path).unwrap();
    let wf = doc.wavefunction.clone().unwrap();
    let frame = |at: f64| KeyFrame {
        at,
        source: format!("{at}"),
        molecule: doc.molecule.clone(),
        content: FrameContent::Wavefunctions(vec![wf.clone()]),
    };
    let scan = Scan::new(
        "uhf".into(),
        Coordinate::Path(PathMeasure::ArcLength),
        vec!["homo".into()],
        vec![frame(0.0), frame(1.0)],
    )
    .unwrap();
    let diagram = correlation(&scan, 1, 1).unwrap();
    let labels: Vec<&str> = diagram.lines.iter().map(|l| l.label.as_str()).collect();
    assert_eq!(labels, ["HOMO−1 α", "HOMO α", "LUMO α", "LUMO+1 α", "HOMO−1 β", "HOMO β", "LUMO β", "LUMO+1 β"]);
    // The same frame twice: every line stays on its own orbital, no crossing.
    assert!(diagram.lines.iter().all(|l| l.crossings.is_empty() && l.points[0].2 == l.points[1].2));
}
